"""Outlier recovery of the manager: the envelope map, re-localization from it, in replay and live use."""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Callable

import numpy as np
import pytest

from aura_ums.errors import FileFormatError, InputError
from aura_ums.expecter import PerceptualStrategy
from aura_ums.geometry import ConvexPolygon
from aura_ums.logs import LogObservation, ReplayOptions, RobotLog, replay_log, synthetic_log
from aura_ums.manager import (
    Blackboard,
    ManagerSettings,
    ManagerStep,
    PositionReport,
    RejectReason,
    UncertaintyMapManager,
)
from aura_ums.uncertainty import (
    BearingObservation,
    GroundLineLandmark,
    GroundLineObservation,
    LandmarkClass,
    Observation,
    PointLandmark,
    Pose,
    RangeBearingObservation,
    SpatialUncertaintyMap,
    TerrainTable,
    TurnAndRun,
    VerticalLineLandmark,
)
from aura_ums.world import LandmarkRecord, Meadow, MeadowMap, make_grid_world

FLOOR = TerrainTable({"floor": TerrainTable.default()["tile"]})
POLE = VerticalLineLandmark("pole", 8.0, 6.0, 0.0, 4.0)
CORNER = PointLandmark("corner", 12.0, -3.0, 2.0)
EDGE = GroundLineLandmark("edge", (0.0, -5.0), (20.0, -5.0))
WORLD = MeadowMap(
    [
        Meadow(
            "floor", ConvexPolygon([(0, -5), (20, -5), (20, 8), (0, 8)]), "floor", ("pole", "corner", "edge")
        )
    ],
    [
        LandmarkRecord(lm, PerceptualStrategy.for_class(lm.landmark_class)[0], {}, 30.0, 0.5)
        for lm in (POLE, CORNER, EDGE)
    ],
)
START = SpatialUncertaintyMap.from_pose(Pose(2.0, 0.0, 0.0), 0.2, 0.03)
STRIDE = TurnAndRun(0.0, 1.0)


def sightings(pose: Pose, time: float) -> list[Observation]:
    """One observation of each landmark from ``pose``, exact, with small bounds."""
    pole = math.atan2(POLE.y - pose.y, POLE.x - pose.x) - pose.heading
    distance = math.hypot(CORNER.x - pose.x, CORNER.y - pose.y)
    corner = math.atan2(CORNER.y - pose.y, CORNER.x - pose.x) - pose.heading
    # The pole last: with the default window of one observation, the last inconsistency counts.
    return [
        RangeBearingObservation("corner", time, corner, 0.01, distance - 0.3, distance + 0.3),
        GroundLineObservation("edge", time, pose.y + 5.0, 0.05, -pose.heading, 0.01),
        BearingObservation("pole", time, pole, 0.01),
    ]


def assert_same_map(a: SpatialUncertaintyMap | None, b: SpatialUncertaintyMap | None) -> None:
    assert a is not None
    assert b is not None
    assert a.polygon.vertices.tobytes() == b.polygon.vertices.tobytes()
    assert a.center.tobytes() == b.center.tobytes()
    assert (a.wedge.center, a.wedge.cw, a.wedge.ccw) == (b.wedge.center, b.wedge.cw, b.wedge.ccw)


def walk(manager: UncertaintyMapManager, steps: int, wrong_at: tuple[int, ...] = ()) -> list[ManagerStep]:
    """Drive east a metre a step, seeing every landmark; at ``wrong_at``, the pole misplaced by 2 rad."""
    board = Blackboard()
    pose, result = Pose(2.0, 0.0, 0.0), []
    for k in range(1, steps + 1):
        pose = Pose(pose.x + 1.0, pose.y, pose.heading)
        board.post_report(PositionReport(float(k), STRIDE))
        for observation in sightings(pose, float(k)):
            if k in wrong_at and isinstance(observation, BearingObservation):
                observation = dataclasses.replace(observation, bearing=observation.bearing + 2.0)
            board.identified.post(observation)
        result.append(manager.update(board, now=float(k)))
    return result


# --- the manager's own recovery ----------------------------------------------------------


def test_an_inconsistent_observation_re_localizes_from_the_envelope() -> None:
    robust = UncertaintyMapManager(START, WORLD, FLOOR)
    gate = UncertaintyMapManager(START, WORLD, FLOOR, ManagerSettings(robust=False))
    with_recovery, gate_only = walk(robust, 4, wrong_at=(3,)), walk(gate, 4, wrong_at=(3,))
    assert [s.relocalized for s in with_recovery] == [False, False, True, False]
    assert robust.relocalizations == 1
    assert robust.inconsistent_count == gate.inconsistent_count == 1
    assert {r for r, _ in robust.rejected_counts.items()} == {r for r, _ in gate.rejected_counts.items()}
    assert all(s.envelope_map is None and not s.relocalized for s in gate_only)
    assert gate.envelope_map is None
    # Before the outlier both managers hold the very same working map; the envelope is larger.
    for ours, theirs in zip(with_recovery[:2], gate_only[:2], strict=True):
        assert_same_map(ours.map, theirs.map)
        assert ours.envelope_map is not None
        assert ours.envelope_map.area >= ours.map.area
    assert with_recovery[2].envelope_map is not None
    assert with_recovery[2].map.area <= with_recovery[2].envelope_map.area
    assert robust.map.contains(Pose(6.0, 0.0, 0.0))


def test_the_observation_found_inconsistent_does_not_re_seed_the_map() -> None:
    # A gross outlier the working map rejects, but the wider envelope map accepts, re-seeded
    # the map to its own region: the truth, in both maps before it, was outside after it.
    world = make_grid_world(2, 3)  # poles at (0, 0), (10, 0), (0, 10), (10, 10)
    poles = {"pole_0_2": (10.0, 0.0), "pole_2_0": (0.0, 10.0), "pole_2_2": (10.0, 10.0)}
    truth = Pose(5.0, 5.0, 0.0)

    def seen(landmark: str, time: float, error: float, bound: float) -> BearingObservation:
        x, y = poles[landmark]
        return BearingObservation(landmark, time, math.atan2(y - truth.y, x - truth.x) + error, bound)

    start = SpatialUncertaintyMap.from_pose(truth, 0.5, 0.3)
    manager = UncertaintyMapManager(start, world, TerrainTable.default(), ManagerSettings(joint_above=None))
    board = Blackboard()
    for time, sightings_now in ((1.0, (("pole_0_2", 0.0), ("pole_2_0", 0.0))), (2.0, (("pole_2_2", 0.25),))):
        board.post_report(PositionReport(time, TurnAndRun(0.0, 0.0)))
        for landmark, error in sightings_now:
            board.identified.post(seen(landmark, time, error, 0.01))
        twins = [seen(landmark, time, error, 0.2) for landmark, error in sightings_now]
        step = manager.update(board, now=time, envelope=twins)
        assert step.envelope_map is not None
        assert step.envelope_map.contains(truth)
    assert [o.reason for o in step.rejected] == [RejectReason.NO_POSITION]
    assert step.relocalized
    assert step.map.contains(truth)
    envelope_map = step.envelope_map
    assert envelope_map is not None
    assert step.map.area <= envelope_map.area


def test_without_twins_the_envelope_is_reduced_by_the_observations_widened() -> None:
    factor = 3.0
    robust = UncertaintyMapManager(START, WORLD, FLOOR, ManagerSettings(envelope_factor=factor))
    steps = walk(robust, 3)
    # The same run, gate only, with every bound widened by hand: the envelope map exactly.
    plain = UncertaintyMapManager(START, WORLD, FLOOR, ManagerSettings(robust=False))
    board = Blackboard()
    pose = Pose(2.0, 0.0, 0.0)
    for k in range(1, 4):
        pose = Pose(pose.x + 1.0, pose.y, pose.heading)
        board.post_report(PositionReport(float(k), STRIDE))
        ranged, line, bearing = sightings(pose, float(k))
        assert isinstance(bearing, BearingObservation)
        assert isinstance(ranged, RangeBearingObservation)
        assert isinstance(line, GroundLineObservation)
        middle, half = (ranged.range_min + ranged.range_max) / 2, (ranged.range_max - ranged.range_min) / 2
        board.identified.post(dataclasses.replace(bearing, bearing_error=bearing.bearing_error * factor))
        board.identified.post(
            dataclasses.replace(
                ranged,
                bearing_error=ranged.bearing_error * factor,
                range_min=max(0.0, middle - half * factor),
                range_max=middle + half * factor,
            )
        )
        board.identified.post(
            dataclasses.replace(
                line, offset_error=line.offset_error * factor, angle_error=line.angle_error * factor
            )
        )
        assert_same_map(steps[k - 1].envelope_map, plain.update(board, now=float(k)).map)


def test_twins_given_to_the_update_reduce_the_envelope() -> None:
    robust = UncertaintyMapManager(START, WORLD, FLOOR)
    plain = UncertaintyMapManager(START, WORLD, FLOOR, ManagerSettings(robust=False))
    pose = Pose(3.0, 0.0, 0.0)
    seen = sightings(pose, 1.0)
    twins = [
        dataclasses.replace(o, bearing_error=0.3) if isinstance(o, BearingObservation) else o for o in seen
    ]
    boards = Blackboard(), Blackboard()
    for board, posted in zip(boards, (seen, twins), strict=True):
        board.post_report(PositionReport(1.0, STRIDE))
        for observation in posted:
            board.identified.post(observation)
    step = robust.update(boards[0], now=1.0, envelope=twins)
    assert_same_map(step.envelope_map, plain.update(boards[1], now=1.0).map)


def test_twins_that_do_not_pair_are_refused_and_nothing_changes() -> None:
    manager = UncertaintyMapManager(START, WORLD, FLOOR)
    board = Blackboard()
    board.post_report(PositionReport(1.0, STRIDE))
    seen = sightings(Pose(3.0, 0.0, 0.0), 1.0)
    for observation in seen:
        board.identified.post(observation)
    with pytest.raises(
        InputError, match=r"envelope: expected one observation per identified .* \(3\), got 2"
    ):
        manager.update(board, now=1.0, envelope=seen[:2])
    moved = [seen[0], seen[1], dataclasses.replace(seen[2], time=0.5)]
    with pytest.raises(InputError, match=r"envelope\[2\]: expected a BearingObservation of 'pole' at t=1\.0"):
        manager.update(board, now=1.0, envelope=moved)
    with pytest.raises(InputError, match="envelope: expected a sequence of observations or None, got str"):
        manager.update(board, now=1.0, envelope="twins")  # type: ignore[arg-type]
    assert (manager.consumed_reports, len(board.identified), manager.map) == (0, 3, START)
    assert manager.update(board, now=1.0, envelope=seen).outcomes[0].accepted


def test_a_re_seed_uses_no_sighting_taken_before_the_motion_the_envelope_has_grown_since() -> None:
    # One update: a metre, the sightings (the pole wrong: re-localization), then half a metre
    # more. The re-seed reduced the envelope map, grown to the end, by the sightings taken
    # half a metre back: it put the robot where it was, and the truth ended outside.
    manager = UncertaintyMapManager(START, WORLD, FLOOR)
    board = Blackboard()
    seen_at = Pose(3.0, 0.0, 0.0)
    board.post_report(PositionReport(1.0, STRIDE))
    for observation in sightings(seen_at, 1.0):
        if isinstance(observation, BearingObservation):
            observation = dataclasses.replace(observation, bearing=observation.bearing + 2.0)
        board.identified.post(observation)
    board.post_report(PositionReport(2.0, TurnAndRun(0.0, 0.5)))
    step = manager.update(board, now=2.0)
    assert step.relocalized
    assert step.envelope_map is not None
    truth = Pose(3.5, 0.0, 0.0)
    assert step.envelope_map.contains(truth)
    assert step.map.contains(truth)


def test_relocalize_after_counts_inconsistencies_in_a_window() -> None:
    settings = ManagerSettings(relocalize_after=2, relocalize_window=6)
    manager = UncertaintyMapManager(START, WORLD, FLOOR, settings)
    # Three observations a step, the wrong pole last at steps 2 and 4: six observations
    # apart, so never two inconsistencies among the last six.
    steps = walk(manager, 5, wrong_at=(2, 4))
    assert manager.inconsistent_count == 2
    assert not any(s.relocalized for s in steps)
    wider = UncertaintyMapManager(START, WORLD, FLOOR, dataclasses.replace(settings, relocalize_window=7))
    assert [s.relocalized for s in walk(wider, 5, wrong_at=(2, 4))] == [False, False, False, True, False]


def test_the_state_is_judged_after_the_re_seed() -> None:
    # Re-seeded from the envelope, the map is larger than the working map was: above the
    # limit, the robot is lost; the gate alone keeps the smaller map and stays nominal.
    limit = 0.045
    robust = walk(UncertaintyMapManager(START, WORLD, FLOOR, ManagerSettings(area_limit=limit)), 4, (3,))
    gate = ManagerSettings(area_limit=limit, robust=False)
    gate_only = walk(UncertaintyMapManager(START, WORLD, FLOOR, gate), 4, (3,))
    assert [s.relocalized for s in robust] == [False, False, True, False]
    assert robust[2].map.area > limit > gate_only[2].map.area
    assert [s.state.value for s in robust] == ["nominal", "nominal", "lost", "nominal"]
    assert "area_limit" in robust[2].lost_reason
    assert {s.state.value for s in gate_only} == {"nominal"}


def test_save_and_restore_keep_the_envelope_and_the_recent_inconsistencies() -> None:
    settings = ManagerSettings(relocalize_after=2, relocalize_window=7)
    whole = UncertaintyMapManager(START, WORLD, FLOOR, settings)
    reference = walk(whole, 4, wrong_at=(2, 4))
    assert reference[3].relocalized
    # Stop after step 3 (one inconsistency remembered), restore, and play step 4.
    first = UncertaintyMapManager(START, WORLD, FLOOR, settings)
    board = Blackboard()
    pose = Pose(2.0, 0.0, 0.0)
    for k in range(1, 5):
        pose = Pose(pose.x + 1.0, pose.y, pose.heading)
        board.post_report(PositionReport(float(k), STRIDE))
        for observation in sightings(pose, float(k)):
            if k in (2, 4) and isinstance(observation, BearingObservation):
                observation = dataclasses.replace(observation, bearing=observation.bearing + 2.0)
            board.identified.post(observation)
        if k == 4:
            document = json.loads(first.to_json())
            assert document["envelope"]["recent"] == [False, False, False, True, False, False, False]
            first = UncertaintyMapManager.from_json(first.to_json(), WORLD, FLOOR)
            board = Blackboard.from_json(board.to_json())
        step = first.update(board, now=float(k))
    assert step.relocalized
    assert_same_map(step.map, reference[3].map)
    assert_same_map(step.envelope_map, reference[3].envelope_map)
    assert first.to_json() == whole.to_json()


def test_restore_refuses_an_envelope_that_does_not_fit_the_settings() -> None:
    robust = json.loads(UncertaintyMapManager(START, WORLD, FLOOR).to_json())
    robust["envelope"] = None
    with pytest.raises(
        FileFormatError, match=r"envelope: expected the envelope map \(settings\.robust is true\)"
    ):
        UncertaintyMapManager.from_json(json.dumps(robust), WORLD, FLOOR)
    robust = json.loads(UncertaintyMapManager(START, WORLD, FLOOR).to_json())
    robust["envelope"]["recent"] = [True, True]
    with pytest.raises(FileFormatError, match=r"envelope\.recent: expected at most 1 booleans"):
        UncertaintyMapManager.from_json(json.dumps(robust), WORLD, FLOOR)
    # Saved before outlier recovery: no envelope, restored as it ran.
    older = json.loads(UncertaintyMapManager(START, WORLD, FLOOR).to_json())
    del older["envelope"], older["settings"]["robust"]
    restored = UncertaintyMapManager.from_json(json.dumps(older), WORLD, FLOOR)
    assert (restored.settings.robust, restored.envelope_map) == (False, None)


def test_rejections_are_keyed_by_reason_and_saved_by_their_text() -> None:
    manager = UncertaintyMapManager(START, WORLD, FLOOR)
    walk(manager, 2, wrong_at=(2,))
    (reason,) = manager.rejected_counts
    assert isinstance(reason, RejectReason)
    assert reason.inconsistent
    assert json.loads(manager.to_json())["counters"]["rejected"] == {reason.value: 1}


# --- in replay -----------------------------------------------------------------------------


@pytest.fixture(scope="module")
def clean_log() -> RobotLog:
    return synthetic_log(np.random.default_rng(5), duration=60.0)


def inject(
    log: RobotLog, start: float, end: float, change: Callable[[LogObservation], LogObservation]
) -> RobotLog:
    rows = tuple(change(o) if start <= o.time < end else o for o in log.observations)
    return dataclasses.replace(log, observations=rows)


@pytest.mark.parametrize("landmark_class", [LandmarkClass.VERTICAL_LINE, LandmarkClass.POINT])
def test_gross_outliers_are_rejected_counted_and_never_applied(
    clean_log: RobotLog, landmark_class: LandmarkClass
) -> None:
    wrong = inject(clean_log, 20.0, 23.0, lambda o: dataclasses.replace(o, bearing=o.bearing + 2.0))
    injected = sum(1 for o in wrong.observations if 20.0 <= o.time < 23.0)
    result = replay_log(wrong, FLOOR, ReplayOptions(landmark_class=landmark_class))
    assert 1 <= result.inconsistent_observations <= injected
    assert result.relocalizations >= 1
    assert result.containment_rate == 1.0
    assert all(step.map.area > 0.0 for step in result.steps)


def test_consistent_but_wrong_observations_mislead_only_briefly(clean_log: RobotLog) -> None:
    # A 3.5% range bias for 3 s on top of the 2% noise: beyond the working bounds (2%),
    # within the envelope's (three times them).
    biased = inject(clean_log, 20.0, 23.0, lambda o: dataclasses.replace(o, range=(o.range or 0.0) * 0.965))
    options = ReplayOptions(settings=ManagerSettings(envelope_factor=3.0), landmark_class=LandmarkClass.POINT)
    result = replay_log(biased, FLOOR, options)
    outside = [step.time for step in result.steps if step.inside is False]
    assert outside, "the bias was expected to mislead the working map for a while"
    assert max(outside) < 23.0 + 5.0  # never wrong for long
    assert all(step.envelope_inside for step in result.steps)  # the envelope stays sound
    assert result.steps[-1].inside
    assert result.containment_rate > 0.9
    # Re-localization from the envelope shortens the misled stretch against the gate alone.
    gate = dataclasses.replace(options, settings=dataclasses.replace(options.settings, robust=False))
    gate_only = replay_log(biased, FLOOR, gate)
    assert len(outside) <= sum(1 for step in gate_only.steps if step.inside is False)
    assert all(step.envelope_inside is None and not step.relocalized for step in gate_only.steps)


def test_a_coarse_envelope_stays_sound_and_re_seeds_within_the_working_cap(clean_log: RobotLog) -> None:
    wrong = inject(clean_log, 20.0, 23.0, lambda o: dataclasses.replace(o, bearing=o.bearing + 2.0))
    settings = ManagerSettings(max_vertices=24, envelope_max_vertices=6)
    steps = replay_log(
        wrong, FLOOR, ReplayOptions(settings=settings, landmark_class=LandmarkClass.POINT)
    ).steps
    assert any(step.relocalized for step in steps)
    assert all(step.envelope_inside for step in steps)
    assert all(len(step.map.polygon.vertices) <= 24 for step in steps[1:])
    assert sum(step.inside is True for step in steps) == len(steps)


def test_sightings_that_say_nothing_of_the_heading_are_not_reduced_jointly(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # An envelope calibrated on a misread landmark bounds bearings by 3.7 rad: its wedge never
    # narrows, and every frame was reduced jointly (40 times the map's own update time).
    world = make_grid_world(2, 3)
    truth = Pose(5.0, 5.0, 0.3)
    joint_calls: list[int] = []
    reduce_jointly = SpatialUncertaintyMap._reduce_jointly

    def counted(self: SpatialUncertaintyMap, *args: object, **kwargs: object) -> object:
        joint_calls.append(1)
        return reduce_jointly(self, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(SpatialUncertaintyMap, "_reduce_jointly", counted)
    for bound, joint in ((3.5, False), (0.05, True)):
        joint_calls.clear()
        start = SpatialUncertaintyMap.from_pose(truth, 0.5, 2.0)  # a wedge wider than joint_above
        manager = UncertaintyMapManager(start, world, TerrainTable.default(), ManagerSettings(robust=False))
        board = Blackboard()
        board.post_report(PositionReport(1.0, TurnAndRun(0.0, 0.0)))
        for landmark, (x, y) in (("pole_0_2", (10.0, 0.0)), ("pole_2_0", (0.0, 10.0))):
            seen = math.atan2(y - truth.y, x - truth.x) - truth.heading
            board.identified.post(BearingObservation(landmark, 1.0, seen, bound))
        step = manager.update(board, now=1.0)
        assert bool(joint_calls) is joint
        assert step.map.contains(truth)
        assert len(step.accepted) == 2
