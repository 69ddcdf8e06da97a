"""Fixtures shared by the whole test suite."""

from __future__ import annotations

import errno
import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

# Figures draw off screen however pytest is started (`make test` sets it too): an
# interactive backend found on a developer's machine would open windows, or wait on them.
os.environ.setdefault("MPLBACKEND", "Agg")

import numpy as np  # after the backend is chosen
import pytest
from hypothesis import HealthCheck, settings

import aura_ums as ums
from aura_ums.logs import Calibration, RobotLog, calibrate_logs, read_mrclam

# CI is reproducible (a failure shows every time, not by chance); developers' runs and the
# "thorough" profile (AURA_HYPOTHESIS_PROFILE=thorough) keep exploring new examples.
settings.register_profile(
    "ci",
    max_examples=100,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile("dev", max_examples=50, deadline=None)
settings.register_profile("thorough", max_examples=1000, deadline=None)
settings.load_profile(os.environ.get("AURA_HYPOTHESIS_PROFILE") or ("ci" if os.environ.get("CI") else "dev"))

#: Where the published datasets live (never copied into the repository).
SHARED_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
MRCLAM6 = SHARED_DATA / "mrclam6"


@pytest.fixture(scope="session")
def mrclam6_robot1() -> RobotLog:
    """MRCLAM Dataset 6 robot 1, read once per test process (a log is an immutable value)."""
    if not (MRCLAM6 / "Robot1_Measurement.dat").is_file():
        pytest.skip(f"MRCLAM Dataset 6 not found at {MRCLAM6} (shared data is not part of the repository)")
    return read_mrclam(MRCLAM6, 1)


@pytest.fixture(scope="session")
def mrclam6_robot1_calibration(mrclam6_robot1: RobotLog) -> Calibration:
    """The calibration on MRCLAM Dataset 6 robot 1 with the defaults: the acceptance setup."""
    return calibrate_logs([mrclam6_robot1])


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261121)


@pytest.fixture
def terrains() -> ums.TerrainTable:
    return ums.TerrainTable.default()


@pytest.fixture
def point_map() -> ums.SpatialUncertaintyMap:
    return ums.SpatialUncertaintyMap.from_pose(ums.Pose(0.0, 0.0, 0.0), 0.0, 0.0)


@pytest.fixture
def figure5_map(terrains: ums.TerrainTable) -> ums.SpatialUncertaintyMap:
    start = ums.SpatialUncertaintyMap.from_pose(ums.Pose(0.0, 0.0, 0.0), 0.0, 0.0)
    return start.grow(ums.TurnAndRun(math.radians(45), 30 * ums.FOOT), terrains["concrete"])


class _FullDiskStream:
    """A text stream over a real one that fails as a full disk does: ENOSPC on a write or on close.

    ``where`` is ``"write"`` (every write after the first fails: the first is a header that
    fits) or ``"close"`` (writes are buffered and the flush on close fails). The real
    stream is closed either way, as Python's buffered files close their descriptor.
    """

    def __init__(self, stream: Any, where: str) -> None:
        self._stream, self._where, self._writes = stream, where, 0

    def write(self, text: str) -> int:
        self._writes += 1
        if self._where == "write" and self._writes > 1:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return int(self._stream.write(text))

    def close(self) -> None:
        self._stream.close()
        if self._where == "close":
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    def __enter__(self) -> _FullDiskStream:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()


@pytest.fixture
def full_disk(monkeypatch: pytest.MonkeyPatch) -> Callable[[str, str], None]:
    """Make files whose name holds ``part``, opened for writing, fail as on a full disk (see above)."""
    opened = Path.open

    def arm(part: str, where: str) -> None:
        def opening(path: Path, mode: str = "r", *args: Any, **kwargs: Any) -> Any:
            stream = opened(path, mode, *args, **kwargs)
            if part in path.name and any(flag in mode for flag in "wxa"):
                return _FullDiskStream(stream, where)
            return stream

        monkeypatch.setattr(Path, "open", opening)

    return arm


def ros_calibration_yaml(name: str, k: str, d: str, p: str) -> str:
    """A 640 x 480 camera's calibration as ROS's camera_calibration_parsers writes it.

    ``k``, ``d`` and ``p`` are the camera matrix's 9, the distortion's 5 and the projection
    matrix's 12 numbers as the file spells them (``"554.25, 0, 320.5, ..."``); the
    rectification is the identity.
    """
    return (
        f"image_width: 640\nimage_height: 480\ncamera_name: {name}\n"
        f"camera_matrix:\n  rows: 3\n  cols: 3\n  data: [{k}]\n"
        f"distortion_model: plumb_bob\n"
        f"distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [{d}]\n"
        f"rectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
        f"projection_matrix:\n  rows: 3\n  cols: 4\n  data: [{p}]\n"
    )
