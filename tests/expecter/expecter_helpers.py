"""Shared builders for the Expecter tests: random maps, cameras, landmarks and samples."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from aura_ums.camera import NEAR_PLANE, Camera, CameraIntrinsics, CameraMount
from aura_ums.geometry import ConvexPolygon, HeadingWedge
from aura_ums.uncertainty import (
    GroundLineLandmark,
    Landmark,
    PointLandmark,
    SpatialUncertaintyMap,
    VerticalLineLandmark,
)

Array = NDArray[np.float64]

DISTORTION = (-0.28, 0.09, 1.2e-3, -8e-4, -0.015)

#: Cameras: tilted and panned with a mount offset; distorted, panned the other way and
#: tilted up; a plain one.
CAMERAS = {
    "tilted_panned_offset": Camera(
        CameraIntrinsics(520.0, 500.0, 322.0, 236.0, 640, 480),
        CameraMount(height=1.3, forward=0.4, left=-0.15, pan=0.4, tilt=0.3),
    ),
    "distorted": Camera(
        CameraIntrinsics(480.0, 490.0, 318.0, 242.0, 640, 480, distortion=DISTORTION),
        CameraMount(height=0.9, forward=-0.2, left=0.1, pan=-0.3, tilt=-0.1),
    ),
    "plain": Camera(CameraIntrinsics(500.0, 500.0, 319.5, 239.5, 640, 480), CameraMount(height=1.0)),
}


def random_map(rng: np.random.Generator, *, wide_wedge: bool = False) -> SpatialUncertaintyMap:
    """A random elongated convex polygon (3 to ~14 vertices) with a random wedge."""
    count = int(rng.integers(3, 15))
    points = rng.normal(size=(count, 2)) * [rng.uniform(0.3, 2.5), rng.uniform(0.05, 0.7)]
    angle = rng.uniform(-math.pi, math.pi)
    rotation = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    polygon = ConvexPolygon.from_points(points @ rotation.T + rng.uniform(-1.0, 1.0, 2))
    center = polygon.vertices.mean(axis=0)
    spread = 1.2 if wide_wedge else 0.25
    wedge = HeadingWedge(rng.uniform(-0.4, 0.4), rng.uniform(0.0, spread), rng.uniform(0.0, spread))
    return SpatialUncertaintyMap(polygon, center, wedge)


def random_landmark(rng: np.random.Generator, kind: str, center: Array, *, ahead: bool = True) -> Landmark:
    """A landmark of a class, in front of a robot facing east (or anywhere around)."""
    if ahead:
        distance, bearing = rng.uniform(5.0, 14.0), rng.uniform(-0.5, 0.5)
        place = center + distance * np.array([math.cos(bearing), math.sin(bearing)])
    else:
        place = center + rng.uniform(-10.0, 10.0, 2)
    radius = float(rng.choice([0.0, 0.0, 0.3]))
    if kind == "I":
        return VerticalLineLandmark(
            "pole",
            place[0],
            place[1],
            rng.uniform(0.0, 0.5),
            rng.uniform(1.0, 6.0),
            position_uncertainty=radius,
        )
    if kind == "II":
        return PointLandmark("corner", place[0], place[1], rng.uniform(0.0, 3.0), position_uncertainty=radius)
    end = place + rng.uniform(-6.0, 6.0, 2)
    return GroundLineLandmark("edge", place, end, position_uncertainty=radius)


def landmark_points(landmark: Landmark, rng: np.random.Generator, count: int = 17) -> Array:
    """World points (n, 3) along the landmark, at its place and displaced within its uncertainty."""
    t = np.linspace(0.0, 1.0, count)
    if isinstance(landmark, VerticalLineLandmark):
        z = landmark.z_bottom + t * (landmark.z_top - landmark.z_bottom)
        base = np.column_stack([np.full(count, landmark.x), np.full(count, landmark.y), z])
    elif isinstance(landmark, PointLandmark):
        base = np.array([[landmark.x, landmark.y, landmark.z]])
    else:
        ground = landmark.start + t[:, None] * (landmark.end - landmark.start)
        base = np.column_stack([ground, np.zeros(count)])
    radius = landmark.position_uncertainty
    if radius == 0.0:
        return base
    shifts = [np.zeros(2)]
    for _ in range(3):
        angle = rng.uniform(-math.pi, math.pi)
        reach = radius * (1.0 if len(shifts) % 2 else math.sqrt(rng.uniform()))
        shifts.append(reach * np.array([math.cos(angle), math.sin(angle)]))
    return np.concatenate([base + np.append(shift, 0.0) for shift in shifts])


def extreme_poses(the_map: SpatialUncertaintyMap, per_edge: int = 4) -> Array:
    """Vertices and edge points of the polygon with the wedge's two ends and its centre."""
    v = the_map.polygon.vertices
    following = np.roll(v, -1, axis=0)
    t = np.linspace(0.0, 1.0, per_edge, endpoint=False)
    places = (v[:, None, :] + t[None, :, None] * (following - v)[:, None, :]).reshape(-1, 2)
    w = the_map.wedge
    headings = [w.center - w.cw, w.center + w.ccw, w.center]
    return np.vstack([np.column_stack([places, np.full(len(places), h)]) for h in headings])


def visible_pixels(camera: Camera, poses: Array, points: Array) -> Array:
    """Pixels (k, 2) of the points the camera images from every pose.

    Those in front of it (z > NEAR_PLANE) and, with lens distortion, within the lens's fold
    (``fold_radius``): the others project to NaN.
    """
    frame = camera.to_camera_frame(poses, points)
    visible = frame[..., 2] > NEAR_PLANE
    pixels = np.asarray(camera.project_camera_frame(frame[visible]), dtype=np.float64)
    return pixels[np.isfinite(pixels).all(axis=1)]
