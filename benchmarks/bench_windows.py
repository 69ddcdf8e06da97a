"""Image windows on real logs: ours vs an EKF's 3-sigma box vs the disk model.

Calibrates on MRCLAM Dataset 6 robot 1 (../shared/data), replays Dataset 6 robot 2 and
Dataset 7 robots 1-5 in Class I and Class II through the virtual camera of
examples/virtual_camera_60deg.toml (640 x 480, 60 degrees, 0.3 m up, level), and prints,
per log, class and method: the share of judged real observations whose measured pixel lies
inside the window (``window_containment``), the same for the landmark projected from the
true pose (``window_truth_containment``), and the median window width and area as fractions
of the image's. The same figures as ``aura-ums replay LOG --camera ...`` with the
calibration's sensors file (aura_ums.logs.replay_windows, margin 0, the EKF's noise from the
working bounds). Writes one figure to FIGURE: window width over time on Dataset 7 robot 1,
Class II, ours vs the EKF's box.

    MPLBACKEND=Agg .venv/bin/python benchmarks/bench_windows.py FIGURE.png
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from aura_ums.camera import load_camera
from aura_ums.logs import ReplayOptions, WindowReport, calibrate_logs, read_mrclam, replay_windows
from aura_ums.uncertainty import LandmarkClass

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"
CAMERA = ROOT / "examples" / "virtual_camera_60deg.toml"
REPLAYED = [("mrclam6", 2), *[("mrclam7", robot) for robot in range(1, 6)]]
FIGURE_LOG = ("mrclam7", 1)


def main(figure: Path) -> None:
    if not (DATA / "mrclam6").is_dir() or not (DATA / "mrclam7").is_dir():
        print(f"MRCLAM data not found under {DATA}: nothing to measure")
        return
    camera = load_camera(CAMERA)
    calibration = calibrate_logs([read_mrclam(DATA / "mrclam6", 1)])
    table = calibration.terrain_table()
    print("calibrated on mrclam6 robot 1; camera", CAMERA.name)
    header = (
        f"{'log':16s} {'class':5s} {'method':16s} {'judged':>6s} {'inside':>7s} {'truth in':>8s} "
        f"{'width':>6s} {'area':>7s} {'map in':>7s} {'s':>5s}"
    )
    print(header)
    print("-" * len(header))
    kept: WindowReport | None = None
    for dataset, robot in REPLAYED:
        log = read_mrclam(DATA / dataset, robot)
        for landmark_class in (LandmarkClass.VERTICAL_LINE, LandmarkClass.POINT):
            options = ReplayOptions(
                landmark_class=landmark_class,
                working=calibration.working,
                envelope=calibration.envelope,
                motion=calibration.motion,
            )
            began = time.perf_counter()
            result, windows = replay_windows(log, table, camera, options)
            seconds = time.perf_counter() - began
            judged = len(windows.judged("aura-ums"))
            for method in WindowReport.methods:
                figures = windows.figures(method)
                cells = (
                    f"{judged:6d}",
                    _f(figures.number("window_containment")),
                    _f(figures.number("window_truth_containment"), 8),
                    _f(figures.number("median_window_width_frac"), 6, 3),
                    _f(figures.number("median_window_area_frac")),
                    f"{result.containment_rate:7.4f} {seconds:5.1f}",
                )
                print(f"{log.meta.name:16s} {landmark_class.value:5s} {method:16s} " + " ".join(cells))
            if (dataset, robot) == FIGURE_LOG and landmark_class is LandmarkClass.POINT:
                kept = windows
    if kept is not None:
        _draw(kept, figure, f"{FIGURE_LOG[0]} robot {FIGURE_LOG[1]}, Class II")
        print(f"wrote {figure}")


def _f(value: float, width: int = 7, digits: int = 4) -> str:
    return f"{'n/a':>{width}s}" if math.isnan(value) else f"{value:{width}.{digits}f}"


def _draw(windows: WindowReport, path: Path, title: str) -> None:
    figure, axes = plt.subplots(figsize=(9, 3.6), constrained_layout=True)
    for method, colour in (("aura-ums", "tab:blue"), ("EKF 3-sigma box", "tab:orange")):
        rows = windows.judged(method)
        times = np.array([row.time for row in rows])
        widths = np.array([row.width_frac for row in rows])
        if not times.size:
            continue
        axes.plot(
            times - times[0],
            widths,
            ".",
            markersize=2,
            color=colour,
            label=f"{method} (median {np.median(widths):.2f})",
        )
    axes.set_xlabel("time since the first judged observation, s")
    axes.set_ylabel("window width / image width")
    axes.set_ylim(0.0, 1.02)
    axes.set_title(f"Image windows through a 640x480, 60 deg camera: {title}")
    axes.legend(loc="upper right", markerscale=6)
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=120)
    plt.close(figure)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: bench_windows.py FIGURE.png")
    main(Path(sys.argv[1]))
