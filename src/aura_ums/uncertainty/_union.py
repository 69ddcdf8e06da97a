"""An outer bound of the union of maps: the hull of their polygons and the union of their wedges."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from aura_ums._validate import finite_float, sequence_of
from aura_ums.errors import InputError
from aura_ums.geometry import ConvexPolygon, HeadingWedge
from aura_ums.uncertainty._growth import DEFAULT_MAX_VERTICES, MAX_VERTICES
from aura_ums.uncertainty._map import SpatialUncertaintyMap
from aura_ums.uncertainty._slices import distributed, split_product

_TWO_PI = 2.0 * math.pi


def union_of_maps(
    maps: Sequence[SpatialUncertaintyMap], *, max_vertices: int = DEFAULT_MAX_VERTICES
) -> SpatialUncertaintyMap:
    """Return one map holding every pose of every map given (an outer bound of their union).

    The polygon is an outer bound of the convex hull of the maps' polygons: the polygon of
    their supporting lines in ``max_vertices`` fixed directions (exact at the hull's
    vertices, a thin bulge over each hull edge, at most ``max_vertices`` vertices, at a
    fixed cost); the wedge is the shortest arc of headings that
    holds every map's wedge (the full circle when no arc shorter than a turn does). The
    first map is the primary one: its centre and most probable heading are kept. Only the
    maps' ``polygon``, ``wedge`` and ``center`` are read.

    Parameters
    ----------
    maps : sequence of SpatialUncertaintyMap
        At least one map. A single map is returned as it is.
    max_vertices : int
        Cap on the hull's vertex count (>= 3).

    Returns
    -------
    SpatialUncertaintyMap
        Contains every pose (position in a polygon, heading in that map's wedge) of every
        map; positions and headings combine freely (a product set, hence an outer bound).
        When the first map is heading-sliced, the union is sliced on its grid: each cell
        holds the hull of every map's positions at its headings.

    Raises
    ------
    InputError
        For an empty sequence, an item that is not a map, or ``max_vertices < 3``.

    Examples
    --------
    >>> from aura_ums.uncertainty import Pose
    >>> east = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 3.0), 1.0, 0.1)
    >>> west = SpatialUncertaintyMap.from_pose(Pose(4.0, 0.0, -3.0), 1.0, 0.1)
    >>> both = union_of_maps([east, west])
    >>> both.contains(Pose(2.0, 0.0, math.pi)), round(both.wedge.width, 4)   # across the seam
    (True, 0.4832)
    >>> both.most_probable_pose() == east.most_probable_pose()
    True
    >>> union_of_maps([east]) is east                  # one map: itself
    True
    >>> union_of_maps([])
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: maps: expected at least one SpatialUncertaintyMap, got none
    """
    if isinstance(max_vertices, bool) or not isinstance(max_vertices, int) or max_vertices < 3:
        raise InputError(f"max_vertices: expected an integer >= 3, got {max_vertices!r}")
    if max_vertices > MAX_VERTICES:
        raise InputError(
            f"max_vertices: expected at most {MAX_VERTICES} (the hull is built from that many supporting "
            f"directions, about 100 bytes each), got {max_vertices} (about {max_vertices * 100 / 1e9:.3g} GB)"
        )
    items = sequence_of(maps, SpatialUncertaintyMap, "maps")
    if not items:
        raise InputError("maps: expected at least one SpatialUncertaintyMap, got none")
    primary = items[0]
    if len(items) == 1:
        return primary
    if primary.is_sliced:
        return _sliced_union(primary, items, max_vertices)
    polygon = _support_hull([item.polygon.vertices for item in items], max_vertices)
    wedge = _union_of_wedges([item.wedge for item in items], primary.wedge.center)
    return SpatialUncertaintyMap._trusted(polygon, primary.center.copy(), wedge)


def _sliced_union(
    primary: SpatialUncertaintyMap, items: Sequence[SpatialUncertaintyMap], max_vertices: int
) -> SpatialUncertaintyMap:
    """Return the union on the first map's heading grid: each cell the hull of the positions there.

    A product map among them is cut onto the grid first (its polygon in every cell its
    wedge meets). Each cell then holds every pose any map held at its headings: an outer
    bound, as tight as the grid allows; the slice cap merges neighbours, as growth does.
    """
    cells, cap = primary._cells, primary._max_slices
    parts = []
    # Slices of one map that hold one polygon keep their common source; no two maps share one.
    offset = 0
    seen: dict[int, int] = {}
    for item in items:
        slices = item._slices
        if slices is None or item._cells != cells:
            wedge = item.wedge
            slices, _ = split_product(
                item.polygon.vertices, wedge.center - wedge.cw, wedge.width, cells, cells + 1, wedge.center
            )
        base = seen.setdefault(id(item), offset)
        if base == offset:
            offset += int(slices.sources.max()) + 1
        parts.append((slices, base))
    grid, wedge = distributed(
        np.concatenate([p.points for p, _ in parts]),
        np.concatenate([p.counts for p, _ in parts]),
        np.concatenate([p.lo for p, _ in parts]),
        np.concatenate([p.hi for p, _ in parts]),
        np.concatenate([p.sources + base for p, base in parts]),
        cells,
        max_vertices,
        cap,
        primary.wedge.center,
    )
    return SpatialUncertaintyMap._sliced(grid, primary.center.copy(), wedge, cells, cap)


def union_of_wedges(wedges: Sequence[HeadingWedge], center: float) -> HeadingWedge:
    """Return the shortest wedge holding every wedge given, with ``center`` (inside one of them).

    The union's clockwise end is the clockwise end of one of the wedges: from each, the
    arc counter-clockwise that reaches the far end of every other wedge is measured, and
    the shortest is kept. A wedge that holds that end strictly inside would need a whole
    turn: such a start loses.

    Examples
    --------
    >>> a, b = HeadingWedge(0.0, 0.1, 0.1), HeadingWedge(1.0, 0.1, 0.1)
    >>> w = union_of_wedges([a, b], 0.0)
    >>> round(w.cw, 6), round(w.ccw, 6)
    (0.1, 1.1)
    >>> union_of_wedges([a, HeadingWedge.full_circle()], 0.0).is_full_circle
    True
    >>> union_of_wedges([], 0.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: wedges: expected at least one HeadingWedge, got none
    """
    wedges = sequence_of(wedges, HeadingWedge, "wedges")
    if not wedges:
        raise InputError("wedges: expected at least one HeadingWedge, got none")
    return _union_of_wedges(wedges, finite_float(center, "center"))


def _union_of_wedges(wedges: Sequence[HeadingWedge], center: float) -> HeadingWedge:
    """:func:`union_of_wedges` for checked arguments (at least one wedge, a finite centre)."""
    if any(wedge.is_full_circle for wedge in wedges):
        return HeadingWedge.full_circle(center)
    starts = np.array([wedge.center - wedge.cw for wedge in wedges]) % _TWO_PI
    widths = np.array([wedge.width for wedge in wedges])
    # offsets[k, i]: how far counter-clockwise of wedge k's start wedge i starts.
    offsets = (starts[None, :] - starts[:, None]) % _TWO_PI
    reach = (offsets + widths[None, :]).max(axis=1)
    best = int(np.argmin(reach))
    width = float(reach[best])
    if width >= _TWO_PI:
        return HeadingWedge.full_circle(center)
    cw = float((center - starts[best]) % _TWO_PI)
    if cw > width:
        # Rounding put the centre a hair outside: clamp to the nearer end.
        cw = width if cw - width < _TWO_PI - cw else 0.0
    return HeadingWedge(center, cw, width - cw)


def _support_hull(vertex_arrays: Sequence[NDArray[np.float64]], count: int) -> ConvexPolygon:
    """Return the polygon of the supporting lines of all the points in ``count`` fixed directions.

    Directions ``2 pi k / count`` from +x, the same for every call: the result holds every
    point (each line is pushed out by a margin, ``4 * _NEAR`` of the coordinates' size) and
    taking it twice adds only that margin, so repeated unions do not creep. It touches the
    points' extreme vertices (but for the margin) and bulges by a thin triangle over each
    hull edge between two sampled directions.
    A fixed cost, one matrix product, whatever the number of points.
    """
    points = np.concatenate(vertex_arrays, axis=0)
    directions = _DIRECTIONS[count]
    support = (points @ directions.transposed).max(axis=0)
    scale = max(float(np.abs(points).max()), 1.0)
    near = _NEAR * scale
    support += 4.0 * near
    following = support[directions.following]
    # Lines n_k . x = h_k and n_k+1 . x = h_k+1 meet at one corner.
    corners = np.empty((count, 2))
    corners[:, 0] = support * directions.x_of_own - following * directions.x_of_next
    corners[:, 1] = following * directions.y_of_next - support * directions.y_of_own
    # A point extreme in several directions gives a fan of corners a hair apart, and such
    # short edges have directions too noisy to test points against: keep one corner of
    # each run within ``near`` of the last one kept. What that cuts off lies within
    # 2 sqrt(2) near of the next line, and every point is 4 near inside it.
    step = np.abs(corners - corners[directions.preceding]).max(axis=1)
    starts = step > near
    starts[0] = True
    first = np.maximum.accumulate(np.where(starts, directions.index, 0))
    # Commonly every corner is within ``near`` of its run's first: keep the runs' firsts.
    runs_hold = np.abs(corners - corners[first]).max() <= near
    distinct = corners[starts] if runs_hold else _thinned(corners, near)
    last, head = distinct[-1], distinct[0]
    if len(distinct) > 1 and abs(last[0] - head[0]) <= near and abs(last[1] - head[1]) <= near:
        distinct = distinct[:-1]
    return ConvexPolygon._trusted(np.ascontiguousarray(distinct))


def _thinned(corners: NDArray[np.float64], near: float) -> NDArray[np.float64]:
    """Keep each corner farther than ``near`` (either coordinate) from the last one kept."""
    kept = [corners[0].tolist()]
    for x, y in corners[1:].tolist():
        last_x, last_y = kept[-1]
        if abs(x - last_x) > near or abs(y - last_y) > near:
            kept.append([x, y])
    return np.array(kept, dtype=np.float64)


@dataclass(frozen=True, slots=True)
class _Fan:
    """``count`` unit normals evenly spaced from +x, and the coefficients of their corners."""

    transposed: NDArray[np.float64]
    index: NDArray[np.intp]
    following: NDArray[np.intp]
    preceding: NDArray[np.intp]
    x_of_own: NDArray[np.float64]
    x_of_next: NDArray[np.float64]
    y_of_own: NDArray[np.float64]
    y_of_next: NDArray[np.float64]

    @classmethod
    def of(cls, count: int) -> _Fan:
        angles = np.arange(count) * (2.0 * math.pi / count)
        normals = np.column_stack([np.cos(angles), np.sin(angles)])
        index = np.arange(count)
        following, preceding = (index + 1) % count, (index - 1) % count
        after = normals[following]
        det = normals[0, 0] * after[0, 1] - normals[0, 1] * after[0, 0]
        # Cramer's rule for n . x = h, m . x = g: x = (h m_y - g n_y) / det, y = (g n_x - h m_x) / det.
        return cls(
            np.ascontiguousarray(normals.T),
            index,
            following,
            preceding,
            after[:, 1] / det,
            normals[:, 1] / det,
            after[:, 0] / det,
            normals[:, 0] / det,
        )


class _Fans(dict[int, _Fan]):
    """The fan of each direction count, built on first use."""

    def __missing__(self, count: int) -> _Fan:
        fan = self[count] = _Fan.of(count)
        return fan


_DIRECTIONS = _Fans()
#: Corners closer than this, relative to the coordinates' size, are one; each supporting line
#: is pushed out by four times as much. Well above rounding, so that no edge is short enough
#: for its direction to be noise.
_NEAR = 1e-6
