"""Private glue between a landmark record and perception: detectors, evaluation, motion prediction.

Supported (landmark class, perceptual strategy) pairs, with the record's ``parameters``:

- Class I, ``LINE_FINDER``: :class:`FastLineFinder` tuned to ``orientation`` (image
  radians, default pi/2), ``tolerance``, ``min_length``, ``min_gradient``,
  ``min_contrast``, ``smoothing``, ``buckets``; :func:`evaluate_vertical_line`.
- Class I, ``REGION_SEGMENTER``: :class:`RegionSegmenter` (``threshold``, ``min_area``);
  the tallest region at least ``min_aspect`` (default 3) times taller than wide; value:
  its height in pixels; location: its centroid (on the line's axis).
- Class II, ``INTEREST_OPERATOR``: :class:`MoravecOperator` (``window`` -> size,
  ``min_interest`` -> threshold, ``suppression``); :func:`evaluate_corner`. Two or more
  interest points at or above the recognition threshold in the window make the corner
  ambiguous: no hit.
- Class III, ``LINE_FINDER``: :class:`FastLineFinder` as for Class I; without an
  ``orientation`` it is tuned, frame by frame, to the image direction of the ground line
  seen from the map's most probable pose; :func:`evaluate_path_edge`.
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np

from aura_ums import _native
from aura_ums.camera import (
    NEAR_PLANE,
    CalibrationBounds,
    Camera,
    fold_radius,
    robot_from_camera_rotation,
    undistort_points,
)
from aura_ums.errors import InputError
from aura_ums.expecter import (
    ImageWindow,
    PerceptualStrategy,
    observe_ground_line,
    observe_point,
    observe_vertical_line,
)
from aura_ums.perception import (
    FastLineFinder,
    MoravecOperator,
    RegionSegmenter,
    evaluate_corner,
    evaluate_path_edge,
    strongest_within,
)
from aura_ums.schemas._frame import Frame
from aura_ums.schemas._state import Detection
from aura_ums.uncertainty import (
    GroundLineLandmark,
    Landmark,
    LandmarkClass,
    Observation,
    PointLandmark,
    Pose,
    SpatialUncertaintyMap,
    VerticalLineLandmark,
)
from aura_ums.world import LandmarkRecord

#: A perceptual strategy, parameterized.
Detector = FastLineFinder | MoravecOperator | RegionSegmenter

#: Default ``min_aspect`` (height over width) of a Class I region.
DEFAULT_MIN_ASPECT = 3.0
#: Ground-line samples used to predict its image direction.
_LINE_SAMPLES = 65


def _integer(name: str, value: float) -> int:
    if not float(value).is_integer():
        raise InputError(f"{name}: expected an integer, got {value!r}")
    return int(value)


def build_detector(record: LandmarkRecord) -> Detector:
    """Return the record's perceptual strategy, parameterized from its ``parameters``.

    A parameter out of its strategy's range is named as the map names it
    (``pole_a.parameters.smoothing``), not by the detector's own field.
    """
    try:
        return _build_detector(record)
    except InputError as exc:
        field, sep, message = str(exc).partition(": ")
        if not sep or "." in field:
            raise
        renamed = _MORAVEC_PARAMETERS if record.strategy is PerceptualStrategy.INTEREST_OPERATOR else {}
        raise InputError(f"{record.id}.parameters.{renamed.get(field, field)}: {message}") from None


# MoravecOperator's fields as a map's parameters name them.
_MORAVEC_PARAMETERS = {"size": "window", "threshold": "min_interest"}


def _build_detector(record: LandmarkRecord) -> Detector:
    # The record checked its strategy against its class and its parameters' names
    # (PerceptualStrategy.for_class and .parameters); the values' ranges are the detectors'.
    cls, strategy, params = record.landmark_class, record.strategy, record.parameters
    name = f"{record.id}.parameters"
    if strategy is PerceptualStrategy.LINE_FINDER:
        options: dict[str, float | int | None] = {k: params[k] for k in strategy.parameters if k in params}
        if "buckets" in options:
            options["buckets"] = _integer(f"{name}.buckets", params["buckets"])
        if cls is LandmarkClass.VERTICAL_LINE:
            options.setdefault("orientation", math.pi / 2)
        else:
            options.setdefault("orientation", None)
        return FastLineFinder(**options)  # type: ignore[arg-type]
    if strategy is PerceptualStrategy.INTEREST_OPERATOR:
        moravec: dict[str, float | int] = {}
        if "window" in params:
            moravec["size"] = _integer(f"{name}.window", params["window"])
        if "min_interest" in params:
            moravec["threshold"] = params["min_interest"]
        if "suppression" in params:
            moravec["suppression"] = _integer(f"{name}.suppression", params["suppression"])
        return MoravecOperator(**moravec)  # type: ignore[arg-type]
    region: dict[str, float | int] = {}
    if "threshold" in params:
        region["threshold"] = params["threshold"]
    if "min_area" in params:
        region["min_area"] = _integer(f"{name}.min_area", params["min_area"])
    aspect = params.get("min_aspect", DEFAULT_MIN_ASPECT)
    if not aspect > 0.0:
        raise InputError(f"{name}.min_aspect: expected a positive number, got {aspect!r}")
    return RegionSegmenter(**region)  # type: ignore[arg-type]


def may_be_within(map: SpatialUncertaintyMap, landmark: Landmark, reach: float) -> bool:
    """Whether some position of the map is within ``reach`` metres of where the landmark may be."""
    return map_gap(map, landmark) - landmark.position_uncertainty <= reach


def map_gap(map: SpatialUncertaintyMap, landmark: Landmark) -> float:
    """Distance (m) from the map's polygon (edges included) to the landmark's point or segment."""
    if isinstance(landmark, GroundLineLandmark):
        (ax, ay), (bx, by) = landmark.start.tolist(), landmark.end.tolist()
        return _native.polygon_distance(map.polygon.vertices, ax, ay, bx, by)
    return _native.polygon_distance(map.polygon.vertices, landmark.x, landmark.y, landmark.x, landmark.y)


def ground_line_orientation(camera: Camera, landmark: GroundLineLandmark, pose: Pose) -> float | None:
    """Image direction (radians in [0, pi), v down) of a ground line seen from ``pose``; None when unseen."""
    t = np.linspace(0.0, 1.0, _LINE_SAMPLES)[:, None]
    ground = landmark.start + t * (landmark.end - landmark.start)
    points = np.column_stack([ground, np.zeros(_LINE_SAMPLES)])
    uv = camera.project(pose, points)
    k = camera.intrinsics
    finite = np.isfinite(uv).all(axis=1)
    inside = finite & (uv[:, 0] >= -0.5) & (uv[:, 0] <= k.width - 0.5)
    inside &= (uv[:, 1] >= -0.5) & (uv[:, 1] <= k.height - 0.5)
    use = uv[inside] if int(inside.sum()) >= 2 else uv[finite]
    if len(use) < 2:
        return None
    du, dv = (use[-1] - use[0]).tolist()
    if math.hypot(du, dv) < 1.0:
        return None
    return math.atan2(dv, du) % math.pi


def _box(u1: float, v1: float, u2: float, v2: float) -> ImageWindow:
    return ImageWindow._trusted(min(u1, u2), min(v1, v2), max(u1, u2), max(v1, v2))


def detect(
    detector: Detector, record: LandmarkRecord, frame: Frame, window: ImageWindow, *, camera: Camera
) -> tuple[float, Detection | None]:
    """Run the strategy on the frame's window only and evaluate what it found; ``(value, detection or None)``.

    Lines come from :meth:`Frame.lines` (shared by schemas with an equal finder and
    window). The detection's pose is the map's most probable pose (the reference for
    motion prediction).
    """
    landmark = record.landmark
    image, time, pose = frame.image, frame.time, frame.map.most_probable_pose()
    if isinstance(detector, FastLineFinder):
        if isinstance(landmark, GroundLineLandmark):
            expected = detector.orientation
            if expected is None:
                expected = ground_line_orientation(camera, landmark, pose)
            tolerance = detector.tolerance
            finder = detector
            if expected is None:  # no prediction: any long line
                expected, tolerance = 0.0, math.pi / 2
            elif detector.orientation is None:
                finder = dataclasses.replace(detector, orientation=expected)
            lines = frame.lines(finder, window)
            evidence = evaluate_path_edge(
                lines, expected, tolerance=tolerance, min_length=detector.min_length
            )
        else:
            orientation = math.pi / 2 if detector.orientation is None else detector.orientation
            lines = frame.lines(detector, window)
            # evaluate_vertical_line without re-checking what the detector validated.
            evidence = strongest_within(lines, orientation, detector.tolerance)
        if evidence.segment is None or evidence.point is None:
            return evidence.value, None
        u1, v1, u2, v2 = (float(c) for c in evidence.segment)
        point = (float(evidence.point[0]), float(evidence.point[1]))
        detection = Detection(time, evidence.value, point, _box(u1, v1, u2, v2), (u1, v1, u2, v2), pose)
        return evidence.value, detection
    if isinstance(detector, MoravecOperator):
        points = detector.find(image, window)
        if int(np.count_nonzero(points[:, 2] >= record.recognition_threshold)) >= 2:
            # Several corners strong enough to be the landmark: which one is the mapped
            # corner cannot be told, and a wrong one would prune the true pose away.
            return 0.0, None
        corner = evaluate_corner(points)
        if corner.point is None:
            return corner.value, None
        u, v = float(corner.point[0]), float(corner.point[1])
        return corner.value, Detection(time, corner.value, (u, v), _box(u, v, u, v), None, pose)
    aspect = record.parameters.get("min_aspect", DEFAULT_MIN_ASPECT)
    best: tuple[float, tuple[float, float], ImageWindow] | None = None
    for region in detector.find(image, window):
        u0, v0, u1, v1 = region.bbox
        tall, wide = v1 - v0 + 1, u1 - u0 + 1
        if tall >= aspect * wide and (best is None or tall > best[0]):
            best = (float(tall), region.centroid, ImageWindow(u0, v0, u1, v1))
    if best is None:
        return 0.0, None
    return best[0], Detection(time, best[0], best[1], best[2], None, pose)


def observe(
    camera: Camera,
    record: LandmarkRecord,
    detection: Detection,
    map: SpatialUncertaintyMap,
    *,
    pixel_error: float,
    bounds: CalibrationBounds | None,
    detector: Detector,
) -> Observation:
    """Turn a detection into the camera's bounded observation (raises InputError when it cannot)."""
    landmark = record.landmark
    if isinstance(landmark, VerticalLineLandmark):
        return observe_vertical_line(
            camera, landmark, detection.point, time=detection.time, pixel_error=pixel_error, bounds=bounds
        )
    if isinstance(landmark, PointLandmark):
        # Moravec's point lies within size // 2 pixels of the corner (see MoravecOperator).
        bias = detector.size // 2 if isinstance(detector, MoravecOperator) else 0
        offset = math.hypot(*camera.mount.sensor_offset)
        farthest = float(np.max(record.distance(map.polygon.vertices)))
        cap = farthest + offset + landmark.position_uncertainty
        return observe_point(
            camera,
            landmark,
            detection.point,
            time=detection.time,
            pixel_error=pixel_error + bias,
            bounds=bounds,
            max_range=max(cap, 1e-9),
        )
    if detection.segment is None:  # pragma: no cover - Class III detectors always give a segment
        raise InputError(f"{landmark.id}: expected a line segment for a ground line, got none")
    return observe_ground_line(
        camera,
        landmark,
        detection.segment,
        expected_angle=landmark.direction - map.heading,
        time=detection.time,
        pixel_error=pixel_error,
        bounds=bounds,
    )


def predicted_shift(
    camera: Camera, landmark: Landmark, detection: Detection, pose: Pose
) -> tuple[float, float] | None:
    """Predict how far (pixels) the last detection has moved in the image from its pose to ``pose``.

    The detection's pixel is back-projected from the pose at detection time to a world
    point at the landmark's known distance (Class I and II: its horizontal range from
    the camera; Class III: the ground plane); that point is projected from ``pose``. None
    when the camera does not image it from there, behind the camera or beyond the lens's
    fold (the landmark has left the view).
    """
    k = camera.intrinsics
    if k.distortion is None:
        u, v = detection.point
        rx, ry = (u - k.cx) / k.fx, (v - k.cy) / k.fy
    else:
        ray = undistort_points(k, [detection.point])[0]
        if not np.isfinite(ray).all():
            return (0.0, 0.0)
        rx, ry = float(ray[0]), float(ray[1])
    then = detection.pose
    mount = camera.mount
    r = _rotation(mount.pan, mount.tilt)
    d0 = r[0] * rx + r[1] * ry + r[2]
    d1 = r[3] * rx + r[4] * ry + r[5]
    d2 = r[6] * rx + r[7] * ry + r[8]
    c, s = math.cos(then.heading), math.sin(then.heading)
    direction = (c * d0 - s * d1, s * d0 + c * d1, d2)
    centre = (
        then.x + c * mount.forward - s * mount.left,
        then.y + s * mount.forward + c * mount.left,
        mount.height,
    )
    if isinstance(landmark, GroundLineLandmark):
        if direction[2] >= -1e-9:
            return (0.0, 0.0)
        t = mount.height / -direction[2]
    else:
        horizontal = math.hypot(direction[0], direction[1])
        reach = math.hypot(landmark.x - centre[0], landmark.y - centre[1])
        if horizontal < 1e-9 or reach < 1e-9:
            return (0.0, 0.0)
        t = reach / horizontal
    point = (centre[0] + t * direction[0], centre[1] + t * direction[1], centre[2] + t * direction[2])
    before = _project(camera, r, then, point)
    after = _project(camera, r, pose, point)
    if before is None or after is None:
        return None
    return (after[0] - before[0], after[1] - before[1])


@functools.lru_cache(maxsize=64)
def _rotation(pan: float, tilt: float) -> tuple[float, ...]:
    """:meth:`CameraMount.rotation` as 9 floats, row by row (camera to robot axes)."""
    return tuple(float(value) for value in robot_from_camera_rotation(pan, tilt).ravel())


def _project(
    camera: Camera, r: tuple[float, ...], pose: Pose, point: tuple[float, float, float]
) -> tuple[float, float] | None:
    """:meth:`Camera.project` of one world point (m) from one pose, on floats; None where it gives NaN.

    None behind the camera and beyond the lens's fold (:func:`~aura_ums.camera.fold_radius`),
    as :meth:`Camera.project_camera_frame`.
    """
    mount, k = camera.mount, camera.intrinsics
    c, s = math.cos(pose.heading), math.sin(pose.heading)
    dx, dy = point[0] - pose.x, point[1] - pose.y
    bx = c * dx + s * dy - mount.forward
    by = -s * dx + c * dy - mount.left
    bz = point[2] - mount.height
    z = bx * r[2] + by * r[5] + bz * r[8]
    if not z > NEAR_PLANE:
        return None
    x = (bx * r[0] + by * r[3] + bz * r[6]) / z
    y = (bx * r[1] + by * r[4] + bz * r[7]) / z
    if k.distortion is not None:  # camera.distort's polynomial, on floats, within the fold
        limit = fold_radius(k.distortion)
        r2 = x * x + y * y
        if not r2 <= limit * limit:
            return None
        k1, k2, p1, p2, k3 = k.distortion
        radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
        x, y = (
            x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
            y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y,
        )
    u, v = k.fx * x + k.cx, k.fy * y + k.cy
    if not (math.isfinite(u) and math.isfinite(v)):
        return None
    return (u, v)


def intersection(a: ImageWindow, b: ImageWindow) -> ImageWindow | None:
    """Return the overlap of two windows, or None."""
    u0, v0 = max(a.u_min, b.u_min), max(a.v_min, b.v_min)
    u1, v1 = min(a.u_max, b.u_max), min(a.v_max, b.v_max)
    if u0 > u1 or v0 > v1:
        return None
    return ImageWindow(u0, v0, u1, v1)
