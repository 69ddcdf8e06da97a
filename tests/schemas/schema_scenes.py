"""Synthetic camera images of the three landmark classes, for the find-landmark schema tests.

Images are drawn with numpy from the *true* pose: a textured background (smooth shading
plus Gaussian noise), and the landmark where ``camera.project`` puts it.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from aura_ums.camera import Camera, CameraIntrinsics, CameraMount
from aura_ums.expecter import PerceptualStrategy
from aura_ums.uncertainty import (
    GroundLineLandmark,
    Landmark,
    Observation,
    PointLandmark,
    Pose,
    SpatialUncertaintyMap,
    VerticalLineLandmark,
)
from aura_ums.world import LandmarkRecord

WIDTH, HEIGHT = 640, 480
CAMERA = Camera(CameraIntrinsics(500.0, 500.0, 320.0, 240.0, WIDTH, HEIGHT), CameraMount(height=1.0))

Image = NDArray[np.uint8]


def background(rng: np.random.Generator, level: float = 90.0, noise: float = 2.5) -> NDArray[np.float64]:
    """Smoothly shaded, noisy gray background (no straight edges, no corners)."""
    v, u = np.mgrid[0:HEIGHT, 0:WIDTH].astype(np.float64)
    shade = 12.0 * np.sin(u / 97.0) + 8.0 * np.cos(v / 63.0 + 0.4)
    return np.asarray(level + shade + rng.normal(0.0, noise, (HEIGHT, WIDTH)), dtype=np.float64)


def finish(image: NDArray[np.float64]) -> Image:
    return np.clip(np.rint(image), 0, 255).astype(np.uint8)


def draw_thick_segment(
    image: NDArray[np.float64],
    a: NDArray[np.float64],
    b: NDArray[np.float64],
    half_width: float,
    value: float,
) -> None:
    """Set the pixels whose centre lies within ``half_width`` of segment ab (pixel coordinates)."""
    v, u = np.mgrid[0:HEIGHT, 0:WIDTH].astype(np.float64)
    d = b - a
    t = np.clip(((u - a[0]) * d[0] + (v - a[1]) * d[1]) / float(d @ d), 0.0, 1.0)
    gap = np.hypot(u - (a[0] + t * d[0]), v - (a[1] + t * d[1]))
    image[gap <= half_width] = value


def pole_image(
    rng: np.random.Generator,
    pose: Pose,
    poles: list[VerticalLineLandmark],
    *,
    half_width: float = 2.5,
    value: float = 200.0,
) -> Image:
    """Bright vertical bars where the poles project from ``pose``."""
    image = background(rng)
    for pole in poles:
        ends = CAMERA.project(pose, [(pole.x, pole.y, pole.z_bottom), (pole.x, pole.y, pole.z_top)])
        if np.isfinite(ends).all():
            draw_thick_segment(image, ends[0], ends[1], half_width, value)
    return finish(image)


def pole_column(pose: Pose, pole: VerticalLineLandmark) -> float:
    """Image column of the pole's axis from ``pose`` (the camera does not tilt: verticals stay vertical)."""
    return float(CAMERA.project(pose, [(pole.x, pole.y, 0.5 * (pole.z_bottom + pole.z_top))])[0, 0])


def corner_image(rng: np.random.Generator, pose: Pose, corner: PointLandmark, value: float = 200.0) -> Image:
    """A bright building face below and to the left of the corner's image (its top-right corner)."""
    image = background(rng)
    u_c, v_c = CAMERA.project(pose, [(corner.x, corner.y, corner.z)])[0]
    v, u = np.mgrid[0:HEIGHT, 0:WIDTH].astype(np.float64)
    image[(u <= u_c) & (v >= v_c)] = value
    return finish(image)


def ground_edge_image(
    rng: np.random.Generator, pose: Pose, edge: GroundLineLandmark, grass_side: float
) -> Image:
    """Dark grass below the horizon on one side of a ground line (the side ``grass_side`` points to)."""
    image = background(rng, level=130.0)
    a, b = edge.start, edge.end
    direction = (b - a) / np.linalg.norm(b - a)
    # two ground points of the line ahead of the robot, projected
    ahead = np.array([pose.x, pose.y]) + 4.0 * np.array([math.cos(pose.heading), math.sin(pose.heading)])
    foot = a + float((ahead - a) @ direction) * direction
    p = np.array([[*foot, 0.0], [*(foot + 10.0 * direction), 0.0]])
    uv = CAMERA.project(pose, p)
    side_point = CAMERA.project(pose, [(foot[0] + 2.0 * grass_side, foot[1] + 2.0 * grass_side, 0.0)])[0]
    v, u = np.mgrid[0:HEIGHT, 0:WIDTH].astype(np.float64)
    d = uv[1] - uv[0]
    side = d[0] * (v - uv[0, 1]) - d[1] * (u - uv[0, 0])
    reference = d[0] * (side_point[1] - uv[0, 1]) - d[1] * (side_point[0] - uv[0, 0])
    below_horizon = v > CAMERA.intrinsics.cy + 2.0
    image[(np.sign(side) == np.sign(reference)) & below_horizon] = 50.0
    return finish(image)


def pole_record(
    pole: VerticalLineLandmark, *, confirm: int = 3, activation: float = 25.0, threshold: float = 1500.0
) -> LandmarkRecord:
    return LandmarkRecord(
        pole,
        PerceptualStrategy.LINE_FINDER,
        {"orientation": math.pi / 2, "tolerance": math.radians(8.0), "min_length": 30.0},
        activation,
        threshold,
        confirm,
    )


def map_around(
    pose: Pose,
    *,
    offset: tuple[float, float, float] = (0.15, -0.1, 0.01),
    radius: float = 0.4,
    halfwidth: float = math.radians(3.0),
) -> SpatialUncertaintyMap:
    """A map whose most probable pose is off the true one by ``offset`` and that contains the true pose."""
    guess = Pose(pose.x + offset[0], pose.y + offset[1], pose.heading + offset[2])
    snapshot = SpatialUncertaintyMap.from_pose(guess, radius, halfwidth)
    assert snapshot.contains(pose)
    return snapshot


def assert_sound(
    observation: Observation, landmark: Landmark, prior: SpatialUncertaintyMap, truth: Pose
) -> None:
    """The observation agrees with the true pose: reducing the map by it is consistent and keeps the truth."""
    reduction = prior.reduce(observation, landmark)
    assert reduction.consistent, reduction.reason
    assert reduction.map.contains(truth)
    assert reduction.area_after <= reduction.area_before + 1e-9
