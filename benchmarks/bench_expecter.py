"""Benchmark the Expecter: time per window, and window areas against the baselines.

Run: ``.venv/bin/python benchmarks/bench_expecter.py``. Prints three tables:

1. median microseconds per ``Expecter.window`` call, per landmark class, for 16- and
   64-vertex maps, with an ideal and a distorted camera: the compiled kernel (when built)
   against the numpy reference, measured in the same run;
2. the Figure 4 scenario: window area of the polygonal map over the disk model's
   (target <= 0.5), and over an EKF's 3-sigma box whose covariance matches the polygon's
   second moments (and the wedge's, as a uniform heading);
3. the same ratios, median over random elongated maps, per class.

Areas are of the guaranteed windows (no margin, not clipped to the image).
"""

from __future__ import annotations

import math
import statistics
import time

import numpy as np
from numpy.typing import NDArray

from aura_ums import _native
from aura_ums._native import _expecter as native_expecter
from aura_ums.camera import Camera, CameraIntrinsics, CameraMount
from aura_ums.expecter import Expecter, disk_model_map, gaussian_box_map
from aura_ums.expecter._scenario import figure4_scenario
from aura_ums.geometry import ConvexPolygon, HeadingWedge
from aura_ums.uncertainty import (
    GroundLineLandmark,
    Landmark,
    PointLandmark,
    SpatialUncertaintyMap,
    VerticalLineLandmark,
)

REPEATS = 300
RANDOM_MAPS = 40


def median_microseconds(
    expecter: Expecter, the_map: SpatialUncertaintyMap, landmark: Landmark, *, compiled: bool = True
) -> float:
    """Median microseconds of ``Expecter.window``; ``compiled=False`` runs the numpy reference."""
    # The kernel the package bound (AURA_UMS_NATIVE=0 binds the reference for a whole process).
    saved = _native.expecter_points
    if not compiled:
        _native.expecter_points = native_expecter.expecter_points_reference
    try:
        for _ in range(10):
            expecter.window(the_map, landmark)
        times = []
        for _ in range(REPEATS):
            start = time.perf_counter()
            expecter.window(the_map, landmark)
            times.append(time.perf_counter() - start)
    finally:
        _native.expecter_points = saved
    return 1e6 * statistics.median(times)


def elongated_map(
    vertices: int, length: float, width: float, angle: float, wedge: float
) -> SpatialUncertaintyMap:
    t = np.arange(vertices) * (2.0 * math.pi / vertices)
    c, s = math.cos(angle), math.sin(angle)
    x, y = length * np.cos(t), width * np.sin(t)
    polygon = ConvexPolygon(np.column_stack([c * x - s * y, s * x + c * y]))
    return SpatialUncertaintyMap(polygon, (0.0, 0.0), HeadingWedge(0.0, wedge, wedge))


def matched_gaussian(the_map: SpatialUncertaintyMap) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Mean and covariance of a uniform pose over the map (position and heading independent)."""
    positions = the_map.polygon.sample(400_000, np.random.default_rng(0))
    wedge = the_map.wedge
    heading = wedge.center + (wedge.ccw - wedge.cw) / 2.0
    covariance = np.zeros((3, 3))
    covariance[:2, :2] = np.cov(positions.T)
    covariance[2, 2] = wedge.width**2 / 12.0
    return np.array([*positions.mean(axis=0), heading]), covariance


def area_ratios(
    expecter: Expecter, the_map: SpatialUncertaintyMap, landmark: Landmark
) -> tuple[float, float]:
    polygon = expecter.bounds(the_map, landmark)
    disk = expecter.bounds(disk_model_map(the_map), landmark)
    mean, covariance = matched_gaussian(the_map)
    box = expecter.bounds(gaussian_box_map(mean, covariance, 3.0), landmark)
    if polygon is None or disk is None or box is None:
        return math.nan, math.nan
    return polygon.area / disk.area, polygon.area / box.area


def timing_table() -> None:
    cameras = {
        "ideal": Camera(
            CameraIntrinsics(500.0, 500.0, 319.5, 239.5, 640, 480),
            CameraMount(height=1.2, forward=0.3, tilt=0.12),
        ),
        "distorted": Camera(
            CameraIntrinsics(
                500.0, 500.0, 319.5, 239.5, 640, 480, distortion=(-0.28, 0.09, 1e-3, -8e-4, -0.015)
            ),
            CameraMount(height=1.2, forward=0.3, tilt=0.12),
        ),
    }
    landmarks: dict[str, Landmark] = {
        "I (vertical line)": VerticalLineLandmark("pole", 10.0, 1.0, 0.0, 4.0, position_uncertainty=0.1),
        "II (point)": PointLandmark("corner", 12.0, -1.5, 2.5, position_uncertainty=0.1),
        "III (ground line)": GroundLineLandmark("edge", (4.0, -2.0), (16.0, -2.5), position_uncertainty=0.1),
    }
    built = _native.NATIVE
    print("Median time per Expecter.window call (microseconds); baseline: the numpy reference")
    if not built:
        print("(the C kernels are not in use: both columns run the numpy reference)")
    print(f"{'class':<20} {'camera':<10} {'vertices':>8} {'compiled':>9} {'numpy':>9} {'speed-up':>9}")
    for class_name, landmark in landmarks.items():
        for camera_name, camera in cameras.items():
            expecter = Expecter(camera)
            for n in (16, 64):
                the_map = elongated_map(n, 2.0, 0.4, 0.3, math.radians(4.0))
                fast = median_microseconds(expecter, the_map, landmark)
                reference = median_microseconds(expecter, the_map, landmark, compiled=False)
                print(
                    f"{class_name:<20} {camera_name:<10} {n:>8} {fast:>9.0f} {reference:>9.0f} "
                    f"{reference / fast:>8.1f}x"
                )


def figure4_table() -> None:
    scenario = figure4_scenario()
    expecter = Expecter(scenario.camera)
    print("\nFigure 4 scenario: guaranteed window areas (pixels^2) and ratios")
    print(
        f"{'landmark':<12} {'polygon':>10} {'disk':>10} {'3-sigma box':>12} {'poly/disk':>10} {'poly/box':>9}"
    )
    for landmark in scenario.landmarks:
        polygon = expecter.bounds(scenario.map, landmark)
        disk = expecter.bounds(disk_model_map(scenario.map), landmark)
        mean, covariance = matched_gaussian(scenario.map)
        box = expecter.bounds(gaussian_box_map(mean, covariance, 3.0), landmark)
        if polygon is None or disk is None or box is None:
            raise RuntimeError(f"{landmark.id}: expected every window, got None")
        print(
            f"{landmark.id:<12} {polygon.area:>10.0f} {disk.area:>10.0f} {box.area:>12.0f} "
            f"{polygon.area / disk.area:>10.3f} {polygon.area / box.area:>9.3f}"
        )


def random_table() -> None:
    rng = np.random.default_rng(7)
    camera = Camera(
        CameraIntrinsics(400.0, 400.0, 319.5, 239.5, 640, 480), CameraMount(height=1.2, tilt=0.14)
    )
    expecter = Expecter(camera)
    print(f"\nRandom elongated maps ({RANDOM_MAPS} per class): median area ratios")
    print(f"{'class':<20} {'poly/disk':>10} {'poly/box':>9}")
    for class_name in ("I (vertical line)", "II (point)", "III (ground line)"):
        disk_ratios, box_ratios = [], []
        for _ in range(RANDOM_MAPS):
            the_map = elongated_map(
                16, rng.uniform(1.0, 3.0), rng.uniform(0.1, 0.4), rng.uniform(-0.3, 0.3), math.radians(2.0)
            )
            distance, bearing = rng.uniform(6.0, 15.0), rng.uniform(-0.5, 0.5)
            x, y = distance * math.cos(bearing), distance * math.sin(bearing)
            landmark: Landmark
            if class_name.startswith("I "):
                landmark = VerticalLineLandmark("pole", x, y, 0.0, rng.uniform(1.0, 4.0))
            elif class_name.startswith("II "):
                landmark = PointLandmark("corner", x, y, rng.uniform(0.0, 3.0))
            else:
                landmark = GroundLineLandmark(
                    "edge", (x, y), (x + rng.uniform(1.0, 4.0), y + rng.uniform(-1.0, 1.0))
                )
            disk_ratio, box_ratio = area_ratios(expecter, the_map, landmark)
            disk_ratios.append(disk_ratio)
            box_ratios.append(box_ratio)
        print(f"{class_name:<20} {np.nanmedian(disk_ratios):>10.3f} {np.nanmedian(box_ratios):>9.3f}")


if __name__ == "__main__":
    timing_table()
    figure4_table()
    random_table()
