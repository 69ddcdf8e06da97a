"""Microseconds per replay step: our map vs an EKF and a particle filter, same log, same run.

Each step is one camera frame of the log: the growth (or prediction) by the position
reports since the previous frame, then the frame's observations. All three methods see the
same reports and observations (aura_ums.logs.compare_on_log). Uses the MRCLAM Dataset 6 logs
in ../shared/data when present (calibrated on robot 1), else a synthetic log.

    .venv/bin/python benchmarks/bench_logs.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from aura_ums.logs import (
    MethodSummary,
    ReplayOptions,
    RobotLog,
    calibrate_logs,
    compare_on_log,
    observation_errors,
    read_mrclam,
    synthetic_log,
)
from aura_ums.uncertainty import LandmarkClass

MRCLAM = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "mrclam6"


def main() -> None:
    if MRCLAM.is_dir():
        logs: list[RobotLog] = [read_mrclam(MRCLAM, 1), read_mrclam(MRCLAM, 2)]
    else:
        print(f"MRCLAM data not found at {MRCLAM}: using a synthetic log")
        logs = [synthetic_log(np.random.default_rng(0), duration=300.0)]
    calibration = calibrate_logs(logs[:1])
    bearing, ranges = observation_errors(logs[:1])

    def compare(log: RobotLog, options: ReplayOptions) -> tuple[tuple[MethodSummary, ...], float]:
        rows = compare_on_log(
            log,
            calibration.terrain_table(),
            options,
            bearing_sd=float(np.std(bearing)),
            range_sd_fraction=max(float(np.std(ranges)), 1e-3),
            rng=np.random.default_rng(0),
        )
        ekf = next(r for r in rows if r.method == "EKF").median_update_us
        return rows, ekf

    print(
        f"{'log':16s} {'class':5s} {'method':10s} {'inside':>7s} {'area m2':>9s} {'head rad':>8s} "
        f"{'RMSE m':>7s} {'us/step':>8s} {'/ EKF':>6s}"
    )
    for log in logs:
        for landmark_class in (LandmarkClass.VERTICAL_LINE, LandmarkClass.POINT):
            options = ReplayOptions(
                landmark_class=landmark_class,
                working=calibration.working,
                envelope=calibration.envelope,
                motion=calibration.motion,
            )
            rows, ekf = compare(log, options)
            for row in rows:
                print(
                    f"{log.meta.name:16s} {landmark_class.value:5s} {row.method:10s} "
                    f"{row.containment_rate:7.4f} {row.median_area_m2:9.4g} "
                    f"{row.median_heading_width_rad:8.3f} {row.position_rmse_m:7.3f} "
                    f"{row.median_update_us:8.1f} {row.median_update_us / ekf:6.2f}"
                )
    # Without the envelope (the consistency gate alone): one manager instead of two.
    log = logs[-1]
    options = ReplayOptions(
        landmark_class=LandmarkClass.POINT,
        working=calibration.working,
        motion=calibration.motion,
        robust=False,
    )
    rows, ekf = compare(log, options)
    print(
        f"gate only ({log.meta.name}, II): ours {rows[0].median_update_us:.1f} us/step, "
        f"{rows[0].median_update_us / ekf:.2f} x EKF, containment {rows[0].containment_rate:.4f}"
    )


if __name__ == "__main__":
    main()
