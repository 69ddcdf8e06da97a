"""The ``aura-ums`` command: figures, demo and the tools built on the library."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console

app = typer.Typer(
    name="aura-ums",
    help="Guaranteed spatial uncertainty management for a mobile robot (after Arkin's AuRA).",
    no_args_is_help=True,
    add_completion=False,
)
_console = Console()


@app.command()
def figures(
    out: Annotated[Path, typer.Option("--out", help="Folder to write the PNG figures into.")] = Path(
        "report/figures"
    ),
    seed: Annotated[int, typer.Option(help="Seed of the sampled true outcomes drawn over the maps.")] = 0,
) -> None:
    """Draw the paper's figures 3-7 (maps, windows, growth) with sampled true outcomes over them."""
    from aura_ums.plot import draw_all_figures

    written = draw_all_figures(out, seed=seed)
    for path in written:
        _console.print(f"wrote {path}")


@app.command()
def demo(
    out: Annotated[Path, typer.Option("--out", help="Folder for the report.")] = Path("report"),
    seed: Annotated[int, typer.Option(help="Seed of every random draw in the report.")] = 0,
) -> None:
    """Run the main job and write its report (figures and summary.md) into OUT."""
    from aura_ums.plot import write_growth_report

    summary = write_growth_report(out, seed=seed)
    _console.print(f"wrote {summary}")


def main() -> None:
    """Entry point of the ``aura-ums`` console script."""
    app()
