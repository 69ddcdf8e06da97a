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

Speed: when the C extension ``aura_ums.geometry._kernels`` was built, one call of its
``expecter_points`` runs every step from the map's vertices to the normalized points and
their box (the three Minkowski operands merged in one pass); the numpy functions below
stay the reference implementation and the fallback.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from aura_ums.camera import NEAR_PLANE, Camera
from aura_ums.errors import InputError
from aura_ums.expecter._distortion import distorted_range
from aura_ums.expecter._window import PerceptualStrategy, margin_pixels, trusted_window
from aura_ums.geometry import UNBOUNDED_PIXELS, ImageWindow, convex_hull, minkowski_sum, outer_disk
from aura_ums.uncertainty import (
    GroundLineLandmark,
    Landmark,
    PointLandmark,
    SpatialUncertaintyMap,
    VerticalLineLandmark,
)

Array = NDArray[np.float64]

_CompiledPoints = Callable[..., tuple[bytes, float, float, float, float] | None]
_compiled_expecter_points: _CompiledPoints | None
try:  # the compiled kernel, when the build had a C compiler
    from aura_ums.geometry._kernels import expecter_points as _compiled_expecter_points
except ImportError:  # pragma: no cover - exercised on machines without a compiler
    _compiled_expecter_points = None

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
#: Distortion bounds are refined until within this many pixels of an attained value.
_DISTORTION_TOLERANCE_PIXELS = 1e-3


@dataclass(frozen=True, slots=True)
class Expecter:
    """Predicts the image window in which a landmark must appear (the paper's Expecter).

    Parameters
    ----------
    camera : Camera
        The calibrated camera on its mount; its pan, tilt and offset stay fixed.

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
    """

    camera: Camera
    _rotation: tuple[float, ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not isinstance(self.camera, Camera):
            raise InputError(f"camera: expected a Camera, got {type(self.camera).__name__}")
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
        return _bounds(self, map, landmark, compiled=_compiled_expecter_points is not None)

    def window(
        self,
        map: SpatialUncertaintyMap,
        landmark: Landmark,
        *,
        margin: float | PerceptualStrategy = PerceptualStrategy.LINE_FINDER,
    ) -> ImageWindow | None:
        """Return the window to search: :meth:`bounds` grown by a margin, clipped to the image.

        Parameters
        ----------
        map : SpatialUncertaintyMap
            Where the robot may be and which way it may face.
        landmark : VerticalLineLandmark, PointLandmark or GroundLineLandmark
            The expected landmark.
        margin : float or PerceptualStrategy
            Pixels (>= 0) added on every side, or the strategy whose
            :data:`DEFAULT_MARGINS` entry to use.

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
        pixels = margin_pixels(margin)
        guaranteed = self.bounds(map, landmark)
        if guaranteed is None:
            return None
        k = self.camera.intrinsics
        return guaranteed.expanded(pixels).clipped(k.width, k.height)


def _bounds(
    expecter: Expecter, map: SpatialUncertaintyMap, landmark: Landmark, *, compiled: bool
) -> ImageWindow | None:
    """:meth:`Expecter.bounds` by the compiled kernel or by the numpy reference."""
    _check_map(map)
    camera = expecter.camera
    k = camera.intrinsics
    normalized: Array | None = None
    if compiled:
        result = _compiled_points(expecter, map, landmark)
        if result is None:
            return None
        raw, x_lo, y_lo, x_hi, y_hi = result
        if k.distortion is None:
            return _pixel_window(k.fx, k.fy, k.cx, k.cy, x_lo, y_lo, x_hi, y_hi)
        normalized = np.frombuffer(raw, dtype=np.float64).reshape(-1, 2)
    else:
        ground, levels = _landmark_geometry(landmark)
        relative = _relative_ground(map, ground)
        camera_points = _clip_to_front(camera, relative, levels)
        if camera_points is None:
            return None
        normalized = camera_points[:, :2] / camera_points[:, 2:3]
        if k.distortion is None:
            lower, upper = normalized.min(axis=0), normalized.max(axis=0)
            return _pixel_window(
                k.fx, k.fy, k.cx, k.cy, float(lower[0]), float(lower[1]), float(upper[0]), float(upper[1])
            )
    tolerance = _DISTORTION_TOLERANCE_PIXELS / max(k.fx, k.fy)
    lower, upper = distorted_range(normalized, k.distortion, tolerance)
    with np.errstate(over="ignore", invalid="ignore"):
        u = (k.fx * lower[0] + k.cx, k.fx * upper[0] + k.cx)
        v = (k.fy * lower[1] + k.cy, k.fy * upper[1] + k.cy)
    return ImageWindow(
        _outward(float(u[0]), -1.0),
        _outward(float(v[0]), -1.0),
        _outward(float(u[1]), 1.0),
        _outward(float(v[1]), 1.0),
    )


def _pixel_window(
    fx: float, fy: float, cx: float, cy: float, x_lo: float, y_lo: float, x_hi: float, y_hi: float
) -> ImageWindow:
    """Pixels of a box of normalized coordinates (fx, fy > 0: monotone), pushed outward."""
    return trusted_window(
        _outward(fx * x_lo + cx, -1.0),
        _outward(fy * y_lo + cy, -1.0),
        _outward(fx * x_hi + cx, 1.0),
        _outward(fy * y_hi + cy, 1.0),
    )


def _compiled_points(
    expecter: Expecter, map: SpatialUncertaintyMap, landmark: Landmark
) -> tuple[bytes, float, float, float, float] | None:
    """Run the compiled kernel: (bytes of the normalized points, their box), or None when behind."""
    assert _compiled_expecter_points is not None  # the caller checked
    if isinstance(landmark, VerticalLineLandmark):
        count, ax, ay = 1, landmark.x, landmark.y
        bx, by = ax, ay
        bottom, top = landmark.z_bottom, landmark.z_top
        levels = 1 if top == bottom else 2
    elif isinstance(landmark, PointLandmark):
        count, ax, ay = 1, landmark.x, landmark.y
        bx, by = ax, ay
        bottom = top = landmark.z
        levels = 1
    elif isinstance(landmark, GroundLineLandmark):
        count = 2
        (ax, ay), (bx, by) = landmark.start.tolist(), landmark.end.tolist()
        bottom = top = 0.0
        levels = 1
    else:
        _landmark_geometry(landmark)  # raises the InputError naming the type
        raise AssertionError("unreachable")  # pragma: no cover
    mount = expecter.camera.mount
    wedge = map.wedge
    full = wedge.is_full_circle
    return _compiled_expecter_points(
        map.polygon.vertices,
        count,
        _DISK_SIDES,
        1 if full else 0,
        levels,
        ax,
        ay,
        bx,
        by,
        landmark.position_uncertainty,
        0.0 if full else wedge.center - wedge.cw,
        0.0 if full else wedge.width,
        _ARC_STEP,
        *expecter._rotation,
        mount.forward,
        mount.left,
        bottom - mount.height,
        top - mount.height,
        _CUT_PLANE,
    )


def _check_map(map: object) -> None:
    if not isinstance(map, SpatialUncertaintyMap):
        raise InputError(f"map: expected a SpatialUncertaintyMap, got {type(map).__name__}")


def _landmark_geometry(landmark: object) -> tuple[Array, tuple[float, ...]]:
    """Return the landmark's ground set (convex CCW vertices, m) and its heights (m)."""
    if isinstance(landmark, VerticalLineLandmark):
        levels: tuple[float, ...] = (landmark.z_bottom, landmark.z_top)
        if landmark.z_top == landmark.z_bottom:
            levels = (landmark.z_bottom,)
        base = landmark.position.reshape(1, 2)
    elif isinstance(landmark, PointLandmark):
        levels = (landmark.z,)
        base = landmark.position.reshape(1, 2)
    elif isinstance(landmark, GroundLineLandmark):
        levels = (0.0,)
        base = np.vstack([landmark.start, landmark.end])
    else:
        raise InputError(
            "landmark: expected a VerticalLineLandmark, PointLandmark or GroundLineLandmark, "
            f"got {type(landmark).__name__}"
        )
    radius = landmark.position_uncertainty
    if radius > 0.0:
        base = minkowski_sum(base, outer_disk(np.zeros(2), radius, _DISK_SIDES))
    return np.asarray(base, dtype=np.float64), levels


def _relative_ground(map: SpatialUncertaintyMap, ground: Array) -> Array:
    """Return robot-frame points (m) whose convex hull holds R(-h)(q - p) for all q, p, h."""
    difference = minkowski_sum(ground, -np.asarray(map.polygon.vertices))
    wedge = map.wedge
    if wedge.is_full_circle:
        reach = float(np.max(np.hypot(difference[:, 0], difference[:, 1])))
        return outer_disk(np.zeros(2), reach, math.ceil(2.0 * math.pi / _ARC_STEP))
    h_lo = wedge.center - wedge.cw
    h_hi = h_lo + wedge.width
    ends = [_rotate(difference, -h_lo)]
    if wedge.width > 0.0:
        ends.append(_rotate(difference, -h_hi))
        count = max(1, math.ceil(wedge.width / _ARC_STEP))
        half = wedge.width / (2 * count)
        radius = np.hypot(difference[:, 0], difference[:, 1]) / math.cos(half)
        phase = np.arctan2(difference[:, 1], difference[:, 0])
        # Rotating by -h for h in [h_lo, h_hi] sweeps phase - h_hi .. phase - h_lo.
        middle = (phase - h_hi)[:, None] + ((2 * np.arange(count) + 1) * half)[None, :]
        ends.append(
            np.column_stack(
                [(radius[:, None] * np.cos(middle)).ravel(), (radius[:, None] * np.sin(middle)).ravel()]
            )
        )
    return np.concatenate(ends)


def _rotate(points: Array, angle: float) -> Array:
    c, s = math.cos(angle), math.sin(angle)
    return np.column_stack([c * points[:, 0] - s * points[:, 1], s * points[:, 0] + c * points[:, 1]])


def _clip_to_front(camera: Camera, ground: Array, levels: tuple[float, ...]) -> Array | None:
    """Return camera-frame points (m) spanning the polytope's part in front of the cut plane."""
    mount = camera.mount
    rotation = mount.rotation()  # robot vector @ rotation -> camera vector
    planar = np.column_stack([ground[:, 0] - mount.forward, ground[:, 1] - mount.left, np.zeros(len(ground))])
    base = planar @ rotation
    up = rotation[2]
    depth_lo = base[:, 2] + min(level - mount.height for level in levels) * up[2]
    depth_hi = base[:, 2] + max(level - mount.height for level in levels) * up[2]
    nearest = np.minimum(depth_lo, depth_hi)
    farthest = np.maximum(depth_lo, depth_hi)
    if float(farthest.max()) <= _CUT_PLANE:
        return None
    if float(nearest.min()) >= _CUT_PLANE:
        return np.concatenate([base + (level - mount.height) * up for level in levels])
    # Part of the polytope is behind: cut it, using its known edges (a prism over the hull).
    hull = convex_hull(ground)
    planar = np.column_stack([hull[:, 0] - mount.forward, hull[:, 1] - mount.left, np.zeros(len(hull))])
    base = planar @ rotation
    layers = [base + (level - mount.height) * up for level in levels]
    starts: list[Array] = []
    stops: list[Array] = []
    if len(hull) >= 2:
        for layer in layers:
            starts.append(layer)
            stops.append(np.roll(layer, -1, axis=0))
    if len(layers) == 2:
        starts.append(layers[0])
        stops.append(layers[1])
    vertices = np.concatenate(layers)
    front = vertices[vertices[:, 2] >= _CUT_PLANE]
    if not starts:
        return front if len(front) else None
    a = np.concatenate(starts)
    b = np.concatenate(stops)
    crossing = (a[:, 2] - _CUT_PLANE) * (b[:, 2] - _CUT_PLANE) < 0.0
    a, b = a[crossing], b[crossing]
    t = (_CUT_PLANE - a[:, 2]) / (b[:, 2] - a[:, 2])
    cut = a + t[:, None] * (b - a)
    cut[:, 2] = _CUT_PLANE
    points = np.concatenate([front, cut])
    return points if len(points) else None


def _outward(value: float, direction: float) -> float:
    """Push a bound outward by the rounding slack; keep it finite (NaN and inf saturate)."""
    if math.isnan(value) or math.isinf(value):
        return direction * UNBOUNDED_PIXELS
    widened = value + direction * (_RELATIVE_SLACK * abs(value) + _ABSOLUTE_SLACK)
    if math.isinf(widened):
        return direction * UNBOUNDED_PIXELS
    return widened
