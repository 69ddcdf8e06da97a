"""The public exporters: simulation runs and log replays to MCAP, and listing an MCAP's channels.

The optional dependencies (``foxglove-sdk`` to write, ``mcap`` to read) are imported only
when a function needs them; without them the function raises
:class:`~aura_ums.errors.MissingDependencyError`.
"""

from __future__ import annotations

import importlib
import struct
from collections.abc import Callable
from pathlib import Path
from typing import IO, TYPE_CHECKING

from aura_ums.errors import FileFormatError, InputError, MissingDependencyError

if TYPE_CHECKING:
    from aura_ums.export._types import ReplayLike
    from aura_ums.logs import WindowReport
    from aura_ums.sim import RunResult, Scenario

_EXTRA = "install aura-ums[foxglove]"


def require(module: str, purpose: str) -> None:
    """Import ``module`` or raise :class:`MissingDependencyError` naming the extra to install."""
    try:
        importlib.import_module(module)
    except ImportError as exc:
        package = module.split(".")[0].replace("foxglove", "foxglove-sdk")
        raise MissingDependencyError(
            f"{purpose} needs the optional package {package!r} (import of {module} failed: {exc}); {_EXTRA}"
        ) from exc


def _path(path: str | Path, name: str = "path") -> Path:
    if not isinstance(path, (str, Path)) or str(path) == "":
        raise InputError(f"{name}: expected a file path, got {path!r}")
    return Path(path)


def write_simulation_mcap(
    path: str | Path,
    scenario: Scenario,
    result: RunResult,
    *,
    camera_topic_images: bool = True,
    progress: Callable[[int, int], None] | None = None,
) -> Path:
    """Write a simulation run to an MCAP file that Foxglove opens, and return its path.

    Channels (all in frame ``"world"``, metres, unless said otherwise; the topics and schemas
    are listed in ``docs/interop.md``):

    - ``/meadows`` (``foxglove.SceneUpdate``, once): the meadows, filled by terrain;
    - ``/landmarks`` (``foxglove.SceneUpdate``, once): Class I cylinders, Class II spheres,
      Class III ground lines; landmarks the robot does not use are translucent;
    - ``/map/polygon``, ``/map/grown`` (``foxglove.SceneUpdate``, per frame): the map's
      polygon after the frame (red when lost) and before its reductions, as closed lines;
    - ``/map/wedge`` (``foxglove.SceneUpdate``, per frame): the heading wedge as a fan from
      the map's centre;
    - ``/map/slices`` (``foxglove.SceneUpdate``, per frame, only when the maps are
      heading-sliced): each slice's polygon, stacked above the ground in heading order and
      coloured by heading;
    - ``/map/center``, ``/truth`` (``foxglove.SceneUpdate``, per frame): arrows at the map's
      centre (along the wedge's centre) and at the true pose;
    - ``/camera/image`` (``foxglove.RawImage`` ``mono8``, per frame with an image, frame
      ``"camera"``) when ``camera_topic_images``;
    - ``/camera/annotations`` (``foxglove.ImageAnnotations``, per frame): each expectation
      window as a rectangle labelled with its landmark id, green when found, red when not,
      and the detections' line segments;
    - ``/metrics`` (JSON, schema ``aura_ums.SimulationMetrics``, per frame): ``run`` (1),
      ``frame``, ``time``, ``area_m2``,
      ``area_before_m2``, ``wedge_width_rad``, ``inside`` (0/1), ``accepted``, ``rejected``,
      ``windows``, ``found``, ``lost`` (0/1), ``frame_ms``: plot them in Foxglove's Plot panel.

    Log times (and message timestamps) are the frames' times, in nanoseconds.

    The file is written under a hidden scratch name in its folder and renamed onto
    ``path`` when complete: an error, a ``KeyboardInterrupt`` or a killed process leaves
    the old file (or none), never a part of one under ``path``.

    Parameters
    ----------
    path : str or Path
        The file to write (``.mcap``); its folder is created, an existing file replaced.
    scenario : Scenario
        The scenario that was run (its meadow map, used landmarks and camera size).
    result : RunResult
        The run, from :func:`aura_ums.sim.run_scenario` (with ``keep_images=True`` for images;
        after a resume the images are those of the last call, i.e. of the last frames).
    camera_topic_images : bool
        Write ``/camera/image`` (needs ``result.images``).
    progress : callable or None
        Called as ``progress(done, total)`` after each frame written (``total`` frames);
        nothing is printed here.

    Returns
    -------
    Path

    Raises
    ------
    MissingDependencyError
        When ``foxglove-sdk`` is not installed (``pip install aura-ums[foxglove]``).
    InputError
        For a run without frames, or without images when ``camera_topic_images``.
    FileFormatError
        When the file cannot be written.

    Examples
    --------
    >>> import pathlib, tempfile, numpy as np
    >>> from aura_ums.sim import Scenario, run_scenario
    >>> scenario = Scenario.from_toml(pathlib.Path("scenarios/paper_sidewalk.toml"))
    >>> result = run_scenario(scenario, np.random.default_rng(1), keep_images=True)
    >>> out = write_simulation_mcap(pathlib.Path(tempfile.mkdtemp()) / "run.mcap", scenario, result)
    >>> mcap_channels(out)["/camera/image"]
    'foxglove.RawImage'
    >>> blind = run_scenario(scenario, np.random.default_rng(1))      # no images kept
    >>> write_simulation_mcap(out, scenario, blind)                   # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: result.images: expected the frames' images (...), got none; ...
    """
    from aura_ums.sim import RunResult, Scenario

    target = _path(path)
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario: expected a Scenario, got {type(scenario).__name__}")
    if not isinstance(result, RunResult):
        raise InputError(f"result: expected a RunResult, got {type(result).__name__}")
    if not isinstance(camera_topic_images, bool):
        raise InputError(f"camera_topic_images: expected a bool, got {camera_topic_images!r}")
    _check_progress(progress)
    require("foxglove.channels", "writing MCAP")
    from aura_ums.export._writer import write_simulation

    return write_simulation(target, scenario, result, camera_topic_images, progress)


def _check_progress(progress: object) -> None:
    if progress is not None and not callable(progress):
        raise InputError(f"progress: expected a callable or None, got {type(progress).__name__}")


def write_replay_mcap(
    path: str | Path,
    replay: ReplayLike,
    *,
    windows: WindowReport | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> Path:
    """Write a log replay to an MCAP file that Foxglove opens, and return its path.

    Channels (frame ``"world"``): ``/landmarks`` (once, the log's landmarks: cylinders
    from ``z_bottom`` to ``z_top``, spheres when they have no height; for a
    :class:`~aura_ums.logs.ReplayResult`, ``/meadows`` too, the replay's arena),
    ``/map/polygon``, ``/map/wedge``, ``/map/center`` (per step, as for
    :func:`write_simulation_mcap`; ``/map/slices`` when the maps are sliced), ``/truth``
    (per step, only when the log has ground truth; a step without it deletes the arrow) and
    ``/metrics`` (JSON, schema ``aura_ums.ReplayMetrics``: ``area_m2``,
    ``wedge_width_rad``, ``inside`` (0/1, null without truth), ``accepted``, ``rejected``,
    ``lost``, ``update_us``, ...). With ``windows``, ``/camera/annotations`` per step draws
    each observation's windows (ours green when the measured pixel fell inside, red when
    not; the EKF's box orange, the disk model's violet) and the measured pixels, over a
    blank ``/camera/image`` of the camera's size (logs carry no images). Log times are the
    log's times in nanoseconds (>= 0).

    Parameters
    ----------
    path : str or Path
        The file to write; its folder is created, an existing file replaced, atomically
        (as for :func:`write_simulation_mcap`).
    replay : aura_ums.logs.ReplayResult
        The replay: ``replay.log.meta.name``, ``replay.log.landmarks`` and ``replay.steps``
        are read (each step's ``time``, ``map``, ``truth``, ``inside``, ``accepted``,
        ``rejected``, ``update_us`` and ``state``).
    windows : aura_ums.logs.WindowReport or None
        The windows of the same replay (:func:`aura_ums.logs.replay_windows`), drawn on
        the camera topics at their steps' times.
    progress : callable or None
        Called as ``progress(done, total)`` after each step written.

    Returns
    -------
    Path

    Raises
    ------
    MissingDependencyError
        When ``foxglove-sdk`` is not installed.
    InputError
        For a replay without steps, or with a negative time, or ``windows`` that are not a
        :class:`~aura_ums.logs.WindowReport`.
    FileFormatError
        When the file cannot be written.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from types import SimpleNamespace as Fake
    >>> from aura_ums import Pose, SpatialUncertaintyMap
    >>> from aura_ums.manager import ManagerState
    >>> start = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.5, 0.1)
    >>> step = Fake(time=0.0, map=start, truth=None, inside=None, accepted=0, rejected=0,
    ...             update_us=1.0, state=ManagerState.NOMINAL)
    >>> replay = Fake(log=Fake(meta=Fake(name="demo"), landmarks=()), steps=(step,))
    >>> out = write_replay_mcap(pathlib.Path(tempfile.mkdtemp()) / "replay.mcap", replay)
    >>> sorted(mcap_channels(out))                      # no ground truth: no /truth
    ['/landmarks', '/map/center', '/map/polygon', '/map/wedge', '/metrics']
    >>> write_replay_mcap(out, Fake(log=replay.log, steps=()))
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: replay.steps: expected at least one step, got none
    """
    target = _path(path)
    for name in ("log", "steps"):
        if not hasattr(replay, name):
            raise InputError(f"replay: expected a ReplayResult (with .{name}), got {type(replay).__name__}")
    _check_progress(progress)
    if windows is not None:
        from aura_ums.logs import WindowReport

        if not isinstance(windows, WindowReport):
            raise InputError(f"windows: expected a WindowReport or None, got {type(windows).__name__}")
    require("foxglove.channels", "writing MCAP")
    from aura_ums.export._writer import write_replay

    return write_replay(target, replay, windows, progress)


def mcap_channels(path: str | Path) -> dict[str, str]:
    """Return the channels of an MCAP file: topic -> schema name (``""`` when schemaless).

    Read with the ``mcap`` package: from the summary section when the file has one, else by
    scanning its records. Topics come in channel-id order.

    Raises
    ------
    MissingDependencyError
        When ``mcap`` is not installed (``pip install aura-ums[foxglove]``).
    FileFormatError
        When the file is missing or not an MCAP file.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from mcap.writer import Writer                  # the foxglove extra's MCAP writer
    >>> good = pathlib.Path(tempfile.mkdtemp()) / "one.mcap"
    >>> with good.open("wb") as stream:
    ...     writer = Writer(stream)
    ...     writer.start()
    ...     schema = writer.register_schema("demo.Point", "jsonschema", b"{}")
    ...     _ = writer.register_channel("/point", "json", schema)
    ...     writer.finish()
    >>> mcap_channels(good)
    {'/point': 'demo.Point'}
    >>> bad = pathlib.Path(tempfile.mkdtemp()) / "not.mcap"
    >>> _ = bad.write_bytes(b"hello")
    >>> mcap_channels(bad)                       # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: ...not.mcap: expected an MCAP file, got ...
    """
    source = _path(path)
    require("mcap.reader", "reading MCAP")
    from mcap.exceptions import McapError
    from mcap.reader import make_reader

    try:
        with source.open("rb") as stream:
            summary = make_reader(stream).get_summary()
            if summary is not None:
                names = {i: s.name for i, s in summary.schemas.items()}
                return {c.topic: names.get(c.schema_id, "") for _, c in sorted(summary.channels.items())}
            stream.seek(0)
            return _scan(stream)
    except FileNotFoundError:
        raise FileFormatError(str(source), "", "expected an MCAP file, got no such file") from None
    except (McapError, OSError, ValueError, EOFError, struct.error) as exc:
        raise FileFormatError(
            str(source), "", f"expected an MCAP file, got {type(exc).__name__}: {exc}"
        ) from exc


def _scan(stream: IO[bytes]) -> dict[str, str]:
    """Channels of an MCAP file without a summary section, from its records."""
    from mcap.records import Channel, Schema
    from mcap.stream_reader import StreamReader

    names: dict[int, str] = {}
    channels: dict[int, tuple[str, int]] = {}
    for record in StreamReader(stream).records:
        if isinstance(record, Schema):
            names[record.id] = record.name
        elif isinstance(record, Channel):
            channels[record.id] = (record.topic, record.schema_id)
    return {topic: names.get(schema, "") for _, (topic, schema) in sorted(channels.items())}
