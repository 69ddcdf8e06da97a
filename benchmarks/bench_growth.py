"""Speed of one `grow` against filterpy's EKF predict step, growth through meadows, numpy vs shapely.

Run: `make bench` or `.venv/bin/python benchmarks/bench_growth.py`. Prints medians (µs)
and ratios measured in the same run. Nothing here is asserted: speed is reported.
"""

from __future__ import annotations

import functools
import math
import statistics
import time
from collections.abc import Callable

import numpy as np
import shapely
from filterpy.kalman import ExtendedKalmanFilter

from aura_ums import HeadingWedge, Pose, SpatialUncertaintyMap, TerrainTable, TurnAndRun
from aura_ums.geometry import convex_hull, minkowski_sum, regular_polygon
from aura_ums.geometry._convex import points_in_convex
from aura_ums.world import commands_for, grow_through, make_grid_world


def median_us(function: Callable[[], object], repeat: int = 2000) -> float:
    """Median wall time of one call, microseconds, after a warm-up."""
    for _ in range(50):
        function()
    samples = []
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        samples.append(time.perf_counter() - start)
    return statistics.median(samples) * 1e6


class TurnAndRunEKF(ExtendedKalmanFilter):  # type: ignore[misc]
    """A user's EKF for the same motion model: state (x, y, heading), control (turn, run)."""

    def __init__(self) -> None:
        super().__init__(dim_x=3, dim_z=2)
        self.x = np.zeros((3, 1))
        self.P = np.diag([0.01, 0.01, 0.001])
        self.u = (0.3, 2.0)

    def predict_x(self, u: object = 0) -> None:
        turn, run = self.u
        heading = float(self.x[2, 0]) + turn
        self.x = np.array(
            [[self.x[0, 0] + run * math.cos(heading)], [self.x[1, 0] + run * math.sin(heading)], [heading]]
        )


def ekf_predict_step(ekf: TurnAndRunEKF, sd_run: float, sd_turn: float) -> Callable[[], None]:
    def step() -> None:
        turn, run = ekf.u
        heading = float(ekf.x[2, 0]) + turn
        # Jacobian of the motion and the noise mapped into the state: work a user does per step.
        ekf.F = np.array(
            [[1.0, 0.0, -run * math.sin(heading)], [0.0, 1.0, run * math.cos(heading)], [0.0, 0.0, 1.0]]
        )
        jacobian_noise = np.array(
            [
                [math.cos(heading), -run * math.sin(heading)],
                [math.sin(heading), run * math.cos(heading)],
                [0.0, 1.0],
            ]
        )
        ekf.Q = jacobian_noise @ np.diag([(sd_run * run) ** 2, (sd_turn * turn) ** 2]) @ jacobian_noise.T
        ekf.predict()
        ekf.x[:] = 0.0  # keep the state bounded over many repetitions
        ekf.P = np.diag([0.01, 0.01, 0.001])

    return step


def main() -> None:
    terrain = TerrainTable.default()["concrete"]
    command = TurnAndRun(0.3, 2.0)
    rows: list[tuple[str, float]] = []
    ekf = TurnAndRunEKF()
    ekf_us = median_us(ekf_predict_step(ekf, terrain.translation_sd, terrain.rotation_sd))
    rows.append(("filterpy EKF predict (incl. Jacobians)", ekf_us))
    for vertices in (16, 64):
        polygon = regular_polygon((0.0, 0.0), 1.0, vertices)
        start = SpatialUncertaintyMap.from_polygon(polygon, (0.0, 0.0), HeadingWedge(0.0, 0.05, 0.05))
        grown = start.grow(command, terrain, max_vertices=vertices)
        rows.append(
            (
                f"grow, {vertices}-vertex map (cap {vertices}, result {grown.polygon.vertex_count} vertices)",
                median_us(functools.partial(start.grow, command, terrain, max_vertices=vertices)),
            )
        )
    print("## One growth step (median µs)")
    print(f"{'operation':64s} {'median µs':>10s} {'/ EKF':>8s}")
    for name, value in rows:
        print(f"{name:64s} {value:10.1f} {value / ekf_us:8.2f}")

    # Growth through meadows: grow_through bounds every pose's run; the paper's split by the
    # most probable pose's run (commands_for, one grow per piece) is the baseline.
    world, table = make_grid_world(5, 5, cell=5.0), TerrainTable.default()
    cases = [
        ("inside a meadow, 0.05 m report", (12.5, 12.5), TurnAndRun(0.01, 0.05)),
        ("0.2 m from a boundary, 0.5 m report", (14.7, 12.5), TurnAndRun(0.01, 0.5)),
        ("a 3 m run across a boundary", (12.5, 12.5), TurnAndRun(0.0, 3.0)),
    ]
    print()
    print("## Growth through meadows (median µs): grow_through vs the paper's split")
    print(f"{'case':40s} {'grow_through':>12s} {'paper split':>12s} {'ratio':>8s}")
    for name, (x, y), step in cases:
        begin = SpatialUncertaintyMap.from_pose(Pose(x, y, 0.3), 0.3, 0.05)

        def paper_split(
            begin: SpatialUncertaintyMap = begin, step: TurnAndRun = step
        ) -> SpatialUncertaintyMap:
            grown = begin
            for piece, stats in commands_for(world, begin.most_probable_pose(), step, table):
                grown = grown.grow(piece, stats)
            return grown

        ours = median_us(functools.partial(grow_through, begin, world, step, table), 1000)
        theirs = median_us(paper_split, 1000)
        print(f"{name:40s} {ours:12.1f} {theirs:12.1f} {ours / theirs:8.2f}")

    # numpy vs shapely on the geometry hot paths
    rng = np.random.default_rng(0)
    polygon = regular_polygon((0.0, 0.0), 3.0, 64)
    points = rng.normal(0.0, 3.0, (20_000, 2))
    shapely_polygon = shapely.Polygon(polygon.vertices)
    shapely.prepare(shapely_polygon)
    a = regular_polygon((0.0, 0.0), 1.0, 48).vertices
    b = regular_polygon((0.0, 0.0), 0.2, 16).vertices
    comparisons = [
        (
            "contains 20,000 points in a 64-gon",
            median_us(lambda: points_in_convex(polygon.vertices, points, 1e-9), 50),
            median_us(lambda: shapely.contains_xy(shapely_polygon, points[:, 0], points[:, 1]), 50),
        ),
        (
            "Minkowski sum 48-gon + 16-gon",
            median_us(lambda: minkowski_sum(a, b), 1000),
            median_us(
                lambda: shapely.MultiPoint((a[:, None, :] + b[None, :, :]).reshape(-1, 2)).convex_hull, 1000
            ),
        ),
        (
            "convex hull of 20,000 points",
            median_us(lambda: convex_hull(points), 50),
            median_us(lambda: shapely.MultiPoint(points).convex_hull, 50),
        ),
    ]
    print()
    print("## Geometry hot paths: ours (numpy) vs shapely 2 (median µs)")
    print(f"{'operation':40s} {'numpy':>10s} {'shapely':>10s} {'numpy/shapely':>14s}")
    for name, ours, theirs in comparisons:
        print(f"{name:40s} {ours:10.1f} {theirs:10.1f} {ours / theirs:14.2f}")


if __name__ == "__main__":
    main()
