"""The ``aura-ums`` command: figures, demo, simulate and the tools built on the library."""

from __future__ import annotations

import contextlib
import dataclasses
import io
import os
import stat
import sys
from pathlib import Path
from typing import Annotated, NoReturn

import typer
from rich.console import Console

from aura_ums.cli._campaign import (
    DEFAULTS,
    Retries,
    RunTimeout,
    Scheduler,
    Workers,
    campaign_failure,
    campaign_settings,
)
from aura_ums.cli._common import (
    NO_OPTIONS,
    PlainCommand,
    PlainGroup,
    Quiet,
    SettingOptions,
    check_seed,
    console,
    err_console,
    fail,
    folder_argument,
    manager_options,
    output_file,
    progress_bar,
    refuse_alone,
)
from aura_ums.cli._interop import (
    LIVE_DEFAULTS,
    MCAP_HELP,
    Live,
    LiveHost,
    LivePort,
    LiveRate,
    LiveWait,
    camera_info_command,
    live_rules,
    live_simulation,
    rosbag_command,
    write_simulation_mcap_option,
)
from aura_ums.cli._interrupt import TERMINATION_SIGNALS, Terminated, received
from aura_ums.cli._logs import import_app
from aura_ums.cli._outputs import (
    CWD_GONE,
    Overwrite,
    Source,
    Target,
    check_outputs,
    interruptible,
    staged,
    write_text,
)
from aura_ums.cli._replay import calibrate, compare, replay
from aura_ums.sim import PerceptionMode

app = typer.Typer(
    name="aura-ums",
    no_args_is_help=True,
    add_completion=False,
    cls=PlainGroup,
)


def _version(value: bool) -> None:
    if value:
        from importlib.metadata import version

        console.print(f"aura-ums {version('aura-ums')}", highlight=False, markup=False)
        raise typer.Exit()


@app.callback()
def _root(
    show_version: Annotated[
        bool,
        typer.Option("--version", help="Print the version and exit.", callback=_version, is_eager=True),
    ] = False,
) -> None:
    """Guaranteed spatial uncertainty management for a mobile robot (after Arkin's AuRA).

    Results go to stdout and files; errors, warnings and progress to stderr. A refused
    input or output exits with code 2, a Ctrl-C with 130 (no partial file is left).
    """


@app.command(cls=PlainCommand)
@interruptible
def figures(
    out: Annotated[
        Path,
        typer.Option(
            "--out",
            help="Folder to write the PNG figures into.",
            parser=folder_argument("--out", "a folder"),
            metavar="<path>",
        ),
    ] = Path("report/figures"),
    seed: Annotated[int, typer.Option(help="Seed of the sampled true outcomes drawn over the maps.")] = 0,
    overwrite: Overwrite = False,
) -> None:
    """Draw the paper's figures 3-7 (maps, windows, growth) with sampled true outcomes over them."""
    from aura_ums.errors import AuraUmsError
    from aura_ums.plot import draw_all_figures

    check_seed(seed)
    target = Target("--out", out, folder=True)
    check_outputs([target], [], overwrite=overwrite)
    try:
        with staged(target) as stage:
            draw_all_figures(stage, seed=seed)
    except AuraUmsError as exc:
        raise fail(str(exc)) from None


@app.command(cls=PlainCommand)
@interruptible
def demo(
    out: Annotated[
        Path,
        typer.Option(
            "--out",
            help="Folder for the report.",
            parser=folder_argument("--out", "a folder"),
            metavar="<path>",
        ),
    ] = Path("report"),
    seed: Annotated[int, typer.Option(help="Seed of every random draw in the report.")] = 0,
    runs: Annotated[int, typer.Option(help="Monte Carlo runs per variant in the summary.")] = 40,
    overwrite: Overwrite = False,
) -> None:
    """Run the paper's experiment and write its report (figures and summary.md) into OUT."""
    from aura_ums.errors import AuraUmsError
    from aura_ums.plot import paper_scenario, write_experiment_report

    # Checked before the report's first Monte Carlo: a traceback from deep inside it before.
    check_seed(seed)
    try:
        paper_scenario().check_runs(runs)
    except AuraUmsError as exc:
        raise fail(f"--{exc}") from None
    target = Target("--out", out, folder=True)
    check_outputs([target], [], overwrite=overwrite)
    try:
        with staged(target) as stage:
            write_experiment_report(stage, seed=seed, runs=runs)
    except AuraUmsError as exc:
        raise fail(str(exc)) from None


@app.command(cls=PlainCommand)
@interruptible
@manager_options(default_from="the scenario's [manager]")
def simulate(
    context: typer.Context,
    scenario: Annotated[Path, typer.Argument(readable=False, help="Scenario TOML file (see aura_ums.sim).")],
    runs: Annotated[int, typer.Option("--runs", help="Monte Carlo runs, >= 1.")] = 100,
    seed: Annotated[int, typer.Option("--seed", help="Seed of the whole Monte Carlo, >= 0.")] = 0,
    metrics_json: Annotated[
        Path | None,
        output_file("--metrics-json", "metrics.json", "Write the metrics as JSON to this file."),
    ] = None,
    prune: Annotated[
        bool,
        typer.Option("--prune/--no-prune", help="Reduce the map by landmarks (default) or only grow it."),
    ] = True,
    perception: Annotated[
        PerceptionMode,
        typer.Option(
            "--perception",
            help=(
                "Where the find-landmark schemas look: windows = the Expecter's (guaranteed) windows; "
                "full_frame = the whole image (the baseline); focus_first = the focus map's window first, "
                "the guaranteed one where the landmark is not there (with --relaxed-q, or --profile relaxed)."
            ),
        ),
    ] = PerceptionMode.WINDOWS,
    mcap: Annotated[Path | None, output_file("--mcap", "run.mcap", MCAP_HELP)] = None,
    live: Live = False,
    live_host: LiveHost = LIVE_DEFAULTS.host,
    live_port: LivePort = LIVE_DEFAULTS.port,
    live_rate: LiveRate = LIVE_DEFAULTS.rate,
    live_wait: LiveWait = None,
    workers: Workers = DEFAULTS.workers,
    scheduler: Scheduler = DEFAULTS.scheduler,
    retries: Retries = DEFAULTS.retries,
    run_timeout: RunTimeout = DEFAULTS.timeout_s,
    overwrite: Overwrite = False,
    quiet: Quiet = False,
    settings: SettingOptions = NO_OPTIONS,
) -> None:
    """Run SCENARIO through the closed loop RUNS times and print (and save) the metrics.

    The map manager's options override the scenario's [manager] table. With --workers N
    or --scheduler the runs go to Dask workers; the metrics are those of one process. With
    --live, each run is streamed to Foxglove as it computes, one after another, in this
    process.
    """
    import numpy as np

    from aura_ums import Metrics
    from aura_ums._files import path_mode
    from aura_ums.campaign import run_campaign, run_seeds, simulate_campaign
    from aura_ums.errors import AuraUmsError
    from aura_ums.sim import RunResult, Scenario, run_scenario, summarize_runs

    refuse_alone(context, live_rules(live))
    campaign_options = campaign_settings(context, workers, scheduler, retries, run_timeout)
    if runs < 1:
        raise fail(f"--runs: expected an integer >= 1, got {runs}")
    check_seed(seed)
    mode = path_mode(scenario)
    if not stat.S_ISREG(mode):
        got = "a folder" if stat.S_ISDIR(mode) else "a named pipe or socket" if mode else "no such file"
        raise fail(f"{scenario}: expected a scenario TOML file, got {got}")
    json_target = None if metrics_json is None else Target("--metrics-json", metrics_json)
    mcap_target = None if mcap is None else Target("--mcap", mcap)
    check_outputs([json_target, mcap_target], [Source("SCENARIO", scenario)], overwrite=overwrite)
    try:
        loaded = Scenario.from_toml(scenario)
    except AuraUmsError as exc:
        raise fail(str(exc)) from None
    # The files the scenario names (its map, camera, terrain table) are inputs too.
    named = [Source(f"SCENARIO's {key}", path) for key, path in loaded.files]
    check_outputs([json_target, mcap_target], [Source("SCENARIO", scenario), *named], overwrite=overwrite)
    loaded = dataclasses.replace(loaded, settings=settings.over(loaded.settings))
    try:
        loaded.check_runs(runs)  # before spawning a generator per run
    except AuraUmsError as exc:
        raise fail(f"--{exc}") from None
    if live and (campaign_options.workers > 1 or campaign_options.scheduler is not None):
        raise fail(
            f"--live: expected the runs in this process (--workers 1, no --scheduler), got "
            f"--workers {campaign_options.workers}"
            + ("" if campaign_options.scheduler is None else f" --scheduler {campaign_options.scheduler}")
        )
    watch = live_simulation(loaded, live=live, host=live_host, port=live_port, rate=live_rate, wait=live_wait)
    try:
        with watch as view, progress_bar(f"{loaded.name}: runs", quiet=quiet, total=runs) as advance:
            if view is None:
                campaign = simulate_campaign(
                    loaded,
                    runs,
                    seed,
                    prune=prune,
                    perception=perception,
                    settings=campaign_options,
                    progress=advance,
                )
                values = list(campaign.values)
                retried = campaign.retried
            else:  # streamed from this process: the serial campaign, each frame to the view
                frame = view.frame

                def watched(run_seed: np.random.SeedSequence) -> RunResult:
                    rng = np.random.default_rng(run_seed)
                    return run_scenario(loaded, rng, prune=prune, perception=perception, after_frame=frame)

                values = list(run_campaign(watched, run_seeds(seed, runs), progress=advance).values)
                retried = 0
    except AuraUmsError as exc:
        raise fail(campaign_failure(exc)) from None
    metrics = Metrics(
        {
            "scenario": loaded.name,
            "runs": runs,
            "seed": seed,
            "prune": prune,
            "perception": perception.value,
            "slice_width_rad": loaded.settings.slice_width,
            "relaxed_q": loaded.settings.relaxed_q,
            "relaxed_window": loaded.settings.relaxed_window,
            **summarize_runs(values),
            "runs_retried": retried,
        }
    )
    for line in metrics.lines():
        console.print(line, highlight=False, markup=False)
    if json_target is not None:
        write_text(json_target, metrics.to_json())
    if mcap_target is not None:
        write_simulation_mcap_option(
            mcap_target, loaded, seed, prune=prune, perception=perception, quiet=quiet
        )


# Commands on recorded logs, and the dataset importers (``aura-ums import ...``).
import_app.command("rosbag", cls=PlainCommand)(interruptible(rosbag_command))
import_app.command("camera-info", cls=PlainCommand)(interruptible(camera_info_command))
app.add_typer(import_app, name="import")
app.command(cls=PlainCommand)(interruptible(calibrate))
app.command(cls=PlainCommand)(interruptible(replay))
app.command(cls=PlainCommand)(interruptible(compare))


def main() -> None:
    """Entry point of the ``aura-ums`` console script."""
    _tolerant_streams()
    _stop_as_on_ctrl_c()
    # The command line only writes figure files (through Agg canvases), never shows one: a
    # backend named in the environment is never needed, and a misspelt one made matplotlib's
    # import fail (a ValueError traceback from --plot, figures and demo).
    os.environ["MPLBACKEND"] = "agg"
    _warn_if_the_current_folder_is_gone()
    out_of_memory = False
    try:
        app()
    except OSError as exc:
        # Every output file's failure is worded where it is written; stdout's own (a full
        # disk, a device that takes nothing) is told by where it was raised.
        if not _raised_writing_stdout(exc):
            raise
        _drop_stdout()
        # Past typer's own handling: its Exit would not become an exit status here.
        refusal = fail(f"stdout: expected a place to print the results, got {exc.strerror or exc}")
        raise SystemExit(refusal.exit_code) from None
    except MemoryError:
        # Said below, once this block is left: the exception holds the frames that hold the
        # arrays, and printing needs memory too.
        out_of_memory = True
    if out_of_memory:
        _say_out_of_memory()


#: Counts that would exhaust memory are refused from an estimate before any work; this is
#: the system refusing memory all the same (a tight ``ulimit -v``, a crowded machine).
_OUT_OF_MEMORY = (
    "error: memory: expected what this command needs, got a refusal from the system (MemoryError); "
    "files already written stay whole, nothing else was written. Raise the process's memory limit "
    "(ulimit -v) or free memory, then run it again\n"
)


def _say_out_of_memory() -> NoReturn:
    """Say on stderr that memory ran out (plainly: rich's rendering needs memory) and exit 2."""
    try:
        sys.stderr.write(_OUT_OF_MEMORY)
        sys.stderr.flush()
    except (MemoryError, OSError, ValueError):
        with contextlib.suppress(OSError):
            os.write(2, _OUT_OF_MEMORY.encode("ascii", "replace"))
    raise SystemExit(2)


def _warn_if_the_current_folder_is_gone() -> None:
    """Say why relative paths will not be found when the shell's current folder was deleted."""
    try:
        os.getcwd()
    except FileNotFoundError:
        err_console.print(
            f"warning: relative paths cannot be found: {CWD_GONE}",
            highlight=False,
            markup=False,
        )


def _stop_as_on_ctrl_c() -> None:
    """Make SIGTERM and SIGHUP stop the command as a Ctrl-C does (:class:`Terminated`).

    By default they end the process at once: `timeout`, `kill`, a CI runner cancelling a
    job or a closed terminal left a command's scratch files behind, said nothing, and
    ended it by the signal. A signal someone chose to ignore (``nohup``) stays ignored.
    """
    import signal

    def stop(signum: int, frame: object) -> None:
        request = Terminated(signum, signal.Signals(signum).name)
        received(request)
        raise request

    stop.stops_the_command = True  # type: ignore[attr-defined]  # told apart at the end (cli.main)
    for name in TERMINATION_SIGNALS:
        number = getattr(signal, name, None)
        if number is None:  # not on this system (SIGHUP on Windows)
            continue
        with contextlib.suppress(ValueError, OSError):  # not the main thread: the caller's signals
            if signal.getsignal(number) is signal.SIG_DFL:
                signal.signal(number, stop)


def _raised_writing_stdout(exc: BaseException) -> bool:
    """Whether ``exc`` came from a console writing to stdout (rich's write of its buffer)."""
    innermost = exc.__traceback__
    if innermost is None:
        return False
    while innermost.tb_next is not None:
        innermost = innermost.tb_next
    writer = innermost.tb_frame.f_locals.get("self")
    return isinstance(writer, Console) and writer.file is sys.stdout


def _drop_stdout() -> None:
    """Send what is left for stdout nowhere: the interpreter's last flush would fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError, AttributeError):
        pass


def _tolerant_streams() -> None:
    """Let stdout and stderr show what their encoding cannot, escaped, instead of failing.

    The help and the tables hold a few characters beyond ASCII (an ellipsis, a micro
    sign); on a stream that cannot encode them (``PYTHONIOENCODING=ascii``, an old
    console's code page) printing raised UnicodeEncodeError, a traceback, after the
    command had done its work. A UTF-8 stream is left exactly as it is.
    """
    for stream in (sys.stdout, sys.stderr):
        encoding = (getattr(stream, "encoding", None) or "").lower().replace("-", "")
        if encoding != "utf8" and isinstance(stream, io.TextIOWrapper):
            stream.reconfigure(errors="backslashreplace")
