"""Pixels turned into bounded measurements of the three landmark classes.

The camera knows a *nominal* calibration and, in :class:`CalibrationBounds`, how far each
calibrated parameter may be off; it is told how far a measured pixel may be off
(``pixel_error``). Every bearing, range, offset and angle it returns carries an error
bound that holds for *every* camera and pixel within those bounds (a set-membership
bound, not a standard deviation), so that the reductions of the spatial uncertainty map
stay sound. The observers of :mod:`aura_ums.expecter` attach them to a landmark as
observations.

Error propagation
-----------------
The bounds are computed with interval arithmetic on the parameter box, arranged so that
every step is either exact or an outer enclosure:

1. Normalized distorted coordinates ``xd = (u - cx) / fx``, ``yd = (v - cy) / fy``: each
   variable appears once, so the interval result is the exact range over the box
   (``|du|, |dv| <= pixel_error``: the pixel error is a square, which contains the disk).
2. Undistortion: the set of undistorted points whose distortion falls in that box is
   enclosed by the Krawczyk interval-Newton operator (an enclosure of every solution of
   ``distort(x) = b`` for every ``b`` in the box, with existence and uniqueness in the
   enclosing box proved by ``K(X) ⊂ X``).
3. From the undistorted (x, y) the ray in the robot frame is summarized by two numbers:
   ``psi = tilt + atan(y)``, the depression of the ray's projection on the camera's
   vertical plane, and ``w = x / sqrt(1 + y^2)``. The azimuth of the ray (before pan) is
   ``atan2(-w, cos psi)`` and, for a plane ``delta`` metres below the optical centre, the
   ray meets it at forward ``delta * cot psi``, left ``-delta * w / sin psi``, horizontal
   range ``|delta| * sqrt((1 + w^2) / sin^2 psi - 1)``. Each of these is evaluated with
   monotone interval functions (range: increasing in ``w^2``, decreasing in
   ``sin^2 psi``; azimuth: extreme at a corner of the (w, cos psi) box, which is convex
   and, unless it holds the origin, spans less than half a turn).
4. Pan only rotates, camera height only scales: both are applied exactly at the end.
5. Ground lines (Class III) use one enclosure per end; the calibration parameters the two
   ends share (fx, fy, cx, cy, tilt) are split into sub-boxes so that the decorrelation
   costs little, and the direction is split into pieces in which the two ends must agree
   on the line's offset (an exact test for boxes of points).

Floating-point rounding is not directed; it is covered by a documented safety margin:
every error bound is multiplied by ``1 + _SAFETY_RELATIVE`` and increased by
``_SAFETY_ABSOLUTE`` (radians or metres), and intermediate boxes are padded by ``1e-12``.

The camera images only the rays within the lens's fold (:func:`~aura_ums.camera.fold_radius`),
where the distortion is proved one-to-one: a pixel is inverted to the one ray within the fold
that reaches it (NaN, or an error, where none does), and an enclosure is kept only when its
box lies within the fold, so that the unique solution it proves is that ray.

Assumptions: the distortion coefficients and the mount's ``forward``/``left`` are exact;
the landmark is where the landmark says (its own ``position_uncertainty`` is for the
reduction to handle).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import HEIGHT, PIXEL, Range, finite_float, nonnegative_float, points_array
from aura_ums.camera._model import Camera, CameraIntrinsics, _distort, _within_fold, fold_radius
from aura_ums.errors import InputError
from aura_ums.geometry import wrap_angle

Array = NDArray[np.float64]
Coefficients = tuple[float, float, float, float, float]

#: A bound on a pixel's error, pixels: up to the span of any pixel coordinate (:data:`PIXEL`):
#: beyond it a bound says nothing of the pixel, and 1e300 px overflowed the bounds.
PIXEL_ERROR = Range(0.0, PIXEL.high, "px")

#: Every error bound is multiplied by ``1 + _SAFETY_RELATIVE`` ...
_SAFETY_RELATIVE = 1e-6
#: ... and increased by ``_SAFETY_ABSOLUTE`` (rad or m) to cover floating-point rounding.
_SAFETY_ABSOLUTE = 1e-9
#: Fixed-point iterations of the undistortion (as cv::undistortPoints' default criteria).
_UNDISTORT_ITERATIONS = 20
#: Largest accepted residual of the undistortion, normalized image units (about 1e-7 px).
_UNDISTORT_TOLERANCE = 1e-10
#: Splits per shared calibration parameter when bounding a ground line.
_GROUND_LINE_SPLITS = 3
_ANGLE_PIECES = 12
_NEWTON_STEPS = 8
_KRAWCZYK_STEPS = 12
_PAD = 1e-12


# --------------------------------------------------------------------------- intervals


@dataclass(frozen=True, slots=True)
class _Interval:
    """Element-wise intervals [lo, hi] over numpy arrays (no directed rounding)."""

    lo: Array
    hi: Array

    # numpy must hand ``array - interval`` to the interval's reflected operators
    __array_ufunc__ = None

    @staticmethod
    def around(center: ArrayLike, radius: ArrayLike) -> _Interval:
        c = np.asarray(center, dtype=np.float64)
        r = np.asarray(radius, dtype=np.float64)
        return _Interval(c - r, c + r)

    @staticmethod
    def point(value: ArrayLike) -> _Interval:
        v = np.asarray(value, dtype=np.float64)
        return _Interval(v, v)

    @property
    def mid(self) -> Array:
        return np.asarray(0.5 * (self.lo + self.hi), dtype=np.float64)

    @property
    def rad(self) -> Array:
        return np.asarray(0.5 * (self.hi - self.lo), dtype=np.float64)

    def __add__(self, other: _Interval | float | Array) -> _Interval:
        if isinstance(other, _Interval):
            return _Interval(self.lo + other.lo, self.hi + other.hi)
        return _Interval(self.lo + other, self.hi + other)

    def __radd__(self, other: float | Array) -> _Interval:
        return self + other

    def __neg__(self) -> _Interval:
        return _Interval(-self.hi, -self.lo)

    def __sub__(self, other: _Interval | float | Array) -> _Interval:
        return self + (-other)

    def __rsub__(self, other: float | Array) -> _Interval:
        return (-self) + other

    def __mul__(self, other: _Interval | float | Array) -> _Interval:
        if isinstance(other, _Interval):
            products = (self.lo * other.lo, self.lo * other.hi, self.hi * other.lo, self.hi * other.hi)
            return _Interval(np.minimum.reduce(products), np.maximum.reduce(products))
        a, b = self.lo * other, self.hi * other
        return _Interval(np.minimum(a, b), np.maximum(a, b))

    def __rmul__(self, other: float | Array) -> _Interval:
        return self * other

    def __truediv__(self, other: _Interval) -> _Interval:
        """Divide by an interval that excludes zero (callers guarantee it)."""
        return self * _Interval(1.0 / other.hi, 1.0 / other.lo)

    def sqr(self) -> _Interval:
        a, b = self.lo * self.lo, self.hi * self.hi
        low = np.where((self.lo <= 0.0) & (self.hi >= 0.0), 0.0, np.minimum(a, b))
        return _Interval(low, np.maximum(a, b))

    def abs(self) -> _Interval:
        a, b = np.abs(self.lo), np.abs(self.hi)
        low = np.where((self.lo <= 0.0) & (self.hi >= 0.0), 0.0, np.minimum(a, b))
        return _Interval(low, np.maximum(a, b))

    def padded(self, pad: float | Array) -> _Interval:
        return _Interval(self.lo - pad, self.hi + pad)

    def intersect(self, other: _Interval) -> _Interval:
        return _Interval(np.maximum(self.lo, other.lo), np.minimum(self.hi, other.hi))

    def contains_zero(self) -> NDArray[np.bool_]:
        return np.asarray((self.lo <= 0.0) & (self.hi >= 0.0))


def _isin(x: _Interval) -> _Interval:
    """Exact range of sin over each interval."""
    s_lo, s_hi = np.sin(x.lo), np.sin(x.hi)
    low, high = np.minimum(s_lo, s_hi), np.maximum(s_lo, s_hi)
    peak = math.pi / 2 + 2 * math.pi * np.ceil((x.lo - math.pi / 2) / (2 * math.pi))
    trough = -math.pi / 2 + 2 * math.pi * np.ceil((x.lo + math.pi / 2) / (2 * math.pi))
    return _Interval(np.where(trough <= x.hi, -1.0, low), np.where(peak <= x.hi, 1.0, high))


def _icos(x: _Interval) -> _Interval:
    """Exact range of cos over each interval."""
    c_lo, c_hi = np.cos(x.lo), np.cos(x.hi)
    low, high = np.minimum(c_lo, c_hi), np.maximum(c_lo, c_hi)
    peak = 2 * math.pi * np.ceil(x.lo / (2 * math.pi))
    trough = math.pi + 2 * math.pi * np.ceil((x.lo - math.pi) / (2 * math.pi))
    return _Interval(np.where(trough <= x.hi, -1.0, low), np.where(peak <= x.hi, 1.0, high))


def _atan2_range(y: _Interval, x: _Interval) -> tuple[Array, Array, Array, NDArray[np.bool_]]:
    """Directions of the points of the boxes ``y x x``: (reference, min, max relative, holds origin).

    A box that excludes the origin is convex and spans less than half a turn, so its
    extreme directions are at corners and lie within (-pi, pi) of its centre's direction.
    """
    reference = np.arctan2(y.mid, x.mid)
    relative = [
        wrap_angle(np.arctan2(yy, xx) - reference) for yy, xx in itertools.product((y.lo, y.hi), (x.lo, x.hi))
    ]
    low = np.minimum.reduce(relative)
    high = np.maximum.reduce(relative)
    return reference, low, high, y.contains_zero() & x.contains_zero()


# ----------------------------------------------------------------------- undistortion


def _distortion_jacobian(
    x: _Interval, y: _Interval, k: Coefficients
) -> tuple[_Interval, _Interval, _Interval, _Interval]:
    """Enclose the Jacobian of :func:`distort` over the boxes ``x x y`` (exact for points)."""
    k1, k2, p1, p2, k3 = k
    x2, y2 = x.sqr(), y.sqr()
    r2 = x2 + y2
    rho = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
    drho = k1 + r2 * (2.0 * k2 + r2 * (3.0 * k3))
    cross = 2.0 * (x * y) * drho + 2.0 * p1 * x + 2.0 * p2 * y
    j00 = rho + 2.0 * x2 * drho + 2.0 * p1 * y + 6.0 * p2 * x
    j11 = rho + 2.0 * y2 * drho + 6.0 * p1 * y + 2.0 * p2 * x
    return j00, cross, cross, j11


def _point_jacobian(x: Array, y: Array, k: Coefficients) -> tuple[Array, Array, Array, Array]:
    """Return the Jacobian of :func:`distort` at points (the same formulas as the interval version)."""
    k1, k2, p1, p2, k3 = k
    x2, y2 = x * x, y * y
    r2 = x2 + y2
    rho = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
    drho = k1 + r2 * (2.0 * k2 + r2 * (3.0 * k3))
    cross = 2.0 * x * y * drho + 2.0 * p1 * x + 2.0 * p2 * y
    j00 = rho + 2.0 * x2 * drho + 2.0 * p1 * y + 6.0 * p2 * x
    j11 = rho + 2.0 * y2 * drho + 6.0 * p1 * y + 2.0 * p2 * x
    return j00, cross, cross, j11


def _undistort_normalized(xd: Array, yd: Array, k: Coefficients, iterations: int) -> tuple[Array, Array]:
    """Invert :func:`distort` point by point; NaN where it finds no ray within the lens's fold."""
    k1, k2, p1, p2, k3 = k
    x, y = xd.copy(), yd.copy()
    with np.errstate(all="ignore"):
        for _ in range(iterations):  # cv::undistortPoints' fixed-point iteration
            r2 = x * x + y * y
            icdist = 1.0 / (1.0 + r2 * (k1 + r2 * (k2 + r2 * k3)))
            dx = 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x)
            dy = p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y
            x_next, y_next = (xd - dx) * icdist, (yd - dy) * icdist
            step = np.max(np.abs(x_next - x) + np.abs(y_next - y), initial=0.0)
            x, y = x_next, y_next
            if not step > 1e-3 * _UNDISTORT_TOLERANCE:  # converged (or NaN: left to the check below)
                break
        fx, fy = _distort(x, y, k)
        for _ in range(_NEWTON_STEPS):  # polish: Newton converges quadratically near the solution
            ex, ey = fx - xd, fy - yd
            if not np.any(np.hypot(ex, ey) > 1e-3 * _UNDISTORT_TOLERANCE):
                break
            j00, j01, j10, j11 = _point_jacobian(x, y, k)
            det = j00 * j11 - j01 * j10
            x, y = x - (j11 * ex - j01 * ey) / det, y - (j00 * ey - j10 * ex) / det
            fx, fy = _distort(x, y, k)
        j00, j01, j10, j11 = _point_jacobian(x, y, k)
        good = (np.hypot(fx - xd, fy - yd) <= _UNDISTORT_TOLERANCE) & (j00 * j11 - j01 * j10 > 0.0)
        good &= _within_fold(x, y, fold_radius(k))  # the rays the camera images (Camera.project_camera_frame)
    return np.where(good, x, np.nan), np.where(good, y, np.nan)


def undistort_points(intrinsics: CameraIntrinsics, pixels: ArrayLike, *, iterations: int = 20) -> Array:
    """Turn pixels into normalized undistorted image coordinates (the inverse of the projection).

    The iterative inverse of OpenCV's radial-tangential model, as ``cv::undistortPoints``
    (``iterations`` fixed-point steps), polished by Newton steps and checked: a pixel
    whose residual exceeds 1e-10 (normalized units), or whose ray lies beyond the fold of
    the distortion polynomial (:func:`~aura_ums.camera.fold_radius`, where the camera
    images nothing), gives NaN. Within the fold the distortion is one-to-one, so a ray
    found there is the only one the camera images at that pixel.

    Parameters
    ----------
    intrinsics : CameraIntrinsics
        The camera's intrinsics.
    pixels : array_like, shape (n, 2) or (2,)
        Pixel coordinates (u, v), finite.
    iterations : int
        Fixed-point iterations before the Newton polish, >= 1.

    Returns
    -------
    ndarray, shape (n, 2)
        Normalized coordinates (x/z, y/z) of the rays in the camera frame (dimensionless).

    Examples
    --------
    >>> k = CameraIntrinsics(500, 500, 320, 240, 640, 480, distortion=(-0.2, 0.05, 0.0, 0.0, 0.0))
    >>> undistort_points(k, [(320, 240)]).tolist()   # the principal point is its own image
    [[0.0, 0.0]]
    >>> bad = CameraIntrinsics(500, 500, 320, 240, 640, 480, distortion=(-1.0, 0.0, 0.0, 0.0, 0.0))
    >>> undistort_points(bad, [(639, 479)]).tolist()  # beyond the image of r(1 - r^2)'s fold: no ray
    [[nan, nan]]
    """
    if not isinstance(intrinsics, CameraIntrinsics):
        raise InputError(f"intrinsics: expected CameraIntrinsics, got {type(intrinsics).__name__}")
    if isinstance(iterations, bool) or not isinstance(iterations, int) or iterations < 1:
        raise InputError(f"iterations: expected a positive integer, got {iterations!r}")
    uv = points_array(pixels, "pixels")
    xd = (uv[:, 0] - intrinsics.cx) / intrinsics.fx
    yd = (uv[:, 1] - intrinsics.cy) / intrinsics.fy
    if intrinsics.distortion is None:
        return np.column_stack([xd, yd])
    x, y = _undistort_normalized(xd, yd, intrinsics.distortion, iterations)
    return np.column_stack([x, y])


def _undistort_box(xd: _Interval, yd: _Interval, k: Coefficients | None) -> tuple[_Interval, _Interval]:
    """Enclose every undistorted point whose distorted image lies in the boxes ``xd x yd``."""
    if k is None:
        return xd, yd
    mx, my = _undistort_normalized(xd.mid, yd.mid, k, _UNDISTORT_ITERATIONS)
    if not (np.all(np.isfinite(mx)) and np.all(np.isfinite(my))):
        raise InputError("pixel: expected a pixel the distortion model can invert, got one beyond its fold")
    j00, j01, j10, j11 = _point_jacobian(mx, my, k)
    det = j00 * j11 - j01 * j10
    y00, y01, y10, y11 = j11 / det, -j01 / det, -j10 / det, j00 / det
    dmx, dmy = _distort(mx, my, k)
    rx = _Interval(dmx - xd.hi, dmx - xd.lo)
    ry = _Interval(dmy - yd.hi, dmy - yd.lo)
    c0 = mx - (rx * y00 + ry * y01)
    c1 = my - (rx * y10 + ry * y11)
    pad = _PAD * (1.0 + np.abs(mx) + np.abs(my))
    x0 = _Interval.around(mx, 2.0 * (np.abs(y00) * xd.rad + np.abs(y01) * yd.rad) + pad)
    x1 = _Interval.around(my, 2.0 * (np.abs(y10) * xd.rad + np.abs(y11) * yd.rad) + pad)

    def krawczyk(x0: _Interval, x1: _Interval) -> tuple[_Interval, _Interval]:
        a00, a01, a10, a11 = _distortion_jacobian(x0, x1, k)
        m00 = 1.0 - (a00 * y00 + a10 * y01)
        m01 = -(a01 * y00 + a11 * y01)
        m10 = -(a00 * y10 + a10 * y11)
        m11 = 1.0 - (a01 * y10 + a11 * y11)
        d0, d1 = x0 - mx, x1 - my
        return (c0 + m00 * d0 + m01 * d1).padded(pad), (c1 + m10 * d0 + m11 * d1).padded(pad)

    for _ in range(_KRAWCZYK_STEPS):
        # A box inflated past the fold may overflow (inf, then NaN): it then never passes the
        # test below, and the loop ends in the error; numpy need not warn about it.
        with np.errstate(over="ignore", invalid="ignore"):
            k0, k1 = krawczyk(x0, x1)
            inside = (k0.lo >= x0.lo) & (k0.hi <= x0.hi) & (k1.lo >= x1.lo) & (k1.hi <= x1.hi)
            if np.all(inside):
                break
            # epsilon-inflation of the boxes that failed, keeping the ones that passed
            grow0 = k0.padded(0.5 * (k0.hi - k0.lo) + pad)
            grow1 = k1.padded(0.5 * (k1.hi - k1.lo) + pad)
        x0 = _Interval(np.where(inside, x0.lo, np.minimum(grow0.lo, mx)), np.where(inside, x0.hi, grow0.hi))
        x1 = _Interval(np.where(inside, x1.lo, np.minimum(grow1.lo, my)), np.where(inside, x1.hi, grow1.hi))
        x0 = _Interval(x0.lo, np.maximum(x0.hi, mx))
        x1 = _Interval(x1.lo, np.maximum(x1.hi, my))
    else:
        raise InputError(
            "pixel: expected error bounds small enough to bound the undistortion, "
            "got a box that reaches the fold of the distortion model"
        )
    # Every solution in X lies in K(X): tighten twice.
    for _ in range(2):
        x0, x1 = k0.intersect(x0), k1.intersect(x1)
        k0, k1 = krawczyk(x0, x1)
    x0, x1 = k0.intersect(x0), k1.intersect(x1)
    # The solution proved unique in the box is the imaged ray only if the box lies within the
    # fold, where the distortion is one-to-one: beyond, a ray within the fold elsewhere may
    # share the pixel.
    limit = fold_radius(k)
    reach = np.maximum(x0.lo * x0.lo, x0.hi * x0.hi) + np.maximum(x1.lo * x1.lo, x1.hi * x1.hi)
    if not bool(np.all(reach <= limit * limit)):
        raise InputError(
            "pixel: expected error bounds small enough to bound the undistortion, "
            "got a box that reaches the fold of the distortion model"
        )
    return x0, x1


# ------------------------------------------------------------------ calibration bounds


@dataclass(frozen=True, slots=True)
class CalibrationBounds:
    """Half-widths of the uncertainty of each calibration parameter (guaranteed bounds).

    The true parameter lies within ``nominal +- bound``. Distortion coefficients and the
    mount's ``forward``/``left`` are taken as exact.

    Parameters
    ----------
    fx, fy : float
        Focal lengths, pixels, >= 0 (and less than the focal length they bound).
    cx, cy : float
        Principal point, pixels, >= 0.
    pan, tilt : float
        Mount angles, radians, >= 0.
    height : float
        Height of the optical centre above the ground, metres, >= 0.

    Examples
    --------
    >>> CalibrationBounds(fx=5.0, tilt=0.01).cx
    0.0
    >>> CalibrationBounds(pan=-0.1)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: CalibrationBounds.pan: expected a non-negative number, got -0.1
    """

    fx: float = 0.0
    fy: float = 0.0
    cx: float = 0.0
    cy: float = 0.0
    pan: float = 0.0
    tilt: float = 0.0
    height: float = 0.0

    def __post_init__(self) -> None:
        for name in ("fx", "fy", "cx", "cy", "pan", "tilt", "height"):
            value = nonnegative_float(getattr(self, name), f"CalibrationBounds.{name}")
            object.__setattr__(self, name, value)

    @staticmethod
    def field_names() -> tuple[str, ...]:
        """Names of the bounded parameters, in order."""
        return ("fx", "fy", "cx", "cy", "pan", "tilt", "height")


#: The bounds of an exact calibration (what ``bounds=None`` means).
_EXACT = CalibrationBounds()


# --------------------------------------------------------------------------- the rays


def _check_camera(camera: object, bounds: object) -> tuple[Camera, CalibrationBounds]:
    if not isinstance(camera, Camera):
        raise InputError(f"camera: expected Camera, got {type(camera).__name__}")
    if bounds is None:
        bounds = _EXACT
    if not isinstance(bounds, CalibrationBounds):
        raise InputError(f"bounds: expected CalibrationBounds, got {type(bounds).__name__}")
    k = camera.intrinsics
    if bounds.fx >= k.fx or bounds.fy >= k.fy:
        name = "fx" if bounds.fx >= k.fx else "fy"
        raise InputError(
            f"bounds.{name}: expected less than the focal length {name} ({getattr(k, name)}), "
            f"got {getattr(bounds, name)}"
        )
    return camera, bounds


def _check_pixels(camera: Camera, pixels: ArrayLike, name: str, rows: int) -> Array:
    k = camera.intrinsics
    uv = points_array(pixels, name)
    if uv.shape != (rows, 2):
        expected = "(u, v)" if rows == 1 else "(u1, v1, u2, v2)"
        raise InputError(f"{name}: expected {expected}, got shape {np.shape(pixels)}")
    for row in uv:
        u, v = float(row[0]), float(row[1])
        if not (-0.5 <= u <= k.width - 0.5 and -0.5 <= v <= k.height - 0.5):
            raise InputError(
                f"{name}: expected a pixel inside the {k.width}x{k.height} image "
                f"([-0.5, {k.width - 0.5}] x [-0.5, {k.height - 0.5}]), got ({u}, {v})"
            )
    return uv


@dataclass(frozen=True, slots=True)
class _Rays:
    """Ray summaries: ``w`` and ``psi`` (see the module notes) as enclosures and nominal values."""

    w: _Interval
    psi: _Interval
    w0: Array
    psi0: Array


def _param(nominal: float, bound: float, splits: int) -> _Interval:
    edges = nominal - bound + 2.0 * bound * np.linspace(0.0, 1.0, splits + 1 if bound > 0.0 else 2)
    return _Interval(edges[:-1], edges[1:])


def _rays(
    camera: Camera, bounds: CalibrationBounds, uv: Array, pixel_error: float, *, splits: int = 1
) -> _Rays:
    """Enclose (w, psi) for each pixel row over the calibration box, split ``splits`` ways.

    Returns intervals of shape (number of sub-boxes, number of pixels).
    """
    k, mount = camera.intrinsics, camera.mount
    names = ("fx", "fy", "cx", "cy", "tilt")
    nominal = (k.fx, k.fy, k.cx, k.cy, mount.tilt)
    parts = [_param(value, getattr(bounds, name), splits) for name, value in zip(names, nominal, strict=True)]
    grids_lo = np.meshgrid(*[p.lo for p in parts], indexing="ij")
    grids_hi = np.meshgrid(*[p.hi for p in parts], indexing="ij")
    fx, fy, cx, cy, tilt = (
        _Interval(lo.reshape(-1, 1), hi.reshape(-1, 1)) for lo, hi in zip(grids_lo, grids_hi, strict=True)
    )
    u = _Interval.around(uv[None, :, 0], pixel_error)
    v = _Interval.around(uv[None, :, 1], pixel_error)
    xd, yd = (u - cx) / fx, (v - cy) / fy
    shape = np.broadcast_shapes(xd.lo.shape, yd.lo.shape)
    xd = _Interval(np.broadcast_to(xd.lo, shape).ravel(), np.broadcast_to(xd.hi, shape).ravel())
    yd = _Interval(np.broadcast_to(yd.lo, shape).ravel(), np.broadcast_to(yd.hi, shape).ravel())
    x, y = _undistort_box(xd, yd, k.distortion)
    x = _Interval(x.lo.reshape(shape), x.hi.reshape(shape))
    y = _Interval(y.lo.reshape(shape), y.hi.reshape(shape))
    s = y.sqr() + 1.0
    w = x / _Interval(np.sqrt(s.lo), np.sqrt(s.hi))
    psi = tilt + _Interval(np.arctan(y.lo), np.arctan(y.hi))
    # nominal values (no error): the nominal camera, the measured pixel
    nominal_xy = undistort_points(k, uv)
    if not np.all(np.isfinite(nominal_xy)):
        raise InputError("pixel: expected a pixel the distortion model can invert, got one beyond its fold")
    x0, y0 = nominal_xy[:, 0], nominal_xy[:, 1]
    return _Rays(w, psi, x0 / np.sqrt(1.0 + y0 * y0), mount.tilt + np.arctan(y0))


# ------------------------------------------------------- one pixel, plain floats
#
# Class I and II observe one pixel over one calibration box. The functions below are the
# same interval arithmetic as _Interval, _rays and _bearing_bound, operation for
# operation, on plain floats: numpy's per-call overhead dominates arrays of one element.


class _PixelRay(NamedTuple):
    """Enclosures [lo, hi] of ``w`` and ``psi`` of one pixel's ray, and their nominal values."""

    w_lo: float
    w_hi: float
    psi_lo: float
    psi_hi: float
    w0: float
    psi0: float


def _mul(a_lo: float, a_hi: float, b_lo: float, b_hi: float) -> tuple[float, float]:
    """Interval product, as ``_Interval.__mul__``."""
    p1, p2, p3, p4 = a_lo * b_lo, a_lo * b_hi, a_hi * b_lo, a_hi * b_hi
    return min(p1, p2, p3, p4), max(p1, p2, p3, p4)


def _sqr(lo: float, hi: float) -> tuple[float, float]:
    """Interval square, as ``_Interval.sqr``."""
    a, b = lo * lo, hi * hi
    return (0.0 if lo <= 0.0 <= hi else min(a, b)), max(a, b)


def _param_scalar(nominal: float, bound: float) -> tuple[float, float]:
    """One sub-box of a parameter, as ``_param(nominal, bound, 1)``."""
    low = nominal - bound
    return low + 0.0, low + 2.0 * bound


def _normalized_interval(
    pixel: float, error: float, centre: tuple[float, float], focal: tuple[float, float]
) -> tuple[float, float]:
    """``(pixel +- error - centre) / focal`` as in ``_rays``: a difference, then a product."""
    lo, hi = (pixel - error) + (-centre[1]), (pixel + error) + (-centre[0])
    return _mul(lo, hi, 1.0 / focal[1], 1.0 / focal[0])


def _pixel_ray(
    camera: Camera, bounds: CalibrationBounds, u: float, v: float, pixel_error: float
) -> _PixelRay:
    """Enclose (w, psi) of one pixel over the calibration box (``_rays`` with one sub-box)."""
    k, mount = camera.intrinsics, camera.mount
    if k.distortion is not None:  # the interval Newton enclosure runs on arrays
        rays = _rays(camera, bounds, np.array([[u, v]]), pixel_error)
        return _PixelRay(
            float(rays.w.lo.ravel()[0]),
            float(rays.w.hi.ravel()[0]),
            float(rays.psi.lo.ravel()[0]),
            float(rays.psi.hi.ravel()[0]),
            float(rays.w0[0]),
            float(rays.psi0[0]),
        )
    fx = _param_scalar(k.fx, bounds.fx)
    fy = _param_scalar(k.fy, bounds.fy)
    cx = _param_scalar(k.cx, bounds.cx)
    cy = _param_scalar(k.cy, bounds.cy)
    tilt = _param_scalar(mount.tilt, bounds.tilt)
    x_lo, x_hi = _normalized_interval(u, pixel_error, cx, fx)
    y_lo, y_hi = _normalized_interval(v, pixel_error, cy, fy)
    s_lo, s_hi = _sqr(y_lo, y_hi)
    w_lo, w_hi = _mul(x_lo, x_hi, 1.0 / math.sqrt(s_hi + 1.0), 1.0 / math.sqrt(s_lo + 1.0))
    psi_lo, psi_hi = tilt[0] + math.atan(y_lo), tilt[1] + math.atan(y_hi)
    x0, y0 = (u - k.cx) / k.fx, (v - k.cy) / k.fy
    return _PixelRay(w_lo, w_hi, psi_lo, psi_hi, x0 / math.sqrt(1.0 + y0 * y0), mount.tilt + math.atan(y0))


def _sin_range(lo: float, hi: float) -> tuple[float, float]:
    """Exact range of sin over [lo, hi], as ``_isin``."""
    s_lo, s_hi = math.sin(lo), math.sin(hi)
    peak = math.pi / 2 + 2 * math.pi * math.ceil((lo - math.pi / 2) / (2 * math.pi))
    trough = -math.pi / 2 + 2 * math.pi * math.ceil((lo + math.pi / 2) / (2 * math.pi))
    return (-1.0 if trough <= hi else min(s_lo, s_hi)), (1.0 if peak <= hi else max(s_lo, s_hi))


def _cos_range(lo: float, hi: float) -> tuple[float, float]:
    """Exact range of cos over [lo, hi], as ``_icos``."""
    c_lo, c_hi = math.cos(lo), math.cos(hi)
    peak = 2 * math.pi * math.ceil(lo / (2 * math.pi))
    trough = math.pi + 2 * math.pi * math.ceil((lo - math.pi) / (2 * math.pi))
    return (-1.0 if trough <= hi else min(c_lo, c_hi)), (1.0 if peak <= hi else max(c_lo, c_hi))


def _pixel_bearing(camera: Camera, bounds: CalibrationBounds, ray: _PixelRay) -> tuple[float, float]:
    """(bearing, bearing_error) of one pixel's ray over the box, as ``_bearing_bound``."""
    y_lo, y_hi = -ray.w_hi, -ray.w_lo
    x_lo, x_hi = _cos_range(ray.psi_lo, ray.psi_hi)
    nominal = wrap_angle(camera.mount.pan + math.atan2(-ray.w0, math.cos(ray.psi0)))
    if y_lo <= 0.0 <= y_hi and x_lo <= 0.0 <= x_hi:
        return nominal, math.pi
    # A box that excludes the origin spans less than half a turn: extremes at its corners.
    reference = math.atan2(0.5 * (y_lo + y_hi), 0.5 * (x_lo + x_hi))
    relative = [
        wrap_angle(math.atan2(yy, xx) - reference)
        for yy, xx in ((y_lo, x_lo), (y_lo, x_hi), (y_hi, x_lo), (y_hi, x_hi))
    ]
    lo = reference + min(relative) - bounds.pan
    hi = reference + max(relative) + bounds.pan
    error = _widen(0.5 * (hi - lo))
    if error >= math.pi:
        return nominal, math.pi
    return wrap_angle(camera.mount.pan + 0.5 * (lo + hi)), error


def _one_pixel(camera: Camera, pixel: ArrayLike) -> tuple[float, float]:
    """Check one pixel, as ``_check_pixels(camera, pixel, "pixel", 1)``; a fast path for two floats."""
    if isinstance(pixel, tuple) and len(pixel) == 2 and all(isinstance(c, float) for c in pixel):
        u, v = pixel
        k = camera.intrinsics
        if (
            math.isfinite(u)
            and math.isfinite(v)
            and -0.5 <= u <= k.width - 0.5
            and -0.5 <= v <= k.height - 0.5
        ):
            return float(u), float(v)
    uv = _check_pixels(camera, pixel, "pixel", 1)
    return float(uv[0, 0]), float(uv[0, 1])


def _widen(error: float) -> float:
    return error * (1.0 + _SAFETY_RELATIVE) + _SAFETY_ABSOLUTE


def _bearing_bound(camera: Camera, bounds: CalibrationBounds, rays: _Rays) -> tuple[float, float]:
    """(bearing, bearing_error) of the first pixel's ray over the whole box; error pi when unbounded."""
    reference, low, high, full = _atan2_range(-rays.w, _icos(rays.psi))
    nominal = wrap_angle(camera.mount.pan + float(np.arctan2(-rays.w0[0], np.cos(rays.psi0[0]))))
    if bool(np.any(full)):
        return nominal, math.pi
    # one sub-box and one pixel here
    lo = float(reference.ravel()[0] + low.ravel()[0]) - bounds.pan
    hi = float(reference.ravel()[0] + high.ravel()[0]) + bounds.pan
    error = _widen(0.5 * (hi - lo))
    if error >= math.pi:
        return nominal, math.pi
    return wrap_angle(camera.mount.pan + 0.5 * (lo + hi)), error


# ------------------------------------------------------------------ the three classes


def bound_vertical_line(
    camera: Camera,
    pixel: ArrayLike,
    *,
    pixel_error: float = 0.5,
    bounds: CalibrationBounds | None = None,
) -> tuple[float, float]:
    """Bound the bearing of a vertical line from one pixel of its image (Class I).

    The pixel's back-projected ray lies in the vertical plane through the optical centre
    and the line, whatever the tilt, so its horizontal component points at the line: the
    bearing is its azimuth in the robot frame (counter-clockwise from robot forward),
    measured from the optical centre (``camera.mount.sensor_offset``).

    Parameters
    ----------
    camera : Camera
        The nominal camera.
    pixel : array_like, shape (2,)
        (u, v) of any point of the line's image, inside the image.
    pixel_error : float
        Bound on the pixel's error in u and in v, pixels, in [0, 1e5].
    bounds : CalibrationBounds, optional
        Bounds on the calibration; None for an exact calibration.

    Returns
    -------
    bearing, bearing_error : float
        The centre of the guaranteed interval of bearings and its half-width, radians;
        the half-width is pi when the ray may be vertical (no bearing information).

    Raises
    ------
    InputError
        For a pixel outside the image or not finite, a negative error, or bounds that
        make a focal length non-positive.

    Examples
    --------
    >>> from aura_ums.camera import CameraMount
    >>> camera = Camera(CameraIntrinsics(500, 500, 320, 240, 640, 480), CameraMount(1.0, pan=0.5))
    >>> bearing, error = bound_vertical_line(camera, (320, 100), pixel_error=0.0)
    >>> round(bearing, 6), error < 1e-8    # the optical axis, tilted or not
    (0.5, True)
    >>> bound_vertical_line(camera, (640, 100))
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: pixel: expected a pixel inside the 640x480 image \
([-0.5, 639.5] x [-0.5, 479.5]), got (640.0, 100.0)
    """
    camera, checked = _check_camera(camera, bounds)
    error = PIXEL_ERROR.check(pixel_error, "pixel_error")
    u, v = _one_pixel(camera, pixel)
    return _pixel_bearing(camera, checked, _pixel_ray(camera, checked, u, v, error))


def bound_point(
    camera: Camera,
    pixel: ArrayLike,
    z: float,
    *,
    pixel_error: float = 0.5,
    bounds: CalibrationBounds | None = None,
    max_range: float | None = None,
) -> tuple[float, float, float, float]:
    """Bound the bearing and range of a point of known height from its pixel (Class II).

    The range is the horizontal distance from the optical centre to where the
    back-projected ray meets the horizontal plane at height ``z`` (the ground-plane
    assumption), bounded over every camera and pixel within the bounds.

    Near the horizon the range grows without bound. A pixel whose nominal ray does not
    meet the plane (at or above the horizon for that height) is an error. When the ray
    meets the plane but the error bounds reach the horizon, the range is unbounded
    above: that is an error unless ``max_range`` is given, which the caller asserts is
    a bound on the true range (e.g. the landmark's activation range) and which then caps
    ``range_max`` (it caps it in every case).

    Parameters
    ----------
    camera : Camera
        The nominal camera.
    pixel : array_like, shape (2,)
        (u, v) of the point's image, inside the image.
    z : float
        Height of the point above the ground, metres, in [-1e4, 1e4].
    pixel_error : float
        Bound on the pixel's error in u and in v, pixels, in [0, 1e5].
    bounds : CalibrationBounds, optional
        Bounds on the calibration; None for an exact calibration.
    max_range : float, optional
        Known bound on the true range, metres, > 0.

    Returns
    -------
    bearing, bearing_error, range_min, range_max : float
        Bearing as in :func:`bound_vertical_line` (radians), ``[range_min, range_max]``
        in metres.

    Raises
    ------
    InputError
        As :func:`bound_vertical_line`; also for a pixel at or above the horizon, error
        bounds reaching the horizon without ``max_range``, a camera height bound that
        reaches the point's height, or a range_min beyond ``max_range``.

    Examples
    --------
    >>> from aura_ums.camera import CameraMount
    >>> camera = Camera(CameraIntrinsics(500, 500, 320, 240, 640, 480), CameraMount(1.0, tilt=0.1))
    >>> _, _, near, far = bound_point(camera, (320, 240), 0.0, pixel_error=0.0)
    >>> round(near, 6), round(far, 6)    # 1 m / tan(0.1)
    (9.966644, 9.966644)
    >>> bound_point(camera, (320, 100), 0.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: pixel: expected a pixel below the horizon for a landmark at \
height 0.0 m (camera at 1.0 m), got (320.0, 100.0) whose ray never meets that plane
    """
    camera, checked = _check_camera(camera, bounds)
    error = PIXEL_ERROR.check(pixel_error, "pixel_error")
    cap = math.inf
    if max_range is not None:
        cap = finite_float(max_range, "max_range")
        if cap <= 0.0:
            raise InputError(f"max_range: expected a positive number, got {cap}")
    z = HEIGHT.check(z, "z")
    u, v = _one_pixel(camera, pixel)
    height = camera.mount.height
    drop_lo, drop_hi = (height - z) - checked.height, (height - z) + checked.height
    if drop_lo <= 0.0 <= drop_hi:
        raise InputError(
            f"bounds.height: expected the camera height {height} +- {checked.height} m to exclude the "
            f"landmark's height {z} m, got an interval that reaches it"
        )
    sign = 1.0 if drop_lo > 0.0 else -1.0
    ray = _pixel_ray(camera, checked, u, v, error)
    if sign * math.sin(ray.psi0) <= 0.0:
        raise InputError(
            f"pixel: expected a pixel {'below' if sign > 0 else 'above'} the horizon for a landmark at "
            f"height {z} m (camera at {height} m), got ({u}, {v}) whose ray "
            "never meets that plane"
        )
    bearing, bearing_error = _pixel_bearing(camera, checked, ray)
    sine_lo, sine_hi = _sin_range(ray.psi_lo, ray.psi_hi)
    s_min, s_max = min(sine_lo * sign, sine_hi * sign), max(sine_lo * sign, sine_hi * sign)
    w2_lo, w2_hi = _sqr(ray.w_lo, ray.w_hi)
    d_abs_lo = 0.0 if drop_lo <= 0.0 <= drop_hi else min(abs(drop_lo), abs(drop_hi))
    d_abs_hi = max(abs(drop_lo), abs(drop_hi))
    low = d_abs_lo * math.sqrt(max((1.0 + w2_lo) / (s_max * s_max) - 1.0, 0.0))
    # s_min <= 0: the error bounds reach the horizon, the range is unbounded above
    high = d_abs_hi * math.sqrt(max((1.0 + w2_hi) / (s_min * s_min) - 1.0, 0.0)) if s_min > 0.0 else math.inf
    margin = _widen(0.5 * (high - low)) - 0.5 * (high - low) if math.isfinite(high) else 0.0
    range_min = max(0.0, low - margin - _PAD * low)
    range_max = high + margin + _PAD * high
    if math.isinf(range_max) and math.isinf(cap):
        raise InputError(
            f"max_range: expected a bound on the range, because the error bounds of pixel "
            f"({u}, {v}) reach the horizon (unbounded range), got None"
        )
    if range_min > cap:
        raise InputError(f"max_range: expected at least the smallest possible range {range_min} m, got {cap}")
    return bearing, bearing_error, range_min, min(range_max, cap)


def _ground_boxes(camera: Camera, bounds: CalibrationBounds, uv: Array, pixel_error: float) -> _Rays:
    return _rays(camera, bounds, uv, pixel_error, splits=_GROUND_LINE_SPLITS)


def bound_ground_line(
    camera: Camera,
    segment: ArrayLike,
    *,
    expected_angle: float,
    pixel_error: float = 0.5,
    bounds: CalibrationBounds | None = None,
) -> tuple[float, float, float, float]:
    """Bound the offset and angle of a ground line from an image segment of it (Class III).

    Both ends are back-projected to the ground plane z = 0, giving the line in the robot
    frame. ``offset`` is the signed distance from the optical centre (the
    ``sensor_offset``) to the line, positive when it is left of the line's direction;
    ``angle`` is that direction relative to the heading.

    The image does not say which way the line runs: it is oriented along whichever of
    its two directions is closer to ``expected_angle`` (robot frame, radians), e.g.
    ``landmark.direction - heading`` for a heading estimate; it must be within 90 degrees
    of the truth.

    Parameters
    ----------
    camera : Camera
        The nominal camera.
    segment : array_like, shape (4,) or (2, 2)
        (u1, v1, u2, v2): two image points of the line, inside the image, both below
        the horizon.
    expected_angle : float
        Roughly expected direction of the line relative to the heading, radians.
    pixel_error : float
        Bound on each end's error in u and in v, pixels, in [0, 1e5].
    bounds : CalibrationBounds, optional
        Bounds on the calibration; None for an exact calibration.

    Returns
    -------
    offset, offset_error, angle, angle_error : float
        ``offset`` (m) and ``angle`` (rad, wrapped) at the centres of their guaranteed
        intervals, with the half-widths as errors.

    Raises
    ------
    InputError
        For bad pixels or errors as :func:`bound_vertical_line`; an end at or above the
        horizon, or whose error bounds reach it; a camera height bound that reaches the
        ground; a segment too short for its error bounds to fix a direction.

    Examples
    --------
    >>> from aura_ums.camera import CameraMount
    >>> from aura_ums.geometry import Pose
    >>> camera = Camera(CameraIntrinsics(500, 500, 320, 240, 640, 480), CameraMount(1.0, tilt=0.3))
    >>> # the images of the ground points (3, -2) and (6, -2) seen from the origin, heading 0
    >>> uv = camera.project(Pose(0, 0, 0), [(3.0, -2.0, 0.0), (6.0, -2.0, 0.0)])
    >>> offset, _, angle, _ = bound_ground_line(camera, uv[::-1], expected_angle=0.0, pixel_error=0.0)
    >>> round(offset, 6), round(angle, 6) + 0.0      # ends given in either order
    (2.0, 0.0)
    >>> bound_ground_line(camera, (0, 0, 10, 10), expected_angle=0.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: segment: expected both ends below the horizon, got end 1 at (0.0, 0.0)
    """
    camera, checked = _check_camera(camera, bounds)
    error = PIXEL_ERROR.check(pixel_error, "pixel_error")
    hint = finite_float(expected_angle, "expected_angle")
    try:
        flat = np.asarray(segment, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"segment: expected (u1, v1, u2, v2) numbers, got {segment!r}") from exc
    if flat.size != 4:
        raise InputError(f"segment: expected (u1, v1, u2, v2), got shape {flat.shape}")
    uv = _check_pixels(camera, flat.reshape(2, 2), "segment", 2)
    mount = camera.mount
    height = _Interval.around(np.float64(mount.height), checked.height)
    if height.lo <= 0.0:
        raise InputError(
            f"bounds.height: expected the camera height {mount.height} +- {checked.height} m to stay above "
            "the ground, got an interval that reaches it"
        )
    rays = _ground_boxes(camera, checked, uv, error)
    for end in range(2):
        if math.sin(float(rays.psi0[end])) <= 0.0:
            raise InputError(
                f"segment: expected both ends below the horizon, got end {end + 1} at "
                f"({uv[end, 0]}, {uv[end, 1]})"
            )
    # nominal ground points, per unit height, pan-free robot frame
    p0 = np.column_stack([1.0 / np.tan(rays.psi0), -rays.w0 / np.sin(rays.psi0)])
    chord = p0[1] - p0[0]
    theta0 = math.atan2(float(chord[1]), float(chord[0]))

    sine = _isin(rays.psi)
    if bool(np.any(sine.lo <= 0.0)) or bool(np.any(rays.psi.hi >= math.pi)):
        raise InputError(
            "segment: expected error bounds that keep both ends below the horizon, got bounds that "
            "reach it (the ground point is unbounded)"
        )
    px = _Interval(1.0 / np.tan(rays.psi.hi), 1.0 / np.tan(rays.psi.lo))
    py = -rays.w / sine
    pad = _PAD * (1.0 + np.abs(px.lo) + np.abs(px.hi) + np.abs(py.lo) + np.abs(py.hi))
    px, py = px.padded(pad), py.padded(pad)
    ax, ay = _Interval(px.lo[:, 0], px.hi[:, 0]), _Interval(py.lo[:, 0], py.hi[:, 0])
    bx, by = _Interval(px.lo[:, 1], px.hi[:, 1]), _Interval(py.lo[:, 1], py.hi[:, 1])
    reference, low, high, full = _atan2_range(by - ay, bx - ax)
    if bool(np.any(full)):
        raise InputError(
            "segment: expected a segment long enough for its error bounds to fix the line's direction, "
            f"got ends ({uv[0, 0]}, {uv[0, 1]}) and ({uv[1, 0]}, {uv[1, 1]})"
        )
    # The image gives the line's direction up to a half turn: from end 1 to end 2 in
    # theta0 + [rel_lo, rel_hi], or the reverse. The landmark's (start -> end) is the one
    # within 90 degrees of the hint, with the pan's bound (pan-free frame): keep the parts
    # of both orientations in that window. A wide interval can have parts of both, and
    # choosing one by the nominal chord alone lost the truth.
    shift = wrap_angle(reference - theta0)
    rel_lo, rel_hi = shift + low - _PAD, shift + high + _PAD
    centre = hint - mount.pan
    reach = math.pi / 2 + checked.pan + _PAD
    middle, half = theta0 + 0.5 * (rel_lo + rel_hi), 0.5 * (rel_hi - rel_lo)
    parts_lo, parts_hi = [], []
    for turn in (0.0, math.pi):
        at = centre + wrap_angle(middle + turn - centre)
        parts_lo.append(np.maximum(at - half, centre - reach))
        parts_hi.append(np.minimum(at + half, centre + reach))
    lo = np.column_stack(parts_lo)  # (sub-boxes, orientation)
    hi = np.column_stack(parts_hi)
    kept = lo <= hi
    if not bool(np.any(kept)):
        raise InputError(
            f"expected_angle: expected a direction within 90 degrees of the line's, got {hint!r} rad, "
            f"which no direction the segment allows is"
        )
    fractions = np.linspace(0.0, 1.0, _ANGLE_PIECES + 1)
    span = np.where(kept, hi - lo, 0.0)
    edges = lo[:, :, None] + span[:, :, None] * fractions[None, None, :]
    pieces = _Interval(
        edges[:, :, :-1].reshape(len(lo), -1), edges[:, :, 1:].reshape(len(lo), -1)
    )  # (sub-boxes, pieces of both orientations)
    valid = np.repeat(kept, _ANGLE_PIECES, axis=1)

    def offsets(bx_: _Interval, by_: _Interval) -> _Interval:
        # cross(p, d(theta)) = |p| sin(theta - angle(p)); linear in p: extreme at a corner
        lows, highs = [], []
        for cx_, cy_ in itertools.product((bx_.lo, bx_.hi), (by_.lo, by_.hi)):
            radius, angle = np.hypot(cx_, cy_)[:, None], np.arctan2(cy_, cx_)[:, None]
            s = _isin(pieces - angle) * radius
            lows.append(s.lo)
            highs.append(s.hi)
        return _Interval(np.minimum.reduce(lows), np.maximum.reduce(highs))

    both = offsets(ax, ay).intersect(offsets(bx, by))
    feasible = (both.lo <= both.hi) & valid
    if not bool(np.any(feasible)):  # cannot happen but for rounding beyond the padding
        raise InputError("segment: expected a consistent line, got ends that no line through both fits")
    angle_lo = float(np.min(np.where(feasible, pieces.lo, np.inf))) - checked.pan + mount.pan
    angle_hi = float(np.max(np.where(feasible, pieces.hi, -np.inf))) + checked.pan + mount.pan
    unit = _Interval(
        np.asarray(np.min(np.where(feasible, both.lo, np.inf)), dtype=np.float64),
        np.asarray(np.max(np.where(feasible, both.hi, -np.inf)), dtype=np.float64),
    )
    offset = unit * height
    angle_error = min(_widen(0.5 * (angle_hi - angle_lo)), math.pi)
    offset_error = _widen(float(offset.rad))
    return float(offset.mid), offset_error, wrap_angle(0.5 * (angle_lo + angle_hi)), angle_error
