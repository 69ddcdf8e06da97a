"""The find-landmark schema's life cycle on synthetic image sequences."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.typing import NDArray

from aura_ums.expecter import Expecter, PerceptualStrategy
from aura_ums.perception import FastLineFinder
from aura_ums.schemas import FindLandmarkSchema, Frame, SchemaManager, SchemaReport, SchemaState, SchemaStatus
from aura_ums.uncertainty import (
    GroundLineLandmark,
    GroundLineObservation,
    PointLandmark,
    Pose,
    SpatialUncertaintyMap,
    VerticalLineLandmark,
)
from aura_ums.world import LandmarkRecord
from tests.schemas.schema_scenes import (
    CAMERA,
    assert_sound,
    corner_image,
    ground_edge_image,
    map_around,
    pole_column,
    pole_image,
    pole_record,
)

EXPECTER = Expecter(CAMERA)
TRUTH = Pose(0.0, 0.0, 0.0)
POLE = VerticalLineLandmark("pole", 10.0, 1.0, 0.0, 4.0, symbol="lamppost", position_uncertainty=0.1)


def run(
    schema: FindLandmarkSchema,
    images: list[NDArray[np.uint8]],
    maps: list[SpatialUncertaintyMap],
    truths: list[Pose],
) -> list[SchemaReport]:
    """Step a schema through a sequence; check every observation it posts against the truth."""
    reports = []
    status: SchemaStatus | None = None
    for k, (image, snapshot, truth) in enumerate(zip(images, maps, truths, strict=True)):
        report = schema.step(Frame(0.1 * k, image, snapshot), status)
        status = report.status
        if report.observation is not None:
            assert report.observation.time == pytest.approx(0.1 * k)
            assert report.observation.landmark_id == schema.landmark_id
            assert_sound(report.observation, schema.record.landmark, snapshot, truth)
        reports.append(report)
    return reports


# (a) discovery needs N consecutive hits --------------------------------------------------


@pytest.mark.parametrize("confirm", [1, 3, 5])
def test_discovery_is_posted_on_the_nth_consecutive_hit(rng: np.random.Generator, confirm: int) -> None:
    schema = FindLandmarkSchema(pole_record(POLE, confirm=confirm), EXPECTER)
    snapshot = map_around(TRUTH)
    frames = confirm + 2
    reports = run(
        schema, [pole_image(rng, TRUTH, [POLE]) for _ in range(frames)], [snapshot] * frames, [TRUTH] * frames
    )
    assert all(r.hit for r in reports)
    assert [r.status.hits for r in reports] == list(range(1, frames + 1))
    for r in reports[: confirm - 1]:
        assert r.state is SchemaState.DISCOVERING
        assert r.observation is None
    confirming = reports[confirm - 1]
    assert confirming.state is SchemaState.TRACKING
    assert confirming.observation is not None
    assert all(r.observation is not None for r in reports[confirm - 1 :])
    # confirming hits follow the first one (as tracking does), inside the Expecter's window
    guaranteed = EXPECTER.window(snapshot, POLE, margin=PerceptualStrategy.LINE_FINDER)
    assert guaranteed is not None
    assert confirming.window is not None
    if confirm == 1:
        assert confirming.window == guaranteed
    else:
        assert guaranteed.u_min <= confirming.window.u_min <= confirming.window.u_max <= guaranteed.u_max
    assert confirming.window is not None
    assert confirming.window.u_min <= pole_column(TRUTH, POLE) <= confirming.window.u_max


def test_a_focus_window_is_searched_first_and_the_guaranteed_one_where_it_misses(
    rng: np.random.Generator,
) -> None:
    schema = FindLandmarkSchema(pole_record(POLE, confirm=1), EXPECTER)
    snapshot = map_around(TRUTH, radius=0.4, halfwidth=math.radians(10.0))
    guaranteed = EXPECTER.window(snapshot, POLE, margin=PerceptualStrategy.LINE_FINDER)
    assert guaranteed is not None
    image = pole_image(rng, TRUTH, [POLE])
    column = pole_column(TRUTH, POLE)
    # A focus map about the truth: the pole is in its narrower window, found there.
    near = map_around(TRUTH, offset=(0.02, 0.0, 0.002), radius=0.1, halfwidth=math.radians(1.0))
    found = schema.step(Frame(0.0, image, snapshot, focus=near))
    assert found.hit
    assert found.focus_window is not None
    assert found.window == found.focus_window
    assert guaranteed.u_min <= found.window.u_min <= column <= found.window.u_max <= guaranteed.u_max
    assert found.window.width < 0.5 * guaranteed.width
    # A focus map turned 6 degrees away (a wrong sighting trusted): nothing there, so the
    # guaranteed window is searched and the pole is found all the same.
    away = SpatialUncertaintyMap.from_pose(
        Pose(TRUTH.x, TRUTH.y, TRUTH.heading + math.radians(6.0)), 0.05, math.radians(1.0)
    )
    missed = schema.step(Frame(0.1, image, snapshot, focus=away))
    assert missed.focus_window is not None
    assert not missed.focus_window.u_min <= column <= missed.focus_window.u_max
    assert missed.hit
    assert missed.window == guaranteed
    # While lost (windows widened) no focus window is searched.
    lost = schema.step(Frame(0.2, image, snapshot, focus=near, window_scale=2.0))
    assert lost.focus_window is None
    assert lost.hit
    # Without a focus map, only the guaranteed window.
    plain = schema.step(Frame(0.3, image, snapshot))
    assert plain.focus_window is None
    assert plain.window == guaranteed


def test_discovery_of_a_class_ii_corner(rng: np.random.Generator) -> None:
    corner = PointLandmark("corner", 12.0, 2.0, 3.0, symbol="building corner", position_uncertainty=0.1)
    record = LandmarkRecord(
        corner, PerceptualStrategy.INTEREST_OPERATOR, {"window": 5.0, "min_interest": 150.0}, 30.0, 1000.0, 3
    )
    schema = FindLandmarkSchema(record, EXPECTER, pixel_error=1.0)
    snapshot = map_around(TRUTH)
    reports = run(schema, [corner_image(rng, TRUTH, corner) for _ in range(4)], [snapshot] * 4, [TRUTH] * 4)
    assert [r.state for r in reports] == [SchemaState.DISCOVERING] * 2 + [SchemaState.TRACKING] * 2
    assert [r.observation is not None for r in reports] == [False, False, True, True]
    truth_pixel = CAMERA.project(TRUTH, [(corner.x, corner.y, corner.z)])[0]
    detection = reports[2].detection
    assert detection is not None
    assert math.dist(detection.point, truth_pixel) <= 3.0


def test_a_corner_with_a_second_strong_corner_in_its_window_is_not_identified(
    rng: np.random.Generator,
) -> None:
    corner = PointLandmark("corner", 12.0, 2.0, 3.0, symbol="building corner", position_uncertainty=0.1)
    record = LandmarkRecord(
        corner, PerceptualStrategy.INTEREST_OPERATOR, {"window": 5.0, "min_interest": 150.0}, 30.0, 1000.0, 1
    )
    schema = FindLandmarkSchema(record, EXPECTER, pixel_error=1.0)
    snapshot = map_around(TRUTH)
    u_c, v_c = CAMERA.project(TRUTH, [(corner.x, corner.y, corner.z)])[0]
    images = []
    for _ in range(3):
        image = corner_image(rng, TRUTH, corner).astype(np.float64)
        # A dark notch in the bright face just below the corner's row: its corners are as
        # strong, and taking one for the landmark would prune the true pose away.
        image[int(v_c) + 1 : int(v_c) + 7, int(u_c) - 14 : int(u_c) - 9] = 90.0
        images.append(image.astype(np.uint8))
    reports = run(schema, images, [snapshot] * 3, [TRUTH] * 3)
    assert all(r.observation is None for r in reports)
    assert all(r.state is SchemaState.DISCOVERING for r in reports)


def test_discovery_of_a_class_iii_path_edge(rng: np.random.Generator) -> None:
    edge = GroundLineLandmark(
        "edge", (-5.0, -1.0), (30.0, -1.0), symbol="sidewalk edge", position_uncertainty=0.05
    )
    record = LandmarkRecord(
        edge, PerceptualStrategy.LINE_FINDER, {"tolerance": 0.35, "min_length": 60.0}, 4.0, 1000.0, 3
    )
    schema = FindLandmarkSchema(record, EXPECTER, pixel_error=1.0)
    assert isinstance(schema.detector, FastLineFinder)
    assert schema.detector.orientation is None  # tuned frame by frame to the predicted direction
    snapshot = map_around(TRUTH)
    images = [ground_edge_image(rng, TRUTH, edge, grass_side=-1.0) for _ in range(4)]
    reports = run(schema, images, [snapshot] * 4, [TRUTH] * 4)
    assert [r.observation is not None for r in reports] == [False, False, True, True]
    observation = reports[2].observation
    assert isinstance(observation, GroundLineObservation)
    assert observation.offset == pytest.approx(1.0, abs=0.05)  # the robot is 1 m left of the edge


def test_discovery_with_the_region_segmenter(rng: np.random.Generator) -> None:
    record = LandmarkRecord(POLE, PerceptualStrategy.REGION_SEGMENTER, {"min_area": 40.0}, 25.0, 50.0, 2)
    schema = FindLandmarkSchema(record, EXPECTER, pixel_error=1.0)
    snapshot = map_around(TRUTH)
    reports = run(schema, [pole_image(rng, TRUTH, [POLE]) for _ in range(3)], [snapshot] * 3, [TRUTH] * 3)
    assert [r.state for r in reports] == [SchemaState.DISCOVERING, SchemaState.TRACKING, SchemaState.TRACKING]
    assert reports[1].observation is not None
    assert reports[1].value is not None
    assert reports[1].value > 100.0


# (b) tracking follows a moving landmark -------------------------------------------------


def test_tracking_window_follows_the_landmark_as_the_robot_turns(rng: np.random.Generator) -> None:
    schema = FindLandmarkSchema(pole_record(POLE, confirm=2), EXPECTER)
    # the robot turns left in place, 0.03 rad per frame: the pole slides ~15 px per frame to the right
    truths = [Pose(0.0, 0.0, 0.03 * k) for k in range(10)]
    maps = [map_around(t, offset=(0.1, -0.05, 0.005)) for t in truths]
    images = [pole_image(rng, t, [POLE]) for t in truths]
    reports = run(schema, images, maps, truths)
    columns = [pole_column(t, POLE) for t in truths]
    assert columns[-1] - columns[0] > 120.0  # it did move across the image
    assert all(r.hit for r in reports)
    tracking = reports[2:]  # confirmed on frame 1; from frame 2 on, the window follows the detection
    assert all(r.state is SchemaState.TRACKING and r.observation is not None for r in tracking)
    for report, column, snapshot in zip(tracking, columns[2:], maps[2:], strict=True):
        window = report.window
        guaranteed = EXPECTER.window(snapshot, POLE, margin=PerceptualStrategy.LINE_FINDER)
        assert window is not None
        assert guaranteed is not None
        assert window.u_min <= column <= window.u_max
        assert abs(0.5 * (window.u_min + window.u_max) - column) < 6.0  # centred by the motion prediction
        assert window.width < 0.5 * guaranteed.width  # smaller than the Expecter's window
        assert guaranteed.u_min <= window.u_min
        assert window.u_max <= guaranteed.u_max


def test_tracking_follows_the_landmark_as_the_robot_drives_past(rng: np.random.Generator) -> None:
    schema = FindLandmarkSchema(pole_record(POLE, confirm=2), EXPECTER, tracking_margin=12.0)
    truths = [Pose(0.6 * k, 0.0, 0.0) for k in range(10)]
    maps = [map_around(t) for t in truths]
    reports = run(schema, [pole_image(rng, t, [POLE]) for t in truths], maps, truths)
    assert all(r.observation is not None for r in reports[1:])
    for report, truth in zip(reports[2:], truths[2:], strict=True):
        assert report.window is not None
        assert report.window.u_min <= pole_column(truth, POLE) <= report.window.u_max


# (c) a false single-frame match is not posted ----------------------------------------


def test_a_bar_in_one_frame_only_is_never_posted(rng: np.random.Generator) -> None:
    schema = FindLandmarkSchema(pole_record(POLE, confirm=3), EXPECTER)
    snapshot = map_around(TRUTH)
    images = [pole_image(rng, TRUTH, [POLE] if k == 2 else []) for k in range(7)]
    reports = run(schema, images, [snapshot] * 7, [TRUTH] * 7)
    assert [r.hit for r in reports] == [False, False, True, False, False, False, False]
    assert [r.status.hits for r in reports] == [0, 0, 1, 0, 0, 0, 0]
    assert all(r.state is SchemaState.DISCOVERING for r in reports)
    assert all(r.observation is None for r in reports)


def test_a_miss_resets_the_count(rng: np.random.Generator) -> None:
    schema = FindLandmarkSchema(pole_record(POLE, confirm=3), EXPECTER)
    manager = SchemaManager([schema])
    snapshot = map_around(TRUTH)
    visible = [True, True, False, True, True, True]
    posted = []
    for k, seen in enumerate(visible):
        step = manager.step(Frame(0.1 * k, pole_image(rng, TRUTH, [POLE] if seen else []), snapshot))
        posted.append(len(step.posted))
        for observation in step.posted:
            assert_sound(observation, POLE, snapshot, TRUTH)
    assert posted == [0, 0, 0, 0, 0, 1]  # two hits, a miss, then three hits: posted on the third
    assert len(manager.buffer) == 1


# (d) out of range: hibernating, and the strategy never runs ---------------------------


def test_a_landmark_out_of_range_hibernates_and_its_strategy_never_runs(
    rng: np.random.Generator, monkeypatch: pytest.MonkeyPatch
) -> None:
    calls: list[object] = []
    original = FastLineFinder.find_detailed

    def spy(self: FastLineFinder, image: object, window: object = None) -> object:
        calls.append(window)
        return original(self, image, window)  # type: ignore[arg-type]

    monkeypatch.setattr(FastLineFinder, "find_detailed", spy)
    far = VerticalLineLandmark("far_pole", 60.0, 0.0, 0.0, 6.0)
    schema = FindLandmarkSchema(pole_record(far, activation=20.0), EXPECTER)
    snapshot = map_around(TRUTH)
    status = None
    for k in range(4):
        report = schema.step(Frame(0.1 * k, pole_image(rng, TRUTH, [far]), snapshot), status)
        status = report.status
        assert report.state is SchemaState.HIBERNATING
        assert report.window is None
        assert report.value is None
        assert report.observation is None
    assert calls == []
    # once the robot may be within range, it wakes and the strategy runs on the window
    near = map_around(Pose(41.0, 0.0, 0.0))
    report = schema.step(Frame(1.0, pole_image(rng, Pose(41.0, 0.0, 0.0), [far]), near), status)
    assert report.state is SchemaState.DISCOVERING
    assert calls == [report.window]


def test_activation_uses_the_polygon_edges_not_only_its_vertices(rng: np.random.Generator) -> None:
    from aura_ums.geometry import ConvexPolygon, HeadingWedge

    long_map = SpatialUncertaintyMap.from_polygon(
        ConvexPolygon([(-10.0, -1.0), (10.0, -1.0), (10.0, 1.0), (-10.0, 1.0)]),
        (0.0, 0.0),
        HeadingWedge(0.0, 0.1, 0.1),
    )
    beside = VerticalLineLandmark("beside", 0.0, 5.0, 0.0, 3.0)
    record = pole_record(beside, activation=4.5)
    assert float(record.distance(long_map.polygon.vertices).min()) > 4.5  # every vertex is out of range
    schema = FindLandmarkSchema(record, EXPECTER)
    frame = Frame(0.0, pole_image(rng, TRUTH, []), long_map)
    assert schema.is_active(frame)  # ... but the edge y = 1 is 4 m away
    assert schema.step(frame).state is not SchemaState.HIBERNATING
    moved = SpatialUncertaintyMap.from_pose(Pose(0.0, -1.0, 0.0), 0.4, 0.05)
    assert not schema.is_active(Frame(0.1, pole_image(rng, TRUTH, []), moved))


def test_position_uncertainty_counts_towards_activation(rng: np.random.Generator) -> None:
    snapshot = SpatialUncertaintyMap.from_pose(TRUTH, 0.0, 0.05)
    image = pole_image(rng, TRUTH, [])
    sure = VerticalLineLandmark("p", 10.5, 0.0, 0.0, 3.0)
    unsure = VerticalLineLandmark("p", 10.5, 0.0, 0.0, 3.0, position_uncertainty=0.6)
    assert not FindLandmarkSchema(pole_record(sure, activation=10.0), EXPECTER).is_active(
        Frame(0, image, snapshot)
    )
    assert FindLandmarkSchema(pole_record(unsure, activation=10.0), EXPECTER).is_active(
        Frame(0, image, snapshot)
    )


# (e) a tracked landmark that disappears becomes suspect --------------------------------


@pytest.mark.parametrize("lost_frames", [1, 2, 3])
def test_a_tracked_landmark_that_disappears_becomes_suspect(
    rng: np.random.Generator, lost_frames: int
) -> None:
    schema = FindLandmarkSchema(pole_record(POLE, confirm=2), EXPECTER, lost_frames=lost_frames)
    manager = SchemaManager([schema])
    snapshot = map_around(TRUTH)
    steps = []
    sequence = [True, True, True] + [False] * (lost_frames + 1) + [True]
    for k, seen in enumerate(sequence):
        steps.append(manager.step(Frame(0.1 * k, pole_image(rng, TRUTH, [POLE] if seen else []), snapshot)))
        for observation in steps[-1].posted:
            assert_sound(observation, POLE, snapshot, TRUTH)
    states = [s.report("pole").state for s in steps]
    gone = 3 + lost_frames - 1  # the frame on which the M-th consecutive miss happens
    assert states[:3] == [SchemaState.DISCOVERING, SchemaState.TRACKING, SchemaState.TRACKING]
    assert states[3:gone] == [SchemaState.TRACKING] * (lost_frames - 1)
    assert states[gone] is SchemaState.SUSPECT
    assert steps[gone].suspects == ("pole",)
    assert all(s.suspects == () for k, s in enumerate(steps) if k != gone)
    # misses while tracking search the tracking window; then discovery starts over in the Expecter's window
    assert steps[gone].report("pole").window != EXPECTER.window(
        snapshot, POLE, margin=PerceptualStrategy.LINE_FINDER
    )
    rediscovering = steps[gone + 1].report("pole")
    assert rediscovering.state is SchemaState.DISCOVERING
    assert rediscovering.window == EXPECTER.window(snapshot, POLE, margin=PerceptualStrategy.LINE_FINDER)
    # back in view: a fresh discovery, needing its confirm frames again (nothing posted on the first hit)
    assert steps[-1].report("pole").hit
    assert steps[-1].posted == ()
    assert steps[-1].report("pole").state is SchemaState.DISCOVERING


def test_a_landmark_leaving_the_view_is_not_suspect(rng: np.random.Generator) -> None:
    schema = FindLandmarkSchema(pole_record(POLE, confirm=2), EXPECTER)
    # the robot turns left fast: the pole (ahead, slightly left) leaves the image on the right
    truths = [Pose(0.0, 0.0, 0.0), Pose(0.0, 0.0, 0.0)] + [Pose(0.0, 0.0, 1.0 + 0.5 * k) for k in range(3)]
    maps = [map_around(t) for t in truths]
    reports = run(schema, [pole_image(rng, t, [POLE]) for t in truths], maps, truths)
    assert reports[1].state is SchemaState.TRACKING
    assert all(r.state is SchemaState.DISCOVERING for r in reports[2:])
    assert all(r.window is None for r in reports[2:])


def test_leaving_the_activation_range_hibernates_again(rng: np.random.Generator) -> None:
    schema = FindLandmarkSchema(pole_record(POLE, confirm=1, activation=15.0), EXPECTER)
    first = schema.step(Frame(0.0, pole_image(rng, TRUTH, [POLE]), map_around(TRUTH)))
    assert first.state is SchemaState.TRACKING
    away = Pose(-20.0, 0.0, 0.0)
    second = schema.step(Frame(0.1, pole_image(rng, away, [POLE]), map_around(away)), first.status)
    assert second.status == SchemaStatus()
