"""Interoperability commands: ``aura-ums import rosbag`` (a ROS bag to a log folder) and ``--mcap``.

The command functions are plain typer callbacks that the application registers
(``import_app.command("rosbag")(rosbag_command)``); the ``--mcap`` helpers are called by
the commands that run a scenario or replay a log.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from aura_ums.cli._common import Quiet, fail, print_log_summary, progress_bar
from aura_ums.cli._outputs import Overwrite, Source, Target, check_outputs, resolved, wrote

if TYPE_CHECKING:
    from aura_ums.logs import ReplayResult
    from aura_ums.sim import Scenario


def rosbag_command(
    bag: Annotated[
        Path, typer.Argument(help="ROS bag: a rosbag2 folder (sqlite3 or MCAP) or a ROS 1 .bag file.")
    ],
    out_dir: Annotated[Path, typer.Argument(help="Log folder to write.")],
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
        Path, typer.Option("--landmarks", help="landmarks.csv in the log format (id, x, y, ...; SI units).")
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

    from aura_ums.errors import AuraUmsError
    from aura_ums.logs import LogMeta, read_rosbag, write_log

    target = Target("OUT_DIR", out_dir, folder=True)
    sources = [Source("BAG", bag, folder=bag.is_dir()), Source("--landmarks", landmarks)]
    check_outputs([target], sources, overwrite=overwrite)
    try:
        meta = None if name is None else LogMeta(name, source=f"ROS bag {bag.name}")
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
        raise fail(str(exc)) from None
    wrote(folder)
    print_log_summary(dataclasses.replace(log, path=folder))


# --- MCAP export, for the commands that run or replay (``--mcap``) ---------------------------

MCAP_HELP = "Also write an MCAP file to open in Foxglove (needs aura-ums[foxglove]; topics: docs/interop.md)."


def write_simulation_mcap_option(
    target: Target, scenario: Scenario, seed: int, *, prune: bool, quiet: bool
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
        result = run_scenario(scenario, rng, prune=prune, keep_images=True)
        with progress_bar(f"{target.path.name}: frames", quiet=quiet) as advance:
            write_simulation_mcap(resolved(target.path), scenario, result, progress=advance)
    except AuraUmsError as exc:
        raise fail(f"{target.option}: {exc}") from None
    wrote(target.path, f" (run 1 of seed {seed}; open it in Foxglove)")
    return target.path


def write_replay_mcap_option(target: Target, replay: ReplayResult, *, quiet: bool) -> Path:
    """Write a replay as MCAP (whole or not at all); says where, or ``error: ...`` and exits with code 2."""
    from aura_ums.errors import AuraUmsError
    from aura_ums.export import write_replay_mcap

    try:
        with progress_bar(f"{target.path.name}: steps", quiet=quiet) as advance:
            write_replay_mcap(resolved(target.path), replay, progress=advance)
    except AuraUmsError as exc:
        raise fail(f"{target.option}: {exc}") from None
    wrote(target.path, " (open it in Foxglove)")
    return target.path
