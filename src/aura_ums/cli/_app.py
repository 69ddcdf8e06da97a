"""The ``aura-ums`` command: figures, demo, simulate and the tools built on the library."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console

from aura_ums.cli._common import NO_OPTIONS, SettingOptions, fail, manager_options, write_metrics_json
from aura_ums.cli._interop import MCAP_HELP, rosbag_command, write_simulation_mcap_option
from aura_ums.cli._logs import import_app
from aura_ums.cli._replay import calibrate, compare, replay

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
    runs: Annotated[int, typer.Option(help="Monte Carlo runs per variant in the summary.")] = 40,
) -> None:
    """Run the paper's experiment and write its report (figures and summary.md) into OUT."""
    from aura_ums.plot import write_experiment_report

    summary = write_experiment_report(out, seed=seed, runs=runs)
    _console.print(f"wrote {summary}")


@app.command()
@manager_options(default_from="the scenario's [manager]")
def simulate(
    scenario: Annotated[Path, typer.Argument(help="Scenario TOML file (see aura_ums.sim).")],
    runs: Annotated[int, typer.Option("--runs", help="Monte Carlo runs, >= 1.")] = 100,
    seed: Annotated[int, typer.Option("--seed", help="Seed of the whole Monte Carlo, >= 0.")] = 0,
    metrics_json: Annotated[
        Path | None, typer.Option("--metrics-json", help="Write the metrics as JSON to this file.")
    ] = None,
    prune: Annotated[
        bool,
        typer.Option("--prune/--no-prune", help="Reduce the map by landmarks (default) or only grow it."),
    ] = True,
    mcap: Annotated[Path | None, typer.Option("--mcap", help=MCAP_HELP)] = None,
    settings: SettingOptions = NO_OPTIONS,
) -> None:
    """Run SCENARIO through the closed loop RUNS times and print (and save) the metrics.

    The map manager's options override the scenario's [manager] table.
    """
    import numpy as np
    from rich.progress import Progress

    from aura_ums import Metrics
    from aura_ums.errors import AuraUmsError
    from aura_ums.sim import Scenario, run_scenario, summarize_runs

    if runs < 1:
        raise fail(f"--runs: expected an integer >= 1, got {runs}")
    if seed < 0:
        raise fail(f"--seed: expected an integer >= 0, got {seed}")
    if not scenario.is_file():
        raise fail(f"{scenario}: expected a scenario TOML file, got no such file")
    try:
        loaded = Scenario.from_toml(scenario)
    except AuraUmsError as exc:
        raise fail(str(exc)) from None
    loaded = dataclasses.replace(loaded, settings=settings.over(loaded.settings))
    generators = np.random.default_rng(seed).spawn(runs)
    results = []
    try:
        with Progress(console=_console, transient=True) as progress:
            task = progress.add_task(f"{loaded.name}", total=runs)
            for rng in generators:
                results.append(run_scenario(loaded, rng, prune=prune))
                progress.advance(task)
    except AuraUmsError as exc:
        raise fail(str(exc)) from None
    metrics = Metrics(
        {
            "scenario": loaded.name,
            "runs": runs,
            "seed": seed,
            "prune": prune,
            "relaxed_q": loaded.settings.relaxed_q,
            "relaxed_window": loaded.settings.relaxed_window,
            **summarize_runs(results),
        }
    )
    for line in metrics.lines():
        _console.print(line, highlight=False, markup=False)
    if metrics_json is not None:
        write_metrics_json(metrics_json, metrics)
    if mcap is not None:
        write_simulation_mcap_option(mcap, loaded, seed, prune=prune)


# Commands on recorded logs, and the dataset importers (``aura-ums import ...``).
import_app.command("rosbag")(rosbag_command)
app.add_typer(import_app, name="import")
app.command()(calibrate)
app.command()(replay)
app.command()(compare)


def main() -> None:
    """Entry point of the ``aura-ums`` console script."""
    app()
