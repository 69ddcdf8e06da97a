"""Heading-sliced map vs the paper's product map, side by side on every development log.

Calibrated on MRCLAM Dataset 6 robot 1 (motion and sensor bounds), then every development
log -- Dataset 6 robots 1 and 2, Dataset 7 robots 1 to 5 -- is replayed in Class I (bearings)
and Class II (range and bearing) with the product map (``ManagerSettings.slice_width =
None``) and with sliced maps (``slice_width``, default 2 degrees; more widths with
``--widths``). Per run: containment of the ground truth, median map area, median heading
wedge width, and median microseconds per frame (growth since the previous frame and the
frame's reductions; on this machine, under whatever else runs on it).

    .venv/bin/python benchmarks/bench_sliced.py [--widths 2,4] [--slice-vertices 16] \
        [--logs mrclam6:2,mrclam7:3]

The sliced maps keep ``max_vertices`` per slice (``--slice-vertices``, default the settings'
default); the product map keeps the default.

Measured (issue 18, the batched slice kernels: ``grow_slices``, ``distribute_slices``,
``reduce_cone_slices``): with 4-degree cells (``--slice-width 0.0698``), each replay of
Dataset 6 robot 2 and Dataset 7 robots 1-5 run side by side with the version before them on a
busy machine (load average about 25 on 2 cores): Class I 760-1,860 -> 470-1,310 µs per frame,
Class II 570-650 -> 350-400 µs, 1.4-1.9x faster with every metric unchanged. With
``relaxed_q=1, relaxed_window=10`` on Dataset 6 robot 2 and Dataset 7 robot 5: 65,000-86,000 ->
53,000-61,000 µs (Class I) and 40,000-78,000 -> 28,000-49,000 µs (Class II), 1.2-1.6x.

Measured (28 November 2026, the manager no longer taking the areas it never reads: 038176d
against 09c1b76, run alternately twice with ``--logs mrclam6:2,mrclam7:1,mrclam7:3,mrclam7:5``,
the older tree through ``PYTHONPATH``, load about 1): 2-degree cells, Class I 820-1,611 ->
489-1,070 µs per frame, Class II 589-953 -> 358-566, every other figure identical; the product
map's Class I replays 3.1-4.6 -> 1.6-3.4 s wall time, its median µs within the noise.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

from aura_ums.logs import RobotLog, calibrate_logs, read_mrclam, replay_log
from aura_ums.manager import ManagerSettings
from aura_ums.uncertainty import LandmarkClass
from bench_real_logs import replay_options

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
LOGS = [
    ("mrclam6", 1),
    ("mrclam6", 2),
    ("mrclam7", 1),
    ("mrclam7", 2),
    ("mrclam7", 3),
    ("mrclam7", 4),
    ("mrclam7", 5),
]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--widths", default="2", help="slice widths in degrees, comma-separated")
    parser.add_argument("--logs", default="", help="dataset:robot pairs, comma-separated (default: all)")
    parser.add_argument("--max-slices", type=int, default=ManagerSettings().max_slices)
    parser.add_argument(
        "--slice-vertices",
        type=int,
        default=ManagerSettings().max_vertices,
        help="max_vertices of the sliced maps",
    )
    args = parser.parse_args()
    if not DATA.is_dir():
        print(f"development data not found at {DATA}: nothing to compare")
        return
    chosen = LOGS
    if args.logs:
        chosen = [(name, int(robot)) for name, robot in (item.split(":") for item in args.logs.split(","))]
    calibration = calibrate_logs([read_mrclam(DATA / "mrclam6", 1)])
    table = calibration.terrain_table()
    variants: list[tuple[str, ManagerSettings]] = [("product", ManagerSettings(slice_width=None))]
    for text in args.widths.split(","):
        width = float(text)
        variants.append(
            (
                f"sliced {width:g}deg",
                ManagerSettings(
                    slice_width=math.radians(width),
                    max_slices=args.max_slices,
                    max_vertices=args.slice_vertices,
                ),
            )
        )
    print(f"{'log':12s} {'class':5s} {'map':13s} {'inside':>7s} {'env in':>7s} {'area m2':>9s} "
          f"{'head rad':>8s} {'us/frame':>9s} {'relocs':>6s} {'wall s':>7s}")  # fmt: skip
    for name, robot in chosen:
        log: RobotLog = read_mrclam(DATA / name, robot)
        for landmark_class in (LandmarkClass.VERTICAL_LINE, LandmarkClass.POINT):
            for label, settings in variants:
                start = time.perf_counter()
                result = replay_log(log, table, replay_options(calibration, landmark_class, settings))
                wall = time.perf_counter() - start
                envelope = [s.envelope_inside for s in result.steps if s.envelope_inside is not None]
                envelope_rate = sum(envelope) / len(envelope) if envelope else math.nan
                print(
                    f"{name}:{robot:<4d} {landmark_class.value:5s} {label:13s} "
                    f"{result.containment_rate:7.4f} "
                    f"{envelope_rate:7.4f} {result.median_area_m2:9.4g} {result.median_wedge_width_rad:8.3f} "
                    f"{result.median_update_us:9.1f} {result.relocalizations:6d} {wall:7.1f}",
                    flush=True,
                )
    print("inside: containment of the ground truth in the working map; env in: in the envelope map")


if __name__ == "__main__":
    main()
