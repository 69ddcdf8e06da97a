"""Heading slices: a pose set kept as convex polygons on a fixed global grid of headings.

A product map (one polygon of positions, one wedge of headings) smears every position
over every heading. A *sliced* map keeps, for each heading interval of a fixed global grid
(cells of width ``2 pi / cells``, the first starting at heading 0), the convex polygon of
the positions possible at those headings. The pose set is the union over slices of
``polygon x interval``. A slice's interval lies inside one grid cell, or inside a run of
contiguous cells when the slice count was capped.

A map holds its slices packed (:class:`SliceSet`): every polygon one after the other, so
that a growth or a reduction of the whole map is one call of a kernel of
``aura_ums._native`` (``grow_slices``, ``distribute_slices``, ``reduce_cone_slices``,
``reduce_strip_slices``), with no loop over slices here. Every operation is an outer bound:

- :func:`split_product` cuts a product map into one slice per covered cell (exact);
- :func:`distributed` puts pieces (grown slices, or the slices of several maps) back on
  the grid: a piece spanning several cells gives its polygon to each, the pieces of one
  cell merge by convex hull, and neighbours merge (hull of polygons, span of intervals)
  until at most ``max_slices`` remain.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from aura_ums import _native
from aura_ums._validate import finite_float, integer_at_least
from aura_ums.errors import InputError
from aura_ums.geometry import ConvexPolygon, HeadingWedge, checks_every_edge, points_in_convex, polygon_area

Array = NDArray[np.float64]
Counts = NDArray[np.int64]

_TWO_PI = 2.0 * math.pi

#: Default width of a grid cell, radians (2 degrees).
DEFAULT_SLICE_WIDTH = math.radians(2.0)

#: Default cap on a map's slice count.
DEFAULT_MAX_SLICES = 48


class SliceSet(NamedTuple):
    """A map's heading slices, packed.

    Attributes
    ----------
    points : ndarray, shape (n, 2)
        Every slice's counter-clockwise convex polygon of positions, metres, one after the
        other; read-only.
    counts : ndarray of int64, shape (k,)
        Vertices of each slice, each >= 1.
    lo : ndarray, shape (k,)
        Clockwise-most heading of each slice, radians, in [0, 2 pi), ascending.
    hi : ndarray, shape (k,)
        Counter-clockwise-most heading, radians, ``lo <= hi <= lo + 2 pi`` (not wrapped).
    sources : ndarray of int64, shape (k,)
        Equal for slices that hold one polygon (merging them keeps it as it is).
    """

    points: Array
    counts: Counts
    lo: Array
    hi: Array
    sources: Counts

    def polygons(self) -> list[Array]:
        """Return each slice's polygon (views of :attr:`points`)."""
        ends = np.cumsum(self.counts).tolist()
        return [
            self.points[end - int(size) : end] for size, end in zip(self.counts.tolist(), ends, strict=True)
        ]


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


#: Most heading cells round the circle, so the narrowest slice width (0.1 degree). Growth
#: spreads a slice over every cell its headings cover, so a step costs in proportion to the
#: cells: four_terrains.toml (one run, ``--profile relaxed --max-slices 100000``) took 1.4,
#: 5.3 and 15.9 s at 720, 3600 and 7200 cells, and 1e-6 rad (6.3 million cells) ran out of
#: memory. No odometry resolves a heading finer than a tenth of a degree.
MAX_CELLS = 3600
MIN_SLICE_WIDTH = _TWO_PI / MAX_CELLS
#: Largest slice cap a sliced map takes (and the manager settings' ``max_slices``): the grid has
#: at most :data:`MAX_CELLS` cells, so no cap above it caps anything (2**63 overflowed the kernel).
MAX_SLICES = 100_000


def slice_cap(value: object, name: str = "max_slices") -> int:
    """Return a slice cap, an integer in [1, :data:`MAX_SLICES`], or raise naming ``name``."""
    cap = integer_at_least(value, name, 1)
    if cap > MAX_SLICES:
        raise InputError(
            f"{name}: expected at most {MAX_SLICES} slices (the grid has at most {MAX_CELLS} cells), "
            f"got {cap}"
        )
    return cap


def cell_count(width: float) -> int:
    """Return the number of heading cells of a sliced map's grid for a cell width (radians, in (0, 2 pi]).

    The grid has a whole number of cells round the circle, each at most ``width`` wide
    (``ManagerSettings.slice_width``); a width under ``2 pi / 3600`` (0.1 degree) is refused.

    Examples
    --------
    >>> cell_count(math.radians(2.0)), cell_count(2.0 * math.pi), cell_count(1.0)
    (180, 1, 7)
    >>> cell_count(1e-12)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: slice_width: expected at least 0.00174533 rad (...), got 1e-12
    >>> cell_count(float("inf"))
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: slice_width: expected a finite number, got inf
    """
    width = finite_float(width, "slice_width")
    if width < MIN_SLICE_WIDTH:
        raise InputError(
            f"slice_width: expected at least {MIN_SLICE_WIDTH:g} rad (0.1 degree, {MAX_CELLS} heading "
            f"cells; a step costs in proportion to the cells), "
            f"got {width!r}"
        )
    return max(1, math.ceil(_TWO_PI / width - 1e-9))


def split_product(
    vertices: Array, lo: float, width: float, cells: int, max_slices: int, heading: float
) -> tuple[SliceSet, HeadingWedge]:
    """Cut a product map (a polygon, headings ``lo`` to ``lo + width``) into one slice per covered cell.

    Parameters
    ----------
    vertices : ndarray, shape (n, 2)
        The polygon, counter-clockwise, metres.
    lo, width : float
        The headings, radians (``width >= 2 pi``: every heading).
    cells : int
        Cells of the grid, >= 1.
    max_slices : int
        Cap on the slice count, >= 1 (neighbours merge beyond it).
    heading : float
        The most probable heading, radians: the summary wedge's centre.

    Returns
    -------
    SliceSet, HeadingWedge
        The slices, every one holding the polygon, and their summary wedge.

    Examples
    --------
    >>> point = np.zeros((1, 2))
    >>> slices, wedge = split_product(point, -0.1, 0.3, 36, 48, 0.0)
    >>> [round(v, 3) for v in slices.lo.tolist()], [round(v, 3) for v in slices.hi.tolist()]
    ([0.0, 0.175, 6.183], [0.175, 0.2, 6.283])
    >>> len(split_product(point, 0.0, 7.0, 36, 48, 0.0)[0].lo)    # every heading: every cell
    36
    """
    points = np.ascontiguousarray(vertices, dtype=np.float64)
    return distributed(
        points, np.array([len(points)], dtype=np.int64), np.array([lo]), np.array([lo + width]),
        np.zeros(1, dtype=np.int64), cells, max(len(points), 3), max_slices, heading,
    )  # fmt: skip


def distributed(
    points: Array,
    counts: Counts,
    starts: Array,
    stops: Array,
    sources: Counts,
    cells: int,
    max_vertices: int,
    max_slices: int,
    heading: float,
) -> tuple[SliceSet, HeadingWedge]:
    """Put pieces (packed polygons, unwrapped heading intervals) on the grid: ``_native.distribute_slices``.

    Returns the slices and their summary wedge, centred on ``heading`` clamped into it.
    Pieces that would cover more than :data:`CELL_ROW_BUDGET` cells in all (finely sliced
    maps grown over wide heading intervals: every cell a piece covers holds its polygon
    until the cell's hull is taken; 0.1 degree cells over +-1.5 rad took 23 s and hundreds
    of MB for one growth) are first merged with their neighbours in heading order, hull and
    interval (an outer bound), so that they cover about that many. Grids of 1 degree or
    coarser never reach it (181 pieces of 181 cells each).
    """
    points, counts, starts, stops, sources = _within_budget(
        points, counts, starts, stops, sources, cells, max_vertices
    )
    grid = _native.distribute_slices(
        points, counts, starts, stops, sources, cells, max_vertices, max_slices, heading
    )
    slices = SliceSet(_read_only(grid.points), grid.counts, grid.lo, grid.hi, grid.sources)
    return slices, HeadingWedge._trusted(grid.center, grid.cw, grid.ccw)


#: Cells the pieces of one distribution may cover in all (see distributed).
CELL_ROW_BUDGET = 131_072


def _within_budget(
    points: Array, counts: Counts, starts: Array, stops: Array, sources: Counts, cells: int, max_vertices: int
) -> tuple[Array, Counts, Array, Array, Counts]:
    """Merge neighbouring pieces (in heading order) until they cover at most the budget of cells."""
    if len(counts) * (cells + 1) <= CELL_ROW_BUDGET:
        return points, counts, starts, stops, sources  # within it whatever they cover (every growth step)
    step = _TWO_PI / cells
    spans = np.minimum(np.ceil(stops / step) - np.floor(starts / step), cells + 1)
    total, budget = float(spans.sum()), CELL_ROW_BUDGET
    if total <= budget or len(counts) < 2:
        return points, counts, starts, stops, sources
    size = math.ceil(total / budget)
    order = np.argsort(starts, kind="stable")
    offsets = np.concatenate(([0], np.cumsum(counts)))
    groups = [order[i : i + size] for i in range(0, len(order), size)]
    gathered = np.concatenate([points[offsets[j] : offsets[j + 1]] for group in groups for j in group])
    sizes = [int(counts[group].sum()) for group in groups]
    hulls = _native.merge_groups(np.ascontiguousarray(gathered), sizes, max_vertices)
    fresh = int(sources.max()) + 1
    return (
        np.ascontiguousarray(np.concatenate(hulls), dtype=np.float64),
        np.array([len(hull) for hull in hulls], dtype=np.int64),
        np.array([float(starts[group].min()) for group in groups]),
        np.array([float(stops[group].max()) for group in groups]),
        np.arange(fresh, fresh + len(groups), dtype=np.int64),
    )


def _read_only(points: Array) -> Array:
    points.setflags(write=False)
    return points


def packed(
    polygons: Sequence[Array], lo: Sequence[float], hi: Sequence[float]
) -> tuple[Array, Counts, Array, Array, Counts]:
    """Pack polygons and intervals; polygons that are one array object share a source."""
    first: dict[int, int] = {}
    sources = np.array([first.setdefault(id(p), len(first)) for p in polygons], dtype=np.int64)
    points = np.ascontiguousarray(np.concatenate(polygons), dtype=np.float64)
    counts = np.array([len(p) for p in polygons], dtype=np.int64)
    return points, counts, np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64), sources


def heading_slices(slices: SliceSet) -> tuple[HeadingSlice, ...]:
    """Return the slices as :class:`HeadingSlice` values, in heading order."""
    return tuple(
        HeadingSlice(ConvexPolygon._trusted(polygon), lo, hi - lo)
        for polygon, lo, hi in zip(slices.polygons(), slices.lo.tolist(), slices.hi.tolist(), strict=True)
    )


def summary_polygon(slices: SliceSet) -> Array:
    """Return the convex hull of every slice's polygon (counter-clockwise, metres).

    Slices that all hold one polygon give that polygon.
    """
    # A set of a dozen ints costs a tenth of a numpy reduction's dispatch, once per summary.
    if len(set(slices.sources.tolist())) == 1:
        return slices.points[: int(slices.counts[0])]
    total = len(slices.points)
    return _native.merge_groups(slices.points, [total], max(total, 3))[0]


def point_in(vertices: Array, x: float, y: float, tolerance: float, area: float | None = None) -> bool:
    """:func:`~aura_ums.geometry.points_in_convex` for one point, bit for bit, at a tenth of the cost.

    Where that function tests the point edge by edge (a polygon of positive area), the
    compiled ``point_in_solid_convex`` does the same operations; otherwise it is called.
    ``area`` is the polygon's :func:`~aura_ums.geometry.polygon_area` when the caller has it.
    """
    count = len(vertices)
    solid = count >= 3 and checks_every_edge(1, count)
    if solid and (polygon_area(vertices) if area is None else area) > 0.0:
        return bool(_native.point_in_solid_convex(vertices, x, y, tolerance))
    return bool(points_in_convex(vertices, np.array([[x, y]]), tolerance)[0])


def contains_one(slices: SliceSet, x: float, y: float, heading: float, tolerance: float) -> bool:
    """:func:`contains` for one pose (finite floats), with the same operations on floats."""
    slack = _native.ANGLE_SLACK
    ends = 0
    for count, lo, hi in zip(slices.counts.tolist(), slices.lo.tolist(), slices.hi.tolist(), strict=True):
        ends += count
        width = hi - lo
        # Python's % on floats gives np.mod's bits.
        offset = (heading - lo) % _TWO_PI
        if (offset <= width + slack or offset >= _TWO_PI - slack or width >= _TWO_PI) and point_in(
            slices.points[ends - count : ends], x, y, tolerance
        ):
            return True
    return False


def contains(slices: SliceSet, points: Array, headings: Array, tolerance: float) -> NDArray[np.bool_]:
    """Tell which poses lie in some slice: position in its polygon, heading in its interval.

    Parameters
    ----------
    slices : SliceSet
        The map's slices.
    points : ndarray, shape (m, 2)
        Positions, metres.
    headings : ndarray, shape (m,)
        Headings, radians, any winding.
    tolerance : float
        Metres outside a polygon that still count as inside.
    """
    lo, hi = slices.lo, slices.hi
    width = hi - lo
    # near[i, j]: heading i lies in slice j's interval (within the slack).
    offset = np.mod(headings[:, None] - lo[None, :], _TWO_PI)
    near = (
        (offset <= width + _native.ANGLE_SLACK)
        | (offset >= _TWO_PI - _native.ANGLE_SLACK)
        | (width >= _TWO_PI)
    )
    inside = np.zeros(len(points), dtype=bool)
    candidates = np.flatnonzero(near.any(axis=0)).tolist()
    if not candidates:
        return inside
    ends = np.cumsum(slices.counts)
    for index in candidates:
        todo = near[:, index] & ~inside
        if todo.any():
            end = int(ends[index])
            polygon = slices.points[end - int(slices.counts[index]) : end]
            inside[todo] = points_in_convex(polygon, points[todo], tolerance)
    return inside
