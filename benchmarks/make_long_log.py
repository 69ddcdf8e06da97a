"""Write a long synthetic odometry log folder (any number of rows) for the streaming benchmark.

The robot drives a figure of eight (3 m by 1.5 m) among the eight poles of
:func:`aura_ums.logs.synthetic_log`; everything is computed with numpy, so 10^6 rows take a
few seconds. ``odometry.csv`` and ``groundtruth.csv`` hold one row per ``1/rate`` seconds;
every ``frame_every``-th row is a camera frame observing each pole within 9 m and inside a
1.2 rad field of view (bearing and range, errors uniform within the bounds ``meta.toml``
states). The log's terrain is ``floor``: replay it with the built-in ``tile`` statistics
under that name (``benchmarks/bench_long_log.py`` does).

    .venv/bin/python benchmarks/make_long_log.py /tmp/long-log --rows 1000000
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from aura_ums.logs import LogLandmark, LogMeta, RobotLog, write_log
from aura_ums.manager import PositionReport
from aura_ums.uncertainty import TurnAndRun

POLES = (
    ("L1", -6.0, -6.0),
    ("L2", 0.0, -6.5),
    ("L3", 6.0, -6.0),
    ("L4", 6.5, 0.0),
    ("L5", 6.0, 6.0),
    ("L6", 0.0, 6.5),
    ("L7", -6.0, 6.0),
    ("L8", -6.5, 0.0),
)
BEARING_NOISE = 0.01  # rad
RANGE_NOISE = 0.02  # fraction of the true range
FIELD_OF_VIEW = 1.2  # rad
MAX_RANGE = 9.0  # m
PERIOD = 120.0  # s per figure of eight


def _path(t: np.ndarray) -> tuple[np.ndarray, ...]:
    """Pose, speed and turn rate of the figure of eight at times ``t`` (s)."""
    w = 2.0 * math.pi / PERIOD
    x, y = 3.0 * np.sin(w * t), 1.5 * np.sin(2.0 * w * t)
    dx, dy = 3.0 * w * np.cos(w * t), 3.0 * w * np.cos(2.0 * w * t)
    ddx, ddy = -3.0 * w * w * np.sin(w * t), -6.0 * w * w * np.sin(2.0 * w * t)
    speed = np.hypot(dx, dy)
    return x, y, np.arctan2(dy, dx), speed, (dx * ddy - dy * ddx) / speed**2


def _csv(path: Path, title: str, header: str, columns: list[np.ndarray], formats: list[str]) -> None:
    with path.open("w", encoding="utf-8") as handle:
        handle.write(f"# {title}\n{header}\n")
        np.savetxt(handle, np.column_stack(columns), fmt=formats, delimiter=",")


def make_long_log(
    folder: Path, rows: int, *, rate: float = 100.0, frame_every: int = 10, seed: int = 1
) -> Path:
    """Write a log of ``rows`` odometry rows into ``folder`` (created; must hold no log)."""
    rng = np.random.default_rng(seed)
    t = np.arange(rows) / rate
    x, y, heading, speed, turn_rate = _path(t)
    meta = LogMeta(
        "long",
        terrain="floor",
        bearing_error=BEARING_NOISE,
        range_error=0.0,
        range_error_fraction=RANGE_NOISE / (1.0 - RANGE_NOISE),
        start_radius=0.05,
        start_heading_halfwidth=0.02,
        source="benchmarks/make_long_log.py",
    )
    landmarks = tuple(LogLandmark(name, px, py, 0.01, 0.0, 2.0, "pole") for name, px, py in POLES)
    # The small files through write_log (meta, landmarks); a placeholder motion it needs.
    placeholder = RobotLog(meta, landmarks, (), commands=(PositionReport(1.0, TurnAndRun(0.0, 0.0)),))
    write_log(placeholder, folder)
    (folder / "commands.csv").unlink()
    _csv(
        folder / "odometry.csv",
        "odometry: time [s], v [m/s], omega [rad/s]; each row holds until the next",
        "time,v,omega",
        [t, speed, turn_rate],
        ["%.2f", "%.9f", "%.9f"],
    )
    _csv(
        folder / "groundtruth.csv",
        "ground truth: time [s], x [m], y [m], heading [rad]",
        "time,x,y,heading",
        [t, x, y, heading],
        ["%.2f", "%.9f", "%.9f", "%.9f"],
    )
    frames = np.arange(frame_every, rows, frame_every)
    px = np.array([p[1] for p in POLES])
    py = np.array([p[2] for p in POLES])
    dx, dy = px[None, :] - x[frames, None], py[None, :] - y[frames, None]
    distance = np.hypot(dx, dy)
    bearing = np.remainder(np.arctan2(dy, dx) - heading[frames, None] + math.pi, 2.0 * math.pi) - math.pi
    seen = (distance <= MAX_RANGE) & (np.abs(bearing) <= FIELD_OF_VIEW / 2.0)
    frame_index, pole = np.nonzero(seen)
    measured = bearing[seen] + rng.uniform(-BEARING_NOISE, BEARING_NOISE, size=pole.size)
    measured = np.remainder(measured + math.pi, 2.0 * math.pi) - math.pi
    ranges = distance[seen] * (1.0 + rng.uniform(-RANGE_NOISE, RANGE_NOISE, size=pole.size))
    with (folder / "observations.csv").open("w", encoding="utf-8") as handle:
        handle.write("# observations: time [s], landmark_id, bearing [rad], range [m]\n")
        handle.write("time,landmark_id,bearing,range\n")
        names = np.array([p[0] for p in POLES])
        table = np.column_stack(
            (
                np.char.mod("%.2f", t[frames][frame_index]),
                names[pole],
                np.char.mod("%.9f", measured),
                np.char.mod("%.9f", ranges),
            )
        )
        np.savetxt(handle, table, fmt="%s", delimiter=",")
    return folder


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("folder", type=Path)
    parser.add_argument("--rows", type=int, default=1_000_000)
    parser.add_argument("--rate", type=float, default=100.0, help="odometry rows per second")
    parser.add_argument("--frame-every", type=int, default=10, help="odometry rows per camera frame")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    make_long_log(args.folder, args.rows, rate=args.rate, frame_every=args.frame_every, seed=args.seed)
    print(args.folder)


if __name__ == "__main__":
    main()
