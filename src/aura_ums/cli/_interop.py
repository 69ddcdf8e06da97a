"""Interoperability: ``aura-ums import rosbag`` (a ROS bag to a log folder), ``--mcap`` and ``--live``.

The command functions are plain typer callbacks that the application registers
(``import_app.command("rosbag")(rosbag_command)``); the ``--mcap`` and ``--live`` helpers
are called by the commands that run a scenario or replay a log.
"""

from __future__ import annotations

import math
import stat
from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager, contextmanager, nullcontext, suppress
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, TypeVar

import typer

from aura_ums.cli._common import (
    NewLogFolder,
    Quiet,
    err_console,
    fail,
    folder_argument,
    none_or_float,
    output_file,
    print_log_summary,
    progress_bar,
)
from aura_ums.cli._outputs import Overwrite, Source, Target, check_outputs, placed, write_text, wrote
from aura_ums.export import LiveOptions

if TYPE_CHECKING:
    from aura_ums.camera import Camera
    from aura_ums.export import LiveReplay, LiveSimulation
    from aura_ums.logs import ReplayOptions, ReplayResult, RobotLog, WindowReport
    from aura_ums.sim import PerceptionMode, Scenario


#: The BAG argument of the ``import`` commands that read a ROS bag.
_Bag = Annotated[
    Path,
    typer.Argument(
        help="ROS bag: a rosbag2 folder (sqlite3 or MCAP) or a ROS 1 .bag file.",
        parser=folder_argument("BAG", "a ROS bag"),
    ),
]


def rosbag_command(
    bag: _Bag,
    out_dir: NewLogFolder,
    odom: Annotated[
        str,
        typer.Option(
            "--odom", help="Motion topic: nav_msgs/msg/Odometry, geometry_msgs/msg/TwistStamped or Twist."
        ),
    ],
    observations: Annotated[
        str,
        typer.Option(
            "--observations",
            help="Observation topic: geometry_msgs/msg/PointStamped, frame_id = landmark id, "
            "x = range m (0: bearing only), y = bearing rad, z = bearing error rad (0: default).",
        ),
    ],
    landmarks: Annotated[
        Path,
        typer.Option(
            "--landmarks", readable=False, help="landmarks.csv in the log format (id, x, y, ...; SI units)."
        ),
    ],
    groundtruth: Annotated[
        str | None,
        typer.Option(
            "--groundtruth",
            help="Ground-truth topic: nav_msgs/msg/Odometry, geometry_msgs/msg/PoseStamped or "
            "PoseWithCovarianceStamped.",
        ),
    ] = None,
    name: Annotated[str | None, typer.Option("--name", help="Log name (default: the bag's name).")] = None,
    overwrite: Overwrite = False,
    quiet: Quiet = False,
) -> None:
    """Import the ROS bag BAG as a log folder OUT_DIR (topics and conventions: docs/interop.md).

    Sensor bounds are the log defaults (meta.toml): edit them, or calibrate, before replaying.
    """
    import dataclasses

    from aura_ums._files import path_mode
    from aura_ums.errors import AuraUmsError
    from aura_ums.logs import LogMeta, read_rosbag, write_log

    target = Target("OUT_DIR", out_dir, folder=True)
    sources = [Source("BAG", bag, folder=stat.S_ISDIR(path_mode(bag))), Source("--landmarks", landmarks)]
    check_outputs([target], sources, overwrite=overwrite)
    try:
        meta = None if name is None else LogMeta(name, source=f"ROS bag {bag.name}")
    except AuraUmsError as exc:  # "LogMeta.name: expected ...": the user typed --name
        field, _, rest = str(exc).partition(": ")
        raise fail(f"--name: {rest}" if field == "LogMeta.name" else f"BAG {bag}: {exc}") from None
    try:
        log = read_rosbag(
            bag,
            odom_topic=odom,
            observations_topic=observations,
            landmarks=landmarks,
            meta=meta,
            groundtruth_topic=groundtruth,
        )
        with progress_bar(f"{out_dir}: files", quiet=quiet) as advance:
            folder = write_log(log, out_dir, overwrite=overwrite, progress=advance)
    except AuraUmsError as exc:
        # "odom_topic: expected ...": read_rosbag names its argument, the user typed the option.
        field, _, rest = str(exc).partition(": ")
        raise fail(f"{_TOPIC_OPTIONS[field]}: {rest}" if field in _TOPIC_OPTIONS else str(exc)) from None
    wrote(folder)
    print_log_summary(dataclasses.replace(log, path=folder))


def camera_info_command(
    bag: _Bag,
    topic: Annotated[
        str, typer.Option("--topic", help="sensor_msgs/msg/CameraInfo topic (its first message is read).")
    ],
    out: Annotated[Path, output_file("--out", "camera.toml", "Camera TOML to write (replay --camera).")],
    height: Annotated[
        float,
        typer.Option(
            "--height", help="Optical centre above the ground plane, m (a CameraInfo has no mount)."
        ),
    ],
    forward: Annotated[
        float, typer.Option("--forward", help="Optical centre ahead of the robot's reference point, m.")
    ] = 0.0,
    left: Annotated[
        float, typer.Option("--left", help="Optical centre left of the reference point, m.")
    ] = 0.0,
    pan_deg: Annotated[
        float, typer.Option("--pan-deg", help="Degrees, counter-clockwise (to the left) positive.")
    ] = 0.0,
    tilt_deg: Annotated[
        float, typer.Option("--tilt-deg", help="Degrees, positive when the camera looks below the horizon.")
    ] = 0.0,
    overwrite: Overwrite = False,
) -> None:
    """Write the camera of BAG's CameraInfo topic, on the mount given, as a camera TOML (docs/interop.md)."""
    from aura_ums._files import path_mode
    from aura_ums.camera import CameraMount, camera_to_toml
    from aura_ums.errors import AuraUmsError
    from aura_ums.logs import read_camera_info

    target = Target("--out", out)
    check_outputs([target], [Source("BAG", bag, folder=stat.S_ISDIR(path_mode(bag)))], overwrite=overwrite)
    try:
        mount = CameraMount(height, forward, left, math.radians(pan_deg), math.radians(tilt_deg))
    except AuraUmsError as exc:  # "CameraMount.tilt: expected ...": the user typed --tilt-deg
        field, _, rest = str(exc).partition(": ")
        option = _MOUNT_OPTIONS.get(field.removeprefix("CameraMount."))
        raise fail(f"{option}: {rest}" if option is not None else str(exc)) from None
    try:
        camera = read_camera_info(bag, topic, mount)
    except AuraUmsError as exc:
        field, _, rest = str(exc).partition(": ")
        raise fail(f"--topic: {rest}" if field == "topic" else str(exc)) from None
    write_text(target, camera_to_toml(camera))


#: CameraMount's fields, as ``import camera-info`` spells them.
_MOUNT_OPTIONS = {
    "height": "--height",
    "forward": "--forward",
    "left": "--left",
    "pan": "--pan-deg",
    "tilt": "--tilt-deg",
}


#: read_rosbag's topic arguments, as ``import rosbag`` spells them.
_TOPIC_OPTIONS = {
    "odom_topic": "--odom",
    "observations_topic": "--observations",
    "groundtruth_topic": "--groundtruth",
}


# --- MCAP export, for the commands that run or replay (``--mcap``) ---------------------------

MCAP_HELP = "Also write an MCAP file to open in Foxglove (needs aura-ums[foxglove]; topics: docs/interop.md)."


def write_simulation_mcap_option(
    target: Target, scenario: Scenario, seed: int, *, prune: bool, perception: PerceptionMode, quiet: bool
) -> Path:
    """Run the first Monte Carlo run of ``seed`` again, with its images, and write it as MCAP.

    The run is the one ``simulate --seed SEED`` runs first (the first child of
    ``default_rng(seed).spawn(...)``). Says where it wrote; on an aura-ums error prints
    ``error: ...`` and exits with code 2. The file is written whole or not at all.
    """
    import numpy as np

    from aura_ums.errors import AuraUmsError
    from aura_ums.export import write_simulation_mcap
    from aura_ums.sim import run_scenario

    (rng,) = np.random.default_rng(seed).spawn(1)
    try:
        result = run_scenario(scenario, rng, prune=prune, perception=perception, keep_images=True)
        with placed(target) as scratch, progress_bar(f"{target.path.name}: frames", quiet=quiet) as advance:
            write_simulation_mcap(scratch, scenario, result, progress=advance)
    except AuraUmsError as exc:
        raise fail(f"{target.option}: {exc}") from None
    wrote(target.path, f" (run 1 of seed {seed}; open it in Foxglove)")
    return target.path


def write_replay_mcap_option(
    target: Target, replay: ReplayResult, *, quiet: bool, windows: WindowReport | None = None
) -> Path:
    """Write a replay (and its windows) as MCAP, whole or not at all; says where, or exits with code 2."""
    from aura_ums.errors import AuraUmsError
    from aura_ums.export import write_replay_mcap

    try:
        with placed(target) as scratch, progress_bar(f"{target.path.name}: steps", quiet=quiet) as advance:
            write_replay_mcap(scratch, replay, windows=windows, progress=advance)
    except AuraUmsError as exc:
        raise fail(f"{target.option}: {exc}") from None
    wrote(target.path, " (open it in Foxglove)")
    return target.path


# --- live view, for the commands that run or replay (``--live``) ------------------------------

#: The defaults of ``--live-host``, ``--live-port`` and ``--live-rate``: the library's.
LIVE_DEFAULTS = LiveOptions()


def live_rules(live: bool) -> list[tuple[str, str, str, bool]]:
    """Return the rules of :func:`~aura_ums.cli._common.refuse_alone` for the options of ``--live``."""
    names = ("live_host", "live_port", "live_rate", "live_wait")
    return [(name, "--live", "no --live", live) for name in names]


#: ``--live``: stream to Foxglove while computing.
Live = Annotated[
    bool,
    typer.Option(
        "--live",
        help="Stream the map, truth, windows, image and metrics to Foxglove over WebSocket while "
        "computing (needs aura-ums[foxglove]); waits for Foxglove to connect first (docs/interop.md).",
    ),
]
#: ``--live-host``: the address the live server listens on.
LiveHost = Annotated[
    str,
    typer.Option("--live-host", help="Address the --live server listens on (0.0.0.0: every interface)."),
]
#: ``--live-port``: its port.
LivePort = Annotated[
    int, typer.Option("--live-port", help="Port of the --live server (Foxglove's default; 0: any free port).")
]
#: ``--live-rate``: its pace.
LiveRate = Annotated[
    float,
    typer.Option(
        "--live-rate",
        help="Pace of --live, times the run's own clock: 1 as recorded, 10 ten times faster, "
        "0 as fast as computed.",
    ),
]


def _wait(text: str) -> float | None:
    """Read ``--live-wait``: seconds >= 0, or ``none`` (the default: as long as it takes)."""
    try:
        seconds = none_or_float(text)
    except ValueError:
        seconds = math.nan
    if seconds is not None and not 0.0 <= seconds < math.inf:
        raise fail(f"--live-wait: expected a finite number of seconds >= 0 or none, got {text!r}")
    return seconds


#: ``--live-wait``: how long the live view waits for Foxglove before the run.
LiveWait = Annotated[
    float | None,
    typer.Option(
        "--live-wait",
        help="Seconds --live waits for Foxglove to connect before computing; past them it exits 2 "
        "having computed nothing (default none: as long as it takes).",
        parser=_wait,
        metavar="<seconds>",
    ),
]


def _live_options(host: str, port: int, rate: float) -> LiveOptions:
    from aura_ums.errors import InputError

    try:
        return LiveOptions(host, port, rate)
    except InputError as exc:  # "port: expected ...": named as the option given
        raise fail(f"--live-{exc}") from None


_View = TypeVar("_View", "LiveSimulation", "LiveReplay")


@contextmanager
def _serving(start: Callable[[], _View], what: str, wait: float | None) -> Iterator[_View]:
    """Start a live view, say where to connect, wait for a client; at the end, wait until it leaves.

    The computation runs inside; after it the server stays while a client is subscribed
    (it reads to the end and shows the last frame): a disconnect, or a Ctrl-C, stops it,
    and the command goes on to print and write its results.
    """
    from aura_ums.errors import AuraUmsError, MissingDependencyError

    try:
        view = start()
    except MissingDependencyError as exc:
        raise fail(f"--live: {exc}") from None
    except AuraUmsError as exc:  # a port in use, an address refused: "port: ...", "host: ..."
        raise fail(f"--live-{exc}") from None
    with view:
        waiting = "" if wait is None else f" for up to {wait:g} s"
        _note(
            f"live: serving on {view.url}; in Foxglove: Open connection, Foxglove WebSocket, {view.url} "
            f"(waiting{waiting} for it to subscribe; Ctrl-C to stop)"
        )
        if not view.wait_for_client(wait):
            raise fail(f"--live-wait: expected a Foxglove client at {view.url} within {wait:g} s, got none")
        _note(f"live: a client subscribed; streaming the {what}")
        yield view
        _note(
            f"live: streamed {view.published} {what}; the view stays until Foxglove disconnects "
            "(Ctrl-C to stop it)"
        )
        # a Ctrl-C here ends the view, not the command: its results are still to be printed and written
        with suppress(KeyboardInterrupt):
            view.wait_while_watched()
        _note("live: server stopped")


def _note(text: str) -> None:
    err_console.print(text, highlight=False, markup=False)


def live_simulation(
    scenario: Scenario, *, live: bool, host: str, port: int, rate: float, wait: float | None = None
) -> AbstractContextManager[LiveSimulation | None]:
    """With ``--live``, a live view of the scenario's runs (its ``frame`` is ``after_frame``); else None.

    The view starts and waits for a client when entered, and stops when left. Errors (the
    extra missing, the port in use) print ``error: --live...: ...`` and exit with code 2.
    """
    if not live:
        return nullcontext(None)
    from aura_ums.export import serve_simulation

    options = _live_options(host, port, rate)
    return _serving(lambda: serve_simulation(scenario, options), "frames", wait)


def live_replay(
    log: RobotLog,
    replay_options: ReplayOptions,
    camera: Camera | None,
    *,
    live: bool,
    host: str,
    port: int,
    rate: float,
    wait: float | None = None,
) -> AbstractContextManager[LiveReplay | None]:
    """With ``--live``, a live view of the log's replay (its ``step`` is ``after_step``); else None.

    As :func:`live_simulation`; with ``camera``, the windows are streamed too.
    """
    if not live:
        return nullcontext(None)
    from aura_ums.export import serve_replay

    options = _live_options(host, port, rate)
    return _serving(lambda: serve_replay(log, replay_options, camera=camera, options=options), "steps", wait)
