"""Observers: the pixels where an expected landmark appeared, turned into its observation.

The camera bounds the bearing, range, offset or angle that a pixel (or an image segment)
measures, over every camera and pixel within the calibration and pixel error bounds
(:func:`~aura_ums.camera.bound_vertical_line` and its kin). The observers here attach that
measurement to the landmark seen, at the time of the image, from the camera's place on the
robot: a Class I, II or III observation that the reductions of the map accept.
"""

from __future__ import annotations

from numpy.typing import ArrayLike

from aura_ums._validate import finite_float
from aura_ums.camera import (
    CalibrationBounds,
    Camera,
    bound_ground_line,
    bound_point,
    bound_vertical_line,
)
from aura_ums.errors import InputError
from aura_ums.uncertainty import (
    BearingObservation,
    GroundLineLandmark,
    GroundLineObservation,
    PointLandmark,
    RangeBearingObservation,
    VerticalLineLandmark,
)


def observe_vertical_line(
    camera: Camera,
    landmark: VerticalLineLandmark,
    pixel: ArrayLike,
    *,
    time: float,
    pixel_error: float = 0.5,
    bounds: CalibrationBounds | None = None,
) -> BearingObservation:
    """Turn a pixel on the image of a vertical line into a bounded bearing (Class I).

    The bearing is :func:`~aura_ums.camera.bound_vertical_line`'s: the azimuth of the
    vertical plane through the pixel's ray, in the robot frame, measured from the optical
    centre (``sensor_offset = camera.mount.sensor_offset``).

    Parameters
    ----------
    camera : Camera
        The nominal camera.
    landmark : VerticalLineLandmark
        The landmark seen (its id names the observation).
    pixel : array_like, shape (2,)
        (u, v) of any point of the line's image, inside the image.
    time : float
        Time of the image, seconds.
    pixel_error : float
        Bound on the pixel's error in u and in v, pixels, in [0, 1e5].
    bounds : CalibrationBounds, optional
        Bounds on the calibration; None for an exact calibration.

    Returns
    -------
    BearingObservation
        ``bearing`` is the centre of the guaranteed interval (radians), ``bearing_error``
        its half-width, pi when the ray may be vertical (no bearing information).

    Raises
    ------
    InputError
        For a landmark of another class, a time that is not finite, a pixel outside the
        image or not finite, a negative error, or bounds that make a focal length
        non-positive.

    Examples
    --------
    >>> from aura_ums.camera import CameraIntrinsics, CameraMount
    >>> camera = Camera(CameraIntrinsics(500, 500, 320, 240, 640, 480), CameraMount(1.0, pan=0.5))
    >>> pole = VerticalLineLandmark("pole", 5.0, 0.0, 0.0, 3.0)
    >>> obs = observe_vertical_line(camera, pole, (320, 100), time=0.0, pixel_error=0.0)
    >>> round(obs.bearing, 6), obs.bearing_error < 1e-8    # the optical axis, tilted or not
    (0.5, True)
    >>> observe_vertical_line(camera, pole, (640, 100), time=0.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: pixel: expected a pixel inside the 640x480 image \
([-0.5, 639.5] x [-0.5, 479.5]), got (640.0, 100.0)
    """
    if not isinstance(landmark, VerticalLineLandmark):
        raise InputError(f"landmark: expected VerticalLineLandmark, got {type(landmark).__name__}")
    when = finite_float(time, "time")
    bearing, bearing_error = bound_vertical_line(camera, pixel, pixel_error=pixel_error, bounds=bounds)
    return BearingObservation(landmark.id, when, bearing, bearing_error, camera.mount.sensor_offset)


def observe_point(
    camera: Camera,
    landmark: PointLandmark,
    pixel: ArrayLike,
    *,
    time: float,
    pixel_error: float = 0.5,
    bounds: CalibrationBounds | None = None,
    max_range: float | None = None,
) -> RangeBearingObservation:
    """Turn the pixel of a point landmark of known height into bounded bearing and range (Class II).

    Bearing and range are :func:`~aura_ums.camera.bound_point`'s at the landmark's height
    ``z`` (the ground-plane assumption): near the horizon the range grows without bound,
    and ``max_range``, when given, is a bound on the true range that the caller asserts
    (e.g. the landmark's activation range) and that caps ``range_max``.

    Parameters
    ----------
    camera : Camera
        The nominal camera.
    landmark : PointLandmark
        The landmark seen; its ``z`` is used.
    pixel : array_like, shape (2,)
        (u, v) of the landmark's image, inside the image.
    time : float
        Time of the image, seconds.
    pixel_error : float
        Bound on the pixel's error in u and in v, pixels, in [0, 1e5].
    bounds : CalibrationBounds, optional
        Bounds on the calibration; None for an exact calibration.
    max_range : float, optional
        Known bound on the true range, metres, > 0.

    Returns
    -------
    RangeBearingObservation
        Bearing as in :func:`observe_vertical_line`, ``[range_min, range_max]`` in metres.

    Raises
    ------
    InputError
        As :func:`observe_vertical_line`; also for a pixel at or above the horizon, error
        bounds reaching the horizon without ``max_range``, a camera height bound that
        reaches the landmark's height, or a range_min beyond ``max_range``.

    Examples
    --------
    >>> from aura_ums.camera import CameraIntrinsics, CameraMount
    >>> camera = Camera(CameraIntrinsics(500, 500, 320, 240, 640, 480), CameraMount(1.0, tilt=0.1))
    >>> corner = PointLandmark("corner", 10.0, 0.0, 0.0)
    >>> obs = observe_point(camera, corner, (320, 240), time=0.0, pixel_error=0.0)
    >>> round(obs.range_min, 6), round(obs.range_max, 6)    # 1 m / tan(0.1)
    (9.966644, 9.966644)
    >>> observe_point(camera, corner, (320, 100), time=0.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: pixel: expected a pixel below the horizon for a landmark at \
height 0.0 m (camera at 1.0 m), got (320.0, 100.0) whose ray never meets that plane
    """
    if not isinstance(landmark, PointLandmark):
        raise InputError(f"landmark: expected PointLandmark, got {type(landmark).__name__}")
    when = finite_float(time, "time")
    bearing, bearing_error, range_min, range_max = bound_point(
        camera, pixel, landmark.z, pixel_error=pixel_error, bounds=bounds, max_range=max_range
    )
    return RangeBearingObservation(
        landmark.id, when, bearing, bearing_error, range_min, range_max, camera.mount.sensor_offset
    )


def observe_ground_line(
    camera: Camera,
    landmark: GroundLineLandmark,
    segment: ArrayLike,
    *,
    expected_angle: float,
    time: float,
    pixel_error: float = 0.5,
    bounds: CalibrationBounds | None = None,
) -> GroundLineObservation:
    """Turn an image segment of a known ground line into bounded offset and angle (Class III).

    Offset and angle are :func:`~aura_ums.camera.bound_ground_line`'s: ``offset`` is the
    signed distance from the optical centre (the ``sensor_offset``) to the line, positive
    when it is left of the landmark's start -> end direction; ``angle`` is that direction
    relative to the heading. The image does not say which end is ``start``: the line is
    oriented along whichever of its two directions is closer to ``expected_angle`` (robot
    frame, radians), e.g. ``landmark.direction - heading`` for a heading estimate; it must
    be within 90 degrees of the truth.

    Parameters
    ----------
    camera : Camera
        The nominal camera.
    landmark : GroundLineLandmark
        The landmark seen.
    segment : array_like, shape (4,) or (2, 2)
        (u1, v1, u2, v2): two image points of the line, inside the image, both below
        the horizon.
    expected_angle : float
        Roughly expected direction start -> end relative to the heading, radians.
    time : float
        Time of the image, seconds.
    pixel_error : float
        Bound on each end's error in u and in v, pixels, in [0, 1e5].
    bounds : CalibrationBounds, optional
        Bounds on the calibration; None for an exact calibration.

    Returns
    -------
    GroundLineObservation
        ``offset`` (m) and ``angle`` (rad, wrapped) at the centres of their guaranteed
        intervals, with the half-widths as errors.

    Raises
    ------
    InputError
        For bad pixels, errors or landmark type as :func:`observe_vertical_line`; an end
        at or above the horizon, or whose error bounds reach it; a camera height bound
        that reaches the ground; a segment too short for its error bounds to fix a
        direction.

    Examples
    --------
    >>> from aura_ums.camera import CameraIntrinsics, CameraMount
    >>> from aura_ums.geometry import Pose
    >>> camera = Camera(CameraIntrinsics(500, 500, 320, 240, 640, 480), CameraMount(1.0, tilt=0.3))
    >>> edge = GroundLineLandmark("edge", (0.0, -2.0), (10.0, -2.0))
    >>> # the images of the ground points (3, -2) and (6, -2) seen from the origin, heading 0
    >>> uv = camera.project(Pose(0, 0, 0), [(3.0, -2.0, 0.0), (6.0, -2.0, 0.0)])
    >>> obs = observe_ground_line(camera, edge, uv[::-1], expected_angle=0.0, time=0.0, pixel_error=0.0)
    >>> round(obs.offset, 6), round(obs.angle, 6) + 0.0      # ends given in either order
    (2.0, 0.0)
    >>> observe_ground_line(camera, edge, (0, 0, 10, 10), expected_angle=0.0, time=0.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: segment: expected both ends below the horizon, got end 1 at (0.0, 0.0)
    """
    if not isinstance(landmark, GroundLineLandmark):
        raise InputError(f"landmark: expected GroundLineLandmark, got {type(landmark).__name__}")
    when = finite_float(time, "time")
    offset, offset_error, angle, angle_error = bound_ground_line(
        camera, segment, expected_angle=expected_angle, pixel_error=pixel_error, bounds=bounds
    )
    return GroundLineObservation(
        landmark.id, when, offset, offset_error, angle, angle_error, camera.mount.sensor_offset
    )
