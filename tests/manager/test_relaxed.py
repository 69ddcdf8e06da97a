"""The q-relaxed intersection: the truth stays inside when at most q of any N consecutive are wrong."""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import pytest

from aura_ums import MapProfile
from aura_ums.errors import FileFormatError, InputError
from aura_ums.expecter import PerceptualStrategy
from aura_ums.geometry import ConvexPolygon
from aura_ums.manager import (
    Blackboard,
    ManagerSettings,
    ManagerStep,
    PositionReport,
    RejectReason,
    UncertaintyMapManager,
    _relaxed,
)
from aura_ums.manager._relaxed import Branch, RelaxedState
from aura_ums.manager._relaxed import grow as relaxed_grow
from aura_ums.uncertainty import (
    BearingObservation,
    Observation,
    PointLandmark,
    Pose,
    RangeBearingObservation,
    SpatialUncertaintyMap,
    TerrainTable,
    TurnAndRun,
    VerticalLineLandmark,
)
from aura_ums.world import LandmarkRecord, Meadow, MeadowMap

FLOOR = TerrainTable({"floor": TerrainTable.default()["tile"]})
POLES = (
    VerticalLineLandmark("north_west", 4.0, 9.0, 0.0, 4.0),
    VerticalLineLandmark("north_east", 16.0, 8.0, 0.0, 4.0),
    VerticalLineLandmark("south", 10.0, -7.0, 0.0, 4.0),
    VerticalLineLandmark("far_east", 26.0, 1.0, 0.0, 4.0),
)
WORLD = MeadowMap(
    [
        Meadow(
            "floor",
            ConvexPolygon([(-5, -10), (30, -10), (30, 12), (-5, 12)]),
            "floor",
            tuple(p.id for p in POLES),
        )
    ],
    [
        LandmarkRecord(pole, PerceptualStrategy.for_class(pole.landmark_class)[0], {}, 50.0, 0.5)
        for pole in POLES
    ],
)
START_POSE = Pose(2.0, 0.0, 0.0)
START = SpatialUncertaintyMap.from_pose(START_POSE, 0.6, 0.15)
STRIDE = TurnAndRun(0.0, 1.0)
ERROR = 0.02


def bearing(pose: Pose, x: float, y: float, pole: VerticalLineLandmark) -> float:
    return math.atan2(pole.y - y, pole.x - x) - pose.heading


def wrong_bearing(truth: Pose, around: SpatialUncertaintyMap, pole: VerticalLineLandmark) -> float | None:
    """The bearing seen from the vertex of ``around`` that makes it most wrong, if wrong by > 2 bounds.

    Seen from a position the map still holds, it is consistent with the map: a gate cannot
    tell it from a good one. It excludes the truth.
    """
    true = bearing(truth, truth.x, truth.y, pole)
    best, worst = None, 0.0
    for x, y in around.polygon.vertices.tolist():
        seen = bearing(truth, x, y, pole)
        off = abs(math.remainder(seen - true, 2 * math.pi))
        if off > worst:
            best, worst = seen, off
    return best if worst > 2.5 * ERROR else None


def drive(
    settings: ManagerSettings, rng: np.random.Generator, steps: int, wrong_per_step: int
) -> tuple[list[ManagerStep], list[Pose], list[bool]]:
    """Walk east a metre a step seeing every pole; the first ``wrong_per_step`` sightings made wrong.

    Returns the steps, the true poses and, per sighting in order, whether it was wrong.
    """
    manager = UncertaintyMapManager(START, WORLD, FLOOR, settings)
    board = Blackboard()
    truth, results, truths, wrong = START_POSE, [], [], []
    for k in range(1, steps + 1):
        before = manager.map
        truth = Pose(truth.x + 1.0, truth.y, truth.heading)
        board.post_report(PositionReport(float(k), STRIDE))
        moved = SpatialUncertaintyMap.from_polygon(
            before.polygon.translated(1.0, 0.0), before.center + np.array([1.0, 0.0]), before.wedge
        )
        for index, pole in enumerate(POLES):
            seen = bearing(truth, truth.x, truth.y, pole) + rng.uniform(-0.9, 0.9) * ERROR
            made_wrong = False
            if index < wrong_per_step:
                fake = wrong_bearing(truth, moved, pole)
                if fake is not None:
                    seen, made_wrong = fake, True
            wrong.append(made_wrong)
            board.identified.post(BearingObservation(pole.id, float(k), seen, ERROR))
        results.append(manager.update(board, now=float(k)))
        truths.append(truth)
    return results, truths, wrong


def at_most(wrong: list[bool], q: int, n: int) -> bool:
    """Whether at most ``q`` of any ``n`` consecutive sightings are wrong."""
    flags = np.asarray(wrong, dtype=int)
    if len(flags) < n:
        return int(flags.sum()) <= q
    return bool(np.convolve(flags, np.ones(n, dtype=int), mode="valid").max() <= q)


@pytest.mark.parametrize(("q", "window", "wrong_per_step"), [(1, 4, 1), (2, 4, 2), (2, 8, 1)])
@pytest.mark.parametrize("seed", range(6))
def test_the_truth_stays_inside_when_at_most_q_of_any_n_are_wrong(
    q: int, window: int, wrong_per_step: int, seed: int
) -> None:
    settings = ManagerSettings(relaxed_q=q, relaxed_window=window)
    # Four sightings a step, the first ones wrong: one a step is one in any four and two in
    # any eight; two a step are two in any four.
    steps, truths, wrong = drive(settings, np.random.default_rng(seed), 10, wrong_per_step)
    assert at_most(wrong, q, window)
    assert sum(wrong) >= 8 * wrong_per_step
    for step, truth in zip(steps, truths, strict=True):
        assert step.map.contains(truth), (step.time, step.map, truth)
        assert not step.relocalized


@pytest.mark.parametrize("seed", range(6))
def test_without_relaxation_the_same_wrong_sightings_remove_the_truth(seed: int) -> None:
    # The test above can fail: the gate alone (q = 0) loses the truth to the same injection.
    steps, truths, wrong = drive(ManagerSettings(), np.random.default_rng(seed), 10, 1)
    assert any(wrong)
    assert not all(step.map.contains(truth) for step, truth in zip(steps, truths, strict=True))
    assert all(not step.excluded for step in steps)


@pytest.mark.parametrize("slice_width", [None, math.radians(2.0)])
def test_the_focus_map_lies_in_the_map_and_takes_the_truth_back_once_the_wrong_sighting_leaves(
    slice_width: float | None,
) -> None:
    settings = ManagerSettings(relaxed_q=1, relaxed_window=4, slice_width=slice_width)
    manager = UncertaintyMapManager(START, WORLD, FLOOR, settings)
    board = Blackboard()
    rng = np.random.default_rng(7)
    truth, lost_at = START_POSE, []
    for k in range(1, 9):
        truth = Pose(truth.x + 1.0, truth.y, truth.heading)
        board.post_report(PositionReport(float(k), STRIDE))
        before = manager.map
        moved = SpatialUncertaintyMap.from_polygon(
            before.polygon.translated(1.0, 0.0), before.center + np.array([1.0, 0.0]), before.wedge
        )
        for index, pole in enumerate(POLES):
            seen = bearing(truth, truth.x, truth.y, pole) + rng.uniform(-0.9, 0.9) * ERROR
            fake = wrong_bearing(truth, moved, pole) if (k == 5 and index == 0) else None
            seen = seen if fake is None else fake
            board.identified.post(BearingObservation(pole.id, float(k), seen, ERROR))
        step = manager.update(board, now=float(k))
        assert step.focus_map is manager.focus_map is step.focus
        # Inside the map: every pose drawn from it is one the map holds.
        drawn = step.focus.sample_poses(300, np.random.default_rng(k))
        assert np.all(step.map.contains(drawn[:, 0], drawn[:, 1], drawn[:, 2]))
        assert step.focus.area <= step.map.area + 1e-9
        assert step.map.contains(truth)  # the guarantee, for the map
        if not step.focus.contains(truth):
            lost_at.append(k)
    # Step 5's wrong sighting took the truth out of the focus map (it trusts every sighting)
    # until four more sightings had pushed it out of the window: from step 6 on it is back.
    assert lost_at == [5], lost_at


def test_without_the_relaxed_intersection_the_focus_map_is_the_map() -> None:
    steps, _, _ = drive(ManagerSettings(), np.random.default_rng(2), 3, 0)
    for step in steps:
        assert step.focus_map is None
        assert step.focus is step.map
    manager = UncertaintyMapManager(START, WORLD, FLOOR, ManagerSettings())
    assert manager.focus_map is manager.map


def landmarks_at_most(wrong: list[bool], q: int, n: int) -> bool:
    """Whether the wrong ones of any ``n`` consecutive sightings (all poles a step) name <= ``q`` poles."""
    named = [POLES[k % len(POLES)].id if flag else None for k, flag in enumerate(wrong)]
    spans = [named[start : start + n] for start in range(max(1, len(named) - n + 1))]
    return all(len({name for name in span if name is not None}) <= q for span in spans)


@pytest.mark.parametrize("seed", range(6))
def test_repeated_wrong_sightings_of_one_landmark_count_once(seed: int) -> None:
    # One pole misread at every step: two wrong in any eight sightings, more than q = 1 of
    # N = 8, but all of one landmark (a misread barcode repeats). A branch that excluded a
    # sighting of it does not trust it again while that one is in the window (before that
    # rule, 5 of 6 seeds lost the truth).
    settings = ManagerSettings(relaxed_q=1, relaxed_window=8)
    steps, truths, wrong = drive(settings, np.random.default_rng(seed), 10, 1)
    assert not at_most(wrong, 1, 8)
    assert landmarks_at_most(wrong, 1, 8)
    for step, truth in zip(steps, truths, strict=True):
        assert step.map.contains(truth), (step.time, step.map, truth)
        assert not step.relocalized


def test_with_more_wrong_than_q_the_guarantee_is_not_claimed() -> None:
    # Two wrong in every four break q = 1, N = 4: the map may lose the truth (and here does).
    lost = 0
    for seed in range(6):
        steps, truths, wrong = drive(
            ManagerSettings(relaxed_q=1, relaxed_window=4), np.random.default_rng(seed), 10, 2
        )
        assert not at_most(wrong, 1, 4)
        lost += not all(step.map.contains(truth) for step, truth in zip(steps, truths, strict=True))
    assert lost > 0


def test_excluded_observations_are_reported_once_and_counted() -> None:
    settings = ManagerSettings(relaxed_q=1, relaxed_window=4)
    manager = UncertaintyMapManager(START, WORLD, FLOOR, settings)
    board = Blackboard()
    truth = START_POSE
    seen_ids: list[int] = []
    for k in range(1, 7):
        truth = Pose(truth.x + 1.0, truth.y, truth.heading)
        board.post_report(PositionReport(float(k), STRIDE))
        for pole in POLES:
            board.identified.post(
                BearingObservation(pole.id, float(k), bearing(truth, truth.x, truth.y, pole), ERROR)
            )
        if k == 4:
            # The pole behind: no branch agrees, every one that would include it dies.
            board.identified.post(
                BearingObservation("south", float(k), bearing(truth, truth.x, truth.y, POLES[2]) + 3.0, ERROR)
            )
        step = manager.update(board, now=float(k))
        seen_ids += [id(o) for o in step.excluded]
        if k == 4:
            assert step.rejected[0].reason is RejectReason.EXCLUDED
            assert not step.rejected[0].accepted
            assert step.excluded == (step.rejected[0].observation,)
    assert len(seen_ids) == len(set(seen_ids)) == manager.excluded_count == 1
    assert manager.rejected_counts == {RejectReason.EXCLUDED: 1}
    assert manager.relocalizations == 0
    assert manager.inconsistent_count == 0


def test_q_zero_is_one_branch_and_the_branch_count_stays_bounded() -> None:
    steps, _, _ = drive(ManagerSettings(), np.random.default_rng(1), 4, 0)
    assert all(not s.excluded for s in steps)
    manager = UncertaintyMapManager(START, WORLD, FLOOR, ManagerSettings(relaxed_q=2, relaxed_window=5))
    assert manager.branch_count == 1
    board = Blackboard()
    truth = START_POSE
    for k in range(1, 8):
        truth = Pose(truth.x + 1.0, truth.y, truth.heading)
        board.post_report(PositionReport(float(k), STRIDE))
        for pole in POLES:
            board.identified.post(
                BearingObservation(pole.id, float(k), bearing(truth, truth.x, truth.y, pole), ERROR)
            )
        manager.update(board, now=float(k))
        assert manager.branch_count <= 1 + 5 + 10  # C(5, 0) + C(5, 1) + C(5, 2)


def test_a_saved_relaxed_manager_goes_on_exactly_as_the_original() -> None:
    settings = ManagerSettings(relaxed_q=1, relaxed_window=5)
    rng = np.random.default_rng(4)
    manager = UncertaintyMapManager(START, WORLD, FLOOR, settings)
    board = Blackboard()
    truth = START_POSE
    copy: UncertaintyMapManager | None = None
    copy_board: Blackboard | None = None
    for k in range(1, 9):
        truth = Pose(truth.x + 1.0, truth.y + 0.1, truth.heading)
        observations: list[Observation] = [
            BearingObservation(
                pole.id, float(k), bearing(truth, truth.x, truth.y, pole) + rng.uniform(-0.01, 0.01), ERROR
            )
            for pole in POLES
        ]
        for target, target_board in ((manager, board), (copy, copy_board)):
            if target is None or target_board is None:
                continue
            target_board.post_report(PositionReport(float(k), STRIDE))
            for observation in observations:
                target_board.identified.post(observation)
            target.update(target_board, now=float(k))
        if k == 4:
            copy = UncertaintyMapManager.from_json(manager.to_json(), WORLD, FLOOR)
            copy_board = Blackboard.from_json(board.to_json())
            assert copy.to_json() == manager.to_json()
            assert copy.branch_count == manager.branch_count > 1
            assert '"carried"' in manager.to_json()  # sightings a branch carries are saved too
    assert copy is not None
    assert copy.to_json() == manager.to_json()
    assert copy.map.polygon.vertices.tobytes() == manager.map.polygon.vertices.tobytes()
    # The focus map is one of the saved branches: it comes back too.
    assert copy.focus_map is not copy.map
    assert copy.focus_map.polygon.vertices.tobytes() == manager.focus_map.polygon.vertices.tobytes()
    assert copy.focus_map.wedge == manager.focus_map.wedge


def test_a_saved_document_must_match_its_settings() -> None:
    relaxed = UncertaintyMapManager(START, WORLD, FLOOR, ManagerSettings(relaxed_q=1, relaxed_window=3))
    text = relaxed.to_json()
    plain = UncertaintyMapManager(START, WORLD, FLOOR).to_json()
    assert '"relaxed"' in text
    assert '"relaxed"' not in plain
    without = json.loads(text)
    del without["relaxed"]
    with pytest.raises(
        FileFormatError, match=r"relaxed: expected the branches \(settings.relaxed_q > 0\), got none"
    ):
        UncertaintyMapManager.from_json(json.dumps(without), WORLD, FLOOR)
    broken = text.replace('"excluded": []', '"excluded": [7]', 1)
    with pytest.raises(
        FileFormatError, match=r"relaxed.branches\[0\].excluded: expected at most 1 serials of the window"
    ):
        UncertaintyMapManager.from_json(broken, WORLD, FLOOR)


def test_the_window_must_be_longer_than_q() -> None:
    with pytest.raises(
        InputError, match=r"ManagerSettings.relaxed_window: expected an integer > relaxed_q \(3\), got 3"
    ):
        ManagerSettings(relaxed_q=3, relaxed_window=3)
    assert ManagerSettings(relaxed_q=0, relaxed_window=1).relaxed_window == 1
    assert dataclasses.replace(ManagerSettings(), relaxed_q=1).relaxed_window == 10


def test_a_saved_branch_cannot_carry_a_sighting_it_chose() -> None:
    settings = ManagerSettings(relaxed_q=1, relaxed_window=8)
    manager = UncertaintyMapManager(START, WORLD, FLOOR, settings)
    board = Blackboard()
    truth = START_POSE
    for k in range(1, 4):
        truth = Pose(truth.x + 1.0, truth.y, truth.heading)
        board.post_report(PositionReport(float(k), STRIDE))
        for pole in POLES:
            board.identified.post(
                BearingObservation(pole.id, float(k), bearing(truth, truth.x, truth.y, pole), ERROR)
            )
        manager.update(board, now=float(k))
    document = json.loads(manager.to_json())
    branch = next(b for b in document["relaxed"]["branches"] if b.get("carried"))
    branch["carried"] = branch["carried"] + branch["excluded"]
    with pytest.raises(FileFormatError, match=r"carried: expected no serial of excluded, got \[\d+\]"):
        UncertaintyMapManager.from_json(json.dumps(document), WORLD, FLOOR)


def test_growth_ends_what_branches_carry_and_keeps_their_choices() -> None:
    start = SpatialUncertaintyMap.from_pose(Pose(10.0, 1.0, 0.0), 0.1, 0.02)
    state = RelaxedState(
        (Branch(frozenset(), start), Branch(frozenset({4}), start, frozenset({6, 7}))), (), frozenset(), 8
    )

    grown = relaxed_grow(state, lambda m: m.grow(TurnAndRun(0.0, 1.0), FLOOR["floor"]), 64)

    assert [(b.excluded, b.carried) for b in grown.branches] == [
        (frozenset(), frozenset()),
        (frozenset({4}), frozenset()),
    ]
    assert all(b.map.area > start.area for b in grown.branches)


def test_growth_merges_branches_left_with_the_same_choices_and_keeps_both_maps() -> None:
    # Two hypotheses that chose the same sighting and differ only in what they carry: once
    # growth ends what they carry they are one, and either may hold the truth.
    east = SpatialUncertaintyMap.from_pose(Pose(10.0, 1.0, 0.0), 0.1, 0.02)
    west = SpatialUncertaintyMap.from_pose(Pose(6.0, 1.0, 0.0), 0.1, 0.02)
    state = RelaxedState(
        (
            Branch(frozenset(), east),
            Branch(frozenset({4}), east, frozenset({6})),
            Branch(frozenset({4}), west, frozenset({5, 6})),
        ),
        (),
        frozenset(),
        8,
    )

    grown = relaxed_grow(state, lambda m: m.grow(TurnAndRun(0.0, 1.0), FLOOR["floor"]), 64)

    assert [(b.excluded, b.carried) for b in grown.branches] == [
        (frozenset(), frozenset()),
        (frozenset({4}), frozenset()),
    ]
    merged = grown.branches[1].map
    for start in (east, west):
        alone = start.grow(TurnAndRun(0.0, 1.0), FLOOR["floor"])
        assert all(merged.contains(Pose(x, y, 0.0)) for x, y in alone.polygon.vertices.tolist())


TWO_POINTS = (PointLandmark("A", 58.0, 20.0, 1.0), PointLandmark("B", 20.0, 30.0, 1.0))
TWO_POINT_WORLD = MeadowMap(
    [Meadow("floor", ConvexPolygon([(0, 0), (60, 0), (60, 40), (0, 40)]), "floor", ("A", "B"))],
    [
        LandmarkRecord(lm, PerceptualStrategy.for_class(lm.landmark_class)[0], {}, 80.0, 0.5)
        for lm in TWO_POINTS
    ],
)


def _wrong_choice_then_growth(seed: int, *, save_after: bool) -> tuple[Pose, ManagerStep | None, str]:
    """Sightings s0..s7 of two point landmarks, A far east and B north; s1 (B) and s6 (A) are wrong.

    Every 5 consecutive hold wrong sightings of at most one landmark (q = 1, N = 5). After
    the instant of s5 and s6 (no growth before it), two branches exclude s5 and differ only
    in what they carry; one of them, which carries s6, holds the truth. Returns the truth,
    the last step (None with ``save_after``: the state after one more growth instead) and
    the manager's JSON.
    """
    a, b = TWO_POINTS
    rng = np.random.default_rng(seed)
    truth = Pose(20.0, 20.0, 0.0)
    settings = ManagerSettings.from_dict(
        {"relaxed_q": 1, "relaxed_window": 5}, base=MapProfile.RELAXED.settings()
    )
    manager = UncertaintyMapManager(
        SpatialUncertaintyMap.from_pose(truth, 3.0, 0.3), TWO_POINT_WORLD, FLOOR, settings
    )
    board = Blackboard()

    def seen(landmark: PointLandmark, pose: Pose) -> float:
        return math.atan2(landmark.y - pose.y, landmark.x - pose.x) - pose.heading

    def move(now: float) -> None:
        nonlocal truth
        truth = FLOOR["floor"].sample_motion(truth, TurnAndRun(0.0, 0.3), rng, truncate=3.0)
        board.post_report(PositionReport(now, TurnAndRun(0.0, 0.3)))

    def good(landmark: PointLandmark, now: float, fraction: float) -> None:
        board.identified.post(
            BearingObservation(landmark.id, now, seen(landmark, truth) + fraction * ERROR, ERROR)
        )

    move(1.0)
    good(a, 1.0, 0.8)
    elsewhere = Pose(truth.x, truth.y - 2.5, truth.heading)  # B seen from 2.5 m south: consistent, wrong
    reach = math.hypot(b.x - elsewhere.x, b.y - elsewhere.y)
    board.identified.post(
        RangeBearingObservation("B", 1.0, seen(b, elsewhere), ERROR, reach - 0.2, reach + 0.2)
    )
    manager.update(board, now=1.0)
    move(2.0)
    good(a, 2.0, -0.8)
    good(a, 2.0, 0.6)
    manager.update(board, now=2.0)
    move(3.0)
    good(a, 3.0, -0.7)
    manager.update(board, now=3.0)
    good(a, 3.5, 0.75)
    board.identified.post(BearingObservation("A", 3.5, seen(a, truth) + 0.15, ERROR))  # wrong
    manager.update(board, now=3.5)
    if save_after:
        move(3.8)
        manager.update(board, now=3.8)
        return truth, None, manager.to_json()
    move(4.0)
    good(b, 4.0, 0.5)
    return truth, manager.update(board, now=4.0), manager.to_json()


@pytest.mark.parametrize("seed", range(4))
def test_branches_that_differ_only_in_what_they_carry_both_survive_growth(seed: int) -> None:
    truth, step, _ = _wrong_choice_then_growth(seed, save_after=False)

    assert step is not None
    assert not step.relocalized
    assert step.map.contains(truth)


def test_a_state_saved_after_such_branches_grew_reads_back() -> None:
    _, _, text = _wrong_choice_then_growth(0, save_after=True)

    branches = json.loads(text)["relaxed"]["branches"]
    keys = [(tuple(b["excluded"]), tuple(b.get("carried", []))) for b in branches]
    assert len(set(keys)) == len(keys)
    restored = UncertaintyMapManager.from_json(text, TWO_POINT_WORLD, FLOOR)
    assert restored.to_json() == text


@dataclasses.dataclass(frozen=True)
class _Respecting:
    """An abstract map: the sightings whose bounds it respects (it holds the truth iff none is wrong)."""

    serials: frozenset[int]


@dataclasses.dataclass(frozen=True)
class _Named:
    landmark_id: str


def _respected_by_both(maps: list[_Respecting], max_vertices: int = 0) -> _Respecting:
    del max_vertices
    return _Respecting(frozenset.intersection(*(m.serials for m in maps)))


@pytest.mark.parametrize(("q", "window"), [(1, 2), (1, 5), (2, 5), (3, 4)])
def test_some_branch_respects_only_correct_sightings_under_any_admissible_pattern(
    q: int, window: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    # The bookkeeping alone, with maps reduced to the sightings they respect: merges, growth
    # (which ends what branches carry) and sightings that leave the window, in random order.
    # Whenever the wrong sightings among any N consecutive name at most q landmarks, some
    # branch must respect no wrong one.
    monkeypatch.setattr(_relaxed, "union_of_maps", _respected_by_both)
    rng = np.random.default_rng(q * 100 + window)
    for _ in range(150):
        state = RelaxedState.start(_Respecting(frozenset()))  # type: ignore[arg-type]
        history: list[tuple[str, bool]] = []
        wrong: set[int] = set()
        for _step in range(40):
            instant: list[tuple[str, bool]] = []
            for _ in range(int(rng.integers(1, 4))):
                landmark = "ABCD"[int(rng.integers(4))]
                before = history[max(0, len(history) - window + 1) :]  # the N - 1 before it
                named = {name for name, bad in before if bad} | {landmark}
                instant.append((landmark, bool(rng.random() < 0.6 and len(named) <= q)))
                history.append(instant[-1])
            for start in range(0, len(instant), window):
                chunk = instant[start : start + window]
                sightings: list[Any] = [_Named(name) for name, _ in chunk]
                state, serials = _relaxed.admit(state, sightings, window, 0)
                wrong |= {serial for serial, (_, bad) in zip(serials, chunk, strict=True) if bad}

                def reduce(m: Any, keep: Sequence[int], serials: tuple[int, ...] = serials) -> Any:
                    return _Respecting(m.serials | {serials[index] for index in keep})

                relaxed = _relaxed.relax(state, serials, q, reduce)
                assert relaxed is not None
                state = relaxed
            if rng.random() < 0.4:
                state = _relaxed.grow(state, lambda m: m, 0)
            assert any(not (branch.map.serials & wrong) for branch in state.branches)  # type: ignore[attr-defined]
