"""The manager growing from an anchor: once per update by the moves since the last correction."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from aura_ums.manager import ManagerSettings, UncertaintyMapManager
from aura_ums.uncertainty import (
    Composite,
    Pose,
    SpatialUncertaintyMap,
    TerrainStats,
    TerrainTable,
    TurnAndRun,
    grow_from_anchor,
    intersect_maps,
)
from tests.manager.test_map_manager import (
    LANDMARKS,
    POLE_NORTH,
    START,
    WORLD,
    assert_same_map,
    bearing_of,
    board_with,
    box,
    manager_for,
    start_map,
    world_of,
)

#: One meadow of one terrain: the anchored growth's case.
STATS = TerrainStats(0.0, 0.25, 0.06, 0.27, 0.0, 0.033, 0.0, 0.027)
TABLE = TerrainTable({"tile": STATS})  # the meadow map checks names against the default table
ONE = world_of([("floor", box(-50, -50, 50, 50), "tile")], LANDMARKS)
STEP = TurnAndRun(0.02, 0.05)


def anchored(**settings: Any) -> UncertaintyMapManager:
    chosen = ManagerSettings(**{"robust": False, "anchor_growth": True, **settings})
    return UncertaintyMapManager(start_map(), ONE, TABLE, chosen)


def test_the_map_is_the_anchor_grown_once_by_every_move_since() -> None:
    reports = [(0.25 * (i + 1), STEP) for i in range(40)]
    manager = anchored()
    for count in (10, 25, 40):  # three updates: the anchor stays the start
        manager.update(board_with(*reports), now=0.25 * count)
    composite = Composite().extended([STEP] * 40, STATS)
    expected = grow_from_anchor(start_map(), composite, STATS, 3.0, 64)
    # Equal up to rounding: the composite was summed in three pieces.
    assert np.allclose(manager.map.polygon.vertices, expected.polygon.vertices, atol=1e-12)
    assert math.isclose(manager.map.wedge.width, expected.wedge.width, abs_tol=1e-12)


def test_a_correction_joins_the_anchors() -> None:
    reports = [(0.25 * (i + 1), STEP) for i in range(40)]
    seen = Pose(START.x + 0.5, START.y + 0.1, START.heading + 0.2)
    observation = bearing_of(seen, POLE_NORTH, 5.0, error=0.05)
    manager = anchored()
    step = manager.update(board_with(*reports, observations=(observation,)), now=10.0)
    assert step.outcomes[0].accepted
    # By hand: grown to t = 5, reduced; then the reduced map and the start, each grown by
    # the moves since its time, intersected.
    first_half = Composite().extended([STEP] * 20, STATS)
    before = grow_from_anchor(start_map(), first_half, STATS, 3.0, 64)
    reduced = before.reduce(observation, POLE_NORTH).map
    from_reduced = grow_from_anchor(reduced, Composite().extended([STEP] * 20, STATS), STATS, 3.0, 64)
    from_start = grow_from_anchor(start_map(), first_half.extended([STEP] * 20, STATS), STATS, 3.0, 64)
    assert_same_map(manager.map, intersect_maps(from_reduced, [from_start], 64))
    assert manager.map.area <= from_reduced.area


def test_one_update_per_report_counts_the_offset_once() -> None:
    # As a replay runs: one update per frame. The wedge is the composite's one bound (with
    # L0 = 0.25 m once), not a sum over the 120 updates.
    reports = [(0.25 * (i + 1), STEP) for i in range(120)]
    manager = anchored()
    board = board_with(*reports)
    for count in range(1, 121):
        manager.update(board, now=0.25 * count)
    bound = 3.0 * STATS.rotation_sd * 120 * STEP.turn + STATS.drift * (120 * STEP.run + 0.25)
    assert math.isclose(manager.map.wedge.width, start_map().wedge.width + 2.0 * bound, rel_tol=1e-9)


def test_several_meadows_grow_move_by_move() -> None:
    reports = [(1.0, TurnAndRun(0.0, 2.0)), (2.0, TurnAndRun(0.0, 2.0))]
    plain, asked = manager_for(), manager_for(anchor_growth=True)
    for manager in (plain, asked):
        manager.update(board_with(*reports), now=2.0)
    assert_same_map(asked.map, plain.map)
    assert WORLD.meadows[0].terrain != WORLD.meadows[1].terrain


def test_relaxed_branches_and_the_envelope_keep_the_truth() -> None:
    # A straight drive with bearings every 2 s: every branch grows from its own anchor.
    rng = np.random.default_rng(7)
    manager = anchored(relaxed_q=1, relaxed_window=4, robust=True, slice_width=math.radians(4.0))
    truth = START
    reports, observations = [], []
    for i in range(80):
        t = 0.25 * (i + 1)
        reports.append((t, TurnAndRun(0.0, 0.05)))
        truth = Pose(truth.x + 0.05, truth.y, truth.heading)
        if i % 8 == 7:
            observations.append(bearing_of(truth, POLE_NORTH, t, error=0.02 + 0.01 * rng.uniform()))
    board = board_with(*reports, observations=tuple(observations))
    for now in np.arange(1.0, 20.5, 1.0):
        step = manager.update(board, now=float(now))
        assert step.map.area > 0.0
    assert manager.map.contains(truth)
    assert manager.envelope_map is not None
    assert manager.envelope_map.contains(truth)


def test_a_restored_manager_anchors_at_its_restored_map() -> None:
    reports = [(0.25 * (i + 1), STEP) for i in range(20)]
    manager = anchored()
    manager.update(board_with(*reports[:10]), now=2.5)
    again = UncertaintyMapManager.from_json(manager.to_json(), ONE, TABLE)
    assert again.settings.anchor_growth
    again.update(board_with(*reports), now=5.0)
    restored: SpatialUncertaintyMap = UncertaintyMapManager.from_json(manager.to_json(), ONE, TABLE).map
    by_hand = grow_from_anchor(restored, Composite().extended([STEP] * 10, STATS), STATS, 3.0, 64)
    assert_same_map(again.map, by_hand)
