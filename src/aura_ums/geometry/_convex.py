"""Pure functions on convex polygons stored as ``(n, 2)`` counter-clockwise arrays.

Degenerate polygons are allowed everywhere: one vertex is a point, two are a
segment. Every function that replaces an arc by a polygon returns an *outer*
polygon (one that contains the arc), so that bounds built from them stay sound.
"""

from __future__ import annotations

import contextlib
import math

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import ConvexHull, QhullError

from aura_ums.geometry._angles import TWO_PI

#: Default angular step of the outer polygon of an arc, radians. The polygon's
#: vertices between the arc's ends lie 1/cos(step/2) - 1 ~ 0.5 % outside the arc.
ARC_STEP = math.pi / 16

# Relative size below which a cross product counts as zero (a straight vertex).
_COLLINEAR_EPS = 1e-12

# Angular widths below this (radians) are a single direction.
_TINY_ANGLE = 1e-12

# Vertices closer than this fraction of the polygon's extent are merged.
_MERGE_EPS = 1e-12

# Point sets larger than this are thinned by Qhull before the exact monotone chain.
_QHULL_PREFILTER = 200

Array = NDArray[np.float64]


def cross2(a: Array, b: Array) -> Array:
    """Return the z component of the cross product of 2-D vectors, row by row."""
    return np.asarray(a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0], dtype=np.float64)


def polygon_area(vertices: Array) -> float:
    """Return the signed area (m^2, positive when counter-clockwise) of a polygon.

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
    return float(0.5 * (np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def remove_collinear(vertices: Array) -> Array:
    """Drop repeated, nearly coincident and straight (180 degree) vertices of a convex polygon.

    Vertices closer than 1e-12 of the polygon's extent are merged: their rounding
    noise would otherwise read as a reflex corner.
    """
    n = len(vertices)
    if n < 2:
        return vertices
    span = float(np.max(np.ptp(vertices, axis=0)))
    following = np.roll(vertices, -1, axis=0) - vertices
    length = np.hypot(following[:, 0], following[:, 1])
    keep = length > _MERGE_EPS * span
    if not np.all(keep):
        if not np.any(keep):
            return vertices[:1].copy()
        vertices = vertices[keep]
        if len(vertices) < 3:
            return vertices
        following = np.roll(vertices, -1, axis=0) - vertices
        length = np.hypot(following[:, 0], following[:, 1])
    if len(vertices) < 3:
        return vertices
    preceding = np.roll(following, 1, axis=0)
    turn = cross2(preceding, following)
    straight = (np.abs(turn) <= _cross_noise(vertices, length, np.roll(length, 1))) & (
        np.einsum("ij,ij->i", preceding, following) > 0
    )
    if np.any(straight):
        vertices = vertices[~straight]
    return vertices


def _cross_noise(vertices: Array, length: Array, preceding_length: Array) -> Array:
    """Return the size below which a corner's cross product is rounding noise.

    The cross product of two edges carries rounding error proportional to the
    coordinates' magnitude times the edge lengths, not only to the edge lengths.
    """
    magnitude = float(np.max(np.abs(vertices)))
    return np.asarray(
        _COLLINEAR_EPS * length * preceding_length + 1e-15 * magnitude * (length + preceding_length),
        dtype=np.float64,
    )


def convex_hull(points: Array) -> Array:
    """Return the convex hull of points as counter-clockwise vertices without repeats.

    The result has one row for a single point, two for collinear points.

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
    pts = np.unique(points, axis=0)
    if len(pts) > _QHULL_PREFILTER:
        # Degenerate (collinear) input makes Qhull fail; the exact chain below handles it.
        with contextlib.suppress(QhullError):
            pts = np.unique(pts[ConvexHull(pts).vertices], axis=0)
    if len(pts) <= 2:
        return pts
    order = np.lexsort((pts[:, 0], pts[:, 1]))  # lowest, then leftmost first
    anchor = pts[order[0]]
    rest = pts[order[1:]] - anchor
    angle = np.arctan2(rest[:, 1], rest[:, 0])
    distance = np.hypot(rest[:, 0], rest[:, 1])
    ordered = rest[np.lexsort((distance, angle))]
    hull: list[tuple[float, float]] = [(0.0, 0.0)]
    for px, py in ordered.tolist():
        while len(hull) >= 2:
            ax, ay = hull[-2]
            bx, by = hull[-1]
            if (bx - ax) * (py - ay) - (by - ay) * (px - ax) > 0.0:
                break
            hull.pop()
        hull.append((px, py))
    result = np.asarray(hull, dtype=np.float64) + anchor
    return remove_collinear(result)


def minkowski_sum(*polygons: Array) -> Array:
    """Return the Minkowski sum of convex counter-clockwise polygons.

    Merges the edges of all operands by direction, which is exact and linear in
    the total vertex count.

    Examples
    --------
    >>> square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> minkowski_sum(square, np.array([[5.0, 5.0]])).tolist()[0]  # with a point: a shift
    [5.0, 5.0]
    """
    start = np.zeros(2)
    edges = []
    for vertices in polygons:
        lowest = np.lexsort((vertices[:, 0], vertices[:, 1]))[0]
        start = start + vertices[lowest]
        if len(vertices) >= 2:
            edges.append(np.roll(vertices, -1, axis=0) - vertices)
    if not edges:
        return start.reshape(1, 2)
    merged = np.concatenate(edges)
    merged = merged[(merged[:, 0] != 0.0) | (merged[:, 1] != 0.0)]
    if len(merged) == 0:
        return start.reshape(1, 2)
    direction = np.arctan2(merged[:, 1], merged[:, 0])
    direction = np.where(direction < 0.0, direction + TWO_PI, direction)
    merged = merged[np.argsort(direction, kind="stable")]
    vertices = np.empty((len(merged), 2))
    vertices[0] = start
    np.cumsum(merged[:-1], axis=0, out=vertices[1:])
    vertices[1:] += start
    return remove_collinear(vertices)


def clip_halfplane(vertices: Array, normal: Array, offset: float) -> Array:
    """Return the part of a convex polygon where ``normal . p <= offset``.

    Returns an empty ``(0, 2)`` array when nothing is left.

    Examples
    --------
    >>> square = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]])
    >>> clip_halfplane(square, np.array([1.0, 0.0]), 1.0).tolist()
    [[0.0, 0.0], [1.0, 0.0], [1.0, 2.0], [0.0, 2.0]]
    >>> clip_halfplane(square, np.array([1.0, 0.0]), -1.0).shape   # empty
    (0, 2)
    """
    signed = vertices @ normal - offset
    inside = signed <= 0.0
    if np.all(inside):
        return vertices
    if not np.any(inside):
        return np.empty((0, 2))
    following = np.roll(vertices, -1, axis=0)
    signed_following = np.roll(signed, -1)
    crossing = inside != (signed_following <= 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.where(crossing, signed / (signed - signed_following), 0.0)
    cut = vertices + t[:, None] * (following - vertices)
    candidates = np.stack([vertices, cut], axis=1).reshape(-1, 2)
    mask = np.stack([inside, crossing], axis=1).reshape(-1)
    return remove_collinear(candidates[mask])


def outer_disk(center: Array, radius: float, sides: int = 16) -> Array:
    """Return a regular polygon with ``sides`` vertices that contains the disk.

    Examples
    --------
    >>> outer_disk(np.zeros(2), 0.0).tolist()  # a zero radius gives the point
    [[0.0, 0.0]]
    """
    if radius <= 0.0:
        return np.asarray(center, dtype=np.float64).reshape(1, 2).copy()
    angles = np.arange(sides) * (TWO_PI / sides)
    reach = radius / math.cos(math.pi / sides)
    return np.column_stack([center[0] + reach * np.cos(angles), center[1] + reach * np.sin(angles)])


def outer_arc(radius: float, start: float, stop: float, step: float = ARC_STEP) -> Array:
    """Return points, counter-clockwise from ``start`` to ``stop``, of an outer polygon of an arc.

    The arc is centred on the origin; ``0 < stop - start < 2*pi``. The returned
    polyline runs from the arc's start point through tangent intersections to its
    end point, so the region between it and the origin contains the arc.
    """
    width = stop - start
    count = max(1, math.ceil(width / step))
    half = width / (2 * count)
    middle = start + (2 * np.arange(count) + 1) * half
    reach = radius / math.cos(half)
    points = np.empty((count + 2, 2))
    points[0] = (radius * math.cos(start), radius * math.sin(start))
    points[1:-1, 0] = reach * np.cos(middle)
    points[1:-1, 1] = reach * np.sin(middle)
    points[-1] = (radius * math.cos(stop), radius * math.sin(stop))
    return points


def outer_annular_sector(
    inner: float, outer: float, start: float, stop: float, step: float = ARC_STEP
) -> Array:
    """Return a convex outer polygon of an annular sector centred on the origin.

    The sector holds the points at distance ``inner`` to ``outer`` (m) from the
    origin whose direction lies counter-clockwise from ``start`` to ``stop``
    (radians, ``start <= stop``). A sector of ``2*pi`` or more is a disk.

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
    if width >= TWO_PI:
        return outer_disk(np.zeros(2), outer, sides=32)
    if width <= _TINY_ANGLE:
        # Narrower than rounding can resolve at any sensible radius: a single ray.
        direction = np.array([math.cos(start), math.sin(start)])
        if inner >= outer:
            return (outer * direction).reshape(1, 2)
        return np.vstack([inner * direction, outer * direction])
    arc = outer_arc(outer, start, stop, step)
    if width >= math.pi:
        # The hull of an arc of pi or more already holds the origin, hence the inner arc.
        return remove_collinear(arc)
    if inner <= 0.0:
        return remove_collinear(np.vstack([arc, np.zeros((1, 2))]))
    ends = inner * np.array([[math.cos(stop), math.sin(stop)], [math.cos(start), math.sin(start)]])
    return remove_collinear(np.vstack([arc, ends]))


def simplify_outer(vertices: Array, max_vertices: int) -> Array:
    """Return a convex polygon with at most ``max_vertices`` vertices that contains ``vertices``.

    Repeatedly removes the edges whose removal (extending both neighbouring
    edges until they meet) adds the least area; non-adjacent edges go in one pass.
    Polygons that cannot lose an edge (a triangle) are returned as they are.
    """
    while len(vertices) > max(max_vertices, 3):
        n = len(vertices)
        edge = np.roll(vertices, -1, axis=0) - vertices
        preceding = np.roll(edge, 1, axis=0)
        following = np.roll(edge, -1, axis=0)
        denominator = cross2(preceding, following)
        removable = denominator > _COLLINEAR_EPS * np.hypot(*preceding.T) * np.hypot(*following.T)
        with np.errstate(invalid="ignore", divide="ignore"):
            t = np.where(removable, cross2(edge, following) / denominator, 0.0)
        cost = np.where(removable, 0.5 * t * cross2(preceding, edge), np.inf)
        # Rank to break ties, so that local minima are never adjacent edges.
        rank = np.empty(n, dtype=np.int64)
        rank[np.argsort(cost, kind="stable")] = np.arange(n)
        local_min = (rank < np.roll(rank, 1)) & (rank < np.roll(rank, -1)) & np.isfinite(cost)
        candidates = np.flatnonzero(local_min)
        if len(candidates) == 0:
            break
        chosen = candidates[np.argsort(cost[candidates], kind="stable")[: n - max_vertices]]
        result = vertices.copy()
        result[chosen] = vertices[chosen] + t[chosen, None] * preceding[chosen]
        keep = np.ones(n, dtype=bool)
        keep[(chosen + 1) % n] = False
        vertices = result[keep]
    return vertices


def points_in_convex(vertices: Array, points: Array, tolerance: float) -> NDArray[np.bool_]:
    """Tell which points lie in a convex polygon, counting ``tolerance`` metres around it.

    Works for degenerate polygons (a point, a segment) by distance.
    """
    n = len(vertices)
    if n >= 3 and polygon_area(vertices) > 0.0:
        edge = np.roll(vertices, -1, axis=0) - vertices
        length = np.hypot(edge[:, 0], edge[:, 1])
        # Signed distance of every point to every edge's line, positive inside.
        relative_x = points[:, 0, None] - vertices[None, :, 0]
        relative_y = points[:, 1, None] - vertices[None, :, 1]
        signed = (edge[None, :, 0] * relative_y - edge[None, :, 1] * relative_x) / length[None, :]
        return np.asarray(np.all(signed >= -tolerance, axis=1))
    return np.asarray(distance_to_boundary(vertices, points) <= tolerance)


def distance_to_boundary(vertices: Array, points: Array) -> Array:
    """Return each point's distance (m) to the nearest point of the polygon's boundary."""
    if len(vertices) == 1:
        return np.asarray(np.hypot(*(points - vertices[0]).T), dtype=np.float64)
    start = vertices
    edge = np.roll(vertices, -1, axis=0) - vertices
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
    edge = np.roll(vertices, -1, axis=0) - vertices
    if np.any((edge[:, 0] == 0.0) & (edge[:, 1] == 0.0)):
        return "repeated consecutive vertices"
    preceding = np.roll(edge, 1, axis=0)
    turn = cross2(preceding, edge)
    dot = np.einsum("ij,ij->i", preceding, edge)
    scale = np.hypot(*preceding.T) * np.hypot(*edge.T)
    angle = np.arctan2(turn, dot)
    angle = np.where((np.abs(turn) <= _COLLINEAR_EPS * scale) & (dot < 0.0), math.pi, angle)
    if polygon_area(vertices) < 0.0:
        return "clockwise order (reverse the vertices, or use ConvexPolygon.from_points)"
    lengths = np.hypot(*edge.T)
    reflex = turn < -(1e-9 * scale + 1e3 * _cross_noise(vertices, lengths, np.roll(lengths, 1)))
    if np.any(reflex):
        bad = int(np.flatnonzero(reflex)[0])
        return f"a reflex (non-convex) corner at vertex {bad} {vertices[bad].tolist()}"
    if abs(float(np.sum(angle)) - TWO_PI) > 1e-6:
        return "a boundary that winds around more than once"
    return None
