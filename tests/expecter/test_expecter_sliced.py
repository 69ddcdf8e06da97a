"""The Expecter on heading-sliced maps: sound from every pose of every slice, and no wider."""

from __future__ import annotations

import math

import numpy as np
import pytest

from aura_ums.expecter import Expecter
from aura_ums.uncertainty import TerrainTable, TurnAndRun
from tests.expecter.expecter_helpers import (
    CAMERAS,
    landmark_points,
    random_landmark,
    random_map,
    visible_pixels,
)


@pytest.mark.parametrize("kind", ["I", "II", "III"])
def test_projection_from_a_sliced_map_lies_inside_its_bounds(kind: str, rng: np.random.Generator) -> None:
    terrain = TerrainTable.default()["grass"]
    checked = 0
    for name, camera in CAMERAS.items():
        expecter = Expecter(camera)
        for index in range(3):
            product = random_map(rng, wide_wedge=index == 2)
            # Grown once: the slices then hold different positions.
            sliced = product.with_slices(math.radians(2.0)).grow(TurnAndRun(0.3, 3.0), terrain)
            landmark = random_landmark(rng, kind, sliced.center, ahead=index != 1)
            poses = sliced.sample_poses(1500, rng)
            pixels = visible_pixels(camera, poses, landmark_points(landmark, rng))
            window = expecter.bounds(sliced, landmark)
            checked += len(poses)
            if window is None:
                assert len(pixels) == 0, f"{name}: None, yet {len(pixels)} visible projections"
                continue
            u, v = pixels[:, 0], pixels[:, 1]
            assert np.all((u >= window.u_min) & (u <= window.u_max)), name
            assert np.all((v >= window.v_min) & (v <= window.v_max)), name
            summary = expecter.bounds(sliced.without_slices(), landmark)
            assert summary is not None
            # The slices' union lies inside its summary: its window is no larger, but for the
            # outer polygons of the arcs (0.03 % of the reach), which the slices cut elsewhere.
            slack = 1e-3 * max(summary.width, summary.height, 1.0)
            # (Without distortion, whose bounds are refined over each set of points on its own.)
            moderate = (
                max(abs(summary.u_min), abs(summary.u_max), abs(summary.v_min), abs(summary.v_max)) < 1e5
            )
            if moderate and camera.intrinsics.distortion is None:
                assert window.u_min >= summary.u_min - slack
                assert window.u_max <= summary.u_max + slack
                assert window.v_min >= summary.v_min - slack
                assert window.v_max <= summary.v_max + slack
    assert checked >= 10_000
