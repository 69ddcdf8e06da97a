"""What every ``aura-ums`` command shares: the console, the error exit, a log's summary, metrics JSON."""

from __future__ import annotations

import math
from collections import Counter
from pathlib import Path
from typing import TYPE_CHECKING

import typer
from rich.console import Console
from rich.markup import escape

if TYPE_CHECKING:
    from aura_ums import Metrics
    from aura_ums.logs import RobotLog

console = Console(soft_wrap=True)


def fail(message: str) -> typer.Exit:
    """Print ``error: <message>`` (markup-safe) and return the exit (code 2) for the caller to raise."""
    console.print(f"[red]error:[/red] {escape(message)}", highlight=False)
    return typer.Exit(code=2)


def write_metrics_json(path: Path, metrics: Metrics) -> None:
    """Write ``--metrics-json`` (strict JSON, atomically) and say so; an unwritable path fails cleanly."""
    try:
        metrics.write_json(path)
    except OSError as exc:
        raise fail(f"--metrics-json: expected a writable path, got {path}: {exc.strerror}") from None
    console.print(f"wrote {path}", highlight=False, markup=False)


def span(first: float, last: float) -> str:
    """Describe a time span in seconds, or ``none`` when either end is missing."""
    if not (math.isfinite(first) and math.isfinite(last)):
        return "none"
    return f"{first:.3f} .. {last:.3f} s ({last - first:.1f} s)"


def print_log_summary(log: RobotLog) -> None:
    """Print where a log was written and what it holds: counts and time spans."""
    kinds = Counter(observation.kind.value for observation in log.observations)
    seen = len({observation.landmark_id for observation in log.observations})
    times = [observation.time for observation in log.observations]
    console.print(f"wrote {log.path}", highlight=False, markup=False)
    rows = [
        ("log", log.meta.name),
        ("source", log.meta.source),
        ("landmarks", f"{len(log.landmarks)} ({seen} observed)"),
        (
            "observations",
            f"{len(log.observations)} ("
            + ", ".join(f"{count} {kind}" for kind, count in sorted(kinds.items()))
            + ")",
        ),
        ("observation span", span(min(times, default=math.nan), max(times, default=math.nan))),
        ("odometry rows", str(len(log.odometry) if log.odometry is not None else 0)),
        ("odometry span", span(*log.motion_span)),
    ]
    if log.groundtruth is not None:
        truth = log.groundtruth
        rows.append(("ground truth rows", str(len(truth))))
        rows.append(("ground truth span", span(float(truth.time[0]), float(truth.time[-1]))))
    for key, value in rows:
        console.print(f"{key:18s} {value}", highlight=False, markup=False)
