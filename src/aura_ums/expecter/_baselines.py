"""Baseline windows to compare the polygon map with: the disk model and an EKF's 3-sigma box.

Both build a :class:`SpatialUncertaintyMap` that stands for the baseline's belief and
ask the same :class:`Expecter` for its window, so that the comparison isolates the shape
of the position region (and, for the EKF, of the heading interval).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import COORDINATE, Range, finite_float, integer_at_least
from aura_ums.errors import InputError
from aura_ums.expecter._expecter import Expecter
from aura_ums.expecter._window import class_margin, margin_pixels
from aura_ums.geometry import ConvexPolygon, HeadingWedge, ImageWindow, outer_disk
from aura_ums.uncertainty import Landmark, Pose, SpatialUncertaintyMap
from aura_ums.world import PerceptualStrategy

#: Sides of the outer polygon that stands for the disk model's circle.
_DISK_SIDES = 64
#: Half-width of a Gaussian box in standard deviations: up to 100 (Chebyshev leaves at most
#: 1e-4 of any belief outside); 1e300 passed and failed later, naming the box's corners.
BOX_SIGMAS = Range(0.0, 100.0, "", low_open=True)


def disk_model_map(map: SpatialUncertaintyMap, *, sides: int = _DISK_SIDES) -> SpatialUncertaintyMap:
    """Return the paper's disk model of a map: a circle around its centre enclosing its polygon.

    The circle is centred on ``map.center`` with the radius (m) of the polygon's farthest
    vertex, represented by an outer regular polygon of ``sides`` sides; the wedge is kept.

    Parameters
    ----------
    map : SpatialUncertaintyMap
        The polygonal map.
    sides : int
        Sides of the outer polygon of the circle, >= 3.

    Examples
    --------
    >>> from aura_ums.uncertainty import Pose
    >>> start = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.0, 0.1)
    >>> disk_model_map(start).area                   # a point stays a point
    0.0
    """
    _check_map(map)
    integer_at_least(sides, "sides", 3)
    center = np.asarray(map.center, dtype=np.float64)
    offsets = map.polygon.vertices - center
    radius = float(np.max(np.hypot(offsets[:, 0], offsets[:, 1])))
    polygon = ConvexPolygon(outer_disk(center, radius, sides))
    return SpatialUncertaintyMap(polygon, center, map.wedge)


def disk_model_window(
    expecter: Expecter,
    map: SpatialUncertaintyMap,
    landmark: Landmark,
    *,
    margin: float | PerceptualStrategy | None = None,
    clip: bool = True,
) -> ImageWindow | None:
    """Return the window the disk model gives: :meth:`Expecter.window` on :func:`disk_model_map`.

    Parameters
    ----------
    expecter : Expecter
        The Expecter (its camera) to use.
    map : SpatialUncertaintyMap
        The polygonal map whose disk model is compared.
    landmark : VerticalLineLandmark, PointLandmark or GroundLineLandmark
        The expected landmark.
    margin : float, PerceptualStrategy or None
        As in :meth:`Expecter.window` (None: the landmark class's usual strategy's).
    clip : bool
        Clip to the image (as :meth:`Expecter.window`); False returns the guaranteed
        window grown by the margin, for comparing areas beyond the image. A bool.

    Returns
    -------
    ImageWindow or None
        Pixels; None when the landmark cannot be in view.

    Examples
    --------
    >>> import math
    >>> from aura_ums.camera import Camera, CameraIntrinsics, CameraMount
    >>> from aura_ums.geometry import ConvexPolygon, HeadingWedge
    >>> from aura_ums.uncertainty import PointLandmark
    >>> camera = Camera(CameraIntrinsics(500, 500, 320, 240, 640, 480), CameraMount(height=1.0))
    >>> road = ConvexPolygon([(-3, -0.2), (3, -0.2), (3, 0.2), (-3, 0.2)])   # long and thin
    >>> m = SpatialUncertaintyMap(road, (0, 0), HeadingWedge(0.0, 0.01, 0.01))
    >>> side = PointLandmark("sign", 2.0, 6.0, 1.5)
    >>> e = Expecter(camera)
    >>> polygon = e.bounds(m, side)
    >>> disk = disk_model_window(e, m, side, margin=0.0, clip=False)
    >>> polygon.area < disk.area
    True
    >>> disk_model_window(e, m, side, clip="no")
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: clip: expected a bool, got 'no'
    """
    _check_expecter(expecter)
    _check_clip(clip)
    return _window(expecter, disk_model_map(map), landmark, margin, clip)


def gaussian_box_map(
    mean_pose: Pose | ArrayLike, covariance: ArrayLike, sigmas: float = 3.0
) -> SpatialUncertaintyMap:
    """Return the ``sigmas`` box of a Gaussian belief over (x, y, heading) as a map.

    The box is ``mean +- sigmas * sqrt(diag(covariance))`` in x and y (an axis-aligned
    rectangle, metres) and in heading (a wedge, radians; the full circle from pi up). It
    is the region an EKF user would search (correlations ignored, as a box does).

    Parameters
    ----------
    mean_pose : Pose or array_like, shape (3,)
        Mean x (m), y (m), heading (rad).
    covariance : array_like, shape (3, 3)
        Covariance of (x, y, heading): finite, symmetric, non-negative diagonal (m^2,
        m^2, rad^2; cross terms in m^2 and m rad).
    sigmas : float
        Half-width of the box in standard deviations, in (0, 100].

    Raises
    ------
    InputError
        On a non-finite or ill-shaped mean or covariance, a negative variance, an
        asymmetric covariance, ``sigmas`` outside (0, 100], or a box that reaches beyond
        the world's coordinates (+-1e6 m).

    Examples
    --------
    >>> box = gaussian_box_map((0.0, 0.0, 0.0), [[0.01, 0, 0], [0, 0.04, 0], [0, 0, 1e-4]])
    >>> round(box.area, 6), round(box.wedge.ccw, 6)
    (0.72, 0.03)
    >>> gaussian_box_map((0.0, 0.0, 0.0), [[0.01, 0, 0], [0, 0.04, 0], [0, 0, 4.0]]).wedge.is_full_circle
    True
    """
    mean = _mean_pose(mean_pose)
    cov = _covariance(covariance)
    s = BOX_SIGMAS.check(sigmas, "sigmas")
    half = s * np.sqrt(np.diag(cov))
    x, y, heading = mean
    if not (COORDINATE.contains(x) and COORDINATE.contains(y)):
        raise InputError(f"mean_pose: expected x and y each {COORDINATE.text()}, got ({x}, {y})")
    if max(abs(x), abs(y)) + max(half[0], half[1]) > COORDINATE.high:
        raise InputError(
            f"covariance: expected a {s:g}-sigma box within the world's coordinates {COORDINATE.text()}, "
            f"got half-widths ({half[0]:.3g}, {half[1]:.3g}) m around ({x}, {y})"
        )
    corners = [
        (x - half[0], y - half[1]),
        (x + half[0], y - half[1]),
        (x + half[0], y + half[1]),
        (x - half[0], y + half[1]),
    ]
    polygon = ConvexPolygon.from_points(corners)
    if half[2] >= math.pi:
        wedge = HeadingWedge.full_circle(heading)
    else:
        wedge = HeadingWedge(heading, float(half[2]), float(half[2]))
    return SpatialUncertaintyMap(polygon, (x, y), wedge)


def gaussian_window(
    expecter: Expecter,
    mean_pose: Pose | ArrayLike,
    covariance: ArrayLike,
    landmark: Landmark,
    sigmas: float = 3.0,
    *,
    margin: float | PerceptualStrategy | None = None,
    clip: bool = True,
) -> ImageWindow | None:
    """Return the window an EKF's ``sigmas`` box of (x, y, heading) gives.

    The box (:func:`gaussian_box_map`) goes through the same :class:`Expecter`, so the
    window is guaranteed for every pose of the box (not merely to first order).

    Parameters
    ----------
    expecter : Expecter
        The Expecter (its camera) to use.
    mean_pose : Pose or array_like, shape (3,)
        The EKF's mean x (m), y (m), heading (rad).
    covariance : array_like, shape (3, 3)
        The EKF's covariance of (x, y, heading).
    landmark : VerticalLineLandmark, PointLandmark or GroundLineLandmark
        The expected landmark.
    sigmas : float
        Half-width of the box in standard deviations, in (0, 100].
    margin : float, PerceptualStrategy or None
        As in :meth:`Expecter.window` (None: the landmark class's usual strategy's).
    clip : bool
        Clip to the image; False keeps the whole window, for comparing areas. A bool.

    Returns
    -------
    ImageWindow or None
        Pixels; None when the landmark cannot be in view.

    Raises
    ------
    InputError
        On bad input (see :func:`gaussian_box_map`).

    Examples
    --------
    >>> from aura_ums.camera import Camera, CameraIntrinsics, CameraMount
    >>> from aura_ums.uncertainty import PointLandmark
    >>> e = Expecter(Camera(CameraIntrinsics(500, 500, 320, 240, 640, 480), CameraMount(height=1.0)))
    >>> corner = PointLandmark("corner", 10.0, 0.0, 2.0)
    >>> gaussian_window(e, (0, 0, 0), np.zeros((3, 3)), corner, margin=0.0).width < 1e-3
    True
    >>> gaussian_window(e, (0, 0, 0), np.eye(3), corner, sigmas=0.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: sigmas: expected a number in (0, 100], got 0.0
    """
    _check_expecter(expecter)
    _check_clip(clip)
    return _window(expecter, gaussian_box_map(mean_pose, covariance, sigmas), landmark, margin, clip)


def _window(
    expecter: Expecter,
    map: SpatialUncertaintyMap,
    landmark: Landmark,
    margin: float | PerceptualStrategy | None,
    clip: bool,
) -> ImageWindow | None:
    if clip:
        return expecter.window(map, landmark, margin=margin)
    pixels = None if margin is None else margin_pixels(margin)
    guaranteed = expecter.bounds(map, landmark)  # checks the landmark
    if guaranteed is None:
        return None
    return guaranteed.expanded(class_margin(landmark.landmark_class) if pixels is None else pixels)


def _check_expecter(expecter: object) -> None:
    if not isinstance(expecter, Expecter):
        raise InputError(f"expecter: expected an Expecter, got {type(expecter).__name__}")


def _check_clip(clip: object) -> None:
    if not isinstance(clip, bool):  # truth-tested: 'no' clipped, an array raised numpy's error
        raise InputError(f"clip: expected a bool, got {clip!r}")


def _check_map(map: object) -> None:
    if not isinstance(map, SpatialUncertaintyMap):
        raise InputError(f"map: expected a SpatialUncertaintyMap, got {type(map).__name__}")


def _mean_pose(value: Pose | ArrayLike) -> tuple[float, float, float]:
    if isinstance(value, Pose):
        return (value.x, value.y, value.heading)
    if isinstance(value, (str, bytes)):
        raise InputError(f"mean_pose: expected a Pose or (x, y, heading), got {value!r}")
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"mean_pose: expected a Pose or (x, y, heading), got {value!r}") from exc
    if array.shape != (3,):
        raise InputError(f"mean_pose: expected shape (3,), got {array.shape}")
    x, y, heading = (finite_float(float(v), f"mean_pose[{i}]") for i, v in enumerate(array))
    return (x, y, heading)


def _covariance(value: ArrayLike) -> NDArray[np.float64]:
    if isinstance(value, (str, bytes)):
        raise InputError(f"covariance: expected a (3, 3) array of numbers, got {value!r}")
    try:
        cov = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"covariance: expected a (3, 3) array of numbers, got {value!r}") from exc
    if cov.shape != (3, 3):
        raise InputError(f"covariance: expected shape (3, 3), got {cov.shape}")
    if not np.all(np.isfinite(cov)):
        raise InputError("covariance: expected finite numbers, got non-finite values")
    diagonal = np.diag(cov)
    if np.any(diagonal < 0.0):
        raise InputError(f"covariance: expected non-negative variances, got {diagonal.tolist()}")
    scale = float(np.max(np.abs(cov)))
    if not np.allclose(cov, cov.T, rtol=1e-9, atol=1e-12 * scale):
        raise InputError("covariance: expected a symmetric matrix, got an asymmetric one")
    return cov
