"""The schemas' fast paths against their references: activation distance, motion prediction, projection."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

from aura_ums.camera import Camera, CameraIntrinsics, CameraMount, fold_radius, undistort_points
from aura_ums.expecter import ImageWindow
from aura_ums.geometry import ConvexPolygon, HeadingWedge
from aura_ums.schemas._perceive import _project, _rotation, map_gap, may_be_within, predicted_shift
from aura_ums.schemas._state import Detection
from aura_ums.uncertainty import (
    GroundLineLandmark,
    Landmark,
    PointLandmark,
    Pose,
    SpatialUncertaintyMap,
    VerticalLineLandmark,
)

CAMERAS = [
    Camera(CameraIntrinsics(500.0, 500.0, 320.0, 240.0, 640, 480), CameraMount(height=1.0)),
    Camera(
        CameraIntrinsics(520.0, 505.0, 318.0, 236.0, 640, 480, distortion=(-0.2, 0.05, 1e-3, -8e-4, -0.01)),
        CameraMount(height=1.3, forward=0.3, left=-0.1, pan=0.35, tilt=0.2),
    ),
]


def random_polygon_map(rng: np.random.Generator) -> SpatialUncertaintyMap:
    """A random convex polygon of 1 to 11 vertices (points and segments included)."""
    points = rng.normal(size=(int(rng.integers(1, 12)), 2)) * rng.uniform(0.01, 4.0) + rng.normal(size=2)
    polygon = ConvexPolygon.from_points(points)
    center = polygon.vertices[0] if polygon.vertex_count < 3 else polygon.vertices.mean(axis=0)
    return SpatialUncertaintyMap(polygon, center, HeadingWedge(0.0, 0.1, 0.1))


def random_landmark(rng: np.random.Generator, index: int) -> Landmark:
    place = rng.normal(size=2) * 3.0
    if index % 3 == 0:
        return VerticalLineLandmark("pole", place[0], place[1], 0.0, 2.0)
    if index % 3 == 1:
        return PointLandmark("corner", place[0], place[1], 1.0)
    return GroundLineLandmark("edge", place, place + rng.normal(size=2) * rng.uniform(0.01, 6.0))


def test_distance_edge_cases() -> None:
    square = SpatialUncertaintyMap.from_polygon(
        ConvexPolygon([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]), (0.5, 0.5), HeadingWedge(0, 0, 0)
    )
    crossing = GroundLineLandmark("across", (-1.0, 0.5), (2.0, 0.5))  # no end inside
    corner_touch = GroundLineLandmark("touch", (1.0, 1.0), (2.0, 3.0))
    beside = GroundLineLandmark("beside", (2.0, -1.0), (2.0, 2.0))
    for landmark, gap in ((crossing, 0.0), (corner_touch, 0.0), (beside, 1.0)):
        assert map_gap(square, landmark) == pytest.approx(gap, abs=1e-15)


def test_activation_is_the_distance_within_reach(rng: np.random.Generator) -> None:
    the_map = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.5, 0.1)
    pole = VerticalLineLandmark("pole", 10.0, 0.0, 0.0, 3.0, position_uncertainty=0.2)
    gap = float(shapely.distance(the_map.polygon.to_shapely(), shapely.Point(10.0, 0.0)))
    assert may_be_within(the_map, pole, gap - 0.2 + 1e-9)
    assert not may_be_within(the_map, pole, gap - 0.2 - 1e-9)
    for index in range(300):
        other, landmark = random_polygon_map(rng), random_landmark(rng, index)
        geometry: shapely.Geometry
        if isinstance(landmark, GroundLineLandmark):
            geometry = shapely.LineString([landmark.start, landmark.end])
        else:
            geometry = shapely.Point(landmark.x, landmark.y)
        expected = float(shapely.distance(other.polygon.to_shapely(), geometry))
        assert map_gap(other, landmark) == pytest.approx(expected, abs=1e-12)


# --- motion prediction and projection -------------------------------------------------


def reference_shift(
    camera: Camera, landmark: Landmark, detection: Detection, pose: Pose
) -> tuple[float, float] | None:
    """The numpy formulation of predicted_shift (Camera.project and the mount's rotation matrix)."""
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


@pytest.mark.parametrize("camera", CAMERAS, ids=["plain", "distorted"])
def test_predicted_shift_agrees_with_the_numpy_formulation(camera: Camera, rng: np.random.Generator) -> None:
    left_view = 0
    for index in range(400):
        then = Pose(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-0.3, 0.3))
        now = Pose(
            then.x + rng.uniform(-2, 2), then.y + rng.uniform(-1, 1), then.heading + rng.uniform(-1.5, 1.5)
        )
        landmark: Landmark
        if index % 2:
            landmark = VerticalLineLandmark("pole", rng.uniform(3, 12), rng.uniform(-4, 4), 0.0, 3.0)
        else:
            landmark = GroundLineLandmark("edge", (1.0, -2.0), (12.0, -2.5))
        u, v = rng.uniform(-0.5, 639.5), rng.uniform(-0.5, 479.5)
        box = ImageWindow(u, v, u, v)
        detection = Detection(0.0, 1.0, (u, v), box, None, then)
        ours = predicted_shift(camera, landmark, detection, now)
        reference = reference_shift(camera, landmark, detection, now)
        assert (ours is None) == (reference is None)
        if ours is None or reference is None:
            left_view += 1
            continue
        assert ours == pytest.approx(reference, rel=1e-9, abs=1e-7)
    assert left_view > 0


@pytest.mark.parametrize("camera", CAMERAS, ids=["plain", "distorted"])
def test_float_projection_agrees_with_camera_project(camera: Camera, rng: np.random.Generator) -> None:
    rotation = _rotation(camera.mount.pan, camera.mount.tilt)
    assert np.allclose(np.array(rotation).reshape(3, 3), camera.mount.rotation(), rtol=0.0, atol=0.0)
    behind = 0
    for _ in range(500):
        pose = Pose(rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-math.pi, math.pi))
        point = (rng.uniform(-10, 10), rng.uniform(-10, 10), rng.uniform(-1, 3))
        ours = _project(camera, rotation, pose, point)
        reference = camera.project(pose, [point])[0]
        if ours is None:
            assert not np.isfinite(reference).all()
            behind += 1
            continue
        assert ours == pytest.approx(reference.tolist(), rel=1e-12, abs=1e-9)
    assert behind > 0


def test_float_projection_beyond_the_lens_fold_is_none_as_camera_project_is_nan() -> None:
    # A barrel lens folding 57 degrees off axis (r = 1.543): the polynomial put a point 63
    # degrees off axis on the pixels of a ray within the fold; both projections refuse it.
    camera = Camera(
        CameraIntrinsics(300.0, 300.0, 320.0, 240.0, 640, 480, distortion=(-0.14, 0.0, 0.0, 0.0, 0.0)),
        CameraMount(height=1.0),
    )
    rotation = _rotation(camera.mount.pan, camera.mount.tilt)
    pose = Pose(0.0, 0.0, 0.0)
    limit = fold_radius(camera.intrinsics.distortion)
    for angle in np.linspace(-math.pi, math.pi, 13):  # around the optical axis (robot forward)
        for scale, imaged in ((0.999, True), (1.001, False), (1.3, False)):
            r = scale * limit
            point = (1.0, -r * math.cos(angle), 1.0 - r * math.sin(angle))  # 1 m ahead
            ours = _project(camera, rotation, pose, point)
            reference = camera.project(pose, [point])[0]
            assert (ours is not None) is imaged
            assert bool(np.isfinite(reference).all()) is imaged
            if ours is not None:
                assert ours == pytest.approx(reference.tolist(), rel=1e-12, abs=1e-9)
