"""The landmark reductions' geometry: the numpy reference and the compiled kernels behind one call.

Every function here keeps every pose of the prior map that is consistent with an
observation within its stated bounds: where an exact set is not convex or not a
polygon, an outer bound is taken. Bounds are pushed outward by :data:`TOLERANCE` so
that poses exactly on a bound survive floating-point rounding.

The sensor sits at ``p + R(h) o`` for a robot at ``p`` with heading ``h`` and a sensor
offset ``o = (forward, left)``. With ``o != 0`` the Class I and II reductions first bound
the sensor positions, constrain them, and map them back to robot positions through the
arc ``R(W) o`` (replaced by an outer polygon).

An arc is a pair ``(lo, width)`` of radians: every direction from ``lo``
counter-clockwise to ``lo + width``. The numpy functions are the specification;
``reduce.c`` repeats them operation for operation.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from enum import IntEnum
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from aura_ums._native import _extension
from aura_ums._native._extension import points_view
from aura_ums.geometry import (
    HeadingWedge,
    clip_halfplane,
    convex_hull,
    intersect_arcs,
    minkowski_sum,
    nearest_on_polygon,
    outer_arc,
    outer_disk,
    points_in_convex,
    subtended_arc,
)

Array = NDArray[np.float64]
Arc = tuple[float, float]

#: Outward margin (m for positions, rad for angles) added to every bound of a reduction.
TOLERANCE = 1e-9

#: Widest sub-cone of Class I, radians: a cone of pi or more is not convex, and the
#: widening of a sub-cone by the landmark's uncertainty is loosest near pi.
CONE_PIECE = 0.75 * math.pi
#: Widest annular sub-sector of Class II, radians.
SECTOR_PIECE = math.pi / 4
#: Spacing (radians) of the tangents that bound a sector's outer arc: the polygon lies
#: <= 1/cos(pi/16) - 1 ~ 2 % outside it.
TANGENT_STEP = math.pi / 8
#: Sides of the outer polygon of the sensor's circle when any heading is possible.
SENSOR_ARC_SIDES = 16


class EmptyReason(IntEnum):
    """Why a reduction is empty: no pose of the prior agrees with the observation."""

    #: No position is consistent with the observation.
    NO_POSITION = 0
    #: No sensor position (robot position plus offset) is consistent with it.
    NO_SENSOR_POSITION = 1
    #: No heading sees the landmark at the observed bearing.
    NO_BEARING_HEADING = 2
    #: No heading sees the ground line at the observed angle.
    NO_LINE_HEADING = 3
    #: No position is at the observed offset from the ground line.
    NO_OFFSET_POSITION = 4


#: A reduction as the kernels give it: the reduced polygon's vertices (float64 x, y pairs,
#: counter-clockwise, metres, inside the prior, at most ``max(max_vertices, len(prior))`` of
#: them) as bytes, the headings that remain as an arc (lo, width; radians), the centre (x, y;
#: the prior's, or the reduced polygon's point nearest to it; metres), and the areas of the
#: prior and the reduced polygon (square metres). Bytes, not an array: the reductions run
#: dozens of times per step, and the caller's read-only view of them costs nothing more.
RawReduction = tuple[bytes, float, float, float, float, float, float]

#: The cone kernel's type (:func:`reduce_cone_reference`, or the compiled one).
ConeKernel = Callable[
    [Array, float, float, float, float, float, float, float, float, float, float, float, float, float, float,
     float, int],
    RawReduction | int,
]  # fmt: skip
#: The strip kernel's type (:func:`reduce_strip_reference`, or the compiled one).
StripKernel = Callable[
    [Array, float, float, float, float, float, float, float, float, float, float, float, float, float, float,
     float, float, int],
    RawReduction | int,
]  # fmt: skip


if _extension.BUILT:
    from aura_ums._native import _kernels

    # The C kernels themselves, typed by their stub: a Python wrapper would cost a call, and
    # the reductions run dozens of times per step.
    reduce_cone_compiled: ConeKernel = _kernels.reduce_cone
    reduce_strip_compiled: StripKernel = _kernels.reduce_strip
    _compiled_reduce_sectors = _kernels.reduce_sectors


# --- arcs -------------------------------------------------------------------------------


def wedge_arc(center: float, cw: float, ccw: float) -> Arc:
    """Return the arc ``(lo, width)`` of a wedge's headings (width at most 2 pi)."""
    return (center - cw, min(cw + ccw, math.tau))


def widen_arc(arc: Arc, margin: float) -> Arc:
    """Return the arc with ``margin`` radians added on both sides."""
    return (arc[0] - margin, arc[1] + 2.0 * margin)


def cos_range(arc: Arc) -> tuple[float, float]:
    """Return (min, max) of ``cos`` over an arc of angles.

    Examples
    --------
    >>> cos_range((-0.5, 1.0))[1], cos_range((3.0, 0.5))[0]   # through 0 and through pi
    (1.0, -1.0)
    """
    lo, width = arc
    if width >= math.tau:
        return (-1.0, 1.0)
    ends = (math.cos(lo), math.cos(lo + width))
    upper = 1.0 if (-lo) % math.tau <= width else max(ends)
    lower = -1.0 if (math.pi - lo) % math.tau <= width else min(ends)
    return (lower, upper)


# --- polygons ---------------------------------------------------------------------------


def clip_halfplanes(vertices: Array, normals: Array, offsets: Array) -> Array:
    """Return the part of a convex polygon where ``normals[i] . p <= offsets[i]`` for all i.

    Half-planes that hold the whole polygon are skipped (they hold every part of it
    too), so the cost is one elementwise projection plus the clips that cut.
    Returns an empty ``(0, 2)`` array when nothing is left.
    """
    # Not vertices @ normals.T: BLAS may fuse the multiply and the add, the C does not.
    signed = vertices[:, 0, None] * normals[None, :, 0] + vertices[:, 1, None] * normals[None, :, 1] - offsets
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
    # libm's hypot, as reduce.c: numpy's own may differ by an ulp.
    length = np.array([math.hypot(x, y) for x, y in edge.tolist()])
    keep = length > 1e-9 * max(1.0, float(np.abs(other).max()))
    outward = np.column_stack([edge[keep, 1], -edge[keep, 0]]) / length[keep, None]
    start = other[keep]
    offsets = outward[:, 0] * start[:, 0] + outward[:, 1] * start[:, 1] + margin
    return clip_halfplanes(vertices, outward, offsets)


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
        count = max(1, math.ceil(width / TANGENT_STEP))
        for angle in np.linspace(lo, hi, count + 1).tolist():
            normals.append((math.cos(angle), math.sin(angle)))
            reach.append(r_max)
    normal_array = np.asarray(normals, dtype=np.float64)
    along = normal_array[:, 0] * apex[0] + normal_array[:, 1] * apex[1]
    offsets = along + np.asarray(reach) + (widen + TOLERANCE)
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
    count = max(1, math.ceil(min(width, math.tau) / piece))
    step = min(width, math.tau) / count
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
    if width >= math.tau:
        return outer_disk(np.zeros(2), radius, SENSOR_ARC_SIDES)
    if width <= 0.0:
        return np.array([[radius * math.cos(lo), radius * math.sin(lo)]])
    return convex_hull(outer_arc(radius, lo, lo + width))


def cap_inside(vertices: Array, prior: Array, max_vertices: int) -> Array:
    """Return an outer polygon of ``vertices`` inside ``prior``, of at most ``max_vertices`` if it can.

    Removes one edge at a time, extending its neighbours until they meet, choosing the
    cheapest removal whose new vertex lies inside ``prior``, until none can go. A clip
    that cut off one prior vertex can always be undone this way, so a polygon cut from
    ``prior`` by half-planes comes down to ``max(max_vertices, len(prior))`` vertices
    unless rounding blocks it (the kernels' tail, :func:`_finish`, then takes the prior).

    Examples
    --------
    >>> square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> cut = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.9], [0.9, 1.0], [0.0, 1.0]])
    >>> cap_inside(cut, square, 4).tolist()   # the cut corner is undone
    [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
    >>> len(cap_inside(square, square, 3))     # no corner inside the prior can go
    4
    """
    while len(vertices) > max(max_vertices, 3):
        edge = np.roll(vertices, -1, axis=0) - vertices
        preceding = np.roll(edge, 1, axis=0)
        following = np.roll(edge, -1, axis=0)
        denominator = preceding[:, 0] * following[:, 1] - preceding[:, 1] * following[:, 0]
        removable = denominator > 1e-12 * np.hypot(*preceding.T) * np.hypot(*following.T)
        with np.errstate(invalid="ignore", divide="ignore"):
            t = np.where(
                removable, (edge[:, 0] * following[:, 1] - edge[:, 1] * following[:, 0]) / denominator, 0.0
            )
        corner = vertices + t[:, None] * preceding
        removable &= points_in_convex(prior, corner, TOLERANCE)
        if not np.any(removable):
            break
        turn = preceding[:, 0] * edge[:, 1] - preceding[:, 1] * edge[:, 0]
        cost = np.where(removable, 0.5 * t * turn, np.inf)
        chosen = int(np.argmin(cost))
        result = vertices.copy()
        result[chosen] = corner[chosen]
        vertices = np.delete(result, (chosen + 1) % len(vertices), axis=0)
    return vertices


# --- the cone (Classes I and II) and the strip (Class III) --------------------------------


def _sensor_constrained(
    polygon: Array, headings: Arc, sensor_offset: tuple[float, float], constrain: Callable[[Array], Array]
) -> tuple[Array, Array] | EmptyReason:
    """Apply a constraint on sensor positions; return (robot positions, sensor positions) or why empty."""
    arc = sensor_arc(sensor_offset, headings)
    if arc is None:
        sensors = constrain(polygon)
        if len(sensors) == 0:
            return EmptyReason.NO_POSITION
        return sensors, sensors
    sensors = constrain(minkowski_sum(polygon, arc))
    if len(sensors) == 0:
        return EmptyReason.NO_SENSOR_POSITION
    # A robot position is possible when some heading puts its sensor in the region:
    # p = s - R(h) o, an outer bound of which is the region summed with the mirrored arc.
    positions = clip_convex(polygon, minkowski_sum(sensors, -arc))
    if len(positions) == 0:
        return EmptyReason.NO_POSITION
    # Sensors must also be reachable from the remaining positions.
    narrowed = clip_convex(sensors, minkowski_sum(positions, arc))
    return positions, narrowed if len(narrowed) else sensors


def _bearing_headings(sensors: Array, landmark: Array, widen: float, bearing: float, error: float) -> Arc:
    """Return the headings from which some sensor position sees the landmark at the bearing."""
    lo, width = subtended_arc(sensors, landmark, widen)
    if width >= math.tau:
        return (lo, math.tau)
    # Directions from the sensors towards the landmark are those from it, turned by pi.
    return widen_arc((lo + math.pi - bearing, width), error + TOLERANCE)


def _summed_area(vertices: Array) -> float:
    """Return :func:`~aura_ums.geometry.polygon_area` summed in order, as ``polygon.c`` sums it (m^2).

    ``polygon_area``'s np.dot adds in BLAS's order; the kernels' areas follow the C's.
    """
    if len(vertices) < 3:
        return 0.0
    x = vertices[:, 0] - vertices[0, 0]
    y = vertices[:, 1] - vertices[0, 1]
    xy = np.cumsum(x * np.roll(y, -1))[-1]
    yx = np.cumsum(y * np.roll(x, -1))[-1]
    return float(0.5 * (xy - yx))


def _finish(positions: Array, prior: Array, center: Array, headings: Arc, max_vertices: int) -> RawReduction:
    """Apply the vertex cap, keep the centre (or move it to the nearest position) and measure both areas.

    The positions end with at most ``max(max_vertices, len(prior))`` vertices: when
    rounding keeps :func:`cap_inside` above that, the prior, which holds them, is taken.
    """
    if len(positions) > max_vertices:
        positions = cap_inside(positions, prior, max_vertices)
        if len(positions) > max(max_vertices, len(prior)):
            positions = prior
    _, nearest = nearest_on_polygon(positions, center)
    x, y = nearest.tolist()
    raw = np.ascontiguousarray(positions, dtype=np.float64).tobytes()
    return (raw, headings[0], headings[1], x, y, _summed_area(prior), _summed_area(positions))


def reduce_cone_reference(
    vertices: Array,
    center_x: float,
    center_y: float,
    wedge_center: float,
    wedge_cw: float,
    wedge_ccw: float,
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
) -> RawReduction | EmptyReason:
    """Reduce a map by a bearing (Class I) or a range and bearing (Class II) to a landmark.

    The numpy reference, the specification ``reduce.c`` follows: ``aura_ums._native.reduce_cone``
    is this function, or the C kernel (``reduce_cone_compiled``) when the kernels run
    compiled.

    The positions from which the landmark is seen at the bearing (within its error, for
    some heading of the wedge, and within the range interval) form a cone, or an annular
    sector, at the landmark, widened by its position uncertainty; the polygon is cut by
    it, piece by piece of at most ``piece`` radians, then the wedge narrows to the
    headings that see the landmark at the bearing from what remains.

    Parameters
    ----------
    vertices : ndarray, shape (n, 2)
        The prior polygon, counter-clockwise, metres, finite.
    center_x, center_y : float
        The prior's most probable position, metres.
    wedge_center, wedge_cw, wedge_ccw : float
        The prior wedge, radians.
    forward, left : float
        The sensor's offset in the robot frame, metres.
    landmark_x, landmark_y : float
        Where the landmark is mapped, metres.
    widen : float
        Radius of where the landmark truly is around that, metres, >= 0.
    bearing, bearing_error : float
        The observed bearing and its error bound, radians.
    range_min, range_max : float
        The range interval, metres; ``0`` and ``inf`` for a bearing alone.
    piece : float
        Widest sub-cone, radians: :data:`CONE_PIECE` (Class I) or :data:`SECTOR_PIECE`.
    max_vertices : int
        Cap on the result's vertex count, >= 3 (a larger prior may keep its own count).

    Returns
    -------
    RawReduction or EmptyReason
        The reduction (see :data:`RawReduction`), or why no pose of the prior agrees with the
        observation (the compiled kernel gives the reason's value, a plain int).

    Examples
    --------
    >>> from aura_ums import _native
    >>> square = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    >>> pole = (0, 0, 0, 0.01, 0.01, 0, 0, 20, 0, 0)   # centre, wedge, offset, landmark, widen
    >>> seen = _native.reduce_cone(square, *pole, 0.0, 0.001, 0, math.inf, CONE_PIECE, 16)
    >>> seen[5], round(seen[6], 2)    # areas before and after: the cone keeps |y| <~ 0.22
    (4.0, 0.88)
    >>> int(_native.reduce_cone(square, *pole, math.pi, 0.01, 0, math.inf, CONE_PIECE, 16))   # behind
    0
    """
    headings = wedge_arc(wedge_center, wedge_cw, wedge_ccw)
    landmark = np.array([landmark_x, landmark_y])
    # The landmark is seen towards h + bearing, so the sensor lies from the landmark
    # towards h + bearing + pi, for some heading h of the wedge and bearing error.
    cone = widen_arc((headings[0] + bearing + math.pi, headings[1]), bearing_error + TOLERANCE)

    def constrain(polygon: Array) -> Array:
        if cone[1] >= math.tau and not math.isfinite(range_max):
            return polygon  # seen from every direction: no constraint on position
        return clip_to_sector(polygon, landmark, cone, widen, range_min, range_max, piece)

    found = _sensor_constrained(vertices, headings, (forward, left), constrain)
    if isinstance(found, EmptyReason):
        return found
    positions, sensors = found
    narrowed = intersect_arcs(headings, _bearing_headings(sensors, landmark, widen, bearing, bearing_error))
    if narrowed is None:
        return EmptyReason.NO_BEARING_HEADING
    return _finish(positions, vertices, np.array([center_x, center_y]), narrowed, max_vertices)


def reduce_strip_reference(
    vertices: Array,
    center_x: float,
    center_y: float,
    wedge_center: float,
    wedge_cw: float,
    wedge_ccw: float,
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
) -> RawReduction | EmptyReason:
    """Reduce a map by a ground line's observed angle and offset (Class III).

    The numpy reference, the specification ``reduce.c`` follows: ``aura_ums._native.reduce_strip``
    is this function, or the C kernel (``reduce_strip_compiled``) when the kernels run
    compiled.

    The angle narrows the wedge directly; the offset cuts a strip parallel to the line
    (the true line is taken parallel to the mapped one, within ``position_uncertainty``).

    Parameters
    ----------
    vertices, center_x, center_y, wedge_center, wedge_cw, wedge_ccw, forward, left
        The prior and the sensor offset, as for :func:`reduce_cone`.
    start_x, start_y, end_x, end_y : float
        The mapped line's ends, metres (distinct).
    position_uncertainty : float
        How far the true line may lie from the mapped one, metres, >= 0.
    offset, offset_error : float
        The observed signed distance to the line and its error bound, metres.
    angle, angle_error : float
        The observed direction of the line relative to the heading and its error, radians.
    max_vertices : int
        Cap on the result's vertex count, as for :func:`reduce_cone`.

    Returns
    -------
    RawReduction or EmptyReason
        The reduction (see :data:`RawReduction`), or why no pose of the prior agrees with the
        observation (the compiled kernel gives the reason's value, a plain int).

    Examples
    --------
    >>> from aura_ums import _native
    >>> square = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    >>> edge = (0, 0, 0, 0.1, 0.1, 0, 0, -9, -2, 9, -2, 0)   # centre, wedge, offset, line, uncertainty
    >>> strip = _native.reduce_strip(square, *edge, 2.0, 0.5, 0, 0.05, 16)
    >>> round(strip[6], 6), round(strip[2], 6)   # area after (|y| <= 0.5), heading width
    (2.0, 0.1)
    >>> int(_native.reduce_strip(square, *edge, 9.0, 0.5, 0, 0.05, 16))   # EmptyReason.NO_OFFSET_POSITION
    4
    """
    direction = math.atan2(end_y - start_y, end_x - start_x)
    # angle = direction - heading, so the heading is direction - angle.
    observed = widen_arc((direction - angle, 0.0), angle_error + TOLERANCE)
    headings = intersect_arcs(wedge_arc(wedge_center, wedge_cw, wedge_ccw), observed)
    if headings is None:
        return EmptyReason.NO_LINE_HEADING
    normal = np.array([-math.sin(direction), math.cos(direction)])
    base = float(normal[0] * start_x + normal[1] * start_y)
    margin = offset_error + position_uncertainty
    lo = base + offset - margin
    hi = base + offset + margin
    radius = math.hypot(forward, left)
    if radius > 0.0:
        # normal . R(h) o = |o| cos(h + atan2(left, forward) - direction - pi/2).
        shift = math.atan2(left, forward) - direction - math.pi / 2.0
        lowest, highest = cos_range((headings[0] + shift, headings[1]))
        lo -= radius * highest
        hi -= radius * lowest
    normals = np.vstack([normal, -normal])
    offsets = np.array([hi + TOLERANCE, -lo + TOLERANCE])
    positions = clip_halfplanes(vertices, normals, offsets)
    if len(positions) == 0:
        return EmptyReason.NO_OFFSET_POSITION
    return _finish(positions, vertices, np.array([center_x, center_y]), headings, max_vertices)


# --- every sector of a wedge at once (the joint reduction's sectors) ----------------------

#: Numbers per observation row of :func:`reduce_sectors_reference`: the kind (0 a cone, 1 a
#: strip), then the kernel's arguments after the wedge, without the cap (a cone's ten are
#: followed by one unused 0).
SECTOR_ROW = 12


def arc_parts(lo: float, width: float, center: float) -> tuple[float, float, float]:
    """Return the wedge of an arc ``(lo, width)`` narrower than 2 pi: unwrapped centre, cw, ccw (rad).

    Centred on ``center`` when the arc holds it, else on the arc's end nearer to it (the
    shorter way round). The centre is not wrapped: ``HeadingWedge._trusted`` wraps it.

    Examples
    --------
    >>> arc_parts(0.0, 1.0, 0.25)                   # inside: kept
    (0.25, 0.25, 0.75)
    >>> arc_parts(0.0, 1.0, -0.5)                   # outside, nearer the start
    (0.0, 0.0, 1.0)
    """
    offset = (center - lo) % math.tau
    if offset > width:
        # Outside: clamp to whichever end is the shorter way round.
        offset = width if offset - width < math.tau - offset else 0.0
    return lo + offset, offset, width - offset


class ReducedSectors(NamedTuple):
    """The sectors a :func:`reduce_sectors_reference` kept, in sector order.

    Attributes
    ----------
    points : ndarray, shape (n, 2)
        Every kept sector's polygon, one after the other (metres, counter-clockwise).
    counts : ndarray of int64, shape (k,)
        Each kept sector's vertex count.
    sectors : ndarray of int64, shape (k,)
        Each kept sector's index, 0 to ``count - 1``.
    values : ndarray, shape (k, 5)
        Each kept sector's centre x, y (metres, not held inside its polygon), then its
        wedge: unwrapped centre, cw and ccw (radians).
    """

    points: Array
    counts: NDArray[np.int64]
    sectors: NDArray[np.int64]
    values: Array


def reduce_sectors_reference(
    vertices: Array,
    center_x: float,
    center_y: float,
    lo: float,
    step: float,
    count: int,
    half: float,
    arguments: Sequence[float],
    max_vertices: int,
) -> ReducedSectors:
    """Reduce one polygon over ``count`` heading sectors by every observation in turn, each sector on its own.

    Sector ``s`` is the wedge centred on ``lo + s step + step / 2`` with extents ``half``
    on both sides (radians), holding the polygon ``vertices`` (metres) and the centre. Each
    observation row (:data:`SECTOR_ROW` numbers) reduces it as :func:`reduce_cone_reference`
    or :func:`reduce_strip_reference` would, the next row reducing what the last one left:
    the centre is the kernel's (not held), and the wedge narrows to the kernel's arc
    (:func:`arc_parts`) when that is narrower. A sector that one row empties is dropped.
    This is the joint reduction's loop over sectors (``uncertainty._joint``), one call for
    them all.

    Examples
    --------
    >>> square = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    >>> ahead = [0, 0, 0, 5, 0, 0, 0, 0.05, 0, math.inf, CONE_PIECE, 0]   # a pole at (5, 0), dead ahead
    >>> kept = reduce_sectors_reference(square, 0, 0, -math.pi, math.pi / 2, 4, math.pi / 4, ahead, 16)
    >>> kept.sectors.tolist()                      # the two sectors that meet facing +x see it ahead
    [1, 2]
    >>> len(reduce_sectors_reference(square, 0, 0, 2.0, 0.5, 2, 0.25, ahead, 16).sectors)   # facing away
    0
    """
    rows = [tuple(arguments[at : at + SECTOR_ROW]) for at in range(0, len(arguments), SECTOR_ROW)]
    polygons: list[Array] = []
    sectors: list[int] = []
    values: list[tuple[float, float, float, float, float]] = []
    for sector in range(count):
        raw = (lo + sector * step) + 0.5 * step
        wedge = HeadingWedge._trusted(raw, half, half)
        polygon, x, y = vertices, center_x, center_y
        for row in rows:
            # A strip takes eleven numbers after the wedge, a cone ten.
            kernel: Callable[..., RawReduction | int] = (
                reduce_strip_reference if row[0] else reduce_cone_reference
            )
            numbers = row[1:12] if row[0] else row[1:11]
            found = kernel(polygon, x, y, wedge.center, wedge.cw, wedge.ccw, *numbers, max_vertices)
            if isinstance(found, int):
                break
            data, arc_lo, arc_width, x, y, _, _ = found
            polygon = points_view(data)
            if arc_width < wedge.width:
                raw, cw, ccw = arc_parts(arc_lo, arc_width, wedge.center)
                wedge = HeadingWedge._trusted(raw, cw, ccw)
        else:
            polygons.append(polygon)
            sectors.append(sector)
            values.append((x, y, raw, wedge.cw, wedge.ccw))
    points = np.concatenate(polygons) if polygons else np.empty((0, 2))
    return ReducedSectors(
        points,
        np.array([len(p) for p in polygons], dtype=np.int64),
        np.array(sectors, dtype=np.int64),
        np.array(values, dtype=np.float64).reshape(-1, 5),
    )


def reduce_sectors_compiled(
    vertices: Array,
    center_x: float,
    center_y: float,
    lo: float,
    step: float,
    count: int,
    half: float,
    arguments: Sequence[float],
    max_vertices: int,
) -> ReducedSectors:
    """Compiled :func:`reduce_sectors_reference` (needs the extension module: ``_extension.BUILT``)."""
    raw, raw_counts, raw_sectors, raw_values = _compiled_reduce_sectors(
        vertices, center_x, center_y, lo, step, count, half, arguments, max_vertices
    )
    return ReducedSectors(
        points_view(raw),
        np.frombuffer(raw_counts, dtype=np.int64),
        np.frombuffer(raw_sectors, dtype=np.int64),
        np.frombuffer(raw_values, dtype=np.float64).reshape(-1, 5),
    )
