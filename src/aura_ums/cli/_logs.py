"""``aura-ums import``: turn published datasets into aura-ums log folders (docs/log-format.md)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from aura_ums._files import read_folder
from aura_ums.cli._common import (
    NewLogFolder,
    PlainCommand,
    PlainGroup,
    Quiet,
    fail,
    folder_argument,
    print_log_summary,
    progress_bar,
)
from aura_ums.cli._outputs import Overwrite, Source, Target, check_outputs, interruptible, wrote

import_app = typer.Typer(
    help="Turn published datasets into aura-ums log folders (see docs/log-format.md).",
    no_args_is_help=True,
    add_completion=False,
    cls=PlainGroup,
)


@import_app.command("mrclam", cls=PlainCommand)
@interruptible
def mrclam(
    dataset_dir: Annotated[
        Path,
        typer.Argument(
            help="UTIAS MRCLAM dataset folder (Barcodes.dat, RobotN_*.dat, ...).",
            parser=folder_argument("DATASET_DIR", "a dataset folder"),
        ),
    ],
    out_dir: NewLogFolder,
    robot: Annotated[int, typer.Option("--robot", help="Robot number, 1 to 5.")],
    overwrite: Overwrite = False,
    quiet: Quiet = False,
) -> None:
    """Import robot ROBOT's run of the UTIAS MRCLAM dataset in DATASET_DIR as a log folder OUT_DIR.

    Measurements of other robots and of unknown barcodes are dropped (counted in the log's
    source text); ranges stay in metres; sensor bounds are placeholders to calibrate.
    The folder is written under a hidden scratch name and renamed when complete.
    """
    import dataclasses

    from aura_ums.errors import AuraUmsError
    from aura_ums.logs import read_mrclam, write_log

    try:
        # before the outputs are checked: a mistyped DATASET_DIR is the likelier mistake
        read_folder(dataset_dir, kind="UTIAS MRCLAM dataset folder")
    except AuraUmsError as exc:
        raise fail(str(exc)) from None
    target = Target("OUT_DIR", out_dir, folder=True)
    check_outputs([target], [Source("DATASET_DIR", dataset_dir, folder=True)], overwrite=overwrite)
    try:
        log = read_mrclam(dataset_dir, robot)
        with progress_bar(f"{out_dir}: files", quiet=quiet) as advance:
            folder = write_log(log, out_dir, overwrite=overwrite, progress=advance)
    except AuraUmsError as exc:
        message = str(exc)
        # the library names its argument; the user gave the option
        raise fail(f"--{message}" if message.startswith("robot: ") else message) from None
    wrote(folder)
    print_log_summary(dataclasses.replace(log, path=folder))
