"""Tests of arc arithmetic: intersections and directions subtended by a polygon."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums.geometry import ConvexPolygon, intersect_arcs, subtended_arc
from aura_ums.geometry._angles import TWO_PI
from aura_ums.geometry._arcs import nearest_on_polygon

SQUARE = np.array([[1.0, -1.0], [3.0, -1.0], [3.0, 1.0], [1.0, 1.0]])


def in_arc(direction: float, arc: tuple[float, float], tolerance: float = 1e-9) -> bool:
    lo, width = arc
    offset = (direction - lo) % TWO_PI
    return width >= TWO_PI or offset <= width + tolerance or offset >= TWO_PI - tolerance


def test_two_pieces_give_the_enclosing_arc_inside_the_first() -> None:
    # second covers both ends of first: the pieces are [0, 0.5] and [2.5, 3] of first.
    result = intersect_arcs((0.0, 3.0), (2.5, TWO_PI - 2.0))
    assert result == pytest.approx((0.0, 3.0))
    # The other way round the enclosing arc lies in the (now) first arc.
    lo, width = intersect_arcs((2.5, TWO_PI - 2.0), (0.0, 3.0)) or (math.nan, math.nan)
    assert width == pytest.approx(TWO_PI - 2.0)
    assert lo == pytest.approx(2.5)


def test_full_circles_and_disjoint_arcs() -> None:
    assert intersect_arcs((1.0, TWO_PI), (2.0, 0.5)) == (2.0, 0.5)
    assert intersect_arcs((2.0, 0.5), (1.0, 7.0)) == (2.0, 0.5)
    assert intersect_arcs((0.0, 1.0), (1.5, 1.0)) is None
    # Touching ends meet in a single direction.
    assert intersect_arcs((0.0, 1.0), (1.0, 1.0)) == (1.0, 0.0)


def test_subtended_arc_of_a_square() -> None:
    lo, width = subtended_arc(SQUARE, np.zeros(2))
    assert (lo, width) == pytest.approx((-math.pi / 4, math.pi / 2))
    widened = subtended_arc(SQUARE, np.zeros(2), 0.5)
    # The nearest point is at 1 m: the directions widen by asin(0.5) on each side.
    assert widened == pytest.approx((-math.pi / 4 - math.asin(0.5), math.pi / 2 + 2 * math.asin(0.5)))


def test_subtended_arc_is_full_from_inside_or_within_reach() -> None:
    assert subtended_arc(SQUARE, np.array([2.0, 0.0]))[1] == TWO_PI
    assert subtended_arc(SQUARE, np.array([1.0, 0.0]))[1] == TWO_PI  # on the boundary
    assert subtended_arc(SQUARE, np.array([0.5, 0.0]), 0.5)[1] == TWO_PI
    assert subtended_arc(SQUARE, np.array([0.5, 0.0]), 0.49)[1] < TWO_PI


def test_subtended_arc_of_degenerate_polygons() -> None:
    point = np.array([[3.0, 3.0]])
    assert subtended_arc(point, np.zeros(2)) == pytest.approx((math.pi / 4, 0.0))
    segment = np.array([[1.0, 0.0], [0.0, 1.0]])
    assert subtended_arc(segment, np.zeros(2)) == pytest.approx((0.0, math.pi / 2))
    assert subtended_arc(segment, np.array([0.5, 0.5]))[1] == TWO_PI  # on the segment


def test_nearest_on_polygon() -> None:
    assert nearest_on_polygon(SQUARE, np.array([2.0, 0.5]))[0] == 0.0
    distance, nearest = nearest_on_polygon(SQUARE, np.array([0.0, 2.0]))
    assert distance == pytest.approx(math.sqrt(2.0))
    assert nearest.tolist() == [1.0, 1.0]
    assert nearest_on_polygon(np.array([[1.0, 1.0]]), np.zeros(2))[0] == pytest.approx(math.sqrt(2.0))
    distance, nearest = nearest_on_polygon(np.array([[0.0, 0.0], [2.0, 0.0]]), np.array([1.0, 1.0]))
    assert (distance, nearest.tolist()) == (1.0, [1.0, 0.0])


@given(st.integers(0, 2**32 - 1), st.floats(0.0, 2.0))
def test_subtended_arc_holds_every_direction(seed: int, radius: float) -> None:
    rng = np.random.default_rng(seed)
    polygon = ConvexPolygon.from_points(
        rng.normal(size=(int(rng.integers(1, 12)), 2)) + rng.uniform(-4, 4, 2)
    )
    point = rng.uniform(-5.0, 5.0, 2)
    arc = subtended_arc(np.asarray(polygon.vertices), point, radius)
    angle = rng.uniform(0.0, TWO_PI, 200)
    reach = radius * np.sqrt(rng.uniform(size=200))
    targets = polygon.sample(200, rng) + np.column_stack([reach * np.cos(angle), reach * np.sin(angle)])
    gap = targets - point
    for direction in np.arctan2(gap[:, 1], gap[:, 0]).tolist():
        assert in_arc(direction, arc)
