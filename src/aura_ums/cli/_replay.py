"""``aura-ums calibrate``, ``replay`` and ``compare``: the map on recorded logs."""

from __future__ import annotations

import contextlib
import dataclasses
import enum
import inspect
import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.table import Table

from aura_ums._validate import IMAGE_SIDE, exact_text
from aura_ums.cli._campaign import (
    DEFAULTS,
    Retries,
    RunTimeout,
    Scheduler,
    Workers,
    campaign_failure,
    campaign_settings,
    replay_logs,
)
from aura_ums.cli._common import (
    NO_OPTIONS,
    Quiet,
    SettingOptions,
    check_seed,
    console,
    err_console,
    fail,
    folder_argument,
    input_file,
    manager_options,
    output_file,
    progress_bar,
    refuse_alone,
    warn,
)
from aura_ums.cli._interop import (
    LIVE_DEFAULTS,
    Live,
    LiveHost,
    LivePort,
    LiveRate,
    LiveWait,
    live_replay,
    live_rules,
)
from aura_ums.cli._outputs import (
    Overwrite,
    Source,
    Target,
    check_outputs,
    placed,
    refuse_root,
    resolved,
    safe_name,
    staged,
    write_text,
    wrote,
)

if TYPE_CHECKING:
    from aura_ums import Metrics
    from aura_ums.logs import LogStream, ReplayOptions, ReplayResult, RobotLog, WindowReport
    from aura_ums.manager import ManagerSettings
    from aura_ums.uncertainty import TerrainTable


# A calibrated bearing bound wider than this (29 degrees) is warned about: a misread log.
_LOOSE_BEARING_RAD = 0.5

# draw_replay's file name after the log's name
_FIGURE = "_replay.png"


class Classes(enum.StrEnum):
    """The landmark classes a replay reads a log's observations as (``--classes``)."""

    #: Class I: bearings only, to vertical lines.
    VERTICAL_LINE = "I"
    #: Class II: range and bearing, to points.
    POINT = "II"


class Reverse(enum.StrEnum):
    """What a replay does with negative forward speeds (``--reverse``): ``ReverseMotion``'s choices."""

    #: Refuse the log, naming the first reversing row.
    ERROR = "error"
    #: Report each reversing piece as a half turn, a forward run and a half turn back.
    FLIP = "flip"


_Classes = Annotated[Classes, typer.Option("--classes", help="I: bearings only; II: range and bearing.")]
_Terrain = Annotated[
    Path,
    typer.Option(
        "--terrain",
        parser=input_file("--terrain", "a terrain table TOML file"),
        metavar="<path>",
        help="Terrain table TOML holding the log's terrain.",
    ),
]
_Sensors = Annotated[
    Path | None,
    typer.Option(
        "--sensors",
        readable=False,
        help="Sensor calibration TOML from `aura-ums calibrate` (default: the one it wrote beside "
        "--terrain, TERRAIN.sensors.toml, when there is one; else the log's meta.toml).",
    ),
]
_ReverseOption = Annotated[
    Reverse,
    typer.Option(
        "--reverse", help="Negative forward speed: refuse (error) or replay as turn, run, turn (flip)."
    ),
]
_MaxTruthGap = Annotated[
    float | None,
    typer.Option(
        "--max-truth-gap",
        help="Longest interval, seconds, between ground-truth rows interpolated across; frames in a "
        "longer gap are not scored (default 0.5 s; 'inf' for none).",
    ),
]

_Camera = Annotated[
    Path | None,
    typer.Option(
        "--camera",
        readable=False,
        help="Camera TOML (e.g. examples/virtual_camera_60deg.toml; its [intrinsics] may name an OpenCV or "
        "ROS calibration file instead of giving fx...): judge each observation's image window.",
    ),
]
_WindowMargin = Annotated[
    float,
    typer.Option("--window-margin", help="Pixels added on every side of each window (--camera)."),
]
_WindowsCsv = Annotated[
    Path | None,
    output_file(
        "--windows-csv", "windows.csv", "Write one row per observation and window method (--camera)."
    ),
]


# How the library names the parts of a saved state in its messages (--resume names the file).
_STATE_PARTS = ("blackboard: ", "<manager JSON>", "<blackboard JSON>")
#: How a sensors file's growth is said: the terrain statistics were fitted ...
_FITTED = {False: "move by move (calibrate without --anchor)", True: "from an anchor (calibrate --anchor)"}
#: How the library's messages start when they name a log by its name (its repr's quotes).
_LOG_NAMED = ("log '", 'log "')
#: Most particles of compare's particle filter (about 100 bytes each, several arrays).
_MOST_PARTICLES = 1_000_000

#: calibrate_logs' arguments that calibrate takes as options.
_CALIBRATE_OPTIONS = {"quantile": "--quantile", "move": "--move", "horizons": "--horizon"}


def _check_truth_gap(max_truth_gap: float | None) -> None:
    """Refuse (exit 2) a --max-truth-gap that is not a positive number of seconds (inf: none)."""
    if max_truth_gap is not None and not max_truth_gap > 0.0:
        raise fail(f"--max-truth-gap: expected a positive number of seconds (or inf), got {max_truth_gap}")


def _figure(value: float, spec: str) -> str:
    """Format a table figure; NaN (nothing to measure, e.g. no step with ground truth) as ``n/a``."""
    return "n/a" if math.isnan(value) else format(value, spec)


def _terrain_table(terrain: Path, name: str, log_dir: Path) -> TerrainTable:
    """Read ``--terrain``; refuse (exit 2, naming the option and file) a table without the log's terrain."""
    from aura_ums.errors import InputError
    from aura_ums.uncertainty import TerrainTable

    table = TerrainTable.from_toml(terrain)
    try:
        table.require(name, where=f"--terrain {terrain}", whose=f"the log in {log_dir} (its meta.toml)")
    except InputError as exc:
        raise fail(str(exc)) from None
    return table


def _calibration_source(camera: Path | None) -> Source | None:
    """Return the calibration file the --camera file names (``[intrinsics] calibration``) as an input.

    Reads the camera file (an AuraUmsError for a malformed one, as loading it would give).
    """
    from aura_ums.camera import camera_calibration_file

    named = None if camera is None else camera_calibration_file(camera)
    return None if named is None else Source("--camera's [intrinsics] calibration", named)


def _sensors_source(sensors: Path | None, terrain: Path) -> Source | None:
    """Return the sensors file as an input: the one given, else the one :func:`_sensors_file` reads."""
    from aura_ums._files import regular_file
    from aura_ums.logs import sensors_path

    if sensors is not None:
        return Source("--sensors", sensors)
    beside = sensors_path(terrain)
    return Source("--sensors (by default, beside --terrain)", beside) if regular_file(beside) else None


def _sensors_file(sensors: Path | None, terrain: Path) -> Path | None:
    """Return the sensors file to read: the one given, else the one calibrate wrote beside ``terrain``."""
    from aura_ums._files import regular_file
    from aura_ums.logs import sensors_path

    if sensors is not None:
        return sensors
    beside = sensors_path(terrain)
    if regular_file(beside):
        # Replaying without the calibrated sensor bounds is silently much worse: read them.
        # A note, not a result: on stderr, so that stdout holds the metrics alone.
        err_console.print(
            f"note: sensors: {beside} (written by calibrate beside {terrain})", markup=False, highlight=False
        )
        return beside
    return None


def _refuse_other_settings(settings: SettingOptions, kept: ManagerSettings) -> None:
    """Refuse (exit 2) an option given with --resume that differs from the saved settings.

    A resumed replay runs on with the settings it was saved with (so that it ends as an
    uninterrupted one would): an option that asks for another value would be ignored.
    """
    wanted = settings.over(kept)
    for name in settings.given:
        saved, asked = getattr(kept, name), getattr(wanted, name)
        if saved != asked:
            raise fail(
                f"{settings.option_of(name)}: expected {name} {_setting_text(saved)}, as --resume's state "
                f"was saved with (a resumed replay runs with its saved settings), got {_setting_text(asked)}"
            )


def _setting_text(value: object) -> str:
    return "none" if value is None else f"{value:g}" if isinstance(value, float) else str(value).lower()


#: The replay's inputs a resumed state recorded (``ReplayState.inputs``) and the options that give them.
_RESUMED_INPUTS = {
    "landmark_class": "--classes",
    "reverse": "--reverse",
    "sensor bounds": "--sensors",
    "terrain table": "--terrain",
}


def _resumed_input(message: str) -> str:
    """Return the input a library refusal to resume names (``resume: expected [the] NAME ...``), else ''."""
    for name in _RESUMED_INPUTS:
        if message.startswith((f"resume: expected {name} ", f"resume: expected the {name} ")):
            return name
    return ""


def _options(
    classes: Classes, sensors: Path | None, settings: ManagerSettings, reverse: Reverse = Reverse.ERROR
) -> ReplayOptions:
    from aura_ums.logs import ReplayOptions, ReverseMotion, fitted_for_anchor, load_sensors
    from aura_ums.uncertainty import LandmarkClass

    # Without a sensors file, the options' defaults: the log's meta.toml.
    motion, working, envelope = load_sensors(sensors) if sensors is not None else (None, None, None)
    fitted = None if sensors is None else fitted_for_anchor(sensors)
    if fitted is not None and fitted != settings.anchor_growth:
        # The statistics of one growth bound nothing of the other: from an anchor, those fitted
        # move by move kept the truth in under 1% of a log's frames, with exit 0.
        said = _FITTED[fitted]
        wanted = "without it" if fitted is False else "with it"
        raise fail(
            f"--anchor-growth: expected the growth the terrain statistics were fitted for, got {sensors} "
            f"saying they were fitted {said}: replay {wanted}, or calibrate again"
        )
    if settings.anchor_growth and fitted is None:
        where = "no sensors file" if sensors is None else f"{sensors}, which does not say (an older file)"
        warn(
            "--anchor-growth: the terrain statistics must be fitted for growth from an anchor "
            f"(aura-ums calibrate --anchor), and {where} says they were"
        )
    return ReplayOptions(
        settings=settings,
        landmark_class=LandmarkClass[classes.name],
        working=working,
        envelope=envelope,
        motion=motion,
        reverse=ReverseMotion(reverse.value),
    )


def calibrate(
    context: typer.Context,
    log_dirs: Annotated[
        list[Path],
        typer.Argument(
            help="Log folders with groundtruth.csv, one terrain.",
            parser=folder_argument("LOG_DIRS"),
        ),
    ],
    out: Annotated[
        Path,
        output_file("--out", "terrain.toml", "Terrain table TOML to write."),
    ],
    sensors_out: Annotated[
        Path | None,
        output_file(
            "--sensors-out",
            "terrain.sensors.toml",
            "Motion and sensor bounds TOML (default: OUT with .sensors.toml).",
        ),
    ] = None,
    quantile: Annotated[float, typer.Option(help="Quantile the motion and working bounds cover.")] = 0.99,
    move: Annotated[float, typer.Option("--move", help="Seconds per move of the motion fit.")] = 0.5,
    horizons: Annotated[
        list[float] | None,
        typer.Option(
            "--horizon",
            metavar="<float>",
            help="Seconds without correction over which the motion bound must hold; repeat it "
            "(default 1, 2, 5, 10 and 30).",
        ),
    ] = None,
    max_truth_gap: _MaxTruthGap = None,
    anchor: Annotated[
        bool,
        typer.Option(
            "--anchor/--per-move",
            help="Fit the terrain statistics for growth from an anchor (replay --anchor-growth) "
            "or move by move.",
        ),
    ] = False,
    workers: Workers = DEFAULTS.workers,
    scheduler: Scheduler = DEFAULTS.scheduler,
    retries: Retries = DEFAULTS.retries,
    run_timeout: RunTimeout = DEFAULTS.timeout_s,
    overwrite: Overwrite = False,
    quiet: Quiet = False,
) -> None:
    """Estimate terrain statistics and sensor bounds from logs with ground truth.

    With --workers N or --scheduler the logs are read on Dask workers; the fit pools them.
    """
    import numpy as np

    from aura_ums.campaign import LoadLog, run_campaign
    from aura_ums.errors import AuraUmsError
    from aura_ums.logs import calibrate_logs

    if not out.name:
        raise fail(f"--out: expected a file path, got {str(out)!r}")
    # Each folder's windows would count twice, as if two robots had run it.
    _distinct("LOG_DIRS", log_dirs)
    _check_truth_gap(max_truth_gap)
    out_target = Target("--out", out)
    sensors_target = Target(
        "--sensors-out" if sensors_out is not None else "--out (its .sensors.toml)",
        sensors_out if sensors_out is not None else out.with_suffix(".sensors.toml"),
    )
    check_outputs(
        [out_target, sensors_target],
        [Source("LOG_DIRS", folder, folder=True) for folder in log_dirs],
        overwrite=overwrite,
    )
    campaign_options = campaign_settings(context, workers, scheduler, retries, run_timeout)
    try:
        with progress_bar("calibrate: logs", quiet=quiet, total=len(log_dirs)) as advance:
            loaded = run_campaign(LoadLog(max_truth_gap), log_dirs, campaign_options, progress=advance)
    except AuraUmsError as exc:
        raise fail(campaign_failure(exc)) from None
    logs = list(loaded.values)
    for folder, log in zip(log_dirs, logs, strict=True):
        if log.groundtruth is None:
            raise fail(
                f"LOG_DIRS: expected log folders with ground truth (the calibration fits the motion and "
                f"sensor bounds against it), got {folder} without a groundtruth.csv"
            )
    try:
        if horizons:
            calibration = calibrate_logs(
                logs, quantile=quantile, move=move, horizons=tuple(horizons), anchor=anchor
            )
        else:  # calibrate_logs' default horizons
            calibration = calibrate_logs(logs, quantile=quantile, move=move, anchor=anchor)
    except AuraUmsError as exc:
        message = str(exc)
        name, _, rest = message.partition(": ")
        if name == "horizons" and not horizons and "windows of motion" in rest:
            # no --horizon given: the logs are too short for the default horizons
            folders = ", ".join(str(folder) for folder in log_dirs)
            raise fail(f"LOG_DIRS ({folders}): calibrating from their contents: default {message}") from None
        if name == "horizons" and not horizons:
            # no --horizon given: the defaults are too short for the --move given, the option at fault
            defaults = inspect.signature(calibrate_logs).parameters["horizons"].default
            raise fail(
                f"--move: expected seconds <= the shortest horizon ({min(defaults):g} s of the defaults "
                f"{', '.join(f'{h:g}' for h in defaults)}; --horizon sets others), got {move!r}"
            ) from None
        if name in _CALIBRATE_OPTIONS:  # an option out of range: named as the user gave it
            raise fail(f"{_CALIBRATE_OPTIONS[name]}: {rest}") from None
        # The logs read cleanly; what they hold does not calibrate: name them, not the library's arguments.
        folders = ", ".join(str(folder) for folder in log_dirs)
        raise fail(f"LOG_DIRS ({folders}): calibrating from their contents: {message}") from None
    write_text(out_target, calibration.terrain_table().to_toml())
    write_text(sensors_target, calibration.sensors_toml())
    motion, working, envelope = calibration.motion, calibration.working, calibration.envelope
    console.print(
        f"motion: delay {motion.delay_s:.2f} s, run scale {motion.run_scale:.3f}, "
        f"turn scale {motion.turn_scale:.3f} ({calibration.motion_windows} windows)"
    )
    for name, bounds in (("working", working), ("envelope", envelope)):
        console.print(
            f"{name}: bearing +-{bounds.bearing_error:.4f} rad, range "
            f"-{bounds.range_fraction_high:.3f}/+{bounds.range_fraction_low:.3f} of measured "
            f"+-{bounds.range_error:.3f} m "
            f"({calibration.observations} observations)"
        )
    if working.bearing_error > _LOOSE_BEARING_RAD:
        # Sound, but a map no sighting can shrink: most likely the logs, not the sensor.
        warn(
            f"working bearing bound: expected the observations to agree with the ground truth within "
            f"{_LOOSE_BEARING_RAD:g} rad, got +-{working.bearing_error:.4f} rad: no sighting will shrink the "
            "map much; check the logs' landmark ids, and their bearings' sign and units"
        )
    if envelope.bearing_error >= math.pi:
        # The largest error seen sets it: one misidentified landmark in the logs is enough.
        warn(
            f"envelope bearing bound: expected less than pi rad, got +-{envelope.bearing_error:.4f} rad (the "
            "largest bearing error seen, times the margin): the envelope map learns nothing from bearings, "
            "and re-localizes from a wide map; check the logs for a misidentified landmark"
        )
    for folder, log in zip(log_dirs, logs, strict=True):
        speeds = np.empty(0) if log.odometry is None else log.odometry.v
        backing = int(np.count_nonzero(speeds < 0.0))
        if backing:
            warn(
                f"{folder}: {backing} odometry rows with a negative forward speed (down to "
                f"{float(speeds.min()):.4g} m/s) calibrated by the length they ran, as replay "
                "--reverse flip replays them; replay refuses them without --reverse flip"
            )
    if campaign_options.distributed:
        console.print(f"logs read on Dask workers: {len(logs)} ({loaded.retried} retried)", highlight=False)
    console.print("growth bound against the truth, by horizon without correction:", highlight=False)
    console.print(calibration.report(), highlight=False, markup=False)


@manager_options()
def replay(
    context: typer.Context,
    log_dirs: Annotated[
        list[Path],
        typer.Argument(
            help="Log folder (docs/log-format.md); several are replayed as one campaign (--workers).",
            parser=folder_argument("LOG_DIR"),
        ),
    ],
    terrain: _Terrain,
    sensors: _Sensors = None,
    classes: _Classes = Classes.VERTICAL_LINE,
    reverse: _ReverseOption = Reverse.ERROR,
    max_truth_gap: _MaxTruthGap = None,
    settings: SettingOptions = NO_OPTIONS,
    metrics_json: Annotated[
        Path | None,
        output_file("--metrics-json", "metrics.json", "Write the metrics as JSON to this file."),
    ] = None,
    steps_csv: Annotated[
        Path | None,
        output_file("--steps-csv", "steps.csv", "Write one row per time step to this CSV file."),
    ] = None,
    plot: Annotated[
        Path | None,
        typer.Option(
            "--plot",
            help="Folder for a figure of the replay.",
            parser=folder_argument("--plot", "a folder"),
            metavar="<path>",
        ),
    ] = None,
    mcap: Annotated[
        Path | None,
        output_file("--mcap", "run.mcap", "Write the replay as MCAP for Foxglove."),
    ] = None,
    camera: _Camera = None,
    window_margin: _WindowMargin = 0.0,
    windows_csv: _WindowsCsv = None,
    save_state: Annotated[
        Path | None,
        output_file(
            "--save-state", "state.json", "Write where the replay stopped (versioned JSON), to --resume from."
        ),
    ] = None,
    resume: Annotated[
        Path | None,
        typer.Option(
            "--resume",
            readable=False,
            help="Continue a replay of this log from a state saved by --save-state.",
        ),
    ] = None,
    until: Annotated[
        float | None,
        typer.Option(
            "--until",
            help="Stop after the last frame at or before this log time, in s (whatever the time unit of "
            "the log's files; a time after its last frame is said).",
        ),
    ] = None,
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
) -> None:
    """Run the map manager over a log and report containment, area, wedge width and speed.

    With --camera, also the image windows of each real observation (ours, an EKF's
    3-sigma box, the disk model) and how often the observation fell inside.

    With --resume the replay continues where a --save-state left it (its settings, landmark
    class, sensors and terrain are the saved ones: an option asking for others is refused)
    and reports the frames after it; it ends with exactly the map of a replay run in one go. With --live, the
    replay is streamed to Foxglove as it computes (with --camera, its windows too, on a
    blank image: logs carry no images).

    With several LOG_DIRs, each is replayed on its own (on Dask workers with --workers N
    or --scheduler) and the metrics list one entry per log (`replays`); the outputs of
    one log's steps, maps and state, and --live, need one LOG_DIR.
    """
    from aura_ums import Metrics
    from aura_ums.camera import load_calibration_bounds, load_camera
    from aura_ums.campaign import LoadLog
    from aura_ums.errors import AuraUmsError
    from aura_ums.logs import ReplayState, RobotLog, replay_log, replay_windows
    from aura_ums.manager import UncertaintyMapManager
    from aura_ums.uncertainty import TerrainTable

    if windows_csv is not None and camera is None:
        raise fail("--windows-csv: expected --camera too, got no camera")
    if until is not None and not math.isfinite(until):
        raise fail(f"--until: expected a finite number of seconds, got {until}")
    _check_truth_gap(max_truth_gap)
    if not 0.0 <= window_margin < float("inf"):
        raise fail(f"--window-margin: expected a finite number of pixels >= 0, got {window_margin}")
    if window_margin > IMAGE_SIDE.high:
        raise fail(
            f"--window-margin: expected at most {IMAGE_SIDE.high:g} pixels (an image's longest side), "
            f"got {window_margin:g}"
        )
    refuse_alone(context, [("window_margin", "--camera", "no camera", camera is not None), *live_rules(live)])
    campaign_options = campaign_settings(context, workers, scheduler, retries, run_timeout)
    if len(log_dirs) > 1:
        one_log = {"--steps-csv": steps_csv, "--plot": plot, "--mcap": mcap, "--save-state": save_state,
                   "--resume": resume, "--windows-csv": windows_csv}  # fmt: skip
        given = [flag for flag, value in one_log.items() if value is not None]
        given += ["--live"] if live else []
        if given:
            raise fail(f"{given[0]}: expected one LOG_DIR, got {len(log_dirs)}")
        json_target = None if metrics_json is None else Target("--metrics-json", metrics_json)
        sources: list[Source | None] = [Source("LOG_DIR", folder, folder=True) for folder in log_dirs]
        sources += [Source("--terrain", terrain), _sensors_source(sensors, terrain),
                    None if camera is None else Source("--camera", camera)]  # fmt: skip
        check_outputs([json_target], sources, overwrite=overwrite)
        try:
            # The calibration file the camera file names is an input too.
            check_outputs([json_target], [*sources, _calibration_source(camera)], overwrite=overwrite)
            many = TerrainTable.from_toml(terrain)
            options = _options(classes, _sensors_file(sensors, terrain), settings.over(), reverse)
            lens = None if camera is None else load_camera(camera)
            # The windows hold for every camera within the file's [calibration_bounds] (none: exact).
            lens_bounds = None if camera is None else load_calibration_bounds(camera)
        except AuraUmsError as exc:
            raise fail(str(exc)) from None
        replay_logs(log_dirs, many, options, table_file=terrain, camera=lens, calibration_bounds=lens_bounds,
                    window_margin=window_margin,
                    max_truth_gap=max_truth_gap, until=until, json_target=json_target,
                    settings=campaign_options, quiet=quiet)  # fmt: skip
        return
    (log_dir,) = log_dirs
    sources = [
        Source("LOG_DIR", log_dir, folder=True),
        Source("--terrain", terrain),
        _sensors_source(sensors, terrain),
        None if resume is None else Source("--resume", resume),
        None if camera is None else Source("--camera", camera),
    ]
    targets = [
        None if metrics_json is None else Target("--metrics-json", metrics_json),
        None if steps_csv is None else Target("--steps-csv", steps_csv),
        None if mcap is None else Target("--mcap", mcap),
        None if save_state is None else Target("--save-state", save_state),
        None if windows_csv is None else Target("--windows-csv", windows_csv),
    ]
    check_outputs(targets, sources, overwrite=overwrite)
    json_target, csv_target, mcap_target, state_target, windows_target = targets
    windows = None
    try:
        # Streamed (bounded memory) unless an output needs the whole log: maps drawn or
        # exported, the live view, a camera's windows, a saved state's digest.
        whole = any(item is not None for item in (plot, mcap, resume, save_state, camera)) or live
        log = LoadLog(max_truth_gap)(log_dir) if whole else _open(log_dir, max_truth_gap)
        figure = f"{safe_name(log.meta.name)}{_FIGURE}"
        plot_target = None if plot is None else Target("--plot", plot / figure)
        if plot is not None:
            refuse_root("--plot", plot)  # the figure is drawn in a scratch folder beside it
        sources.append(_calibration_source(camera))  # the calibration file the camera file names
        check_outputs([*targets, plot_target], sources, overwrite=overwrite)
        table = _terrain_table(terrain, log.meta.terrain, log_dir)
        options = _options(classes, _sensors_file(sensors, terrain), settings.over(), reverse)
        if save_state is not None and options.settings.anchor_growth:
            raise fail(
                "--save-state: expected a replay without --anchor-growth (a saved state does not hold "
                "the anchors, so a resumed replay would not end with the map of an uninterrupted one), "
                "got both"
            )
        if resume is not None and camera is not None:
            warn(
                "--camera with --resume: the EKF's 3-sigma boxes start again at the resumed frame "
                "(a saved state holds our map, not the EKF), so their window figures differ from an "
                "uninterrupted replay's; ours and the disk model's do not"
            )
        saved = None if resume is None else ReplayState.load(resume)
        if saved is not None:
            kept = UncertaintyMapManager.saved_settings(saved.manager_json, source=f"{resume}: manager")
            _refuse_other_settings(settings, kept)
            # What runs from here (replay_log takes them too), so the live view announces the same.
            options = dataclasses.replace(options, settings=kept)
        # A map per step only for the outputs that draw them: a long log's replay stays lean.
        keep_maps = plot is not None or mcap is not None
        lens = None if camera is None else load_camera(camera)
        lens_bounds = None if camera is None else load_calibration_bounds(camera)
        watch = (
            live_replay(
                log, options, lens, live=live, host=live_host, port=live_port, rate=live_rate, wait=live_wait
            )
            if isinstance(log, RobotLog)
            else contextlib.nullcontext(None)
        )
        # The per-step CSV is streamed into a scratch file, moved onto its name once whole.
        steps = contextlib.nullcontext(None) if csv_target is None else placed(csv_target)
        with (
            steps as steps_path,
            watch as view,
            progress_bar(f"{safe_name(log.meta.name)}: frames", quiet=quiet) as advance,
        ):
            if lens is None:
                result = replay_log(
                    log, table, options, keep_maps=keep_maps, steps_csv=steps_path, progress=advance,
                    until=until, resume=saved, save_state=save_state is not None,
                    after_step=None if view is None else view.step,
                )  # fmt: skip
            else:
                assert isinstance(log, RobotLog)
                result, windows = replay_windows(
                    log, table, lens, options, margin=window_margin, keep_maps=keep_maps,
                    steps_csv=steps_path, progress=advance, until=until, resume=saved,
                    save_state=save_state is not None, after_step=None if view is None else view.step,
                    calibration_bounds=lens_bounds,
                )  # fmt: skip
            # Inside the outputs' block, so no empty steps CSV is left under its name.
            if resume is None and save_state is None:
                result.require_steps(until)
            elif saved is not None and save_state is None and not result.trace.time.size:
                bounded = "" if until is None else f" (--until {exact_text(until)})"
                raise fail(
                    f"--resume: expected a state with frames left after it, got {resume}, saved at "
                    f"{exact_text(saved.last_time)} s{bounded}: nothing is left to replay"
                )
            if mcap_target is not None and not result.steps:
                # A state saved before any frame has no step to export: refused before any
                # output is written (the MCAP writer refused it after the others were).
                early = (
                    "" if until is None else f" (--until {exact_text(until)} comes before the first frame)"
                )
                raise fail(f"--mcap: expected a replay of at least one frame to export, got none{early}")
    except AuraUmsError as exc:
        message = str(exc)
        option = _RESUMED_INPUTS.get(_resumed_input(message)) if resume is not None else None
        if option is not None:
            # The library names the input; the user gave it with an option.
            state = f"the state in {resume} (--resume)"
            said = message.removeprefix("resume: ").replace("the state", state, 1)
            message = f"{option}: {said}"
        elif resume is not None and message.startswith("resume: "):
            # the library names its argument; the user gave a file
            message = f"{resume}: --{message}"
        elif resume is not None and message.startswith(_STATE_PARTS):
            # the saved manager and blackboard disagree (an edited state): the file is at fault
            message = f"{resume}: --resume: {message}"
        elif message.startswith("until: "):
            message = f"--{message.replace('the resumed state', f'the state in {resume}', 1)}"
        elif message.startswith(_LOG_NAMED):  # the library names the log; the user gave its folder
            message = f"{log_dir}: {message}"
        raise fail(message) from None
    metrics = result.metrics() if windows is None else Metrics({**result.metrics(), **windows.metrics()})
    if windows is not None and camera is not None:
        _warn_unseen(windows, camera)
    _warn_unscored(log, log_dir, metrics)
    _warn_early(result.early_observations, result.start_time, log_dir)
    _warn_until_after_the_end(until, result, log_dir)
    _warn_own_bounds(result, _sensors_source(sensors, terrain), log_dir)
    for line in metrics.lines():
        console.print(line, highlight=False, markup=False)
    if json_target is not None:
        write_text(json_target, metrics.to_json())
    if state_target is not None and result.state is not None:
        write_text(state_target, result.state.to_json())
    if csv_target is not None:
        wrote(csv_target.path)  # streamed by replay_log, renamed onto it whole
    if windows_target is not None and windows is not None:
        write_text(windows_target, windows.to_csv())
    if plot_target is not None:
        _draw(result, plot_target)
    if mcap_target is not None:
        from aura_ums.cli._interop import write_replay_mcap_option

        write_replay_mcap_option(mcap_target, result, quiet=quiet, windows=windows)


def _warn_unseen(windows: WindowReport, camera: Path) -> None:
    """Say so when the camera saw none of the observations: its window figures are all n/a."""
    ours = windows.methods[0]
    asked = sum(row.method == ours for row in windows.rows)
    if asked and not windows.judged(ours):
        warn(
            f"--camera: expected some of the {asked} observations to fall in the image of {camera}, "
            "got none (a measured pixel outside the image, or behind the camera): the window figures "
            "are n/a; check its [mount] and [intrinsics]"
        )


def _warn_unscored(log: RobotLog | LogStream, log_dir: Path, metrics: Metrics) -> None:
    """Say so when a log with ground truth had none near any frame: its containment is n/a."""
    from aura_ums.logs import RobotLog

    if isinstance(log, RobotLog):
        gap = None if log.groundtruth is None else log.groundtruth.max_gap
    else:
        gap = None if log.truth_box is None else log.max_gap
    frames = metrics["steps"]
    if gap is not None and frames and not metrics["steps_with_truth"]:
        warn(
            f"{log_dir}: expected some frames between ground-truth rows at most --max-truth-gap "
            f"{gap:g} s apart, got none of the {frames} frames: the containment is n/a; if the ground "
            "truth is recorded more sparsely, pass a larger --max-truth-gap"
        )


def _warn_early(early: int, start: float, log_dir: Path) -> None:
    """Say so when observations came at or before the replay's start: no frame replays them."""
    if early:
        warn(
            f"{log_dir}: {early} observation{'s' if early != 1 else ''} at or before the replay's start "
            f"({start!r} s: the first motion, or the first ground truth when later) not replayed "
            "(observations_before_start)"
        )


def _warn_own_bounds(result: ReplayResult, sensors: Source | None, log_dir: Path) -> None:
    """Say so when observations' own bounds took precedence over a calibrated sensors file's."""
    if sensors is not None and result.own_bounds:
        warn(
            f"{log_dir}: {result.own_bounds} of the observations replayed carry their own bearing_error or "
            f"range_error (observations.csv), which take precedence over the calibrated bounds of "
            f"{sensors.path}"
        )


def _warn_until_after_the_end(until: float | None, result: ReplayResult, log_dir: Path) -> None:
    """Say so when ``--until`` is after the last frame: a value meant in ms replays the whole log.

    An ``--until`` at the last frame itself (a script stopping there) is no mistake: nothing is said.
    """
    if until is not None and not result.cut_short and result.trace.time.size:
        last = float(result.trace.time[-1])
        if until <= last:
            return
        warn(
            f"--until: {exact_text(until)} s is after the last frame of {log_dir} ({exact_text(last)} s): "
            "every frame was replayed (--until is in seconds, whatever the time unit of the log's files)"
        )


def _open(folder: Path, max_truth_gap: float | None) -> LogStream:
    """Open a log folder to replay it block by block (:func:`~aura_ums.logs.open_log`)."""
    from aura_ums.logs import open_log

    return open_log(folder) if max_truth_gap is None else open_log(folder, max_gap=max_truth_gap)


def _distinct(option: str, folders: Sequence[Path]) -> None:
    """Refuse (exit 2) a log folder given twice (by any path to it) where the logs are pooled."""
    seen: dict[Path, Path] = {}
    for folder in folders:
        first = seen.setdefault(resolved(folder), folder)
        if first is not folder:
            raise fail(f"{option}: expected distinct log folders, got {first} and {folder}, one folder")


def _draw(result: ReplayResult, target: Target) -> None:
    """Draw the replay figure into a scratch folder and move it onto ``target`` (named safely)."""
    import dataclasses

    from aura_ums.plot import draw_replay

    # The figure's file name comes from the log's name: drawn under the safe name only.
    meta = dataclasses.replace(result.log.meta, name=target.path.name.removesuffix(_FIGURE))
    named = dataclasses.replace(result, log=dataclasses.replace(result.log, meta=meta))
    with staged(Target(target.option, target.path.parent, folder=True)) as stage:
        draw_replay(named, stage)


@manager_options()
def compare(
    log_dir: Annotated[
        Path,
        typer.Argument(help="Log folder with groundtruth.csv.", parser=folder_argument("LOG_DIR")),
    ],
    terrain: _Terrain,
    sensors: _Sensors = None,
    calibration_logs: Annotated[
        list[Path] | None,
        typer.Option(
            "--noise-from",
            readable=False,
            metavar="<path>",
            help="Calibration logs whose observation errors give the filters' noise (default: the "
            "[noise] of the sensors file; never LOG_DIR itself).",
        ),
    ] = None,
    classes: _Classes = Classes.POINT,
    reverse: _ReverseOption = Reverse.ERROR,
    max_truth_gap: _MaxTruthGap = None,
    particles: Annotated[int, typer.Option("--particles", help="Particles of the particle filter.")] = 1000,
    seed: Annotated[int, typer.Option("--seed", help="Seed of the particle filter.")] = 0,
    settings: SettingOptions = NO_OPTIONS,
    metrics_json: Annotated[
        Path | None,
        output_file("--metrics-json", "metrics.json", "Write the table as JSON."),
    ] = None,
    overwrite: Overwrite = False,
    quiet: Quiet = False,
) -> None:
    """Print our map next to an EKF, a particle filter (99% regions) and a Codac box on the same log.

    The Codac row needs the codac extra (pip install aura-ums[codac]); without it, it is left out.
    """
    import numpy as np

    from aura_ums import Metrics
    from aura_ums.baselines import codac_available
    from aura_ums.campaign import LoadLog
    from aura_ums.errors import AuraUmsError
    from aura_ums.logs import compare_on_log, load_log, load_noise, observation_errors

    if not 1 <= particles <= _MOST_PARTICLES:
        # a billion particles was a MemoryError traceback
        raise fail(f"--particles: expected an integer in [1, {_MOST_PARTICLES}], got {particles}")
    check_seed(seed)
    _check_truth_gap(max_truth_gap)
    json_target = None if metrics_json is None else Target("--metrics-json", metrics_json)
    sources = [
        Source("LOG_DIR", log_dir, folder=True),
        Source("--terrain", terrain),
        _sensors_source(sensors, terrain),
        *(Source("--noise-from", p, folder=True) for p in calibration_logs or ()),
    ]
    check_outputs([json_target], sources, overwrite=overwrite)
    _distinct("--noise-from", calibration_logs or [])  # pooled: a folder given twice counts twice
    for source in calibration_logs or ():
        # The filters would be fitted to the errors they are judged on.
        if resolved(source) == resolved(log_dir):
            raise fail(
                f"--noise-from: expected calibration logs other than LOG_DIR, got {source}, which is LOG_DIR "
                f"{log_dir}: noise fitted on the log compared on flatters the filters"
            )
    try:
        log = LoadLog(max_truth_gap)(log_dir)
        if log.groundtruth is None:  # was named by the log's name alone, deep in the comparison
            raise fail(
                f"LOG_DIR: expected a log folder with groundtruth.csv to compare against, got {log_dir}"
            )
        table = _terrain_table(terrain, log.meta.terrain, log_dir)
        sensors_file = _sensors_file(sensors, terrain)
        options = _options(classes, sensors_file, settings.over(), reverse)
        if calibration_logs:
            bearing, ranges = observation_errors([load_log(p) for p in calibration_logs])
            if bearing.size < 2:
                raise fail(
                    "--noise-from: expected logs with observations inside their ground truth, got none"
                )
            bearing_sd = float(np.std(bearing))
            range_sd = float(np.std(ranges)) if ranges.size > 1 else 0.05
        else:
            # The filters' noise comes from the calibration, never from the log they are judged on.
            noise = load_noise(sensors_file) if sensors_file is not None else None
            if noise is None:
                where = (
                    "no sensors file" if sensors_file is None else f"{sensors_file} without a [noise] table"
                )
                raise fail(
                    "compare: expected the filters' noise from a sensors file written by "
                    f"`aura-ums calibrate` (--sensors) or from calibration logs (--noise-from), got {where}"
                )
            bearing_sd, range_sd = noise.bearing_sd, noise.range_sd_fraction
        with_codac = codac_available()
        if not with_codac:
            err_console.print(
                "note: no codac row: Codac is not installed (pip install aura-ums[codac])",
                markup=False,
                highlight=False,
            )
        with progress_bar(f"{safe_name(log.meta.name)}: frames x methods", quiet=quiet) as advance:
            rows = compare_on_log(
                log,
                table,
                options,
                bearing_sd=bearing_sd,
                range_sd_fraction=max(range_sd, 1e-3),
                rng=np.random.default_rng(seed),
                particles=particles,
                codac=with_codac,
                progress=advance,
            )
    except AuraUmsError as exc:
        message = str(exc)
        if message.startswith("particles: "):
            message = f"--{message}"
        elif message.startswith(_LOG_NAMED):  # the library names the log; the user gave its folder
            message = f"{log_dir}: {message}"
        raise fail(message) from None
    boxes = ", the Codac box" if with_codac else ""
    grid = Table(title=f"{log.meta.name}: Class {classes}, 99% regions of the filters{boxes}")
    for column in (
        "method",
        "truth inside",
        "median area m^2",
        "median wedge width rad",
        "RMSE m",
        "us/step",
        "rejected",
    ):
        grid.add_column(column, justify="right")
    for row in rows:
        grid.add_row(
            row.method,
            _figure(row.containment_rate, ".4f"),
            _figure(row.median_area_m2, ".4g"),
            _figure(row.median_wedge_width_rad, ".3f"),
            _figure(row.position_rmse_m, ".3f"),
            _figure(row.median_update_us, ".1f"),
            str(row.inconsistent_observations),
        )
    console.print(grid)
    if json_target is not None:
        table_metrics = Metrics(
            {
                "log": log.meta.name,
                "landmark_class": classes,
                "bearing_sd_rad": bearing_sd,
                "range_sd_fraction": range_sd,
                "methods": tuple(row.metrics() for row in rows),
            }
        )
        write_text(json_target, table_metrics.to_json())
