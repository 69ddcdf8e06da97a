"""The one switch: AURA_UMS_NATIVE=0 or a missing extension runs the numpy reference everywhere."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import aura_ums
from aura_ums import _native

SOURCE = Path(aura_ums.__file__).parent

#: Grows, reduces, expects and measures a distance, then prints what ran.
EXERCISE = """
import math, sys
import aura_ums as ums
from aura_ums import _native
from aura_ums.camera import Camera, CameraIntrinsics, CameraMount
from aura_ums.expecter import Expecter
from aura_ums.schemas._perceive import map_gap
start = ums.SpatialUncertaintyMap.from_pose(ums.Pose(0, 0, 0), 0.2, 0.05)
grown = start.grow(ums.TurnAndRun(0.3, 4.0), ums.TerrainTable.default()["grass"], max_vertices=8)
pole = ums.VerticalLineLandmark("pole", 12.0, 2.0, 0.0, 3.0)
seen = grown.reduce(ums.BearingObservation("pole", 0.0, 0.12, 0.02), pole)
camera = Camera(CameraIntrinsics(500, 500, 320, 240, 640, 480), CameraMount(height=1.0))
window = Expecter(camera).window(seen.map, pole)
print(_native.BUILT, _native.NATIVE, "aura_ums._native._kernels" in sys.modules)
print(grown.polygon.vertex_count <= 8, seen.consistent, window is not None, map_gap(seen.map, pole) > 0)
"""

#: Makes the extension module unimportable, as on a machine without a C compiler.
WITHOUT_EXTENSION = """
import importlib.abc, sys
class NoKernels(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path, target=None):
        if name == "aura_ums._native._kernels":
            raise ImportError("no compiler at install")
        return None
sys.meta_path.insert(0, NoKernels())
"""


def run(code: str, **environment: str) -> list[str]:
    env = {key: value for key, value in os.environ.items() if key != "AURA_UMS_NATIVE"} | environment
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=False)
    assert done.returncode == 0, done.stderr
    return done.stdout.split("\n")[:2]


def test_the_switch_is_read_once_from_the_environment() -> None:
    assert (_native.BUILT and os.environ.get("AURA_UMS_NATIVE", "").strip() != "0") == _native.NATIVE


@pytest.mark.skipif(not _native.BUILT, reason="the C extension was not built (no compiler)")
def test_by_default_the_kernels_run_compiled() -> None:
    assert run(EXERCISE) == ["True True True", "True True True True"]


def test_aura_ums_native_0_runs_the_reference_everywhere() -> None:
    built = str(_native.BUILT)
    assert run(EXERCISE, AURA_UMS_NATIVE="0") == [f"{built} False {built}", "True True True True"]


def test_without_the_extension_the_reference_runs() -> None:
    assert run(WITHOUT_EXTENSION + EXERCISE) == ["False False False", "True True True True"]


def test_nothing_outside_the_native_package_reaches_the_extension() -> None:
    """The owning layers call the wrappers only: no import of the extension, no switches of their own."""
    pattern = re.compile(r"_kernels|_compiled_|AURA_UMS_NATIVE|_extension")
    offenders = [
        f"{path.relative_to(SOURCE)}:{number}"
        for path in sorted(SOURCE.rglob("*.py"))
        if "_native" not in path.parts
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1)
        if pattern.search(line)
    ]
    assert offenders == []
