"""The schema manager: stepping, posting, and counting predicted-but-not-found landmarks."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from aura_ums.errors import InputError
from aura_ums.expecter import Expecter
from aura_ums.manager import IdentifiedLandmarkBuffer
from aura_ums.perception import FastLineFinder, LineSegments
from aura_ums.schemas import FindLandmarkSchema, Frame, SchemaManager, SchemaState, StepReport
from aura_ums.uncertainty import Pose, VerticalLineLandmark
from tests.schemas.schema_scenes import CAMERA, assert_sound, map_around, pole_image, pole_record

EXPECTER = Expecter(CAMERA)
TRUTH = Pose(0.0, 0.0, 0.0)
LEFT = VerticalLineLandmark("left_pole", 10.0, 2.0, 0.0, 4.0, position_uncertainty=0.1)
RIGHT = VerticalLineLandmark("right_pole", 12.0, -2.5, 0.0, 5.0, position_uncertainty=0.1)
BEHIND = VerticalLineLandmark("behind_pole", -8.0, 0.0, 0.0, 4.0, position_uncertainty=0.1)
FAR = VerticalLineLandmark("far_pole", 80.0, 0.0, 0.0, 4.0, position_uncertainty=0.1)


def manager_for(*poles: VerticalLineLandmark, confirm: int = 2) -> SchemaManager:
    return SchemaManager(
        [FindLandmarkSchema(pole_record(p, confirm=confirm, activation=20.0), EXPECTER) for p in poles]
    )


# (f) predicted but not found -----------------------------------------------------------


def test_predicted_but_not_found_counting(rng: np.random.Generator) -> None:
    manager = manager_for(LEFT, RIGHT, BEHIND, FAR)
    snapshot = map_around(TRUTH)
    away = map_around(Pose(-200.0, 0.0, 0.0))  # nothing within range: every schema hibernates
    plan: list[tuple[list[VerticalLineLandmark], object]] = [
        ([], snapshot),  # both poles ahead predicted, none found            -> 1
        ([], snapshot),  #                                                   -> 2
        ([], away),  # nothing predicted: no evidence either way             -> 2
        ([], snapshot),  #                                                   -> 3
        ([LEFT], snapshot),  # one found: the other is still predicted-but-not-found, but not lost -> 0
        ([], snapshot),  # the tracked one and the other both missed         -> 1
    ]
    steps: list[StepReport] = []
    for k, (poles, snap) in enumerate(plan):
        steps.append(manager.step(Frame(0.1 * k, pole_image(rng, TRUTH, poles), snap)))  # type: ignore[arg-type]
    assert [s.consecutive_missed for s in steps] == [1, 2, 2, 3, 0, 1]
    assert [s.missed for s in steps] == [
        ("left_pole", "right_pole"),
        ("left_pole", "right_pole"),
        (),
        ("left_pole", "right_pole"),
        ("right_pole",),
        ("left_pole", "right_pole"),
    ]
    # the pole behind the camera is awake but never predicted; the far one hibernates
    for step in steps:
        assert "behind_pole" not in step.predicted
        assert step.report("far_pole").state is SchemaState.HIBERNATING
    assert steps[0].report("behind_pole").state is SchemaState.DISCOVERING
    assert steps[0].report("behind_pole").window is None
    assert steps[4].found == ("left_pole",)
    assert manager.consecutive_missed == 1
    assert manager.frames == 6
    assert manager.missed_frames == 4
    assert manager.predicted_total == 10
    assert manager.missed_total == 9
    assert manager.posted_total == 0  # one hit is not a confirmed discovery


def test_a_tracked_landmark_that_keeps_matching_keeps_the_count_at_zero(rng: np.random.Generator) -> None:
    manager = manager_for(LEFT, RIGHT)
    snapshot = map_around(TRUTH)
    counts = []
    for k in range(5):
        step = manager.step(Frame(0.1 * k, pole_image(rng, TRUTH, [LEFT]), snapshot))
        counts.append(step.consecutive_missed)
        for observation in step.posted:
            assert_sound(observation, LEFT, snapshot, TRUTH)
    assert counts == [0] * 5
    assert manager.posted_total == 4
    assert manager.missed_total == 5  # the right pole, every frame
    assert manager.missed_frames == 0


def test_step_posts_identifications_to_the_buffer(rng: np.random.Generator) -> None:
    buffer = IdentifiedLandmarkBuffer()
    manager = SchemaManager(
        [FindLandmarkSchema(pole_record(p, confirm=2, activation=20.0), EXPECTER) for p in (LEFT, RIGHT)],
        buffer=buffer,
    )
    assert manager.buffer is buffer
    snapshot = map_around(TRUTH)
    steps = [
        manager.step(Frame(1.0 + 0.1 * k, pole_image(rng, TRUTH, [LEFT, RIGHT]), snapshot)) for k in range(3)
    ]
    assert [len(s.posted) for s in steps] == [0, 2, 2]
    assert manager.posted_total == 4
    held = buffer.drain()
    assert [o.time for o in held] == pytest.approx([1.1, 1.1, 1.2, 1.2])
    landmarks = {"left_pole": LEFT, "right_pole": RIGHT}
    for observation in held:
        assert_sound(observation, landmarks[observation.landmark_id], snapshot, TRUTH)
    assert dict(manager.states) == {"left_pole": SchemaState.TRACKING, "right_pole": SchemaState.TRACKING}
    assert manager.status("left_pole").hits == 3
    report = steps[-1].report("right_pole")
    assert report.observation is steps[-1].posted[1]
    with pytest.raises(dataclasses.FrozenInstanceError, match="cannot assign"):
        report.hit = False  # type: ignore[misc]


def test_instantiate_adds_schemas_hibernating(rng: np.random.Generator) -> None:
    manager = SchemaManager()
    assert len(manager) == 0
    assert "no schemas" in repr(manager)
    manager.instantiate([FindLandmarkSchema(pole_record(LEFT), EXPECTER)])
    manager.instantiate(FindLandmarkSchema(pole_record(p), EXPECTER) for p in (RIGHT,))
    assert [s.landmark_id for s in manager.schemas] == ["left_pole", "right_pole"]
    assert set(manager.states.values()) == {SchemaState.HIBERNATING}
    assert "2 hibernating" in repr(manager)
    step = manager.step(Frame(0.0, pole_image(rng, TRUTH, []), map_around(TRUTH)))
    assert [r.landmark_id for r in step.schemas] == ["left_pole", "right_pole"]


def test_manager_rejects_bad_input(rng: np.random.Generator) -> None:
    schema = FindLandmarkSchema(pole_record(LEFT), EXPECTER)
    manager = SchemaManager([schema])
    with pytest.raises(InputError, match="expected one schema per landmark, got 'left_pole' again"):
        manager.instantiate([FindLandmarkSchema(pole_record(LEFT), EXPECTER)])
    with pytest.raises(InputError, match=r"schemas\[1\]: expected a FindLandmarkSchema, got str"):
        manager.instantiate([FindLandmarkSchema(pole_record(RIGHT), EXPECTER), "pole"])  # type: ignore[list-item]
    assert len(manager) == 1  # nothing of a refused call is instantiated
    with pytest.raises(InputError, match="expected an iterable of FindLandmarkSchema, got one"):
        SchemaManager(schema)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="schemas: expected an iterable of FindLandmarkSchema, got dict"):
        SchemaManager({})
    with pytest.raises(InputError, match="buffer: expected an IdentifiedLandmarkBuffer or None, got list"):
        SchemaManager([], buffer=[])  # type: ignore[arg-type]
    with pytest.raises(InputError, match="frame: expected a Frame, got ndarray"):
        manager.step(np.zeros((480, 640)))  # type: ignore[arg-type]
    with pytest.raises(InputError, match="landmark_id: expected one of left_pole, got 'nope'"):
        manager.status("nope")
    snapshot = map_around(TRUTH)
    step = manager.step(Frame(1.0, pole_image(rng, TRUTH, []), snapshot))
    with pytest.raises(InputError, match="landmark_id: expected one of left_pole, got 'nope'"):
        step.report("nope")
    with pytest.raises(
        InputError, match=r"frame\.time: expected a time after the previous frame's 1\.0, got 0\.5"
    ):
        manager.step(Frame(0.5, pole_image(rng, TRUTH, []), snapshot))
    with pytest.raises(InputError, match=r"frame\.image: expected the camera's 640x480 image, got 320x240"):
        manager.step(Frame(2.0, np.zeros((240, 320), dtype=np.uint8), snapshot))


# identifications another landmark of the same kind could explain ------------------------


def test_a_detection_inside_another_landmarks_bounds_is_withheld(rng: np.random.Generator) -> None:
    # Two poles 0.3 m apart at 10 m: from some pose of the map each could appear where the
    # other is seen, so neither identification may prune the map.
    near = VerticalLineLandmark("near_pole", 10.0, 2.0, 0.0, 4.0, position_uncertainty=0.1)
    twin = VerticalLineLandmark("twin_pole", 10.0, 2.3, 0.0, 4.0, position_uncertainty=0.1)
    manager = manager_for(near, twin, confirm=1)
    snapshot = map_around(TRUTH)
    step = manager.step(Frame(1.0, pole_image(rng, TRUTH, [near, twin]), snapshot))
    assert step.posted == ()
    assert set(step.ambiguous) == {"near_pole", "twin_pole"}
    assert manager.ambiguous_total == 2
    assert len(manager.buffer) == 0
    # Far apart, the same two kinds of landmark are told apart and posted.
    apart = manager_for(LEFT, RIGHT, confirm=1)
    step = apart.step(Frame(1.0, pole_image(rng, TRUTH, [LEFT, RIGHT]), snapshot))
    assert {o.landmark_id for o in step.posted} == {"left_pole", "right_pole"}
    assert step.ambiguous == ()


def test_full_frame_schemas_with_equal_finders_share_one_search(
    rng: np.random.Generator, monkeypatch: pytest.MonkeyPatch
) -> None:
    image = pole_image(rng, TRUTH, [LEFT, RIGHT])
    snapshot = map_around(TRUTH)

    def run() -> tuple[StepReport, int]:
        calls = 0
        original = FastLineFinder.find_detailed

        def counted(self: FastLineFinder, *args: object, **kwargs: object) -> LineSegments:
            nonlocal calls
            calls += 1
            return original(self, *args, **kwargs)  # type: ignore[arg-type]

        with monkeypatch.context() as patch:
            patch.setattr(FastLineFinder, "find_detailed", counted)
            report = manager_for(LEFT, RIGHT).step(Frame(0.0, image, snapshot, window_scale=math.inf))
        return report, calls

    shared, shared_calls = run()
    # The two schemas' finders are equal (the same record parameters) and both search the
    # whole image: one line finding serves both, and both still find their pole.
    assert shared_calls == 1
    assert shared.found == ("left_pole", "right_pole")
    windowed = manager_for(LEFT, RIGHT).step(Frame(0.0, image, snapshot))
    assert windowed.found == shared.found
    assert windowed.report("left_pole").window != windowed.report("right_pole").window
