"""The Expecter: the image window where a landmark must appear, from the uncertainty map.

Method (why the window is guaranteed)
-------------------------------------
For a pose (p, h) of the map, a landmark point q (world, ground part (x, y), height z)
sits in the robot frame at ``(R(-h)(q - p), z)``. Over every pose of the map and every
place the landmark may truly be, its ground part ranges over

    S = { R(-h) d : d in D, h in W },   D = Q (+) (-P),

with ``P`` the map's polygon, ``W`` its wedge, ``Q`` the landmark's ground set (its
point, or its ground segment, Minkowski-summed with an outer polygon of the disk of its
position uncertainty) and (+) the Minkowski sum (exact for convex polygons). ``D`` is a
convex polygon, so the convex hull of ``S`` is the hull of the arcs that the vertices of
``D`` sweep as ``h`` runs over ``W``. Each arc is replaced by its *outer* polygon (its
two exact ends and the points where tangents meet), which contains it; a full-circle
wedge gives the outer polygon of the disk through the farthest vertex.

Extruding over the landmark's heights (Class I: [z_bottom, z_top]; Class II: z;
Class III: the ground, z = 0) gives a convex polytope ``K`` that holds every landmark
point from every pose. The mount's offset and rotation map it, affinely, into the
camera frame. The visible points (z_cam > NEAR_PLANE) lie in ``K`` cut by the plane
z_cam = NEAR_PLANE / 2 (a safety margin below the camera's own threshold); the cut
polytope's vertices are ``K``'s vertices in front and the crossings of ``K``'s edges
(known: ``K`` is a prism over a convex polygon) with the plane. A perspective projection
maps a convex set in front of the camera onto a convex set, the convex hull of its
vertices' projections; so the bounding box of those projections contains every
projection. Lens distortion is bounded rigorously over that convex hull (see
``_distortion``), and the intrinsics map the box to pixels monotonically (fx, fy > 0).

The result is exact up to the outer polygons (relative excess below 1/cos(pi/128) - 1,
0.03 %) whenever the landmark stays in front of the camera and there is no distortion:
the extremes of a projection over a convex set are attained at its extreme points, and
those are actual poses (a vertex of the map with an end of the wedge, or a point of the
landmark's own set).

With calibration bounds (``Expecter(camera, calibration_bounds)``) the window holds for every camera
within them. The true camera differs from the nominal one by its height (within
``bounds.height``) and by a rotation about its optical centre: pan and tilt errors, a rotation
of angle at most ``rho = pan + tilt`` (the angle between two rotations is a metric invariant on
both sides, so the pan and tilt errors add whatever the order of the mount's rotations).
Seen through the nominal camera, that rotation moves a landmark point ``q`` about the optical
centre ``c`` by at most ``2 sin(rho / 2) |q - c|``: the window is the nominal window of the
landmark with its position uncertainty and its heights widened by that much (``|q - c|`` at
most the farthest the landmark can be from the camera over the map), and its heights by the
height bound too. The intrinsics' bounds then widen the pixels: ``u = fx x + cx`` is
monotone in ``fx`` and ``cx`` for each ``x``, so the extremes are at the bounds' ends.

A heading-sliced map (``SpatialUncertaintyMap.is_sliced``) is a union of such product
sets, one per slice: its window is the bounding window of the slices' windows, each made as
above from the slice's polygon and interval, so it holds every projection too, and a slice
keeps only the positions possible at its own headings.

The geometry, from the map's vertices to the normalized points and their box, is one
kernel of ``aura_ums._native`` (:func:`~aura_ums._native.expecter_points`, compiled when the
C extension was built, its numpy reference otherwise); here the landmark and the mount
become its numbers and its box becomes pixels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from aura_ums import _native
from aura_ums.camera import NEAR_PLANE, CalibrationBounds, Camera
from aura_ums.errors import InputError
from aura_ums.expecter._distortion import distorted_range
from aura_ums.expecter._window import class_margin, margin_pixels
from aura_ums.geometry import UNBOUNDED_PIXELS, ImageWindow
from aura_ums.uncertainty import (
    GroundLineLandmark,
    Landmark,
    PointLandmark,
    SpatialUncertaintyMap,
    VerticalLineLandmark,
)
from aura_ums.world import PerceptualStrategy

Array = NDArray[np.float64]

#: Angular step (rad) of the outer polygons of swept arcs: 0.03 % outside the arc.
_ARC_STEP = math.pi / 64
#: Sides of the outer polygon of a landmark's position-uncertainty disk.
_DISK_SIDES = 64
#: The cut plane (m along the optical axis): below NEAR_PLANE, so that rounding can never
#: hide a visible point.
_CUT_PLANE = 0.5 * NEAR_PLANE
#: Relative and absolute slack (pixels) added to every bound, far above rounding error.
_RELATIVE_SLACK = 1e-9
_ABSOLUTE_SLACK = 1e-7
#: The bounds of an exact calibration (an Expecter given them keeps no bounds).
_EXACT = CalibrationBounds()
#: Distortion bounds are refined until within this many pixels of an attained value.
_DISTORTION_TOLERANCE_PIXELS = 1e-3


@dataclass(frozen=True, slots=True)
class Expecter:
    """Predicts the image window in which a landmark must appear (the paper's Expecter).

    Parameters
    ----------
    camera : Camera
        The calibrated camera on its mount; its pan, tilt and offset stay fixed.
    calibration_bounds : CalibrationBounds or None
        How far the true camera may be from ``camera`` (``[calibration_bounds]`` of a camera
        file: :func:`~aura_ums.camera.load_calibration_bounds`); the windows then hold for
        every camera within them (see the module notes), and are wider. None (or all zero):
        the camera is exact. Its ``fx`` and ``fy`` bounds must be below the camera's own.

    Examples
    --------
    >>> import math
    >>> from aura_ums.camera import Camera, CameraIntrinsics, CameraMount
    >>> from aura_ums.uncertainty import Pose, PointLandmark, SpatialUncertaintyMap
    >>> camera = Camera(CameraIntrinsics(500, 500, 320, 240, 640, 480), CameraMount(height=1.0))
    >>> expecter = Expecter(camera)
    >>> known = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.0, 0.0)   # exact pose
    >>> corner = PointLandmark("corner", 10.0, 0.0, 2.0)
    >>> w = expecter.bounds(known, corner)
    >>> round(w.u_min, 6), round(w.u_max, 6), round(w.v_min, 6)           # one pixel
    (320.0, 320.0, 190.0)
    >>> unsure = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.5, math.radians(3))
    >>> expecter.window(unsure, corner, margin=PerceptualStrategy.INTEREST_OPERATOR).width > 50
    True
    >>> expecter.window(unsure, PointLandmark("behind", -10.0, 0.0, 2.0)) is None
    True

    A camera whose pan and tilt are known to half a degree, its principal point to 2 pixels:
    the window holds for every such camera, so it is wider.

    >>> from aura_ums.camera import CalibrationBounds
    >>> half_degree = math.radians(0.5)
    >>> loose = Expecter(camera, CalibrationBounds(cx=2.0, cy=2.0, pan=half_degree, tilt=half_degree))
    >>> wide = loose.bounds(known, corner)
    >>> round(wide.u_min, 1), round(wide.u_max, 1)   # the corner's 0.18 m at 10 m (pan + tilt: 1 deg), +-2 px
    (309.2, 330.8)
    """

    camera: Camera
    calibration_bounds: CalibrationBounds | None = None
    _rotation: tuple[float, ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not isinstance(self.camera, Camera):
            raise InputError(f"camera: expected a Camera, got {type(self.camera).__name__}")
        calibration = self.calibration_bounds
        if calibration is not None:
            if not isinstance(calibration, CalibrationBounds):
                got = type(calibration).__name__
                raise InputError(f"calibration_bounds: expected CalibrationBounds or None, got {got}")
            k = self.camera.intrinsics
            for name, focal in (("fx", k.fx), ("fy", k.fy)):
                bound = getattr(calibration, name)
                if bound >= focal:
                    raise InputError(
                        f"calibration_bounds.{name}: expected a bound below the camera's {name} "
                        f"({focal!r} px), got {bound!r}"
                    )
            if calibration == _EXACT:  # an exact calibration: the windows of no bounds, computed so
                object.__setattr__(self, "calibration_bounds", None)
        rotation = tuple(float(value) for value in self.camera.mount.rotation().ravel())
        object.__setattr__(self, "_rotation", rotation)

    def bounds(self, map: SpatialUncertaintyMap, landmark: Landmark) -> ImageWindow | None:
        """Return the guaranteed window, before any margin and before clipping to the image.

        For every pose of ``map`` (every point of its polygon, every heading of its wedge)
        and every place within the landmark's ``position_uncertainty``, the projection of
        the landmark's visible part lies inside the returned window: Class I, the part of
        the vertical segment [z_bottom, z_top] in front of the camera; Class II, the
        point; Class III, the part of the ground segment in front of the camera.

        Parameters
        ----------
        map : SpatialUncertaintyMap
            Where the robot may be and which way it may face.
        landmark : VerticalLineLandmark, PointLandmark or GroundLineLandmark
            The expected landmark (world frame, metres).

        Returns
        -------
        ImageWindow or None
            Pixels; may extend beyond the image (far beyond when part of the landmark
            may come close to the camera plane; an overflowing side is
            :data:`UNBOUNDED_PIXELS`). None when the landmark is behind the camera from
            every pose.

        Raises
        ------
        InputError
            When ``map`` or ``landmark`` is of the wrong type.
        """
        return _bounds(self, map, landmark)

    def window(
        self,
        map: SpatialUncertaintyMap,
        landmark: Landmark,
        *,
        margin: float | PerceptualStrategy | None = None,
    ) -> ImageWindow | None:
        """Return the window to search: :meth:`bounds` grown by a margin, clipped to the image.

        Parameters
        ----------
        map : SpatialUncertaintyMap
            Where the robot may be and which way it may face.
        landmark : VerticalLineLandmark, PointLandmark or GroundLineLandmark
            The expected landmark.
        margin : float, PerceptualStrategy or None
            Pixels (>= 0) added on every side, or the strategy whose
            :data:`DEFAULT_MARGINS` entry to use. None: the entry of the strategy that
            usually looks for the landmark's class (:meth:`PerceptualStrategy.for_class`:
            a line finder's 24 px for Class I and III, an interest operator's 4 px for
            Class II). Pass the landmark record's own ``strategy`` when it names another.

        Returns
        -------
        ImageWindow or None
            Pixels, inside ``[-0.5, width - 0.5] x [-0.5, height - 0.5]``. None when the
            landmark cannot be in view from any pose of the map (behind the camera, or
            the guaranteed window, grown by the margin, misses the image).

        Raises
        ------
        InputError
            On a map or landmark of the wrong type, or a negative or non-finite margin.
        """
        pixels = None if margin is None else margin_pixels(margin)
        guaranteed = self.bounds(map, landmark)  # checks the landmark
        if guaranteed is None:
            return None
        if pixels is None:
            pixels = class_margin(landmark.landmark_class)
        k = self.camera.intrinsics
        return guaranteed.expanded(pixels).clipped(k.width, k.height)


def _bounds(expecter: Expecter, map: SpatialUncertaintyMap, landmark: Landmark) -> ImageWindow | None:
    """:meth:`Expecter.bounds`: the kernel's points, then pixels (with the lens's distortion)."""
    _check_map(map)
    ends, heights = _landmark_geometry(landmark)
    camera = expecter.camera
    mount, k = camera.mount, camera.intrinsics
    rises = tuple(height - mount.height for height in heights)
    uncertainty = landmark.position_uncertainty
    bounds = expecter.calibration_bounds
    if bounds is not None:
        spread = _rotation_spread(map, ends, uncertainty, rises, camera, bounds)
        uncertainty += spread
        rises = (min(rises) - bounds.height - spread, max(rises) + bounds.height + spread)
    if map.is_sliced:
        found = _sliced_points(expecter, map, ends, uncertainty, rises)
    else:
        wedge = map.wedge
        found = _points(
            expecter, map.polygon.vertices, ends, uncertainty,
            wedge.is_full_circle, wedge.center - wedge.cw, wedge.width, rises,
        )  # fmt: skip
    if found is None:
        return None
    if k.distortion is None:
        if bounds is None:
            return _pixel_window(k.fx, k.fy, k.cx, k.cy, found.x_min, found.y_min, found.x_max, found.y_max)
        lower, upper = np.array([found.x_min, found.y_min]), np.array([found.x_max, found.y_max])
    else:
        tolerance = _DISTORTION_TOLERANCE_PIXELS / max(k.fx, k.fy)
        imaged = distorted_range(found.points, k.distortion, tolerance)
        if imaged is None:  # every ray beyond the lens's fold: not in view
            return None
        lower, upper = imaged
    # Zero bounds leave focal x + centre as it is, bit for bit (x - 0.0 is x).
    within = _EXACT if bounds is None else bounds
    with np.errstate(over="ignore", invalid="ignore"):
        u = _pixel_range(k.fx, within.fx, k.cx, within.cx, lower[0], upper[0])
        v = _pixel_range(k.fy, within.fy, k.cy, within.cy, lower[1], upper[1])
    return ImageWindow(
        _outward(float(u[0]), -1.0),
        _outward(float(v[0]), -1.0),
        _outward(float(u[1]), 1.0),
        _outward(float(v[1]), 1.0),
    )


def _rotation_spread(
    map: SpatialUncertaintyMap,
    ends: tuple[tuple[float, float], ...],
    uncertainty: float,
    rises: tuple[float, ...],
    camera: Camera,
    bounds: CalibrationBounds,
) -> float:
    """Metres a landmark point may seem moved by the mount's pan and tilt errors (module notes).

    ``2 sin(rho / 2)`` times the farthest the landmark can be from the optical centre: over
    the map's polygon (the hull of its slices), the landmark's ground set and the camera's
    offset across, its heights (the camera's height error included) up and down.
    """
    rho = min(bounds.pan + bounds.tilt, math.pi)
    if rho == 0.0:
        return 0.0
    vertices = map.polygon.vertices
    across = (
        max(float(np.max(np.hypot(vertices[:, 0] - x, vertices[:, 1] - y))) for x, y in ends)
        + uncertainty
        + math.hypot(camera.mount.forward, camera.mount.left)
    )
    up = max(abs(rise) for rise in rises) + bounds.height
    return 2.0 * math.sin(rho / 2.0) * math.hypot(across, up)


def _pixel_range(
    focal: float, focal_bound: float, centre: float, centre_bound: float, low: float, high: float
) -> tuple[float, float]:
    """Return the least and most of ``focal x + centre``: x in [low, high], focal and centre in bounds."""
    least, most = focal - focal_bound, focal + focal_bound  # both > 0 (checked by the Expecter)
    return (
        min(least * low, most * low) - centre_bound + centre,
        max(least * high, most * high) + centre_bound + centre,
    )


def _points(
    expecter: Expecter,
    vertices: Array,
    ends: tuple[tuple[float, float], ...],
    uncertainty: float,
    full: bool,
    lo: float,
    width: float,
    rises: tuple[float, ...],
) -> _native.ExpectedPoints | None:
    """Return the kernel's points for one polygon and heading interval (``full``: every heading)."""
    mount = expecter.camera.mount
    return _native.expecter_points(
        vertices,
        ends,
        uncertainty,
        _DISK_SIDES,
        full,
        0.0 if full else lo,
        0.0 if full else width,
        _ARC_STEP,
        expecter._rotation,
        mount.forward,
        mount.left,
        rises,
        _CUT_PLANE,
    )


def _sliced_points(
    expecter: Expecter,
    map: SpatialUncertaintyMap,
    ends: tuple[tuple[float, float], ...],
    uncertainty: float,
    rises: tuple[float, ...],
) -> _native.ExpectedPoints | None:
    """Return the points of every slice of a sliced map and their joint box (None: behind from all).

    Every pose of the map lies in some slice, and each slice's points span every projection
    from its poses (the method above, with the slice's polygon and interval for ``P`` and
    ``W``): so the box of all the slices' boxes spans every projection from the map, and
    is the bounding window of the per-slice windows.
    """
    found: list[_native.ExpectedPoints] = []
    for piece in map.slices:
        full = piece.width >= 2.0 * math.pi
        points = _points(
            expecter, piece.polygon.vertices, ends, uncertainty, full, piece.lo, piece.width, rises
        )
        if points is not None:
            found.append(points)
    if not found:
        return None
    if len(found) == 1:
        return found[0]
    return _native.ExpectedPoints(
        np.concatenate([f.points for f in found]),
        min(f.x_min for f in found),
        min(f.y_min for f in found),
        max(f.x_max for f in found),
        max(f.y_max for f in found),
    )


def _pixel_window(
    fx: float, fy: float, cx: float, cy: float, x_lo: float, y_lo: float, x_hi: float, y_hi: float
) -> ImageWindow:
    """Pixels of a box of normalized coordinates (fx, fy > 0: monotone), pushed outward."""
    return ImageWindow._trusted(
        _outward(fx * x_lo + cx, -1.0),
        _outward(fy * y_lo + cy, -1.0),
        _outward(fx * x_hi + cx, 1.0),
        _outward(fy * y_hi + cy, 1.0),
    )


def _check_map(map: object) -> None:
    if not isinstance(map, SpatialUncertaintyMap):
        raise InputError(f"map: expected a SpatialUncertaintyMap, got {type(map).__name__}")


def _landmark_geometry(landmark: object) -> tuple[tuple[tuple[float, float], ...], tuple[float, ...]]:
    """Return the landmark's ground point or segment ends (m) and its one or two heights (m, ascending)."""
    if isinstance(landmark, VerticalLineLandmark):
        if landmark.z_top == landmark.z_bottom:
            return ((landmark.x, landmark.y),), (landmark.z_bottom,)
        return ((landmark.x, landmark.y),), (landmark.z_bottom, landmark.z_top)
    if isinstance(landmark, PointLandmark):
        return ((landmark.x, landmark.y),), (landmark.z,)
    if isinstance(landmark, GroundLineLandmark):
        (ax, ay), (bx, by) = landmark.start.tolist(), landmark.end.tolist()
        return ((ax, ay), (bx, by)), (0.0,)
    raise InputError(
        "landmark: expected a VerticalLineLandmark, PointLandmark or GroundLineLandmark, "
        f"got {type(landmark).__name__}"
    )


def _outward(value: float, direction: float) -> float:
    """Push a bound outward by the rounding slack; keep it finite (NaN and inf saturate)."""
    if math.isnan(value) or math.isinf(value):
        return direction * UNBOUNDED_PIXELS
    widened = value + direction * (_RELATIVE_SLACK * abs(value) + _ABSOLUTE_SLACK)
    if math.isinf(widened):
        return direction * UNBOUNDED_PIXELS
    return widened
