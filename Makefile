# keyplace — top-level entry points. `make demo` and `make test` work on a fresh Debian 12 machine.
BUILD_DIR ?= build
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc)
KEYPLACE := $(BUILD_DIR)/keyplace
DEMO_LOG := data/fr079-corrected.log.gz
DEMO_OUT := $(BUILD_DIR)/demo
REPORT_DIR ?= $(BUILD_DIR)/report
KEYPLACE_SHARED ?= ../shared

.PHONY: all deps configure build demo test bench report format format-check tidy install clean

all: build

deps:
	@bash scripts/install-deps.sh

configure: deps
	@cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) $(if $(shell command -v ccache),-DCMAKE_CXX_COMPILER_LAUNCHER=ccache) >/dev/null

build: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS)

# The main job on the bundled data set, printing its results.
demo: build
	@bash scripts/demo.sh $(KEYPLACE) $(DEMO_LOG) $(DEMO_OUT)

test: build format-check
	@cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

# Every bench/*_bench program (docs/BENCHMARKS.md), medians of 3 repetitions.
bench: build
	@set -e; for program in $(BUILD_DIR)/bench/*_bench; do \
	  echo "== $$program"; \
	  $$program --benchmark_repetitions=3 --benchmark_report_aggregates_only=true; \
	done

# Every figure and table of the paper for all six data sets, ours beside the paper's, in
# $(REPORT_DIR)/index.html (docs/REPORT.md: what it runs and how long it takes). Resumable.
report: build
	@$(KEYPLACE) report --out $(REPORT_DIR) --data $(KEYPLACE_SHARED)/data --threads $(JOBS)

format:
	@git ls-files '*.cpp' '*.hpp' | xargs clang-format -i

format-check:
	@git ls-files '*.cpp' '*.hpp' | xargs clang-format --dry-run --Werror
	@echo "format-check: clang-format clean"

tidy: configure
	@git ls-files 'src/*.cpp' 'apps/*.cpp' 'tools/*.cpp' 'examples/*.cpp' | xargs -P $(JOBS) -n 4 clang-tidy -p $(BUILD_DIR) --quiet 2>/dev/null
	@echo "tidy: clang-tidy clean"

install: build
	@cmake --install $(BUILD_DIR) --prefix $(or $(PREFIX),/usr/local)

clean:
	@rm -rf $(BUILD_DIR)
