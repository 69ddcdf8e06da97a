"""The three landmark reductions on maps: pairing, the kernels' results, the Reduction record.

The geometry of each reduction (set-membership intersections on plain arrays and arcs,
every bound an outer one) is in ``aura_ums._native``, with its numpy reference and its
compiled kernel; here an observation and its landmark become the kernel's numbers, and
its result becomes a map.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, cast

import numpy as np
from numpy.typing import NDArray

from aura_ums import _native
from aura_ums._native import CONE_PIECE, SECTOR_PIECE, EmptyReason, RawReduction
from aura_ums._validate import vertex_cap
from aura_ums.errors import InputError
from aura_ums.geometry import (
    POSITION_TOLERANCE,
    HeadingWedge,
    points_in_convex,
)
from aura_ums.uncertainty._landmarks import (
    BearingObservation,
    GroundLineLandmark,
    GroundLineObservation,
    Landmark,
    LandmarkClass,
    Observation,
    PointLandmark,
    RangeBearingObservation,
    VerticalLineLandmark,
)
from aura_ums.uncertainty._slices import SliceSet, point_in

if TYPE_CHECKING:
    from aura_ums.uncertainty._map import SpatialUncertaintyMap


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


def arc_wedge(arc: tuple[float, float], center: float) -> HeadingWedge:
    """Return the wedge of an arc ``(lo, width)`` (radians), centred on ``center`` or its nearer end."""
    lo, width = arc
    if width >= math.tau:
        return HeadingWedge.full_circle(center)
    # 0 <= cw, ccw and both finite: the checks of HeadingWedge() would all pass.
    return HeadingWedge._trusted(*_native.arc_parts(lo, width, center))


# --- the map-level entry point ------------------------------------------------------

#: The observation types, and the landmark type of each class (which classes an observation
#: can name is LandmarkClass.observes).
_OBSERVATIONS = (BearingObservation, RangeBearingObservation, GroundLineObservation)
_LANDMARKS = {
    LandmarkClass.VERTICAL_LINE: VerticalLineLandmark,
    LandmarkClass.POINT: PointLandmark,
    LandmarkClass.GROUND_LINE: GroundLineLandmark,
}


def check_pair(observation: object, landmark: object) -> None:
    """Raise :class:`InputError` unless the observation can name the landmark, by class and id."""
    if type(observation) not in _OBSERVATIONS:
        names = ", ".join(kind.__name__ for kind in _OBSERVATIONS)
        raise InputError(f"observation: expected one of {names}, got {type(observation).__name__}")
    observed = cast(Observation, observation).landmark_class
    named = isinstance(landmark, (VerticalLineLandmark, PointLandmark, GroundLineLandmark))
    if not named or not observed.observes(cast(Landmark, landmark).landmark_class):
        names = " or ".join(kind.__name__ for each, kind in _LANDMARKS.items() if observed.observes(each))
        raise InputError(
            f"landmark: expected a {names} for a {type(observation).__name__}, got {type(landmark).__name__}"
        )
    observed_id = cast(Observation, observation).landmark_id
    landmark_id = cast(Landmark, landmark).id
    if landmark_id != observed_id:
        raise InputError(f"landmark.id: expected {observed_id!r} (the observation's), got {landmark_id!r}")


#: Why a reduction is empty, by the reason its kernel gives (an EmptyReason, or its value).
_REASONS: dict[int, str] = {
    EmptyReason.NO_POSITION: "no position of the map is consistent with the observation",
    EmptyReason.NO_SENSOR_POSITION: "no sensor position of the map is consistent with the observation",
    EmptyReason.NO_BEARING_HEADING: "no heading of the map is consistent with the observed bearing",
    EmptyReason.NO_LINE_HEADING: "no heading of the map is consistent with the observed line angle",
    EmptyReason.NO_OFFSET_POSITION: "no position of the map is at the observed offset from the line",
}


#: A reduction without its record: (reduced map, area before, area after), or why it is empty.
Reduced = tuple["SpatialUncertaintyMap", float, float] | str

#: A reduction that says only whether it kept the same set: (reduced map, same), or why it is empty.
Kept = tuple["SpatialUncertaintyMap", bool] | str


def reduce_map(
    prior: SpatialUncertaintyMap, observation: Observation, landmark: Landmark, max_vertices: int
) -> Reduction:
    """Reduce a map by one observation of a landmark; see :meth:`SpatialUncertaintyMap.reduce`."""
    check_pair(observation, landmark)
    cap = vertex_cap(max_vertices)
    found = reduce_checked(prior, observation, landmark, cap)
    wedge = prior.wedge
    if isinstance(found, str):
        area = prior.polygon.area
        return Reduction(prior, False, area, area, wedge, wedge, found)
    reduced, area_before, area_after = found
    return Reduction(reduced, True, area_before, area_after, wedge, reduced.wedge)


#: Metres from the origin beyond which a reduction runs in a frame moved next to the map.
#: Far out, the kernels' rounding margins, made for coordinates of a work area, were too
#: small: at 990 km a sighting from an offset sensor cut the true pose out by up to 7.7 cm,
#: where the same scene at the origin kept it. Moved by a whole number of metres near the
#: map's centre, every coordinate of the map and the landmark changes exactly.
LOCAL_FRAME_BEYOND = 1e4


def local_origin(x: float, y: float) -> tuple[float, float] | None:
    """Return whole metres near a map's centre (x, y) to reduce it about, or None near the origin."""
    if abs(x) <= LOCAL_FRAME_BEYOND and abs(y) <= LOCAL_FRAME_BEYOND:
        return None
    return float(round(x)), float(round(y))


def moved_landmark(landmark: Landmark, dx: float, dy: float) -> Landmark:
    """Return the landmark moved by (dx, dy) metres (for a frame moved next to the map)."""
    if isinstance(landmark, GroundLineLandmark):
        step = np.array([dx, dy])
        return GroundLineLandmark(
            landmark.id,
            landmark.start + step,
            landmark.end + step,
            landmark.symbol,
            landmark.position_uncertainty,
        )
    return dataclasses.replace(landmark, x=landmark.x + dx, y=landmark.y + dy)


def reduce_checked(
    prior: SpatialUncertaintyMap,
    observation: Observation,
    landmark: Landmark,
    max_vertices: int,
    *,
    measured: bool = True,
) -> Reduced:
    """:func:`reduce_map` for arguments already checked, without its :class:`Reduction` record.

    For the map manager, which pairs each observation with its landmark by id and class
    itself (``max_vertices >= 3``). Without ``measured``, a sliced map's areas are NaN:
    each is a hull of every slice, and the manager keeps the maps, not their areas. A
    product map's come from its kernel at no cost, so they are always given. Beyond
    :data:`LOCAL_FRAME_BEYOND` from the origin the reduction runs in a frame moved next
    to the map.
    """
    center_x, center_y = prior.center.tolist()
    origin = local_origin(center_x, center_y)
    if origin is not None:
        return _reduce_far(prior, origin, observation, landmark, max_vertices, measured)
    slices = prior._slices
    if slices is not None:
        return _reduce_sliced(prior, slices, observation, landmark, max_vertices, measured=measured)
    wedge = prior.wedge
    kernel, _, arguments = _kernel_call(observation, landmark, max_vertices)
    found = kernel(prior.polygon.vertices, center_x, center_y, wedge.center, wedge.cw, wedge.ccw, *arguments)
    if isinstance(found, int):
        return _REASONS[found]
    raw, lo, width, x, y, area_before, area_after = found
    reduced_vertices = _native.points_view(raw)
    reduced_wedge = arc_wedge((lo, width), wedge.center) if width < wedge.width else wedge
    if x != center_x or y != center_y:
        x, y = held_centre(reduced_vertices, x, y)
    reduced = type(prior)._at(type(prior.polygon)._trusted(reduced_vertices), x, y, reduced_wedge)
    return reduced, area_before, area_after


def _reduce_far(
    prior: SpatialUncertaintyMap,
    origin: tuple[float, float],
    observation: Observation,
    landmark: Landmark,
    max_vertices: int,
    measured: bool,
) -> Reduced:
    """:func:`reduce_checked` of a map far from the origin: moved by -``origin``, reduced, moved back."""
    ox, oy = origin
    found = reduce_checked(
        prior._moved(-ox, -oy),
        observation,
        moved_landmark(landmark, -ox, -oy),
        max_vertices,
        measured=measured,
    )
    if isinstance(found, str):
        return found
    reduced, before, after = found
    return reduced._moved(ox, oy, merge=True), before, after


#: A reduction kernel with its observation's arguments: called on (vertices, centre x, centre
#: y, wedge centre, cw, ccw) of one polygon and wedge; and its kernel over every slice of a
#: sliced map, called on (points, counts, lo, hi, centre x, centre y, heading).
_Call = tuple[
    Callable[..., "RawReduction | int"], Callable[..., "_native.ReducedSlices | int"], tuple[float | int, ...]
]


def _kernel_call(observation: Observation, landmark: Landmark, max_vertices: int) -> _Call:
    """Return the reduction kernels of the observation's class and their arguments after the wedge."""
    forward, left = observation.sensor_offset
    if isinstance(observation, (BearingObservation, RangeBearingObservation)) and isinstance(
        landmark, (VerticalLineLandmark, PointLandmark)
    ):
        if isinstance(observation, RangeBearingObservation):
            r_min, r_max, piece = observation.range_min, observation.range_max, SECTOR_PIECE
        else:
            r_min, r_max, piece = 0.0, math.inf, CONE_PIECE
        return _native.reduce_cone, _native.reduce_cone_slices, (
            forward, left, landmark.x, landmark.y, landmark.position_uncertainty, observation.bearing,
            observation.bearing_error, r_min, r_max, piece, max_vertices,
        )  # fmt: skip
    if isinstance(observation, GroundLineObservation) and isinstance(landmark, GroundLineLandmark):
        (start_x, start_y), (end_x, end_y) = landmark.start.tolist(), landmark.end.tolist()
        return _native.reduce_strip, _native.reduce_strip_slices, (
            forward, left, start_x, start_y, end_x, end_y, landmark.position_uncertainty, observation.offset,
            observation.offset_error, observation.angle, observation.angle_error, max_vertices,
        )  # fmt: skip
    # The callers refused every other pairing.
    raise InputError(
        f"observation: expected a known pairing, got {type(observation).__name__}"
    )  # pragma: no cover


def _reduce_sliced(
    prior: SpatialUncertaintyMap,
    slices: SliceSet,
    observation: Observation,
    landmark: Landmark,
    max_vertices: int,
    *,
    measured: bool = True,
) -> Reduced:
    """Reduce a sliced map slice by slice (one kernel call); empty slices drop out, all empty is inconsistent.

    Without ``measured``, both areas are returned as NaN (the caller takes them if it needs
    them: each is a hull of every slice).

    Each slice is a product map of its polygon and its (narrow) interval, so its reduction
    is the single kernel's, sound as it is; the union of the reduced slices holds every
    pose of the prior that agrees with the observation. The most probable pose is the one
    the kernel kept (or moved) in the slice nearest to the prior heading.
    """
    center_x, center_y = prior.center.tolist()
    _, kernel, arguments = _kernel_call(observation, landmark, max_vertices)
    found = kernel(
        slices.points, slices.counts, slices.lo, slices.hi, center_x, center_y, prior.wedge.center, *arguments
    )
    if isinstance(found, int):
        return _REASONS[found]
    points = found.points
    points.setflags(write=False)
    kept = SliceSet(points, found.counts, found.lo, found.hi, np.arange(len(found.counts), dtype=np.int64))
    wedge = HeadingWedge._trusted(found.center, found.cw, found.ccw)
    x, y = found.x, found.y
    if x != center_x or y != center_y:
        home = _native.home_slice(found.lo.tolist(), found.hi.tolist(), prior.wedge.center)
        start = int(found.counts[:home].sum())
        x, y = held_centre(points[start : start + int(found.counts[home])], x, y)
    reduced = type(prior)._sliced(kept, np.array([x, y]), wedge, prior._cells, prior._max_slices)
    if not measured:
        return reduced, math.nan, math.nan
    return reduced, prior.area, reduced.area


def reduce_kept(
    prior: SpatialUncertaintyMap, observation: Observation, landmark: Landmark, max_vertices: int
) -> Kept:
    """:func:`reduce_checked`, telling only whether the reduced map is the same set as the prior.

    *Same* is what the map manager tests: the areas before and after are equal and
    positive, and the wedge kept its width. A sliced map's areas are its hulls' (a hull of
    every slice each, the costly part of a reduction); they are taken only when the widths
    agree, since a narrower wedge settles it. The answer is the test's, bit for bit.
    """
    slices = prior._slices
    if slices is None:
        found = reduce_checked(prior, observation, landmark, max_vertices)
        if isinstance(found, str):
            return found
        reduced, before, after = found
        return reduced, 0.0 < before == after and reduced.wedge.width == prior.wedge.width
    sliced = reduce_checked(prior, observation, landmark, max_vertices, measured=False)
    if isinstance(sliced, str):
        return sliced
    reduced = sliced[0]
    return reduced, reduced.wedge.width == prior.wedge.width and 0.0 < prior.area == reduced.area


def held_centre(vertices: NDArray[np.float64], x: float, y: float) -> tuple[float, float]:
    """Return a kernel's moved centre, or the nearest point to it that the polygon holds (metres).

    A centre the prior's polygon no longer holds is moved by the kernel to the reduced
    polygon's nearest point, on its boundary. A reduced polygon may keep an edge shorter
    than rounding whose direction is noise (a turn of -1e-8 rad is within the convexity
    tolerance); its line, extended, can pass more than ``POSITION_TOLERANCE`` outside a
    boundary point a metre away, so the map would not hold its own centre. Such a point is
    moved towards the mean of the vertices, by steps growing fourfold from
    ``POSITION_TOLERANCE``, until :func:`~aura_ums.geometry.points_in_convex` holds it with
    that tolerance, the test ``SpatialUncertaintyMap.contains`` applies; the mean itself is
    the last resort. A point or a segment holds every point of itself, so a degenerate
    polygon keeps the kernel's point.

    Parameters
    ----------
    vertices : ndarray, shape (n, 2)
        The reduced polygon, counter-clockwise, metres, n >= 1.
    x, y : float
        The kernel's centre, on or near the polygon, metres.

    Examples
    --------
    >>> square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> held_centre(square, 1.0, 0.5)                 # on the boundary: held as it is
    (1.0, 0.5)
    >>> notch = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [1.0 - 1e-8, 1.0 - 1e-16], [0.0, 1.0]])
    >>> x, y = held_centre(notch, 0.5, 1.0)           # a noisy 1e-8 m edge cuts the top edge
    >>> abs(x - 0.5) < 1e-6 and 1.0 - 1e-6 < y < 1.0
    True
    """
    # points_in_convex's answer, by the compiled test where it does the same operations:
    # the centre is tested so many times a frame.
    if point_in(vertices, x, y, POSITION_TOLERANCE):
        return x, y
    point = np.array([[x, y]])
    inner = vertices.mean(axis=0)
    gap = inner - point[0]
    length = math.hypot(gap[0], gap[1])
    step = POSITION_TOLERANCE
    while step < length:
        candidate = point[0] + (step / length) * gap
        if points_in_convex(vertices, candidate[None, :], POSITION_TOLERANCE)[0]:
            return float(candidate[0]), float(candidate[1])
        step *= 4.0
    return float(inner[0]), float(inner[1])
