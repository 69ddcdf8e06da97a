"""The joint reduction's sectors kernel: its loop against the single kernels', compiled against reference."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums import _native
from aura_ums._native import CONE_PIECE, SECTOR_ROW, ReducedSectors
from aura_ums._native import _reduce as native_reduce
from aura_ums._native._reduce import reduce_sectors_reference
from aura_ums.geometry._convex import convexity_defect
from tests._native.native_helpers import Array, built, contains, kernels, random_polygon, scale_of
from tests._native.test_native_reduce import cone_arguments, strip_arguments

#: The numbers of a cone's and a strip's row after the kind: the kernels' arguments after
#: the centre and the wedge (five numbers), without the cap.
_CONE_NUMBERS = slice(5, 15)
_STRIP_NUMBERS = slice(5, 16)


def random_rows(rng: np.random.Generator, vertices: Array) -> list[float]:
    """One to three observation rows, cones and strips mixed: often consistent, not always."""
    rows: list[float] = []
    for _ in range(int(rng.integers(1, 4))):
        if rng.uniform() < 0.7:
            numbers = list(cone_arguments(rng, vertices))[_CONE_NUMBERS]
            rows += [0.0, *numbers, 0.0]
        else:
            rows += [1.0, *list(strip_arguments(rng, vertices))[_STRIP_NUMBERS]]
    return rows


def random_sectors(rng: np.random.Generator) -> tuple[float, float, int, float]:
    """(lo, step, count, half): a wedge of up to a full circle split into 1 to 40 sectors."""
    width = float(rng.choice([2.0 * math.pi, rng.uniform(0.01, 2.0 * math.pi)]))
    count = int(rng.integers(1, 41))
    step = width / count
    return float(rng.uniform(-4.0, 4.0)), step, count, 0.5 * step + 1e-9


@built
@given(st.integers(0, 2**32 - 1), st.sampled_from([3, 5, 16, 64]))
def test_the_compiled_loop_is_the_reference_loop_over_the_compiled_kernels(seed: int, cap: int) -> None:
    # The reference loop run with the compiled single kernels must give the compiled sectors
    # kernel bit for bit: it repeats the joint reduction's loop, no more and no less.
    rng = np.random.default_rng(seed)
    prior = random_polygon(rng)
    x, y = prior.mean(axis=0).tolist()
    lo, step, count, half = random_sectors(rng)
    rows = random_rows(rng, prior)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(native_reduce, "reduce_cone_reference", native_reduce.reduce_cone_compiled)
        patch.setattr(native_reduce, "reduce_strip_reference", native_reduce.reduce_strip_compiled)
        looped = reduce_sectors_reference(prior, x, y, lo, step, count, half, rows, cap)
    compiled = native_reduce.reduce_sectors_compiled(prior, x, y, lo, step, count, half, rows, cap)
    assert compiled.sectors.tolist() == looped.sectors.tolist()
    assert compiled.counts.tolist() == looped.counts.tolist()
    assert np.array_equal(compiled.points, looped.points)
    assert np.array_equal(compiled.values, looped.values)


@built
@given(st.integers(0, 2**32 - 1))
def test_compiled_sectors_agree_with_the_reference(seed: int) -> None:
    rng = np.random.default_rng(seed)
    prior = random_polygon(rng)
    x, y = prior.mean(axis=0).tolist()
    lo, step, count, half = random_sectors(rng)
    rows = random_rows(rng, prior)
    # No cap at work: the single kernels agree to rounding, so the sectors do.
    compiled = native_reduce.reduce_sectors_compiled(prior, x, y, lo, step, count, half, rows, 1_000_000)
    reference = reduce_sectors_reference(prior, x, y, lo, step, count, half, rows, 1_000_000)
    scale = scale_of(prior)
    assert compiled.sectors.tolist() == reference.sectors.tolist()
    assert compiled.values[:, 2:] == pytest.approx(reference.values[:, 2:], abs=1e-9)
    starts = np.concatenate([[0], np.cumsum(compiled.counts)])
    others = np.concatenate([[0], np.cumsum(reference.counts)])
    for index in range(len(compiled.sectors)):
        ours = compiled.points[starts[index] : starts[index + 1]]
        theirs = reference.points[others[index] : others[index + 1]]
        assert convexity_defect(ours) is None
        assert contains(ours, theirs, 1e-7 * scale)
        assert contains(theirs, ours, 1e-7 * scale)


_SQUARE = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
#: A pole at (5, 0) seen dead ahead (bearing 0 +- 0.05 rad) by a sensor at the robot's centre.
_AHEAD = [0.0, 0.0, 0.0, 5.0, 0.0, 0.0, 0.0, 0.05, 0.0, math.inf, CONE_PIECE, 0.0]
#: The ground line y = -2 seen 2 m to the right (offset -2 +- 0.5 m, angle 0 +- 0.05 rad).
_LINE_RIGHT = [1.0, 0.0, 0.0, -9.0, -2.0, 9.0, -2.0, 0.0, 2.0, 0.5, 0.0, 0.05]

_KERNELS = [reduce_sectors_reference] + ([native_reduce.reduce_sectors_compiled] if _native.BUILT else [])


@pytest.mark.parametrize("kernel", _KERNELS, ids=lambda k: k.__name__)
def test_only_the_sectors_facing_the_pole_are_kept(kernel: object) -> None:
    assert callable(kernel)
    # A full circle in four quarter sectors; the pole ahead at +x is seen only from the two
    # sectors that meet at heading 0, and each narrows to its side of 0: as far as the
    # square's corners see the pole off the x axis (atan(1 / 4)), plus the bearing error.
    kept: ReducedSectors = kernel(_SQUARE, 0.0, 0.0, -math.pi, math.pi / 2, 4, math.pi / 4 + 1e-9, _AHEAD, 16)
    assert kept.sectors.tolist() == [1, 2]
    assert kept.counts.tolist() == [4, 4]
    reach = math.atan(1.0 / 4.0) + 0.05
    (x, y, *below), (_, _, *above) = kept.values.tolist()
    assert (x, y) == (0.0, 0.0)
    assert [below[0] - below[1], below[0] + below[2]] == pytest.approx([-reach, 0.0], abs=1e-6)
    assert [above[0] - above[1], above[0] + above[2]] == pytest.approx([0.0, reach], abs=1e-6)


@pytest.mark.parametrize("kernel", _KERNELS, ids=lambda k: k.__name__)
def test_no_sector_kept_gives_empty_arrays(kernel: object) -> None:
    assert callable(kernel)
    # Facing away from the pole (headings 2 to 3 rad): nothing sees it ahead.
    kept: ReducedSectors = kernel(_SQUARE, 0.0, 0.0, 2.0, 0.5, 2, 0.25, _AHEAD, 16)
    assert kept.points.shape == (0, 2)
    assert kept.counts.shape == kept.sectors.shape == (0,)
    assert kept.values.shape == (0, 5)


@pytest.mark.parametrize("kernel", _KERNELS, ids=lambda k: k.__name__)
def test_rows_reduce_in_turn_and_a_strip_cuts_positions(kernel: object) -> None:
    assert callable(kernel)
    # One sector round heading 0: the pole keeps the whole square, then the ground line
    # y = -2, seen 2 +- 0.5 m to the right, keeps the band |y| <= 0.5 of it.
    kept: ReducedSectors = kernel(_SQUARE, 0.0, 0.0, -0.1, 0.2, 1, 0.1, [*_AHEAD, *_LINE_RIGHT], 16)
    assert kept.sectors.tolist() == [0]
    ys, xs = kept.points[:, 1], kept.points[:, 0]
    assert (ys.min(), ys.max()) == pytest.approx((-0.5, 0.5), abs=1e-6)
    assert (xs.min(), xs.max()) == pytest.approx((-1.0, 1.0), abs=1e-12)


@built
def test_the_kernel_refuses_bad_arguments() -> None:
    reduce_sectors = kernels().reduce_sectors
    start = (_SQUARE, 0.0, 0.0, 0.0, 0.5, 2, 0.25)
    with pytest.raises(TypeError, match="reduce_sectors: expected 9 arguments, got 8"):
        reduce_sectors(*start, _AHEAD)
    with pytest.raises(
        ValueError, match=f"arguments: expected rows of {SECTOR_ROW} numbers, at least one, got 11"
    ):
        reduce_sectors(*start, _AHEAD[:11], 16)
    with pytest.raises(ValueError, match="arguments: expected rows of 12 numbers, at least one, got 0"):
        reduce_sectors(*start, [], 16)
    with pytest.raises(ValueError, match=r"arguments: expected kind 0 \(cone\) or 1 \(strip\), got 2\.0"):
        reduce_sectors(*start, [2.0, *_AHEAD[1:]], 16)
    with pytest.raises(ValueError, match="bearing: expected a finite number, got nan"):
        reduce_sectors(*start, [*_AHEAD[:6], math.nan, *_AHEAD[7:]], 16)
    with pytest.raises(
        ValueError, match=r"piece: expected a positive angle of at least 2 pi / 1e6, got 0\.0"
    ):
        reduce_sectors(*start, [*_AHEAD[:10], 0.0, 0.0], 16)
    with pytest.raises(ValueError, match=r"count: expected an integer in \[1, 1000000\], got 0"):
        reduce_sectors(_SQUARE, 0.0, 0.0, 0.0, 0.5, 0, 0.25, _AHEAD, 16)
    with pytest.raises(ValueError, match="max_vertices: expected at least 3, got 2"):
        reduce_sectors(*start, _AHEAD, 2)
    with pytest.raises(TypeError, match="arguments: expected a sequence of numbers"):
        reduce_sectors(*start, 7, 16)
