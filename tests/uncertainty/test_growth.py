"""The compiled growth kernel against the numpy reference, and soundness on both paths."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums.geometry import ConvexPolygon, convex_hull, polygon_area
from aura_ums.geometry._convex import convexity_defect
from aura_ums.uncertainty import Pose, SpatialUncertaintyMap, TerrainStats, TerrainTable, TurnAndRun, _growth
from aura_ums.uncertainty._growth import MotionBounds, grow_polygon, grow_polygon_reference, motion_bounds

KERNEL = _growth.compiled_kernel()
compiled = pytest.mark.skipif(KERNEL is None, reason="the C growth kernel was not built (no compiler)")


def random_bounds(rng: np.random.Generator) -> MotionBounds:
    turn = float(rng.choice([0.0, math.pi, rng.uniform(-4, 4)]))
    run_max = float(rng.choice([0.0, rng.uniform(0, 20)]))
    run_min = float(rng.uniform(0, run_max)) if run_max else 0.0
    drift = float(rng.choice([0.0, rng.uniform(0, 0.5)]))
    return MotionBounds(
        turn_min=min(0.8 * turn, turn),
        turn_max=max(0.8 * turn, turn),
        turn_mean=0.9 * turn,
        run_min=run_min,
        run_max=run_max,
        run_mean=run_min,
        chord_min=float(rng.uniform(0, run_min)) if run_min else 0.0,
        skitter_radius=float(rng.choice([0.0, rng.uniform(0, 0.2), 1e-300])),
        drift_max=drift,
    )


@compiled
@given(st.integers(0, 2**32 - 1), st.integers(3, 80))
def test_compiled_kernel_matches_the_numpy_reference(seed: int, cap: int) -> None:
    rng = np.random.default_rng(seed)
    count = int(rng.integers(1, 60))
    vertices = convex_hull(rng.normal(0.0, rng.uniform(0.01, 10), (count, 2)) + rng.uniform(-100, 100, 2))
    lo = float(rng.uniform(-4, 4))
    hi = lo + float(rng.choice([0.0, rng.uniform(0, 3), 2 * math.pi, rng.uniform(0, 7)]))
    bounds = random_bounds(rng)
    ours = grow_polygon(vertices, lo, hi, bounds, cap)
    reference = grow_polygon_reference(vertices, lo, hi, bounds, cap)
    assert not ours.flags.writeable
    assert convexity_defect(ours) is None
    scale = 1.0 + float(np.abs(reference).max())
    exact = grow_polygon_reference(vertices, lo, hi, bounds, 10_000)
    if len(exact) <= cap:
        # No cap applied: both are the exact Minkowski sum.
        assert polygon_area(ours) == pytest.approx(polygon_area(reference), rel=1e-9, abs=1e-9 * scale**2)
    elif cap >= 8:
        # Capped: rounding-level differences may break the greedy's cost ties differently.
        # (Below 8 vertices the outer bound may need nearly parallel edges to meet far
        # away; it stays sound, checked below, but the two paths may stop differently.)
        assert len(ours) <= cap or len(ours) == len(reference) == len(vertices)
    # Both are outer bounds of the same set: each holds the exact sum's vertices.
    for polygon in (ours, reference):
        assert np.all(ConvexPolygon._trusted(polygon).contains(exact, tolerance=1e-9 * scale))


@compiled
def test_compiled_kernel_handles_points_and_segments() -> None:
    bounds = MotionBounds(0.0, 0.0, 0.0, 1.0, 2.0, 1.5, 1.0, 0.0, 0.0)
    point = np.array([[3.0, 4.0]])
    grown = grow_polygon(point, 0.0, 0.0, bounds)
    assert np.allclose(grown, [[4.0, 4.0], [5.0, 4.0]])
    nothing = MotionBounds(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    assert grow_polygon(point, 0.0, 0.0, nothing).tolist() == [[3.0, 4.0]]


@compiled
def test_compiled_kernel_refuses_a_malformed_buffer() -> None:
    assert KERNEL is not None
    with pytest.raises(ValueError, match=r"vertices: expected a C-contiguous \(n, 2\) float64 buffer"):
        KERNEL(b"abc", 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 16)


def _clipped(value: float, lo: float, hi: float) -> float:
    return lo if value < lo else hi if value > hi else value


def _motion_bounds_as_documented(stats: TerrainStats, command: TurnAndRun, sigmas: float) -> MotionBounds:
    """The bounds of MotionBounds' documentation, written plainly (min, max and a clip function)."""
    turn, run = command.turn, command.run
    fraction_lo = _clipped(1.0 - stats.rotation_loss - sigmas * stats.rotation_sd, 0.0, 1.0)
    fraction_hi = _clipped(1.0 - stats.rotation_loss + sigmas * stats.rotation_sd, 0.0, 1.0)
    loss, spread = stats.translation_loss, sigmas * stats.translation_sd
    run_lo = _clipped(run * (1.0 - loss - spread) - stats.translation_inertial_loss, 0.0, run)
    run_hi = _clipped(run * (1.0 - loss + spread) - stats.translation_inertial_loss, 0.0, run)
    drift_max = stats.drift * run_hi
    if stats.drift == 0.0:
        chord_min = run_lo
    elif drift_max <= math.pi:
        chord_min = 2.0 * math.sin(stats.drift * run_lo / 2.0) / stats.drift
    else:
        chord_min = 0.0
    return MotionBounds(
        min(turn * fraction_lo, turn * fraction_hi),
        max(turn * fraction_lo, turn * fraction_hi),
        turn * _clipped(1.0 - stats.rotation_loss, 0.0, 1.0),
        run_lo,
        run_hi,
        _clipped(run * (1.0 - loss) - stats.translation_inertial_loss, 0.0, run),
        chord_min,
        abs(turn) * max(0.0, stats.skitter + sigmas * stats.skitter_sd),
        drift_max,
    )


fraction = st.floats(0.0, 0.99)
spread = st.floats(0.0, 2.0)


@given(
    st.tuples(fraction, st.floats(0.0, 0.5), spread, st.floats(0.0, 0.5), fraction, spread, spread, spread),
    st.floats(-7.0, 7.0),
    st.floats(0.0, 30.0),
    st.sampled_from([0.5, 1.0, 3.0, 5.0]),
)
def test_motion_bounds_are_exactly_the_documented_formulas(
    stats: tuple[float, ...], turn: float, run: float, sigmas: float
) -> None:
    """The clipping written out in motion_bounds gives the very same floats (any turn, zero runs)."""
    terrain, command = TerrainStats(*stats), TurnAndRun(turn, run)
    assert motion_bounds(terrain, command, sigmas) == _motion_bounds_as_documented(terrain, command, sigmas)


SEQUENCE_KERNEL = _growth.compiled_sequence_kernel()


def _same_map(a: SpatialUncertaintyMap, b: SpatialUncertaintyMap) -> bool:
    return (
        a.polygon.vertices.tobytes() == b.polygon.vertices.tobytes()
        and a.center.tobytes() == b.center.tobytes()
        and (a.wedge.center, a.wedge.cw, a.wedge.ccw) == (b.wedge.center, b.wedge.cw, b.wedge.ccw)
    )


@given(
    st.tuples(fraction, st.floats(0.0, 0.5), spread, st.floats(0.0, 0.5), fraction, spread, spread, spread),
    st.lists(st.tuples(st.floats(-7.0, 7.0), st.floats(0.0, 30.0)), max_size=6),
    st.floats(-math.pi, math.pi),
    st.sampled_from([0.0, 0.05, 1.0, math.pi]),
    st.sampled_from([1.0, 3.0]),
    st.sampled_from([3, 8, 64]),
)
def test_a_run_of_growths_is_bit_for_bit_a_loop_of_grow(
    stats: tuple[float, ...],
    commands: list[tuple[float, float]],
    heading: float,
    halfwidth: float,
    sigmas: float,
    cap: int,
) -> None:
    """The manager's one-call growth (compiled when built) equals growing report by report.

    Full-circle wedges, headings at the +-pi seam, zero-length commands and the vertex
    cap included: the polygon, the centre and the wedge are the very same floats.
    """
    terrain = TerrainStats(*stats)
    start = SpatialUncertaintyMap.from_pose(Pose(3.0, -2.0, heading), 0.3, halfwidth)
    runs = [TurnAndRun(turn, run) for turn, run in commands]
    expected = start
    for command in runs:
        expected = expected.grow(command, terrain, sigmas=sigmas, max_vertices=cap)
    grown = start._grow_many(runs, terrain, sigmas, cap)
    assert _same_map(grown, expected)
    assert not grown.polygon.vertices.flags.writeable


def test_a_run_of_growths_without_the_kernel_is_the_loop(monkeypatch: pytest.MonkeyPatch) -> None:
    terrain = TerrainTable.default()["grass"]
    start = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 3.0), 0.1, 0.05)
    runs = [TurnAndRun(0.4, 2.0), TurnAndRun(-1.0, 0.0), TurnAndRun(0.0, 5.0)]
    compiled_result = start._grow_many(runs, terrain, 3.0)
    monkeypatch.setattr(_growth, "_compiled_grow_commands", None)
    assert start._grow_many([], terrain, 3.0) is start
    assert _same_map(start._grow_many(runs, terrain, 3.0), compiled_result)


@pytest.mark.skipif(SEQUENCE_KERNEL is None, reason="the C growth kernel was not built (no compiler)")
def test_the_run_kernel_refuses_bad_commands() -> None:
    assert SEQUENCE_KERNEL is not None
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    stats = (0.5, 0.5, 0.0, 0.1, 0.1, 0.0, 0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 3.0)
    with pytest.raises(ValueError, match=r"commands: expected \(turn, run\) pairs, got 3 numbers"):
        SEQUENCE_KERNEL(square, *stats, [0.0, 1.0, 2.0], 16)
    with pytest.raises(ValueError, match=r"commands: expected finite numbers, got 0.0, nan at pair 1"):
        SEQUENCE_KERNEL(square, *stats, [0.0, 1.0, 0.0, math.nan], 16)
    with pytest.raises(TypeError, match="commands: expected a sequence of numbers"):
        SEQUENCE_KERNEL(square, *stats, 5, 16)
    with pytest.raises(ValueError, match="max_vertices: expected at least 3, got 2"):
        SEQUENCE_KERNEL(square, *stats, [], 2)
