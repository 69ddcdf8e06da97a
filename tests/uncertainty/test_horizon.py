"""Growth from an anchor: it holds every pose the composite's bounds allow, product or sliced.

The truth here is built step by step: a start pose in the anchor, then moves whose
accumulated heading and position errors (against the terrain's mean motion) stay within
:func:`anchor_bounds`, however they are spread over the steps.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from aura_ums.errors import InputError
from aura_ums.uncertainty import (
    Composite,
    Pose,
    SpatialUncertaintyMap,
    TerrainStats,
    TurnAndRun,
    anchor_bounds,
    grow_from_anchor,
    intersect_maps,
)


def _nominal_steps(commands: list[TurnAndRun], stats: TerrainStats) -> tuple[np.ndarray, np.ndarray]:
    """Displacements (n, 2) and headings (n,) after each command, from heading 0, by the mean motion."""
    heading, x, y = 0.0, 0.0, 0.0
    points, headings = [], []
    for command in commands:
        heading += command.turn * (1.0 - stats.rotation_loss)
        run = command.run * (1.0 - stats.translation_loss)
        x, y = x + run * math.cos(heading), y + run * math.sin(heading)
        points.append((x, y))
        headings.append(heading)
    return np.array(points), np.array(headings)


def _truth(
    start: np.ndarray,
    commands: list[TurnAndRun],
    stats: TerrainStats,
    rng: np.random.Generator,
    sigmas: float,
) -> np.ndarray:
    """True end poses (m, 3): each start's nominal composite plus errors within the bounds.

    The errors grow step by step (a random walk rescaled into the bound), so the truth at
    the end is any pose the bound allows, reached through bounded per-step motions.
    """
    composite = Composite().extended(commands, stats)
    heading_bound, position_bound = anchor_bounds(stats, composite, sigmas)
    points, headings = _nominal_steps(commands, stats)
    count = len(start)
    steps = rng.normal(size=(len(commands), count, 3)).cumsum(axis=0)[-1]
    size = np.maximum(np.hypot(steps[:, 0], steps[:, 1]), 1e-12)
    # Radius up to the bound: some on it, most inside.
    radius = position_bound * np.minimum(rng.uniform(0.0, 1.2, count), 1.0)
    error = steps[:, :2] / size[:, None] * radius[:, None]
    eta = heading_bound * np.clip(rng.uniform(-1.2, 1.2, count), -1.0, 1.0)
    cos, sin = np.cos(start[:, 2]), np.sin(start[:, 2])
    local = points[-1] + error
    out = np.empty_like(start)
    out[:, 0] = start[:, 0] + cos * local[:, 0] - sin * local[:, 1]
    out[:, 1] = start[:, 1] + sin * local[:, 0] + cos * local[:, 1]
    out[:, 2] = start[:, 2] + headings[-1] + eta
    return out


terrains = st.builds(
    TerrainStats,
    st.floats(0.0, 0.3),
    st.floats(0.0, 1.0),
    st.floats(0.0, 0.1),
    st.floats(0.0, 0.5),
    st.floats(0.0, 0.3),
    st.floats(0.0, 0.1),
    st.floats(0.0, 0.2),
    st.floats(0.0, 0.1),
)
moves = st.lists(st.builds(TurnAndRun, st.floats(-1.5, 1.5), st.floats(0.0, 1.0)), min_size=1, max_size=12)


@settings(max_examples=60, deadline=None)
@given(
    stats=terrains,
    commands=moves,
    radius=st.floats(0.0, 0.5),
    halfwidth=st.floats(0.0, 0.4),
    sliced=st.booleans(),
    seed=st.integers(0, 2**32 - 1),
)
def test_anchor_growth_contains_every_bounded_truth(
    stats: TerrainStats,
    commands: list[TurnAndRun],
    radius: float,
    halfwidth: float,
    sliced: bool,
    seed: int,
) -> None:
    rng = np.random.default_rng(seed)
    anchor = SpatialUncertaintyMap.from_pose(Pose(1.0, -2.0, 0.7), radius, halfwidth)
    if sliced:
        anchor = anchor.with_slices(math.radians(4.0))
    composite = Composite().extended(commands, stats)
    grown = grow_from_anchor(anchor, composite, stats, 3.0, 64)
    start = anchor.sample_poses(300, rng)
    truth = _truth(start, commands, stats, rng, 3.0)
    inside = np.asarray(grown.contains(truth[:, 0], truth[:, 1], truth[:, 2]))
    assert inside.all()


def test_monte_carlo_containment_over_composites() -> None:
    # Seeded: 200 random composites on one calibrated-like terrain, 500 truths each.
    rng = np.random.default_rng(18)
    stats = TerrainStats(0.0, 0.25, 0.06, 0.27, 0.0, 0.033, 0.0, 0.027)
    outside = 0
    for _ in range(200):
        commands = [
            TurnAndRun(float(rng.normal(0.0, 0.05)), float(rng.uniform(0.0, 0.05)))
            for _ in range(int(rng.integers(1, 120)))
        ]
        anchor = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.1, 0.05).with_slices(
            math.radians(4.0)
        )
        grown = grow_from_anchor(anchor, Composite().extended(commands, stats), stats, 3.0, 64)
        truth = _truth(anchor.sample_poses(500, rng), commands, stats, rng, 3.0)
        outside += int((~np.asarray(grown.contains(truth[:, 0], truth[:, 1], truth[:, 2]))).sum())
    assert outside == 0


def test_anchor_growth_does_not_sum_per_move_offsets() -> None:
    # A hundred short moves: the anchor counts the fixed distance L0 once, the per-move
    # growth a hundred times (in the drift, which is per metre actually run there).
    stats = TerrainStats(0.0, 0.0, 0.01, 0.2, 0.0, 0.0, 0.0, 0.0)
    commands = [TurnAndRun(0.0, 0.02)] * 100
    start = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.0, 0.0)
    once = grow_from_anchor(start, Composite().extended(commands, stats), stats, 3.0, 64)
    heading_bound, _ = anchor_bounds(stats, Composite().extended(commands, stats), 3.0)
    assert math.isclose(once.wedge.width, 2.0 * heading_bound, rel_tol=1e-9)
    assert math.isclose(heading_bound, 0.2 * 2.0, rel_tol=1e-9)


def test_still_composite_keeps_the_anchor() -> None:
    anchor = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.2, 0.1)
    stats = TerrainStats(0.0, 0.5, 0.1, 0.3, 0.0, 0.1, 0.0, 0.1)
    assert grow_from_anchor(anchor, Composite(), stats, 3.0, 64) is anchor
    assert anchor_bounds(stats, Composite(), 3.0) == (0.0, 0.0)


def test_wide_heading_bound_gives_every_heading() -> None:
    anchor = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.0, 0.0)
    stats = TerrainStats(0.0, 0.0, 0.0, 5.0, 0.0, 0.0, 0.0, 0.0)
    grown = grow_from_anchor(anchor, Composite().extended([TurnAndRun(0.0, 1.0)], stats), stats, 3.0, 64)
    assert grown.wedge.width >= 2.0 * math.pi - 1e-9


def test_large_position_bound_takes_more_turns() -> None:
    # A position bound beyond what one turn's skitter can hold (10 m/rad) stays sound.
    anchor = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.0, 0.0)
    stats = TerrainStats(0.0, 0.0, 10.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    composite = Composite().extended([TurnAndRun(0.0, 5.0)], stats)
    _, position_bound = anchor_bounds(stats, composite, 3.0)
    grown = grow_from_anchor(anchor, composite, stats, 3.0, 64)
    assert position_bound > 10.0 * 2.0 * math.pi
    assert grown.contains(Pose(5.0, 0.9 * position_bound, 0.0))


@pytest.mark.parametrize("sigmas", [0.1, 0.5, 3.0])
def test_a_large_position_bound_at_few_sigmas_takes_more_turns_too(sigmas: float) -> None:
    # Below one sigma the skitter's spread (position bound / turn / sigmas) outgrew its range
    # (10 m/rad) and the growth raised on a valid call.
    anchor = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.0, 0.0)
    stats = TerrainStats(0.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0)
    composite = Composite().extended([TurnAndRun(0.0, 200.0)], stats)
    _, position_bound = anchor_bounds(stats, composite, sigmas)
    grown = grow_from_anchor(anchor, composite, stats, sigmas, 64)
    assert grown.contains(Pose(200.0, 0.9 * position_bound, 0.0))
    assert grown.contains(Pose(200.0 - 0.9 * position_bound, 0.0, 0.0))


@pytest.mark.parametrize(("runs", "sigmas"), [(1, 0.5), (2, 1.0), (10, 3.0)])
def test_a_kilometre_scale_composite_grows_without_refusing_its_own_commands(
    runs: int, sigmas: float
) -> None:
    # The growth's internal turn (a thousand turns for a 10 km bound) and run (20 km) are
    # beyond the public TurnAndRun's ranges; it raised their range error instead of growing.
    anchor = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 1.0, 0.5)
    stats = TerrainStats(0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    composite = Composite().extended([TurnAndRun(0.0, 10_000.0)] * runs, stats)
    _, position_bound = anchor_bounds(stats, composite, sigmas)
    grown = grow_from_anchor(anchor, composite, stats, sigmas, 64)
    far = 10_000.0 * runs
    assert grown.contains(Pose(far, 0.9 * position_bound, 0.0))
    assert grown.contains(Pose(far - 0.9 * position_bound, 0.0, 0.0))


@settings(max_examples=40, deadline=None)
@given(
    stats=terrains,
    commands=moves,
    halfwidth=st.floats(0.0, 0.6),
    sliced=st.booleans(),
    seed=st.integers(0, 2**32 - 1),
)
# Found by exploration: GEOS gave an intersection with two vertices 6e-17 m apart, and the
# containment test by edge lines cut off a truth 2 cm inside both maps.
@example(
    stats=TerrainStats(0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0),
    commands=[TurnAndRun(1.5, 1.0)],
    halfwidth=0.5,
    sliced=True,
    seed=0,
)
def test_the_intersection_of_grown_anchors_keeps_every_pose_they_share(
    stats: TerrainStats, commands: list[TurnAndRun], halfwidth: float, sliced: bool, seed: int
) -> None:
    # Two anchors of one truth: the start, and the start moved part of the way (tight).
    rng = np.random.default_rng(seed)
    start = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.3), 0.3, halfwidth)
    if sliced:
        start = start.with_slices(math.radians(4.0))
    composite = Composite().extended(commands, stats)
    older = grow_from_anchor(start, composite, stats, 3.0, 64)
    looser = dataclasses.replace(stats, translation_inertial_loss=stats.translation_inertial_loss + 0.2)
    wider = grow_from_anchor(start, Composite().extended(commands, looser), looser, 3.0, 64)
    both = intersect_maps(older, [wider], 64)
    truth = _truth(start.sample_poses(300, rng), commands, stats, rng, 3.0)
    assert np.asarray(both.contains(truth[:, 0], truth[:, 1], truth[:, 2])).all()
    assert both.area <= older.area + 1e-9
    assert both.is_sliced == sliced


def test_intersection_with_a_disjoint_map_is_the_first() -> None:
    here = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.5, 0.1).with_slices()
    there = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 2.0), 0.5, 0.1)
    assert intersect_maps(here, [there], 64) is here
    assert intersect_maps(here, [here], 64) is here


@pytest.mark.parametrize(
    ("fields", "match"),
    [
        ({"x": math.nan}, "Composite.x: expected a finite number, got nan"),
        ({"y": None}, "Composite.y: expected a finite number, got None"),
        ({"heading": "a"}, "Composite.heading: expected a finite number, got 'a'"),
        ({"path": math.nan}, "Composite.path: expected a finite number, got nan"),
        ({"turning": -1.0}, "Composite.turning: expected a non-negative number, got -1.0"),
    ],
)
def test_a_composite_refuses_what_is_not_a_move(fields: dict[str, object], match: str) -> None:
    with pytest.raises(InputError, match=match):
        Composite(**fields)  # type: ignore[arg-type]
