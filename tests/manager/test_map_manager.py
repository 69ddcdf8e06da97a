"""The uncertainty map manager: growth to each observation, reduction, rejections, lost, save/restore."""

from __future__ import annotations

import json
import math
from dataclasses import FrozenInstanceError, dataclass, fields
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from aura_ums.errors import FileFormatError, InputError, UnknownTerrainError
from aura_ums.expecter import PerceptualStrategy
from aura_ums.geometry import ConvexPolygon, HeadingWedge, wrap_angle
from aura_ums.manager import (
    Blackboard,
    ManagerSettings,
    ManagerState,
    ManagerStep,
    ObservationOutcome,
    PositionReport,
    RejectReason,
    UncertaintyMapManager,
)
from aura_ums.uncertainty import (
    BearingObservation,
    GroundLineLandmark,
    GroundLineObservation,
    Landmark,
    Observation,
    PointLandmark,
    Pose,
    RangeBearingObservation,
    SpatialUncertaintyMap,
    TerrainTable,
    TurnAndRun,
    VerticalLineLandmark,
    reduce_jointly,
)
from aura_ums.world import RUN_TOLERANCE, LandmarkRecord, Meadow, MeadowMap, grow_through, outer_terrain

TABLE = TerrainTable.default()
POLE_NORTH = VerticalLineLandmark("pole_north", 8.0, 6.0, 0.0, 4.0)
POLE_SOUTH = VerticalLineLandmark("pole_south", 14.0, -7.0, 0.0, 4.0)
CORNER = PointLandmark("corner", 22.0, 3.0, 2.0)
EDGE = GroundLineLandmark("edge", (0.0, -5.0), (20.0, -5.0))
LANDMARKS: tuple[Landmark, ...] = (POLE_NORTH, POLE_SOUTH, CORNER, EDGE)
START = Pose(2.0, 0.0, 0.0)
STRIDE = TurnAndRun(0.0, 2.0)


def box(x0: float, y0: float, x1: float, y1: float) -> ConvexPolygon:
    return ConvexPolygon([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])


def record(landmark: Landmark) -> LandmarkRecord:
    return LandmarkRecord(landmark, PerceptualStrategy.for_class(landmark.landmark_class)[0], {}, 30.0, 0.5)


def world_of(meadows: list[tuple[str, ConvexPolygon, str]], landmarks: tuple[Landmark, ...]) -> MeadowMap:
    ids = [landmark.id for landmark in landmarks]
    return MeadowMap(
        [Meadow(name, polygon, terrain, tuple(ids)) for name, polygon, terrain in meadows],
        [record(landmark) for landmark in landmarks],
        terrain_table=TABLE,
    )


#: Two meadows side by side: concrete west of x = 10, gravel east of it.
WORLD = world_of([("west", box(0, -5, 10, 5), "concrete"), ("east", box(10, -5, 20, 5), "gravel")], LANDMARKS)


def start_map() -> SpatialUncertaintyMap:
    return SpatialUncertaintyMap.from_pose(START, 0.2, 0.03)


def manager_for(initial: SpatialUncertaintyMap | None = None, **settings: Any) -> UncertaintyMapManager:
    """A manager of WORLD; gate only unless told (outlier recovery: tests/manager/test_localizer.py)."""
    return UncertaintyMapManager(
        initial or start_map(), WORLD, TABLE, ManagerSettings(**{"robust": False, **settings})
    )


# --- observations synthesised from a pose ------------------------------------------------


def bearing_of(
    pose: Pose, landmark: VerticalLineLandmark, time: float, error: float = 0.01
) -> BearingObservation:
    bearing = math.atan2(landmark.y - pose.y, landmark.x - pose.x) - pose.heading
    return BearingObservation(landmark.id, time, bearing, error)


def range_bearing_of(
    pose: Pose, landmark: PointLandmark, time: float, error: float = 0.01, spread: float = 0.2
) -> RangeBearingObservation:
    distance = math.hypot(landmark.x - pose.x, landmark.y - pose.y)
    bearing = math.atan2(landmark.y - pose.y, landmark.x - pose.x) - pose.heading
    return RangeBearingObservation(
        landmark.id, time, bearing, error, max(distance - spread, 0.0), distance + spread
    )


def line_of(
    pose: Pose,
    landmark: GroundLineLandmark,
    time: float,
    offset_error: float = 0.05,
    angle_error: float = 0.01,
) -> GroundLineObservation:
    d = landmark.end - landmark.start
    q = np.array([pose.x, pose.y]) - landmark.start
    offset = float(d[0] * q[1] - d[1] * q[0]) / landmark.length
    return GroundLineObservation(
        landmark.id, time, offset, offset_error, landmark.direction - pose.heading, angle_error
    )


def assert_same_map(a: SpatialUncertaintyMap, b: SpatialUncertaintyMap) -> None:
    """Bit-exact equality of two maps."""
    assert a.polygon.vertices.shape == b.polygon.vertices.shape
    assert a.polygon.vertices.tobytes() == b.polygon.vertices.tobytes()
    assert a.center.tobytes() == b.center.tobytes()
    assert (a.wedge.center, a.wedge.cw, a.wedge.ccw) == (b.wedge.center, b.wedge.cw, b.wedge.ccw)


def board_with(*reports: tuple[float, TurnAndRun], observations: tuple[Observation, ...] = ()) -> Blackboard:
    board = Blackboard()
    board.post_reports(PositionReport(t, command) for t, command in reports)
    for observation in observations:
        board.identified.post(observation)
    return board


# --- growth to each observation, then reduction ------------------------------------------


def by_hand() -> tuple[list[SpatialUncertaintyMap], BearingObservation, RangeBearingObservation]:
    """Reports at t = 1, 2, 3, 4; a bearing at t = 2 and a range-bearing at t = 3.5, done by hand."""
    m = start_map()
    m = grow_through(m, WORLD, STRIDE, TABLE)
    m = grow_through(m, WORLD, STRIDE, TABLE)
    first = bearing_of(m.most_probable_pose(), POLE_NORTH, 2.0)
    reduced_first = m.reduce(first, POLE_NORTH).map
    m = grow_through(reduced_first, WORLD, STRIDE, TABLE)
    second = range_bearing_of(m.most_probable_pose(), CORNER, 3.5)
    reduced_second = m.reduce(second, CORNER).map
    final = grow_through(reduced_second, WORLD, STRIDE, TABLE)
    return [reduced_first, reduced_second, final], first, second


def test_grows_to_each_observation_then_reduces_as_by_hand() -> None:
    (after_first, after_second, final), first, second = by_hand()
    board = board_with(*[(float(t), STRIDE) for t in (1, 2, 3, 4)], observations=(second, first))  # any order
    manager = manager_for()
    step = manager.update(board, now=4.0)
    assert isinstance(step, ManagerStep)
    assert_same_map(step.map, final)
    assert step.map is manager.map
    assert [o.observation for o in step.accepted] == [first, second]
    assert step.rejected == ()
    assert step.outcomes[0].area_after == pytest.approx(after_first.area)
    assert step.outcomes[1].area_after == pytest.approx(after_second.area)
    assert step.outcomes[1].area_after < step.outcomes[1].area_before
    assert step.outcomes[0].wedge_width_after == after_first.wedge.width
    assert step.outcomes[0].wedge_width_after <= step.outcomes[0].wedge_width_before
    assert (step.time, step.grown_reports, step.state, step.lost_reason) == (4.0, 4, ManagerState.NOMINAL, "")
    assert (manager.consumed_reports, manager.map_time, manager.grown_reports) == (4, 4.0, 4)
    assert (manager.accepted_count, manager.rejected_count) == (2, 0)
    assert not board.identified


def test_the_update_records_are_those_the_public_constructors_build() -> None:
    # The manager builds its records through the slots (faster than the frozen __init__).
    _, first, second = by_hand()
    unknown = BearingObservation("nowhere", 3.0, 0.0, 0.01)
    board = board_with(*[(float(t), STRIDE) for t in (1, 2, 3, 4)], observations=(first, second, unknown))
    step = manager_for().update(board, now=4.0)
    assert [o.accepted for o in step.outcomes] == [True, False, True]
    for outcome in step.outcomes:
        rebuilt = ObservationOutcome(*(getattr(outcome, field.name) for field in fields(outcome)))
        assert rebuilt == outcome
        assert hash(rebuilt) == hash(outcome)
    public = ManagerStep(*(getattr(step, field.name) for field in fields(step)))
    assert repr(public) == repr(step)
    with pytest.raises(FrozenInstanceError, match="cannot assign"):
        step.outcomes[0].accepted = False  # type: ignore[misc]
    with pytest.raises(FrozenInstanceError, match="cannot assign"):
        step.time = 0.0  # type: ignore[misc]


@pytest.mark.parametrize("slice_width", [None, math.radians(2.0)])
def test_outcomes_keep_the_maps_and_take_their_areas_and_widths_from_them(slice_width: float | None) -> None:
    # The areas are read from the maps when asked: a sliced map's is a hull of every slice.
    _, first, second = by_hand()
    unknown = BearingObservation("nowhere", 3.0, 0.0, 0.01)
    board = board_with(*[(float(t), STRIDE) for t in (1, 2, 3, 4)], observations=(first, second, unknown))
    step = manager_for(slice_width=slice_width).update(board, now=4.0)
    accepted_first, rejected, accepted_second = step.outcomes
    assert rejected.map_before is rejected.map_after
    assert rejected.area_before == rejected.area_after == rejected.map_before.area
    for outcome in (accepted_first, accepted_second):
        assert outcome.map_after is not outcome.map_before
        assert outcome.map_after.is_sliced == outcome.map_before.is_sliced == (slice_width is not None)
        assert outcome.area_after == outcome.map_after.polygon.area <= outcome.area_before
        assert outcome.wedge_width_after == outcome.map_after.wedge.width <= outcome.wedge_width_before
    assert accepted_second.area_after < accepted_second.area_before
    # Between them the map grew (reports at t = 3): the second starts from a grown map.
    assert accepted_second.map_before.area > accepted_first.map_after.area


def test_split_updates_consume_each_report_once_and_give_the_same_map() -> None:
    (_, _, final), first, second = by_hand()
    board = board_with(*[(float(t), STRIDE) for t in (1, 2, 3, 4)], observations=(first, second))
    manager = manager_for()
    early = manager.update(board, now=2.5)  # reports 1, 2; the observation at t = 2
    assert (early.grown_reports, len(early.outcomes), len(board.identified)) == (2, 1, 1)
    again = manager.update(board, now=2.5)  # nothing new: nothing grown twice
    assert (again.grown_reports, again.outcomes) == (0, ())
    assert again.map is early.map
    late = manager.update(board, now=10.0)
    assert late.grown_reports == 2
    assert_same_map(late.map, final)
    assert manager.grown_reports == 4


def test_reports_and_observations_after_now_wait() -> None:
    board = board_with((1.0, STRIDE), (3.0, STRIDE))
    board.identified.post(BearingObservation("pole_north", 2.5, 0.5, 0.01))
    manager = manager_for()
    step = manager.update(board, now=2.0)
    assert (step.grown_reports, step.outcomes, len(board.identified)) == (1, (), 1)
    assert manager.map_time == 1.0


def test_each_piece_of_a_run_grows_with_its_meadows_terrain() -> None:
    initial = SpatialUncertaintyMap.from_pose(Pose(7.0, 0.0, 0.0), 0.1, 0.02)
    crossing = TurnAndRun(0.1, 7.0)  # concrete up to x = 10, gravel after
    step = manager_for(initial).update(board_with((1.0, crossing)), now=1.0)
    assert_same_map(step.map, grow_through(initial, WORLD, crossing, TABLE))
    concrete_only = initial.grow(crossing, TABLE["concrete"])
    assert step.map.area > concrete_only.area * 1.05  # gravel is rougher than concrete


def test_the_vertex_cap_holds_through_growth_across_meadows_and_reductions() -> None:
    initial = SpatialUncertaintyMap.from_pose(Pose(7.0, 0.0, 0.0), 0.1, 0.02)
    crossing = TurnAndRun(0.1, 7.0)
    truth = Pose(14.0, 0.7, 0.1)  # within the grown map: the reduction below keeps it
    coarse, fine = manager_for(initial, max_vertices=6), manager_for(initial)
    seen = (bearing_of(truth, POLE_NORTH, 1.0, 0.02),)
    steps = [m.update(board_with((1.0, crossing), observations=seen), now=1.0) for m in (coarse, fine)]
    grown = grow_through(initial, WORLD, crossing, TABLE, max_vertices=6)
    uncapped = grow_through(initial, WORLD, crossing, TABLE)
    assert len(grown.polygon.vertices) <= 6 < len(uncapped.polygon.vertices)
    assert_same_map(steps[0].map, grown.reduce(seen[0], POLE_NORTH, max_vertices=6).map)
    assert len(steps[0].map.polygon.vertices) <= 6
    assert coarse.settings.max_vertices == 6
    # Fewer vertices, a coarser outer approximation: looser here, and still sound.
    assert steps[0].map.area > steps[1].map.area
    assert steps[0].map.contains(truth)


# --- rejections --------------------------------------------------------------------------


def test_misidentified_landmark_is_rejected_and_counted_not_applied() -> None:
    grown = grow_through(start_map(), WORLD, STRIDE, TABLE)
    wrong = bearing_of(grown.most_probable_pose(), POLE_NORTH, 1.0)
    wrong = BearingObservation(wrong.landmark_id, 1.0, wrong.bearing + math.pi, 0.01)  # seen behind
    manager = manager_for()
    step = manager.update(board_with((1.0, STRIDE), observations=(wrong,)), now=1.0)
    (outcome,) = step.rejected
    assert not outcome.accepted
    assert outcome.reason is not None
    assert outcome.reason.inconsistent
    assert (outcome.area_before, outcome.wedge_width_before) == (
        outcome.area_after,
        outcome.wedge_width_after,
    )
    assert_same_map(step.map, grown)
    assert step.map.area > 0.1  # kept whole, not emptied
    assert dict(manager.rejected_counts) == {outcome.reason: 1}
    assert manager.accepted_count == 0


def test_unknown_id_wrong_class_and_stale_observations_are_rejected_with_reasons() -> None:
    board = board_with((1.0, STRIDE), (2.0, STRIDE))
    board.identified.post(BearingObservation("ghost_pole", 1.0, 0.3, 0.01))
    board.identified.post(RangeBearingObservation("pole_north", 1.0, 0.3, 0.01, 5.0, 6.0))  # a Class I pole
    manager = manager_for()
    step = manager.update(board, now=2.0)
    assert [o.reason for o in step.rejected] == [RejectReason.UNKNOWN_LANDMARK, RejectReason.CLASS_MISMATCH]
    board.identified.post(
        bearing_of(manager.map.most_probable_pose(), POLE_NORTH, 1.5)
    )  # the map is at t = 2
    late = manager.update(board, now=3.0)
    assert [o.reason for o in late.rejected] == [RejectReason.STALE]
    assert manager.rejected_counts == {
        RejectReason.UNKNOWN_LANDMARK: 1,
        RejectReason.CLASS_MISMATCH: 1,
        RejectReason.STALE: 1,
    }
    assert manager.rejected_count == 3
    with pytest.raises(TypeError, match="does not support item assignment"):
        manager.rejected_counts[RejectReason.STALE] = 0  # type: ignore[index]


def test_a_rejection_does_not_stop_later_observations() -> None:
    grown = grow_through(start_map(), WORLD, STRIDE, TABLE)
    good = line_of(grown.most_probable_pose(), EDGE, 1.0)
    step = manager_for().update(
        board_with((1.0, STRIDE), observations=(BearingObservation("ghost", 1.0, 0.0, 0.01), good)), now=1.0
    )
    assert [o.accepted for o in step.outcomes] == [False, True]
    assert_same_map(step.map, grown.reduce(good, EDGE).map)


# --- lost detection ----------------------------------------------------------------------


def test_lost_by_area_then_found_again_by_a_consistent_reduction() -> None:
    manager = manager_for(area_limit=2.0)
    board = Blackboard()
    states = []
    for t in range(1, 6):  # the area passes 2 m^2 after the fifth stride (see below)
        board.post_report(PositionReport(float(t), STRIDE))
        states.append(manager.update(board, now=float(t)).state)
    assert states[:4] == [ManagerState.NOMINAL] * 4
    assert states[4] is ManagerState.LOST
    assert manager.map.area > 2.0
    assert manager.should_stop_and_look
    assert manager.window_scale == 2.0
    assert "area" in manager.lost_reason
    # a misidentification is no landmark found: still lost
    board.identified.post(BearingObservation("pole_north", 5.0, 3.0, 0.001))
    assert manager.update(board, now=5.0).state is ManagerState.LOST
    board.identified.post(range_bearing_of(manager.map.most_probable_pose(), CORNER, 5.0))
    step = manager.update(board, now=5.0)
    assert len(step.accepted) == 1
    assert step.map.area < 2.0
    assert (step.state, step.lost_reason) == (ManagerState.NOMINAL, "")
    assert not manager.should_stop_and_look
    assert manager.window_scale == 1.0


def test_lost_while_the_area_stays_too_large_even_after_a_landmark() -> None:
    manager = manager_for(area_limit=0.25)
    board = board_with((1.0, STRIDE))
    assert manager.update(board, now=1.0).state is ManagerState.LOST
    board.identified.post(bearing_of(manager.map.most_probable_pose(), POLE_NORTH, 1.0, error=0.5))  # loose
    step = manager.update(board, now=1.0)
    assert len(step.accepted) == 1
    assert step.state is ManagerState.LOST


def test_lost_by_missed_predictions_persists_until_a_landmark_is_found() -> None:
    manager = manager_for(missed_limit=3, lost_window_scale=3.0)
    board = board_with((1.0, STRIDE))
    assert manager.update(board, now=1.0, missed_in_a_row=2).state is ManagerState.NOMINAL
    lost = manager.update(board, now=1.5, missed_in_a_row=3)
    assert lost.state is ManagerState.LOST
    assert "missed_limit 3" in lost.lost_reason
    assert manager.window_scale == 3.0
    # no evidence either way (the count is back to 0 but nothing was found): still lost
    assert manager.update(board, now=1.6, missed_in_a_row=0).state is ManagerState.LOST
    board.post_report(PositionReport(2.0, STRIDE))
    board.identified.post(
        bearing_of(grow_through(manager.map, WORLD, STRIDE, TABLE).most_probable_pose(), POLE_SOUTH, 2.0)
    )
    found = manager.update(board, now=2.0, missed_in_a_row=4)  # the count predates the identification
    assert (found.state, len(found.accepted)) == (ManagerState.NOMINAL, 1)
    assert manager.window_scale == 1.0


# --- robustness --------------------------------------------------------------------------


def test_an_update_that_fails_changes_nothing(monkeypatch: pytest.MonkeyPatch) -> None:
    start = start_map()
    manager = manager_for(start)
    board = board_with(
        (1.0, TurnAndRun(0.5, 0.0)), observations=(BearingObservation("pole_north", 1.0, 0.0, 0.1),)
    )

    def failing(*args: object, **kwargs: object) -> SpatialUncertaintyMap:
        raise InputError("growth: expected to fail here, got a test")

    monkeypatch.setattr("aura_ums.manager._map_manager.grow_through", failing)
    with pytest.raises(InputError, match="expected to fail here"):
        manager.update(board, now=1.0)
    assert manager.map is start
    assert (manager.consumed_reports, manager.map_time, manager.grown_reports) == (0, None, 0)
    assert len(board.identified) == 1


def test_a_different_blackboard_is_refused() -> None:
    manager = manager_for()
    manager.update(board_with((1.0, STRIDE), (2.0, STRIDE)), now=2.0)
    with pytest.raises(InputError, match=r"with at least 2 position reports \(consumed so far\), got 0"):
        manager.update(Blackboard(), now=3.0)
    with pytest.raises(InputError, match=r"whose report 1 is at t=2\.0, got t=5\.0"):
        manager.update(board_with((1.0, STRIDE), (5.0, STRIDE)), now=6.0)


def test_an_update_to_before_the_maps_time_is_refused_and_changes_nothing() -> None:
    """A clock that went back is told, not answered with the map as it was."""
    manager = manager_for()
    board = board_with((1.0, STRIDE), (2.0, STRIDE))
    grown = manager.update(board, now=2.0).map
    with pytest.raises(
        InputError, match=r"^now: expected a time at or after the map's \(2\.0 s, .*\), got 1\.5$"
    ):
        manager.update(board, now=1.5)
    assert manager.map is grown
    assert manager.map_time == 2.0
    assert manager.update(board, now=2.0).map is grown  # the same time again is no change


def test_an_update_to_before_the_last_update_is_refused_with_no_report_grown() -> None:
    """Before any report the map has no time; the steps still must not go back (gave step.time 1.0)."""
    manager = manager_for()
    board = Blackboard()
    assert manager.update(board, now=5.0).time == 5.0
    assert manager.map_time is None
    with pytest.raises(
        InputError, match=r"^now: expected a time at or after the last update's \(5\.0 s\), got 1\.0$"
    ):
        manager.update(board, now=1.0)
    assert manager.update(board, now=5.0).time == 5.0  # the same time again is fine


def test_bad_arguments_are_refused() -> None:
    with pytest.raises(InputError, match="initial_map: expected a SpatialUncertaintyMap, got Pose"):
        UncertaintyMapManager(START, WORLD, TABLE)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="meadow_map: expected a MeadowMap, got dict"):
        UncertaintyMapManager(start_map(), {}, TABLE)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="table: expected a TerrainTable, got dict"):
        UncertaintyMapManager(start_map(), WORLD, {})  # type: ignore[arg-type]
    manager = manager_for()
    with pytest.raises(InputError, match="blackboard: expected a Blackboard, got IdentifiedLandmarkBuffer"):
        manager.update(Blackboard().identified, now=1.0)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="now: expected a finite number, got nan"):
        manager.update(Blackboard(), now=math.nan)
    with pytest.raises(InputError, match="missed_in_a_row: expected a non-negative integer, got -1"):
        manager.update(Blackboard(), now=1.0, missed_in_a_row=-1)
    assert "nominal" in repr(manager)


# --- save and restore --------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Event:
    """One step of a scripted run: what is posted, then the update."""

    reports: tuple[PositionReport, ...]
    observations: tuple[Observation, ...]
    now: float
    missed: int


def scripted_run(seed: int, steps: int) -> list[Event]:
    """A true trajectory east along the two meadows, with observations of it (and one wrong one)."""
    rng = np.random.default_rng(seed)
    truth = START
    events = []
    for k in range(1, steps + 1):
        command = TurnAndRun(float(rng.uniform(-0.05, 0.05)), 1.4)
        terrain = WORLD.meadow_at(truth.x, truth.y)
        assert terrain is not None
        truth = TABLE[terrain.terrain].sample_motion(truth, command, rng, truncate=3.0)
        t = float(k)
        observations: list[Observation] = []
        if k % 3 == 0:
            observations.append(bearing_of(truth, POLE_NORTH if k < 6 else POLE_SOUTH, t))
        if k % 4 == 0:
            observations.append(line_of(truth, EDGE, t))
        if k == 5:
            observations.append(BearingObservation("pole_north", t, -2.0, 0.01))  # misidentified
        if k == 6:
            observations.append(BearingObservation("ghost", t + 0.5, 0.0, 0.01))  # waits for the next update
        events.append(Event((PositionReport(t, command),), tuple(observations), t, 3 if k in (7, 8) else 0))
    return events


def play(manager: UncertaintyMapManager, board: Blackboard, events: list[Event]) -> list[ManagerStep]:
    steps = []
    for event in events:
        board.post_reports(event.reports)
        for observation in event.observations:
            board.identified.post(observation)
        steps.append(manager.update(board, now=event.now, missed_in_a_row=event.missed))
    return steps


def test_save_half_way_restore_and_continue_gives_the_same_map_bit_for_bit() -> None:
    events = scripted_run(seed=11, steps=10)
    whole = manager_for(area_limit=3.0)
    whole_board = Blackboard()
    uninterrupted = play(whole, whole_board, events)
    assert {s.state for s in uninterrupted} == {ManagerState.NOMINAL, ManagerState.LOST}  # a varied run
    assert whole.accepted_count >= 3
    assert whole.rejected_count >= 2

    first = manager_for(area_limit=3.0)
    first_board = Blackboard()
    play(first, first_board, events[:6])
    # something is pending: a future observation in the buffer, a report not yet consumed, commands
    first_board.post_report(PositionReport(6.25, TurnAndRun(0.0, 0.0)))
    first_board.push_command(TurnAndRun(0.0, 1.4))
    saved_manager, saved_board = first.to_json(), first_board.to_json()
    del first, first_board

    manager = UncertaintyMapManager.from_json(saved_manager, WORLD, TABLE)
    board = Blackboard.from_json(saved_board)
    assert len(board.identified) == 1
    assert board.pending_commands == (TurnAndRun(0.0, 1.4),)
    resumed = play(manager, board, events[6:])

    # the reference run had no extra zero-motion report: replay it that way too
    reference = manager_for(area_limit=3.0)
    reference_board = Blackboard()
    play(reference, reference_board, events[:6])
    reference_board.post_report(PositionReport(6.25, TurnAndRun(0.0, 0.0)))
    expected = play(reference, reference_board, events[6:])

    assert_same_map(resumed[-1].map, expected[-1].map)
    assert [s.state for s in resumed] == [s.state for s in expected]
    assert manager.to_json() == reference.to_json()
    assert (manager.accepted_count, dict(manager.rejected_counts), manager.grown_reports) == (
        reference.accepted_count,
        dict(reference.rejected_counts),
        reference.grown_reports,
    )


def test_restore_of_the_uninterrupted_script_matches_every_step() -> None:
    events = scripted_run(seed=5, steps=9)
    whole = manager_for(area_limit=3.0)
    uninterrupted = play(whole, Blackboard(), events)
    for cut in (0, 4, 8):
        manager, board = manager_for(area_limit=3.0), Blackboard()
        play(manager, board, events[:cut])
        manager = UncertaintyMapManager.from_json(manager.to_json(), WORLD, TABLE)
        board = Blackboard.from_json(board.to_json())
        rest = play(manager, board, events[cut:])
        for got, want in zip(rest, uninterrupted[cut:], strict=True):
            assert_same_map(got.map, want.map)
            assert got.state is want.state
            assert [o.reason for o in got.outcomes] == [o.reason for o in want.outcomes]


def test_round_trip_keeps_settings_state_and_counters() -> None:
    manager = manager_for(sigmas=2.5, area_limit=0.2, missed_limit=4, lost_window_scale=1.5)
    board = board_with((1.0, STRIDE), observations=(BearingObservation("ghost", 1.0, 0.0, 0.01),))
    manager.update(board, now=1.0)
    again = UncertaintyMapManager.from_json(manager.to_json(), WORLD, TABLE)
    assert again.settings == manager.settings
    assert (again.settings.sigmas, again.settings.area_limit, again.window_scale) == (2.5, 0.2, 1.5)
    assert (again.state, again.lost_reason) == (ManagerState.LOST, manager.lost_reason)
    assert (again.consumed_reports, again.map_time, again.grown_reports) == (1, 1.0, 1)
    assert again.rejected_counts == {RejectReason.UNKNOWN_LANDMARK: 1}
    assert_same_map(again.map, manager.map)
    assert again.to_json() == manager.to_json()
    fresh = UncertaintyMapManager.from_json(manager_for().to_json(), WORLD, TABLE)
    assert (fresh.settings.area_limit, fresh.map_time, fresh.consumed_reports) == (None, None, 0)


def test_a_wedge_centre_that_rewrapping_would_move_is_restored_exactly() -> None:
    heading = next(h for h in np.linspace(0.01, 0.5, 1000).tolist() if wrap_angle(h) != h)
    data = json.loads(manager_for().to_json())
    data["map"]["wedge"]["center"] = heading
    again = UncertaintyMapManager.from_json(json.dumps(data), WORLD, TABLE)
    assert again.map.wedge.center == heading
    assert json.loads(again.to_json())["map"]["wedge"]["center"] == heading


def test_a_polygon_with_collinear_vertices_is_restored_exactly() -> None:
    # A vertex on an edge: the public constructor would drop it, the saved map kept it.
    rows = [[1.0, -1.0], [2.0, -1.0], [3.0, -1.0], [3.0, 1.0], [1.0, 1.0]]
    assert len(ConvexPolygon(rows).vertices) == 4
    data = json.loads(manager_for().to_json())
    data["map"]["vertices"] = rows
    again = UncertaintyMapManager.from_json(json.dumps(data), WORLD, TABLE)
    assert again.map.polygon.vertices.tolist() == rows
    assert not again.map.polygon.vertices.flags.writeable
    assert json.loads(again.to_json())["map"] == data["map"]
    step = again.update(board_with((1.0, STRIDE)), now=1.0)  # and it goes on from there
    assert step.grown_reports == 1


def test_a_run_shorter_than_the_split_tolerance_grows_on_the_start_meadow() -> None:
    for run in (0.0, 5e-324, 1e-12, RUN_TOLERANCE):
        command = TurnAndRun(0.2, run)
        step = manager_for().update(board_with((1.0, command)), now=1.0)
        assert_same_map(step.map, start_map().grow(command, TABLE["concrete"]))
    crossing = TurnAndRun(0.0, 2 * RUN_TOLERANCE)  # long enough for grow_through
    step = manager_for().update(board_with((1.0, crossing)), now=1.0)
    assert_same_map(step.map, grow_through(start_map(), WORLD, crossing, TABLE))


def manager_document() -> dict[str, object]:
    manager = manager_for(area_limit=5.0)
    manager.update(
        board_with((1.0, STRIDE), observations=(BearingObservation("ghost", 1.0, 0.0, 0.01),)), now=1.0
    )
    result: dict[str, object] = json.loads(manager.to_json())
    return result


def edited(path: str, value: object) -> str:
    data = manager_document()
    target: object = data
    *keys, last = path.split("/")
    for key in keys:
        target = target[int(key)] if isinstance(target, list) else target[key]  # type: ignore[index]
    if value is KeyError:
        del target[last]  # type: ignore[attr-defined]
    elif isinstance(target, list):
        target[int(last)] = value
    else:
        target[last] = value  # type: ignore[index]
    return json.dumps(data)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("not json", r"<manager JSON>:1:1: expected valid JSON"),
        (
            '{"format": "aura-ums/blackboard", "version": 1}',
            r"format: expected 'aura-ums/uncertainty-map-manager'",
        ),
        (edited("map", KeyError), r"<manager JSON>: expected a key 'map', got none"),
        (edited("map/vertices", []), r"map\.vertices: expected at least one vertex, got none"),
        (edited("map/vertices/0", [1.0]), r"map\.vertices\[0\]: expected \[x, y\], got 1 numbers"),
        (
            edited("map/vertices/2/1", "north"),
            r"map\.vertices\[2\]\[1\]: expected a finite number, got 'north'",
        ),
        (
            edited("map/vertices/0", [30.0, -30.0]),
            r"map\.vertices: .*expected a convex counter-clockwise polygon",
        ),
        (edited("map/center", [40.0, 0.0]), r"map\.center: center: expected a point inside the polygon"),
        (edited("map/wedge/cw", -0.1), r"map\.wedge\.cw: expected a number in \[0, 1000\] rad, got -0\.1"),
        (
            edited("map/wedge/ccw", 1e300),
            r"map\.wedge\.ccw: expected a number in \[0, 1000\] rad, got 1e\+300",
        ),
        (edited("settings/area_limit", 1e300), r"settings\.area_limit: expected a number in \(0, 4e\+12\]"),
        (edited("map/wedge/center", 4.0), r"map\.wedge\.center: expected a heading in \(-pi, pi\], got 4\.0"),
        (edited("map/wedge/spin", 0.0), r"map\.wedge: expected only the keys"),
        (edited("version", True), r"version: expected 1, got true"),  # JSON true == 1 in Python
        (edited("state", "confused"), r"state: expected one of \['nominal', 'lost'\], got 'confused'"),
        (edited("consumed_reports", -1), r"consumed_reports: expected an integer >= 0, got -1"),
        (edited("consumed_reports", 1.5), r"consumed_reports: expected an integer >= 0, got 1\.5"),
        (edited("map_time", None), r"map_time: expected null exactly when consumed_reports is 0"),
        (
            edited("counters/rejected/unknown landmark id", "one"),
            r"counters\.rejected\['unknown landmark id'\]",
        ),
        (edited("counters/accepted", None), r"counters\.accepted: expected an integer >= 0, got null"),
        (edited("settings/sigmas", -3.0), r"settings\.sigmas: expected a number in \[0\.1, 100\], got -3\.0"),
        (edited("settings/missed_limit", 0), r"settings\.missed_limit: expected an integer >= 1, got 0"),
        (
            edited("settings/area_limit", "big"),
            r"settings\.area_limit: expected a number in \(0, 4e\+12\] or none, got 'big'",
        ),
        (edited("settings/sigma", 3.0), r"settings\.sigma: expected a field of ManagerSettings \(sigmas, "),
        (
            edited("settings/relocalize_after", 2),
            r"settings\.relocalize_window: expected an integer >= relocalize_after \(2\), got 1",
        ),
        (
            edited("counters/rejected/no such reason", 1),
            r"counters\.rejected\['no such reason'\]: expected one of \[\"observation older",
        ),
        (edited("envelope", {"map": None}), r"envelope: expected null \(settings\.robust is false\)"),
        (edited("lost_reason", 3), r"lost_reason: expected a string, got 3"),
        (
            json.dumps(manager_document()).replace("5.0", "Infinity"),
            r"expected valid JSON, got the non-standard number Infinity",
        ),
    ],
)
def test_malformed_manager_json_names_what_is_wrong(text: str, message: str) -> None:
    with pytest.raises(FileFormatError, match=message):
        UncertaintyMapManager.from_json(text, WORLD, TABLE)


def test_restore_needs_the_long_term_memory() -> None:
    text = manager_for().to_json()
    with pytest.raises(InputError, match="meadow_map: expected a MeadowMap, got NoneType"):
        UncertaintyMapManager.from_json(text, None, TABLE)  # type: ignore[arg-type]
    with pytest.raises(FileFormatError, match=r"^saved\.json: version: expected 1, got 2$"):
        UncertaintyMapManager.from_json(
            text.replace('"version": 1', '"version": 2'), WORLD, TABLE, source="saved.json"
        )


# --- soundness over random runs ----------------------------------------------------------

#: Landmarks of all three classes around the origin of one large meadow.
FIELD_LANDMARKS: tuple[Landmark, ...] = (
    VerticalLineLandmark("p1", 25.0, 20.0, 0.0, 4.0),
    VerticalLineLandmark("p2", -20.0, 30.0, 0.0, 4.0),
    VerticalLineLandmark("p3", 5.0, -35.0, 0.0, 4.0),
    PointLandmark("c1", -30.0, -25.0, 2.5),
    GroundLineLandmark("g1", (-60.0, 45.0), (60.0, 45.0)),
    GroundLineLandmark("g2", (50.0, -60.0), (50.0, 60.0)),
)
FIELDS = {name: world_of([("field", box(-100, -100, 100, 100), name)], FIELD_LANDMARKS) for name in TABLE}


def observe(pose: Pose, landmark: Landmark, time: float, rng: np.random.Generator) -> Observation:
    """An observation of the true pose, noisy but within its stated bounds."""
    u = float(rng.uniform(-0.99, 0.99))
    if isinstance(landmark, VerticalLineLandmark):
        exact = bearing_of(pose, landmark, time, error=0.02)
        return BearingObservation(exact.landmark_id, time, exact.bearing + u * 0.02, 0.02)
    if isinstance(landmark, PointLandmark):
        exact_rb = range_bearing_of(pose, landmark, time, error=0.02, spread=0.5)
        shift = float(rng.uniform(-0.4, 0.4))
        return RangeBearingObservation(
            landmark.id,
            time,
            exact_rb.bearing + u * 0.02,
            0.02,
            max(exact_rb.range_min + shift, 0.0),
            exact_rb.range_max + shift,
        )
    exact_line = line_of(pose, landmark, time, offset_error=0.1, angle_error=0.02)
    return GroundLineObservation(
        landmark.id, time, exact_line.offset + u * 0.1, 0.1, exact_line.angle - u * 0.02, 0.02
    )


@settings(deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    terrain=st.sampled_from(sorted(TABLE)),
    commands=st.lists(st.tuples(st.floats(-1.0, 1.0), st.floats(0.0, 3.0)), min_size=1, max_size=12),
    seen=st.lists(st.integers(-1, len(FIELD_LANDMARKS) - 1), min_size=12, max_size=12),
    stride=st.integers(1, 3),
    cap=st.sampled_from([3, 5, 16, 64]),
)
def test_the_map_contains_the_true_pose_after_any_run(
    seed: int, terrain: str, commands: list[tuple[float, float]], seen: list[int], stride: int, cap: int
) -> None:
    rng = np.random.default_rng(seed)
    truth = Pose(float(rng.uniform(-3, 3)), float(rng.uniform(-3, 3)), float(rng.uniform(-math.pi, math.pi)))
    guess = Pose(truth.x + 0.1, truth.y - 0.1, truth.heading + 0.02)
    initial = SpatialUncertaintyMap.from_pose(guess, 0.3, 0.05)
    manager = UncertaintyMapManager(
        initial, FIELDS[terrain], TABLE, ManagerSettings(sigmas=3.0, max_vertices=cap)
    )
    # Growth caps the polygons it moves; one that no motion moved keeps its vertices.
    most = max(cap, len(initial.polygon.vertices))
    board = Blackboard()
    for k, (turn, run) in enumerate(commands, start=1):
        command = TurnAndRun(turn, run)
        truth = TABLE[terrain].sample_motion(truth, command, rng, truncate=3.0)
        board.post_report(PositionReport(float(k), command))
        if seen[k - 1] >= 0:
            board.identified.post(observe(truth, FIELD_LANDMARKS[seen[k - 1]], float(k), rng))
        if k % stride == 0 or k == len(commands):
            step = manager.update(board, now=float(k))
            assert step.rejected == (), [o.reason for o in step.rejected]
            assert step.map.contains(truth), (k, truth, step.map)
            assert step.envelope_map is not None  # the default: with outlier recovery
            assert step.envelope_map.contains(truth)
            assert not step.relocalized
            assert len(step.map.polygon.vertices) <= most


def test_a_run_from_an_estimate_outside_every_meadow_grows_on_every_terrain_it_may_be_on() -> None:
    # The estimate lies beyond reach of mapped free space (the meadow map knows no walls):
    # a robot outside every meadow moves on the terrain of the meadow it was last in, which
    # the manager cannot know, so it grows on the outer terrain of all of them, not give up.
    outside = SpatialUncertaintyMap.from_pose(Pose(2.0, 10.5, math.pi / 2), 0.1, 0.01)
    manager = UncertaintyMapManager(outside, WORLD, TABLE)
    board = Blackboard()
    board.post_report(PositionReport(1.0, TurnAndRun(0.0, 2.0)))
    step = manager.update(board, now=1.0)
    every = outer_terrain([TABLE["concrete"], TABLE["gravel"]], 1, TurnAndRun(0.0, 2.0), 3.0)
    expected = outside.grow(TurnAndRun(0.0, 2.0), every)
    assert np.array_equal(step.map.polygon.vertices, expected.polygon.vertices)
    for name in ("concrete", "gravel"):
        one = outside.grow(TurnAndRun(0.0, 2.0), TABLE[name])
        assert step.map.polygon.contains(one.polygon.vertices).all(), name
    assert manager.grown_reports == 1


def test_a_terrain_missing_from_the_table_is_refused_when_the_manager_is_made() -> None:
    """Not at the first run through that meadow, in the middle of a live run: naming the meadow."""
    only = Meadow("only", box(0, -5, 20, 5), "marsh", tuple(landmark.id for landmark in LANDMARKS))
    world = MeadowMap([only], [record(landmark) for landmark in LANDMARKS])  # no table to check against
    with pytest.raises(
        UnknownTerrainError,
        match=r"^table: expected the terrain 'marsh' of the meadow 'only' of meadow_map, got ",
    ):
        UncertaintyMapManager(start_map(), world, TABLE)


def test_a_one_meadow_manager_grows_as_the_map_does_on_its_terrain() -> None:
    """Report after report, the manager's map is the map grown by each command on the meadow's terrain."""
    world = world_of([("only", box(-50, -50, 50, 50), "gravel")], LANDMARKS)
    manager = UncertaintyMapManager(start_map(), world, TABLE, ManagerSettings(sigmas=2.5))
    board, expected = Blackboard(), start_map()
    for k, command in enumerate([TurnAndRun(0.3, 1.0), TurnAndRun(-0.2, 0.0), TurnAndRun(0.0, 2.0)]):
        board.post_report(PositionReport(float(k + 1), command))
        expected = expected.grow(command, TABLE["gravel"], sigmas=2.5)
        grown = manager.update(board, now=float(k + 1)).map
        assert grown.polygon.vertices.tobytes() == expected.polygon.vertices.tobytes()
        assert grown.wedge == expected.wedge
        assert grown.center.tolist() == expected.center.tolist()


# --- observations of one instant, reduced together ---------------------------------------

#: Lost in the west meadow: any heading.
LOST_HERE = SpatialUncertaintyMap.from_polygon(box(1, -4, 9, 4), (5.0, 0.0), HeadingWedge.full_circle(0.0))
TRUTH_HERE = Pose(4.0, 1.0, 2.5)


def instant(*landmarks: VerticalLineLandmark, time: float = 0.0) -> tuple[Observation, ...]:
    return tuple(bearing_of(TRUTH_HERE, landmark, time, 0.02) for landmark in landmarks)


def test_observations_of_one_instant_reduce_together_while_the_heading_is_wide_open() -> None:
    seen = instant(POLE_NORTH, POLE_SOUTH)
    joint = manager_for(LOST_HERE).update(board_with(observations=seen), now=0.0)
    one_by_one = manager_for(LOST_HERE, joint_above=None).update(board_with(observations=seen), now=0.0)
    expected = reduce_jointly(LOST_HERE, [(seen[0], POLE_NORTH), (seen[1], POLE_SOUTH)])
    assert_same_map(joint.map, expected.map)
    assert joint.map.contains(TRUTH_HERE)
    assert one_by_one.map.contains(TRUTH_HERE)
    assert one_by_one.map.area == LOST_HERE.area  # each bearing alone: no position learnt
    assert joint.map.wedge.width < 0.8 * one_by_one.map.wedge.width
    assert joint.map.area < 0.3 * one_by_one.map.area
    # Both accepted, sharing the joint reduction's figures.
    assert [o.accepted for o in joint.outcomes] == [True, True]
    assert {(o.area_before, o.area_after, o.wedge_width_after) for o in joint.outcomes} == {
        (LOST_HERE.area, expected.area_after, expected.map.wedge.width)
    }
    # Observations at different instants, or a narrow wedge, are reduced one by one.
    apart = (bearing_of(TRUTH_HERE, POLE_NORTH, 0.0, 0.02), bearing_of(TRUTH_HERE, POLE_SOUTH, 0.5, 0.02))
    step = manager_for(LOST_HERE).update(board_with(observations=apart), now=1.0)
    assert_same_map(step.map, one_by_one.map)
    narrow = manager_for(LOST_HERE, joint_above=2 * math.pi)
    assert_same_map(narrow.update(board_with(observations=seen), now=0.0).map, one_by_one.map)


def test_a_joint_instant_still_rejects_unknown_ids_and_falls_back_when_no_heading_agrees() -> None:
    seen = (*instant(POLE_NORTH), BearingObservation("ghost", 0.0, 0.0, 0.01), *instant(POLE_SOUTH))
    manager = manager_for(LOST_HERE)
    step = manager.update(board_with(observations=seen), now=0.0)
    assert [(o.accepted, o.reason) for o in step.outcomes] == [
        (True, None),
        (False, RejectReason.UNKNOWN_LANDMARK),
        (True, None),
    ]
    assert step.map.area < 0.5 * LOST_HERE.area  # the two poles together
    assert manager.rejected_counts == {RejectReason.UNKNOWN_LANDMARK: 1}
    # The south pole where the truth cannot see it with the north one: no heading agrees
    # with both, so each is taken alone and the consistency gate decides.
    north = bearing_of(TRUTH_HERE, POLE_NORTH, 0.0, 0.02)
    wrong = (north, BearingObservation("pole_south", 0.0, north.bearing, 0.0))
    assert not reduce_jointly(LOST_HERE, [(wrong[0], POLE_NORTH), (wrong[1], POLE_SOUTH)]).consistent
    manager = manager_for(LOST_HERE)
    alone = manager.update(board_with(observations=wrong), now=0.0)
    one_by_one = manager_for(LOST_HERE, joint_above=None)
    assert_same_map(alone.map, one_by_one.update(board_with(observations=wrong), now=0.0).map)
    assert alone.outcomes[0].accepted


def test_joint_settings_are_saved_and_an_older_document_restores_without_them() -> None:
    manager = manager_for(joint_above=1.0, joint_sector=0.2)
    again = UncertaintyMapManager.from_json(manager.to_json(), WORLD, TABLE)
    assert (again.settings.joint_above, again.settings.joint_sector) == (1.0, 0.2)
    assert (manager_for().settings.joint_above, manager_for().settings.joint_sector) == (
        math.pi / 2,
        ManagerSettings().joint_sector,
    )
    document = json.loads(manager.to_json())
    del document["settings"]["joint_above"], document["settings"]["joint_sector"]
    older = UncertaintyMapManager.from_json(json.dumps(document), WORLD, TABLE)
    # As such a manager ran: one by one.
    assert (older.settings.joint_above, older.settings.joint_sector) == (None, ManagerSettings().joint_sector)


def test_the_vertex_cap_is_saved_and_an_older_document_restores_the_default() -> None:
    manager = manager_for(max_vertices=12)
    assert UncertaintyMapManager.from_json(manager.to_json(), WORLD, TABLE).settings.max_vertices == 12
    document = json.loads(manager.to_json())
    del document["settings"]["max_vertices"]
    older = UncertaintyMapManager.from_json(json.dumps(document), WORLD, TABLE)
    default = ManagerSettings().max_vertices
    assert older.settings.max_vertices == default == manager_for().settings.max_vertices
    document["settings"]["max_vertices"] = 2
    with pytest.raises(FileFormatError, match=r"settings\.max_vertices: expected an integer >= 3, got 2"):
        UncertaintyMapManager.from_json(json.dumps(document), WORLD, TABLE)


def test_a_manager_reading_a_board_that_forgot_what_it_consumed_grows_the_same_map() -> None:
    commands = [TurnAndRun(0.05 * (k % 3), 0.4) for k in range(12)]
    maps: list[tuple[list[list[float]], HeadingWedge]] = []
    for forgetting in (False, True):
        manager, board = manager_for(), Blackboard()
        for k, command in enumerate(commands):
            board.post_report(PositionReport(float(k + 1), command))
            if k % 2:
                grown = manager.update(board, now=float(k + 1)).map
                maps.append((grown.polygon.vertices.tolist(), grown.wedge))
                if forgetting:  # all but the last consumed report, which the manager checks
                    board.forget_reports_before(manager.consumed_reports - 1)
    assert maps[: len(maps) // 2] == maps[len(maps) // 2 :]
    board = Blackboard()
    board.post_reports(PositionReport(float(t), TurnAndRun(0.0, 0.1)) for t in (1.0, 2.0, 3.0))
    manager = manager_for()
    manager.update(board, now=2.0)
    board.forget_reports_before(2)  # the last consumed report (index 1) is gone
    with pytest.raises(
        InputError, match=r"keeping its last consumed report 1, got one that forgot the reports before 2"
    ):
        manager.update(board, now=3.0)
