"""``aura-ums import``: turn published datasets into aura-ums log folders (docs/log-format.md)."""

from __future__ import annotations

import math
from collections import Counter
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.markup import escape

import_app = typer.Typer(
    help="Turn published datasets into aura-ums log folders (see docs/log-format.md).",
    no_args_is_help=True,
    add_completion=False,
)
_console = Console(soft_wrap=True)


def _fail(message: str) -> typer.Exit:
    _console.print(f"[red]error:[/red] {escape(message)}", highlight=False)
    return typer.Exit(code=2)


def _span(first: float, last: float) -> str:
    if not (math.isfinite(first) and math.isfinite(last)):
        return "none"
    return f"{first:.3f} .. {last:.3f} s ({last - first:.1f} s)"


@import_app.command("mrclam")
def mrclam(
    dataset_dir: Annotated[
        Path, typer.Argument(help="UTIAS MRCLAM dataset folder (Barcodes.dat, RobotN_*.dat, ...).")
    ],
    out_dir: Annotated[Path, typer.Argument(help="Log folder to write.")],
    robot: Annotated[int, typer.Option("--robot", help="Robot number, 1 to 5.")],
    overwrite: Annotated[
        bool, typer.Option("--overwrite", help="Replace an existing log in OUT_DIR.")
    ] = False,
) -> None:
    """Import robot ROBOT's run of the UTIAS MRCLAM dataset in DATASET_DIR as a log folder OUT_DIR.

    Measurements of other robots and of unknown barcodes are dropped (counted in the log's
    source text); ranges stay in metres; sensor bounds are placeholders to calibrate.
    """
    from aura_ums.errors import AuraUmsError
    from aura_ums.logs import LOG_FILES, import_mrclam

    if not dataset_dir.is_dir():
        raise _fail(f"{dataset_dir}: expected a UTIAS MRCLAM dataset folder, got no such folder")
    existing = [name for name in LOG_FILES if (out_dir / name).exists()]
    if existing and not overwrite:
        raise _fail(
            f"{out_dir}: expected a folder without a log, got one holding {', '.join(existing)} "
            "(pass --overwrite to replace it)"
        )
    try:
        log = import_mrclam(dataset_dir, robot, out_dir, overwrite=overwrite)
    except AuraUmsError as exc:
        raise _fail(str(exc)) from None
    kinds = Counter(observation.kind.value for observation in log.observations)
    seen = len({observation.landmark_id for observation in log.observations})
    times = [observation.time for observation in log.observations]
    _console.print(f"wrote {log.path}", highlight=False)
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
        ("observation span", _span(min(times, default=math.nan), max(times, default=math.nan))),
        ("odometry rows", str(len(log.odometry) if log.odometry is not None else 0)),
        ("odometry span", _span(*log.motion_span)),
    ]
    if log.groundtruth is not None:
        truth = log.groundtruth
        rows.append(("ground truth rows", str(len(truth))))
        rows.append(("ground truth span", _span(float(truth.time[0]), float(truth.time[-1]))))
    for key, value in rows:
        _console.print(f"{key:18s} {value}", highlight=False, markup=False)
