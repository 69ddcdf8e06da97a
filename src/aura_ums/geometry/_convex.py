"""Pure functions on convex polygons stored as ``(n, 2)`` counter-clockwise arrays.

Degenerate polygons are allowed everywhere: one vertex is a point, two are a
segment. Every function that replaces an arc by a polygon returns an *outer*
polygon (one that contains the arc), so that bounds built from them stay sound.

These are the low-level kernels behind ``ConvexPolygon`` and the maps' growth and
reduction (the numpy references of the compiled kernels, on the hot path when those are
off). They trust their arrays: float64 ``(n, 2)`` arrays of finite coordinates, polygons
convex and counter-clockwise as documented, floats finite. Give them what a
``ConvexPolygon`` holds; anything else gives garbage or numpy's errors. Only what
could hang or exhaust memory is checked: the counts of ``outer_disk`` and the span
and step of ``outer_arc``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import shapely
from numpy.typing import NDArray

from aura_ums._validate import bounded_count
from aura_ums.errors import InputError
from aura_ums.geometry._angles import TWO_PI

#: Default angular step of the outer polygon of an arc, radians. The polygon's
#: vertices between the arc's ends lie 1/cos(step/2) - 1 ~ 0.5 % outside the arc.
ARC_STEP = math.pi / 16

# Relative size below which a cross product counts as zero (a straight vertex).
_COLLINEAR_EPS = 1e-12

# Cut parameters this close to an edge's end are that end.
_SAME_POINT = 1e-12

# Only edges longer than this fraction of the coordinates' magnitude are extended to
# replace a removed neighbour: their directions are then good to ~1e-10 rad.
_EXTENDABLE = 1e-6

# A merged vertex may lie at most this many polygon extents from the vertex it replaces.
_FARTHEST_MERGE = 10.0

# Edges shorter than this fraction of the largest have directions that are rounding noise.
_NOISE_EDGE = 1e-12

# Edge directions closer than this (radians) are joined into one edge.
_PARALLEL_EPS = 1e-12

# Angular widths below this (radians) are a single direction.
_TINY_ANGLE = 1e-12

# Vertices closer than this fraction of the polygon's extent are merged.
_MERGE_EPS = 1e-12
# ...or closer than this fraction of their coordinates' magnitude (about 45 rounding steps):
# far from the origin, two vertices a few rounding steps apart make an edge of no direction.
_MERGE_ROUNDING = 1e-14

#: Sides of the outer polygon of a full-circle annular sector (a disk).
FULL_DISK_SIDES = 32

#: Most vertices a polygon built from a count may have (the sides of a disk, the pieces of an
#: arc): 16 MB of vertices; a million took 0.2 s (a disk) to 3 s (an arc, a regular polygon).
MAX_BUILT_VERTICES = 1_000_000
_BUILT_COST = "vertices (16 MB, 3 s)"

# Outward margin of a support polygon's half-planes, relative to the larger of the
# polygon's extent and its distance from the origin: above their rounding.
_SUPPORT_MARGIN = 1e-12

# Point sets larger than this are thinned by GEOS (shapely) before the exact monotone chain.
_PREFILTER = 200

# Up to this many point-edge pairs, containment tests every edge at once.
_DENSE_LIMIT = 4096

Array = NDArray[np.float64]


def _following(values: NDArray[Any]) -> NDArray[Any]:
    """Return ``values`` shifted so row i holds row i+1 (cyclically); np.roll is ~10x slower."""
    shifted = np.empty_like(values)
    shifted[:-1] = values[1:]
    shifted[-1] = values[0]
    return shifted


def _preceding(values: NDArray[Any]) -> NDArray[Any]:
    """Return ``values`` shifted so row i holds row i-1 (cyclically)."""
    shifted = np.empty_like(values)
    shifted[1:] = values[:-1]
    shifted[0] = values[-1]
    return shifted


def _edges(vertices: Array) -> Array:
    """Return the edge vectors of a closed polygon: row i runs from vertex i to vertex i+1."""
    edges = np.empty_like(vertices)
    np.subtract(vertices[1:], vertices[:-1], out=edges[:-1])
    np.subtract(vertices[0], vertices[-1], out=edges[-1])
    return edges


def cross2(a: Array, b: Array) -> Array:
    """Return the z component of the cross product of 2-D vectors, row by row.

    Parameters
    ----------
    a, b : ndarray, shape (..., 2)
        Vectors (x, y), broadcast against each other.

    Returns
    -------
    ndarray, shape (...)
        ``a_x * b_y - a_y * b_x``: positive when ``b`` turns counter-clockwise from ``a``.

    Examples
    --------
    >>> cross2(np.array([[1.0, 0.0], [1.0, 0.0]]), np.array([[0.0, 2.0], [3.0, 0.0]])).tolist()
    [2.0, 0.0]
    """
    return np.asarray(a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0], dtype=np.float64)


def polygon_area(vertices: Array) -> float:
    """Return the signed area (m^2, positive when counter-clockwise) of a polygon.

    ``vertices`` is a finite float64 ``(n, 2)`` array (trusted, not checked); a clockwise
    polygon's area is negative, which ``convexity_defect`` reads to refuse one.

    Examples
    --------
    >>> polygon_area(np.array([[0.0, 0.0], [2.0, 0.0], [0.0, 1.0]]))
    1.0
    >>> polygon_area(np.array([[1.0, 1.0]]))   # a point has no area
    0.0
    """
    if len(vertices) < 3:
        return 0.0
    # Relative to the first vertex: a small polygon far from the origin would
    # otherwise lose its whole area to cancellation.
    x = vertices[:, 0] - vertices[0, 0]
    y = vertices[:, 1] - vertices[0, 1]
    return float(0.5 * (np.dot(x, _following(y)) - np.dot(y, _following(x))))


def remove_collinear(vertices: Array) -> Array:
    """Drop repeated, nearly coincident and straight (180 degree) vertices of a convex polygon.

    Vertices closer than 1e-12 of the polygon's extent, or than 1e-14 of their
    coordinates' magnitude, are merged: their rounding noise would otherwise read as a
    reflex corner, or as a straight one, and both ends of such an edge could go at once.

    Examples
    --------
    >>> far = np.array([[2e4, 0.0], [2e4 + 1.0, 0.0], [2e4 + 2.0, 1.0], [2e4 + 2.0, 1.0 + 4e-12], [2e4, 1.0]])
    >>> remove_collinear(far).tolist()   # the two corners 4e-12 m apart are one
    [[20000.0, 0.0], [20001.0, 0.0], [20002.0, 1.000000000004], [20000.0, 1.0]]
    >>> turn = np.linspace(0.0, 2.0 * np.pi, 432, endpoint=False)
    >>> speck = np.column_stack([16.0 + 1e-10 * np.cos(turn), 1.5 + 1e-10 * np.sin(turn)])
    >>> len(remove_collinear(speck))     # every corner straight within rounding: a segment, not nothing
    2
    """
    n = len(vertices)
    if n < 2:
        return vertices
    span = float(np.max(np.ptp(vertices, axis=0)))
    following = _edges(vertices)
    length = np.hypot(following[:, 0], following[:, 1])
    magnitude = float(np.max(np.abs(vertices)))
    keep = length > _MERGE_EPS * span + _MERGE_ROUNDING * magnitude
    if not np.all(keep):
        if not np.any(keep):
            return vertices[:1].copy()
        vertices = vertices[keep]
        if len(vertices) < 3:
            return vertices
        following = _edges(vertices)
        length = np.hypot(following[:, 0], following[:, 1])
        magnitude = float(np.max(np.abs(vertices)))
    while len(vertices) >= 3:
        preceding = _preceding(following)
        turn = cross2(preceding, following)
        straight = (np.abs(turn) <= _cross_noise(vertices, length, _preceding(length), magnitude)) & (
            np.einsum("ij,ij->i", preceding, following) > 0
        )
        if not np.any(straight):
            break
        if np.all(straight):
            # Every corner is straight to within rounding: a polygon of the noise's size (a
            # tiny round cluster far from the origin). Its extent stays, as the segment from
            # the first vertex to the farthest from it, not as nothing.
            far = int(np.argmax(np.hypot(vertices[:, 0] - vertices[0, 0], vertices[:, 1] - vertices[0, 1])))
            return vertices[[0, far]]
        # A straight vertex goes only if the one before it stays: each is straight between
        # its own neighbours, and two that go at once could cut off a real corner between
        # them (a thin sliver's 2-micrometre bump, each end a picometre from a neighbour).
        # In a run of straight vertices every other one goes (the first, the third, ...):
        # the run halves each pass, so a million collinear vertices take twenty passes.
        first = int(np.argmin(straight))  # a corner that stays: some vertex is not straight
        turned = np.roll(straight, -first)
        index = np.arange(len(turned))
        since = index - np.maximum.accumulate(np.where(turned, 0, index))  # 1 at a run's first
        drop = np.roll(turned & (since % 2 == 1), first)
        vertices = vertices[~drop]
        if not np.any(straight & ~drop):
            break  # none waited for its neighbour: one pass, as ever
        following = _edges(vertices)
        length = np.hypot(following[:, 0], following[:, 1])
        magnitude = float(np.max(np.abs(vertices)))
    return vertices


def _cross_noise(
    vertices: Array, length: Array, preceding_length: Array, magnitude: float | None = None
) -> Array:
    """Return the size below which a corner's cross product is rounding noise.

    The cross product of two edges carries rounding error proportional to the
    coordinates' magnitude (the largest absolute coordinate of ``vertices``, when the
    caller has not taken it already) times the edge lengths, not only to the edge lengths.
    """
    if magnitude is None:
        magnitude = float(np.max(np.abs(vertices)))
    return np.asarray(
        _COLLINEAR_EPS * length * preceding_length + 1e-15 * magnitude * (length + preceding_length),
        dtype=np.float64,
    )


def convex_hull(points: Array, *, straight: bool = False) -> Array:
    """Return the convex hull of points as counter-clockwise vertices without repeats.

    The result has one row for a single point, two for collinear points. Nearly
    coincident and nearly straight vertices are merged (``remove_collinear``) unless
    ``straight``: then every vertex the monotone chain keeps stays, so each edge's line
    holds all of them, however short the edge (far from the origin, the merge's
    straightness test drops vertices up to a few nanometres off a chord).

    Parameters
    ----------
    points : ndarray, shape (n, 2)
        Finite points, n >= 1.

    Returns
    -------
    ndarray, shape (m, 2)
        Hull vertices, counter-clockwise, starting from the lowest-leftmost one.

    Examples
    --------
    >>> convex_hull(np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]])).tolist()  # collinear
    [[0.0, 0.0], [2.0, 2.0]]
    """
    if len(points) > _PREFILTER:
        points = shapely.get_coordinates(shapely.MultiPoint(points).convex_hull)
    pts = np.unique(points, axis=0)
    if len(pts) <= 2:
        return pts
    # Andrew's monotone chain: sorting by coordinates (np.unique did) and cross-product
    # signs only, which stays consistent for nearly collinear points where angle sorts do not.
    ordered = pts.tolist()

    def half_hull(sequence: list[list[float]]) -> list[list[float]]:
        chain: list[list[float]] = []
        for px, py in sequence:
            while len(chain) >= 2:
                (ax, ay), (bx, by) = chain[-2], chain[-1]
                if (bx - ax) * (py - ay) - (by - ay) * (px - ax) > 0.0:
                    break
                chain.pop()
            chain.append([px, py])
        return chain

    lower = half_hull(ordered)
    upper = half_hull(ordered[::-1])
    hull = np.asarray(lower[:-1] + upper[:-1], dtype=np.float64)
    return hull if straight else remove_collinear(hull)


def _lowest_vertex(vertices: Array) -> int:
    """Index of the lowest vertex, the leftmost of the lowest: where edge directions start at 0."""
    index = int(np.argmin(vertices[:, 1]))
    n = len(vertices)
    # In counter-clockwise order a horizontal bottom edge runs left to right, so the
    # leftmost of tied lowest vertices is the one before.
    for _ in range(n - 1):
        previous = index - 1 if index > 0 else n - 1
        if vertices[previous, 1] != vertices[index, 1] or vertices[previous, 0] > vertices[index, 0]:
            break
        index = previous
    return index


def _pseudo_angle(edges: Array) -> Array:
    """Return a monotone stand-in for the direction angle of each edge, in [0, 4).

    The "diamond angle": one division instead of atan2, and the key the compiled
    Minkowski sum orders and joins edges by, so both paths break rounding-level ties
    alike. Its slope is within [0.5, 1] of the angle's. Edges must not be zero.
    """
    x, y = edges[:, 0], edges[:, 1]
    p = y / (np.abs(x) + np.abs(y))
    return np.asarray(np.where(x >= 0.0, np.where(y >= 0.0, p, 4.0 + p), 2.0 - p), dtype=np.float64)


def minkowski_sum(*polygons: Array) -> Array:
    """Return the Minkowski sum of convex counter-clockwise polygons.

    Each operand is a non-empty finite float64 ``(n, 2)`` convex counter-clockwise array
    (trusted, not checked). Merges the edges of all operands by direction, which is exact
    and linear in the total vertex count (plus a sort). Parallel edges are joined. Each operand's
    edges run from its lowest vertex, ties keep operand order, and the vertices are
    summed edge by edge from the start: the compiled kernel's arithmetic, to the bit.

    Examples
    --------
    >>> square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> minkowski_sum(square, np.array([[5.0, 5.0]])).tolist()[0]  # with a point: a shift
    [5.0, 5.0]
    """
    start = np.zeros(2)
    edges = []
    for vertices in polygons:
        low = _lowest_vertex(vertices)
        start = start + vertices[low]
        if len(vertices) >= 2:
            edge = _edges(vertices)
            edges.append(np.concatenate((edge[low:], edge[:low])) if low else edge)
    if not edges:
        return start.reshape(1, 2)
    # Edges below a few ulps of the coordinates vanish when added to them anyway, and
    # edges below 1e-12 of the largest have directions that are mostly rounding noise.
    largest = max(float(np.abs(edge).max()) for edge in edges)
    threshold = max(4e-16 * float(np.abs(start).max()), _NOISE_EDGE * largest)
    kept = [edge[np.abs(edge).max(axis=1) > threshold] for edge in edges]
    merged = np.concatenate(kept) if len(kept) > 1 else kept[0]
    if len(merged) == 0:
        return start.reshape(1, 2)
    direction = _pseudo_angle(merged)
    # Each operand's edges already increase in direction from its lowest vertex, so a
    # stable sort is a merge whose ties keep operand order.
    order = np.argsort(direction, kind="stable")
    merged = merged[order]
    direction = direction[order]
    parallel = np.diff(direction) <= _PARALLEL_EPS
    if np.any(parallel):
        merged = np.add.reduceat(merged, np.flatnonzero(np.concatenate(([True], ~parallel))), axis=0)
    vertices = np.empty((len(merged), 2))
    vertices[0] = start
    vertices[1:] = merged[:-1]
    # Sequentially from the start, as the compiled sum does: not the edges first.
    return np.asarray(np.cumsum(vertices, axis=0), dtype=np.float64)


def _projection(points: Array, normal: Array) -> Array:
    """Return ``x * nx + y * ny`` of each point, rounded as the compiled kernels round it.

    Not ``points @ normal``: BLAS may fuse the multiply and the add, which rounds once less.
    """
    return np.asarray(points[:, 0] * normal[0] + points[:, 1] * normal[1], dtype=np.float64)


def clip_halfplane(vertices: Array, normal: Array, offset: float) -> Array:
    """Return the part of a convex polygon where ``normal . p <= offset``.

    A line meets a convex polygon's boundary in one entry and one exit edge, so the
    result is the run of inside vertices between two cut points, sliced rather than
    masked. Returns an empty ``(0, 2)`` array when nothing is left.

    Examples
    --------
    >>> square = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]])
    >>> clip_halfplane(square, np.array([1.0, 0.0]), 1.0).tolist()
    [[1.0, 2.0], [0.0, 2.0], [0.0, 0.0], [1.0, 0.0]]
    >>> clip_halfplane(square, np.array([1.0, 0.0]), -1.0).shape   # empty
    (0, 2)
    """
    signed = _projection(vertices, normal) - offset
    outside = signed > 0.0
    count = len(vertices)
    outside_count = int(np.count_nonzero(outside))
    if outside_count == 0:
        return vertices
    if outside_count == count:
        return np.empty((0, 2))
    if count < 3:
        return _clip_halfplane_masked(vertices, normal, offset)
    edges = np.flatnonzero(outside[:-1] != outside[1:]).tolist()
    if outside[-1] != outside[0]:
        edges.append(count - 1)
    if len(edges) != 2:  # a segment, a point, or rounding on a degenerate polygon
        return _clip_halfplane_masked(vertices, normal, offset)
    first, second = edges
    exit_edge, entry_edge = (second, first) if outside[first] else (first, second)

    def cut(edge: int, keep_at: float) -> Array:
        following = edge + 1 if edge + 1 < count else 0
        s0, s1 = float(signed[edge]), float(signed[following])
        t = s0 / (s0 - s1)
        if abs(t - keep_at) <= _SAME_POINT:
            # The cut is the inside vertex itself, up to rounding: an edge that short
            # would have no reliable direction, so the vertex stands for it.
            return np.empty((0, 2))
        (ax, ay), (bx, by) = vertices[[edge, following]].tolist()
        return np.array([[ax + t * (bx - ax), ay + t * (by - ay)]])

    start = entry_edge + 1
    if start <= exit_edge:
        run = vertices[start : exit_edge + 1]
    else:
        run = np.concatenate((vertices[start:], vertices[: exit_edge + 1]))
    # Entry edges run from outside to inside (the inside end is t = 1), exit edges back.
    return np.concatenate((cut(entry_edge, 1.0), run, cut(exit_edge, 0.0)))


def _clip_halfplane_masked(vertices: Array, normal: Array, offset: float) -> Array:
    """Clip by masking every vertex and cut point: slower, but right for degenerate input."""
    signed = _projection(vertices, normal) - offset
    inside = signed <= 0.0
    if np.all(inside):
        return vertices
    if not np.any(inside):
        return np.empty((0, 2))
    following = _following(vertices)
    signed_following = _following(signed)
    crossing = inside != (signed_following <= 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.where(crossing, signed / (signed - signed_following), 0.0)
    cut = vertices + t[:, None] * (following - vertices)
    candidates = np.stack([vertices, cut], axis=1).reshape(-1, 2)
    mask = np.stack([inside, crossing], axis=1).reshape(-1)
    return remove_collinear(candidates[mask])


def side_count(sides: object, name: str = "sides") -> int:
    """Return a polygon's number of sides, an integer in [3, :data:`MAX_BUILT_VERTICES`], or raise.

    Integers only, numpy's too (not a bool, not a float such as 3.0), as every count of the library.
    """
    return bounded_count(sides, name, 3, MAX_BUILT_VERTICES, _BUILT_COST)


def outer_disk(center: Array, radius: float, sides: int = 16) -> Array:
    """Return a regular polygon with ``sides`` vertices that contains the disk.

    Parameters
    ----------
    center : ndarray, shape (2,)
        The disk's centre, metres, finite (trusted, not checked).
    radius : float
        Metres, finite (trusted); <= 0 gives the centre alone.
    sides : int
        An integer in [3, 1,000,000] (checked: 10**12 asked for terabytes).

    Examples
    --------
    >>> outer_disk(np.zeros(2), 0.0).tolist()  # a zero radius gives the point
    [[0.0, 0.0]]
    >>> outer_disk(np.zeros(2), 1.0, 10**12)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: sides: expected at most 1,000,000 vertices (16 MB, 3 s), got 1000000000000
    """
    if type(sides) is not int or not 3 <= sides <= MAX_BUILT_VERTICES:  # a Python int: one test
        sides = side_count(sides)
    if radius <= 0.0:
        return np.asarray(center, dtype=np.float64).reshape(1, 2).copy()
    angles = np.arange(sides) * (TWO_PI / sides)
    reach = radius / math.cos(math.pi / sides)
    return np.column_stack([center[0] + reach * np.cos(angles), center[1] + reach * np.sin(angles)])


#: Radians: the widest piece of an outer arc (a wider ``step`` is cut to it).
_WIDEST_ARC_PIECE = math.pi / 2

#: Radians: the longest span of an outer arc, one turn and a hair (``lo + width - lo`` may
#: round a width just below a turn to above it).
_LONGEST_ARC = TWO_PI * (1.0 + 1e-9)


def outer_arc(radius: float, start: float, stop: float, step: float = ARC_STEP) -> Array:
    """Return points, counter-clockwise from ``start`` to ``stop``, of an outer polygon of an arc.

    The arc is centred on the origin; ``0 < stop - start < 2*pi`` (a span up to a hair
    beyond one turn, as rounding gives one, is taken; more, or not finite, is refused: a
    span of 1e300 rad never returned). The returned polyline runs from the arc's start
    point through tangent intersections to its end point, so the region between it and the
    origin contains the arc. ``radius`` is trusted (finite, >= 0); ``step`` must be
    positive and cut the arc into at most 1,000,000 pieces.

    Examples
    --------
    >>> quarter = outer_arc(1.0, 0.0, math.pi / 2)   # 8 steps of pi/16: ends and 8 tangent corners
    >>> len(quarter), quarter[0].tolist(), quarter[-1].round(12).tolist()
    (10, [1.0, 0.0], [0.0, 1.0])
    >>> bool(np.all(np.hypot(quarter[:, 0], quarter[:, 1]) >= 1.0))   # nothing inside the arc
    True
    >>> outer_arc(1.0, 0.0, 1.0, step=1.0).round(4).tolist()   # one step: a single corner
    [[1.0, 0.0], [1.0, 0.5463], [0.5403, 0.8415]]
    >>> outer_arc(0.0, 0.0, 0.1).tolist()   # a zero radius: the origin, three times
    [[0.0, 0.0], [0.0, 0.0], [0.0, 0.0]]
    >>> len(outer_arc(1.0, 0.0, 3.5, step=4.0))   # a step wider than pi/2 is cut: 3 corners
    5
    >>> outer_arc(1.0, 0.0, 1.0, step=0.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: step: expected a positive number, got 0.0
    >>> outer_arc(1.0, 0.0, 1e300)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: stop - start: expected at most 2 pi rad, got 1e+300 (start 0.0, stop 1e+300)
    """
    if not step > 0.0:  # also NaN
        raise InputError(f"step: expected a positive number, got {step!r}")
    width = stop - start
    if not -_LONGEST_ARC <= width <= _LONGEST_ARC:  # also NaN, from an infinite start or stop
        raise InputError(
            f"stop - start: expected at most 2 pi rad, got {width!r} (start {start!r}, stop {stop!r})"
        )
    # A piece's corner lies at radius / cos(piece / 2): past pi it would be behind the origin.
    pieces = width / min(step, _WIDEST_ARC_PIECE)
    if pieces > MAX_BUILT_VERTICES:
        raise InputError(
            f"step: expected at most {MAX_BUILT_VERTICES:,} pieces of the arc (a vertex each: 16 MB, 3 s), "
            f"got {pieces:.3g} ({width!r} rad in steps of {step!r} rad)"
        )
    count = max(1, math.ceil(pieces))
    half = width / (2 * count)
    reach = radius / math.cos(half)
    # Few points: plain floats beat numpy's per-call overhead here.
    points = [(radius * math.cos(start), radius * math.sin(start))]
    for k in range(count):
        angle = start + (2 * k + 1) * half
        points.append((reach * math.cos(angle), reach * math.sin(angle)))
    points.append((radius * math.cos(stop), radius * math.sin(stop)))
    return np.array(points)


def outer_annular_sector(
    inner: float, outer: float, start: float, stop: float, step: float = ARC_STEP
) -> Array:
    """Return a convex outer polygon of an annular sector centred on the origin.

    The sector holds the points at distance ``inner`` to ``outer`` (m) from the
    origin whose direction lies counter-clockwise from ``start`` to ``stop``
    (radians, ``start <= stop``). A sector of ``2*pi`` or more is a disk. The radii and
    angles are trusted (finite); ``step`` must cut the arc into at most 1,000,000 pieces.

    Examples
    --------
    >>> outer_annular_sector(0.0, 0.0, 0.0, 1.0).tolist()   # zero run: the origin
    [[0.0, 0.0]]
    >>> len(outer_annular_sector(1.0, 2.0, 0.0, 0.0))       # zero width: a segment
    2
    """
    width = stop - start
    if outer <= 0.0:
        return np.zeros((1, 2))
    if not width < TWO_PI:  # NaN too, from infinite bounds: the disk
        return outer_disk(np.zeros(2), outer, sides=FULL_DISK_SIDES)
    if width <= _TINY_ANGLE:
        # Narrower than rounding can resolve at any sensible radius: a single ray.
        direction = np.array([math.cos(start), math.sin(start)])
        if inner >= outer:
            return (outer * direction).reshape(1, 2)
        return np.vstack([inner * direction, outer * direction])
    arc = outer_arc(outer, start, stop, step)
    if width >= math.pi or inner >= outer:
        # The hull of an arc of pi or more already holds the origin, hence the inner arc;
        # a sector with no depth is its arc, closed by the chord.
        return remove_collinear(arc)
    if inner <= 0.0:
        return np.vstack([arc, np.zeros((1, 2))])
    ends = inner * np.array([[math.cos(stop), math.sin(stop)], [math.cos(start), math.sin(start)]])
    return np.vstack([arc, ends])


def simplify_outer(vertices: Array, max_vertices: int) -> Array:
    """Return a convex polygon with at most ``max(max_vertices, 3)`` vertices that contains ``vertices``.

    Removes the edges whose removal (extending both neighbouring edges until they
    meet) adds the least area, greedily and never two adjacent edges in one pass.
    An edge whose neighbours would meet more than 10 extents of the polygon away, or
    whose neighbours are too short for their directions to be reliable, is never
    removed. When no edge can go and there are still too many, the support polygon
    (``_support_polygon``) of ``max(max_vertices, 3)`` directions replaces the
    polygon: coarser, but the cap always holds.

    Examples
    --------
    >>> circle = outer_disk(np.zeros(2), 1.0, 64)
    >>> len(simplify_outer(circle, 16)), len(simplify_outer(circle, 3))
    (16, 3)
    >>> square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> len(simplify_outer(square, 3))   # parallel sides never meet: the support triangle
    3
    """
    while len(vertices) > max(max_vertices, 3):
        n = len(vertices)
        edge = _edges(vertices)
        preceding = _preceding(edge)
        following = _following(edge)
        denominator = cross2(preceding, following)
        # Removing an edge needs its neighbours to turn by less than pi, or they never meet;
        # and neighbours long enough that their lines are not rounding noise.
        # An edge's direction is good to ~1e-16 * |coordinates| / length radians.
        length = np.abs(edge).max(axis=1)
        usable = length > _EXTENDABLE * max(float(np.abs(vertices).max()), float(length.max()))
        removable = (denominator > 0.0) & _preceding(usable) & _following(usable)
        with np.errstate(invalid="ignore", divide="ignore"):
            t = np.where(removable, cross2(edge, following) / denominator, 0.0)
        # Nearly parallel neighbours meet far away: such a vertex is useless and its
        # coordinates swamp the polygon's, so the cap yields instead.
        reach = t * np.abs(preceding).max(axis=1)
        removable &= (t >= 0.0) & (reach <= _FARTHEST_MERGE * float(np.ptp(vertices, axis=0).max()))
        # Both corners of the edge must turn left: after a rounding-level right turn the
        # neighbours' lines meet beyond the following edge's start, on the wrong side.
        turn_in = cross2(preceding, edge)
        removable &= turn_in >= 0.0
        cost = np.where(removable, 0.5 * t * turn_in, np.inf)
        needed = n - max_vertices
        chosen: list[int] = []
        blocked = [False] * n
        costs = cost.tolist()
        for index in np.argsort(cost, kind="stable").tolist():
            if costs[index] == math.inf:
                break
            if blocked[index]:
                continue
            chosen.append(index)
            if len(chosen) == needed:
                break
            blocked[index - 1] = blocked[index] = blocked[(index + 1) % n] = True
        if not chosen:
            break
        picked = np.asarray(chosen)
        result = vertices.copy()
        result[picked] = vertices[picked] + t[picked, None] * preceding[picked]
        keep = np.ones(n, dtype=bool)
        keep[(picked + 1) % n] = False
        vertices = result[keep]
    if len(vertices) > max(max_vertices, 3):
        vertices = _support_polygon(vertices, max(max_vertices, 3))
    return vertices


def _support_polygon(vertices: Array, count: int) -> Array:
    """Return an outer polygon of at most ``count`` (< n) vertices: support lines in even directions.

    The half-planes that support the polygon in ``count`` directions evenly spaced from
    its longest edge's outward normal (pushed out by a margin above rounding) hold it
    whatever their directions' rounding, since each offset is the largest projection of a
    vertex; consecutive lines meet at the result's corners. The longest edge stays as it
    is, and with an even ``count`` the side opposite to it too.
    """
    lower, upper = vertices.min(axis=0), vertices.max(axis=0)
    center = 0.5 * (lower + upper)
    span = float(max(upper[0] - lower[0], upper[1] - lower[1]))
    margin = _SUPPORT_MARGIN * max(span, abs(float(center[0])), abs(float(center[1])))
    edge = _edges(vertices)
    longest = int(np.argmax(np.hypot(edge[:, 0], edge[:, 1])))
    start = math.atan2(-float(edge[longest, 0]), float(edge[longest, 1]))
    angles = start + np.arange(count) * (TWO_PI / count)
    nx, ny = np.cos(angles), np.sin(angles)
    relative = vertices - center
    reach = (relative[:, 0, None] * nx[None, :] + relative[:, 1, None] * ny[None, :]).max(axis=0) + margin
    # Corner j joins the lines of directions j and j + 1.
    mx, my, mreach = _following(nx), _following(ny), _following(reach)
    det = nx * my - ny * mx
    corners = np.column_stack(
        [(reach * my - mreach * ny) / det + center[0], (nx * mreach - mx * reach) / det + center[1]]
    )
    # Lines that touch the polygon where their neighbours meet give repeated corners.
    close = _MERGE_EPS * span
    kept: list[list[float]] = []
    for x, y in corners.tolist():
        if not kept or max(abs(x - kept[-1][0]), abs(y - kept[-1][1])) > close:
            kept.append([x, y])
    while len(kept) > 1 and max(abs(kept[-1][0] - kept[0][0]), abs(kept[-1][1] - kept[0][1])) <= close:
        kept.pop()
    return np.array(kept)


def checks_every_edge(points: int, vertices: int) -> bool:
    """Tell whether :func:`points_in_convex` checks these many points against every edge at once.

    A compiled one-point test that must give the same answers takes the same path up to
    this size (the edge-by-edge test, not the binary search on angles).

    Parameters
    ----------
    points, vertices : int
        How many points are tested, against a polygon of how many vertices (>= 0;
        trusted, not checked: it is asked once per point tested).

    Examples
    --------
    >>> checks_every_edge(1, 64), checks_every_edge(1000, 1000)
    (True, False)
    >>> checks_every_edge(0, 0)   # nothing to test: trivially the dense path
    True
    """
    return points * vertices <= _DENSE_LIMIT


def points_in_convex(vertices: Array, points: Array, tolerance: float) -> NDArray[np.bool_]:
    """Tell which points lie in a convex polygon, counting ``tolerance`` metres around it.

    Works for degenerate polygons (a point, a segment) by distance.

    Parameters
    ----------
    vertices : ndarray, shape (n, 2)
        Convex counter-clockwise polygon, metres, n >= 1.
    points : ndarray, shape (m, 2)
        Points (x, y), metres.
    tolerance : float
        Distance (m, >= 0) outside the polygon that still counts as inside.

    Returns
    -------
    ndarray of bool, shape (m,)
        True for the points inside (or within ``tolerance`` of) the polygon.

    Examples
    --------
    >>> square = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]])
    >>> points_in_convex(square, np.array([[1.0, 1.0], [2.0 + 1e-10, 1.0], [3.0, 1.0]]), 1e-9).tolist()
    [True, True, False]
    >>> points_in_convex(np.array([[1.0, 1.0]]), np.array([[1.0, 1.0]]), 0.0).tolist()  # a point
    [True]
    """
    n = len(vertices)
    if n < 3 or polygon_area(vertices) <= 0.0:
        return np.asarray(distance_to_boundary(vertices, points) <= tolerance)
    if len(points) * n <= _DENSE_LIMIT:
        edge = _edges(vertices)
        length = np.hypot(edge[:, 0], edge[:, 1])
        # Signed distance of every point to every edge's line, positive inside.
        relative_x = points[:, 0, None] - vertices[None, :, 0]
        relative_y = points[:, 1, None] - vertices[None, :, 1]
        signed = edge_distances(
            edge[None, :, 0] * relative_y - edge[None, :, 1] * relative_x, length[None, :]
        )
        return np.asarray(np.all(signed >= -tolerance, axis=1))
    # Many points: find each point's wedge around an interior point by binary search on
    # the vertices' angles, then test the one edge that closes that wedge.
    inside_point = vertices.mean(axis=0)
    angle = np.arctan2(vertices[:, 1] - inside_point[1], vertices[:, 0] - inside_point[0])
    first = int(np.argmin(angle))
    ordered = np.concatenate([vertices[first:], vertices[:first]])
    ordered_angle = np.concatenate([angle[first:], angle[:first]])
    point_angle = np.arctan2(points[:, 1] - inside_point[1], points[:, 0] - inside_point[0])
    index = np.searchsorted(ordered_angle, point_angle, side="right") - 1
    index[index < 0] = n - 1
    start = ordered[index]
    edge = ordered[(index + 1) % n] - start
    signed = edge_distances(cross2(edge, points - start), np.hypot(edge[:, 0], edge[:, 1]))
    return np.asarray(signed >= -tolerance)


def edge_distances(cross: NDArray[np.float64], length: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return ``cross / length``: signed distances (m) to edges' lines, +inf for an edge of no length.

    A repeated vertex makes an edge of no length, which constrains nothing: 0 / 0 would
    be NaN (and a warning), and NaN >= -tolerance would put every point outside.

    Parameters
    ----------
    cross : ndarray
        Each edge's vector crossed with the point relative to the edge's start, m^2.
    length : ndarray
        Each edge's length, m; broadcasts against ``cross``.

    Returns
    -------
    ndarray of float64
        The distances, m, positive on the left of the edge (inside a counter-clockwise polygon).

    Examples
    --------
    >>> edge_distances(np.array([2.0, -4.0, 0.0]), np.array([2.0, 2.0, 0.0])).tolist()  # the edge: no length
    [1.0, -2.0, inf]
    """
    out = np.full(np.broadcast_shapes(cross.shape, length.shape), np.inf)
    return np.asarray(np.divide(cross, length, out=out, where=length > 0.0), dtype=np.float64)


def distance_to_boundary(vertices: Array, points: Array) -> Array:
    """Return each point's distance (m) to the nearest point of the polygon's boundary."""
    if len(vertices) == 1:
        return np.asarray(np.hypot(*(points - vertices[0]).T), dtype=np.float64)
    start = vertices
    edge = _edges(vertices)
    squared = np.einsum("ij,ij->i", edge, edge)
    relative = points[:, None, :] - start[None, :, :]
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.where(squared > 0.0, np.einsum("pij,ij->pi", relative, edge) / squared, 0.0)
    t = np.clip(t, 0.0, 1.0)
    nearest = start[None, :, :] + t[:, :, None] * edge[None, :, :]
    gap = points[:, None, :] - nearest
    return np.asarray(np.min(np.hypot(gap[..., 0], gap[..., 1]), axis=1), dtype=np.float64)


def convexity_defect(vertices: Array) -> str | None:
    """Describe why ``vertices`` is not a convex counter-clockwise polygon, or return None."""
    n = len(vertices)
    if n < 3:
        return None
    edge = _edges(vertices)
    if np.any((edge[:, 0] == 0.0) & (edge[:, 1] == 0.0)):
        return "repeated consecutive vertices"
    preceding = _preceding(edge)
    turn = cross2(preceding, edge)
    dot = np.einsum("ij,ij->i", preceding, edge)
    scale = np.hypot(*preceding.T) * np.hypot(*edge.T)
    angle = np.arctan2(turn, dot)
    angle = np.where((np.abs(turn) <= _COLLINEAR_EPS * scale) & (dot < 0.0), math.pi, angle)
    if polygon_area(vertices) < 0.0:
        return "clockwise order (reverse the vertices, or use ConvexPolygon.from_points)"
    lengths = np.hypot(*edge.T)
    reflex = turn < -(1e-9 * scale + 1e3 * _cross_noise(vertices, lengths, _preceding(lengths)))
    if np.any(reflex):
        bad = int(np.flatnonzero(reflex)[0])
        return f"a reflex (non-convex) corner at vertex {bad} {vertices[bad].tolist()}"
    if abs(float(np.sum(angle)) - TWO_PI) > 1e-6:
        return "a boundary that winds around more than once"
    return None
