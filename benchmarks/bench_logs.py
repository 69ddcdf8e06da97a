"""Microseconds per replay step: our map vs an EKF (ours and filterpy's) and a particle filter.

Each step is one camera frame of the log: the growth (or prediction) by the position
reports since the previous frame, then the frame's observations (built before the clock
starts, for every method). All methods see the same reports and observations
(aura_ums.logs.compare_on_log; filterpy's EKF joins through its ``others``, with the same
model in numpy matrices and the same gate, from benchmarks/filterpy_ekf.py). Uses the MRCLAM
Dataset 6 logs in the data folder beside the clone (docs/getting-real-data.md) when present
(calibrated on robot 1), else a synthetic log. Each log is run ``REPEATS`` times; a method's
figure is the lowest of its per-run medians, so that a burst of load on this machine does not
land on one method only. Robot 1 is also replayed with the map polygon capped at 16 vertices
(``ManagerSettings.max_vertices``, default 64): the speed a coarser polygon buys and the area
it costs.

    .venv/bin/python benchmarks/bench_logs.py
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from aura_ums.logs import (
    ReplayOptions,
    RobotLog,
    calibrate_logs,
    compare_on_log,
    filter_settings,
    observation_errors,
    read_mrclam,
    synthetic_log,
)
from aura_ums.manager import ManagerSettings
from aura_ums.uncertainty import LandmarkClass, Pose
from filterpy_ekf import FilterpyLogEkf

MRCLAM = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "mrclam6"
REPEATS = 2


def main() -> None:
    if MRCLAM.is_dir():
        logs: list[RobotLog] = [read_mrclam(MRCLAM, 1), read_mrclam(MRCLAM, 2)]
    else:
        print(f"MRCLAM data not found at {MRCLAM}: using a synthetic log")
        logs = [synthetic_log(np.random.default_rng(0), duration=300.0)]
    calibration = calibrate_logs(logs[:1])
    bearing, ranges = observation_errors(logs[:1])
    bearing_sd = float(np.std(bearing))
    range_sd_fraction = max(float(np.std(ranges)), 1e-3)
    table = calibration.terrain_table()

    def run(log: RobotLog, options: ReplayOptions, label: str) -> None:
        def filterpy_ekf(start: Pose) -> FilterpyLogEkf:
            # Started as compare_on_log starts its own EKF.
            return FilterpyLogEkf(
                start, **filter_settings(log, bearing_sd=bearing_sd, range_sd_fraction=range_sd_fraction)
            )

        best: dict[str, float] = {}
        rows = {}
        for _ in range(REPEATS):
            for row in compare_on_log(
                log,
                table,
                options,
                bearing_sd=bearing_sd,
                range_sd_fraction=range_sd_fraction,
                rng=np.random.default_rng(0),
                others={"filterpy EKF": filterpy_ekf},
            ):
                rows[row.method] = row
                best[row.method] = min(best.get(row.method, math.inf), row.median_update_us)
        ekf, filterpy = best["EKF"], best["filterpy EKF"]
        for method, row in rows.items():
            print(
                f"{log.meta.name:16s} {label:11s} {method:13s} {row.containment_rate:7.4f} "
                f"{row.median_area_m2:9.4g} {row.median_wedge_width_rad:8.3f} {row.position_rmse_m:7.3f} "
                f"{best[method]:8.1f} {best[method] / ekf:6.2f} {best[method] / filterpy:6.2f}"
            )

    print(
        f"{'log':16s} {'class':11s} {'method':13s} {'inside':>7s} {'area m2':>9s} {'head rad':>8s} "
        f"{'RMSE m':>7s} {'us/step':>8s} {'/ EKF':>6s} {'/ fpy':>6s}"
    )

    def calibrated(landmark_class: LandmarkClass, **settings: Any) -> ReplayOptions:
        return ReplayOptions(
            settings=ManagerSettings(**settings),
            landmark_class=landmark_class,
            working=calibration.working,
            envelope=calibration.envelope,
            motion=calibration.motion,
        )

    for log in logs:
        for landmark_class in (LandmarkClass.VERTICAL_LINE, LandmarkClass.POINT):
            run(log, calibrated(landmark_class), landmark_class.value)
    # Without the envelope (the consistency gate alone): one manager instead of two.
    run(logs[-1], calibrated(LandmarkClass.POINT, robust=False), "II gate only")
    # A coarser polygon (ManagerSettings.max_vertices, replay --max-vertices): speed for area.
    for landmark_class in (LandmarkClass.VERTICAL_LINE, LandmarkClass.POINT):
        run(logs[0], calibrated(landmark_class, max_vertices=16), f"{landmark_class.value} cap 16")
    print(
        "us/step: the lowest of the per-run medians; / EKF: against aura-ums's ExtendedKalmanFilter "
        "(written out on floats); / fpy: against filterpy's ExtendedKalmanFilter"
    )


if __name__ == "__main__":
    main()
