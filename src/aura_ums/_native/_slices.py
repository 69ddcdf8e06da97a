"""Heading slices, every slice of a map at once: the numpy references and the compiled kernels.

A sliced map keeps its slices packed: every slice's polygon one after the other (``points``,
shape (n, 2)), the vertex count of each (``counts``, int64) and each heading interval
(``lo``, ``hi``). Each kernel here takes and gives that layout, so a growth or a reduction
of the whole map is one call, whatever its slice count:

- :func:`grow_slices_reference`: every slice grown by a run of turn-and-run commands;
- :func:`distribute_slices_reference`: pieces put back on the heading grid, the polygons
  that meet one cell merged into their (capped) convex hull, neighbours merged under the
  slice cap, and the summary wedge;
- :func:`reduce_cone_slices_reference`, :func:`reduce_strip_slices_reference`: every slice
  reduced by one observation, empty slices dropped;
- :func:`merge_groups_reference`: the capped hull of each group of points.

The numpy functions are the specification; ``slices.c``, ``growth.c`` and ``reduce.c``
repeat them operation for operation.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from aura_ums._native import _extension
from aura_ums._native._extension import points_view
from aura_ums._native._growth import Grown, MotionModel, grow_commands_reference
from aura_ums._native._reduce import RawReduction, reduce_cone_reference, reduce_strip_reference
from aura_ums.geometry import convex_hull, simplify_outer

if _extension.BUILT:
    from aura_ums._native._kernels import distribute_slices as _compiled_distribute_slices
    from aura_ums._native._kernels import grow_slices as _compiled_grow_slices
    from aura_ums._native._kernels import merge_groups as _compiled_merge_groups
    from aura_ums._native._kernels import reduce_cone_slices as _compiled_reduce_cone_slices
    from aura_ums._native._kernels import reduce_strip_slices as _compiled_reduce_strip_slices

Array = NDArray[np.float64]


def merge_groups_reference(points: Array, counts: Sequence[int], max_vertices: int) -> tuple[Array, ...]:
    """Return the convex hull of each group of consecutive points, capped at ``max_vertices``.

    The numpy reference, the specification ``slices.c`` follows: ``aura_ums._native.merge_groups``
    is this function, or :func:`merge_groups_compiled` when the kernels run compiled.

    Parameters
    ----------
    points : ndarray, shape (n, 2)
        Finite points, metres: the groups one after the other.
    counts : sequence of int
        Points in each group, each >= 1, adding up to n.
    max_vertices : int
        Cap on each hull's vertex count (>= 3); beyond it an outer polygon
        (``geometry.simplify_outer``).

    Returns
    -------
    tuple of ndarray, shape (m, 2)
        Each group's hull, counter-clockwise, starting from its lowest-leftmost vertex.

    Examples
    --------
    >>> from aura_ums import _native
    >>> square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> hulls = _native.merge_groups(np.vstack([square, square + 2.0, square]), [8, 4], 8)
    >>> [len(h) for h in hulls], hulls[1].tolist() == square.tolist()
    ([6, 4], True)
    >>> _native.merge_groups(np.zeros((2, 2)), [1, 1], 3)[0].tolist()   # a point is its own hull
    [[0.0, 0.0]]
    """
    if any(count < 1 for count in counts) or sum(counts) != len(points):
        raise ValueError(
            f"counts: expected group sizes adding up to the {len(points)} rows, got {list(counts)}"
        )
    if max_vertices < 3:
        raise ValueError(f"max_vertices: expected at least 3, got {max_vertices}")
    hulls = []
    start = 0
    for count in counts:
        hull = convex_hull(points[start : start + count])
        if len(hull) > max_vertices:
            hull = simplify_outer(hull, max_vertices)
        hulls.append(hull)
        start += count
    return tuple(hulls)


def merge_groups_compiled(points: Array, counts: Sequence[int], max_vertices: int) -> tuple[Array, ...]:
    """Compiled :func:`merge_groups_reference` (needs the extension module: ``_extension.BUILT``)."""
    if not points.flags.c_contiguous:
        points = np.ascontiguousarray(points, dtype=np.float64)
    # Bytes are immutable, so the arrays are read-only as map values must be.
    return tuple(points_view(raw) for raw in _compiled_merge_groups(points, counts, max_vertices))


# --- every slice of a map at once -------------------------------------------------------------

_TWO_PI = 2.0 * math.pi
#: Angular slack (radians) when testing a heading against a slice, as wedges allow.
ANGLE_SLACK = 1e-9

Counts = NDArray[np.int64]


class Distributed(NamedTuple):
    """Slices on the heading grid, as :func:`distribute_slices` gives them.

    Attributes
    ----------
    points : ndarray, shape (n, 2)
        Every slice's polygon (counter-clockwise, metres), one after the other.
    counts : ndarray of int64, shape (k,)
        Vertices of each slice, each >= 1.
    lo, hi : ndarray, shape (k,)
        Each slice's interval, radians: ``0 <= lo <= hi <= lo + 2 pi``, ordered by ``lo``.
    sources : ndarray of int64, shape (k,)
        Equal for slices holding one polygon (merging such slices keeps it as it is).
    center, cw, ccw : float
        The summary wedge: the heading given clamped into the slices (unwrapped), and its
        clockwise and counter-clockwise extents, radians (pi, pi: every heading).
    """

    points: Array
    counts: Counts
    lo: Array
    hi: Array
    sources: Counts
    center: float
    cw: float
    ccw: float


class GrownSlices(NamedTuple):
    """Every slice grown, as :func:`grow_slices` gives them (not yet on the grid).

    Attributes
    ----------
    points, counts : ndarray
        The grown polygons, as in :class:`Distributed`.
    starts, stops : ndarray, shape (k,)
        Each grown interval, radians, unwrapped (``stops - starts >= 2 pi``: every heading).
    x, y, heading : float
        The most probable pose grown in the home slice (metres; radians, unwrapped).
    """

    points: Array
    counts: Counts
    starts: Array
    stops: Array
    x: float
    y: float
    heading: float


class ReducedSlices(NamedTuple):
    """The slices a reduction kept, as :func:`reduce_cone_slices` gives them.

    Attributes
    ----------
    points, counts, lo, hi : ndarray
        The kept slices, narrowed, ordered by ``lo``, as in :class:`Distributed`.
    x, y : float
        The most probable position the home slice's reduction kept or moved, metres.
    center, cw, ccw : float
        The summary wedge, as in :class:`Distributed`.
    """

    points: Array
    counts: Counts
    lo: Array
    hi: Array
    x: float
    y: float
    center: float
    cw: float
    ccw: float


def clamp_into(heading: float, lo: float, hi: float) -> float:
    """Return the heading of [lo, hi] (unwrapped) nearest to ``heading``, unwrapped near ``lo``.

    Examples
    --------
    >>> clamp_into(0.05, 0.0, 0.1), clamp_into(-0.01, 0.0, 0.1), round(clamp_into(7.0, 0.0, 0.1), 3)
    (0.05, 0.0, 0.1)
    """
    offset = (heading - lo) % _TWO_PI
    if offset <= hi - lo:
        return lo + offset
    # Outside: the nearer end, the shorter way round.
    return hi if offset - (hi - lo) < _TWO_PI - offset else lo


def home_slice(lo: Sequence[float], hi: Sequence[float], heading: float) -> int:
    """Return the index of the slice nearest in heading to ``heading`` (the first that holds it).

    Examples
    --------
    >>> home_slice([0.0, 1.0], [0.5, 1.5], 1.2), home_slice([0.0, 1.0], [0.5, 1.5], 0.6)
    (1, 0)
    """
    best, best_gap = 0, math.inf
    for index, (start, stop) in enumerate(zip(lo, hi, strict=True)):
        offset = (heading - start) % _TWO_PI
        if offset <= stop - start:
            return index
        gap = min(offset - (stop - start), _TWO_PI - offset)
        if gap < best_gap:
            best, best_gap = index, gap
    return best


def summary_wedge(lo: Sequence[float], hi: Sequence[float], heading: float) -> tuple[float, float, float]:
    """Return the smallest wedge holding every interval, centred on ``heading``: (centre, cw, ccw).

    The intervals are ordered by ``lo`` and disjoint but for shared ends; ``heading`` is
    clamped into the wedge. The wedge leaves out the widest gap between them; none left
    out: every heading, ``(heading, pi, pi)``.

    Examples
    --------
    >>> [round(v, 3) for v in summary_wedge([0.0, 6.0], [0.1, 6.2], 0.05)]   # across 0, unwrapped
    [6.333, 0.333, 0.05]
    >>> summary_wedge([0.0], [7.0], 1.0) == (1.0, math.pi, math.pi)
    True
    """
    if len(lo) == 1:
        start, stop = lo[0], hi[0]
    else:
        reach = hi[0]
        widest, after = -math.inf, 0
        for index in range(1, len(lo)):
            gap = lo[index] - reach
            if gap > widest:
                widest, after = gap, index
            reach = max(reach, hi[index])
        wrap = lo[0] + _TWO_PI - reach
        if wrap >= widest:
            widest, after = wrap, 0
        if widest <= ANGLE_SLACK:
            # No gap but rounding's between neighbouring cells: every heading.
            return heading, math.pi, math.pi
        start = lo[after]
        stop = start + _TWO_PI - widest
    if stop - start >= _TWO_PI:
        return heading, math.pi, math.pi
    center = clamp_into(heading, start, stop)
    return center, center - start, stop - center


def _check_packed(points: Array, counts: Counts, lo: Array, hi: Array) -> list[int]:
    sizes = [int(c) for c in counts]
    if not sizes or any(c < 1 for c in sizes) or sum(sizes) != len(points):
        raise ValueError(f"counts: expected slice sizes adding up to the {len(points)} rows, got {sizes}")
    if len(lo) != len(sizes) or len(hi) != len(sizes):
        raise ValueError(f"lo, hi: expected {len(sizes)} headings each, got {len(lo)} and {len(hi)}")
    return sizes


def _split(points: Array, sizes: Sequence[int]) -> list[Array]:
    ends = np.cumsum(sizes).tolist()
    return [points[end - size : end] for size, end in zip(sizes, ends, strict=True)]


def _packed(polygons: Sequence[Array]) -> tuple[Array, Counts]:
    return (
        np.ascontiguousarray(np.concatenate(polygons), dtype=np.float64),
        np.array([len(p) for p in polygons], dtype=np.int64),
    )


def _merged(
    polygons: Sequence[Array], sources: Sequence[int], max_vertices: int, fresh: int
) -> tuple[Array, int]:
    """Return the polygon of slices sharing one source, else the capped hull of theirs (source ``fresh``)."""
    if all(source == sources[0] for source in sources):
        return polygons[0], sources[0]
    return merge_groups_reference(np.concatenate(polygons), [sum(len(p) for p in polygons)], max_vertices)[
        0
    ], fresh


def distribute_slices_reference(
    points: Array,
    counts: Counts,
    starts: Array,
    stops: Array,
    sources: Counts,
    cells: int,
    max_vertices: int,
    max_slices: int,
    heading: float,
) -> Distributed:
    """Put heading intervals with polygons onto the grid, then cap the slice count.

    The numpy reference, the specification ``slices.c`` follows:
    ``aura_ums._native.distribute_slices`` is this function, or
    :func:`distribute_slices_compiled` when the kernels run compiled.

    A piece (``starts[i]`` to ``stops[i]``, radians, unwrapped; ``stops - starts >= 2 pi``
    is every heading) gives its polygon to every cell of the grid (``cells`` cells of
    ``2 pi / cells``, the first from heading 0) it meets, with its interval cut to the
    cell. The pieces of one cell merge: the convex hull of their polygons (an outer polygon
    of at most ``max_vertices`` vertices when it has more; pieces of one source keep their
    polygon) and the span of their intervals. Beyond ``max_slices`` slices, neighbours merge
    in groups of ``ceil(count / max_slices)``: the hull of their polygons, from the first
    ``lo`` to the largest ``hi``. Every step is an outer bound.

    Parameters
    ----------
    points : ndarray, shape (n, 2)
        The pieces' polygons, counter-clockwise, metres, one after the other.
    counts : ndarray of int64, shape (k,)
        Vertices of each piece, each >= 1, adding up to n.
    starts, stops : ndarray, shape (k,)
        Each piece's headings, radians, ``starts <= stops``.
    sources : ndarray of int64, shape (k,)
        Equal for pieces holding one polygon.
    cells : int
        Cells of the grid, >= 1.
    max_vertices : int
        Cap on a merged polygon's vertex count, >= 3.
    max_slices : int
        Cap on the slice count, >= 1.
    heading : float
        The heading the summary wedge is centred on (clamped into it), radians.

    Returns
    -------
    Distributed
        The slices, ordered by ``lo``, each interval inside its cell (or run of cells).

    Examples
    --------
    >>> from aura_ums import _native
    >>> point, one = np.zeros((1, 2)), np.ones(1, dtype=np.int64)
    >>> grid = _native.distribute_slices(point, one, np.array([-0.1]), np.array([0.2]),
    ...                                  np.zeros(1, dtype=np.int64), 36, 8, 48, 0.0)
    >>> [round(v, 3) for v in grid.lo.tolist()], [round(v, 3) for v in grid.hi.tolist()], grid.counts.tolist()
    ([0.0, 0.175, 6.183], [0.175, 0.2, 6.283], [1, 1, 1])
    >>> len(_native.distribute_slices(point, one, np.zeros(1), np.full(1, 7.0),
    ...                               np.zeros(1, dtype=np.int64), 36, 8, 4, 0.0).lo)  # capped
    4
    """
    sizes = _check_packed(points, counts, starts, stops)
    if len(sources) != len(sizes):
        raise ValueError(f"sources: expected {len(sizes)} items, got {len(sources)}")
    if max_vertices < 3:
        raise ValueError(f"max_vertices: expected at least 3, got {max_vertices}")
    polygons = _split(points, sizes)
    step = _TWO_PI / cells
    begin = np.array(starts, dtype=np.float64)
    end = np.array(stops, dtype=np.float64)
    every = end - begin >= _TWO_PI
    begin[every], end[every] = 0.0, _TWO_PI
    first = np.floor(begin / step).astype(np.int64)
    last = np.maximum(first, np.ceil(end / step).astype(np.int64) - 1)
    # One row per (piece, cell it meets): k the cell's unwrapped index.
    spans = last - first + 1
    owner = np.repeat(np.arange(len(sizes)), spans)
    k = np.repeat(first - np.cumsum(spans) + spans, spans) + np.arange(int(spans.sum()))
    cell = k % cells
    shift = (k - cell) * step
    cell_lo, cell_hi = cell * step, (cell + 1) * step
    # Rounding must not leave the cell, nor turn the interval inside out.
    lo = np.minimum(np.maximum(np.maximum(begin[owner], k * step) - shift, cell_lo), cell_hi)
    hi = np.minimum(np.maximum(np.minimum(end[owner], (k + 1) * step) - shift, lo), cell_hi)
    occupied, where = np.unique(cell, return_inverse=True)
    lows = np.full(len(occupied), np.inf)
    highs = np.full(len(occupied), -np.inf)
    np.minimum.at(lows, where, lo)
    np.maximum.at(highs, where, hi)
    groups: list[list[int]] = [[] for _ in range(len(occupied))]
    for slot, index in zip(where.tolist(), owner.tolist(), strict=True):
        groups[slot].append(index)
    source_list = [int(s) for s in sources]
    fresh = max(source_list) + 1
    grid: list[tuple[float, float, Array, int]] = []
    for slot, group in enumerate(groups):
        polygon, source = _merged(
            [polygons[i] for i in group], [source_list[i] for i in group], max_vertices, fresh + slot
        )
        grid.append((float(lows[slot]), float(highs[slot]), polygon, source))
    if len(grid) > max_slices:
        size = math.ceil(len(grid) / max_slices)
        fresh = max(g[3] for g in grid) + 1
        capped: list[tuple[float, float, Array, int]] = []
        for start in range(0, len(grid), size):
            group_of = grid[start : start + size]
            polygon, source = _merged(
                [g[2] for g in group_of], [g[3] for g in group_of], max_vertices, fresh + len(capped)
            )
            capped.append((group_of[0][0], max(g[1] for g in group_of), polygon, source))
        grid = capped
    los = np.array([g[0] for g in grid])
    his = np.array([g[1] for g in grid])
    out_points, out_counts = _packed([g[2] for g in grid])
    center, cw, ccw = summary_wedge(los.tolist(), his.tolist(), heading)
    return Distributed(out_points, out_counts, los, his, np.array([g[3] for g in grid], dtype=np.int64),
                       center, cw, ccw)  # fmt: skip


def distribute_slices_compiled(
    points: Array,
    counts: Counts,
    starts: Array,
    stops: Array,
    sources: Counts,
    cells: int,
    max_vertices: int,
    max_slices: int,
    heading: float,
) -> Distributed:
    """Compiled :func:`distribute_slices_reference` (needs the extension module)."""
    raw, raw_counts, raw_lo, raw_hi, raw_sources, center, cw, ccw = _compiled_distribute_slices(
        points, counts, starts, stops, sources, cells, max_vertices, max_slices, heading
    )
    return Distributed(
        points_view(raw),
        np.frombuffer(raw_counts, dtype=np.int64),
        np.frombuffer(raw_lo, dtype=np.float64),
        np.frombuffer(raw_hi, dtype=np.float64),
        np.frombuffer(raw_sources, dtype=np.int64),
        center,
        cw,
        ccw,
    )


def grow_slices_reference(
    points: Array,
    counts: Counts,
    lo: Array,
    hi: Array,
    x: float,
    y: float,
    heading: float,
    terrain: MotionModel,
    sigmas: float,
    commands: Sequence[float],
    max_vertices: int,
) -> GrownSlices:
    """Grow every slice of a sliced map by the commands, each over its own headings.

    The numpy reference, the specification of ``grow_slices`` in ``growth.c``:
    ``aura_ums._native.grow_slices`` is this function, or :func:`grow_slices_compiled`.

    Each slice is a product map of its polygon and interval, grown as such
    (:func:`~aura_ums._native._growth.grow_commands_reference`, sound for its poses): the
    home slice's (:func:`home_slice` of ``heading``) wedge centred on ``heading`` clamped
    into it, the others' on their middles. The most probable pose grows in the home slice.

    Parameters
    ----------
    points, counts, lo, hi : ndarray
        The slices, as :class:`Distributed` holds them.
    x, y, heading : float
        The most probable pose, metres and radians.
    terrain : MotionModel
        The terrain's statistics.
    sigmas : float
        Standard deviations bounded, > 0.
    commands : sequence of float
        Turn (radians) and run (metres) of each command, flat.
    max_vertices : int
        Cap on each grown polygon's vertex count, >= 3.

    Returns
    -------
    GrownSlices
        The grown slices, in the order given.

    Examples
    --------
    >>> from aura_ums import _native
    >>> from aura_ums.uncertainty import TerrainTable
    >>> tile = TerrainTable.default()["tile"]
    >>> square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]] * 2)
    >>> grown = _native.grow_slices(square, np.array([4, 4]), np.array([0.0, 0.1]), np.array([0.1, 0.2]),
    ...                             0.5, 0.5, 0.05, tile, 3.0, [0.0, 1.0], 16)
    >>> len(grown.counts), round(grown.x, 2), bool(grown.stops[1] > 0.2)
    (2, 1.47, True)
    >>> _native.grow_slices(square, np.array([8]), np.zeros(1), np.zeros(1), 0, 0, 0, tile, 3.0, [], 16).x
    0.0
    """
    return _grow_slices(
        grow_commands_reference,
        points,
        counts,
        lo,
        hi,
        x,
        y,
        heading,
        terrain,
        sigmas,
        commands,
        max_vertices,
    )


def _grow_slices(
    grow: Callable[..., Grown],
    points: Array,
    counts: Counts,
    lo: Array,
    hi: Array,
    x: float,
    y: float,
    heading: float,
    terrain: MotionModel,
    sigmas: float,
    commands: Sequence[float],
    max_vertices: int,
) -> GrownSlices:
    """Grow slice by slice with a single-map growth kernel; see :func:`grow_slices_reference`."""
    sizes = _check_packed(points, counts, lo, hi)
    polygons = _split(points, sizes)
    los, his = [float(v) for v in lo], [float(v) for v in hi]
    home = home_slice(los, his, heading)
    grown_polygons: list[Array] = []
    begins: list[float] = []
    ends: list[float] = []
    x_out, y_out, heading_out = float(x), float(y), heading
    for index, (polygon, start, stop) in enumerate(zip(polygons, los, his, strict=True)):
        middle = clamp_into(heading, start, stop) if index == home else 0.5 * (start + stop)
        grown = grow(
            polygon,
            x,
            y,
            middle,
            middle - start,
            max(0.0, stop - middle),
            terrain,
            sigmas,
            commands,
            max_vertices,
        )
        grown_polygons.append(grown.vertices)
        begins.append(grown.heading - grown.cw)
        ends.append(grown.heading + grown.ccw)
        if index == home:
            x_out, y_out, heading_out = float(grown.x), float(grown.y), float(grown.heading)
    out_points, out_counts = _packed(grown_polygons)
    return GrownSlices(out_points, out_counts, np.array(begins), np.array(ends), x_out, y_out, heading_out)


def grow_slices_compiled(
    points: Array,
    counts: Counts,
    lo: Array,
    hi: Array,
    x: float,
    y: float,
    heading: float,
    terrain: MotionModel,
    sigmas: float,
    commands: Sequence[float],
    max_vertices: int,
) -> GrownSlices:
    """Compiled :func:`grow_slices_reference` (needs the extension module)."""
    raw, raw_counts, raw_starts, raw_stops, x, y, heading = _compiled_grow_slices(
        points, counts, lo, hi, x, y, heading, terrain.rotation_loss, terrain.rotation_sd,
        terrain.translation_loss, terrain.translation_sd, terrain.translation_inertial_loss, terrain.drift,
        terrain.skitter, terrain.skitter_sd, sigmas, commands, max_vertices,
    )  # fmt: skip
    return GrownSlices(
        points_view(raw),
        np.frombuffer(raw_counts, dtype=np.int64),
        np.frombuffer(raw_starts, dtype=np.float64),
        np.frombuffer(raw_stops, dtype=np.float64),
        x,
        y,
        heading,
    )


def narrowed(arc_lo: float, arc_width: float, lo: float, hi: float) -> tuple[float, float]:
    """Return a slice's interval [lo, hi] narrowed to a kernel's heading arc ``(arc_lo, arc_width)``.

    The kernel's arc holds every heading of the slice that agrees with the observation,
    so their intersection does; where that intersection is not one interval (a slice wider
    than pi) or the arc is no narrower, the slice's interval is kept (an outer bound).

    Examples
    --------
    >>> [round(h, 9) for h in narrowed(0.15 - 2 * math.pi, 0.02, 0.1, 0.2)]   # any winding
    [0.15, 0.17]
    >>> [round(h, 9) for h in narrowed(0.05, 0.08, 0.1, 0.2)]                 # cut to the slice
    [0.1, 0.13]
    """
    span = hi - lo
    if arc_width >= span:
        return lo, hi
    if span >= _TWO_PI:
        start = arc_lo % _TWO_PI
        return start, start + arc_width
    if span > math.pi:
        return lo, hi
    offset = (arc_lo - lo) % _TWO_PI
    if offset > 0.5 * (span + _TWO_PI):
        offset -= _TWO_PI  # the arc starts clockwise of lo
    new_lo = max(lo + offset, lo)
    new_hi = min(lo + offset + arc_width, hi)
    if new_hi < new_lo:  # rounding at an end: keep the end's heading
        new_hi = new_lo = min(max(new_lo, lo), hi)
    return new_lo, new_hi


def _reduce_slices(
    kernel: Callable[..., RawReduction | int],
    points: Array,
    counts: Counts,
    lo: Array,
    hi: Array,
    x: float,
    y: float,
    heading: float,
    arguments: Sequence[float],
    max_vertices: int,
) -> ReducedSlices | int:
    """Reduce slice by slice with one of the single kernels; see :func:`reduce_cone_slices_reference`."""
    sizes = _check_packed(points, counts, lo, hi)
    kept: list[tuple[float, float, Array, float, float]] = []
    first_reason = -1
    for polygon, piece_lo, piece_hi in zip(_split(points, sizes), lo.tolist(), hi.tolist(), strict=True):
        middle = clamp_into(heading, piece_lo, piece_hi)
        found = kernel(
            polygon, x, y, middle, middle - piece_lo, max(0.0, piece_hi - middle), *arguments, max_vertices
        )
        if isinstance(found, int):
            if first_reason < 0:
                first_reason = int(found)
            continue
        raw, arc_lo, arc_width, center_x, center_y, _, _ = found
        if arc_width < piece_hi - piece_lo:
            piece_lo, piece_hi = narrowed(arc_lo, arc_width, piece_lo, piece_hi)
        kept.append((piece_lo, piece_hi, points_view(raw), center_x, center_y))
    if not kept:
        return first_reason
    # A full-circle slice's arc may start anywhere: keep the slices in heading order.
    kept.sort(key=lambda piece: piece[0])
    los, his = [k[0] for k in kept], [k[1] for k in kept]
    home = home_slice(los, his, heading)
    center, cw, ccw = summary_wedge(los, his, clamp_into(heading, los[home], his[home]))
    out_points, out_counts = _packed([k[2] for k in kept])
    return ReducedSlices(out_points, out_counts, np.array(los), np.array(his), kept[home][3], kept[home][4],
                         center, cw, ccw)  # fmt: skip


def reduce_cone_slices_reference(
    points: Array,
    counts: Counts,
    lo: Array,
    hi: Array,
    x: float,
    y: float,
    heading: float,
    forward: float,
    left: float,
    landmark_x: float,
    landmark_y: float,
    widen: float,
    bearing: float,
    bearing_error: float,
    range_min: float,
    range_max: float,
    piece: float,
    max_vertices: int,
) -> ReducedSlices | int:
    """Reduce every slice by a bearing (Class I) or a range and bearing (Class II).

    The numpy reference, the specification of ``reduce_cone_slices`` in ``reduce.c``:
    ``aura_ums._native.reduce_cone_slices`` is this function, or the compiled one.

    Each slice is a product map of its polygon and its interval, its wedge centred on
    ``heading`` clamped into it, reduced by
    :func:`~aura_ums._native._reduce.reduce_cone_reference` (sound as it is); its interval
    narrows to the kernel's arc (:func:`narrowed`). Empty slices drop out; the union of the
    rest holds every pose of the prior that agrees with the observation. The most probable
    position is the one kept (or moved) in the slice nearest to ``heading``.

    Parameters
    ----------
    points, counts, lo, hi : ndarray
        The slices, as :class:`Distributed` holds them.
    x, y, heading : float
        The most probable pose, metres and radians.
    forward, left, landmark_x, landmark_y, widen, bearing, bearing_error, range_min, range_max, piece
        As for :func:`~aura_ums._native._reduce.reduce_cone_reference`.
    max_vertices : int
        Cap on each reduced polygon's vertex count, >= 3.

    Returns
    -------
    ReducedSlices or int
        The kept slices, or the first slice's :class:`~aura_ums._native.EmptyReason` value
        when every slice is empty.

    Examples
    --------
    >>> from aura_ums import _native
    >>> square = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]] * 2)
    >>> pole = (0.0, 0.0, 20.0, 0.0, 0.0, 0.0, 0.001, 0.0, math.inf, 0.75 * math.pi, 16)
    >>> two = (square, np.array([4, 4]), np.array([0.0, 0.1]), np.array([0.1, 0.2]), 0.0, 0.0, 0.05)
    >>> seen = _native.reduce_cone_slices(*two, *pole)
    >>> len(seen.counts), float(seen.lo[0]), round(float(seen.hi[0]), 4)   # one kept, its headings cut
    (1, 0.0, 0.0536)
    >>> _native.reduce_cone_slices(*two[:6], 3.0, 0.0, 0.0, 20.0, 0.0, 0.0, 3.0, 0.01, 0.0, math.inf, 2.3, 16)
    0
    """
    return _reduce_slices(
        reduce_cone_reference, points, counts, lo, hi, x, y, heading,
        (forward, left, landmark_x, landmark_y, widen, bearing, bearing_error, range_min, range_max, piece),
        max_vertices,
    )  # fmt: skip


def reduce_strip_slices_reference(
    points: Array,
    counts: Counts,
    lo: Array,
    hi: Array,
    x: float,
    y: float,
    heading: float,
    forward: float,
    left: float,
    start_x: float,
    start_y: float,
    end_x: float,
    end_y: float,
    position_uncertainty: float,
    offset: float,
    offset_error: float,
    angle: float,
    angle_error: float,
    max_vertices: int,
) -> ReducedSlices | int:
    """Reduce every slice by a ground line's angle and offset (Class III).

    The numpy reference, the specification of ``reduce_strip_slices`` in ``reduce.c``, as
    :func:`reduce_cone_slices_reference` with
    :func:`~aura_ums._native._reduce.reduce_strip_reference` for each slice.

    Examples
    --------
    >>> from aura_ums import _native
    >>> square = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    >>> one = (square, np.array([4]), np.array([0.0]), np.array([0.2]), 0.0, 0.0, 0.1)
    >>> strip = _native.reduce_strip_slices(*one, 0, 0, -9, -2, 9, -2, 0, 2.0, 0.5, 0, 0.05, 16)
    >>> strip.counts.tolist(), round(float(strip.hi[0]), 6)
    ([4], 0.05)
    >>> _native.reduce_strip_slices(*one, 0, 0, -9, -2, 9, -2, 0, 9.0, 0.5, 0, 0.05, 16)
    4
    """
    return _reduce_slices(
        reduce_strip_reference, points, counts, lo, hi, x, y, heading,
        (forward, left, start_x, start_y, end_x, end_y, position_uncertainty, offset, offset_error, angle,
         angle_error),
        max_vertices,
    )  # fmt: skip


def _reduced(
    found: tuple[bytes, bytes, bytes, bytes, float, float, float, float, float] | int,
) -> ReducedSlices | int:
    if isinstance(found, int):
        return found
    raw, raw_counts, raw_lo, raw_hi, x, y, center, cw, ccw = found
    return ReducedSlices(
        points_view(raw),
        np.frombuffer(raw_counts, dtype=np.int64),
        np.frombuffer(raw_lo, dtype=np.float64),
        np.frombuffer(raw_hi, dtype=np.float64),
        x,
        y,
        center,
        cw,
        ccw,
    )


def reduce_cone_slices_compiled(
    points: Array,
    counts: Counts,
    lo: Array,
    hi: Array,
    x: float,
    y: float,
    heading: float,
    forward: float,
    left: float,
    landmark_x: float,
    landmark_y: float,
    widen: float,
    bearing: float,
    bearing_error: float,
    range_min: float,
    range_max: float,
    piece: float,
    max_vertices: int,
) -> ReducedSlices | int:
    """Compiled :func:`reduce_cone_slices_reference` (needs the extension module)."""
    return _reduced(
        _compiled_reduce_cone_slices(
            points, counts, lo, hi, x, y, heading, forward, left, landmark_x, landmark_y, widen, bearing,
            bearing_error, range_min, range_max, piece, max_vertices,
        )
    )  # fmt: skip


def reduce_strip_slices_compiled(
    points: Array,
    counts: Counts,
    lo: Array,
    hi: Array,
    x: float,
    y: float,
    heading: float,
    forward: float,
    left: float,
    start_x: float,
    start_y: float,
    end_x: float,
    end_y: float,
    position_uncertainty: float,
    offset: float,
    offset_error: float,
    angle: float,
    angle_error: float,
    max_vertices: int,
) -> ReducedSlices | int:
    """Compiled :func:`reduce_strip_slices_reference` (needs the extension module)."""
    return _reduced(
        _compiled_reduce_strip_slices(
            points, counts, lo, hi, x, y, heading, forward, left, start_x, start_y, end_x, end_y,
            position_uncertainty, offset, offset_error, angle, angle_error, max_vertices,
        )
    )  # fmt: skip
