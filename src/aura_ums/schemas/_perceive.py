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
import math
from collections.abc import Mapping

import numpy as np
import shapely
from numpy.typing import NDArray

from aura_ums.camera import (
    CalibrationBounds,
    Camera,
    observe_ground_line,
    observe_point,
    observe_vertical_line,
    undistort_points,
)
from aura_ums.errors import InputError
from aura_ums.expecter import ImageWindow, PerceptualStrategy
from aura_ums.perception import (
    FastLineFinder,
    MoravecOperator,
    RegionSegmenter,
    evaluate_corner,
    evaluate_path_edge,
    evaluate_vertical_line,
)
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

_LINE_KEYS = (
    "orientation",
    "tolerance",
    "min_length",
    "min_gradient",
    "min_contrast",
    "smoothing",
    "buckets",
)
_MORAVEC_KEYS = ("window", "min_interest", "suppression")
_REGION_KEYS = ("threshold", "min_area", "min_aspect")
_SUPPORTED: Mapping[LandmarkClass, tuple[PerceptualStrategy, ...]] = {
    LandmarkClass.VERTICAL_LINE: (PerceptualStrategy.LINE_FINDER, PerceptualStrategy.REGION_SEGMENTER),
    LandmarkClass.POINT: (PerceptualStrategy.INTEREST_OPERATOR,),
    LandmarkClass.GROUND_LINE: (PerceptualStrategy.LINE_FINDER,),
}
#: Default ``min_aspect`` (height over width) of a Class I region.
DEFAULT_MIN_ASPECT = 3.0
#: Ground-line samples used to predict its image direction.
_LINE_SAMPLES = 65


def _integer(name: str, value: float) -> int:
    if not float(value).is_integer():
        raise InputError(f"{name}: expected an integer, got {value!r}")
    return int(value)


def build_detector(record: LandmarkRecord) -> Detector:
    """Return the record's perceptual strategy, parameterized from its ``parameters``."""
    cls, strategy, params = record.landmark_class, record.strategy, record.parameters
    name = f"{record.id}.parameters"
    if strategy not in _SUPPORTED[cls]:
        allowed = ", ".join(s.value for s in _SUPPORTED[cls])
        raise InputError(
            f"{record.id}.strategy: expected {allowed} for a Class {cls.value} landmark, got {strategy.value}"
        )
    keys = {
        PerceptualStrategy.LINE_FINDER: _LINE_KEYS,
        PerceptualStrategy.INTEREST_OPERATOR: _MORAVEC_KEYS,
        PerceptualStrategy.REGION_SEGMENTER: _REGION_KEYS,
    }[strategy]
    for key in params:
        if key not in keys:
            raise InputError(f"{name}: expected names among {', '.join(keys)}, got {key!r}")
    if strategy is PerceptualStrategy.LINE_FINDER:
        options: dict[str, float | int | None] = {k: params[k] for k in _LINE_KEYS if k in params}
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
    geometry: shapely.Geometry
    if isinstance(landmark, GroundLineLandmark):
        geometry = shapely.LineString([landmark.start, landmark.end])
    else:
        geometry = shapely.Point(landmark.x, landmark.y)
    gap = float(shapely.distance(map.polygon.to_shapely(), geometry))
    return gap - landmark.position_uncertainty <= reach


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


def _box(points: NDArray[np.float64]) -> ImageWindow:
    lo, hi = points.min(axis=0), points.max(axis=0)
    return ImageWindow(float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))


def detect(
    detector: Detector,
    record: LandmarkRecord,
    image: NDArray[np.generic],
    window: ImageWindow,
    *,
    camera: Camera,
    map: SpatialUncertaintyMap,
    time: float,
) -> tuple[float, Detection | None]:
    """Run the strategy on the window only and evaluate what it found; ``(value, detection or None)``."""
    pose = map.most_probable_pose()
    landmark = record.landmark
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
            lines = finder.find_detailed(image, window)
            evidence = evaluate_path_edge(
                lines, expected, tolerance=tolerance, min_length=detector.min_length
            )
        else:
            orientation = math.pi / 2 if detector.orientation is None else detector.orientation
            lines = detector.find_detailed(image, window)
            evidence = evaluate_vertical_line(lines, orientation=orientation, tolerance=detector.tolerance)
        if evidence.segment is None or evidence.point is None:
            return evidence.value, None
        seg = evidence.segment
        box = _box(np.array([[seg[0], seg[1]], [seg[2], seg[3]]]))
        return evidence.value, Detection(time, evidence.value, evidence.point, box, seg, pose)
    if isinstance(detector, MoravecOperator):
        points = detector.find(image, window)
        if int(np.count_nonzero(points[:, 2] >= record.recognition_threshold)) >= 2:
            # Several corners strong enough to be the landmark: which one is the mapped
            # corner cannot be told, and a wrong one would prune the true pose away.
            return 0.0, None
        corner = evaluate_corner(points)
        if corner.point is None:
            return corner.value, None
        box = _box(np.array([corner.point]))
        return corner.value, Detection(time, corner.value, corner.point, box, None, pose)
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
    when it is then behind the camera (the landmark has left the view).
    """
    ray = undistort_points(camera.intrinsics, [detection.point])[0]
    then = detection.pose
    if not np.isfinite(ray).all():
        return (0.0, 0.0)
    mount = camera.mount
    d = mount.rotation() @ np.array([ray[0], ray[1], 1.0])
    c, s = math.cos(then.heading), math.sin(then.heading)
    direction = np.array([c * d[0] - s * d[1], s * d[0] + c * d[1], d[2]])
    centre = np.array(
        [
            then.x + c * mount.forward - s * mount.left,
            then.y + s * mount.forward + c * mount.left,
            mount.height,
        ]
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
    point = (centre + t * direction).reshape(1, 3)
    before = camera.project(then, point)[0]
    after = camera.project(pose, point)[0]
    if not (np.isfinite(before).all() and np.isfinite(after).all()):
        return None
    return (float(after[0] - before[0]), float(after[1] - before[1]))


def intersection(a: ImageWindow, b: ImageWindow) -> ImageWindow | None:
    """Return the overlap of two windows, or None."""
    u0, v0 = max(a.u_min, b.u_min), max(a.v_min, b.v_min)
    u1, v1 = min(a.u_max, b.u_max), min(a.v_max, b.v_max)
    if u0 > u1 or v0 > v1:
        return None
    return ImageWindow(u0, v0, u1, v1)
