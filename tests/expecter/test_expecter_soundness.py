"""Soundness: from every pose of the map, the landmark projects inside Expecter.bounds.

Horizontal and vertical extents are asserted separately; >= 10,000 poses per class, over
tilted/panned cameras with a mount offset and a distorted camera.
"""

from __future__ import annotations

import numpy as np
import pytest

from aura_ums.expecter import Expecter
from tests.expecter.expecter_helpers import (
    CAMERAS,
    extreme_poses,
    landmark_points,
    random_landmark,
    random_map,
    visible_pixels,
)

POSES_PER_MAP = 1000
MAPS_PER_CAMERA = 4


@pytest.mark.parametrize("kind", ["I", "II", "III"])
def test_projection_lies_inside_bounds(kind: str, rng: np.random.Generator) -> None:
    checked_poses = 0
    checked_pixels = 0
    for name, camera in CAMERAS.items():
        expecter = Expecter(camera)
        for index in range(MAPS_PER_CAMERA):
            the_map = random_map(rng, wide_wedge=index == 3)
            landmark = random_landmark(rng, kind, the_map.center, ahead=index != 2)
            poses = np.vstack([the_map.sample_poses(POSES_PER_MAP, rng), extreme_poses(the_map)])
            pixels = visible_pixels(camera, poses, landmark_points(landmark, rng))
            window = expecter.bounds(the_map, landmark)
            checked_poses += len(poses)
            checked_pixels += len(pixels)
            if window is None:
                assert len(pixels) == 0, f"{name}: None, yet {len(pixels)} visible projections"
                continue
            u, v = pixels[:, 0], pixels[:, 1]
            assert np.all((u >= window.u_min) & (u <= window.u_max)), (
                f"{name} map {index}: u in [{u.min()}, {u.max()}] outside [{window.u_min}, {window.u_max}]"
            )
            assert np.all((v >= window.v_min) & (v <= window.v_max)), (
                f"{name} map {index}: v in [{v.min()}, {v.max()}] outside [{window.v_min}, {window.v_max}]"
            )
    assert checked_poses >= 10_000
    assert checked_pixels > 0


@pytest.mark.parametrize("kind", ["I", "II", "III"])
def test_distorted_camera_extreme_poses_are_inside(kind: str, rng: np.random.Generator) -> None:
    # Landmarks anywhere around, including partly behind and close: distortion far off-axis.
    camera = CAMERAS["distorted"]
    expecter = Expecter(camera)
    for _ in range(8):
        the_map = random_map(rng, wide_wedge=True)
        landmark = random_landmark(rng, kind, the_map.center, ahead=False)
        poses = np.vstack([the_map.sample_poses(300, rng), extreme_poses(the_map, per_edge=8)])
        pixels = visible_pixels(camera, poses, landmark_points(landmark, rng))
        window = expecter.bounds(the_map, landmark)
        if window is None:
            assert len(pixels) == 0
            continue
        assert np.all((pixels[:, 0] >= window.u_min) & (pixels[:, 0] <= window.u_max))
        assert np.all((pixels[:, 1] >= window.v_min) & (pixels[:, 1] <= window.v_max))
