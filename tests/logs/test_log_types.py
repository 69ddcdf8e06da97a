"""The value types of a log: validation, bounds, ground-truth interpolation, position reports."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums.errors import InputError
from aura_ums.logs import (
    GroundTruth,
    LogLandmark,
    LogMeta,
    LogObservation,
    ObservationKind,
    Odometry,
    RobotLog,
    odometry_to_commands,
    synthetic_log,
)
from aura_ums.manager import PositionReport
from aura_ums.uncertainty import TurnAndRun
from tests.logs.log_helpers import small_log


@pytest.mark.parametrize(
    ("changes", "pattern"),
    [
        ({"bearing_error": 0.0}, r"LogMeta\.bearing_error: expected a positive number, got 0\.0"),
        ({"bearing_error": math.nan}, r"LogMeta\.bearing_error: expected a finite number"),
        ({"range_error": -1.0}, r"LogMeta\.range_error: expected a non-negative number"),
        ({"range_error_fraction": -0.1}, r"LogMeta\.range_error_fraction: expected a non-negative"),
        ({"delay_s": -0.1}, r"LogMeta\.delay_s: expected a non-negative number"),
        ({"turn_scale": -2.0}, r"LogMeta\.turn_scale: expected a positive number"),
        ({"start": (0.0, 0.0, 0.0)}, r"LogMeta\.start: expected a Pose or None, got tuple"),
        ({"start_radius": math.inf}, r"LogMeta\.start_radius: expected a finite number"),
        ({"landmark_z_top": -1.0}, r"LogMeta\.landmark_z_top: expected >= landmark_z_bottom"),
        ({"terrain": " tile"}, r"LogMeta\.terrain: expected a non-empty string without surrounding spaces"),
        ({"terrain": "ti\nle"}, r"LogMeta\.terrain: expected printable characters"),
        ({"name": 3}, r"LogMeta\.name: expected a string, got 3"),
        ({"run_scale": True}, r"LogMeta\.run_scale: expected a finite number, got True"),
    ],
)
def test_log_meta_rejects_bad_values(changes: dict[str, Any], pattern: str) -> None:
    values: dict[str, Any] = {"name": "m", **changes}
    with pytest.raises(InputError, match=pattern):
        LogMeta(**values)


def test_log_meta_range_bound_is_affine() -> None:
    meta = LogMeta("m", range_error=0.1, range_error_fraction=0.05)
    assert meta.range_bound(0.0) == 0.1
    assert meta.range_bound(4.0) == pytest.approx(0.3)


def test_observation_bounds_fall_back_to_the_meta() -> None:
    meta = LogMeta("m", bearing_error=0.04, range_error=0.2, range_error_fraction=0.1)
    plain = LogObservation(1.0, "a", 0.5, range=3.0)
    own = LogObservation(1.0, "a", 0.5, range=3.0, bearing_error=0.01, range_error=0.05)
    bearing_only = LogObservation(1.0, "a", 0.5)
    assert plain.kind is ObservationKind.RANGE_BEARING
    assert bearing_only.kind is ObservationKind.BEARING
    assert (plain.bearing_bound(meta), plain.range_bound(meta)) == pytest.approx((0.04, 0.5))
    assert (own.bearing_bound(meta), own.range_bound(meta)) == (0.01, 0.05)
    assert bearing_only.range_bound(meta) is None


def test_observation_bearing_is_wrapped_and_in_range_values_kept_exactly() -> None:
    assert LogObservation(0.0, "a", 3 * math.pi / 2).bearing == pytest.approx(-math.pi / 2)
    assert LogObservation(0.0, "a", -math.pi).bearing == math.pi
    assert LogObservation(0.0, "a", -0.539).bearing == -0.539


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"landmark_id": ""}, r"LogObservation\.landmark_id: expected a non-empty string"),
        ({"bearing": math.inf}, r"LogObservation\.bearing: expected a finite number"),
        ({"range": -0.5}, r"LogObservation\.range: expected a non-negative number"),
        ({"bearing_error": 0.0}, r"LogObservation\.bearing_error: expected a positive number"),
        ({"range_error": -1.0}, r"LogObservation\.range_error: expected a non-negative number"),
        ({"line": -1}, r"LogObservation\.line: expected an integer >= 0, got -1"),
        ({"time": "now"}, r"LogObservation\.time: expected a finite number, got 'now'"),
    ],
)
def test_observation_rejects_bad_values(kwargs: dict[str, Any], pattern: str) -> None:
    values: dict[str, Any] = {"time": 0.0, "landmark_id": "a", "bearing": 0.0}
    values.update(kwargs)
    with pytest.raises(InputError, match=pattern):
        LogObservation(**values)


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"id": "a\tb"}, r"LogLandmark\.id: expected printable characters"),
        ({"x": math.nan}, r"LogLandmark\.x: expected a finite number"),
        ({"position_uncertainty": -0.1}, r"LogLandmark\.position_uncertainty: expected a non-negative"),
        ({"z_bottom": 2.0, "z_top": 1.0}, r"LogLandmark\.z_top: expected >= z_bottom \(2\.0\), got 1\.0"),
        ({"symbol": ""}, r"LogLandmark\.symbol: expected a non-empty string"),
    ],
)
def test_landmark_rejects_bad_values(kwargs: dict[str, Any], pattern: str) -> None:
    values: dict[str, Any] = {"id": "a", "x": 0.0, "y": 0.0}
    values.update(kwargs)
    with pytest.raises(InputError, match=pattern):
        LogLandmark(**values)


def test_landmark_heights_default_to_the_meta() -> None:
    meta = LogMeta("m", landmark_z_bottom=0.5, landmark_z_top=2.0)
    assert LogLandmark("a", 0.0, 0.0).heights(meta) == (0.5, 2.0)
    assert LogLandmark("a", 0.0, 0.0, z_top=1.0).heights(meta) == (0.5, 1.0)
    assert LogLandmark("a", 0.0, 0.0, z_bottom=3.0).heights(meta) == (3.0, 3.0)  # never upside down


def test_odometry_arrays_are_read_only_copies() -> None:
    time = np.array([0.0, 1.0])
    odometry = Odometry(time, [1.0, 0.0], [0.0, 0.0])
    time[0] = -5.0
    assert odometry.time[0] == 0.0
    with pytest.raises(ValueError, match="read-only"):
        odometry.v[0] = 3.0


@pytest.mark.parametrize(
    ("args", "pattern"),
    [
        (
            ([0.0, 1.0], [1.0], [0.0, 0.0]),
            r"Odometry: expected columns of equal length, got time 2, v 1, omega 2",
        ),
        (([], [], []), r"Odometry\.time: expected at least one row, got none"),
        (
            ([1.0, 0.0], [1.0, 1.0], [0.0, 0.0]),
            r"Odometry\.time: expected strictly increasing times, got 0\.0 after 1\.0",
        ),
        (([0.0, 1.0], [1.0, math.nan], [0.0, 0.0]), r"Odometry\.v: expected finite numbers"),
        (
            ([[0.0, 1.0]], [[1.0, 1.0]], [[0.0, 0.0]]),
            r"Odometry\.time: expected a 1-D array, got shape \(1, 2\)",
        ),
    ],
)
def test_odometry_rejects_bad_arrays(args: tuple[Any, Any, Any], pattern: str) -> None:
    with pytest.raises(InputError, match=pattern):
        Odometry(*args)


# --- ground truth ------------------------------------------------------------------------------


def test_groundtruth_interpolates_across_plus_minus_pi() -> None:
    truth = GroundTruth([0.0, 1.0, 2.0], [0.0, 1.0, 1.0], [0.0, 0.0, 2.0], [3.0, -3.0, -2.0], max_gap=1.0)
    poses = truth.at([0.0, 0.25, 0.5, 0.75, 1.5, 2.0])
    step = 2 * math.pi - 6.0  # from 3.0 to -3.0 the short way is through pi, +0.283 rad
    expected = [3.0, 3.0 + 0.25 * step, math.pi, -3.0 - 0.25 * step, -2.5, -2.0]
    np.testing.assert_allclose(np.cos(poses[:, 2] - expected), 1.0, atol=1e-12)
    assert np.all((poses[:, 2] > -math.pi) & (poses[:, 2] <= math.pi))
    np.testing.assert_allclose(poses[:, 0], [0.0, 0.25, 0.5, 0.75, 1.0, 1.0])
    np.testing.assert_allclose(poses[:, 1], [0.0, 0.0, 0.0, 0.0, 1.0, 2.0])


def test_groundtruth_is_nan_outside_its_span_and_exact_at_rows() -> None:
    truth = GroundTruth([1.0, 2.0], [0.5, 0.7], [0.1, 0.2], [4.0, 0.0], max_gap=math.inf)
    assert truth.heading[0] == pytest.approx(4.0 - 2 * math.pi)  # stored wrapped
    poses = truth.at([0.999, 1.0, 2.0, 2.001])
    assert np.isnan(poses[[0, 3]]).all()
    np.testing.assert_array_equal(poses[1:3, :2], [[0.5, 0.1], [0.7, 0.2]])
    assert truth.at(1.5).shape == (1, 3)
    single = GroundTruth([3.0], [1.0], [2.0], [0.5])
    np.testing.assert_array_equal(single.at([3.0, 3.5]), [[1.0, 2.0, 0.5], [np.nan] * 3])


def test_groundtruth_keeps_gaps_as_gaps() -> None:
    # Rows 0.1 s apart, then a lost track of 2 s: nothing is interpolated across the gap,
    # but its two edge rows are poses like any other.
    time = [0.0, 0.1, 0.2, 2.2, 2.3]
    truth = GroundTruth(time, [0.0, 0.1, 0.2, 2.2, 2.3], [0.0] * 5, [0.0] * 5)
    assert truth.max_gap == 0.5  # the documented default
    poses = truth.at([0.05, 0.2, 0.21, 1.2, 2.19, 2.2, 2.25])
    np.testing.assert_array_equal(np.isnan(poses[:, 0]), [False, False, True, True, True, False, False])
    np.testing.assert_allclose(poses[[0, 1, 5, 6], 0], [0.05, 0.2, 2.2, 2.25])
    assert not np.isnan(truth.with_max_gap(2.5).at([1.2])).any()
    assert not np.isnan(truth.with_max_gap(math.inf).at([1.2])).any()


@pytest.mark.parametrize("max_gap", [0.0, -1.0, math.nan, True, "1"])
def test_groundtruth_max_gap_must_be_positive(max_gap: object) -> None:
    with pytest.raises(InputError, match=r"GroundTruth\.max_gap: expected a positive number of seconds"):
        GroundTruth([0.0], [0.0], [0.0], [0.0], max_gap=max_gap)  # type: ignore[arg-type]


@given(
    st.lists(st.floats(-3.0, 3.0), min_size=2, max_size=8),
    st.floats(-math.pi, math.pi),
    st.floats(0.0, 1.0),
)
def test_groundtruth_heading_moves_the_short_way(steps: list[float], first: float, fraction: float) -> None:
    # Headings that change by less than pi between rows: the interpolated heading lies on
    # the short arc between its two neighbours, at the fraction of the way along it.
    headings = first + np.concatenate(([0.0], np.cumsum(steps[1:])))
    truth = GroundTruth(
        np.arange(len(headings), dtype=float),
        np.zeros(len(headings)),
        np.zeros(len(headings)),
        headings,
        max_gap=1.0,
    )
    row = len(headings) // 2 - 1
    heading = truth.at(row + fraction)[0, 2]
    want = headings[row] + fraction * (headings[row + 1] - headings[row])
    assert math.cos(heading - want) == pytest.approx(1.0, abs=1e-9)
    assert -math.pi < heading <= math.pi


# --- the log ----------------------------------------------------------------------------------


def test_robot_log_rejects_inconsistent_parts() -> None:
    meta = LogMeta("m")
    landmarks = (LogLandmark("a", 0.0, 0.0),)
    odometry = Odometry([0.0, 1.0], [1.0, 0.0], [0.0, 0.0])
    commands = (PositionReport(1.0, TurnAndRun(0.0, 1.0)),)
    with pytest.raises(InputError, match="expected exactly one of odometry and commands, got both"):
        RobotLog(meta, landmarks, (), odometry=odometry, commands=commands)
    with pytest.raises(InputError, match="expected exactly one of odometry and commands, got neither"):
        RobotLog(meta, landmarks, ())
    with pytest.raises(InputError, match=r"RobotLog\.landmarks\[1\]: expected a unique id, got 'a' again"):
        RobotLog(meta, landmarks * 2, (), odometry=odometry)
    with pytest.raises(InputError, match=r"RobotLog\.observations\[0\]: expected a landmark id listed"):
        RobotLog(meta, landmarks, (LogObservation(0.0, "b", 0.0),), odometry=odometry)
    unsorted = (LogObservation(1.0, "a", 0.0), LogObservation(0.5, "a", 0.0))
    with pytest.raises(InputError, match=r"RobotLog\.observations\[1\]: expected times in order"):
        RobotLog(meta, landmarks, unsorted, odometry=odometry)
    with pytest.raises(InputError, match=r"RobotLog\.commands\[1\]: expected strictly increasing times"):
        RobotLog(meta, landmarks, (), commands=commands * 2)
    with pytest.raises(InputError, match=r"RobotLog\.landmarks\[0\]: expected a LogLandmark, got str"):
        RobotLog(meta, ("a",), (), odometry=odometry)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"RobotLog\.meta: expected a LogMeta, got str"):
        RobotLog("m", landmarks, (), odometry=odometry)  # type: ignore[arg-type]


def test_landmark_lookup() -> None:
    log = small_log()
    assert log.landmark("#7").symbol == "sign, red"
    with pytest.raises(
        InputError, match=r"landmark_id: expected one of the log's landmark ids \(a, #7, b\"q\), got 'z'"
    ):
        log.landmark("z")


def test_commands_are_delayed_scaled_and_windowed() -> None:
    log = small_log(commands=True)  # delay 0.125, run_scale 1.1, turn_scale 1.05
    reports = log.position_reports([0.3])  # cut times do not apply to commands
    assert [r.time for r in reports] == [0.325, 0.525]
    assert reports[0].command == TurnAndRun(0.1 * 1.05, 0.2 * 1.1)
    assert reports[1].command == TurnAndRun(-0.3 * 1.05, 0.0)
    assert [r.time for r in log.position_reports(start=0.325)] == [0.525]
    assert [r.time for r in log.position_reports(end=0.5)] == [0.325]
    with pytest.raises(InputError, match=r"end: expected a time >= start \(1\.0\), got 0\.0"):
        log.position_reports(start=1.0, end=0.0)


def test_odometry_reports_use_the_meta() -> None:
    log = small_log()
    assert log.odometry is not None
    meta = log.meta
    expected = odometry_to_commands(
        log.odometry.time,
        log.odometry.v,
        log.odometry.omega,
        [0.3],
        max_interval=0.1,
        delay_s=meta.delay_s,
        run_scale=meta.run_scale,
        turn_scale=meta.turn_scale,
    )
    assert log.position_reports([0.3], max_interval=0.1) == expected
    assert expected[0].time > meta.delay_s  # the delay shifted the first motion time
    assert log.motion_span == (0.0, 0.35)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"max_interval": None}, r"max_interval: expected a positive number of seconds \(or inf\), got None"),
        (
            {"max_interval": -1.0},
            r"max_interval: expected a positive number of seconds \(or inf\), got -1\.0",
        ),
        (
            {"max_interval": math.nan},
            r"max_interval: expected a positive number of seconds \(or inf\), got nan",
        ),
        ({"cut_times": "abc"}, "cut_times: expected numbers, got 'abc'"),
        ({"cut_times": [math.nan]}, "cut_times: expected finite numbers"),
        ({"reverse": "flip"}, "reverse: expected a ReverseMotion, got 'flip'"),
    ],
)
def test_a_log_of_commands_checks_the_odometry_arguments_too(kwargs: dict[str, Any], match: str) -> None:
    # ignored before when the log has recorded commands (every value gave its 50 reports)
    log = synthetic_log(np.random.default_rng(1), duration=5.0)
    assert log.odometry is None
    with pytest.raises(InputError, match=match):
        log.position_reports(**kwargs)
    with pytest.raises(InputError, match=match):
        log.position_report_arrays(**kwargs)
