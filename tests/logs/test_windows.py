"""Image windows on replayed logs: ours, an EKF's 3-sigma box and the disk model, judged per observation."""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from aura_ums.camera import CalibrationBounds, Camera, CameraMount, load_camera
from aura_ums.errors import InputError
from aura_ums.logs import (
    Calibration,
    LogLandmark,
    LogMeta,
    LogObservation,
    ReplayOptions,
    RobotLog,
    SensorBounds,
    WindowReport,
    ekf_noise,
    read_mrclam,
    replay_log,
    replay_windows,
    synthetic_log,
)
from aura_ums.manager import PositionReport
from aura_ums.uncertainty import LandmarkClass, Pose, SpatialUncertaintyMap, TerrainTable, TurnAndRun
from tests.conftest import SHARED_DATA

CAMERA = load_camera(Path(__file__).resolve().parents[2] / "examples" / "virtual_camera_60deg.toml")
FLOOR = TerrainTable({"floor": TerrainTable.default()["tile"]})
CLASSES = [LandmarkClass.VERTICAL_LINE, LandmarkClass.POINT]


def strict_json(text: str) -> Any:
    def refuse(constant: str) -> None:
        raise ValueError(f"not JSON: {constant}")

    return json.loads(text, parse_constant=refuse)


@pytest.fixture(scope="module")
def clean_log() -> RobotLog:
    return synthetic_log(np.random.default_rng(11), duration=60.0)


def true_pixels(log: RobotLog, report: WindowReport, landmark_class: LandmarkClass) -> np.ndarray:
    """Where each of our rows' landmarks truly appeared (u, v), from the log's ground truth."""
    assert log.groundtruth is not None
    heights = {lm.id: lm.heights(log.meta) for lm in log.landmarks}
    spots = {lm.id: (lm.x, lm.y) for lm in log.landmarks}
    out = []
    for row in report.rows:
        if row.method != "aura-ums":
            continue
        x, y, heading = log.groundtruth.at([row.time])[0]
        bottom, top = heights[row.landmark_id]
        if landmark_class is LandmarkClass.POINT:
            z = (bottom + top) / 2.0
        else:
            z = min(max(CAMERA.mount.height, bottom), top)
        point = (*spots[row.landmark_id], z)
        out.append(CAMERA.project(Pose(float(x), float(y), float(heading)), [point])[0])
    return np.array(out)


@pytest.mark.parametrize("landmark_class", CLASSES)
def test_every_observation_lies_inside_our_window_when_the_noise_is_within_its_bounds(
    clean_log: RobotLog, landmark_class: LandmarkClass
) -> None:
    options = ReplayOptions(landmark_class=landmark_class)
    result, report = replay_windows(clean_log, FLOOR, CAMERA, options)
    assert result.containment_rate == 1.0
    figures = strict_json(report.metrics().to_json())
    assert figures["window_observations"] > 100
    # The Expecter's guarantee: the true projection is inside, with no margin at all.
    assert figures["window_truth_containment"] == 1.0
    # A measured pixel lies within the sensor's error of the true one: a margin of that many
    # pixels (measured from the truth, both bounds being the simulator's) puts every one inside.
    ours = [row for row in report.rows if row.method == "aura-ums"]
    truth = true_pixels(clean_log, report, landmark_class)
    measured = np.array([(row.measured_u, row.measured_v) for row in ours])
    judged = np.array([row.in_view for row in ours])
    columns = 2 if landmark_class is LandmarkClass.POINT else 1
    error = np.abs(measured - truth)[judged][:, :columns]
    assert np.all(np.isfinite(error))
    margin = float(error.max()) + 1e-6
    assert margin < 30.0
    _, widened = replay_windows(clean_log, FLOOR, CAMERA, options, margin=margin)
    widened_figures = strict_json(widened.metrics().to_json())
    assert widened_figures["window_containment"] == 1.0
    assert widened_figures["window_margin_px"] == margin
    # The disk holds the polygon: its windows are never narrower than ours (outer arcs aside).
    by_method = {method: report.judged(method) for method in WindowReport.methods}
    for mine, disk in zip(by_method["aura-ums"], by_method["disk model"], strict=True):
        assert (mine.time, mine.landmark_id) == (disk.time, disk.landmark_id)
        assert mine.width_frac <= disk.width_frac + 1.0 / CAMERA.intrinsics.width


@pytest.mark.parametrize("landmark_class", CLASSES)
def test_the_replay_is_the_same_with_windows(clean_log: RobotLog, landmark_class: LandmarkClass) -> None:
    options = ReplayOptions(landmark_class=landmark_class)
    plain = replay_log(clean_log, FLOOR, options)
    with_windows, report = replay_windows(clean_log, FLOOR, CAMERA, options)
    assert len(plain.steps) == len(with_windows.steps)
    for a, b in zip(plain.steps, with_windows.steps, strict=True):
        assert a.map.polygon.vertices.tobytes() == b.map.polygon.vertices.tobytes()
        assert a.map.wedge == b.map.wedge
        assert (a.inside, a.accepted, a.rejected, a.state) == (b.inside, b.accepted, b.rejected, b.state)
    observed = sum(len([o for o in clean_log.observations if o.time == s.time]) for s in plain.steps)
    assert len(report.rows) == len(WindowReport.methods) * observed


def test_windows_under_calibration_bounds_are_wider_and_the_replay_the_same(clean_log: RobotLog) -> None:
    """Every method's window holds for every camera within the bounds; the maps do not change."""
    options = ReplayOptions(landmark_class=LandmarkClass.POINT)
    exact_result, exact = replay_windows(clean_log, FLOOR, CAMERA, options)
    bounds = CalibrationBounds(cx=3.0, cy=3.0, pan=math.radians(0.5), tilt=math.radians(0.5))
    loose_result, loose = replay_windows(clean_log, FLOOR, CAMERA, options, calibration_bounds=bounds)
    assert loose_result.trace.area_m2.tobytes() == exact_result.trace.area_m2.tobytes()
    for method in WindowReport.methods:
        pairs = list(zip(exact.judged(method), loose.judged(method), strict=True))
        assert pairs
        assert all(wide.width_frac >= narrow.width_frac for narrow, wide in pairs)
        assert any(wide.width_frac > narrow.width_frac for narrow, wide in pairs)


def test_csv_rows_match_the_metrics(clean_log: RobotLog) -> None:
    _, report = replay_windows(clean_log, FLOOR, CAMERA, ReplayOptions(landmark_class=LandmarkClass.POINT))
    rows = list(csv.DictReader(io.StringIO(report.to_csv())))
    assert tuple(rows[0]) == WindowReport.csv_columns
    assert len(rows) == len(report.rows)
    metrics = strict_json(report.metrics().to_json())
    focus = strict_json(report.figures("aura-ums focus").to_json())
    per_method = {
        "aura-ums": metrics,
        "aura-ums focus": focus,
        **{row["method"]: row for row in metrics["window_baselines"]},
    }
    assert list(per_method) == list(WindowReport.methods)
    assert (
        metrics["focus_window_containment"],
        metrics["focus_window_truth_containment"],
        metrics["median_focus_window_width_frac"],
    ) == (focus["window_containment"], focus["window_truth_containment"], focus["median_window_width_frac"])
    for method, figures in per_method.items():
        judged = [row for row in rows if row["method"] == method and row["in_window"] != ""]
        assert all(row["in_view"] == "1" for row in judged)
        assert figures["window_containment"] == np.mean([row["in_window"] == "1" for row in judged])
        truths = [row["truth_in_window"] == "1" for row in judged if row["truth_in_window"] != ""]
        assert figures["window_truth_containment"] == np.mean(truths)
        widths = [float(row["window_width_frac"]) for row in judged]
        areas = [float(row["window_area_frac"]) for row in judged]
        assert figures["median_window_width_frac"] == np.median(widths)
        assert figures["median_window_area_frac"] == np.median(areas)
        for row in judged:
            if row["u_min_px"] == "":
                assert row["in_window"] == "0"
                continue
            # Judged by whole pixels: the window meets the unit square the measured point is in.
            u, v = float(row["measured_u_px"]), float(row["measured_v_px"])
            column, line = math.floor(u + 0.5), math.floor(v + 0.5)
            inside = float(row["u_min_px"]) <= column + 0.5 and column - 0.5 <= float(row["u_max_px"])
            inside = inside and float(row["v_min_px"]) <= line + 0.5 and line - 0.5 <= float(row["v_max_px"])
            assert row["in_window"] == str(int(inside))
            width = (float(row["u_max_px"]) - float(row["u_min_px"])) / CAMERA.intrinsics.width
            assert float(row["window_width_frac"]) == pytest.approx(width, abs=1e-12)
    assert metrics["window_observations"] == len(
        [row for row in rows if row["method"] == "aura-ums" and row["in_view"] == "1"]
    )


def misread(log: RobotLog, every: int) -> tuple[RobotLog, int]:
    """The log with every ``every``-th observation's landmark id swapped for the next landmark's.

    A misread barcode: the bearing and range are right, for the wrong landmark. Returns the
    log and how many were swapped.
    """
    ids = [lm.id for lm in log.landmarks]
    rows = list(log.observations)
    for k in range(every - 1, len(rows), every):
        wrong = ids[(ids.index(rows[k].landmark_id) + 1) % len(ids)]
        rows[k] = dataclasses.replace(rows[k], landmark_id=wrong)
    return dataclasses.replace(log, observations=tuple(rows)), len(range(every - 1, len(rows), every))


def test_without_the_relaxed_intersection_the_focus_window_is_ours(clean_log: RobotLog) -> None:
    _, report = replay_windows(clean_log, FLOOR, CAMERA, ReplayOptions(landmark_class=LandmarkClass.POINT))
    ours, focus = report.judged("aura-ums"), report.judged("aura-ums focus")
    assert len(ours) > 100
    for mine, first in zip(ours, focus, strict=True):
        assert (first.time, first.landmark_id, first.window, first.inside) == (
            mine.time,
            mine.landmark_id,
            mine.window,
            mine.inside,
        )
    metrics = report.metrics()
    assert metrics.number("focus_window_containment") == metrics.number("window_containment")
    for key in ("median_focus_window_width_frac", "median_searched_width_frac"):
        assert metrics.number(key) == metrics.number("median_window_width_frac")


def test_the_focus_window_lies_in_ours_and_a_focus_first_search_scans_less(clean_log: RobotLog) -> None:
    # Misread landmarks, one sighting in 11: at most one in any 5, as relaxed_q = 1,
    # relaxed_window = 5 assume. The map keeps the truth; its windows are the guaranteed ones.
    log, swapped = misread(clean_log, 11)
    assert swapped > 10
    settings = dataclasses.replace(ReplayOptions().settings, relaxed_q=1, relaxed_window=5)
    options = ReplayOptions(landmark_class=LandmarkClass.POINT, settings=settings)
    result, report = replay_windows(log, FLOOR, CAMERA, options)
    assert result.containment_rate == 1.0
    ours, focus = report.judged("aura-ums"), report.judged("aura-ums focus")
    assert len(ours) == len(focus) > 100
    searched = []
    for mine, first in zip(ours, focus, strict=True):
        assert (first.time, first.landmark_id) == (mine.time, mine.landmark_id)
        if first.window is not None:
            assert mine.window is not None
            tolerance = 1e-6  # pixels
            assert mine.window.u_min - tolerance <= first.window.u_min
            assert first.window.u_max <= mine.window.u_max + tolerance
            assert mine.window.v_min - tolerance <= first.window.v_min
            assert first.window.v_max <= mine.window.v_max + tolerance
        searched.append(first.width_frac if first.inside else mine.width_frac)
    metrics = report.metrics()
    focus_width, searched_width, width = (
        metrics.number(key)
        for key in (
            "median_focus_window_width_frac",
            "median_searched_width_frac",
            "median_window_width_frac",
        )
    )
    assert searched_width == np.median(searched)
    assert focus_width <= searched_width <= width
    assert focus_width < width
    assert metrics.number("focus_window_containment") <= metrics.number("window_containment")


def tiny_log(landmarks: tuple[LogLandmark, ...], observations: tuple[LogObservation, ...]) -> RobotLog:
    """A robot standing at the origin facing +x, one position report, known start."""
    meta = LogMeta(
        "tiny",
        terrain="floor",
        bearing_error=0.01,
        range_error=0.05,
        start=Pose(0.0, 0.0, 0.0),
        start_radius=0.05,
        start_heading_halfwidth=0.01,
    )
    reports = (PositionReport(0.5, TurnAndRun(0.0, 0.0)), PositionReport(1.0, TurnAndRun(0.0, 0.0)))
    return RobotLog(meta, landmarks, observations, commands=reports)


@pytest.mark.parametrize(
    ("landmark_class", "forward", "left", "spot", "bearing", "distance"),
    [
        (LandmarkClass.POINT, 1.0, 0.0, (5.0, 0.0), 0.0, 4.0),
        (LandmarkClass.VERTICAL_LINE, 0.0, 1.0, (5.0, 1.0), 0.0, None),
        (LandmarkClass.POINT, 0.5, -0.5, (4.5, 0.5), math.atan2(1.0, 4.0), math.hypot(1.0, 4.0)),
    ],
)
def test_an_exact_sighting_from_an_offset_sensor_is_measured_where_the_landmark_appears(
    landmark_class: LandmarkClass,
    forward: float,
    left: float,
    spot: tuple[float, float],
    bearing: float,
    distance: float | None,
) -> None:
    # The sensor sits at (forward, left) on the robot, and so does the camera: the sighting,
    # exact from there, is where the landmark truly appears in the image.
    meta = dataclasses.replace(tiny_log((), ()).meta, sensor_forward=forward, sensor_left=left)
    camera = dataclasses.replace(CAMERA, mount=dataclasses.replace(CAMERA.mount, forward=forward, left=left))
    landmark = LogLandmark("pole", *spot, z_bottom=0.0, z_top=2.0)
    observed = LogObservation(1.0, "pole", bearing, range=distance)
    log = dataclasses.replace(tiny_log((landmark,), (observed,)), meta=meta)
    _, report = replay_windows(log, FLOOR, camera, ReplayOptions(landmark_class=landmark_class))
    (ours,) = report.judged("aura-ums")
    z = 1.0 if landmark_class is LandmarkClass.POINT else camera.mount.height
    u, v = camera.project(Pose(0.0, 0.0, 0.0), [(*spot, z)])[0]
    assert ours.measured_u == pytest.approx(u, abs=1e-6)
    if landmark_class is LandmarkClass.POINT:
        assert ours.measured_v == pytest.approx(v, abs=1e-6)
    assert ours.inside is True


def test_a_landmark_behind_the_camera_has_no_window_and_is_not_judged() -> None:
    log = tiny_log(
        (LogLandmark("ahead", 5.0, 0.0), LogLandmark("behind", -5.0, 0.0)),
        (LogObservation(1.0, "ahead", 0.0, range=5.0), LogObservation(1.0, "behind", math.pi, range=5.0)),
    )
    _, report = replay_windows(log, FLOOR, CAMERA, ReplayOptions(landmark_class=LandmarkClass.POINT))
    behind = [row for row in report.rows if row.landmark_id == "behind"]
    assert [row.method for row in behind] == list(WindowReport.methods)
    for row in behind:
        assert row.window is None
        assert math.isnan(row.measured_u)
        assert (row.in_view, row.inside, row.truth_inside) == (False, None, None)
        assert (row.width_frac, row.area_frac) == (0.0, 0.0)
    metrics = strict_json(report.metrics().to_json())
    assert metrics["window_observations"] == 1
    assert metrics["window_containment"] == 1.0
    assert metrics["window_truth_containment"] is None  # the log has no ground truth
    line = next(line for line in report.to_csv().splitlines() if line.split(",")[1] == "behind")
    assert line.split(",")[4:13] == ["", "", "", "", "", "", "0", "", ""]


def test_a_pole_wholly_above_a_tilted_cameras_rows_is_not_judged(clean_log: RobotLog) -> None:
    # Its column is in the image, so it was judged in view, and the Expecter's rightful lack
    # of a window counted a miss: window_containment 0.097 at a tilt of 0.5 rad down, every
    # miss a pole imaged nowhere (helper-62). Level, the same log is judged in full.
    options = ReplayOptions(landmark_class=LandmarkClass.VERTICAL_LINE)
    tilted = Camera(CAMERA.intrinsics, CameraMount(0.3, tilt=0.5))
    _, report = replay_windows(clean_log, FLOOR, tilted, options)
    ours = [row for row in report.rows if row.method == "aura-ums"]
    assert ours
    assert all(row.inside for row in ours if row.in_view)
    assert report.metrics()["window_containment"] in (None, 1.0)
    _, level = replay_windows(clean_log, FLOOR, CAMERA, options)
    assert level.metrics()["window_containment"] == 1.0


def test_a_landmark_inside_the_polygon_may_be_anywhere_in_the_image() -> None:
    log = tiny_log(
        (LogLandmark("here", 0.02, 0.0, z_bottom=0.0, z_top=2.0),),
        (LogObservation(1.0, "here", 0.0, range=0.02),),
    )
    _, report = replay_windows(log, FLOOR, CAMERA, ReplayOptions(landmark_class=LandmarkClass.VERTICAL_LINE))
    ours = report.judged("aura-ums")
    assert len(ours) == 1
    assert ours[0].width_frac == 1.0
    assert ours[0].inside is True
    assert report.figures("aura-ums").number("median_window_width_frac") == 1.0


def test_no_observations_give_null_figures_in_strict_json() -> None:
    log = dataclasses.replace(synthetic_log(np.random.default_rng(2), duration=5.0), observations=())
    result, report = replay_windows(log, FLOOR, CAMERA)
    assert result.steps == ()
    assert report.rows == ()
    parsed = strict_json(report.metrics().to_json())
    assert parsed["window_observations"] == 0
    for key in (
        "window_containment",
        "window_truth_containment",
        "median_window_width_frac",
        "median_window_area_frac",
    ):
        assert parsed[key] is None
        assert all(row[key] is None for row in parsed["window_baselines"])
    assert report.to_csv() == ",".join(WindowReport.csv_columns) + "\n"


def test_bad_arguments_are_named(clean_log: RobotLog) -> None:
    with pytest.raises(InputError, match="camera: expected a Camera, got str"):
        replay_windows(clean_log, FLOOR, "camera.toml")  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"margin: expected a non-negative number, got -2\.0"):
        replay_windows(clean_log, FLOOR, CAMERA, margin=-2.0)
    with pytest.raises(InputError, match=r"sigmas: expected a positive number, got 0\.0"):
        replay_windows(clean_log, FLOOR, CAMERA, sigmas=0.0)
    with pytest.raises(InputError, match="bearing_sd, range_sd_fraction: expected positive numbers"):
        replay_windows(clean_log, FLOOR, CAMERA, bearing_sd=0.0)
    with pytest.raises(
        InputError, match=r"^table: expected the terrain 'floor' of the log \(its meta\.toml\), got 'tile', "
    ):
        replay_windows(clean_log, TerrainTable.default(), CAMERA)
    with pytest.raises(InputError, match="method: expected one of"):
        WindowReport(CAMERA, 0.0, ()).judged("EKF")
    with pytest.raises(InputError, match="bounds: expected SensorBounds, got float"):
        ekf_noise(0.05)  # type: ignore[arg-type]


def test_the_ekf_noise_has_the_bounds_as_its_99_percent_interval() -> None:
    bearing_sd, fraction_sd = ekf_noise(SensorBounds(0.1, 0.0, 0.04, 0.06))
    assert bearing_sd * 2.5758293035489 == pytest.approx(0.1)
    assert fraction_sd * 2.5758293035489 == pytest.approx(0.05)


MRCLAM6 = SHARED_DATA / "mrclam6"


@pytest.mark.skipif(not MRCLAM6.is_dir(), reason=f"MRCLAM Dataset 6 not found at {MRCLAM6}")
def test_real_log_windows_on_mrclam6(mrclam6_robot1_calibration: Calibration) -> None:
    calibration = mrclam6_robot1_calibration
    log = read_mrclam(MRCLAM6, 2)
    # The first 600 observations: the test judges the machinery, the benchmark the whole runs.
    log = dataclasses.replace(log, observations=log.observations[:600])
    options = ReplayOptions(
        landmark_class=LandmarkClass.POINT,
        working=calibration.working,
        envelope=calibration.envelope,
        motion=calibration.motion,
    )
    result, report = replay_windows(log, calibration.terrain_table(), CAMERA, options)
    metrics = strict_json(report.metrics().to_json())
    # Most of the robot's camera's bearings lie within the virtual camera's 60 degrees.
    assert metrics["window_observations"] > 0.9 * len(report.rows) / len(WindowReport.methods)
    for key in ("window_containment", "median_window_width_frac", "median_window_area_frac"):
        assert 0.0 <= metrics[key] <= 1.0
    # Wherever the grown map holds the truth, its window holds the true projection: the
    # Expecter's guarantee, on real data.
    truth = log.groundtruth
    assert truth is not None
    holds: dict[float, bool] = {}

    def record(
        time: float,
        grown: SpatialUncertaintyMap,
        rows: Sequence[LogObservation],
        focus: SpatialUncertaintyMap,
    ) -> None:
        x, y, heading = truth.at([time])[0]
        holds[time] = not math.isnan(x) and bool(grown.contains(float(x), float(y), float(heading)))

    replay_log(log, calibration.terrain_table(), options, before_frame=record)
    judged = [row for row in report.judged("aura-ums") if row.truth_inside is not None and holds[row.time]]
    assert len(judged) > 100
    assert all(row.truth_inside for row in judged)
    assert result.containment_rate > 0.5
    disk = next(row for row in metrics["window_baselines"] if row["method"] == "disk model")
    assert metrics["median_window_width_frac"] <= disk["median_window_width_frac"]
