"""Distance from a convex polygon to a segment (shapely, the reference) and whether a point lies in one.

Each with its compiled kernel (``distance.c``).
"""

from __future__ import annotations

import numpy as np
import shapely
from numpy.typing import NDArray

from aura_ums._native import _extension
from aura_ums.geometry import points_in_convex

if _extension.BUILT:
    from aura_ums._native._kernels import point_in_solid_convex as _compiled_point_in_solid_convex
    from aura_ums._native._kernels import polygon_distance as _compiled_polygon_distance

Array = NDArray[np.float64]


def polygon_distance_reference(vertices: Array, ax: float, ay: float, bx: float, by: float) -> float:
    """Return the distance (m) from a convex polygon, edges included, to the segment [a, b].

    The reference, shapely's distance, the specification ``distance.c`` follows:
    ``aura_ums._native.polygon_distance`` is this function, or
    :func:`polygon_distance_compiled` when the kernels run compiled.

    Parameters
    ----------
    vertices : ndarray, shape (n, 2)
        Counter-clockwise convex polygon, metres, finite (a point or a segment allowed).
    ax, ay, bx, by : float
        The segment's ends, metres (a point when they agree).

    Returns
    -------
    float
        Metres; 0 when they meet.

    Examples
    --------
    >>> from aura_ums import _native
    >>> square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> _native.polygon_distance(square, 3.0, 0.5, 3.0, 0.5)
    2.0
    >>> _native.polygon_distance(square, -1.0, 0.5, 2.0, 0.5)   # crossing it
    0.0
    """
    polygon: shapely.Geometry
    if len(vertices) == 1:
        polygon = shapely.Point(vertices[0])
    elif len(vertices) == 2:
        polygon = shapely.LineString(vertices)
    else:
        polygon = shapely.Polygon(vertices)
    segment = shapely.Point(ax, ay) if (ax, ay) == (bx, by) else shapely.LineString([(ax, ay), (bx, by)])
    return float(shapely.distance(polygon, segment))


def polygon_distance_compiled(vertices: Array, ax: float, ay: float, bx: float, by: float) -> float:
    """Compiled :func:`polygon_distance` (needs the extension module: ``_extension.BUILT``)."""
    contiguous = vertices if vertices.flags.c_contiguous else np.ascontiguousarray(vertices, dtype=np.float64)
    return _compiled_polygon_distance(contiguous, ax, ay, bx, by)


def point_in_solid_convex_reference(vertices: Array, x: float, y: float, tolerance: float) -> bool:
    """Tell whether the point (x, y) lies within ``tolerance`` of a convex polygon of positive area.

    The reference is :func:`~aura_ums.geometry.points_in_convex` for one point (its dense
    test, edge by edge, which it takes for one point and up to 4096 vertices):
    ``aura_ums._native.point_in_solid_convex`` is this function, or
    :func:`point_in_solid_convex_compiled` when the kernels run compiled.

    Parameters
    ----------
    vertices : ndarray, shape (n, 2)
        Counter-clockwise convex polygon, metres, finite, 3 <= n <= 4096, of positive area
        (:func:`~aura_ums.geometry.polygon_area`; the caller checks it).
    x, y : float
        The point, metres.
    tolerance : float
        Metres (>= 0) outside the polygon that still count as inside.

    Examples
    --------
    >>> from aura_ums import _native
    >>> square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> inside = _native.point_in_solid_convex
    >>> inside(square, 0.5, 0.5, 0.0), inside(square, 2.0, 0.5, 0.0)
    (True, False)
    >>> inside(square, 1.0 + 1e-10, 0.5, 1e-9)   # just outside, within the tolerance
    True
    """
    return bool(points_in_convex(vertices, np.array([[x, y]]), tolerance)[0])


def point_in_solid_convex_compiled(vertices: Array, x: float, y: float, tolerance: float) -> bool:
    """Compiled :func:`point_in_solid_convex` (needs the extension module: ``_extension.BUILT``)."""
    contiguous = vertices if vertices.flags.c_contiguous else np.ascontiguousarray(vertices, dtype=np.float64)
    return _compiled_point_in_solid_convex(contiguous, x, y, tolerance)
