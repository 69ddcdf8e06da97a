"""Merging heading slices: the compiled kernel against its numpy reference, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums._native._slices import merge_groups_compiled, merge_groups_reference
from aura_ums.geometry import ConvexPolygon
from tests._native.native_helpers import built, kernels, random_polygon


def random_groups(rng: np.random.Generator) -> tuple[np.ndarray, list[int]]:
    """Groups of 1 to 4 random polygons each (as a redistribution makes), moved apart a little."""
    polygons: list[np.ndarray] = []
    counts: list[int] = []
    for _ in range(int(rng.integers(1, 6))):
        members = [random_polygon(rng, many=rng.uniform() < 0.3) for _ in range(int(rng.integers(1, 5)))]
        members = [p + rng.normal(size=2) * float(rng.choice([0.0, 0.01, 1.0])) for p in members]
        polygons += members
        counts.append(sum(len(p) for p in members))
    return np.concatenate(polygons), counts


@built
@given(st.integers(0, 2**32 - 1), st.sampled_from([3, 8, 16, 64]))
def test_compiled_merge_is_the_reference(seed: int, cap: int) -> None:
    rng = np.random.default_rng(seed)
    points, counts = random_groups(rng)
    if max(counts) > 200:  # the reference's hull prefilters larger groups with shapely
        return
    ours = merge_groups_compiled(points, counts, cap)
    reference = merge_groups_reference(points, counts, cap)
    assert len(ours) == len(reference) == len(counts)
    for mine, theirs in zip(ours, reference, strict=True):
        assert mine.tobytes() == theirs.tobytes()
        assert not mine.flags.writeable


@built
@given(st.integers(0, 2**32 - 1), st.sampled_from(["shuffled", "ascending", "descending", "polygons"]))
def test_compiled_hull_sorts_any_order_as_the_reference(seed: int, order: str) -> None:
    # The hull's sort merges the runs its input already has: ties, repeats, long ascending
    # or descending runs and convex polygons one after the other must all sort as numpy does.
    rng = np.random.default_rng(seed)
    count = int(rng.integers(1, 150))
    points = rng.integers(-3, 4, size=(count, 2)).astype(np.float64) * float(rng.choice([1.0, 0.1, 1e-9]))
    if order == "polygons":
        points = np.concatenate([random_polygon(rng) for _ in range(int(rng.integers(1, 6)))])
    elif order != "shuffled":
        points = points[np.lexsort((points[:, 1], points[:, 0]))]
        if order == "descending":
            points = points[::-1]
    points = np.ascontiguousarray(points)
    cap = max(len(points), 3)  # no outer cap: the hull alone
    if len(points) > 200:  # the reference's hull prefilters larger groups with shapely
        return
    (ours,) = merge_groups_compiled(points, [len(points)], cap)
    (reference,) = merge_groups_reference(points, [len(points)], cap)
    assert ours.tobytes() == reference.tobytes()


@built
@pytest.mark.parametrize(("radius", "count"), [(1e-11, 150), (3e-12, 100)])
def test_compiled_hull_of_a_speck_is_the_references_segment(radius: float, count: int) -> None:
    # Every corner straight to within rounding: both kept nothing before (an empty hull).
    turn = np.linspace(0.0, 2.0 * np.pi, count, endpoint=False)
    speck = np.column_stack([16.0 + radius * np.cos(turn), 1.5 + radius * np.sin(turn)])
    (ours,) = merge_groups_compiled(speck, [count], count)
    (reference,) = merge_groups_reference(speck, [count], count)
    assert len(ours) == 2
    assert ours.tobytes() == reference.tobytes()


@built
def test_compiled_hull_keeps_a_corner_between_two_straight_ones_as_the_reference() -> None:
    from tests.geometry.test_polygon import _SLIVER

    (ours,) = merge_groups_compiled(_SLIVER, [len(_SLIVER)], len(_SLIVER))
    (reference,) = merge_groups_reference(_SLIVER, [len(_SLIVER)], len(_SLIVER))
    assert len(ours) == 4
    assert ours.tobytes() == reference.tobytes()


@built
@given(st.integers(0, 2**32 - 1))
def test_compiled_hull_drops_runs_of_straight_vertices_as_the_reference(seed: int) -> None:
    # Runs of near-straight vertices of every length on a polygon's edges: the reference's
    # every-other-one passes and the kernel's must keep the very same vertices.
    rng = np.random.default_rng(seed)
    corners = random_polygon(rng)
    pieces = []
    for k in range(len(corners)):
        a, b = corners[k], corners[(k + 1) % len(corners)]
        t = np.sort(rng.uniform(0.0, 1.0, int(rng.integers(0, 12))))
        pieces += [a[None, :], a + t[:, None] * (b - a)]
    points = np.ascontiguousarray(np.concatenate(pieces))
    cap = max(len(points), 3)
    (ours,) = merge_groups_compiled(points, [len(points)], cap)
    (reference,) = merge_groups_reference(points, [len(points)], cap)
    assert ours.tobytes() == reference.tobytes()


@given(st.integers(0, 2**32 - 1), st.sampled_from([3, 8, 64]))
def test_each_merge_holds_its_group_within_the_cap(seed: int, cap: int) -> None:
    from aura_ums import _native

    rng = np.random.default_rng(seed)
    points, counts = random_groups(rng)
    start = 0
    for hull, count in zip(_native.merge_groups(points, counts, cap), counts, strict=True):
        assert len(hull) <= max(cap, 3)
        group = points[start : start + count]
        if len(hull) >= 3:
            scale = float(np.abs(group).max()) + 1.0
            assert ConvexPolygon._trusted(hull).contains(group, tolerance=1e-9 * scale).all()
        start += count


@built
def test_the_kernel_refuses_bad_input() -> None:
    merge = kernels().merge_groups
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    with pytest.raises(ValueError, match="counts: expected group sizes adding up to the 4 rows"):
        merge(square, [3], 8)
    with pytest.raises(ValueError, match=r"counts\[i\]: expected an integer in \[1, 4\], got 0"):
        merge(square, [0, 4], 8)
    with pytest.raises(TypeError, match="counts: expected a sequence of integers"):
        merge(square, 4, 8)
    with pytest.raises(ValueError, match="max_vertices: expected at least 3, got 2"):
        merge(square, [4], 2)
    with pytest.raises(TypeError, match="merge_groups: expected 3 arguments, got 1"):
        merge(square)
    with pytest.raises(ValueError, match="counts: expected group sizes adding up to the 4 rows"):
        merge_groups_reference(square, [3], 8)
    with pytest.raises(ValueError, match="max_vertices: expected at least 3, got 2"):
        merge_groups_reference(square, [4], 2)
