"""Heading slices: a pose set kept as convex polygons on a fixed global grid of headings.

A product map (one polygon of positions, one wedge of headings) smears every position
over every heading. A *sliced* map keeps, for each heading interval of a fixed global grid
(cells of width ``2 pi / cells``, the first starting at heading 0), the convex polygon of
the positions possible at those headings. The pose set is the union over slices of
``polygon x interval``. A slice's interval lies inside one grid cell, or inside a run of
contiguous cells when the slice count was capped.

These are pure functions on plain values; :class:`~aura_ums.uncertainty.SpatialUncertaintyMap`
holds the slices and calls them. Every operation here is an outer bound:

- :func:`split_product` cuts a product map into one slice per covered cell (exact);
- :func:`distribute` puts grown slices back on the grid: a piece spanning several cells
  gives its polygon to each, and the pieces of one cell merge by convex hull;
- :func:`capped` merges neighbouring slices (hull of polygons, span of intervals) until at
  most ``max_slices`` remain.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from aura_ums import _native
from aura_ums.geometry import ConvexPolygon, HeadingWedge, points_in_convex

Array = NDArray[np.float64]

_TWO_PI = 2.0 * math.pi

#: Default width of a grid cell, radians (2 degrees).
DEFAULT_SLICE_WIDTH = math.radians(2.0)

#: Default cap on a map's slice count.
DEFAULT_MAX_SLICES = 48

#: Angular slack (radians) when testing a heading against a slice, as wedges allow.
_ANGLE_SLACK = 1e-9


class Slice(NamedTuple):
    """One heading slice, as plain numbers.

    Attributes
    ----------
    lo : float
        Clockwise-most heading, radians, in [0, 2 pi).
    hi : float
        Counter-clockwise-most heading, radians, ``lo <= hi <= lo + 2 pi`` (not wrapped).
    vertices : ndarray, shape (n, 2)
        Counter-clockwise convex polygon of the positions possible at those headings, m.
    """

    lo: float
    hi: float
    vertices: Array


class HeadingSlice(NamedTuple):
    """One slice of a map: the positions possible at an interval of headings.

    Attributes
    ----------
    polygon : ConvexPolygon
        Positions, metres, world frame.
    lo : float
        Clockwise-most heading of the interval, radians, in [0, 2 pi).
    width : float
        Width of the interval, radians, in [0, 2 pi].

    Examples
    --------
    >>> piece = HeadingSlice(ConvexPolygon.point(1.0, 2.0), 0.0, 0.1)
    >>> round(piece.wedge.center, 3), round(piece.wedge.width, 3)
    (0.05, 0.1)
    """

    polygon: ConvexPolygon
    lo: float
    width: float

    @property
    def wedge(self) -> HeadingWedge:
        """The interval as a wedge centred on its middle."""
        half = 0.5 * self.width
        return HeadingWedge._trusted(self.lo + half, half, half)


def cell_count(width: float) -> int:
    """Return the number of grid cells for a requested cell width (radians, in (0, 2 pi]).

    The grid has a whole number of cells round the circle, each at most ``width`` wide.

    Examples
    --------
    >>> cell_count(math.radians(2.0)), cell_count(2.0 * math.pi), cell_count(1.0)
    (180, 1, 7)
    """
    return max(1, math.ceil(_TWO_PI / width - 1e-9))


def split_product(vertices: Array, lo: float, width: float, cells: int) -> tuple[Slice, ...]:
    """Cut a product map (a polygon, headings ``lo`` to ``lo + width``) into one slice per covered cell.

    Parameters
    ----------
    vertices : ndarray, shape (n, 2)
        The polygon, counter-clockwise, metres.
    lo, width : float
        The headings, radians (``width >= 2 pi``: every heading).
    cells : int
        Cells of the grid, >= 1.

    Examples
    --------
    >>> point = np.zeros((1, 2))
    >>> [(round(s.lo, 3), round(s.hi, 3)) for s in split_product(point, -0.1, 0.3, 36)]
    [(0.0, 0.175), (0.175, 0.2), (6.183, 6.283)]
    >>> len(split_product(point, 0.0, 7.0, 36))    # every heading: every cell
    36
    """
    return distribute([(lo, lo + width, vertices)], cells, len(vertices))


def distribute(
    pieces: Sequence[tuple[float, float, Array]], cells: int, max_vertices: int
) -> tuple[Slice, ...]:
    """Put heading intervals with polygons onto the grid, one slice per covered cell.

    A piece ``(a, b, vertices)`` (radians, unwrapped, ``a <= b``; ``b - a >= 2 pi`` is every
    heading) gives its polygon to every cell it meets, with its interval cut to the cell.
    The pieces of one cell merge: the convex hull of their polygons (an outer polygon of at
    most ``max_vertices`` vertices when it has more) and the span of their intervals.

    Returns
    -------
    tuple of Slice
        Ordered by ``lo``; each slice's interval inside its cell.
    """
    step = _TWO_PI / cells
    starts = np.array([a for a, _, _ in pieces])
    stops = np.array([b for _, b, _ in pieces])
    every = stops - starts >= _TWO_PI
    starts[every], stops[every] = 0.0, _TWO_PI
    first = np.floor(starts / step).astype(np.int64)
    last = np.maximum(first, np.ceil(stops / step).astype(np.int64) - 1)
    # One row per (piece, cell it meets): k the cell's unwrapped index.
    spans = last - first + 1
    owner = np.repeat(np.arange(len(pieces)), spans)
    k = np.repeat(first - np.cumsum(spans) + spans, spans) + np.arange(int(spans.sum()))
    cell = k % cells
    shift = (k - cell) * step
    cell_lo, cell_hi = cell * step, (cell + 1) * step
    # Rounding must not leave the cell, nor turn the interval inside out.
    lo = np.minimum(np.maximum(np.maximum(starts[owner], k * step) - shift, cell_lo), cell_hi)
    hi = np.minimum(np.maximum(np.minimum(stops[owner], (k + 1) * step) - shift, lo), cell_hi)
    occupied, where = np.unique(cell, return_inverse=True)
    lows = np.full(len(occupied), np.inf)
    highs = np.full(len(occupied), -np.inf)
    np.minimum.at(lows, where, lo)
    np.maximum.at(highs, where, hi)
    groups: list[list[Array]] = [[] for _ in range(len(occupied))]
    for slot, index in zip(where.tolist(), owner.tolist(), strict=True):
        groups[slot].append(pieces[index][2])
    hulls = merged_all(groups, max_vertices)
    return tuple(
        Slice(low, high, hull) for low, high, hull in zip(lows.tolist(), highs.tolist(), hulls, strict=True)
    )


def merged_all(groups: Sequence[Sequence[Array]], max_vertices: int) -> list[Array]:
    """Return, for each group of polygons, their convex hull capped at ``max_vertices`` (outer).

    A group of one polygon (or of one polygon several times) is that polygon; the others
    go through one call of the merging kernel.
    """
    result: list[Array | None] = []
    points: list[Array] = []
    counts: list[int] = []
    for polygons in groups:
        first = polygons[0]
        if all(p is first for p in polygons):
            result.append(first)
            continue
        result.append(None)
        points += polygons
        counts.append(sum(len(p) for p in polygons))
    if not counts:
        return [r for r in result if r is not None]
    hulls = iter(_native.merge_groups(np.concatenate(points), counts, max(max_vertices, 3)))
    return [next(hulls) if r is None else r for r in result]


def capped(slices: tuple[Slice, ...], max_slices: int, max_vertices: int) -> tuple[Slice, ...]:
    """Merge neighbouring slices (in heading order) into groups until at most ``max_slices`` remain.

    A group's interval runs from its first slice's ``lo`` to its last's ``hi`` (covering
    any cells between them) and its polygon is the hull of theirs: an outer bound.

    Examples
    --------
    >>> point = np.zeros((1, 2))
    >>> few = capped(split_product(point, 0.0, 1.0, 36), 3, 8)
    >>> [(round(s.lo, 3), round(s.hi, 3)) for s in few]
    [(0.0, 0.349), (0.349, 0.698), (0.698, 1.0)]
    """
    count = len(slices)
    if count <= max_slices:
        return slices
    size = math.ceil(count / max_slices)
    groups = [slices[start : start + size] for start in range(0, count, size)]
    hulls = merged_all([[s.vertices for s in group] for group in groups], max_vertices)
    return tuple(
        Slice(group[0].lo, max(s.hi for s in group), hull) for group, hull in zip(groups, hulls, strict=True)
    )


def unwrapped_near(heading: float, lo: float) -> float:
    """Return ``heading`` plus a whole number of turns, in [lo, lo + 2 pi)."""
    return lo + (heading - lo) % _TWO_PI


def clamp_into(heading: float, lo: float, hi: float) -> float:
    """Return the heading of [lo, hi] (unwrapped) nearest to ``heading``, unwrapped near ``lo``."""
    offset = (heading - lo) % _TWO_PI
    if offset <= hi - lo:
        return lo + offset
    # Outside: the nearer end, the shorter way round.
    return hi if offset - (hi - lo) < _TWO_PI - offset else lo


def angular_gap(heading: float, lo: float, hi: float) -> float:
    """Radians from ``heading`` to the interval [lo, hi] (0 inside it)."""
    offset = (heading - lo) % _TWO_PI
    if offset <= hi - lo:
        return 0.0
    return min(offset - (hi - lo), _TWO_PI - offset)


def home_slice(slices: Sequence[Slice], heading: float) -> int:
    """Return the index of the slice nearest in heading to ``heading`` (the first that holds it)."""
    best, best_gap = 0, math.inf
    for index, piece in enumerate(slices):
        gap = angular_gap(heading, piece.lo, piece.hi)
        if gap == 0.0:
            return index
        if gap < best_gap:
            best, best_gap = index, gap
    return best


def summary_wedge(slices: Sequence[Slice], heading: float) -> HeadingWedge:
    """Return the smallest wedge holding every slice's interval, centred on ``heading``.

    ``heading`` must lie in one of the intervals (it is clamped into the wedge otherwise).
    The wedge leaves out the widest gap between the (ordered, disjoint but for shared
    ends) intervals; none left out: the full circle.
    """
    if len(slices) == 1:
        lo, hi = slices[0].lo, slices[0].hi
    else:
        reach = slices[0].hi
        widest, after = -math.inf, 0
        for index in range(1, len(slices)):
            gap = slices[index].lo - reach
            if gap > widest:
                widest, after = gap, index
            reach = max(reach, slices[index].hi)
        wrap = slices[0].lo + _TWO_PI - reach
        if wrap >= widest:
            widest, after = wrap, 0
        if widest <= _ANGLE_SLACK:
            # No gap but rounding's between neighbouring cells: every heading.
            return HeadingWedge._trusted(heading, math.pi, math.pi)
        lo = slices[after].lo
        hi = lo + _TWO_PI - widest
    if hi - lo >= _TWO_PI:
        return HeadingWedge._trusted(heading, math.pi, math.pi)
    center = clamp_into(heading, lo, hi)
    return HeadingWedge._trusted(center, center - lo, hi - center)


def summary_polygon(slices: Sequence[Slice]) -> Array:
    """Return the convex hull of every slice's polygon (counter-clockwise, metres)."""
    return merged_all([[s.vertices for s in slices]], sum(len(s.vertices) for s in slices))[0]


def contains(slices: Sequence[Slice], points: Array, headings: Array, tolerance: float) -> NDArray[np.bool_]:
    """Tell which poses lie in some slice: position in its polygon, heading in its interval.

    Parameters
    ----------
    slices : sequence of Slice
        The map's slices.
    points : ndarray, shape (m, 2)
        Positions, metres.
    headings : ndarray, shape (m,)
        Headings, radians, any winding.
    tolerance : float
        Metres outside a polygon that still count as inside.
    """
    inside = np.zeros(len(points), dtype=bool)
    for piece in slices:
        offset = np.mod(headings - piece.lo, _TWO_PI)
        width = piece.hi - piece.lo
        near = (offset <= width + _ANGLE_SLACK) | (offset >= _TWO_PI - _ANGLE_SLACK) | (width >= _TWO_PI)
        candidates = near & ~inside
        if candidates.any():
            inside[candidates] = points_in_convex(piece.vertices, points[candidates], tolerance)
    return inside
