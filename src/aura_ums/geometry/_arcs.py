"""Arithmetic on arcs of the circle of directions.

An arc is a pair ``(lo, width)`` in radians: every direction from ``lo``
counter-clockwise to ``lo + width``. ``lo`` need not be wrapped; a ``width`` of
``2*pi`` or more is the whole circle. Every function here errs outward, so that
set-membership bounds built from them stay sound.

These are kernels of the maps' reduction (the numpy references of the compiled ones, on
the hot path when those are off): they trust their input and check nothing. Arcs are
pairs of finite floats; ``vertices`` a finite float64 ``(n, 2)`` convex counter-clockwise
polygon, n >= 1, as a ``ConvexPolygon`` holds it; ``point`` a finite float64 ``(2,)``
array. A NaN gives NaN out, not an error.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from aura_ums.geometry._angles import TWO_PI

#: An arc of directions ``(lo, width)``, radians (see the module notes).
Arc = tuple[float, float]

#: The arc of every direction.
FULL_CIRCLE: Arc = (0.0, TWO_PI)


def intersect_arcs(first: Arc, second: Arc) -> Arc | None:
    """Return one arc inside ``first`` that holds the intersection of two arcs, or None.

    Two arcs can meet in two pieces (each covers an end of the other); the
    result is then the single arc of ``first`` that encloses both, an outer bound
    that still lies inside ``first``.

    Parameters
    ----------
    first, second : tuple of float
        Arcs ``(lo, width)``, radians; a width of ``2*pi`` or more is the full circle.

    Returns
    -------
    tuple of float or None
        ``(lo, width)`` with ``lo`` measured in ``first``'s winding, or None when
        the arcs do not meet.

    Examples
    --------
    >>> intersect_arcs((0.0, 1.0), (0.5, 1.0))
    (0.5, 0.5)
    >>> lo, width = intersect_arcs((3.0, 0.5), (-3.0, 0.5))   # across the +-pi seam
    >>> round(lo, 6), round(width, 6)
    (3.283185, 0.216815)
    >>> intersect_arcs((0.0, 1.0), (2.0, 1.0)) is None          # disjoint
    True
    """
    a_lo, a_width = first
    b_lo, b_width = second
    if b_width >= TWO_PI:
        return (a_lo, min(a_width, TWO_PI))
    if a_width >= TWO_PI:
        return (b_lo, b_width)
    # Work in first's coordinate t in [0, a_width]; second covers [d, d + b_width]
    # and, once round the circle, [d - 2*pi, d - 2*pi + b_width].
    d = (b_lo - a_lo) % TWO_PI
    starts: list[float] = []
    stops: list[float] = []
    for shift in (d, d - TWO_PI):
        start = max(0.0, shift)
        stop = min(a_width, shift + b_width)
        if start <= stop:
            starts.append(start)
            stops.append(stop)
    if not starts:
        return None
    start, stop = min(starts), max(stops)
    return (a_lo + start, stop - start)


def nearest_on_polygon(
    vertices: NDArray[np.float64], point: NDArray[np.float64]
) -> tuple[float, NDArray[np.float64]]:
    """Return the distance (m) from a point to a convex polygon and the polygon's nearest point.

    The distance is 0, and the point itself is returned, when it lies in the polygon
    (a point or a segment allowed).

    Parameters
    ----------
    vertices : ndarray, shape (n, 2)
        Convex counter-clockwise polygon, metres, n >= 1.
    point : ndarray, shape (2,)
        The point (x, y), metres.

    Returns
    -------
    distance : float
        Metres, >= 0.
    nearest : ndarray, shape (2,)
        The polygon's point nearest to ``point``.

    Examples
    --------
    >>> square = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]])
    >>> distance, nearest = nearest_on_polygon(square, np.array([5.0, 1.0]))
    >>> distance, nearest.tolist()
    (3.0, [2.0, 1.0])
    >>> nearest_on_polygon(square, np.array([1.0, 1.0]))[0]   # inside: distance 0
    0.0
    """
    relative = point - vertices
    if len(vertices) == 1:
        return math.hypot(relative[0, 0], relative[0, 1]), vertices[0].copy()
    edge = np.empty_like(vertices)
    np.subtract(vertices[1:], vertices[:-1], out=edge[:-1])
    np.subtract(vertices[0], vertices[-1], out=edge[-1])
    if len(vertices) >= 3:
        side = edge[:, 0] * relative[:, 1] - edge[:, 1] * relative[:, 0]
        # Left of (or on) every edge of a counter-clockwise polygon; all zero only on a
        # degenerate polygon's line, which the distance below settles.
        if side.min() >= 0.0 and side.max() > 0.0:
            return 0.0, point.copy()
    squared = np.einsum("ij,ij->i", edge, edge)
    along = np.einsum("ij,ij->i", relative, edge)
    t = np.clip(np.divide(along, squared, out=np.zeros_like(along), where=squared > 0.0), 0.0, 1.0)
    gap = relative - t[:, None] * edge
    distances = np.einsum("ij,ij->i", gap, gap)
    best = int(np.argmin(distances))
    return math.sqrt(float(distances[best])), np.asarray(
        vertices[best] + t[best] * edge[best], dtype=np.float64
    )


def subtended_arc(vertices: NDArray[np.float64], point: NDArray[np.float64], radius: float = 0.0) -> Arc:
    """Return the directions from ``point`` towards the points of a convex polygon widened by a disk.

    Parameters
    ----------
    vertices : ndarray, shape (n, 2)
        Convex counter-clockwise polygon (a point or a segment allowed), metres.
    point : ndarray, shape (2,)
        Where the directions start, metres.
    radius : float
        Radius (m, >= 0) of the disk the polygon is widened by (Minkowski sum).

    Returns
    -------
    tuple of float
        ``(lo, width)`` radians: an outer bound of the directions, the full circle
        when ``point`` lies within ``radius`` of the polygon.

    Examples
    --------
    >>> square = np.array([[1.0, -1.0], [3.0, -1.0], [3.0, 1.0], [1.0, 1.0]])
    >>> lo, width = subtended_arc(square, np.zeros(2))
    >>> round(lo, 6), round(width, 6)
    (-0.785398, 1.570796)
    >>> subtended_arc(square, np.array([2.0, 0.0]))[1] == 2 * np.pi   # from inside: every direction
    True
    """
    distance, _ = nearest_on_polygon(vertices, point)
    if distance <= radius:  # inside, or within the disk's reach
        return FULL_CIRCLE
    relative = vertices - point
    # The polygon does not hold the point, so its directions span less than pi and
    # unwrap without ambiguity around the direction of any one of its vertices.
    # libm's atan2, as the compiled kernels: numpy's own (SIMD) arctan2 may differ by an ulp.
    angles = np.array([math.atan2(y, x) for x, y in relative.tolist()])
    reference = float(angles[0])
    angles = (angles - (reference - math.pi)) % TWO_PI - math.pi
    # Every point within radius of a polygon point p lies within asin(radius/|p|) of
    # p's direction, and |p| >= distance.
    spread = math.asin(radius / distance) if radius > 0.0 else 0.0
    lo = reference + float(angles.min()) - spread
    hi = reference + float(angles.max()) + spread
    return (lo, hi - lo)
