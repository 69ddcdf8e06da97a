"""The polygon-to-segment distance: compiled against shapely, its reference."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums._native._distance import (
    point_in_solid_convex_compiled,
    point_in_solid_convex_reference,
    polygon_distance_compiled,
    polygon_distance_reference,
)
from aura_ums.geometry import polygon_area
from tests._native.native_helpers import built, random_polygon, scale_of


@built
@given(st.integers(0, 2**32 - 1), st.sampled_from(["point", "segment", "long segment"]))
def test_compiled_distance_agrees_with_shapely(seed: int, kind: str) -> None:
    rng = np.random.default_rng(seed)
    vertices = random_polygon(rng)
    center = vertices.mean(axis=0)
    a = center + rng.normal(size=2) * float(rng.choice([0.1, 3.0, 30.0]))
    b = a if kind == "point" else a + rng.normal(size=2) * (20.0 if kind == "long segment" else 1.0)
    ends = (*a.tolist(), *b.tolist())
    ours = polygon_distance_compiled(vertices, *ends)
    reference = polygon_distance_reference(vertices, *ends)
    assert ours == pytest.approx(reference, rel=1e-9, abs=1e-12 * scale_of(vertices, np.array([a, b])))


@built
def test_touching_crossing_and_apart_are_exercised() -> None:
    rng = np.random.default_rng(11)
    touching = 0
    for _ in range(2000):
        vertices = random_polygon(rng)
        a = vertices.mean(axis=0) + rng.normal(size=2) * 3.0
        b = a + rng.normal(size=2) * 3.0
        ours = polygon_distance_compiled(vertices, *a.tolist(), *b.tolist())
        assert ours == pytest.approx(polygon_distance_reference(vertices, *a.tolist(), *b.tolist()), abs=1e-9)
        touching += ours == 0.0
    assert 100 < touching < 1900


@built
def test_the_kernel_refuses_bad_input() -> None:
    from aura_ums._native._kernels import polygon_distance

    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    with pytest.raises(ValueError, match=r"ax: expected a finite number"):
        polygon_distance(square, math.nan, 0.0, 1.0, 1.0)
    with pytest.raises(TypeError, match=r"vertices: expected a C-contiguous \(n, 2\) float64 buffer"):
        polygon_distance(None, 0.0, 0.0, 1.0, 1.0)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="polygon_distance: expected 5 arguments, got 1"):
        polygon_distance(square)  # type: ignore[call-arg]


@built
@given(st.integers(0, 2**32 - 1), st.sampled_from([0.0, 1e-9, 1e-3]))
def test_compiled_point_test_is_the_reference(seed: int, tolerance: float) -> None:
    # Bit for bit: points on, just inside and just outside an edge decide alike.
    rng = np.random.default_rng(seed)
    vertices = random_polygon(rng, many=bool(rng.uniform() < 0.3))
    if len(vertices) < 3 or polygon_area(vertices) <= 0.0:
        return
    edge = int(rng.integers(len(vertices)))
    start, stop = vertices[edge], vertices[(edge + 1) % len(vertices)]
    on_edge = start + rng.uniform() * (stop - start)
    inner = vertices.mean(axis=0)
    for point in (on_edge, on_edge + (on_edge - inner) * 1e-12, on_edge + (on_edge - inner) * 1e-9, inner,
                  inner + rng.normal(size=2) * 5.0):  # fmt: skip
        x, y = point.tolist()
        ours = point_in_solid_convex_compiled(vertices, x, y, tolerance)
        assert ours is point_in_solid_convex_reference(vertices, x, y, tolerance)


@built
def test_the_point_test_refuses_what_is_not_solid() -> None:
    from aura_ums._native._kernels import point_in_solid_convex

    segment = np.array([[0.0, 0.0], [1.0, 0.0]])
    with pytest.raises(ValueError, match="vertices: expected a solid polygon of at least 3 vertices, got 2"):
        point_in_solid_convex(segment, 0.5, 0.0, 0.0)
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    with pytest.raises(ValueError, match="tolerance: expected a finite number"):
        point_in_solid_convex(square, 0.5, 0.5, math.inf)
    with pytest.raises(TypeError, match="point_in_solid_convex: expected 4 arguments, got 3"):
        point_in_solid_convex(square, 0.5, 0.5)  # type: ignore[call-arg]  # the wrong count is the test
