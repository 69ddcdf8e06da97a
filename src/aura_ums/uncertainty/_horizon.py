"""Growth from an anchor: the odometry since the last correction, grown once as one move.

Growing move by move sums every move's worst case, while the true errors of consecutive
moves largely cancel: a bound fitted to short moves and summed over many bounds an error
that never happens. Here the map after a correction is the *anchor*; the map at a later
time is the anchor grown once by the *composite* of the moves since then, with bounds
that depend on the composite's path and turning, not on how many moves made it up.

The composite is kept in the frame of the anchor's most probable pose (heading 0 there):
its nominal displacement ``(x, y)`` and heading change, its path ``L`` (the sum of the
runs) and turning ``S`` (the sum of the absolute turns). The nominal motion of each move
is the terrain's mean: the turn times ``1 - rotation_loss`` first, then the run times
``1 - translation_loss`` along the new heading. The composite's bounds, at ``sigmas``
(see :func:`anchor_bounds`), with ``L0 = translation_inertial_loss``:

- heading: the true heading change lies within ``sigmas * rotation_sd * S + drift * (L + L0)``
  of the nominal one;
- position: the true displacement, in the frame of the true start heading, lies within
  ``sigmas * translation_sd * (L + L0) + S * (skitter + sigmas * skitter_sd)`` of the
  nominal one.

These are the paper's statistics read at the scale of one move that lasts from the anchor
to now: ``L0`` is the fixed distance every move accrues errors over, however short. They
hold for a robot whose statistics were calibrated so
(:func:`~aura_ums.logs.calibrate_logs` with ``anchor=True``); they are *not* the sum of
the per-move bounds of :meth:`TerrainStats.sample_motion`'s model, which the per-move
growth of :meth:`SpatialUncertaintyMap.grow` keeps.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from numpy.typing import NDArray

from aura_ums import _native
from aura_ums._native import clamp_into
from aura_ums._validate import SIGMAS, finite_float, nonnegative_float, sequence_of, vertex_cap
from aura_ums.errors import InputError
from aura_ums.geometry import ConvexPolygon, HeadingWedge, convex_hull, intersect_arcs, nearest_on_polygon
from aura_ums.uncertainty._map import SpatialUncertaintyMap
from aura_ums.uncertainty._motion import TurnAndRun
from aura_ums.uncertainty._slices import distributed, packed
from aura_ums.uncertainty._terrain import TerrainStats

_TWO_PI = 2.0 * math.pi
# The largest skitter a TerrainStats holds (m/rad): a position bound beyond it takes more turns.
_MAX_SKITTER = 10.0


@dataclass(frozen=True, slots=True)
class Composite:
    """The moves since an anchor, as one move in the anchor's most probable frame.

    Attributes
    ----------
    x, y : float
        Nominal displacement, metres, in the frame of the anchor's most probable pose
        (x ahead, y to the left).
    heading : float
        Nominal heading change, radians, not wrapped.
    path : float
        Sum of the commanded runs, metres (``L``).
    turning : float
        Sum of the absolute commanded turns, radians (``S``).

    Examples
    --------
    >>> still = Composite()
    >>> still.path, still.is_still
    (0.0, True)
    >>> moved = still.extended([TurnAndRun(math.pi / 2, 1.0)], TerrainStats.zero())
    >>> round(moved.x, 9), round(moved.y, 9), moved.turning, moved.is_still
    (0.0, 1.0, 1.5707963267948966, False)
    >>> Composite(path=-1.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: Composite.path: expected a non-negative number, got -1.0
    """

    x: float = 0.0
    y: float = 0.0
    heading: float = 0.0
    path: float = 0.0
    turning: float = 0.0

    def __post_init__(self) -> None:
        for name in ("x", "y", "heading"):
            object.__setattr__(self, name, finite_float(getattr(self, name), f"Composite.{name}"))
        for name in ("path", "turning"):
            object.__setattr__(self, name, nonnegative_float(getattr(self, name), f"Composite.{name}"))

    @property
    def is_still(self) -> bool:
        """Whether no move turned or ran (the anchor itself is the map)."""
        return self.path == 0.0 and self.turning == 0.0

    def extended(self, commands: Sequence[TurnAndRun], terrain: TerrainStats) -> Composite:
        """Return the composite followed by ``commands`` (each: turn, then run) on ``terrain``.

        Each command moves nominally by the terrain's mean: the turn times
        ``1 - rotation_loss``, the run times ``1 - translation_loss``.
        """
        if not commands:
            return self
        turns = np.array([c.turn for c in commands], dtype=np.float64)
        runs = np.array([c.run for c in commands], dtype=np.float64)
        headings = self.heading + np.cumsum(turns * (1.0 - terrain.rotation_loss))
        ahead = runs * (1.0 - terrain.translation_loss)
        return Composite._trusted(
            self.x + float(np.sum(ahead * np.cos(headings))),
            self.y + float(np.sum(ahead * np.sin(headings))),
            float(headings[-1]),
            self.path + float(runs.sum()),
            self.turning + float(np.abs(turns).sum()),
        )

    @classmethod
    def _trusted(cls, x: float, y: float, heading: float, path: float, turning: float) -> Composite:
        """Return the composite of checked moves, without the checks (extended once a step in replays)."""
        composite = object.__new__(cls)
        for name, value in (("x", x), ("y", y), ("heading", heading), ("path", path), ("turning", turning)):
            object.__setattr__(composite, name, value)
        return composite


def anchor_bounds(terrain: TerrainStats, composite: Composite, sigmas: float) -> tuple[float, float]:
    """Return the composite's heading bound (radians) and position bound (metres) on ``terrain``.

    Examples
    --------
    >>> stats = TerrainStats(0.0, 0.5, 0.02, 0.1, 0.0, 0.01, 0.0, 0.0)
    >>> heading, position = anchor_bounds(stats, Composite(path=1.5, turning=1.0), 3.0)
    >>> round(heading, 6), round(position, 6)             # 0.03 + 0.1 * 2.0; 0.06 * 2.0
    (0.23, 0.12)
    >>> anchor_bounds(stats, Composite(), 3.0)            # no move: no growth, however large L0
    (0.0, 0.0)
    """
    _check_anchor_arguments(terrain, composite)
    return _anchor_bounds(terrain, composite, SIGMAS.check(sigmas, "sigmas"))


def _anchor_bounds(terrain: TerrainStats, composite: Composite, sigmas: float) -> tuple[float, float]:
    """:func:`anchor_bounds` of checked arguments (:func:`grow_from_anchor` checked them)."""
    if composite.is_still:
        return 0.0, 0.0
    reach = composite.path + terrain.translation_inertial_loss
    heading = sigmas * terrain.rotation_sd * composite.turning + terrain.drift * reach
    position = sigmas * terrain.translation_sd * reach + composite.turning * (
        terrain.skitter + sigmas * terrain.skitter_sd
    )
    return heading, position


def _check_anchor_arguments(terrain: object, composite: object) -> None:
    if not isinstance(terrain, TerrainStats):
        raise InputError(f"terrain: expected TerrainStats, got {type(terrain).__name__}")
    if not isinstance(composite, Composite):
        raise InputError(f"composite: expected a Composite, got {type(composite).__name__}")


def grow_from_anchor(
    anchor: SpatialUncertaintyMap,
    composite: Composite,
    terrain: TerrainStats,
    sigmas: float,
    max_vertices: int,
) -> SpatialUncertaintyMap:
    """Return the anchor grown once by the composite, within :func:`anchor_bounds`.

    Every pose ``(p, theta)`` of the anchor goes to ``p + R(theta) (d + e)`` with heading
    ``theta + phi + eta`` for every ``|e| <= position bound`` and ``|eta| <= heading bound``,
    where ``d`` and ``phi`` are the composite's nominal displacement and heading change.
    Through the map's own growth (so a sliced map grows slice by slice): an exact turn to
    the chord and run along it, then a turn on the spot whose band is the heading bound
    and whose skitter disk is the position bound. That turn is the remaining heading change
    plus one whole turn, which changes no heading but lets a band that never exceeds the
    command (the model's turns never overshoot) reach both sides of the nominal heading.

    Parameters
    ----------
    anchor : SpatialUncertaintyMap
        The map at the anchor's time (product or sliced).
    composite : Composite
        The moves since then.
    terrain : TerrainStats
        The statistics at the anchor's scale.
    sigmas : float
        Standard deviations bounded, > 0.
    max_vertices : int
        Cap on the polygon's vertex count, >= 3.

    Examples
    --------
    >>> from aura_ums.geometry import Pose
    >>> start = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.0, 0.0)
    >>> stats = TerrainStats(0.0, 0.0, 0.01, 0.05, 0.0, 0.0, 0.0, 0.0)
    >>> moved = Composite().extended([TurnAndRun(0.0, 2.0)], stats)
    >>> grown = grow_from_anchor(start, moved, stats, 3.0, 64)
    >>> grown.contains(Pose(2.05, 0.0, 0.09)), grown.contains(Pose(2.0, 0.0, 0.2))
    (True, False)
    >>> grow_from_anchor(start, Composite(), stats, 3.0, 64) is start   # no move
    True
    """
    _check_anchor_arguments(terrain, composite)
    if not isinstance(anchor, SpatialUncertaintyMap):
        raise InputError(f"anchor: expected a SpatialUncertaintyMap, got {type(anchor).__name__}")
    sigmas = SIGMAS.check(sigmas, "sigmas")
    max_vertices = vertex_cap(max_vertices)
    if composite.is_still:
        return anchor
    heading_bound, position_bound = _anchor_bounds(terrain, composite, sigmas)
    chord = math.hypot(composite.x, composite.y)
    direction = math.atan2(composite.y, composite.x) if chord > 0.0 else 0.0
    # Internal commands: kilometre-scale composites exceed the public TurnAndRun's ranges.
    grown = anchor._grow_many(
        (TurnAndRun._trusted(direction, chord),), TerrainStats.zero(), sigmas, max_vertices
    )
    if heading_bound >= math.pi:
        # Every heading: a full turn's band, which the wedge takes as the full circle.
        heading_bound = math.pi
    rest = math.remainder(composite.heading - direction, _TWO_PI)
    spin = rest + _TWO_PI + heading_bound
    # More turns until the skitter's spread, position_bound / spin / sigmas, is within its
    # range: counted, not looped (a 10 km bound takes a thousand).
    limit = _MAX_SKITTER * min(1.0, sigmas)
    if position_bound > limit * spin:
        spin += _TWO_PI * math.ceil((position_bound / limit - spin) / _TWO_PI)
    while position_bound > limit * spin:  # rounding: a turn more at most
        spin += _TWO_PI
    if heading_bound == 0.0 and position_bound == 0.0:
        if rest == 0.0:
            return grown
        return grown._grow_many((TurnAndRun._trusted(rest, 0.0),), TerrainStats.zero(), sigmas, max_vertices)
    # The actual turn is spin * clip(1 - loss + sd z, 0, 1): mean spin - heading_bound, and
    # with |z| <= sigmas every value from spin - 2 heading_bound to spin.
    band = heading_bound / spin
    spot = TerrainStats(0.0, 0.0, 0.0, 0.0, band, band / sigmas, 0.0, position_bound / spin / sigmas)
    return grown._grow_many((TurnAndRun._trusted(spin, 0.0),), spot, sigmas, max_vertices)


def intersect_maps(
    first: SpatialUncertaintyMap, others: Sequence[SpatialUncertaintyMap], max_vertices: int
) -> SpatialUncertaintyMap:
    """Return an outer bound of the poses that lie in ``first`` and in every one of ``others``.

    Each map holding the truth, so does the result: this is how the manager combines the
    anchors it keeps (each grown to now). A sliced ``first`` intersects slice by slice on its
    grid (the others' slices, or their summary for a product map); a product ``first``
    intersects polygons and wedges (the others' summaries). The most probable pose is
    ``first``'s, moved into the result when it falls outside. When rounding leaves nothing,
    ``first`` is returned: it holds the truth by itself.

    Parameters
    ----------
    first : SpatialUncertaintyMap
        The map whose form, grid and most probable pose the result keeps.
    others : sequence of SpatialUncertaintyMap
        Maps of the same instant.
    max_vertices : int
        Cap on the polygons' vertex count, >= 3.

    Examples
    --------
    >>> from aura_ums.geometry import Pose
    >>> a = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 1.0, 0.5)
    >>> b = SpatialUncertaintyMap.from_pose(Pose(1.0, 0.0, 0.4), 1.0, 0.5)
    >>> both = intersect_maps(a, [b], 64)
    >>> both.area < a.area, round(both.wedge.width, 6), both.contains(Pose(0.5, 0.0, 0.2))
    (True, 0.6, True)
    >>> far = SpatialUncertaintyMap.from_pose(Pose(9.0, 0.0, 0.0), 1.0, 0.5)
    >>> intersect_maps(a, [far], 64) is a          # nothing in common: the first map
    True
    """
    if not isinstance(first, SpatialUncertaintyMap):
        raise InputError(f"first: expected a SpatialUncertaintyMap, got {type(first).__name__}")
    others = sequence_of(others, SpatialUncertaintyMap, "others")
    max_vertices = vertex_cap(max_vertices)
    result = first
    for other in others:
        if other is result:
            continue
        met = (
            _intersect_sliced(result, other, max_vertices)
            if result.is_sliced
            else _intersect_product(result, other)
        )
        if met is None:
            return first
        result = met
    return result


def _geometries(polygons: Sequence[NDArray[np.float64]]) -> NDArray[np.object_]:
    """Shapely geometries of counter-clockwise convex polygons (a point or a segment allowed)."""
    return np.array(
        [
            shapely.polygons(v) if len(v) >= 3 else shapely.convex_hull(shapely.multipoints(v))
            for v in polygons
        ],
        dtype=object,
    )


def _intersections(
    first: Sequence[NDArray[np.float64]], second: Sequence[NDArray[np.float64]]
) -> list[NDArray[np.float64] | None]:
    """Return the intersection of each pair of convex polygons (counter-clockwise), None when empty.

    One vectorized GEOS call for every pair: a Python clip per edge costs a hundred times more.
    """
    met = shapely.intersection(_geometries(first), _geometries(second))
    result: list[NDArray[np.float64] | None] = []
    rings: list[NDArray[np.float64]] = []
    at: list[int] = []
    for geometry in met.tolist():
        if geometry.is_empty:
            result.append(None)
        elif geometry.geom_type != "Polygon":
            result.append(convex_hull(shapely.get_coordinates(geometry)))
        else:
            at.append(len(result))
            result.append(None)
            rings.append(shapely.get_coordinates(geometry)[:-1])
    if rings:
        # GEOS may keep two vertices a rounding error apart, an edge whose direction is
        # noise: a containment test by edge lines would then cut off points far inside
        # (anchors lost a truth 2 cm inside both maps). The hull kernel (no cap) merges
        # them and orders the ring counter-clockwise, all rings in one call.
        widest = max(3, max(len(ring) for ring in rings))
        hulls = _native.merge_groups(np.concatenate(rings), [len(ring) for ring in rings], widest)
        for index, hull in zip(at, hulls, strict=True):
            result[index] = hull
    return result


def _intersect_product(
    first: SpatialUncertaintyMap, other: SpatialUncertaintyMap
) -> SpatialUncertaintyMap | None:
    common = _intersections([first.polygon.vertices], [other.polygon.vertices])[0]
    if common is None:
        return None
    polygon = ConvexPolygon._trusted(common)
    mine, theirs = first.wedge, other.wedge
    arc = intersect_arcs((mine.center - mine.cw, mine.width), (theirs.center - theirs.cw, theirs.width))
    if arc is None:
        return None
    lo, width = arc
    if width >= _TWO_PI:
        wedge = HeadingWedge._trusted(mine.center, math.pi, math.pi)
    else:
        heading = clamp_into(mine.center, lo, lo + width)
        wedge = HeadingWedge._trusted(heading, heading - lo, lo + width - heading)
    return SpatialUncertaintyMap._trusted(polygon, _inside(polygon.vertices, first.center), wedge)


def _intersect_sliced(
    first: SpatialUncertaintyMap, other: SpatialUncertaintyMap, max_vertices: int
) -> SpatialUncertaintyMap | None:
    mine = first._slices
    assert mine is not None  # only called for a sliced map
    theirs = [(s.lo, s.width, s.polygon.vertices) for s in other.slices]
    arcs: list[tuple[float, float]] = []
    left: list[NDArray[np.float64]] = []
    right: list[NDArray[np.float64]] = []
    for piece_lo, piece_hi, vertices_mine in zip(
        mine.lo.tolist(), mine.hi.tolist(), mine.polygons(), strict=True
    ):
        for lo, width, vertices in theirs:
            arc = intersect_arcs((piece_lo, piece_hi - piece_lo), (lo, width))
            if arc is not None:
                arcs.append(arc)
                left.append(vertices_mine)
                right.append(vertices)
    if not arcs:
        return None
    kept = [
        (lo, width, common)
        for (lo, width), common in zip(arcs, _intersections(left, right), strict=True)
        if common is not None
    ]
    if not kept:
        return None
    cells, cap = first._cells, first._max_slices
    points, counts, starts, stops, sources = packed(
        [common for _, _, common in kept], [lo for lo, _, _ in kept], [lo + width for lo, width, _ in kept]
    )
    heading = first.wedge.center
    grid, wedge = distributed(points, counts, starts, stops, sources, cells, max_vertices, cap, heading)
    near = min(grid.polygons(), key=lambda vertices: _distance(vertices, first.center))
    center = _inside(near, first.center)
    return SpatialUncertaintyMap._sliced(grid, center, wedge, cells, cap)


def _distance(vertices: NDArray[np.float64], point: NDArray[np.float64]) -> float:
    return nearest_on_polygon(vertices, point)[0]


def _inside(vertices: NDArray[np.float64], point: NDArray[np.float64]) -> NDArray[np.float64]:
    """``point`` when it lies in the polygon, else the polygon's nearest point (a new array)."""
    distance, nearest = nearest_on_polygon(vertices, point)
    return point if distance == 0.0 else np.array(nearest, dtype=np.float64)
