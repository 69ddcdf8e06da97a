"""The three landmark reductions: set-membership intersections on plain arrays and arcs.

Every function here keeps every pose of the prior map that is consistent with an
observation within its stated bounds: where an exact set is not convex or not a
polygon, an outer bound is taken. Bounds are pushed outward by ``TOLERANCE`` so
that poses exactly on a bound survive floating-point rounding.

The sensor sits at ``p + R(h) o`` for a robot at ``p`` with heading ``h`` and a
sensor offset ``o = (forward, left)``. With ``o != 0`` the Class I and II
reductions first bound the sensor positions, constrain them, and map them back
to robot positions through the arc ``R(W) o`` (replaced by an outer polygon).

When the C extension ``aura_ums.geometry._kernels`` was built, :func:`reduce_map` runs
each reduction's geometry in one compiled call that mirrors these functions operation
for operation; the numpy functions here stay the reference and the fallback.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, cast

import numpy as np
from numpy.typing import NDArray

from aura_ums.errors import InputError
from aura_ums.geometry import (
    HeadingWedge,
    clip_halfplane,
    convex_hull,
    minkowski_sum,
    outer_arc,
    outer_disk,
)
from aura_ums.geometry._angles import TWO_PI
from aura_ums.geometry._arcs import Arc, intersect_arcs, nearest_on_polygon, subtended_arc
from aura_ums.geometry._convex import cross2, points_in_convex
from aura_ums.uncertainty._landmarks import (
    BearingObservation,
    GroundLineLandmark,
    GroundLineObservation,
    Landmark,
    Observation,
    PointLandmark,
    RangeBearingObservation,
    VerticalLineLandmark,
)

if TYPE_CHECKING:
    from aura_ums.uncertainty._map import SpatialUncertaintyMap

Array = NDArray[np.float64]

#: What a compiled reduction returns: (vertex bytes, arc lo, arc width, centre x, centre y,
#: area before, area after), or the index in ``_REASONS`` of why it is empty.
_KernelResult = tuple[bytes, float, float, float, float, float, float] | int
_Kernel = Callable[..., _KernelResult]

_compiled_reduce_cone: _Kernel | None
_compiled_reduce_strip: _Kernel | None
try:  # the compiled kernels, when the build had a C compiler
    from aura_ums.geometry._kernels import reduce_cone as _compiled_reduce_cone
    from aura_ums.geometry._kernels import reduce_strip as _compiled_reduce_strip
except ImportError:  # pragma: no cover - exercised on machines without a compiler
    _compiled_reduce_cone = _compiled_reduce_strip = None


def compiled_kernels() -> tuple[_Kernel, _Kernel] | None:
    """Return the compiled (cone, strip) reduction kernels, or None when the extension was not built."""
    if _compiled_reduce_cone is None or _compiled_reduce_strip is None:
        return None
    return (_compiled_reduce_cone, _compiled_reduce_strip)


#: Outward margin (m for positions, rad for angles) added to every bound of a reduction.
TOLERANCE = 1e-9

# Widest sub-cone used for Class I: a cone of pi or more is not convex, and the
# u-widening of a sub-cone is loosest near pi.
_CONE_PIECE = 0.75 * math.pi
# Widest annular sub-sector used for Class II, and the spacing of the tangents that
# bound its outer arc (the polygon lies <= 1/cos(pi/16) - 1 ~ 2 % outside it).
_SECTOR_PIECE = math.pi / 4
_TANGENT_STEP = math.pi / 8
_SENSOR_ARC_SIDES = 16


@dataclass(frozen=True, slots=True)
class Reduction:
    """The outcome of reducing a map by one landmark observation.

    Attributes
    ----------
    map : SpatialUncertaintyMap
        The reduced map, or the prior map itself when the observation is inconsistent.
    consistent : bool
        False when no pose of the prior map agrees with the observation (an empty
        intersection): a misidentified landmark or an invalid map. The manager decides.
    area_before, area_after : float
        Area of the position polygon before and after, square metres.
    wedge_before, wedge_after : HeadingWedge
        Heading wedge before and after.
    reason : str
        Why the observation is inconsistent; ``""`` when it is consistent.

    Examples
    --------
    >>> import math
    >>> from aura_ums.uncertainty import GroundLineLandmark, GroundLineObservation, Pose
    >>> from aura_ums.uncertainty import SpatialUncertaintyMap
    >>> prior = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 1.0, 0.2)
    >>> edge = GroundLineLandmark("path_edge", (-10, -1), (10, -1))
    >>> seen = prior.reduce(GroundLineObservation("path_edge", 0.0, 1.0, 0.1, 0.0, 0.05), edge)
    >>> seen.consistent, round(seen.wedge_after.width, 3), seen.area_ratio < 0.3
    (True, 0.1, True)
    >>> prior.reduce(GroundLineObservation("path_edge", 0.0, 5.0, 0.1, 0.0, 0.05), edge).reason
    'no position of the map is at the observed offset from the line'
    """

    map: SpatialUncertaintyMap
    consistent: bool
    area_before: float
    area_after: float
    wedge_before: HeadingWedge
    wedge_after: HeadingWedge
    reason: str = ""

    @property
    def area_ratio(self) -> float:
        """``area_after / area_before`` (1 for a zero-area prior)."""
        return self.area_after / self.area_before if self.area_before > 0.0 else 1.0


# --- arcs and wedges ----------------------------------------------------------------


def wedge_arc(wedge: HeadingWedge) -> Arc:
    """Return a wedge as the arc ``(lo, width)`` of its headings."""
    return (wedge.center - wedge.cw, wedge.width)


def widen_arc(arc: Arc, margin: float) -> Arc:
    """Return the arc with ``margin`` radians added on both sides."""
    return (arc[0] - margin, arc[1] + 2.0 * margin)


def arc_wedge(arc: Arc, center: float) -> HeadingWedge:
    """Return the wedge of an arc, centred on ``center`` if inside it, else on its nearer end."""
    lo, width = arc
    if width >= TWO_PI:
        return HeadingWedge.full_circle(center)
    offset = (center - lo) % TWO_PI
    if offset > width:
        # Outside: clamp to whichever end is the shorter way round.
        offset = width if offset - width < TWO_PI - offset else 0.0
    # 0 <= offset <= width, both finite: the checks of HeadingWedge() would all pass.
    return HeadingWedge._trusted(lo + offset, offset, width - offset)


def cos_range(arc: Arc) -> tuple[float, float]:
    """Return (min, max) of ``cos`` over an arc of angles."""
    lo, width = arc
    if width >= TWO_PI:
        return (-1.0, 1.0)
    ends = (math.cos(lo), math.cos(lo + width))
    upper = 1.0 if (-lo) % TWO_PI <= width else max(ends)
    lower = -1.0 if (math.pi - lo) % TWO_PI <= width else min(ends)
    return (lower, upper)


# --- polygons -----------------------------------------------------------------------


def clip_halfplanes(vertices: Array, normals: Array, offsets: Array) -> Array:
    """Return the part of a convex polygon where ``normals[i] . p <= offsets[i]`` for all i.

    Half-planes that hold the whole polygon are skipped (they hold every part of it
    too), so the cost is one matrix product plus the clips that cut.
    Returns an empty ``(0, 2)`` array when nothing is left.
    """
    signed = vertices @ normals.T - offsets
    if (signed.min(axis=0) > 0.0).any():
        return np.empty((0, 2))
    for j in np.flatnonzero(signed.max(axis=0) > 0.0).tolist():
        vertices = clip_halfplane(vertices, normals[j], float(offsets[j]))
        if len(vertices) == 0:
            break
    return vertices


def clip_convex(vertices: Array, other: Array, margin: float = TOLERANCE) -> Array:
    """Return a convex polygon clipped by another one widened by ``margin`` metres (an outer bound).

    Empty ``(0, 2)`` when they do not meet. Edges of ``other`` too short to have a
    reliable direction are not used: leaving out a half-plane only loosens the bound,
    while one with a rounding-noise normal could cut into the true intersection.
    """
    edge = np.roll(other, -1, axis=0) - other
    length = np.hypot(edge[:, 0], edge[:, 1])
    keep = length > 1e-9 * max(1.0, float(np.abs(other).max()))
    outward = np.column_stack([edge[keep, 1], -edge[keep, 0]]) / length[keep, None]
    return clip_halfplanes(vertices, outward, np.einsum("ij,ij->i", outward, other[keep]) + margin)


def sector_halfplanes(
    apex: Array, lo: float, width: float, widen: float, r_min: float, r_max: float
) -> tuple[Array, Array]:
    """Return half-planes whose intersection holds an annular sector widened by a disk.

    The sector holds ``apex + t (cos phi, sin phi)`` for ``r_min <= t <= r_max`` and
    ``phi`` from ``lo`` to ``lo + width`` (``0 <= width < pi``); ``r_max = inf`` is a
    cone. Its Minkowski sum with the disk of radius ``widen`` lies in every half-plane
    ``normals[i] . p <= offsets[i]``: the two sides, the chord behind the inner arc and
    tangents of the outer arc, each moved out by ``widen + TOLERANCE``.
    """
    hi = lo + width
    middle = lo + width / 2.0
    normals = [
        (math.sin(lo), -math.cos(lo)),
        (-math.sin(hi), math.cos(hi)),
        (-math.cos(middle), -math.sin(middle)),
    ]
    reach = [0.0, 0.0, -r_min * math.cos(width / 2.0)]
    if math.isfinite(r_max):
        count = max(1, math.ceil(width / _TANGENT_STEP))
        for angle in np.linspace(lo, hi, count + 1).tolist():
            normals.append((math.cos(angle), math.sin(angle)))
            reach.append(r_max)
    normal_array = np.asarray(normals, dtype=np.float64)
    offsets = normal_array @ apex + np.asarray(reach) + (widen + TOLERANCE)
    return normal_array, offsets


def clip_to_sector(
    vertices: Array, apex: Array, arc: Arc, widen: float, r_min: float, r_max: float, piece: float
) -> Array:
    """Return an outer convex bound of a polygon intersected with a widened (annular) sector.

    The sector may be wider than pi (then it is not convex): it is cut into pieces of
    at most ``piece`` radians, the polygon is clipped by each, and the convex hull of
    the parts is returned. Empty ``(0, 2)`` when no part is left.
    """
    lo, width = arc
    count = max(1, math.ceil(min(width, TWO_PI) / piece))
    step = min(width, TWO_PI) / count
    parts = []
    for k in range(count):
        normals, offsets = sector_halfplanes(apex, lo + k * step, step, widen, r_min, r_max)
        part = clip_halfplanes(vertices, normals, offsets)
        if len(part):
            parts.append(part)
    if not parts:
        return np.empty((0, 2))
    if len(parts) == 1:
        return parts[0]
    return convex_hull(np.vstack(parts))


def sensor_arc(sensor_offset: tuple[float, float], headings: Arc) -> Array | None:
    """Return an outer convex polygon of the sensor's displacements ``R(h) o`` over an arc of headings.

    None when the sensor sits at the robot's reference point.
    """
    forward, left = sensor_offset
    radius = math.hypot(forward, left)
    if radius == 0.0:
        return None
    lo, width = headings
    lo += math.atan2(left, forward)
    if width >= TWO_PI:
        return outer_disk(np.zeros(2), radius, _SENSOR_ARC_SIDES)
    if width <= 0.0:
        return np.array([[radius * math.cos(lo), radius * math.sin(lo)]])
    return convex_hull(outer_arc(radius, lo, lo + width))


def cap_inside(vertices: Array, prior: Array, max_vertices: int) -> Array:
    """Return an outer polygon of at most ``max_vertices`` vertices that stays inside ``prior``.

    Removes one edge at a time, extending its neighbours until they meet, choosing the
    cheapest removal whose new vertex lies inside ``prior``. A clip that cut off one
    prior vertex can always be undone this way, so the result has at most
    ``max(max_vertices, len(prior))`` vertices.
    """
    while len(vertices) > max(max_vertices, 3):
        edge = np.roll(vertices, -1, axis=0) - vertices
        preceding = np.roll(edge, 1, axis=0)
        following = np.roll(edge, -1, axis=0)
        denominator = cross2(preceding, following)
        removable = denominator > 1e-12 * np.hypot(*preceding.T) * np.hypot(*following.T)
        with np.errstate(invalid="ignore", divide="ignore"):
            t = np.where(removable, cross2(edge, following) / denominator, 0.0)
        corner = vertices + t[:, None] * preceding
        removable &= points_in_convex(prior, corner, TOLERANCE)
        if not np.any(removable):
            break
        cost = np.where(removable, 0.5 * t * cross2(preceding, edge), np.inf)
        chosen = int(np.argmin(cost))
        result = vertices.copy()
        result[chosen] = corner[chosen]
        vertices = np.delete(result, (chosen + 1) % len(vertices), axis=0)
    return vertices


# --- the three classes --------------------------------------------------------------

#: A reduction's outcome before it becomes a map: new polygon and heading arc, or why not.
Outcome = tuple[Array, Arc] | str


def _sensor_constrained(
    polygon: Array, headings: Arc, sensor_offset: tuple[float, float], constrain: Callable[[Array], Array]
) -> tuple[Array, Array] | str:
    """Apply a constraint on sensor positions; return (robot positions, sensor positions) or why empty."""
    arc = sensor_arc(sensor_offset, headings)
    if arc is None:
        sensors = constrain(polygon)
        if len(sensors) == 0:
            return "no position of the map is consistent with the observation"
        return sensors, sensors
    sensors = constrain(minkowski_sum(polygon, arc))
    if len(sensors) == 0:
        return "no sensor position of the map is consistent with the observation"
    # A robot position is possible when some heading puts its sensor in the region:
    # p = s - R(h) o, an outer bound of which is the region summed with the mirrored arc.
    positions = clip_convex(polygon, minkowski_sum(sensors, -arc))
    if len(positions) == 0:
        return "no position of the map is consistent with the observation"
    # Sensors must also be reachable from the remaining positions.
    narrowed = clip_convex(sensors, minkowski_sum(positions, arc))
    return positions, narrowed if len(narrowed) else sensors


def _bearing_headings(sensors: Array, landmark: Array, widen: float, bearing: float, error: float) -> Arc:
    """Return the headings from which some sensor position sees the landmark at the bearing."""
    lo, width = subtended_arc(sensors, landmark, widen)
    if width >= TWO_PI:
        return (lo, TWO_PI)
    # Directions from the sensors towards the landmark are those from it, turned by pi.
    return widen_arc((lo + math.pi - bearing, width), error + TOLERANCE)


def _cone_reduction(
    polygon: Array,
    wedge: HeadingWedge,
    sensor_offset: tuple[float, float],
    landmark: Array,
    widen: float,
    bearing: float,
    error: float,
    r_min: float,
    r_max: float,
    piece: float,
) -> Outcome:
    """Class I (``r_max = inf``) and Class II: the bearing cone, then the headings."""
    headings = wedge_arc(wedge)
    # The landmark is seen towards h + bearing, so the sensor lies from the landmark
    # towards h + bearing + pi, for some heading h of the wedge and bearing error.
    cone = widen_arc((headings[0] + bearing + math.pi, headings[1]), error + TOLERANCE)

    def constrain(vertices: Array) -> Array:
        if cone[1] >= TWO_PI and not math.isfinite(r_max):
            return vertices  # seen from every direction: no constraint on position
        return clip_to_sector(vertices, landmark, cone, widen, r_min, r_max, piece)

    found = _sensor_constrained(polygon, headings, sensor_offset, constrain)
    if isinstance(found, str):
        return found
    positions, sensors = found
    narrowed = intersect_arcs(headings, _bearing_headings(sensors, landmark, widen, bearing, error))
    if narrowed is None:
        return "no heading of the map is consistent with the observed bearing"
    return positions, narrowed


def reduce_bearing(
    polygon: Array, wedge: HeadingWedge, observation: BearingObservation, landmark: VerticalLineLandmark
) -> Outcome:
    """Class I: intersect a map with the cone of a bearing to a vertical line.

    Parameters
    ----------
    polygon : ndarray, shape (n, 2)
        Prior polygon, counter-clockwise, metres.
    wedge : HeadingWedge
        Prior headings.
    observation : BearingObservation
        The bearing and its error bound.
    landmark : VerticalLineLandmark
        The landmark seen.

    Returns
    -------
    tuple or str
        ``(vertices, (lo, width))`` of the reduced polygon and headings (inside the prior),
        or the reason the intersection is empty.
    """
    return _cone_reduction(
        polygon,
        wedge,
        observation.sensor_offset,
        landmark.position,
        landmark.position_uncertainty,
        observation.bearing,
        observation.bearing_error,
        0.0,
        math.inf,
        _CONE_PIECE,
    )


def reduce_range_bearing(
    polygon: Array, wedge: HeadingWedge, observation: RangeBearingObservation, landmark: PointLandmark
) -> Outcome:
    """Class II: intersect a map with the cone of a bearing and the annulus of a range.

    See :func:`reduce_bearing` for parameters and result.
    """
    return _cone_reduction(
        polygon,
        wedge,
        observation.sensor_offset,
        landmark.position,
        landmark.position_uncertainty,
        observation.bearing,
        observation.bearing_error,
        observation.range_min,
        observation.range_max,
        _SECTOR_PIECE,
    )


def reduce_ground_line(
    polygon: Array, wedge: HeadingWedge, observation: GroundLineObservation, landmark: GroundLineLandmark
) -> Outcome:
    """Class III: intersect a map with the headings of a line's angle and the strip of its offset.

    The true line is taken to lie parallel to the mapped one, within
    ``position_uncertainty`` of it. See :func:`reduce_bearing` for parameters and result.
    """
    direction = landmark.direction
    # angle = direction - heading, so the heading is direction - angle.
    observed = widen_arc((direction - observation.angle, 0.0), observation.angle_error + TOLERANCE)
    headings = intersect_arcs(wedge_arc(wedge), observed)
    if headings is None:
        return "no heading of the map is consistent with the observed line angle"
    normal = np.array([-math.sin(direction), math.cos(direction)])
    base = float(normal @ landmark.start)
    margin = observation.offset_error + landmark.position_uncertainty
    lo = base + observation.offset - margin
    hi = base + observation.offset + margin
    forward, left = observation.sensor_offset
    radius = math.hypot(forward, left)
    if radius > 0.0:
        # normal . R(h) o = |o| cos(h + atan2(left, forward) - direction - pi/2).
        shift = math.atan2(left, forward) - direction - math.pi / 2.0
        lowest, highest = cos_range((headings[0] + shift, headings[1]))
        lo -= radius * highest
        hi -= radius * lowest
    normals = np.vstack([normal, -normal])
    offsets = np.array([hi + TOLERANCE, -lo + TOLERANCE])
    positions = clip_halfplanes(polygon, normals, offsets)
    if len(positions) == 0:
        return "no position of the map is at the observed offset from the line"
    return positions, headings


# --- the map-level entry point ------------------------------------------------------

_PAIRS: dict[type, type] = {
    BearingObservation: VerticalLineLandmark,
    RangeBearingObservation: PointLandmark,
    GroundLineObservation: GroundLineLandmark,
}


def check_pair(observation: object, landmark: object) -> None:
    """Raise :class:`InputError` unless the observation and landmark are of one class and id."""
    expected = _PAIRS.get(type(observation))
    if expected is None:
        names = ", ".join(kind.__name__ for kind in _PAIRS)
        raise InputError(f"observation: expected one of {names}, got {type(observation).__name__}")
    if not isinstance(landmark, expected):
        raise InputError(
            f"landmark: expected a {expected.__name__} for a {type(observation).__name__}, "
            f"got {type(landmark).__name__}"
        )
    observed_id = cast(Observation, observation).landmark_id
    landmark_id = cast(Landmark, landmark).id
    if landmark_id != observed_id:
        raise InputError(f"landmark.id: expected {observed_id!r} (the observation's), got {landmark_id!r}")


#: Why a compiled reduction is empty, by the code the kernel returns.
_REASONS = (
    "no position of the map is consistent with the observation",
    "no sensor position of the map is consistent with the observation",
    "no heading of the map is consistent with the observed bearing",
    "no heading of the map is consistent with the observed line angle",
    "no position of the map is at the observed offset from the line",
)


#: A reduction without its record: (reduced map, area before, area after), or why it is empty.
Reduced = tuple["SpatialUncertaintyMap", float, float] | str


def reduce_map(
    prior: SpatialUncertaintyMap, observation: Observation, landmark: Landmark, max_vertices: int
) -> Reduction:
    """Reduce a map by one observation of a landmark; see :meth:`SpatialUncertaintyMap.reduce`."""
    check_pair(observation, landmark)
    if max_vertices < 3:
        raise InputError(f"max_vertices: expected at least 3, got {max_vertices}")
    found = reduce_checked(prior, observation, landmark, max_vertices)
    wedge = prior.wedge
    if isinstance(found, str):
        area = prior.polygon.area
        return Reduction(prior, False, area, area, wedge, wedge, found)
    reduced, area_before, area_after = found
    return Reduction(reduced, True, area_before, area_after, wedge, reduced.wedge)


def reduce_checked(
    prior: SpatialUncertaintyMap, observation: Observation, landmark: Landmark, max_vertices: int
) -> Reduced:
    """:func:`reduce_map` for arguments already checked, without its :class:`Reduction` record.

    For the map manager, which pairs each observation with its landmark by id and class
    itself and reads only the reduced map and the areas (``max_vertices >= 3``).
    """
    if _compiled_reduce_cone is not None and _compiled_reduce_strip is not None:
        return _reduce_map_compiled(
            _compiled_reduce_cone, _compiled_reduce_strip, prior, observation, landmark, max_vertices
        )
    reduction = reduce_map_reference(prior, observation, landmark, max_vertices)
    if not reduction.consistent:
        return reduction.reason
    return reduction.map, reduction.area_before, reduction.area_after


def _reduce_map_compiled(
    reduce_cone: _Kernel,
    reduce_strip: _Kernel,
    prior: SpatialUncertaintyMap,
    observation: Observation,
    landmark: Landmark,
    max_vertices: int,
) -> Reduced:
    """:func:`reduce_checked` with the geometry in one call of a compiled kernel."""
    vertices = prior.polygon.vertices
    if not vertices.flags.c_contiguous:  # polygons hold C-contiguous float64 arrays already
        vertices = np.ascontiguousarray(vertices, dtype=np.float64)
    wedge = prior.wedge
    center_x, center_y = prior.center.tolist()
    forward, left = observation.sensor_offset
    found: _KernelResult
    if isinstance(observation, (BearingObservation, RangeBearingObservation)) and isinstance(
        landmark, (VerticalLineLandmark, PointLandmark)
    ):
        if isinstance(observation, RangeBearingObservation):
            r_min, r_max, piece = observation.range_min, observation.range_max, _SECTOR_PIECE
        else:
            r_min, r_max, piece = 0.0, math.inf, _CONE_PIECE
        found = reduce_cone(
            vertices,
            center_x,
            center_y,
            wedge.center,
            wedge.cw,
            wedge.ccw,
            forward,
            left,
            landmark.x,
            landmark.y,
            landmark.position_uncertainty,
            observation.bearing,
            observation.bearing_error,
            r_min,
            r_max,
            piece,
            max_vertices,
        )
    elif isinstance(observation, GroundLineObservation) and isinstance(landmark, GroundLineLandmark):
        start_x, start_y = landmark.start.tolist()
        end_x, end_y = landmark.end.tolist()
        found = reduce_strip(
            vertices,
            center_x,
            center_y,
            wedge.center,
            wedge.cw,
            wedge.ccw,
            forward,
            left,
            start_x,
            start_y,
            end_x,
            end_y,
            landmark.position_uncertainty,
            observation.offset,
            observation.offset_error,
            observation.angle,
            observation.angle_error,
            max_vertices,
        )
    else:  # pragma: no cover - the callers refused every other pairing
        raise InputError(f"observation: expected a known pairing, got {type(observation).__name__}")
    if isinstance(found, int):
        return _REASONS[found]
    raw, lo, width, x, y, area_before, area_after = found
    # Bytes are immutable, so the array is read-only as map values must be.
    reduced_vertices = np.frombuffer(raw, _FLOAT64).reshape(-1, 2)
    reduced_wedge = arc_wedge((lo, width), wedge.center) if width < wedge.width else wedge
    reduced = type(prior)._trusted(
        type(prior.polygon)._trusted(reduced_vertices), np.array([x, y]), reduced_wedge
    )
    return reduced, area_before, area_after


_FLOAT64 = np.dtype(np.float64)


def reduce_map_reference(
    prior: SpatialUncertaintyMap, observation: Observation, landmark: Landmark, max_vertices: int
) -> Reduction:
    """Pure-numpy :func:`reduce_map`: the reference the compiled kernels are tested against."""
    check_pair(observation, landmark)
    if max_vertices < 3:
        raise InputError(f"max_vertices: expected at least 3, got {max_vertices}")
    polygon = np.asarray(prior.polygon.vertices, dtype=np.float64)
    outcome: Outcome
    if isinstance(observation, BearingObservation) and isinstance(landmark, VerticalLineLandmark):
        outcome = reduce_bearing(polygon, prior.wedge, observation, landmark)
    elif isinstance(observation, RangeBearingObservation) and isinstance(landmark, PointLandmark):
        outcome = reduce_range_bearing(polygon, prior.wedge, observation, landmark)
    elif isinstance(observation, GroundLineObservation) and isinstance(landmark, GroundLineLandmark):
        outcome = reduce_ground_line(polygon, prior.wedge, observation, landmark)
    else:  # pragma: no cover - check_pair refused every other pairing
        raise InputError(f"observation: expected a known pairing, got {type(observation).__name__}")
    area = prior.polygon.area
    if isinstance(outcome, str):
        return Reduction(prior, False, area, area, prior.wedge, prior.wedge, outcome)
    vertices, headings = outcome
    if len(vertices) > max_vertices:
        vertices = cap_inside(vertices, polygon, max_vertices)
    _, center = nearest_on_polygon(vertices, np.asarray(prior.center, dtype=np.float64))
    wedge = arc_wedge(headings, prior.wedge.center) if headings[1] < prior.wedge.width else prior.wedge
    reduced = type(prior)._trusted(type(prior.polygon)._trusted(vertices), center, wedge)
    return Reduction(reduced, True, area, reduced.area, prior.wedge, wedge)
