"""The pinhole camera on its mount: frames, rotation and projection.

Frames (DESIGN §1): world x east, y north, z up; robot x forward, y left, z up;
camera as OpenCV (x right, y down, z forward). Pixel (0, 0) is the centre of the
top-left pixel.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import (
    ANGLE,
    DISTORTION,
    FOCAL_LENGTH,
    IMAGE_SIDE,
    PIXEL,
    SENSOR_OFFSET,
    Range,
    finite_float,
    float_array,
    number_array,
)
from aura_ums.errors import InputError
from aura_ums.geometry import Pose

#: Points closer to the camera plane than this (m, along the optical axis) count as behind it.
NEAR_PLANE = 1e-6

Array = NDArray[np.float64]


def robot_from_camera_rotation(pan: float, tilt: float) -> Array:
    """Return the 3x3 rotation whose columns are the camera's x, y, z axes in the robot frame.

    ``pan`` turns the camera counter-clockwise (to the robot's left) and ``tilt``
    points the optical axis below the horizon, both radians.

    Examples
    --------
    >>> robot_from_camera_rotation(0.0, 0.0)[:, 2].tolist()   # optical axis: robot forward
    [1.0, 0.0, 0.0]
    >>> robot_from_camera_rotation(float("nan"), 0.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: pan: expected a finite number, got nan
    """
    return _robot_from_camera_rotation(ANGLE.check(pan, "pan"), ANGLE.check(tilt, "tilt"))


def _robot_from_camera_rotation(pan: float, tilt: float) -> Array:
    """:func:`robot_from_camera_rotation` of checked angles (:meth:`CameraMount.rotation`, per projection)."""
    ct, st = math.cos(tilt), math.sin(tilt)
    cp, sp = math.cos(pan), math.sin(pan)
    right = np.array([0.0, -1.0, 0.0])
    down = np.array([-st, 0.0, -ct])
    forward = np.array([ct, 0.0, -st])
    pan_rotation = np.array([[cp, -sp, 0.0], [sp, cp, 0.0], [0.0, 0.0, 1.0]])
    return np.asarray(pan_rotation @ np.column_stack([right, down, forward]), dtype=np.float64)


#: Largest normalized coordinate (x/z or y/z, the tangent of the angle off the optical axis)
#: :func:`distort` takes: no fold lies farther out (``_FOLD_HORIZON``), and up to it the
#: polynomial stays far from overflow (about 1e213 with every coefficient at 1000).
NORMALIZED = Range(-1e30, 1e30)
#: Largest camera-frame coordinate :meth:`Camera.project_camera_frame` takes, metres: five
#: times the diagonal of the world's square (:data:`~aura_ums._validate.COORDINATE`); 1e300
#: overflowed the pixels.
CAMERA_COORDINATE = Range(-1e7, 1e7, "m")


def _coefficients(value: ArrayLike, name: str) -> tuple[float, float, float, float, float]:
    """Return distortion coefficients as (k1, k2, p1, p2, k3), checked as :class:`CameraIntrinsics` does."""
    if value is None or isinstance(value, (str, bytes)):
        raise InputError(f"{name}: expected 4, 5, 8, 12 or 14 distortion coefficients, got {value!r}")
    return opencv_distortion(float_array(value, name), name)


def distort(
    x: ArrayLike, y: ArrayLike, coefficients: tuple[float, float, float, float, float]
) -> tuple[Array, Array]:
    """Apply OpenCV's radial-tangential distortion (k1, k2, p1, p2, k3) to normalized coordinates.

    ``x`` and ``y`` (the same shape) are finite, each in [-1e30, 1e30] (no lens folds
    farther out); ``coefficients`` are checked as :attr:`CameraIntrinsics.distortion` is.

    Examples
    --------
    >>> x, y = np.array([0.0, 0.5]), np.array([0.0, 0.0])
    >>> [v.tolist() for v in distort(x, y, (-0.1, 0.0, 0.0, 0.0, 0.0))]   # barrel: the edge moves in
    [[0.0, 0.4875], [0.0, 0.0]]
    >>> [v.tolist() for v in distort(x, y, (0.0, 0.0, 0.0, 0.0, 0.0))]    # all zero: unchanged
    [[0.0, 0.5], [0.0, 0.0]]
    >>> distort(x, y, None)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: coefficients: expected 4, 5, 8, 12 or 14 distortion coefficients, got None
    """
    k = _coefficients(coefficients, "coefficients")
    xs, ys = _normalized(x, "x"), _normalized(y, "y")
    if xs.shape != ys.shape:
        raise InputError(f"y: expected the shape of x {xs.shape}, got {ys.shape}")
    return _distort(xs, ys, k)


def _normalized(value: ArrayLike, name: str) -> Array:
    """Return finite normalized coordinates in :data:`NORMALIZED`, or raise naming ``name``."""
    array = float_array(value, name)
    if np.any(np.abs(array) > NORMALIZED.high):
        raise InputError(
            f"{name}: expected coordinates {NORMALIZED.text()}, got {float(np.max(np.abs(array)))!r}"
        )
    return array


def _distort(
    x: Array, y: Array, coefficients: tuple[float, float, float, float, float]
) -> tuple[Array, Array]:
    """:func:`distort` of trusted arrays and coefficients (the projections, per frame)."""
    k1, k2, p1, p2, k3 = coefficients
    r2 = x * x + y * y
    radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
    xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x)
    yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y
    return xd, yd


#: Folds farther out than this radius are reported as none: a point in front of the near
#: plane (z > NEAR_PLANE) that far out lies more than 1e24 m off the optical axis.
_FOLD_HORIZON = 1e30
#: The search for the fold stops at intervals this narrow (relative): the radius returned is
#: at most this far inside the fold, for a simple root.
_FOLD_RESOLUTION = 2.0**-40
#: An interval's lower bound counts as positive above this fraction of its terms' size (rounding).
_FOLD_ROUNDING = 1e-13


def fold_radius(distortion: tuple[float, float, float, float, float] | None) -> float:
    r"""Return the normalized radius within which the lens is one-to-one: the rays the camera images.

    OpenCV's radial factor makes the image radius ``r (1 + k1 r^2 + k2 r^4 + k3 r^6)`` of a
    ray at normalized radius ``r = hypot(x/z, y/z)``; past the first positive root of its
    derivative ``1 + 3 k1 r^2 + 5 k2 r^4 + 7 k3 r^6`` the polynomial folds back and maps
    farther rays onto the pixels of nearer ones. A camera of this model images the rays with
    ``r <= fold_radius`` and no others: :meth:`Camera.project_camera_frame` gives NaN beyond
    (as behind the camera), :func:`~aura_ums.camera.undistort_points` inverts pixels only to
    rays within, and the schemas' projections and the simulator's renderer read this radius.

    Within it :func:`distort` is one-to-one. Its Jacobian is symmetric (the map is a
    gradient); in the basis (radial, tangential) the radial terms give eigenvalues
    ``1 + 3 k1 r^2 + 5 k2 r^4 + 7 k3 r^6`` and ``1 + k1 r^2 + k2 r^4 + k3 r^6``, and the
    tangential terms ``2 q x^T + 2 x q^T + 2 (q . x) I`` (``q = (p2, p1)``) add a matrix whose
    eigenvalues are ``2 |q| r (2 cos b +- 1)``, at least ``-6 |q| r``. So the Jacobian is
    positive definite on the disk where both

    .. math:: 1 - 6 |q| r + k_1 r^2 + k_2 r^4 + k_3 r^6 > 0, \qquad
              1 - 6 |q| r + 3 k_1 r^2 + 5 k_2 r^4 + 7 k_3 r^6 > 0,

    and the radius returned is the first positive root of either (infinite when neither has
    one). On that disk (convex) ``(d(a) - d(b)) . (a - b) > 0`` for ``a != b``: no two rays
    share a pixel. With ``p1 = p2 = 0`` it is exactly the radial fold (the second polynomial's
    root comes first: the first is ``1/r`` times the integral of the second); tangential
    terms move it inwards by about ``6 |q| r`` over the slope there, a sufficient bound, not
    the exact edge of the one-to-one region.

    Parameters
    ----------
    distortion : tuple of 5 floats, or None
        OpenCV's (k1, k2, p1, p2, k3) (as :attr:`CameraIntrinsics.distortion`); None for an
        ideal pinhole.

    Returns
    -------
    float
        The radius (dimensionless: the tangent of the angle off the optical axis), > 0;
        ``math.inf`` when the lens never folds.

    Raises
    ------
    InputError
        For coefficients :class:`CameraIntrinsics` would refuse.

    Examples
    --------
    >>> round(fold_radius((-0.14, 0.0, 0.0, 0.0, 0.0)), 6)   # 1 - 0.42 r^2 = 0: 57 degrees off axis
    1.543033
    >>> fold_radius((0.1, 0.01, 0.0, 0.0, 0.0)), fold_radius(None)   # pincushion, pinhole: never folds
    (inf, inf)
    """
    if distortion is None:
        return math.inf
    try:
        return _fold_radius(distortion)
    except TypeError:  # unhashable (a list, an array): the same values as a tuple
        return _fold_radius(tuple(float_array(distortion, "distortion").reshape(-1).tolist()))


def within_fold(
    x: ArrayLike, y: ArrayLike, distortion: tuple[float, float, float, float, float] | None
) -> NDArray[np.bool_]:
    """Tell which normalized rays ``(x/z, y/z)`` the camera images: those within :func:`fold_radius`.

    The one test of what a distorted camera sees (:meth:`Camera.project_camera_frame`, the
    pixel observers, the simulator's renderer). NaN coordinates are not imaged.

    Examples
    --------
    >>> within_fold([0.0, 1.5, 1.6, np.nan], [0.0, 0.0, 0.0, 0.0], (-0.14, 0.0, 0.0, 0.0, 0.0)).tolist()
    [True, True, False, False]
    >>> within_fold([1e200], [0.0], None).tolist()   # a pinhole images every ray in front of it
    [True]
    >>> within_fold(None, [0.1], None)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: x: expected numbers, got None
    """
    limit = fold_radius(distortion)
    xs, ys = number_array(x, "x"), number_array(y, "y")
    if xs.shape != ys.shape:
        raise InputError(f"y: expected the shape of x {xs.shape}, got {ys.shape}")
    return _within_fold(xs, ys, limit)


def _within_fold(xs: Array, ys: Array, limit: float) -> NDArray[np.bool_]:
    """:func:`within_fold` of float arrays of one shape and a :func:`fold_radius` (per projection)."""
    with np.errstate(over="ignore", invalid="ignore"):
        return np.asarray(xs * xs + ys * ys <= limit * limit)


@functools.lru_cache(maxsize=256)
def _fold_radius(distortion: tuple[float, ...]) -> float:
    """:func:`fold_radius` of a hashable vector, cached (every projection of a camera asks for it)."""
    k1, k2, p1, p2, k3 = opencv_distortion(float_array(distortion, "distortion"), "distortion")
    tangential = -6.0 * math.hypot(p1, p2)
    return min(
        _first_zero(((1, tangential), (2, k1), (4, k2), (6, k3))),
        _first_zero(((1, tangential), (2, 3.0 * k1), (4, 5.0 * k2), (6, 7.0 * k3))),
    )


def _first_zero(terms: tuple[tuple[int, float], ...]) -> float:
    """Return a radius ``R`` with ``1 + sum(c r^i) > 0`` proved on ``[0, R)``, just below the first zero.

    ``terms`` are (power >= 1, coefficient). Intervals of r are proved positive by interval
    arithmetic (each power is monotone for r > 0: positive terms at the interval's left end,
    negative ones at its right end), left to right, doubling outwards; the left end of the
    first interval that cannot be proved positive at width ``_FOLD_RESOLUTION`` is returned.
    Unlike the companion matrix's roots, this cannot lose a root to bad scaling: it can only
    stop early, which moves the fold inwards. ``math.inf`` when no zero lies below
    ``_FOLD_HORIZON``.
    """
    live = [(power, c) for power, c in terms if c != 0.0]
    if all(c > 0.0 for _, c in live):
        return math.inf  # 1 plus positive terms never vanishes (no terms: the constant 1)
    # Below this radius every term is smaller than 1 / len(live): the sum stays positive.
    log_start = min(-(math.log(len(live)) + math.log(abs(c))) / power for power, c in live)
    if log_start >= math.log(_FOLD_HORIZON):
        return math.inf
    a = math.exp(log_start)
    while a < _FOLD_HORIZON:
        stack = [(a, 2.0 * a)]
        while stack:
            lo, hi = stack.pop()
            positive, negative = 1.0, 0.0
            for power, c in live:
                if c > 0.0:
                    positive += c * lo**power
                else:
                    negative += c * hi**power
            if positive + negative > _FOLD_ROUNDING * (positive - negative):
                continue  # proved positive on [lo, hi]
            if hi - lo <= _FOLD_RESOLUTION * lo:
                return lo
            middle = 0.5 * (lo + hi)
            stack += [(middle, hi), (lo, middle)]  # the left half first
        a *= 2.0
    return math.inf


#: The lengths of OpenCV's distortion vector: (k1, k2, p1, p2[, k3[, k4, k5, k6[, s1-s4[, taux, tauy]]]]).
DISTORTION_LENGTHS = (4, 5, 8, 12, 14)


def opencv_distortion(values: Array, where: str) -> tuple[float, float, float, float, float]:
    """Return OpenCV's distortion vector as (k1, k2, p1, p2, k3); refuse terms aura-ums does not model.

    ``values`` are finite floats (any shape: flattened); ``where`` names them in messages.
    """
    flat = values.reshape(-1)
    if flat.size not in DISTORTION_LENGTHS:
        raise InputError(f"{where}: expected 4, 5, 8, 12 or 14 distortion coefficients, got {flat.size}")
    if flat.size > 5 and np.any(flat[5:] != 0.0):
        raise InputError(
            f"{where}: expected the coefficients beyond k3 (k4-k6, s1-s4, tau) to be zero (aura-ums models "
            f"k1, k2, p1, p2, k3 only), got {flat[5:].tolist()}"
        )
    k = [DISTORTION.check(float(c), f"{where}[{index}]") for index, c in enumerate(flat[:5].tolist())]
    k += [0.0] * (5 - len(k))
    return (k[0], k[1], k[2], k[3], k[4])


@dataclass(frozen=True, slots=True)
class CameraIntrinsics:
    """Pinhole intrinsics, in pixels, with optional OpenCV distortion.

    Parameters
    ----------
    fx, fy : float
        Focal lengths, pixels, in [1, 1e6].
    cx, cy : float
        Principal point, pixels ((0, 0) is the centre of the top-left pixel), in [-1e5, 1e5].
    width, height : int
        Image size, pixels, in [1, 20000].
    distortion : sequence of 4, 5, 8, 12 or 14 floats, optional
        OpenCV's distortion vector (k1, k2, p1, p2[, k3[, k4, k5, k6[, s1-s4[, taux, tauy]]]]),
        each in [-1000, 1000], kept as (k1, k2, p1, p2, k3) (k3 = 0 when absent); the terms
        beyond k3 must be zero. None for an ideal pinhole.

    Examples
    --------
    >>> CameraIntrinsics(500, 500, 320, 240, 640, 480, distortion=(-0.1, 0.01, 0.0, 0.0)).distortion
    (-0.1, 0.01, 0.0, 0.0, 0.0)
    >>> CameraIntrinsics(500, 500, 320, 240, 640, 480, distortion=(0.1, 0.0, 0.0))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: CameraIntrinsics.distortion: expected 4, 5, 8, 12 or 14 ..., got 3
    """

    fx: float
    fy: float
    cx: float
    cy: float
    width: int
    height: int
    distortion: tuple[float, float, float, float, float] | None = None

    def __post_init__(self) -> None:
        # The camera file's ranges (camera/_io.py reads the same ones), for intrinsics built in code.
        for name in ("fx", "fy"):
            object.__setattr__(
                self, name, FOCAL_LENGTH.check(getattr(self, name), f"CameraIntrinsics.{name}")
            )
        for name in ("cx", "cy"):
            object.__setattr__(self, name, PIXEL.check(getattr(self, name), f"CameraIntrinsics.{name}"))
        for name in ("width", "height"):
            value = getattr(self, name)
            if (
                isinstance(value, bool)
                or not isinstance(value, (int, np.integer))
                or not IMAGE_SIDE.contains(float(value))
            ):
                raise InputError(
                    f"CameraIntrinsics.{name}: expected an integer in {IMAGE_SIDE.interval()}, got {value!r}"
                )
            object.__setattr__(self, name, int(value))
        if self.distortion is not None:
            distortion = float_array(self.distortion, "CameraIntrinsics.distortion")
            object.__setattr__(
                self, "distortion", opencv_distortion(distortion, "CameraIntrinsics.distortion")
            )

    def matrix(self) -> Array:
        """Return the 3x3 camera matrix K."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])


@dataclass(frozen=True, slots=True)
class CameraMount:
    """Where the camera sits on the robot and where it points.

    Parameters
    ----------
    height : float
        Optical centre above the ground plane, metres, in [0, 100].
    forward, left : float
        Optical centre's offset from the robot's reference point, metres (robot frame), in
        [-100, 100].
    pan : float
        Radians, counter-clockwise positive (towards the robot's left), in [-1000, 1000].
    tilt : float
        Radians, positive when the optical axis points below the horizon; |tilt| < pi/2.

    Examples
    --------
    >>> mount = CameraMount(1.2, forward=0.3, tilt=math.radians(5.0))
    >>> mount.sensor_offset, mount.rotation()[:, 2].round(4).tolist()   # optical axis: a little down
    ((0.3, 0.0), [0.9962, 0.0, -0.0872])
    >>> CameraMount(1.2, tilt=math.pi / 2)   # looking straight down: no horizon in view
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: CameraMount.tilt: expected |tilt| < pi/2, got 1.5707963267948966
    """

    height: float
    forward: float = 0.0
    left: float = 0.0
    pan: float = 0.0
    tilt: float = 0.0

    def __post_init__(self) -> None:
        # The camera file's ranges (camera/_io.py reads the same ones), for a mount built in code.
        for name in ("forward", "left"):
            object.__setattr__(self, name, SENSOR_OFFSET.check(getattr(self, name), f"CameraMount.{name}"))
        for name in ("pan", "tilt"):
            object.__setattr__(self, name, ANGLE.check(getattr(self, name), f"CameraMount.{name}"))
        object.__setattr__(self, "height", finite_float(self.height, "CameraMount.height"))
        if self.height < 0.0:
            # below the ground plane every landmark's foot is above the camera: all windows were empty
            raise InputError(
                f"CameraMount.height: expected a height >= 0 m above the ground, got {self.height}"
            )
        if self.height > SENSOR_OFFSET.high:
            raise InputError(
                f"CameraMount.height: expected a height <= {SENSOR_OFFSET.high:g} m above the ground, "
                f"got {self.height}"
            )
        if abs(self.tilt) >= math.pi / 2:
            raise InputError(f"CameraMount.tilt: expected |tilt| < pi/2, got {self.tilt}")

    @property
    def sensor_offset(self) -> tuple[float, float]:
        """(forward, left) of the optical centre in the robot frame, metres."""
        return (self.forward, self.left)

    def rotation(self) -> Array:
        """Rotation from camera to robot axes (columns: camera x, y, z in the robot frame)."""
        return _robot_from_camera_rotation(self.pan, self.tilt)


@dataclass(frozen=True, slots=True)
class Camera:
    """A calibrated camera on its mount.

    Examples
    --------
    >>> camera = Camera(CameraIntrinsics(500, 500, 320, 240, 640, 480), CameraMount(height=1.0))
    >>> camera.project(Pose(0, 0, 0), [(10.0, 0.0, 1.0), (-10.0, 0.0, 1.0)]).tolist()
    [[320.0, 240.0], [nan, nan]]
    """

    intrinsics: CameraIntrinsics
    mount: CameraMount

    def __post_init__(self) -> None:
        if not isinstance(self.intrinsics, CameraIntrinsics):
            raise InputError(f"intrinsics: expected CameraIntrinsics, got {type(self.intrinsics).__name__}")
        if not isinstance(self.mount, CameraMount):
            raise InputError(f"mount: expected CameraMount, got {type(self.mount).__name__}")

    def to_camera_frame(self, poses: ArrayLike, points_world: ArrayLike) -> Array:
        """Return world points in the camera frame for each robot pose.

        Parameters
        ----------
        poses : array_like, shape (m, 3) or (3,)
            Robot poses: x (m), y (m), heading (rad).
        points_world : array_like, shape (n, 3)
            World points, metres.

        Returns
        -------
        ndarray, shape (m, n, 3)
            Camera-frame coordinates (x right, y down, z forward), metres.
        """
        state = float_array(poses, "poses")
        if state.shape[-1:] != (3,) or state.ndim > 2:
            raise InputError(f"poses: expected x, y and heading of shape (3,) or (m, 3), got {state.shape}")
        return self._to_camera_frame(state.reshape(-1, 3), points_world)

    def _to_camera_frame(self, state: Array, points_world: ArrayLike) -> Array:
        """:meth:`to_camera_frame` of checked poses ``(m, 3)``; checks the points."""
        points = float_array(points_world, "points_world")
        if points.ndim != 2 or points.shape[1] != 3:
            raise InputError(f"points_world: expected shape (n, 3), got {points.shape}")
        cos_h = np.cos(state[:, 2])[:, None]
        sin_h = np.sin(state[:, 2])[:, None]
        dx = points[None, :, 0] - state[:, 0, None]
        dy = points[None, :, 1] - state[:, 1, None]
        robot = np.empty((len(state), len(points), 3))
        robot[..., 0] = cos_h * dx + sin_h * dy - self.mount.forward
        robot[..., 1] = -sin_h * dx + cos_h * dy - self.mount.left
        robot[..., 2] = points[None, :, 2] - self.mount.height
        return np.asarray(robot @ self.mount.rotation(), dtype=np.float64)

    def project_camera_frame(self, points_camera: ArrayLike) -> Array:
        """Project camera-frame points ``(..., 3)`` to pixels ``(..., 2)``; NaN where not imaged.

        A point is imaged when it is in front of the camera (``z > NEAR_PLANE``) and, with
        lens distortion, its ray lies within the lens's fold (``(x/z)^2 + (y/z)^2 <=
        fold_radius^2``, :func:`fold_radius`): beyond it the distortion polynomial folds
        back onto the pixels of nearer rays, which this camera does not model.

        ``points_camera`` are finite metres, each coordinate within 1e7 m
        ([-1e7, 1e7] m).

        Examples
        --------
        >>> lens = CameraIntrinsics(300, 300, 320, 240, 640, 480, distortion=(-0.14, 0, 0, 0, 0))
        >>> camera = Camera(lens, CameraMount(height=1.0))
        >>> camera.project_camera_frame([(0.0, 0.0, 5.0), (0.0, 0.0, -5.0)]).tolist()   # behind: NaN
        [[320.0, 240.0], [nan, nan]]
        >>> camera.project_camera_frame([(1.5, 0.0, 1.0), (1.6, 0.0, 1.0)]).round(1).tolist()   # fold: 1.543
        [[628.2, 240.0], [nan, nan]]
        >>> camera.project_camera_frame([(1.0, 2.0)])
        Traceback (most recent call last):
        ...
        aura_ums.errors.InputError: points_camera: expected shape (..., 3), got (1, 2)
        """
        pts = float_array(points_camera, "points_camera")
        if pts.ndim == 0 or pts.shape[-1] != 3:
            raise InputError(f"points_camera: expected shape (..., 3), got {pts.shape}")
        if np.any(np.abs(pts) > CAMERA_COORDINATE.high):
            raise InputError(
                f"points_camera: expected coordinates {CAMERA_COORDINATE.text()}, "
                f"got {float(np.max(np.abs(pts)))!r}"
            )
        return self._project_camera_frame(pts)

    def _project_camera_frame(self, pts: Array) -> Array:
        """:meth:`project_camera_frame` of a trusted float array ``(..., 3)`` (:meth:`project`, per frame)."""
        z = pts[..., 2]
        in_front = z > NEAR_PLANE
        with np.errstate(invalid="ignore", divide="ignore"):
            x = np.where(in_front, pts[..., 0] / z, np.nan)
            y = np.where(in_front, pts[..., 1] / z, np.nan)
        k = self.intrinsics
        if k.distortion is not None:
            imaged = _within_fold(x, y, fold_radius(k.distortion))  # behind the camera: NaN, not imaged
            x, y = np.where(imaged, x, np.nan), np.where(imaged, y, np.nan)
            x, y = _distort(x, y, k.distortion)
        return np.asarray(np.stack([k.fx * x + k.cx, k.fy * y + k.cy], axis=-1), dtype=np.float64)

    def project(self, pose: Pose | ArrayLike, points_world: ArrayLike) -> Array:
        """Project world points ``(n, 3)`` (m) seen from a robot pose to pixels ``(n, 2)``.

        Points the camera does not image give NaN: behind it, or beyond the lens's fold
        (:meth:`project_camera_frame`). ``pose`` may also be an ``(m, 3)`` array of
        poses, giving an ``(m, n, 2)`` array.
        """
        if isinstance(pose, Pose):
            pixels = self._project_camera_frame(self._to_camera_frame(pose.as_array()[None, :], points_world))
            return np.asarray(pixels[0], dtype=np.float64)
        state = float_array(pose, "pose")
        if state.shape[-1:] != (3,) or state.ndim > 2:
            raise InputError(
                f"pose: expected a Pose, or x, y and heading of shape (3,) or (m, 3), got {state.shape}"
            )
        pixels = self._project_camera_frame(self._to_camera_frame(state.reshape(-1, 3), points_world))
        return np.asarray(pixels[0] if state.ndim == 1 else pixels, dtype=np.float64)
