"""Replay of logs through the map manager: synthetic logs with known truth, and the MRCLAM data."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from aura_ums.errors import InputError
from aura_ums.logs import (
    Calibration,
    MotionCalibration,
    ReplayOptions,
    RobotLog,
    SensorBounds,
    observation_for,
    read_mrclam,
    replay_log,
    synthetic_log,
)
from aura_ums.manager import ManagerSettings
from aura_ums.uncertainty import (
    BearingObservation,
    LandmarkClass,
    RangeBearingObservation,
    TerrainTable,
)
from tests.logs.log_helpers import LOSSLESS, MRCLAM6, steady_arc_log

MRCLAM = MRCLAM6
FLOOR = TerrainTable({"floor": TerrainTable.default()["tile"]})


@pytest.fixture(scope="module")
def clean_log() -> RobotLog:
    return synthetic_log(np.random.default_rng(5), duration=60.0)


@pytest.mark.parametrize("landmark_class", [LandmarkClass.VERTICAL_LINE, LandmarkClass.POINT])
def test_clean_synthetic_log_keeps_the_truth_at_every_step(
    clean_log: RobotLog, landmark_class: LandmarkClass
) -> None:
    result = replay_log(clean_log, FLOOR, ReplayOptions(landmark_class=landmark_class))
    assert len(result.steps) > 100
    assert all(step.inside for step in result.steps)
    assert all(step.envelope_inside for step in result.steps)
    assert result.inconsistent_observations == 0
    assert result.relocalizations == 0
    # Landmarks do shrink the map: it stays far below the growth-only area.
    grown_only = replay_log(
        dataclasses.replace(clean_log, observations=()), FLOOR, ReplayOptions(landmark_class=landmark_class)
    )
    assert grown_only.steps == ()
    with pytest.raises(
        InputError,
        match=r"^log 'synthetic': expected a frame \(an observation time\) after the .*: the log has no "
        r"observation at all$",
    ):
        grown_only.require_steps()
    result.require_steps()
    assert result.median_area_m2 < 2.0
    metrics = result.metrics()
    for key in (
        "containment_rate",
        "median_area_m2",
        "median_wedge_width_rad",
        "inconsistent_observations",
        "median_update_us",
    ):
        assert key in metrics
    assert metrics["containment_rate"] == 1.0


def test_class_two_is_tighter_than_class_one(clean_log: RobotLog) -> None:
    one = replay_log(clean_log, FLOOR, ReplayOptions(landmark_class=LandmarkClass.VERTICAL_LINE))
    two = replay_log(clean_log, FLOOR, ReplayOptions(landmark_class=LandmarkClass.POINT))
    assert two.median_area_m2 < one.median_area_m2


def test_a_class_two_replay_uses_rows_without_a_range_as_bearings(clean_log: RobotLog) -> None:
    # Every other row loses its range: a bearing to the point, not an observation of another class.
    rows = tuple(
        dataclasses.replace(row, range=None) if i % 2 else row for i, row in enumerate(clean_log.observations)
    )
    mixed = replay_log(
        dataclasses.replace(clean_log, observations=rows),
        FLOOR,
        ReplayOptions(landmark_class=LandmarkClass.POINT),
    )
    metrics = mixed.metrics()
    assert (metrics["inconsistent_observations"], metrics["rejected_by_reason"]) == (0, {})
    assert metrics["accepted_observations"] == len(rows)
    assert all(step.inside for step in mixed.steps)
    # The bearings bite: on the same frames, tighter than with bearings too loose to tell anything.
    loose = tuple(
        row if row.range is not None else dataclasses.replace(row, bearing_error=3.0) for row in rows
    )
    blind = replay_log(
        dataclasses.replace(clean_log, observations=loose),
        FLOOR,
        ReplayOptions(landmark_class=LandmarkClass.POINT),
    )
    assert len(blind.steps) == len(mixed.steps)
    assert mixed.median_area_m2 < 0.95 * blind.median_area_m2


def test_observation_for_uses_row_bounds_first() -> None:
    from aura_ums.logs import LogObservation

    bounds = SensorBounds(0.05, 0.0, 0.1, 0.05)
    row = LogObservation(1.0, "a", 0.2, range=4.0)
    seen = observation_for(row, LandmarkClass.POINT, bounds)
    assert isinstance(seen, RangeBearingObservation)
    assert (seen.range_min, seen.range_max, seen.bearing_error) == pytest.approx((3.8, 4.4, 0.05))
    own = observation_for(
        LogObservation(1.0, "a", 0.2, range=4.0, bearing_error=0.01, range_error=0.2),
        LandmarkClass.POINT,
        bounds,
    )
    assert isinstance(own, RangeBearingObservation)
    assert (own.range_min, own.range_max, own.bearing_error) == pytest.approx((3.8, 4.2, 0.01))
    bearing_only = observation_for(LogObservation(1.0, "a", 0.2), LandmarkClass.POINT, bounds)
    assert isinstance(bearing_only, BearingObservation)


def test_replay_rejects_bad_arguments(clean_log: RobotLog) -> None:
    with pytest.raises(
        InputError, match=r"^table: expected the terrain 'floor' of the log \(its meta\.toml\), got 'tile', "
    ):
        replay_log(clean_log, TerrainTable.default())
    with pytest.raises(InputError, match="log: expected a RobotLog"):
        replay_log("log", FLOOR)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"ReplayOptions\.settings: expected ManagerSettings, got dict"):
        ReplayOptions(settings={"sigmas": 3.0})  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"ReplayOptions\.max_interval: expected a positive number"):
        ReplayOptions(max_interval=0.0)
    # A string for the enum is refused by name, not an AttributeError while wording the message.
    with pytest.raises(InputError, match=r"ReplayOptions\.landmark_class: expected .*, got 'II' \(str\)$"):
        ReplayOptions(landmark_class="II")  # type: ignore[arg-type]
    no_start = dataclasses.replace(clean_log, groundtruth=None)
    with pytest.raises(InputError, match=r"expected a \[start\] pose in meta.toml or a groundtruth.csv"):
        replay_log(no_start, FLOOR)


def test_zero_length_log_gives_no_steps() -> None:
    log = synthetic_log(np.random.default_rng(2), duration=0.1)
    result = replay_log(dataclasses.replace(log, observations=()), FLOOR)
    assert result.steps == ()
    assert np.isnan(result.containment_rate)
    assert result.start_time == pytest.approx(0.0, abs=0.1)
    with pytest.raises(
        InputError, match=r"^until: expected a frame \(an observation time\) between the replay's start"
    ):
        result.require_steps(until=0.05)


@pytest.fixture(scope="module")
def mrclam(
    mrclam6_robot1: RobotLog, mrclam6_robot1_calibration: Calibration
) -> tuple[RobotLog, RobotLog, Calibration]:
    """Robots 1 and 2 of MRCLAM Dataset 6, and the calibration on robot 1 (the acceptance setup)."""
    return mrclam6_robot1, read_mrclam(MRCLAM, 2), mrclam6_robot1_calibration


def calibrated(calibration: Calibration, landmark_class: LandmarkClass) -> ReplayOptions:
    return ReplayOptions(
        landmark_class=landmark_class,
        working=calibration.working,
        envelope=calibration.envelope,
        motion=calibration.motion,
    )


def test_mrclam_range_bearing_replay_keeps_the_truth_on_both_robots(
    mrclam: tuple[RobotLog, RobotLog, Calibration],
) -> None:
    # Calibrated on robot 1, replayed on robot 1 and on robot 2 (the acceptance figure).
    robot1, robot2, calibration = mrclam
    assert isinstance(calibration.motion, MotionCalibration)
    options = calibrated(calibration, LandmarkClass.POINT)
    for log in (robot1, robot2):
        result = replay_log(log, calibration.terrain_table(), options)
        assert result.containment_rate >= 0.99, log.meta.name
        assert result.median_area_m2 < 2.0


def test_mrclam_bearing_only_replay_is_sound_and_informative_with_joint_reductions(
    mrclam: tuple[RobotLog, RobotLog, Calibration],
) -> None:
    # Bearings alone, one by one, leave the map sound but useless once the heading has
    # opened up (robot 1: 2586 m^2, any heading); together they keep closing it.
    robot1, robot2, calibration = mrclam
    options = calibrated(calibration, LandmarkClass.VERTICAL_LINE)
    for log in (robot1, robot2):
        result = replay_log(log, calibration.terrain_table(), options)
        assert result.containment_rate >= 0.99, log.meta.name
        assert result.median_area_m2 < 50.0, log.meta.name
        assert result.median_wedge_width_rad < 2.0, log.meta.name
    alone = dataclasses.replace(options, settings=ManagerSettings(joint_above=None))
    one_by_one = replay_log(robot1, calibration.terrain_table(), alone)
    assert one_by_one.median_area_m2 > 1000.0
    assert one_by_one.metrics()["joint_above_rad"] is None


def test_the_settings_are_reported(clean_log: RobotLog) -> None:
    assert ReplayOptions().settings == ManagerSettings()
    options = ReplayOptions(settings=ManagerSettings(max_vertices=8))
    metrics = replay_log(clean_log, FLOOR, options).metrics()
    assert (metrics["max_vertices"], metrics["envelope_max_vertices"]) == (8, None)
    assert metrics["containment_rate"] == 1.0


def test_replay_measures_from_the_sensor_offset_in_the_meta() -> None:
    # Observations re-measured, exactly, from a sensor 0.4 m ahead and 0.1 m left of the
    # reference point: with the offset in the meta the truth stays inside every map.
    log = synthetic_log(np.random.default_rng(5), duration=30.0)
    truth = log.groundtruth
    assert truth is not None
    rows = []
    for row in log.observations:
        x, y, heading = truth.at([row.time])[0]
        landmark = log.landmark(row.landmark_id)
        sx = x + 0.4 * math.cos(heading) - 0.1 * math.sin(heading)
        sy = y + 0.4 * math.sin(heading) + 0.1 * math.cos(heading)
        bearing = math.atan2(landmark.y - sy, landmark.x - sx) - heading
        rows.append(
            dataclasses.replace(
                row,
                bearing=math.remainder(bearing, math.tau),
                range=math.hypot(landmark.x - sx, landmark.y - sy),
            )
        )
    meta = dataclasses.replace(log.meta, sensor_forward=0.4, sensor_left=0.1, bearing_error=0.01)
    shifted = dataclasses.replace(log, meta=meta, observations=tuple(rows))
    table = TerrainTable({"floor": TerrainTable.default()["tile"]})
    options = ReplayOptions(landmark_class=LandmarkClass.POINT)
    assert replay_log(shifted, table, options).containment_rate == 1.0
    ignored = dataclasses.replace(
        shifted, meta=dataclasses.replace(meta, sensor_forward=0.0, sensor_left=0.0)
    )
    result = replay_log(ignored, table, options)
    assert result.inconsistent_observations > 0 or result.containment_rate < 1.0


@pytest.mark.parametrize("landmark_class", [LandmarkClass.POINT, LandmarkClass.VERTICAL_LINE])
def test_exact_odometry_of_a_steady_arc_keeps_the_truth_on_a_lossless_terrain(
    landmark_class: LandmarkClass,
) -> None:
    # Each piece of the arc turned in full before its run: off its chord by half its turn, a
    # systematic error no terrain statistic bounds. Class II kept the truth in 0.30 of the frames.
    table = TerrainTable({"lossless": LOSSLESS})
    result = replay_log(steady_arc_log(), table, ReplayOptions(landmark_class=landmark_class))
    assert len(result.steps) > 70
    assert result.containment_rate == 1.0
    assert result.inconsistent_observations == 0
