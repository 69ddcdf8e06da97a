"""The convex polygon value type."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import COORDINATE, Range, finite_float, points_array, read_only, world_points
from aura_ums.errors import InputError
from aura_ums.geometry import _convex

if TYPE_CHECKING:
    from shapely.geometry.base import BaseGeometry

#: Points within this many metres of a polygon count as inside it, so that bounds
#: computed in floating point are not refused by their own rounding.
POSITION_TOLERANCE = 1e-9
#: A disk's radius, metres: up to a world frame's width (``COORDINATE``).
DISK_RADIUS = Range(0.0, 2.0 * COORDINATE.high, "m")


@dataclass(frozen=True, slots=True, eq=False, init=False)
class ConvexPolygon:
    """A convex polygon in the world frame, vertices counter-clockwise, in metres.

    A single vertex is a point and two are a segment: degenerate polygons are
    valid (a robot whose position is known exactly). The vertex array is read-only.

    Parameters
    ----------
    vertices : array_like, shape (n, 2)
        Counter-clockwise vertices (x, y) in metres, n >= 1. A closing vertex equal to
        the first (as GeoJSON rings have) is dropped. Clockwise or non-convex input is
        refused; :meth:`from_points` takes the hull of any points instead.

    Raises
    ------
    InputError
        When the array is not (n, 2), not finite, empty, clockwise or not convex.

    Examples
    --------
    >>> square = ConvexPolygon([(0, 0), (2, 0), (2, 2), (0, 2)])
    >>> square.area, square.contains([(1, 1), (3, 1)]).tolist()
    (4.0, [True, False])
    >>> ConvexPolygon([(1.0, 2.0)]).area   # a point is a valid, zero-area polygon
    0.0
    """

    vertices: NDArray[np.float64]
    # The area, computed on first use: managers, reports and lost detection ask it many
    # times of the same immutable polygon.
    _area: float = field(init=False, repr=False, compare=False)

    def __init__(self, vertices: ArrayLike) -> None:
        vertices = world_points(vertices, "ConvexPolygon.vertices", min_rows=1)
        if len(vertices) >= 2 and np.array_equal(vertices[0], vertices[-1]):
            vertices = vertices[:-1]
        defect = _convex.convexity_defect(vertices)
        if defect is not None:
            raise InputError(
                f"ConvexPolygon.vertices: expected a convex counter-clockwise polygon, got {defect}"
            )
        object.__setattr__(self, "vertices", read_only(_convex.remove_collinear(vertices).copy()))
        object.__setattr__(self, "_area", math.nan)

    @classmethod
    def _trusted(cls, vertices: NDArray[np.float64]) -> ConvexPolygon:
        """Wrap vertices that the library itself computed (already convex, CCW, finite)."""
        # The slots' own setters: the library builds a polygon for every growth and reduction.
        polygon = object.__new__(cls)
        if vertices.flags.writeable:  # a kernel's bytes are read-only already
            vertices.setflags(write=False)
        _set_vertices(polygon, vertices)
        _set_area(polygon, math.nan)
        return polygon

    @classmethod
    def from_points(cls, points: ArrayLike) -> ConvexPolygon:
        """Return the convex hull of any finite points, shape (n, 2), n >= 1.

        Examples
        --------
        >>> ConvexPolygon.from_points([(0, 0), (1, 1), (1, 0), (0, 1), (0.5, 0.5)]).vertex_count
        4
        """
        pts = world_points(points, "points", min_rows=1)
        return cls._trusted(_convex.convex_hull(pts))

    @classmethod
    def point(cls, x: float, y: float) -> ConvexPolygon:
        """Return the degenerate polygon of one point."""
        return cls([(COORDINATE.check(x, "x"), COORDINATE.check(y, "y"))])

    @classmethod
    def disk(cls, center: ArrayLike, radius: float, sides: int = 16) -> ConvexPolygon:
        """Return a regular polygon of ``sides`` vertices containing the disk (outer bound).

        A zero radius gives the point itself.
        """
        c = world_points(center, "center", min_rows=1)[0]
        r = DISK_RADIUS.check(radius, "radius")
        if sides < 3:
            raise InputError(f"sides: expected at least 3, got {sides}")
        return cls._trusted(_convex.outer_disk(c, r, sides))

    @classmethod
    def from_shapely(cls, geometry: BaseGeometry) -> ConvexPolygon:
        """Return the convex hull of a shapely geometry as a ConvexPolygon."""
        import shapely
        from shapely.geometry.base import BaseGeometry

        if not isinstance(geometry, BaseGeometry) or geometry.is_empty:
            raise InputError(f"geometry: expected a non-empty shapely geometry, got {geometry!r}")
        return cls.from_points(shapely.get_coordinates(geometry.convex_hull))

    def to_shapely(self) -> BaseGeometry:
        """Return the polygon as a shapely Polygon, LineString or Point."""
        import shapely

        if self.vertex_count == 1:
            return shapely.Point(self.vertices[0])
        if self.vertex_count == 2:
            return shapely.LineString(self.vertices)
        return shapely.Polygon(self.vertices)

    @property
    def vertex_count(self) -> int:
        """Number of vertices."""
        return len(self.vertices)

    @property
    def area(self) -> float:
        """Area in square metres (0 for a point or a segment)."""
        if math.isnan(self._area):
            object.__setattr__(self, "_area", _convex.polygon_area(self.vertices))
        return self._area

    @property
    def centroid(self) -> NDArray[np.float64]:
        """Area centroid (x, y) in metres; the vertex mean for degenerate polygons."""
        area = self.area
        v = self.vertices
        if area <= 0.0:
            return np.asarray(v.mean(axis=0), dtype=np.float64)
        following = np.roll(v, -1, axis=0)
        weight = _convex.cross2(v, following)
        return np.asarray(((v + following) * weight[:, None]).sum(axis=0) / (6.0 * area), dtype=np.float64)

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """Bounding box ``(x_min, y_min, x_max, y_max)`` in metres."""
        lo = self.vertices.min(axis=0)
        hi = self.vertices.max(axis=0)
        return (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))

    def contains(self, points: ArrayLike, *, tolerance: float = POSITION_TOLERANCE) -> NDArray[np.bool_]:
        """Tell which points ``(n, 2)`` (m) lie in the polygon, boundary and ``tolerance`` included."""
        pts = points_array(points, "points")
        return _convex.points_in_convex(self.vertices, pts, tolerance)

    def distance(self, points: ArrayLike) -> NDArray[np.float64]:
        """Return each point's distance (m) to the polygon: 0 inside, else to the boundary."""
        pts = points_array(points, "points")
        inside = _convex.points_in_convex(self.vertices, pts, 0.0)
        return np.where(inside, 0.0, _convex.distance_to_boundary(self.vertices, pts))

    def translated(self, dx: float, dy: float) -> ConvexPolygon:
        """Return the polygon moved by (dx, dy) metres."""
        return ConvexPolygon._trusted(self.vertices + np.array([dx, dy]))

    def minkowski_sum(self, other: ConvexPolygon) -> ConvexPolygon:
        """Return the Minkowski sum with another convex polygon (exact)."""
        return ConvexPolygon._trusted(_convex.minkowski_sum(self.vertices, other.vertices))

    def clipped(self, normal: ArrayLike, offset: float) -> ConvexPolygon | None:
        """Return the part where ``normal . p <= offset``, or None when it is empty.

        Examples
        --------
        >>> square = ConvexPolygon([(0, 0), (2, 0), (2, 2), (0, 2)])
        >>> square.clipped((0, 1), 0.5).area
        1.0
        >>> square.clipped((0, 1), -0.5) is None    # empty intersection
        True
        """
        n = points_array(normal, "normal", min_rows=1)[0]
        if not np.any(n):
            raise InputError("normal: expected a non-zero vector, got (0, 0)")
        result = _convex.clip_halfplane(self.vertices, n, finite_float(offset, "offset"))
        if len(result) == 0:
            return None
        return ConvexPolygon._trusted(result)

    def intersection(self, other: ConvexPolygon) -> ConvexPolygon | None:
        """Return the intersection with another convex polygon, or None when empty."""
        if other.vertex_count < 3 or other.area <= 0.0:
            shapely_result = self.to_shapely().intersection(other.to_shapely())
            return None if shapely_result.is_empty else ConvexPolygon.from_shapely(shapely_result)
        result = self.vertices
        edge = np.roll(other.vertices, -1, axis=0) - other.vertices
        outward = np.column_stack([edge[:, 1], -edge[:, 0]])
        for normal, vertex in zip(outward, other.vertices, strict=True):
            result = _convex.clip_halfplane(result, normal, float(normal @ vertex))
            if len(result) == 0:
                return None
        return ConvexPolygon._trusted(result)

    def simplified_outer(self, max_vertices: int) -> ConvexPolygon:
        """Return a polygon of at most ``max_vertices`` vertices (>= 3) that contains this one."""
        if max_vertices < 3:
            raise InputError(f"max_vertices: expected at least 3, got {max_vertices}")
        return ConvexPolygon._trusted(_convex.simplify_outer(self.vertices, max_vertices))

    def sample(self, count: int, rng: np.random.Generator) -> NDArray[np.float64]:
        """Return ``count`` points (m) drawn uniformly from the polygon, shape (count, 2).

        Degenerate polygons are sampled along their length (a segment) or at the point.
        """
        v = self.vertices
        if self.vertex_count == 1:
            return np.repeat(v, count, axis=0)
        # Fan triangulation from vertex 0, triangles picked by area. A sliver's triangles can
        # round to a negative area: none is drawn; when none is left, the polygon is a segment.
        a = v[0]
        b = v[1:-1]
        c = v[2:]
        weights = np.maximum(0.5 * _convex.cross2(b - a, c - a), 0.0)
        if self.area <= 0.0 or not weights.sum() > 0.0:
            a, b = v[0], v[np.argmax(np.hypot(*(v - v[0]).T))]
            t = rng.uniform(0.0, 1.0, size=(count, 1))
            return np.asarray(a + t * (b - a), dtype=np.float64)
        pick = rng.choice(len(weights), size=count, p=weights / weights.sum())
        r1 = np.sqrt(rng.uniform(0.0, 1.0, size=count))
        r2 = rng.uniform(0.0, 1.0, size=count)
        return np.asarray(
            (1 - r1)[:, None] * a + (r1 * (1 - r2))[:, None] * b[pick] + (r1 * r2)[:, None] * c[pick],
            dtype=np.float64,
        )

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, ConvexPolygon):
            return NotImplemented
        return bool(np.array_equal(self.vertices, other.vertices))

    def __repr__(self) -> str:
        return f"ConvexPolygon({self.vertex_count} vertices, area={self.area:.6g} m^2)"

    __hash__ = None  # type: ignore[assignment]


# Setters of the slots (frozen: the dataclass's own __setattr__ refuses).
_set_vertices: Callable[[ConvexPolygon, NDArray[np.float64]], None] = ConvexPolygon.__dict__[
    "vertices"
].__set__
_set_area: Callable[[ConvexPolygon, float], None] = ConvexPolygon.__dict__["_area"].__set__


def regular_polygon(
    center: tuple[float, float], radius: float, sides: int, phase: float = 0.0
) -> ConvexPolygon:
    """Return the regular polygon with ``sides`` vertices on a circle of ``radius`` metres.

    Examples
    --------
    >>> round(regular_polygon((0, 0), 1.0, 4).area, 12)
    2.0
    """
    if sides < 3:
        raise InputError(f"sides: expected at least 3, got {sides}")
    angles = phase + np.arange(sides) * (2 * math.pi / sides)
    return ConvexPolygon(
        np.column_stack([center[0] + radius * np.cos(angles), center[1] + radius * np.sin(angles)])
    )
