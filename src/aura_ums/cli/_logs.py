"""``aura-ums import``: turn published datasets into aura-ums log folders (docs/log-format.md)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from aura_ums.cli._common import fail, print_log_summary

import_app = typer.Typer(
    help="Turn published datasets into aura-ums log folders (see docs/log-format.md).",
    no_args_is_help=True,
    add_completion=False,
)


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
    from aura_ums.logs import import_mrclam, log_files_in

    if not dataset_dir.is_dir():
        raise fail(f"{dataset_dir}: expected a UTIAS MRCLAM dataset folder, got no such folder")
    existing = log_files_in(out_dir)
    if existing and not overwrite:
        raise fail(
            f"{out_dir}: expected a folder without a log, got one holding {', '.join(existing)} "
            "(pass --overwrite to replace it)"
        )
    try:
        log = import_mrclam(dataset_dir, robot, out_dir, overwrite=overwrite)
    except AuraUmsError as exc:
        raise fail(str(exc)) from None
    print_log_summary(log)
