"""Baselines: the disk model and an EKF's 3-sigma box, against the polygonal map."""

from __future__ import annotations

import math

import numpy as np
import pytest

from aura_ums.errors import InputError
from aura_ums.expecter import (
    Expecter,
    disk_model_map,
    disk_model_window,
    gaussian_box_map,
    gaussian_window,
)
from aura_ums.expecter._scenario import figure4_scenario
from aura_ums.uncertainty import PointLandmark, Pose
from tests.expecter.expecter_helpers import CAMERAS, random_landmark, random_map, visible_pixels


def test_disk_model_encloses_the_polygon(rng: np.random.Generator) -> None:
    for _ in range(10):
        the_map = random_map(rng)
        disk = disk_model_map(the_map)
        assert np.all(disk.polygon.contains(the_map.polygon.vertices, tolerance=1e-9))
        assert disk.wedge == the_map.wedge
        assert np.array_equal(disk.center, the_map.center)


def test_disk_window_contains_the_polygon_window(rng: np.random.Generator) -> None:
    expecter = Expecter(CAMERAS["tilted_panned_offset"])
    for kind in ("I", "II", "III"):
        the_map = random_map(rng)
        landmark = random_landmark(rng, kind, the_map.center)
        polygon = expecter.bounds(the_map, landmark)
        disk = disk_model_window(expecter, the_map, landmark, margin=0.0, clip=False)
        assert polygon is not None
        assert disk is not None
        assert disk.u_min <= polygon.u_min
        assert disk.u_max >= polygon.u_max
        assert disk.v_min <= polygon.v_min
        assert disk.v_max >= polygon.v_max


def test_figure4_scenario_windows_are_tall_and_wide_and_smaller_than_the_disk() -> None:
    scenario = figure4_scenario()
    expecter = Expecter(scenario.camera)
    ahead, beside = (expecter.bounds(scenario.map, lm) for lm in scenario.landmarks)
    assert ahead is not None
    assert beside is not None
    assert ahead.height > 2.0 * ahead.width  # landmark 1: tall
    assert beside.width > 2.0 * beside.height  # landmark 2: wide
    for landmark, window in zip(scenario.landmarks, (ahead, beside), strict=True):
        disk = disk_model_window(expecter, scenario.map, landmark, margin=0.0, clip=False)
        assert disk is not None
        assert window.area / disk.area <= 0.5


def test_gaussian_box_map_and_soundness(rng: np.random.Generator) -> None:
    camera = CAMERAS["tilted_panned_offset"]
    expecter = Expecter(camera)
    covariance = np.array([[0.25, 0.05, 0.0], [0.05, 0.04, 0.0], [0.0, 0.0, 0.003]])
    mean = Pose(1.0, 2.0, 0.1)
    box = gaussian_box_map(mean, covariance)
    assert box.area == pytest.approx(36.0 * 0.5 * 0.2)
    assert box.wedge.cw == pytest.approx(3.0 * math.sqrt(0.003))
    landmark = PointLandmark("corner", 12.0, 3.0, 2.0)
    window = gaussian_window(expecter, mean, covariance, landmark, margin=0.0, clip=False)
    assert window is not None
    assert window == expecter.bounds(box, landmark)
    pixels = visible_pixels(camera, box.sample_poses(3000, rng), np.array([[12.0, 3.0, 2.0]]))
    assert np.all(window.contains(pixels))
    clipped = gaussian_window(expecter, (1.0, 2.0, 0.1), covariance, landmark)
    assert clipped is not None
    assert clipped.u_min >= -0.5


def test_zero_covariance_gives_the_projection() -> None:
    camera = CAMERAS["plain"]
    expecter = Expecter(camera)
    landmark = PointLandmark("corner", 10.0, 0.0, 2.0)
    window = gaussian_window(expecter, (0.0, 0.0, 0.0), np.zeros((3, 3)), landmark, margin=0.0)
    assert window is not None
    assert window.contains(camera.project(Pose(0.0, 0.0, 0.0), [(10.0, 0.0, 2.0)])[0])
    assert window.area < 1e-6


def test_bad_baseline_input_is_refused() -> None:
    expecter = Expecter(CAMERAS["plain"])
    landmark = PointLandmark("corner", 10.0, 0.0, 2.0)
    good = np.eye(3) * 0.01
    with pytest.raises(InputError, match=r"^sigmas: expected a number in \(0, 100\], got 0\.0$"):
        gaussian_window(expecter, (0.0, 0.0, 0.0), good, landmark, sigmas=0.0)
    with pytest.raises(InputError, match=r"^sigmas: expected a number in \(0, 100\], got -3\.0$"):
        gaussian_window(expecter, (0.0, 0.0, 0.0), good, landmark, sigmas=-3.0)
    with pytest.raises(InputError, match=r"^sigmas: expected a finite number, got inf$"):
        gaussian_box_map((0.0, 0.0, 0.0), good, sigmas=math.inf)
    with pytest.raises(InputError, match=r"^sigmas: expected a finite number, got '3'$"):
        gaussian_box_map((0.0, 0.0, 0.0), good, sigmas="3")  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"^sigmas: expected a number in \(0, 100\], got 1e\+300$"):
        gaussian_box_map(Pose(0.5, 0.5, 0.0), np.diag([0.01, 0.01, 0.001]), 1e300)
    with pytest.raises(InputError, match=r"^sigmas: expected a number in \(0, 100\], got 1e\+300$"):
        gaussian_window(expecter, (0.0, 0.0, 0.0), good, landmark, sigmas=1e300)
    with pytest.raises(
        InputError,
        match=r"^covariance: expected a 3-sigma box within the world's coordinates a number in "
        r"\[-1e\+06, 1e\+06\] m, got half-widths \(3e\+100, 3e\+100\) m around \(0\.5, 0\.5\)$",
    ):
        gaussian_box_map(Pose(0.5, 0.5, 0.0), np.diag([1e200, 1e200, 0.001]))
    with pytest.raises(
        InputError,
        match=r"^mean_pose: expected x and y each a number in \[-1e\+06, 1e\+06\] m, "
        r"got \(10000000\.0, 0\.0\)$",
    ):
        gaussian_box_map((1e7, 0.0, 0.0), good)
    assert gaussian_box_map((0.0, 0.0, 0.0), good, sigmas=100).area == pytest.approx(400.0 * 0.01 * 100.0)
    scenario = figure4_scenario()
    with pytest.raises(InputError, match=r"^clip: expected a bool, got 'no'$"):
        disk_model_window(expecter, scenario.map, landmark, clip="no")  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"^clip: expected a bool, got array\(\[ True, False\]\)$"):
        disk_model_window(expecter, scenario.map, landmark, clip=np.array([True, False]))  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"^clip: expected a bool, got 1$"):
        gaussian_window(expecter, (0.0, 0.0, 0.0), good, landmark, clip=1)  # type: ignore[arg-type]
    bad = good.copy()
    bad[1, 1] = math.nan
    with pytest.raises(InputError, match="covariance: expected finite numbers"):
        gaussian_window(expecter, (0.0, 0.0, 0.0), bad, landmark)
    with pytest.raises(InputError, match=r"covariance: expected shape \(3, 3\)"):
        gaussian_box_map((0.0, 0.0, 0.0), np.eye(2))
    with pytest.raises(InputError, match="covariance: expected a \\(3, 3\\) array of numbers"):
        gaussian_box_map((0.0, 0.0, 0.0), "identity")
    with pytest.raises(InputError, match="covariance: expected non-negative variances"):
        gaussian_box_map((0.0, 0.0, 0.0), -good)
    with pytest.raises(InputError, match="covariance: expected a symmetric matrix"):
        gaussian_box_map((0.0, 0.0, 0.0), good + np.triu(np.ones((3, 3)), 1) * 0.001)
    with pytest.raises(InputError, match=r"mean_pose: expected shape \(3,\)"):
        gaussian_box_map((0.0, 0.0), good)
    with pytest.raises(InputError, match="mean_pose\\[2\\]: expected a finite number"):
        gaussian_box_map((0.0, 0.0, math.nan), good)
    with pytest.raises(InputError, match="mean_pose: expected a Pose"):
        gaussian_box_map("pose", good)
    with pytest.raises(InputError, match="expecter: expected an Expecter"):
        gaussian_window("expecter", (0.0, 0.0, 0.0), good, landmark)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="expecter: expected an Expecter"):
        disk_model_window(None, figure4_scenario().map, landmark)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="map: expected a SpatialUncertaintyMap"):
        disk_model_map("map")  # type: ignore[arg-type]
    with pytest.raises(InputError, match="sides: expected an integer >= 3"):
        disk_model_map(figure4_scenario().map, sides=2)
