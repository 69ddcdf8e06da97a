"""Tightness: the window is barely larger than the projections of sampled poses.

Per class, over random maps with the landmark in front of the camera, the median of
window area / area of the bounding box of projections from 5,000 sampled poses must be
at most 1.25. The reference from the map's extreme poses (vertices with the wedge's ends)
shows that the remaining gap is the sampling's, not the window's.
"""

from __future__ import annotations

import numpy as np
import pytest

from aura_ums.camera import Camera, CameraIntrinsics, CameraMount
from aura_ums.expecter import Expecter
from aura_ums.uncertainty import Pose, SpatialUncertaintyMap, TerrainStats, TurnAndRun, VerticalLineLandmark
from tests.expecter.expecter_helpers import (
    CAMERAS,
    extreme_poses,
    landmark_points,
    random_landmark,
    random_map,
    visible_pixels,
)

MAPS = 12
SAMPLED_POSES = 5000


def _box_area(pixels: np.ndarray) -> float:
    return float(np.ptp(pixels[:, 0]) * np.ptp(pixels[:, 1]))


@pytest.mark.parametrize("camera_name", ["tilted_panned_offset", "distorted"])
@pytest.mark.parametrize("kind", ["I", "II", "III"])
def test_median_area_ratio(kind: str, camera_name: str, rng: np.random.Generator) -> None:
    camera = CAMERAS[camera_name]
    expecter = Expecter(camera)
    sampled_ratios: list[float] = []
    extreme_ratios: list[float] = []
    while len(sampled_ratios) < MAPS:
        the_map = random_map(rng)
        landmark = random_landmark(rng, kind, the_map.center)
        points = landmark_points(landmark, rng, count=9)
        poses = the_map.sample_poses(SAMPLED_POSES, rng)
        if np.any(camera.to_camera_frame(poses, points)[..., 2] <= 0.05):
            continue  # keep the landmark wholly in front: near the camera plane no box is finite
        window = expecter.bounds(the_map, landmark)
        assert window is not None
        sampled = visible_pixels(camera, poses, points)
        extremes = np.vstack([sampled, visible_pixels(camera, extreme_poses(the_map, per_edge=16), points)])
        sampled_ratios.append(window.area / _box_area(sampled))
        extreme_ratios.append(window.area / _box_area(extremes))
    median = float(np.median(sampled_ratios))
    print(
        f"class {kind} {camera_name}: median area ratio {median:.3f} (vs sampled poses), "
        f"{float(np.median(extreme_ratios)):.4f} (vs samples + extreme poses), max {max(sampled_ratios):.3f}"
    )
    assert min(sampled_ratios) >= 1.0 - 1e-9  # sound
    assert median <= 1.25
    # The worst too: the distorted camera's windows once held what its polynomial gives beyond
    # the lens's fold, which no ray reaches (up to 678, 6,215 and 3.8e6 times the box).
    assert max(sampled_ratios) <= 2.0


def test_a_distorted_window_of_a_thin_view_is_as_tight_as_the_poses_it_holds() -> None:
    # A vertical line 6 m ahead of a small grown map projects onto a thin sliver; an outer
    # polygon of ten vertices around it reached 107 px left of any pose's projection (u 365
    # against 472), so the window was 4 times wider than the distortion's reach.
    camera = Camera(
        CameraIntrinsics(
            554.256, 554.256, 319.5, 239.5, 640, 480, distortion=(-0.3, 0.1, 0.001, -0.001, 0.0)
        ),
        CameraMount(height=0.3),
    )
    terrain = TerrainStats(0.0, 0.0, 0.02, 0.01, 0.0, 0.02, 0.0, 0.0)
    the_map = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.3), 0.05, 0.02)
    for _ in range(2):
        the_map = the_map.grow(TurnAndRun(0.0, 0.075), terrain)
    landmark = VerticalLineLandmark("pole", 6.0, 0.0, 0.0, 1.0)
    window = Expecter(camera).bounds(the_map, landmark)
    assert window is not None
    rng = np.random.default_rng(0)
    poses = np.vstack([the_map.sample_poses(5000, rng), extreme_poses(the_map, per_edge=16)])
    pixels = visible_pixels(camera, poses, landmark_points(landmark, rng, count=9))
    left, right = pixels[:, 0].min(), pixels[:, 0].max()
    assert 0.0 <= left - window.u_min < 1.0  # sound, and within a pixel
    assert 0.0 <= window.u_max - right < 1.0
