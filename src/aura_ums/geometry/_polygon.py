"""The convex polygon value type."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import (
    ANGLE,
    COORDINATE,
    Range,
    bounded_count,
    check_rng,
    finite_float,
    nonnegative_float,
    points_array,
    read_only,
    vertex_cap,
    world_points,
)
from aura_ums.errors import InputError
from aura_ums.geometry import _convex

if TYPE_CHECKING:
    from shapely.geometry.base import BaseGeometry

#: Points within this many metres of a polygon count as inside it, so that bounds
#: computed in floating point are not refused by their own rounding.
POSITION_TOLERANCE = 1e-9
#: A disk's radius, metres: up to a world frame's width (``COORDINATE``).
DISK_RADIUS = Range(0.0, 2.0 * COORDINATE.high, "m")
#: A regular polygon's radius, metres: a disk's, but not zero (its vertices would be one).
POLYGON_RADIUS = Range(0.0, DISK_RADIUS.high, "m", low_open=True)
#: Most points :meth:`ConvexPolygon.sample` draws in one call: about 10 s and 0.7 GB (10 million
#: from a square took 10.6 s and 630 MB at the peak); 10**12 asked numpy for 7.28 TiB.
MAX_SAMPLES = 10_000_000


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
        c = _one_point(center, "center")
        r = DISK_RADIUS.check(radius, "radius")
        return cls._trusted(_convex.outer_disk(c, r, _convex.side_count(sides)))

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
        """Tell which points ``(n, 2)`` (m) lie in the polygon or within ``tolerance`` m (>= 0) of it."""
        pts = points_array(points, "points")
        return _convex.points_in_convex(self.vertices, pts, nonnegative_float(tolerance, "tolerance"))

    def distance(self, points: ArrayLike) -> NDArray[np.float64]:
        """Return each point's distance (m) to the polygon: 0 inside, else to the boundary."""
        pts = points_array(points, "points")
        inside = _convex.points_in_convex(self.vertices, pts, 0.0)
        return np.where(inside, 0.0, _convex.distance_to_boundary(self.vertices, pts))

    def translated(self, dx: float, dy: float) -> ConvexPolygon:
        """Return the polygon moved by (dx, dy) metres; its vertices must stay in ``COORDINATE``.

        Examples
        --------
        >>> ConvexPolygon([(0, 0), (1, 0), (0, 1)]).translated(2.0, -1.0).vertices.tolist()
        [[2.0, -1.0], [3.0, -1.0], [2.0, 0.0]]
        >>> ConvexPolygon([(0, 0), (1, 0), (0, 1)]).translated(1e300, 0.0)
        Traceback (most recent call last):
        ...
        aura_ums.errors.InputError: dx: expected a shift keeping the vertices in [-1e+06, 1e+06] m, got 1e+300
        """
        shift = (finite_float(dx, "dx"), finite_float(dy, "dy"))
        moved = self.vertices + np.array(shift)
        for axis, name in enumerate(("dx", "dy")):
            if not np.all(np.abs(moved[:, axis]) <= COORDINATE.high):
                raise InputError(
                    f"{name}: expected a shift keeping the vertices in {COORDINATE.interval()}, "
                    f"got {shift[axis]!r}"
                )
        return ConvexPolygon._trusted(moved)

    def minkowski_sum(self, other: ConvexPolygon) -> ConvexPolygon:
        """Return the Minkowski sum with another convex polygon (exact)."""
        _check_polygon(other)
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
        _check_polygon(other)
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
        cap = vertex_cap(max_vertices)
        return ConvexPolygon._trusted(_convex.simplify_outer(self.vertices, cap))

    def sample(self, count: int, rng: np.random.Generator) -> NDArray[np.float64]:
        """Return ``count`` points (m) drawn uniformly from the polygon, shape (count, 2).

        Degenerate polygons are sampled along their length (a segment) or at the point.
        ``count`` is an integer in [0, 10,000,000] (``MAX_SAMPLES``), ``rng`` a numpy Generator.
        """
        count = bounded_count(
            count, "count", 0, MAX_SAMPLES, "points a call (about 10 s and 0.7 GB while they are drawn)"
        )
        check_rng(rng)
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


def _check_polygon(other: object) -> None:
    """Refuse anything but a ConvexPolygon as the other operand (an AttributeError came from inside)."""
    if not isinstance(other, ConvexPolygon):
        raise InputError(f"other: expected a ConvexPolygon, got {type(other).__name__}")


def _one_point(value: ArrayLike, name: str) -> NDArray[np.float64]:
    """Return one point (x, y) in :data:`COORDINATE`, shape (2,), or raise naming ``name``."""
    points = world_points(value, name, min_rows=1)
    if points.shape != (1, 2):
        raise InputError(f"{name}: expected one point (x, y), got shape {np.shape(value)}")
    return points.reshape(2)


# Setters of the slots (frozen: the dataclass's own __setattr__ refuses).
_set_vertices: Callable[[ConvexPolygon, NDArray[np.float64]], None] = ConvexPolygon.__dict__[
    "vertices"
].__set__
_set_area: Callable[[ConvexPolygon, float], None] = ConvexPolygon.__dict__["_area"].__set__


def regular_polygon(
    center: tuple[float, float], radius: float, sides: int, phase: float = 0.0
) -> ConvexPolygon:
    """Return the regular polygon with ``sides`` vertices on a circle of ``radius`` metres.

    ``center`` is one point (x, y) in metres, ``radius`` > 0, ``sides`` an integer in
    [3, 1,000,000] and ``phase`` the first vertex's direction, radians in [-1000, 1000]
    (``ANGLE``); every vertex must lie in the coordinate range.

    Examples
    --------
    >>> round(regular_polygon((0, 0), 1.0, 4).area, 12)
    2.0
    >>> regular_polygon((0, 0), 1.0, 3.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: sides: expected an integer >= 3, got 3.0
    """
    c = _one_point(center, "center")
    r = POLYGON_RADIUS.check(radius, "radius")
    count = _convex.side_count(sides)
    start = ANGLE.check(phase, "phase")
    angles = start + np.arange(count) * (2 * math.pi / count)
    vertices = np.column_stack([c[0] + r * np.cos(angles), c[1] + r * np.sin(angles)])
    if not np.all(np.abs(vertices) <= COORDINATE.high):
        raise InputError(
            f"radius: expected a circle around center {c.tolist()} inside {COORDINATE.interval()}, got {r!r}"
        )
    try:
        return ConvexPolygon(vertices)
    except InputError as exc:  # vertices that rounding merges: a radius far below the centre's size
        raise InputError(
            f"radius: expected {count} distinct vertices around center {c.tolist()}, got {r!r} ({exc})"
        ) from exc
