"""Builders and comparisons shared by the tests of aura_ums.logs."""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from aura_ums.logs import GroundTruth, LogLandmark, LogMeta, LogObservation, Odometry, RobotLog
from aura_ums.manager import PositionReport
from aura_ums.uncertainty import Pose, TerrainStats, TurnAndRun

#: Where the published datasets live (never copied into the repository).
MRCLAM6 = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "mrclam6"

#: A valid log folder, file by file; tests of bad logs replace one file.
VALID_FILES: dict[str, str] = {
    "meta.toml": 'name = "tiny"\nterrain = "tile"\n\n[sensor]\nbearing_error = 0.02\n',
    "landmarks.csv": "id,x,y\n# two poles\nA,3.0,0.0\nB,0.0,4.0\n",
    "observations.csv": "time,landmark_id,bearing,range\n0.5,A,0.1,3.0\n0.5,B,1.5,\n1.0,A,0.2,2.5\n",
    "odometry.csv": "time,v,omega\n0.0,0.5,0.0\n1.0,0.5,0.1\n2.0,0.0,0.0\n",
    "groundtruth.csv": "time,x,y,heading\n0.0,0.0,0.0,0.0\n2.0,1.0,0.0,0.1\n",
}


def write_files(folder: Path, files: Mapping[str, str | None]) -> Path:
    """Write ``files`` into ``folder`` (None: leave that file out) and return the folder."""
    folder.mkdir(parents=True, exist_ok=True)
    for name, text in files.items():
        if text is not None:
            (folder / name).write_text(text, encoding="utf-8")
    return folder


def small_log(*, commands: bool = False, groundtruth: bool = True, start: bool = True) -> RobotLog:
    """A small log exercising every optional field."""
    meta = LogMeta(
        "small log",
        terrain="concrete",
        bearing_error=0.03,
        range_error=0.07,
        range_error_fraction=0.02,
        sensor_forward=0.15,
        sensor_left=-0.05,
        delay_s=0.125,
        run_scale=1.1,
        turn_scale=1.05,
        start=Pose(0.1, -0.2, 3.0) if start else None,
        start_radius=0.3,
        start_heading_halfwidth=0.04,
        landmark_z_bottom=0.2,
        landmark_z_top=2.5,
        source='made up "for tests", with commas',
    )
    landmarks = (
        LogLandmark("a", 1.0 / 3.0, 2.0, 0.01, 0.0, 3.0, "lamppost"),
        LogLandmark("#7", -1e-9, 999999.123456789, symbol="sign, red"),
        LogLandmark('b"q', 0.5, 0.25),
    )
    observations = (
        LogObservation(0.1, "a", 0.7, range=2.0),
        LogObservation(0.1, "#7", -3.0),
        LogObservation(0.3, 'b"q', 0.1, range=1.5, bearing_error=0.01, range_error=0.2),
    )
    truth = GroundTruth([0.0, 0.25, 0.5], [0.0, 0.1, 0.2], [0.0, 0.0, 0.1], [3.1, -3.1, -2.9])
    if commands:
        reports = (PositionReport(0.2, TurnAndRun(0.1, 0.2)), PositionReport(0.4, TurnAndRun(-0.3, 0.0)))
        return RobotLog(
            meta, landmarks, observations, commands=reports, groundtruth=truth if groundtruth else None
        )
    odometry = Odometry([0.0, 0.1, 0.35], [0.2, 0.3, 0.0], [0.0, -0.5, 0.0])
    return RobotLog(
        meta, landmarks, observations, odometry=odometry, groundtruth=truth if groundtruth else None
    )


def assert_same_log(actual: RobotLog, expected: RobotLog, *, lines: bool = False) -> None:
    """Every field equal (floats exactly); observation line numbers only when ``lines``."""
    assert actual.meta == expected.meta
    assert actual.landmarks == expected.landmarks
    assert len(actual.observations) == len(expected.observations)
    for got, want in zip(actual.observations, expected.observations, strict=True):
        if lines:
            assert got == want
        else:
            assert (
                got.time,
                got.landmark_id,
                got.bearing,
                got.range,
                got.bearing_error,
                got.range_error,
            ) == (
                want.time,
                want.landmark_id,
                want.bearing,
                want.range,
                want.bearing_error,
                want.range_error,
            )
    assert actual.commands == expected.commands
    assert (actual.odometry is None) == (expected.odometry is None)
    if actual.odometry is not None and expected.odometry is not None:
        for name in ("time", "v", "omega"):
            np.testing.assert_array_equal(getattr(actual.odometry, name), getattr(expected.odometry, name))
    assert (actual.groundtruth is None) == (expected.groundtruth is None)
    if actual.groundtruth is not None and expected.groundtruth is not None:
        for name in ("time", "x", "y", "heading"):
            np.testing.assert_array_equal(
                getattr(actual.groundtruth, name), getattr(expected.groundtruth, name)
            )


def long_odometry_log(rows: int, *, rate: float = 100.0, frame_every: int = 100) -> RobotLog:
    """A long log of ``rows`` odometry rows: a figure of eight among four poles, all numpy.

    The odometry is the exact path's speed and turn rate; every ``frame_every``-th row is
    a frame observing, without error, each pole within 9 m and 0.6 rad of the heading.
    """
    w = 2.0 * np.pi / 120.0
    t = np.arange(rows) / rate
    x, y = 3.0 * np.sin(w * t), 1.5 * np.sin(2.0 * w * t)
    dx, dy = 3.0 * w * np.cos(w * t), 3.0 * w * np.cos(2.0 * w * t)
    ddx, ddy = -3.0 * w * w * np.sin(w * t), -6.0 * w * w * np.sin(2.0 * w * t)
    speed = np.hypot(dx, dy)
    heading = np.arctan2(dy, dx)
    poles = {"N": (0.0, 6.5), "E": (6.5, 0.0), "S": (0.0, -6.5), "W": (-6.5, 0.0)}
    observations = []
    for row in range(frame_every, rows, frame_every):
        for name, (px, py) in poles.items():
            distance = float(np.hypot(px - x[row], py - y[row]))
            bearing = float(np.angle(np.exp(1j * (np.arctan2(py - y[row], px - x[row]) - heading[row]))))
            if distance <= 9.0 and abs(bearing) <= 0.6:
                observations.append(LogObservation(float(t[row]), name, bearing, range=distance))
    return RobotLog(
        LogMeta("long", terrain="floor", bearing_error=0.01, range_error=0.05),
        tuple(LogLandmark(name, px, py) for name, (px, py) in poles.items()),
        tuple(observations),
        odometry=Odometry(t, speed, (dx * ddy - dy * ddx) / speed**2),
        groundtruth=GroundTruth(t, x, y, heading),
    )


#: A terrain with no losses: exact odometry is inside its growth bound however it is cut.
LOSSLESS = TerrainStats(
    translation_loss=0.0,
    translation_inertial_loss=0.0,
    translation_sd=0.02,
    drift=0.01,
    rotation_loss=0.0,
    rotation_sd=0.02,
    skitter=0.0,
    skitter_sd=0.0,
)


def steady_arc_log(
    *, duration: float = 40.0, v: float = 0.3, omega: float = 0.2, rate: float = 10.0
) -> RobotLog:
    """A robot driving one circle at constant ``v`` and ``omega``, its odometry and truth exact.

    Eight landmarks on a 6 m ring around the circle's centre, each seen every 0.5 s with its
    exact range and bearing when within 0.6 rad of the heading (bounds 0.005 rad and 0.01 m:
    tight maps, which a systematic error of the replayed motion leaves); terrain ``lossless``
    (:data:`LOSSLESS`), a start known to 0.05 m and 0.02 rad.
    """
    heading0, radius = 0.3, v / omega
    time = np.arange(0.0, duration + 1e-9, 1.0 / rate)
    truth_time = np.arange(0.0, duration + 1e-9, 0.05)
    heading = heading0 + omega * truth_time
    x = radius * (np.sin(heading) - math.sin(heading0))
    y = -radius * (np.cos(heading) - math.cos(heading0))
    centre = (-radius * math.sin(heading0), radius * math.cos(heading0))
    landmarks = tuple(
        LogLandmark(
            f"L{i}", centre[0] + 6.0 * math.cos(i * math.pi / 4), centre[1] + 6.0 * math.sin(i * math.pi / 4)
        )
        for i in range(8)
    )
    observations = []
    for when in np.arange(0.5, duration, 0.5):
        h = heading0 + omega * when
        px, py = radius * (math.sin(h) - math.sin(heading0)), -radius * (math.cos(h) - math.cos(heading0))
        for landmark in landmarks:
            bearing = math.remainder(math.atan2(landmark.y - py, landmark.x - px) - h, math.tau)
            if abs(bearing) < 0.6:
                distance = math.hypot(landmark.x - px, landmark.y - py)
                observations.append(LogObservation(float(when), landmark.id, bearing, range=distance))
    meta = LogMeta(
        "steady arc",
        terrain="lossless",
        bearing_error=0.005,
        range_error=0.01,
        start=Pose(0.0, 0.0, heading0),
        start_radius=0.05,
        start_heading_halfwidth=0.02,
    )
    odometry = Odometry(time, np.full(len(time), v), np.full(len(time), omega))
    truth = GroundTruth(truth_time, x, y, heading)
    return RobotLog(meta, landmarks, tuple(observations), odometry=odometry, groundtruth=truth)
