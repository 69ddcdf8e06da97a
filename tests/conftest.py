"""Fixtures shared by the whole test suite."""

from __future__ import annotations

import math
import os
from pathlib import Path

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
