"""Observations taken together: a joint reduction that splits the heading wedge into sectors.

When the heading is wide open, one bearing says little about position: the cone it cuts
is as wide as the wedge. Two bearings taken at the same instant say much more, since
their difference does not depend on the heading; but reducing by them one after the
other forgets that both were seen from one heading. The joint reduction keeps it: the
wedge is split into sectors no wider than ``sector``, the map restricted to each sector
is reduced by every observation in turn, and the result is the convex hull of what the
sectors keep, with the smallest wedge (inside the prior's) that holds their headings.

A sliced map (:meth:`SpatialUncertaintyMap.with_slices`) is reduced slice by slice already:
its slices are the sectors (``sector`` is not used) and the result stays sliced.

Soundness follows from the single reductions': a true pose's heading lies in some
sector, whose reductions keep the pose; the hull and the covering wedge only add. Every
sector's result lies inside the prior, so their hull does too. The hull may have more
vertices than the cap; it is then replaced by an outer polygon inside the prior with at
most ``max(max_vertices, prior's count)`` vertices, or by the prior itself, as a single
reduction's result is: both only add.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from aura_ums import _native
from aura_ums._native import TOLERANCE, cap_inside
from aura_ums._validate import finite_float, vertex_cap
from aura_ums.errors import InputError
from aura_ums.geometry import Arc, ConvexPolygon, HeadingWedge, intersect_arcs
from aura_ums.uncertainty._growth import DEFAULT_MAX_VERTICES
from aura_ums.uncertainty._landmarks import Landmark, Observation
from aura_ums.uncertainty._map import SpatialUncertaintyMap
from aura_ums.uncertainty._reduce import (
    Reduction,
    _kernel_call,
    arc_wedge,
    check_pair,
    local_origin,
    moved_landmark,
    reduce_checked,
)
from aura_ums.uncertainty._slices import MAX_CELLS, MIN_SLICE_WIDTH

#: Default widest heading sector of :func:`reduce_jointly`, radians (5 degrees).
DEFAULT_SECTOR = math.radians(5.0)

_TWO_PI = 2.0 * math.pi
#: Narrowest heading sector of :func:`reduce_jointly` (and the manager's ``joint_sector``): a
#: sliced map's narrowest cell, :data:`MAX_CELLS` sectors round the circle (1e-300 rad asked
#: the kernel for more sectors than it can count).
MIN_SECTOR = MIN_SLICE_WIDTH

#: Why a joint reduction is empty.
JOINT_INCONSISTENT = "no heading of the map agrees with all the observations together"


def reduce_jointly(
    prior: SpatialUncertaintyMap,
    sightings: Sequence[tuple[Observation, Landmark]],
    *,
    sector: float = DEFAULT_SECTOR,
    max_vertices: int = DEFAULT_MAX_VERTICES,
) -> Reduction:
    """Reduce a map by observations taken together, sector by sector of its heading wedge.

    See the module notes. With one sector (a wedge no wider than ``sector``) it is the
    reduction by each observation in turn, :meth:`SpatialUncertaintyMap.reduce`.

    Parameters
    ----------
    prior : SpatialUncertaintyMap
        The map, grown to the observations' time.
    sightings : sequence of (observation, landmark)
        Observations of one instant with the landmarks they name (each pair as
        :meth:`SpatialUncertaintyMap.reduce` takes it), at least one.
    sector : float
        Widest heading sector, radians, in (0, 2 pi]. Narrower sectors keep less
        (tighter maps) and cost more: one reduction per observation and sector.
    max_vertices : int
        Cap on the polygon's vertex count (>= 3), as for a single reduction.

    Returns
    -------
    Reduction
        The reduced map; ``consistent=False`` and the prior itself when no sector's
        heading agrees with all the observations (:data:`JOINT_INCONSISTENT`).

    Raises
    ------
    InputError
        For a bad argument, or an observation whose landmark is of another class or id.

    Examples
    --------
    >>> from aura_ums.uncertainty import BearingObservation, Pose, VerticalLineLandmark
    >>> truth = Pose(3.0, 4.0, 1.0)
    >>> lost = SpatialUncertaintyMap.from_pose(Pose(5.0, 5.0, 0.0), 15.0, math.pi)  # any heading
    >>> a = VerticalLineLandmark("a", 12.0, 4.0, 0.0, 5.0)
    >>> b = VerticalLineLandmark("b", 3.0, 14.0, 0.0, 5.0)
    >>> c = VerticalLineLandmark("c", -4.0, 2.0, 0.0, 5.0)
    >>> def seen(*poles):
    ...     return [(BearingObservation(p.id, 0.0, math.atan2(p.y - truth.y, p.x - truth.x) - truth.heading,
    ...                                 0.02), p) for p in poles]
    >>> one_by_one = lost
    >>> for observation, pole in seen(a, b):
    ...     one_by_one = one_by_one.reduce(observation, pole).map
    >>> one_by_one.area == lost.area, one_by_one.wedge.is_full_circle    # each alone says nothing
    (True, True)
    >>> two = reduce_jointly(lost, seen(a, b))
    >>> two.consistent, two.map.contains(truth), two.area_ratio < 0.2, two.map.wedge.width < 2.0
    (True, True, True, True)
    >>> three = reduce_jointly(lost, seen(a, b, c))
    >>> three.map.contains(truth), round(three.area_after, 1), round(three.map.wedge.width, 2)
    (True, 1.2, 0.09)

    All three dead ahead: they are not in line, so no pose sees them so.

    >>> ahead = [(BearingObservation(p.id, 0.0, 0.0, 0.02), p) for p in (a, b, c)]
    >>> reduce_jointly(lost, ahead).reason
    'no heading of the map agrees with all the observations together'
    """
    if not isinstance(prior, SpatialUncertaintyMap):
        raise InputError(f"prior: expected a SpatialUncertaintyMap, got {type(prior).__name__}")
    pairs = _checked_sightings(sightings)
    width_limit = check_sector(sector, "sector")
    cap = vertex_cap(max_vertices)
    wedge = prior.wedge
    found = joint_reduced(prior, pairs, width_limit, cap)
    if isinstance(found, str):
        area = prior.area
        return Reduction(prior, False, area, area, wedge, wedge, found)
    return Reduction(found, True, prior.area, found.area, wedge, found.wedge)


def joint_reduced(
    prior: SpatialUncertaintyMap, pairs: Sequence[tuple[Observation, Landmark]], sector: float, cap: int
) -> SpatialUncertaintyMap | str:
    """:func:`reduce_jointly` for checked arguments: the reduced map, or why no heading agrees.

    For the map manager, which reads neither area (a sliced map's is a hull of every slice).
    Far from the origin it runs in a frame moved next to the map (see ``reduce_checked``).
    """
    origin = local_origin(*prior.center.tolist())
    if origin is not None:
        ox, oy = origin
        moved = [(observation, moved_landmark(landmark, -ox, -oy)) for observation, landmark in pairs]
        found = _joint_here(prior._moved(-ox, -oy), moved, sector, cap)
        return found if isinstance(found, str) else found._moved(ox, oy, merge=True)
    return _joint_here(prior, pairs, sector, cap)


def _joint_here(
    prior: SpatialUncertaintyMap, pairs: Sequence[tuple[Observation, Landmark]], sector: float, cap: int
) -> SpatialUncertaintyMap | str:
    """:func:`joint_reduced` in the map's own frame."""
    wedge = prior.wedge
    lo, width = wedge.center - wedge.cw, min(wedge.width, _TWO_PI)
    count = max(1, math.ceil(width / sector - 1e-9))
    if count == 1 or prior.is_sliced:
        # A sliced map's slices are its sectors: each is reduced by every observation in
        # turn, and a slice that disagrees with one drops out.
        return _in_turn(prior, pairs, cap)
    step = width / count
    # Neighbouring sectors overlap by the reductions' tolerance: no heading falls between.
    half = 0.5 * step + TOLERANCE

    def restricted(start: float) -> SpatialUncertaintyMap:
        """Return the prior restricted to the sector starting at ``start`` (radians)."""
        # start is finite and half > 0: the checks of HeadingWedge() would all pass.
        return SpatialUncertaintyMap._trusted(
            prior.polygon, prior.center, HeadingWedge._trusted(start + 0.5 * step, half, half)
        )

    # Every sector of the prior reduced by each observation in turn, in one kernel call;
    # centres not held: at most one sector's is read, and that one is reduced again.
    center_x, center_y = prior.center.tolist()
    found = _native.reduce_sectors(
        prior.polygon.vertices, center_x, center_y, lo, step, count, half, _sector_rows(pairs, cap), cap
    )
    if not len(found.sectors):
        return JOINT_INCONSISTENT
    # The combination reads only the results' vertices (all together) and wedges.
    kept: list[_Sector] = [
        (lo + sector * step, HeadingWedge._trusted(center, cw, ccw))
        for sector, (_, _, center, cw, ccw) in zip(found.sectors.tolist(), found.values.tolist(), strict=True)
    ]
    return _combined(prior, kept, found.points, wedge.is_full_circle, pairs, cap, restricted)


def _sector_rows(pairs: Sequence[tuple[Observation, Landmark]], cap: int) -> list[float]:
    """Return the observations as :func:`_native.reduce_sectors` takes them: rows of kind and arguments."""
    rows: list[float] = []
    for observation, landmark in pairs:
        kernel, _, arguments = _kernel_call(observation, landmark, cap)
        # The arguments end with the cap, which the sectors' kernel takes once.
        numbers = [float(value) for value in arguments[:-1]]
        rows += [1.0 if kernel is _native.reduce_strip else 0.0, *numbers]
        rows += [0.0] * (_native.SECTOR_ROW - 1 - len(numbers))
    return rows


def check_sector(value: object, name: str) -> float:
    """Return a sector width (radians, in [:data:`MIN_SECTOR`, 2 pi]) or raise naming ``name``."""
    width = finite_float(value, name)
    if not 0.0 < width <= _TWO_PI:
        raise InputError(f"{name}: expected radians in (0, 2 pi], got {width!r}")
    if width < MIN_SECTOR:
        raise InputError(
            f"{name}: expected at least {MIN_SECTOR:g} rad (0.1 degree, at most {MAX_CELLS} sectors; "
            f"a reduction costs in proportion to the sectors), got {width!r} "
            f"({_TWO_PI / width:.3g} sectors of a full circle)"
        )
    return width


def _checked_sightings(sightings: object) -> list[tuple[Observation, Landmark]]:
    if isinstance(sightings, (str, bytes)) or not isinstance(sightings, Sequence):
        raise InputError(
            f"sightings: expected a sequence of (observation, landmark) pairs, got {type(sightings).__name__}"
        )
    pairs: list[tuple[Observation, Landmark]] = []
    for index, pair in enumerate(sightings):
        if not isinstance(pair, tuple) or len(pair) != 2:
            raise InputError(f"sightings[{index}]: expected an (observation, landmark) pair, got {pair!r}")
        check_pair(*pair)  # once here: every sector reduces by the same pairs
        pairs.append(pair)
    if not pairs:
        raise InputError("sightings: expected at least one (observation, landmark) pair, got none")
    return pairs


def _in_turn(
    current: SpatialUncertaintyMap,
    pairs: Sequence[tuple[Observation, Landmark]],
    cap: int,
) -> SpatialUncertaintyMap | str:
    """Return the map reduced by each (checked) pair in turn, or why the first inconsistent one is."""
    for observation, landmark in pairs:
        found = reduce_checked(current, observation, landmark, cap, measured=False)
        if isinstance(found, str):
            return found
        current = found[0]
    return current


#: A sector the joint reduction kept: where it starts (radians) and its result's wedge.
_Sector = tuple[float, HeadingWedge]


def _combined(
    prior: SpatialUncertaintyMap,
    kept: Sequence[_Sector],
    points: NDArray[np.float64],
    full_circle: bool,
    pairs: Sequence[tuple[Observation, Landmark]],
    cap: int,
    restricted: Callable[[float], SpatialUncertaintyMap],
) -> SpatialUncertaintyMap:
    """One map holding every sector's result: their hull, and one wedge over their headings.

    ``kept`` holds each kept sector's start and result wedge, ``points`` the results'
    vertices one after the other. The kernel did not hold the results' centres inside their
    polygons: the one sector whose centre the map takes is reduced again by ``pairs``, held,
    from the prior ``restricted`` to it.
    """
    # The hull kernel: no cap (at least as many vertices as the points), the hull alone.
    outline = _native.merge_groups(points, [len(points)], max(len(points), 3))[0]
    if len(outline) > cap:
        # As a single reduction's tail does: an outer polygon inside the prior, or, when
        # the hull hugs the prior too closely for that, the prior itself, which holds it.
        outline = cap_inside(outline, prior.polygon.vertices, cap)
        if len(outline) > max(cap, len(prior.polygon.vertices)):
            outline = prior.polygon.vertices
    polygon = ConvexPolygon._trusted(outline)
    # Each result's headings as an interval unwrapped next to its sector, in sector order.
    spans = []
    for start, result_wedge in kept:
        low = start + math.remainder(result_wedge.center - result_wedge.cw - start, _TWO_PI)
        spans.append((low, low + min(result_wedge.width, _TWO_PI)))
    first, last = spans[0][0], max(high for _, high in spans)
    arc: Arc = (first, last - first)
    if not full_circle:
        # The sectors overlap their neighbours, and the prior's ends, by the tolerance:
        # trim that off, so the wedge stays inside the prior's.
        prior_wedge = prior.wedge
        arc = intersect_arcs((prior_wedge.center - prior_wedge.cw, prior_wedge.width), arc) or arc
    else:
        # Any heading was possible: the wedge may leave out the widest gap between results.
        gaps = [(spans[i + 1][0] - spans[i][1], i) for i in range(len(spans) - 1)]
        gaps.append((first + _TWO_PI - last, len(spans) - 1))
        gap, after = max(gaps)
        if gap <= 0.0:
            arc = (first, _TWO_PI)
        else:
            begin = spans[(after + 1) % len(spans)][0]
            arc = (begin, _TWO_PI - gap)
    # The most probable pose: the prior's where it is still possible, as a single reduction
    # keeps it; else the prior's heading (the new wedge's middle when any heading was
    # possible) in the sector result nearest to it, with that result's centre.
    heading_kept = (prior.wedge.center - arc[0]) % _TWO_PI <= arc[1]
    if not full_circle and heading_kept and polygon.contains(prior.center[None, :])[0]:
        return SpatialUncertaintyMap(polygon, prior.center, arc_wedge(arc, prior.wedge.center))
    target = prior.wedge.center if not full_circle else arc[0] + 0.5 * arc[1]
    start = min(kept, key=lambda item: _angular_gap(target, item[1]))[0]
    nearest = _in_turn(restricted(start), pairs, cap)
    # The same polygons and wedges as without held centres: they never depend on the centre.
    assert not isinstance(nearest, str)
    heading = arc_wedge((nearest.wedge.center - nearest.wedge.cw, nearest.wedge.width), target).center
    return SpatialUncertaintyMap(polygon, nearest.center, arc_wedge(arc, heading))


def _angular_gap(angle: float, wedge: HeadingWedge) -> float:
    """Radians from ``angle`` to the nearest heading of ``wedge`` (0 inside it)."""
    offset = (angle - (wedge.center - wedge.cw)) % _TWO_PI
    if offset <= wedge.width:
        return 0.0
    return min(offset - wedge.width, _TWO_PI - offset)
