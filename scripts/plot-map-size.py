#!/usr/bin/python3
"""Draws bench/map_size_bench's results on log-log axes (docs/BENCHMARKS.md, "Map size").

Usage: scripts/plot-map-size.py OUT.svg RESULTS.json [RESULTS.json ...]
RESULTS.json: the benchmark's --benchmark_out (--benchmark_out_format=json); a variant found in
several files is taken from the last. Left: CPU seconds
per query against submaps, one line per variant (dense, words, none); right: the time to make
the recognizer from the places (index and vocabulary).
Needs matplotlib (Debian's python3-matplotlib).
"""

import json
import sys

import matplotlib

matplotlib.use("Agg")
matplotlib.rcParams["svg.fonttype"] = "none"  # text as text: a small file
matplotlib.rcParams["svg.hashsalt"] = "keyplace"  # the same ids on every run
import matplotlib.pyplot as plt  # noqa: E402

VARIANT_STYLE = {"dense": "o-", "words": "s-", "none": "^--"}


def read_rows(path, rows):
    """Adds the file's {variant: [(places, counters), ...]} to rows, sorted by places."""
    try:
        with open(path, encoding="utf-8") as handle:
            results = json.load(handle)
    except (OSError, json.JSONDecodeError) as error:
        sys.exit(f"{path}: cannot read benchmark results: {error}")
    found = {}
    for benchmark in results.get("benchmarks", []):
        name = benchmark.get("name", "")
        parts = name.split("/")
        if len(parts) < 3 or parts[0] != "BM_MapSize":
            continue
        if "s_per_query" not in benchmark or "places" not in benchmark:
            sys.exit(f"{path}: {name} has no s_per_query or places counter")
        found.setdefault(parts[1], []).append((benchmark["places"], benchmark))
    if not found:
        sys.exit(f"{path}: no BM_MapSize results")
    for variant, points in found.items():
        rows[variant] = sorted(points, key=lambda row: row[0])


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    rows = {}
    for path in sys.argv[2:]:
        read_rows(path, rows)
    figure, (queries, building) = plt.subplots(1, 2, figsize=(10, 4))
    for variant, points in sorted(rows.items()):
        style = VARIANT_STYLE.get(variant, "x-")
        places = [row[0] for row in points]
        queries.plot(places, [row[1]["s_per_query"] for row in points], style, label=variant)
        if all("build_s" in row[1] for row in points):
            building.plot(places, [row[1]["build_s"] for row in points], style,
                          label=f"{variant}: build s")
    queries.axhline(0.020, color="grey", linewidth=0.8, linestyle=":")
    queries.text(100, 0.022, "20 ms", color="grey")
    building.plot([1e2, 1e5], [1e-2, 1e1], ":", color="grey", linewidth=0.8,
                  label="1 s per 10^4 submaps")
    for axes, title, label in ((queries, "query time", "CPU s per query"),
                               (building, "recognizer build (at map load)", "wall s")):
        axes.set_xscale("log")
        axes.set_yscale("log")
        axes.set_xlabel("submaps")
        axes.set_ylabel(label)
        axes.set_title(title)
        axes.grid(True, which="major", linewidth=0.3)
        axes.legend()
    figure.tight_layout()
    figure.savefig(sys.argv[1], metadata={"Date": None} if sys.argv[1].endswith(".svg") else None)


if __name__ == "__main__":
    main()
