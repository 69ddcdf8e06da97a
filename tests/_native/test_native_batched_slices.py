"""The kernels over every slice of a map at once: compiled against their numpy references.

The compiled kernels repeat the single-map kernels slice by slice, so against the reference
loop run with the compiled single kernels they agree bit for bit; against the numpy
reference they agree as the single kernels do (round-off in the polygons, the same verdicts
and intervals).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums import _native
from aura_ums._native import _growth as native_growth
from aura_ums._native import _reduce as native_reduce
from aura_ums._native import _slices as native_slices
from aura_ums.geometry import ConvexPolygon, polygon_area
from aura_ums.geometry._convex import convexity_defect
from tests._native.native_helpers import (
    Array,
    built,
    kernels,
    random_commands,
    random_polygon,
    random_terrain,
    scale_of,
)
from tests._native.test_native_reduce import cone_arguments, strip_arguments

Counts = np.ndarray
TWO_PI = 2.0 * math.pi


def random_slices(rng: np.random.Generator) -> tuple[Array, Counts, Array, Array, float]:
    """1 to 8 slices ordered by lo: narrow cells, wide runs, a full circle now and then; and a heading."""
    count = int(rng.integers(1, 9))
    polygons = [random_polygon(rng) for _ in range(count)]
    if rng.uniform() < 0.1:
        lo, hi = np.zeros(1), np.full(1, TWO_PI)
        polygons = polygons[:1]
    else:
        width = float(rng.choice([0.01, 0.07, 0.5]))
        cells = np.sort(rng.choice(int(TWO_PI / width), size=count, replace=False))
        lo = np.asarray(cells * width, dtype=np.float64)
        hi = np.asarray(lo + width * rng.uniform(0.0, 1.0, len(lo)), dtype=np.float64)
    heading = float(rng.choice([rng.uniform(-math.pi, math.pi), lo[0], hi[-1] + 0.1]))
    points = np.ascontiguousarray(np.concatenate(polygons))
    return points, np.array([len(p) for p in polygons], dtype=np.int64), lo, hi, heading


def same(first: tuple[object, ...], second: tuple[object, ...]) -> bool:
    """Every array equal bit for bit, every number the very same float."""
    for a, b in zip(first, second, strict=True):
        if isinstance(a, np.ndarray):
            if not (isinstance(b, np.ndarray) and a.dtype == b.dtype and a.tobytes() == b.tobytes()):
                return False
        elif a != b:
            return False
    return True


@built
@given(st.integers(0, 2**32 - 1), st.sampled_from([3, 8, 16, 64]), st.integers(1, 4))
def test_compiled_growth_of_every_slice_is_the_loop_over_slices(seed: int, cap: int, count: int) -> None:
    rng = np.random.default_rng(seed)
    points, counts, lo, hi, heading = random_slices(rng)
    terrain, commands = random_terrain(rng), random_commands(rng, count)
    arguments = (points, counts, lo, hi, 1.0, -2.0, heading, terrain, 3.0, commands, cap)
    ours = native_slices.grow_slices_compiled(*arguments)
    assert same(ours, native_slices._grow_slices(native_growth.grow_commands_compiled, *arguments))
    reference = native_slices.grow_slices_reference(*arguments)
    # The intervals and the pose: the same scalar operations; the polygons up to rounding.
    assert same(ours[1:], reference[1:])
    scale = scale_of(points, reference.points)
    ends = np.cumsum(ours.counts)
    for end, size in zip(ends.tolist(), ours.counts.tolist(), strict=True):
        polygon = ours.points[end - size : end]
        assert convexity_defect(polygon) is None
        assert (
            polygon_area(polygon)
            == pytest.approx(polygon_area(reference.points[end - size : end]), rel=1e-6, abs=1e-9 * scale**2)
            or len(polygon) == cap
        )


def random_pieces(rng: np.random.Generator) -> tuple[Array, Counts, Array, Array, Counts, int]:
    """Grown-like pieces: unwrapped intervals of any width, some sharing a source."""
    count = int(rng.integers(1, 7))
    polygons = [random_polygon(rng)[:1] if rng.uniform() < 0.2 else random_polygon(rng) for _ in range(count)]
    starts = rng.uniform(-7.0, 7.0, count)
    stops = starts + np.where(rng.uniform(0.0, 1.0, count) < 0.1, 7.0, rng.uniform(0.0, 2.0, count))
    sources = np.arange(count, dtype=np.int64)
    if count > 1 and rng.uniform() < 0.3:
        polygons[1] = polygons[0]
        sources[1] = 0
    cells = int(rng.choice([1, 7, 90, 180]))
    points = np.ascontiguousarray(np.concatenate(polygons))
    return points, np.array([len(p) for p in polygons], dtype=np.int64), starts, stops, sources, cells


@built
@given(st.integers(0, 2**32 - 1), st.sampled_from([3, 8, 64]), st.sampled_from([1, 3, 48, 1000]))
def test_compiled_redistribution_is_the_reference(seed: int, cap: int, max_slices: int) -> None:
    rng = np.random.default_rng(seed)
    points, counts, starts, stops, sources, cells = random_pieces(rng)
    if (
        len(points) * (1 + int(cells >= 90)) > 200
    ):  # the reference's hull prefilters larger groups with shapely
        return
    heading = float(rng.uniform(-math.pi, math.pi))
    arguments = (points, counts, starts, stops, sources, cells, cap, max_slices, heading)
    ours = native_slices.distribute_slices_compiled(*arguments)
    assert same(ours, native_slices.distribute_slices_reference(*arguments))
    assert len(ours.lo) <= max_slices
    assert np.all(np.diff(ours.lo) >= 0.0)
    assert np.all(ours.hi >= ours.lo)


@given(st.integers(0, 2**32 - 1), st.sampled_from([3, 8, 64]))
def test_every_piece_lands_in_a_slice_that_holds_it(seed: int, cap: int) -> None:
    rng = np.random.default_rng(seed)
    points, counts, starts, stops, sources, cells = random_pieces(rng)
    grid = _native.distribute_slices(points, counts, starts, stops, sources, cells, cap, 48, 0.0)
    ends = np.cumsum(grid.counts)
    scale = scale_of(points)
    for index, end in enumerate(np.cumsum(counts).tolist()):
        piece = points[end - int(counts[index]) : end]
        heading = float(rng.uniform(starts[index], stops[index]))
        offset = np.mod(heading - grid.lo, TWO_PI)
        holding = (offset <= grid.hi - grid.lo + 1e-9) | (offset >= TWO_PI - 1e-9)
        assert holding.any()
        found = False
        for slot in np.flatnonzero(holding).tolist():
            polygon = grid.points[int(ends[slot]) - int(grid.counts[slot]) : int(ends[slot])]
            found |= bool(
                ConvexPolygon._trusted(polygon.copy()).contains(piece, tolerance=1e-9 * scale).all()
            )
        assert found


@built
@given(st.integers(0, 2**32 - 1), st.sampled_from([3, 16, 64]))
def test_compiled_reductions_of_every_slice_are_the_loop_over_slices(seed: int, cap: int) -> None:
    rng = np.random.default_rng(seed)
    points, counts, lo, hi, heading = random_slices(rng)
    first = points[: int(counts[0])]
    cone = cone_arguments(rng, first)[5:]  # past the centre and the wedge
    x, y = first.mean(axis=0).tolist()
    packed = (points, counts, lo, hi, x, y, heading)
    ours = native_slices.reduce_cone_slices_compiled(*packed, *cone, cap)
    loop = native_slices._reduce_slices(native_reduce.reduce_cone_compiled, *packed, cone, cap)
    assert ours == loop if isinstance(ours, int) else same(ours, loop)  # type: ignore[arg-type]
    reference = native_slices.reduce_cone_slices_reference(*packed, *cone, cap)
    assert isinstance(ours, int) == isinstance(reference, int)
    if not isinstance(ours, int) and not isinstance(reference, int):
        assert ours.counts.shape == reference.counts.shape
        assert ours.lo == pytest.approx(reference.lo, abs=1e-9)
    strip = strip_arguments(rng, first)[5:]
    ours = native_slices.reduce_strip_slices_compiled(*packed, *strip, cap)
    loop = native_slices._reduce_slices(native_reduce.reduce_strip_compiled, *packed, strip, cap)
    assert ours == loop if isinstance(ours, int) else same(ours, loop)  # type: ignore[arg-type]


@built
def test_the_batched_kernels_refuse_bad_input() -> None:
    module = kernels()
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    one, zero = np.array([4], dtype=np.int64), np.zeros(1, dtype=np.int64)
    with pytest.raises(ValueError, match="counts: expected slice sizes adding up to the 4 rows"):
        module.distribute_slices(
            square, np.array([3], dtype=np.int64), np.zeros(1), np.ones(1), zero, 9, 8, 4, 0.0
        )
    with pytest.raises(ValueError, match="lo: expected a 1-D float64 buffer of 1 items"):
        module.distribute_slices(square, one, np.zeros(2), np.ones(1), zero, 9, 8, 4, 0.0)
    with pytest.raises(ValueError, match="counts: expected a 1-D int64 buffer"):
        module.distribute_slices(square, np.array([4.0]), np.zeros(1), np.ones(1), zero, 9, 8, 4, 0.0)
    with pytest.raises(ValueError, match="lo, hi: expected finite headings"):
        module.distribute_slices(square, one, np.full(1, np.nan), np.ones(1), zero, 9, 8, 4, 0.0)
    with pytest.raises(ValueError, match=r"cells: expected an integer in \[1, 16777216\], got 0"):
        module.distribute_slices(square, one, np.zeros(1), np.ones(1), zero, 0, 8, 4, 0.0)
    with pytest.raises(TypeError, match="grow_slices: expected 18 arguments, got 1"):
        module.grow_slices(square)
    with pytest.raises(ValueError, match="piece: expected a positive angle"):
        module.reduce_cone_slices(square, one, np.zeros(1), np.ones(1), 0, 0, 0, 0, 0, 5, 5, 0, 0, 0.1, 0,
                                  math.inf, 0.0, 8)  # fmt: skip
    with pytest.raises(TypeError, match="reduce_strip_slices: expected 19 arguments, got 2"):
        module.reduce_strip_slices(square, one)
    with pytest.raises(ValueError, match="counts: expected slice sizes adding up to the 4 rows"):
        native_slices.distribute_slices_reference(
            square, np.array([3]), np.zeros(1), np.ones(1), zero, 9, 8, 4, 0.0
        )
