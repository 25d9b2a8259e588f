"""A typed program using the module, which `mypy --strict` must accept with the type stubs pip
installs (keyplace-stubs; python.pip_install type-checks it in the environment it installed the
checkout into). It is type-checked only, never run: its values need not be real files.

It leans on what a stub could get wrong without stubtest noticing: return types (stubtest cannot
read a pybind11 function's signature), an instance attribute set by the library
(MergeResult.config) and None where a figure is missing.
"""

from typing import Dict, List, Optional

import numpy
from numpy.typing import NDArray

import keyplace


def first_ranges(log_path: str) -> NDArray[numpy.float64]:
    log = keyplace.read_log(log_path)
    first: keyplace.Scan = log[0]
    assert len(log.scans) == len(log)
    return first.ranges


def submap_origins(map_path: str) -> List[NDArray[numpy.float64]]:
    submaps: List[keyplace.Submap] = keyplace.load_map(map_path).submaps
    return [submap.origin for submap in submaps]


def merge(map_a: str, map_b: str) -> NDArray[numpy.float64]:
    result = keyplace.merge_maps(map_a, map_b)
    agreeing = [r.confidence for r in result.recognitions if r.agrees]
    print(len(agreeing), result.config.get("merge.min_agreeing"))
    return result.T_a_b


def ate_m(log_path: str) -> Optional[float]:
    run, evaluation = keyplace.slam(log_path)
    print(run.poses.shape, evaluation.mapping.submaps)
    return evaluation.ate_rmse_m


def first_fix_yaml(log_path: str, map_path: str) -> str:
    evaluation = keyplace.relocalize(log_path, map_path, starts=5)
    first = evaluation.first_fix()
    if first is None:
        return ""
    start_scan, fix = first
    print(start_scan, fix.checked_scan)
    return fix.initial_pose().to_yaml()


def settings() -> Dict[str, str]:
    version: str = keyplace.__version__
    print(version)
    return keyplace.Config("strict").to_dict()
