"""Stream a simulation or a log replay to Foxglove while it computes (the live view).

:func:`serve_simulation` and :func:`serve_replay` start a Foxglove WebSocket server
(``foxglove-sdk``) and return a view whose :meth:`LiveSimulation.frame` /
:meth:`LiveReplay.step` are the hooks of :func:`aura_ums.sim.run_scenario`
(``after_frame``) and :func:`aura_ums.logs.replay_log` / :func:`~aura_ums.logs.replay_windows`
(``after_step``). Every frame or step is published on the channels of the MCAP export,
built by the same code: the same topics, schemas and messages, so a Foxglove layout made
for a file works live and back.

The optional dependency is imported only when a server starts; importing this module
needs none.
"""

from __future__ import annotations

import ipaddress
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass
from types import TracebackType
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from aura_ums.errors import InputError
from aura_ums.export._mcap import require
from aura_ums.export._scene import seconds_to_nanoseconds

if TYPE_CHECKING:
    from typing import Self

    from aura_ums.camera import Camera
    from aura_ums.export._messages import ReplayChannels, SimulationChannels
    from aura_ums.export._server import LiveServer
    from aura_ums.logs import ReplayOptions, ReplayStep, RobotLog, WindowRow
    from aura_ums.sim import FrameRecord, Scenario

#: Where the live server listens by default: this machine only.
DEFAULT_HOST = "127.0.0.1"
#: A host name: dot-separated labels of letters, digits and inner hyphens (RFC 1123), 253 at most.
_LABEL = r"[A-Za-z0-9](?:[A-Za-z0-9-]{0,61}[A-Za-z0-9])?"
_HOST_NAME = re.compile(rf"(?=.{{1,253}}\.?$){_LABEL}(?:\.{_LABEL})*\.?")


def _is_host(text: str) -> bool:
    """Whether ``text`` is an IPv4 or IPv6 address or a host name (not a path, a URL or a port)."""
    try:
        ipaddress.ip_address(text)
    except ValueError:
        return _HOST_NAME.fullmatch(text) is not None
    return True


#: Foxglove's default port for a WebSocket connection.
DEFAULT_PORT = 8765
#: Nanoseconds on the live time line between one simulation run's last frame and the next run's first.
_RUN_GAP_NS = 1_000_000_000


@dataclass(frozen=True, slots=True)
class LiveOptions:
    """Where the live view listens and how fast it streams.

    Parameters
    ----------
    host : str
        Address to listen on: ``"127.0.0.1"`` (this machine only, the default) or
        ``"0.0.0.0"`` (every interface: other machines may connect).
    port : int
        Port, 0 to 65535 (default Foxglove's 8765; 0: any free port, read it from the view).
    rate : float
        Pace, times the run's own clock (>= 0): 1 streams a frame when its log time is due
        (a replay as fast as it was recorded), 10 ten times faster, 0 as fast as computed.

    Examples
    --------
    >>> LiveOptions().port, LiveOptions(rate=0).rate
    (8765, 0.0)
    >>> LiveOptions(port=70000)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: port: expected an integer from 0 to 65535, got 70000
    """

    host: str = DEFAULT_HOST
    port: int = DEFAULT_PORT
    rate: float = 1.0

    def __post_init__(self) -> None:
        if not isinstance(self.host, str) or not _is_host(self.host):
            raise InputError(
                f"host: expected an address such as 127.0.0.1 (or a host name such as localhost), "
                f"got {self.host!r}"
            )
        if isinstance(self.port, bool) or not isinstance(self.port, int) or not 0 <= self.port <= 65535:
            raise InputError(f"port: expected an integer from 0 to 65535, got {self.port!r}")
        rate = self.rate
        if isinstance(rate, bool) or not isinstance(rate, (int, float)) or not 0.0 <= rate < math.inf:
            raise InputError(f"rate: expected a finite number >= 0 (0: as fast as computed), got {rate!r}")
        object.__setattr__(self, "rate", float(rate))


class _LiveView:
    """What both views share: the server, waiting for a client, the static scene, closing."""

    def __init__(self, server: LiveServer) -> None:
        self._server = server
        self._started = False
        self._published = 0

    @property
    def published(self) -> int:
        """Frames or steps published so far."""
        return self._published

    @property
    def port(self) -> int:
        """The port the server listens on (the chosen one when asked for port 0)."""
        return self._server.port

    @property
    def url(self) -> str:
        """The address to open in Foxglove (*Open connection*, *Foxglove WebSocket*)."""
        return f"ws://{self._server.host}:{self.port}"

    def wait_for_client(self, timeout: float | None = None) -> bool:
        """Block until a client subscribes to a channel; False when ``timeout`` seconds pass first.

        Messages published before any client subscribes reach nobody: wait here before
        computing to watch a run from its start. ``None`` waits as long as it takes.
        """
        if timeout is not None and (not 0.0 <= timeout < math.inf):
            raise InputError(f"timeout: expected a finite number of seconds >= 0 or None, got {timeout!r}")
        return self._server.wait_for_client(timeout)

    def wait_while_watched(self, timeout: float | None = None) -> bool:
        """Block while a client is subscribed; False when ``timeout`` seconds pass first.

        :meth:`close` stops the server at once, dropping what a client has not read yet:
        wait here first to let it read to the end (and look at the last frame) until it
        disconnects. ``None`` waits as long as it takes.
        """
        if timeout is not None and (not 0.0 <= timeout < math.inf):
            raise InputError(f"timeout: expected a finite number of seconds >= 0 or None, got {timeout!r}")
        return self._server.wait_while_watched(timeout)

    def _scene(self, channels: SimulationChannels | ReplayChannels, ns: int) -> None:
        """Publish the static scene at the first message; again on a topic subscribed to later."""
        fresh = self._server.subscribed_since(channels.static_topics)
        if not self._started:
            channels.scene(ns)
            self._started = True
        elif fresh:
            channels.scene(ns, sorted(fresh))

    def close(self) -> None:
        """Stop the server at once; clients are disconnected. Closing twice does nothing."""
        self._server.stop()

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, traceback: TracebackType | None
    ) -> None:
        self.close()


class LiveSimulation(_LiveView):
    """A live view of simulation runs; made by :func:`serve_simulation`.

    Pass :meth:`frame` as ``run_scenario(..., after_frame=view.frame)``, for one run or for
    each run of a Monte Carlo in turn: a run whose first frame (index 0) follows another
    run's frames is placed on the time line one second after them (log times only grow),
    and its ``/metrics`` carry its run number.

    Examples
    --------
    >>> [name for name in vars(LiveSimulation) if not name.startswith("_")]    # its own; the rest shared
    ['run', 'frame']
    >>> sorted(name for name in vars(_LiveView) if not name.startswith("_"))
    ['close', 'port', 'published', 'url', 'wait_for_client', 'wait_while_watched']
    >>> serve_simulation("scenarios/paper_sidewalk.toml")     # a path, not a Scenario: no server starts
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: scenario: expected a Scenario, got str
    """

    def __init__(self, server: LiveServer, channels: SimulationChannels) -> None:
        super().__init__(server)
        self._channels = channels
        self._run = 0
        self._offset = 0
        self._last: int | None = None

    @property
    def run(self) -> int:
        """The run being streamed, 1 for the first (0 before any frame)."""
        return self._run

    def frame(self, record: FrameRecord, image: NDArray[np.uint8] | None = None) -> None:
        """Publish one frame (paced by the rate): maps, truth, image, windows, detections, metrics."""
        if record.index == 0 or self._run == 0:
            self._run += 1
            if self._last is not None:
                self._offset = self._last + _RUN_GAP_NS
        ns = self._offset + seconds_to_nanoseconds(record.time, "record.time")
        self._server.pace(ns)
        self._scene(self._channels, ns)
        self._channels.frame(record, image, ns, self._run)
        self._last = ns
        self._published += 1


class LiveReplay(_LiveView):
    """A live view of a log replay; made by :func:`serve_replay`.

    Pass :meth:`step` as ``after_step`` to :func:`aura_ums.logs.replay_log` or to
    :func:`aura_ums.logs.replay_windows` (which hands it each step's window rows too).

    Examples
    --------
    >>> [name for name in vars(LiveReplay) if not name.startswith("_")]    # its own; the rest shared
    ['step']
    >>> issubclass(LiveReplay, _LiveView), hasattr(LiveReplay, "__enter__")   # a context manager
    (True, True)
    >>> serve_replay("runs/log")                 # a folder, not a RobotLog: no server starts
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: log: expected a RobotLog, got str
    """

    def __init__(self, server: LiveServer, channels: ReplayChannels) -> None:
        super().__init__(server)
        self._channels = channels

    def step(self, step: ReplayStep, windows: Sequence[WindowRow] = ()) -> None:
        """Publish one step at the log's time (paced by the rate): map, truth, windows, metrics."""
        ns = seconds_to_nanoseconds(step.time, "step.time")
        self._server.pace(ns)
        self._scene(self._channels, ns)
        self._channels.step(self._published, step, ns, windows)
        self._published += 1


def _options(options: LiveOptions | None) -> LiveOptions:
    chosen = LiveOptions() if options is None else options
    if not isinstance(chosen, LiveOptions):
        raise InputError(f"options: expected LiveOptions or None, got {type(chosen).__name__}")
    return chosen


def serve_simulation(scenario: Scenario, options: LiveOptions | None = None) -> LiveSimulation:
    """Start a live view of a scenario's runs and return it (a context manager that stops it).

    The channels are those of :func:`aura_ums.export.write_simulation_mcap`, images
    included (``/map/slices`` when the scenario's settings slice the map).

    Parameters
    ----------
    scenario : Scenario
        The scenario that will run.
    options : LiveOptions or None
        Host, port and rate; default :class:`LiveOptions`.

    Returns
    -------
    LiveSimulation

    Raises
    ------
    MissingDependencyError
        When ``foxglove-sdk`` is not installed (``pip install aura-ums[foxglove]``).
    InputError
        For a port in use (``port: ...``) or an address the server cannot listen on
        (``host: ...``).

    Examples
    --------
    >>> import pathlib
    >>> from aura_ums.sim import Scenario, run_scenario
    >>> scenario = Scenario.from_toml(pathlib.Path("scenarios/paper_sidewalk.toml"))
    >>> with serve_simulation(scenario, LiveOptions(port=0, rate=0)) as view:
    ...     view.wait_for_client(timeout=0)           # nobody connected: do not wait
    ...     result = run_scenario(scenario, np.random.default_rng(1), after_frame=view.frame)
    ...     view.published == len(result.records), view.url.startswith("ws://127.0.0.1:")
    False
    (True, True)
    """
    from aura_ums.sim import Scenario

    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario: expected a Scenario, got {type(scenario).__name__}")
    chosen = _options(options)
    require("foxglove.websocket", "the live view")
    from aura_ums.export._messages import SimulationChannels
    from aura_ums.export._server import LiveServer

    server = LiveServer(f"aura-ums simulate {scenario.name}", chosen.host, chosen.port, chosen.rate)
    try:
        sliced = scenario.settings.slice_width is not None
        channels = SimulationChannels(server.context, scenario, images=True, sliced=sliced)
    except BaseException:
        server.stop()
        raise
    return LiveSimulation(server, channels)


def serve_replay(
    log: RobotLog,
    replay_options: ReplayOptions | None = None,
    *,
    camera: Camera | None = None,
    options: LiveOptions | None = None,
) -> LiveReplay:
    """Start a live view of a log's replay and return it (a context manager that stops it).

    The channels are those of :func:`aura_ums.export.write_replay_mcap` for a replay of
    ``log`` with ``replay_options``: the arena's meadows and landmarks, the map, ``/truth``
    when the log has ground truth, ``/map/slices`` when the settings slice the map, and
    with ``camera`` the windows on a blank image of its size.

    Parameters
    ----------
    log : RobotLog
        The log that will be replayed.
    replay_options : ReplayOptions or None
        The replay's options (its landmark class and arena margin draw the arena).
    camera : Camera or None
        The camera of :func:`aura_ums.logs.replay_windows`, when the windows are judged.
    options : LiveOptions or None
        Host, port and rate; default :class:`LiveOptions`.

    Returns
    -------
    LiveReplay

    Raises
    ------
    MissingDependencyError
        When ``foxglove-sdk`` is not installed.
    InputError
        For bad arguments, a port in use or an address the server cannot listen on.

    Examples
    --------
    >>> from aura_ums.logs import replay_log, synthetic_log
    >>> from aura_ums.uncertainty import TerrainTable
    >>> log = synthetic_log(np.random.default_rng(3), duration=5.0)
    >>> table = TerrainTable({"floor": TerrainTable.default()["tile"]})
    >>> with serve_replay(log, options=LiveOptions(port=0, rate=0)) as view:
    ...     result = replay_log(log, table, after_step=view.step)
    ...     view.published == len(result.trace)
    True
    >>> serve_replay(log, camera="front")
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: camera: expected a Camera or None, got str
    """
    from aura_ums.camera import Camera
    from aura_ums.logs import ReplayOptions, RobotLog, log_meadow_map

    if not isinstance(log, RobotLog):
        raise InputError(f"log: expected a RobotLog, got {type(log).__name__}")
    chosen_replay = ReplayOptions() if replay_options is None else replay_options
    if not isinstance(chosen_replay, ReplayOptions):
        raise InputError(
            f"replay_options: expected ReplayOptions or None, got {type(chosen_replay).__name__}"
        )
    if camera is not None and not isinstance(camera, Camera):
        raise InputError(f"camera: expected a Camera or None, got {type(camera).__name__}")
    chosen = _options(options)
    require("foxglove.websocket", "the live view")
    from aura_ums.export._messages import ReplayChannels
    from aura_ums.export._server import LiveServer

    world = log_meadow_map(log, chosen_replay.landmark_class, margin=chosen_replay.arena_margin)
    size = None if camera is None else (camera.intrinsics.width, camera.intrinsics.height)
    server = LiveServer(f"aura-ums replay {log.meta.name}", chosen.host, chosen.port, chosen.rate)
    try:
        channels = ReplayChannels(
            server.context,
            log,
            world,
            truth=log.groundtruth is not None,
            sliced=chosen_replay.settings.slice_width is not None,
            image_size=size,
        )
    except BaseException:
        server.stop()
        raise
    return LiveReplay(server, channels)
