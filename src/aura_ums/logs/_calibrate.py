"""Calibration from logs with ground truth: terrain statistics, motion delay and scales, sensor bounds.

The paper gathers its growth statistics from the robot's own runs ("Uncertainty Map Growth
Statistics"). Here the runs are logs with ground truth: the recorded motion, cut into moves,
is compared with the true motion accumulated over the horizons a map goes without a
correction (1 to 30 s), and the observations with the bearings and ranges the true poses
imply.

Why horizons, not single moves: the map's bound over a span is the sum of its moves'
bounds, while the true errors of consecutive moves largely cancel (timing jitter, a lagging
controller). A per-move worst case, summed over a hundred moves, bounds an error that
never happens; the bound is fitted where it is used instead, and checked there
(:class:`HorizonCheck`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple, TypeVar

import numpy as np
from numpy.typing import NDArray

from aura_ums._files import Fields, as_path, key_path, load_toml
from aura_ums._validate import (
    ANGLE_ERROR,
    DELAY,
    LENGTH,
    ODOMETRY_SCALE,
    SIGMAS,
    Range,
    exact_text,
    finite_float,
    items_of,
    positive_float,
    sequence_of,
)
from aura_ums.errors import InputError
from aura_ums.logs._io import COMMANDS, GROUNDTRUTH, ODOMETRY
from aura_ums.logs._log import RobotLog
from aura_ums.uncertainty import (
    Composite,
    Pose,
    SpatialUncertaintyMap,
    TerrainStats,
    TerrainTable,
    TurnAndRun,
    grow_from_anchor,
)

_SENSOR_KEYS = ("bearing_error", "range_error", "range_fraction_low", "range_fraction_high")
_MOTION_KEYS = ("delay_s", "run_scale", "turn_scale")
_NOISE_KEYS = ("bearing_sd", "range_sd_fraction")
#: The physical range of every number of a sensor calibration file (docs/formats.md lists them).
KEY_RANGES: dict[str, Range] = {
    "delay_s": DELAY,
    "run_scale": ODOMETRY_SCALE,
    "turn_scale": ODOMETRY_SCALE,
    "bearing_error": ANGLE_ERROR,
    "range_error": LENGTH,
    # The true range is at most (1 + low) times the measured one: a sensor that read a landmark
    # 7 m away at 0.3 m needs a low fraction of 22 (at most 100); it is at least (1 - high)
    # times it, so high < 1.
    "range_fraction_low": Range(0.0, 100.0),
    "range_fraction_high": Range(0.0, 1.0, high_open=True),
    "bearing_sd": ANGLE_ERROR,
    "range_sd_fraction": Range(0.0, 10.0, low_open=True),
}
#: The largest low range fraction (the true range up to 101 times the measured one).
_FARTHEST = KEY_RANGES["range_fraction_low"].high
#: The largest high range fraction a calibration writes: below 1, the true range above 0.
_NEAREST = 0.95
_KIND = "aura-ums/sensor-calibration"
#: How the sensors file's header names the growth the terrain statistics are for.
_GROWTH_WORDS = {False: "move by move", True: "from an anchor (replay --anchor-growth)"}
#: The sensors file's ``growth``: which growth the terrain statistics written with it are for.
_GROWTH_KEYS = {False: "move", True: "anchor"}
_T = TypeVar("_T")


@dataclass(frozen=True, slots=True)
class SensorBounds:
    """Bounds on a landmark sensor's errors, used to turn measurements into bounded observations.

    The bearing error is within ``+-bearing_error``. The range error, relative to the
    *measured* range ``m`` (``e = (m - true) / m``), is within ``[-range_fraction_low,
    range_fraction_high]``, widened by ``range_error`` metres either side: the true range
    lies in ``[m (1 - range_fraction_high) - range_error, m (1 + range_fraction_low) +
    range_error]``. Real range sensors are often biased (they read long more often than
    short), hence two fractions.

    Parameters
    ----------
    bearing_error : float
        Radians, > 0.
    range_error : float
        Metres, >= 0.
    range_fraction_low : float
        Fraction of the measured range the true range may exceed it by, in [0, 100].
    range_fraction_high : float
        Fraction of the measured range the true range may fall short of it by, in [0, 1).

    Raises
    ------
    InputError
        For a value out of range.

    Examples
    --------
    >>> bounds = SensorBounds(0.05, 0.02, 0.1, 0.05)
    >>> bounds.range_interval(4.0)
    (3.78, 4.42)
    >>> SensorBounds(0.05).range_interval(0.01)       # never below zero
    (0.01, 0.01)
    >>> SensorBounds(0.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: SensorBounds.bearing_error: expected a positive number, got 0.0
    """

    bearing_error: float
    range_error: float = 0.0
    range_fraction_low: float = 0.0
    range_fraction_high: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(
            self, "bearing_error", positive_float(self.bearing_error, "SensorBounds.bearing_error")
        )
        value = finite_float(self.range_error, "SensorBounds.range_error")
        if value < 0.0:
            raise InputError(f"SensorBounds.range_error: expected a number >= 0, got {value!r}")
        object.__setattr__(self, "range_error", value)
        for name in ("range_fraction_low", "range_fraction_high"):
            object.__setattr__(
                self, name, KEY_RANGES[name].check(getattr(self, name), f"SensorBounds.{name}")
            )

    def range_interval(self, measured: float) -> tuple[float, float]:
        """Return ``(range_min, range_max)``, metres, of the true range for a measured range (m)."""
        low = max(0.0, measured * (1.0 - self.range_fraction_high) - self.range_error)
        high = measured * (1.0 + self.range_fraction_low) + self.range_error
        return round(low, 12), round(high, 12)

    def widened(self, factor: float) -> SensorBounds:
        """Return these bounds times ``factor`` (>= 1), the low fraction capped at 100, the high at 0.95."""
        return SensorBounds(
            self.bearing_error * factor,
            self.range_error * factor,
            min(self.range_fraction_low * factor, _FARTHEST),
            min(self.range_fraction_high * factor, _NEAREST),
        )


@dataclass(frozen=True, slots=True)
class MotionCalibration:
    """How a log's recorded motion relates to the robot's actual motion.

    Parameters
    ----------
    delay_s : float
        Seconds, >= 0: the motion recorded at ``t`` happens at ``t + delay_s``.
    run_scale, turn_scale : float
        Factors, > 0, that make recorded runs and turns bounds of the actual ones (the
        growth model never moves farther or turns more than commanded).

    Examples
    --------
    >>> MotionCalibration()
    MotionCalibration(delay_s=0.0, run_scale=1.0, turn_scale=1.0)
    >>> MotionCalibration(delay_s=0.1, run_scale=1.05).run_scale
    1.05
    >>> MotionCalibration(delay_s=-0.1)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: MotionCalibration.delay_s: expected a number >= 0, got -0.1
    """

    delay_s: float = 0.0
    run_scale: float = 1.0
    turn_scale: float = 1.0

    def __post_init__(self) -> None:
        delay = finite_float(self.delay_s, "MotionCalibration.delay_s")
        if delay < 0.0:
            raise InputError(f"MotionCalibration.delay_s: expected a number >= 0, got {delay!r}")
        object.__setattr__(self, "delay_s", delay)
        for name in ("run_scale", "turn_scale"):
            object.__setattr__(self, name, positive_float(getattr(self, name), f"MotionCalibration.{name}"))


@dataclass(frozen=True, slots=True)
class FilterNoise:
    """Measurement noise for probabilistic filters (EKF, particle filter), from calibration logs.

    Parameters
    ----------
    bearing_sd : float
        Standard deviation of the bearing error, radians, > 0.
    range_sd_fraction : float
        Standard deviation of the range error as a fraction of the range, > 0.

    Examples
    --------
    >>> FilterNoise(0.02, 0.05).bearing_sd
    0.02
    >>> FilterNoise(0.0, 0.05)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: FilterNoise.bearing_sd: expected a positive number, got 0.0
    """

    bearing_sd: float
    range_sd_fraction: float

    def __post_init__(self) -> None:
        for name in _NOISE_KEYS:
            object.__setattr__(self, name, positive_float(getattr(self, name), f"FilterNoise.{name}"))


@dataclass(frozen=True, slots=True)
class Calibration:
    """The outcome of :func:`calibrate_logs`.

    Attributes
    ----------
    terrain : str
        Name of the calibrated terrain (the logs' ``meta.terrain``).
    stats : TerrainStats
        Growth statistics of that terrain, for the motion after :attr:`motion`.
    motion : MotionCalibration
        Delay and scales of the recorded motion.
    working : SensorBounds
        Sensor bounds at the calibration quantile: the working map's.
    envelope : SensorBounds
        Bounds covering every calibration error, widened by the margin: the envelope's.
    noise : FilterNoise
        Standard deviations of the observation errors, for filters compared with the map.
    quantile : float
        The quantile the motion and working bounds cover.
    move : float
        Seconds per move of the motion fit.
    horizons : tuple of float
        Seconds: the spans over which the motion bound was fitted and checked.
    checks : tuple of HorizonCheck
        How the growth bound holds over each horizon on the calibration logs.
    motion_windows, observations : int
        Samples the fit used (moving windows over all horizons; observations).
    anchor : bool
        Whether :attr:`stats` are for growth from an anchor (``ManagerSettings.anchor_growth``)
        rather than move by move.

    Examples
    --------
    >>> from aura_ums.logs import synthetic_log
    >>> log = synthetic_log(np.random.default_rng(0), duration=10.0)
    >>> calibration = calibrate_logs([log], horizons=(1.0, 2.0, 30.0))
    >>> calibration.terrain, list(calibration.terrain_table()), calibration.observations
    ('floor', ['floor'], 35)
    >>> calibration.report().splitlines()[0]
    'horizon s  windows  inside  heading q0.99 rad  bound rad  position q0.99 m  bound m'
    >>> calibration.report().splitlines()[-1]       # longer than the log: no window, NaN figures
    '       30        0     nan             nan        nan            nan      nan'
    >>> calibration.sensors_toml().splitlines()[8:10]
    ['format = "aura-ums/sensor-calibration"', 'growth = "move"']
    """

    terrain: str
    stats: TerrainStats
    motion: MotionCalibration
    working: SensorBounds
    envelope: SensorBounds
    noise: FilterNoise
    quantile: float
    move: float
    horizons: tuple[float, ...]
    checks: tuple[HorizonCheck, ...]
    motion_windows: int
    observations: int
    anchor: bool = False

    def terrain_table(self) -> TerrainTable:
        """Return a one-terrain table holding :attr:`stats` under :attr:`terrain`."""
        return TerrainTable({self.terrain: self.stats})

    def report(self) -> str:
        """Return the horizon checks as a text table: true error quantile against the bound."""
        lines = [
            f"horizon s  windows  inside  heading q{self.quantile:g} rad  bound rad  "
            f"position q{self.quantile:g} m  bound m"
        ]
        for c in self.checks:
            lines.append(
                f"{c.horizon:9g}  {c.windows:7d}  {c.containment:6.3f}  {c.heading_error:14.3f}  "
                f"{c.heading_bound:9.3f}  {c.position_error:13.3f}  {c.position_bound:7.3f}"
            )
        return "\n".join(lines)

    def sensors_toml(self) -> str:
        """Return motion calibration, sensor bounds and filter noise as TOML (:func:`load_sensors`)."""
        lines = [
            f"# aura-ums sensor calibration: quantile {self.quantile!r}, moves of {self.move!r} s,",
            f"# terrain statistics for growth {_GROWTH_WORDS[self.anchor]},",
            f"# {self.motion_windows} motion windows, {self.observations} observations.",
            "# Growth bound against the truth over each horizon (calibration logs):",
            *(f"# {line}" for line in self.report().splitlines()),
            f'format = "{_KIND}"',
            f'growth = "{_GROWTH_KEYS[self.anchor]}"',
            "",
            "[motion]",
            *(f"{key} = {getattr(self.motion, key)!r}" for key in _MOTION_KEYS),
        ]
        for table, bounds in (("working", self.working), ("envelope", self.envelope)):
            lines += ["", f"[{table}]", *(f"{key} = {getattr(bounds, key)!r}" for key in _SENSOR_KEYS)]
        lines += ["", "[noise]", *(f"{key} = {getattr(self.noise, key)!r}" for key in _NOISE_KEYS)]
        return "\n".join(lines) + "\n"


def sensors_path(terrain: str | Path) -> Path:
    """Return where ``aura-ums calibrate`` writes the sensors file beside a terrain file.

    Examples
    --------
    >>> sensors_path("runs/calib/terrain.toml").as_posix()
    'runs/calib/terrain.sensors.toml'
    >>> sensors_path("runs/..")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: terrain: expected a terrain table file's path, got 'runs/..', ...
    """
    path = as_path(terrain, "terrain")
    if not path.name or path.name == "..":
        raise InputError(
            f"terrain: expected a terrain table file's path, got {str(terrain)!r}, which names a folder"
        )
    return path.with_suffix(".sensors.toml")


def _read_sensors(path: str | Path) -> tuple[Fields, dict[str, object]]:
    document = load_toml(path, kind="sensor calibration TOML")
    reader = Fields(str(path))
    expected, optional = {"format", "motion", "working", "envelope"}, {"noise", "growth"}
    if not expected <= set(document) <= expected | optional:
        missing, extra = sorted(expected - set(document)), sorted(set(document) - expected - optional)
        raise reader.error("", f"expected keys {sorted(expected)}, got missing {missing}, unknown {extra}")
    if document["format"] != _KIND:
        raise reader.error("format", f"expected {_KIND!r}, got {reader.describe(document['format'])}")
    if "growth" in document and document["growth"] not in _GROWTH_KEYS.values():
        kinds = " or ".join(repr(kind) for kind in _GROWTH_KEYS.values())
        raise reader.error("growth", f"expected {kinds}, got {reader.describe(document['growth'])}")
    return reader, document


def _build(
    reader: Fields, document: dict[str, object], name: str, keys: tuple[str, ...], make: Callable[..., _T]
) -> _T:
    values = reader.table(document[name], f"[{name}]")
    if set(values) != set(keys):
        raise reader.error(f"[{name}]", f"expected keys {list(keys)}, got {sorted(values)}")
    numbers = {
        key: (
            reader.ranged(values[key], key_path(f"[{name}]", key), KEY_RANGES[key])
            if key in KEY_RANGES
            else reader.number(values[key], key_path(f"[{name}]", key))
        )
        for key in keys
    }
    try:
        return make(**numbers)
    except InputError as exc:  # named "SensorBounds.bearing_error": name the key instead
        field, _, message = str(exc).partition(": ")
        raise reader.error(key_path(f"[{name}]", field.rpartition(".")[2]), message) from None


def load_sensors(path: str | Path) -> tuple[MotionCalibration, SensorBounds, SensorBounds]:
    """Read a sensor calibration file written by :meth:`Calibration.sensors_toml`.

    Parameters
    ----------
    path : str or Path
        The TOML file.

    Returns
    -------
    (MotionCalibration, SensorBounds, SensorBounds)
        The motion calibration, the working bounds and the envelope bounds.

    Raises
    ------
    FileFormatError
        Naming the file and table for a missing file, bad TOML, a missing or unknown key,
        or a value out of range (in the optional ``[noise]`` table too).

    Examples
    --------
    >>> import tempfile
    >>> from aura_ums.logs import synthetic_log
    >>> log = synthetic_log(np.random.default_rng(0), duration=10.0)
    >>> calibration = calibrate_logs([log], horizons=(1.0,))
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "floor.sensors.toml"
    ...     _ = path.write_text(calibration.sensors_toml())
    ...     motion, working, envelope = load_sensors(path)
    >>> motion == calibration.motion, working == calibration.working, envelope == calibration.envelope
    (True, True, True)
    >>> load_sensors("missing.sensors.toml")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: missing.sensors.toml: expected an existing ... file, got no such file
    """
    reader, document = _read_sensors(path)
    if "noise" in document:
        # Checked though unused here: a bad file is refused by every command that reads it.
        _build(reader, document, "noise", _NOISE_KEYS, FilterNoise)
    motion = _build(reader, document, "motion", _MOTION_KEYS, MotionCalibration)
    working = _build(reader, document, "working", _SENSOR_KEYS, SensorBounds)
    envelope = _build(reader, document, "envelope", _SENSOR_KEYS, SensorBounds)
    for key in _SENSOR_KEYS:
        # The envelope is the worst case the working bounds may be wrong within: a narrower
        # one re-localized into a map that excluded the truth.
        wide, narrow = getattr(envelope, key), getattr(working, key)
        if wide < narrow:
            raise reader.error(
                key_path("[envelope]", key), f"expected at least [working] {key} ({narrow!r}), got {wide!r}"
            )
    return motion, working, envelope


def load_noise(path: str | Path) -> FilterNoise | None:
    """Read the filter noise of a sensor calibration file; None when it has no ``[noise]`` table.

    Files written before the table existed have none.

    Raises
    ------
    FileFormatError
        As :func:`load_sensors`, and for a bad ``[noise]`` table.

    Examples
    --------
    >>> import tempfile
    >>> from aura_ums.logs import synthetic_log
    >>> log = synthetic_log(np.random.default_rng(0), duration=10.0)
    >>> calibration = calibrate_logs([log], horizons=(1.0,))
    >>> text = calibration.sensors_toml()
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "floor.sensors.toml"
    ...     _ = path.write_text(text)
    ...     noise = load_noise(path)
    ...     _ = path.write_text(text.split("[noise]")[0])     # as written before the table existed
    ...     old = load_noise(path)
    >>> noise == calibration.noise, old is None
    (True, True)
    """
    reader, document = _read_sensors(path)
    if "noise" not in document:
        return None
    return _build(reader, document, "noise", _NOISE_KEYS, FilterNoise)


def fitted_for_anchor(path: str | Path) -> bool | None:
    """Whether a sensor calibration file's terrain statistics are for growth from an anchor.

    :func:`calibrate_logs` fits the statistics either for growth move by move or for growth
    from an anchor (``ManagerSettings.anchor_growth``), and the numbers of one are no bound
    for the other: replayed from an anchor, statistics fitted move by move kept the truth
    in under 1% of the frames of a synthetic log. The file says which (its ``growth``).

    Returns
    -------
    bool or None
        True for ``growth = "anchor"``, False for ``"move"``; None when the file does not
        say (written before it did).

    Raises
    ------
    FileFormatError
        As :func:`load_sensors`, and for a ``growth`` other than ``"move"`` or ``"anchor"``.

    Examples
    --------
    >>> import tempfile
    >>> from aura_ums.logs import synthetic_log
    >>> calibration = calibrate_logs([synthetic_log(np.random.default_rng(1), duration=60.0)])
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "floor.sensors.toml"
    ...     _ = path.write_text(calibration.sensors_toml())
    ...     fitted_for_anchor(path)
    False
    """
    _, document = _read_sensors(path)
    growth = document.get("growth")
    return None if growth is None else growth == _GROWTH_KEYS[True]


# --- the fit ---------------------------------------------------------------------------

#: Seconds: the horizons over which :func:`calibrate_logs` makes the growth bound hold and
#: checks it (the time a map typically goes without a correcting observation).
DEFAULT_HORIZONS = (1.0, 2.0, 5.0, 10.0, 30.0)
#: Seconds: the grid of the delay search.
_DELAY_STEP = 0.05
#: Delays whose heading residual is within this fraction of the best one's are told apart by
#: noise alone: the shortest of them is taken. Under a steady turn rate every delay aligns the
#: turns equally well (within 2 to 7% on steady arcs), while a delay the motion reveals leaves
#: its neighbours 10 to 200% worse (MRCLAM robots: 18 and 10% at 0.05 s either side).
_DELAY_TIE = 0.1
#: Metres per second: a window whose recorded run is slower than this does not fit drift
#: or run (its heading and position errors are the ground truth's noise, not motion's).
_MOVING = 0.02
#: The band fractions tried for the turn (0, 0.01, ..., 0.95).
_BANDS = np.linspace(0.0, 0.95, 96)


class _Cumulative(NamedTuple):
    """A log's recorded motion summed from its start, before delay and scales (zero-order hold)."""

    time: NDArray[np.float64]
    #: Metres run either way (forward and backing up alike).
    run: NDArray[np.float64]
    turn: NDArray[np.float64]
    #: Metres of ``run`` backing up (negative ``v``): 0 for commands, which never back up.
    back: NDArray[np.float64]
    #: Whether the motion from each row on backs up.
    backing: NDArray[np.bool_]


def _cumulative_motion(log: RobotLog) -> _Cumulative:
    """Return the times and cumulative recorded run and turn, before delay and scales (zero-order hold)."""
    if log.odometry is not None:
        time = log.odometry.time
        dt = np.diff(time)
        v = log.odometry.v
        run = np.concatenate(([0.0], np.cumsum(np.abs(v[:-1]) * dt)))
        turn = np.concatenate(([0.0], np.cumsum(log.odometry.omega[:-1] * dt)))
        back = np.concatenate(([0.0], np.cumsum(np.maximum(-v[:-1], 0.0) * dt)))
        return _Cumulative(time, run, turn, back, v < 0.0)
    assert log.commands is not None
    time = np.array([r.time for r in log.commands], dtype=np.float64)
    run = np.cumsum([r.command.run for r in log.commands], dtype=np.float64)
    turn = np.cumsum([r.command.turn for r in log.commands], dtype=np.float64)
    return _Cumulative(time, run, turn, np.zeros(len(time)), np.zeros(len(time), dtype=np.bool_))


@dataclass(frozen=True, slots=True)
class _Moves:
    """One log cut into moves of equal duration: per move, recorded and true motion.

    ``run``/``turn`` are recorded (before scales), ``path``/``heading`` the true chord
    length and heading change; ``pose`` the true pose at each move's start and at the
    last one's end, ``(n + 1, 3)``; ``valid`` marks moves whose both ends lie in the
    ground truth (not in a gap). ``back`` is the part of ``run`` backing up, and
    ``backing_first`` whether a move starts backing up.
    """

    run: NDArray[np.float64]
    turn: NDArray[np.float64]
    path: NDArray[np.float64]
    heading: NDArray[np.float64]
    pose: NDArray[np.float64]
    valid: NDArray[np.bool_]
    back: NDArray[np.float64]
    backing_first: NDArray[np.bool_]


#: Longest horizon of :func:`calibrate_logs`, s: no map goes a day without a correction.
MAX_HORIZON = 86_400.0
#: Most moves :func:`calibrate_logs` cuts its logs into (about 100 bytes each, per horizon).
MAX_MOVES = 2_000_000
#: Most growths of a point map :func:`calibrate_logs`'s check of its own bounds may take
#: (:func:`horizon_checks`: tens of microseconds each, so minutes at most).
MAX_CHECK_GROWTHS = 10_000_000
#: Seconds between the starts of the windows :func:`horizon_checks` grows a map over.
_CHECK_STRIDE = 1.0


def _truth_span(log: RobotLog) -> float:
    """Seconds during which the log has both motion and ground truth (at most: before any delay)."""
    truth = log.groundtruth
    assert truth is not None
    first, last = log.motion_span
    return max(0.0, min(last, float(truth.time[-1])) - max(first, float(truth.time[0])))


def _record_spans(log: RobotLog) -> str:
    """Name the files whose times overlap too little to calibrate from, with their spans.

    The message of a log too short to calibrate from: one row of odometry spans 0 s, and
    only the files say which record is the short one.
    """
    truth = log.groundtruth
    assert truth is not None
    first, last = log.motion_span
    motion = ODOMETRY if log.odometry is not None else COMMANDS
    where = f"{log.path}: " if log.path is not None else f"log {log.meta.name!r}: "
    return (
        f"{where}{motion} {exact_text(first)} to {exact_text(last)} s, "
        f"{GROUNDTRUTH} {exact_text(float(truth.time[0]))} to {exact_text(float(truth.time[-1]))} s"
    )


def _moves(log: RobotLog, delay: float, move: float) -> _Moves:
    truth = log.groundtruth
    assert truth is not None
    time, run, turn, back, backing = _cumulative_motion(log)
    first = max(float(time[0]) + delay, float(truth.time[0]))
    last = min(float(time[-1]) + delay, float(truth.time[-1]))
    count = math.floor((last - first) / move) if last > first else 0
    edges = first + move * np.arange(count + 1)
    cum_run = np.interp(edges, time + delay, run)
    cum_turn = np.interp(edges, time + delay, turn)
    pose = truth.at(edges)
    known = ~np.isnan(pose[:, 0])
    # The row whose motion holds at each move's start (the last row at or before it).
    holding = np.clip(np.searchsorted(time + delay, edges[:-1], side="right") - 1, 0, len(time) - 1)
    return _Moves(
        np.diff(cum_run),
        np.diff(cum_turn),
        np.hypot(np.diff(pose[:, 0]), np.diff(pose[:, 1])),
        np.angle(np.exp(1j * np.diff(pose[:, 2]))),
        pose,
        known[:-1] & known[1:],
        np.diff(np.interp(edges, time + delay, back)),
        backing[holding],
    )


def _window_sums(values: NDArray[np.float64], length: int) -> NDArray[np.float64]:
    """Return the sums of ``length`` consecutive values, one per start (``len(values) - length + 1``)."""
    if len(values) < length:
        return np.empty(0)
    total = np.concatenate(([0.0], np.cumsum(values)))
    result: NDArray[np.float64] = total[length:] - total[:-length]
    return result


@dataclass(frozen=True, slots=True)
class _Windows:
    """Sums over every window of consecutive valid moves at one horizon, pooled over logs."""

    run: NDArray[np.float64]
    turn: NDArray[np.float64]
    abs_turn: NDArray[np.float64]
    path: NDArray[np.float64]
    heading: NDArray[np.float64]


def _windows(moves: Sequence[_Moves], length: int) -> _Windows:
    parts: list[list[NDArray[np.float64]]] = [[], [], [], [], []]
    for m in moves:
        whole = _window_sums((~m.valid).astype(np.float64), length) == 0.0
        values = (m.run, m.turn, np.abs(m.turn), m.path, m.heading)
        for part, value in zip(parts, values, strict=True):
            part.append(_window_sums(np.where(m.valid, value, 0.0), length)[whole])
    return _Windows(*(np.concatenate(p) if p else np.empty(0) for p in parts))


def _fit_delay(logs: Sequence[RobotLog], delays: NDArray[np.float64], move: float) -> float:
    """Return the shortest delay that aligns recorded and true heading changes about as well as the best.

    Turns carry the timing. A steady turn rate carries none: every delay fits it alike, and
    a delay picked by noise would shift the whole replay by the motion of that long.
    """
    costs: list[tuple[float, float]] = []
    for delay in delays:
        pooled = [_moves(log, float(delay), move) for log in logs]
        turn = np.concatenate([m.turn[m.valid] for m in pooled])
        heading = np.concatenate([m.heading[m.valid] for m in pooled])
        if turn.size:
            costs.append((float(delay), float(np.mean((turn - heading) ** 2))))
    if not costs:
        return 0.0
    best = min(cost for _, cost in costs)
    return min(delay for delay, cost in costs if cost <= best * (1.0 + _DELAY_TIE))


def _gain(actual: NDArray[np.float64], recorded: NDArray[np.float64]) -> float:
    """Least-squares factor ``k`` of ``actual ~ k * recorded``; 1 when it is undefined or not positive."""
    power = float(np.sum(recorded * recorded))
    if power <= 0.0:
        return 1.0
    gain = float(np.sum(actual * recorded)) / power
    return gain if gain > 1e-3 else 1.0


def _band_stats(gain: float, band: float, sigmas: float) -> tuple[float, float, float]:
    """Scale, loss and sd of a factor within ``gain * [1 - band, 1 + band]`` at ``sigmas``.

    The growth model's actual value is ``scale * recorded * clip(1 - loss + sd z, 0, 1)``;
    with |z| <= sigmas this spans exactly ``gain * recorded * [1 - band, 1 + band]``, and
    its mean is ``gain * recorded``.
    """
    scale = gain * (1.0 + band)
    loss = band / (1.0 + band)
    return scale, loss, loss / sigmas


def _fit_turn_and_drift(windows: Sequence[_Windows], gain: float, q: float) -> tuple[float, float]:
    """Return the turn band and the drift (rad/m) whose summed bound covers ``q`` at every horizon.

    Over a window the bound on the true heading change is ``gain * turn +- (band * gain *
    sum|turn| + drift * path)``: the growth sums it move by move. For each band the drift
    is the smallest that covers the ``q`` quantile of every horizon's moving windows; the
    band kept is the one whose bound is smallest, each horizon weighing the same.
    """
    best = (0.0, 0.0)
    best_cost = math.inf
    for band in _BANDS.tolist():
        drift = 0.0
        for w in windows:
            moving = w.run > 0.0
            if not moving.any():
                continue
            excess = np.abs(w.heading - gain * w.turn) - band * gain * w.abs_turn
            need = np.maximum(excess[moving], 0.0) / np.maximum(w.path[moving], 1e-3)
            drift = max(drift, float(np.quantile(need, q)))
        cost = 0.0
        for w in windows:
            if w.run.size:
                error = float(np.mean(np.abs(w.heading - gain * w.turn))) + 1e-9
                cost += float(np.mean(band * gain * w.abs_turn + drift * w.path)) / error
        if cost < best_cost:
            best, best_cost = (band, drift), cost
    return best


def _fit_run(windows: Sequence[_Windows], gain: float, q: float, sigmas: float) -> tuple[float, float, float]:
    """Return run scale, loss and sd: the true path over recorded run lies in ``[low, high]``.

    ``high`` is the largest ``(1 + q) / 2`` quantile and ``low`` the smallest ``(1 - q) / 2``
    quantile of the ratio over the horizons (runs lag their commands more often than they
    lead them, so the band is not symmetric); the loss keeps the mean at ``gain``.
    """
    high, low = 0.0, math.inf
    for w in windows:
        moving = w.run > 0.0
        if moving.any():
            ratio = w.path[moving] / w.run[moving]
            high = max(high, float(np.quantile(ratio, (1.0 + q) / 2.0)))
            low = min(low, float(np.quantile(ratio, (1.0 - q) / 2.0)))
    if not high > 0.0:
        return 1.0, 0.0, 0.0
    floor = min(max(low / high, 0.0), 1.0)
    loss = min(max(1.0 - gain / high, 0.0), 1.0 - floor)
    return high, loss, (1.0 - loss - floor) / sigmas


#: Metres: the fixed distances per move tried for growth from an anchor (0, 0.05, ..., 1.5).
_ANCHOR_REACH = np.linspace(0.0, 1.5, 31)
#: The turn bands (radians per radian turned) and skitters (metres per radian) tried for it.
_ANCHOR_BANDS = np.linspace(0.0, 1.0, 51)


def _position_errors(
    moves: Sequence[_Moves], length: int, run_gain: float, turn_gain: float
) -> NDArray[np.float64]:
    """Return, per window of ``length`` valid moves, the distance between true and nominal displacement (m).

    Both are taken in their own start frame: the true one in the true start heading's, the
    nominal one (each move's scaled run along the middle of its scaled turn) in the
    nominal heading's. The windows are those of :func:`_windows`, in its order.
    """
    parts: list[NDArray[np.float64]] = []
    for m in moves:
        if len(m.run) < length:
            continue
        whole = _window_sums((~m.valid).astype(np.float64), length) == 0.0
        turn = np.where(m.valid, m.turn, 0.0) * turn_gain
        run = np.where(m.valid, m.run, 0.0) * run_gain
        heading = np.concatenate(([0.0], np.cumsum(turn)))
        middle = heading[:-1] + turn / 2.0
        nominal = np.concatenate(([0.0], np.cumsum(run * np.exp(1j * middle))))
        pose = np.nan_to_num(m.pose)
        true = pose[:, 0] + 1j * pose[:, 1]
        starts = np.arange(len(m.run) - length + 1)
        ours = (nominal[starts + length] - nominal[starts]) * np.exp(-1j * heading[starts])
        theirs = (true[starts + length] - true[starts]) * np.exp(-1j * pose[starts, 2])
        parts.append(np.abs(theirs - ours)[whole])
    return np.concatenate(parts) if parts else np.empty(0)


def _smallest_rate(
    errors: Sequence[NDArray[np.float64]],
    per_turn: Sequence[NDArray[np.float64]],
    reach: Sequence[NDArray[np.float64]],
    band: float,
    q: float,
) -> float:
    """Return the least rate ``r`` whose ``band * turn + r * reach`` covers each horizon's ``q`` quantile."""
    rate = 0.0
    for error, turn, distance in zip(errors, per_turn, reach, strict=True):
        if error.size:
            need = np.maximum(error - band * turn, 0.0) / np.maximum(distance, 1e-3)
            rate = max(rate, float(np.quantile(need, q)))
    return rate


def _fit_anchor(
    windows: Sequence[_Windows],
    position_errors: Sequence[NDArray[np.float64]],
    run_gain: float,
    turn_gain: float,
    q: float,
    sigmas: float,
) -> TerrainStats:
    """Return statistics whose anchor bounds cover the ``q`` quantile of every horizon's errors.

    The heading bound is ``band * S + drift * (L + L0)`` and the position bound ``p * (L +
    L0) + s * S`` (:func:`~aura_ums.uncertainty.anchor_bounds`), with ``L`` and ``S`` the
    scaled path and turning. For each ``L0`` and band (and skitter ``s``), the rates are the
    smallest that cover; the choice kept has the smallest bounds relative to the errors,
    each horizon weighing the same.
    """
    heading_errors = [np.abs(w.heading - turn_gain * w.turn) for w in windows]
    turning = [turn_gain * w.abs_turn for w in windows]
    paths = [run_gain * w.run for w in windows]
    mean_heading = [float(np.mean(e)) + 1e-9 if e.size else 1.0 for e in heading_errors]
    mean_position = [float(np.mean(e)) + 1e-9 if e.size else 1.0 for e in position_errors]

    def cost(band: float, rate: float, reach: list[NDArray[np.float64]], scale: list[float]) -> float:
        return sum(
            float(np.mean(band * turn + rate * distance)) / mean
            for turn, distance, mean in zip(turning, reach, scale, strict=True)
            if turn.size
        )

    best: tuple[float, float, float, float, float, float] | None = None
    for offset in _ANCHOR_REACH.tolist():
        reach = [path + offset for path in paths]
        heading = min(
            (
                (cost(b, r, reach, mean_heading), b, r)
                for b in _ANCHOR_BANDS.tolist()
                for r in (_smallest_rate(heading_errors, turning, reach, b, q),)
            ),
        )
        position = min(
            (
                (cost(s, r, reach, mean_position), s, r)
                for s in _ANCHOR_BANDS.tolist()
                for r in (_smallest_rate(position_errors, turning, reach, s, q),)
            ),
        )
        total = heading[0] + position[0]
        if best is None or total < best[0]:
            best = (total, offset, heading[1], heading[2], position[1], position[2])
    assert best is not None  # _ANCHOR_REACH is not empty
    _, offset, band, drift, skitter, rate = best
    return TerrainStats(
        translation_loss=0.0,
        translation_inertial_loss=offset,
        translation_sd=min(rate / sigmas, 10.0),
        drift=min(drift, 10.0),
        rotation_loss=0.0,
        rotation_sd=band / sigmas,
        skitter=0.0,
        skitter_sd=skitter / sigmas,
    )


@dataclass(frozen=True, slots=True)
class HorizonCheck:
    """How the calibrated growth bound holds over one horizon (a row of the calibration report).

    From the true pose at the start of every window of ``horizon`` seconds in the
    calibration logs, a point map is grown by the window's recorded moves (scaled, at the
    calibration's sigmas) and set against the true pose at its end.

    Attributes
    ----------
    horizon : float
        Seconds without a correcting observation.
    windows : int
        Windows checked (those inside the ground truth).
    containment : float
        Fraction of the windows whose true end pose is inside the grown map.
    heading_error : float
        The calibration quantile of the true heading's distance from the middle of the
        grown wedge, radians.
    heading_bound : float
        Median half-width of the grown wedge, radians.
    position_error : float
        The calibration quantile of the true position's distance from the grown map's
        centre, metres.
    position_bound : float
        Median distance from the grown map's centre to its farthest vertex, metres.

    Examples
    --------
    >>> from aura_ums.logs import synthetic_log
    >>> log = synthetic_log(np.random.default_rng(0), duration=10.0)
    >>> first, too_long = calibrate_logs([log], horizons=(1.0, 30.0)).checks
    >>> first.horizon, first.windows, 0.0 <= first.containment <= 1.0
    (1.0, 9, True)
    >>> too_long.windows, math.isnan(too_long.containment)     # longer than the log: nothing checked
    (0, True)
    """

    horizon: float
    windows: int
    containment: float
    heading_error: float
    heading_bound: float
    position_error: float
    position_bound: float


def horizon_checks(
    logs: Sequence[RobotLog],
    stats: TerrainStats,
    motion: MotionCalibration,
    *,
    quantile: float = 0.99,
    horizons: Sequence[float] = DEFAULT_HORIZONS,
    move: float = 0.5,
    sigmas: float = 3.0,
    stride: float = _CHECK_STRIDE,
    anchor: bool = False,
) -> tuple[HorizonCheck, ...]:
    """Check growth bounds against logs with ground truth over each horizon.

    Windows start every ``stride`` seconds; each grows a point map at the true start pose
    by the recorded motion cut into ``move``-second pieces (``motion``'s delay and scales
    applied; each piece half its turn, its run, the other half) on ``stats`` at
    ``sigmas``, and is compared with the truth after each horizon. A point start is the
    strictest test: a replay's map is never a point, and millimetres of ground-truth
    noise count here.

    Parameters
    ----------
    logs : sequence of RobotLog
        Logs with ground truth.
    stats : TerrainStats
        The growth statistics to check.
    motion : MotionCalibration
        Delay and scales of the recorded motion.
    quantile : float
        In (0, 1): the quantile of the errors reported.
    horizons : sequence of float
        Seconds, each >= ``move``.
    move, stride : float
        Seconds, > 0.
    sigmas : float
        Standard deviations the growth bounds, in [0.1, 100].
    anchor : bool
        Grow from the start pose once by the composite of the window's moves
        (:func:`~aura_ums.uncertainty.grow_from_anchor`) rather than move by move.

    Returns
    -------
    tuple of HorizonCheck
        One per horizon, in the order given; figures are NaN for a horizon without windows.

    Examples
    --------
    >>> import numpy as np
    >>> from aura_ums.logs import synthetic_log
    >>> log = synthetic_log(np.random.default_rng(0), duration=60.0)
    >>> calibration = calibrate_logs([log], horizons=(1.0, 2.0))
    >>> [(c.horizon, c.windows) for c in calibration.checks]
    [(1.0, 59), (2.0, 58)]
    >>> horizon_checks([log], calibration.stats, calibration.motion, horizons=(120.0,))[0].windows
    0
    """
    items = sequence_of(logs, RobotLog, "logs")
    if not items:
        # the checks of no log were NaN-filled
        raise InputError("logs: expected at least one RobotLog, got none")
    q = finite_float(quantile, "quantile")
    if not 0.0 < q < 1.0:
        raise InputError(f"quantile: expected a number in (0, 1), got {q!r}")
    step = positive_float(move, "move")
    every = max(1, round(positive_float(stride, "stride") / step))
    lengths = [max(1, round(positive_float(h, "horizons") / step)) for h in horizons]
    sigma = SIGMAS.check(sigmas, "sigmas")
    rows: list[list[tuple[bool, float, float, float, float]]] = [[] for _ in lengths]
    longest = max(lengths, default=0)
    for log in items:
        m = _moves(log, motion.delay_s, step)
        commands = [
            _move_commands(turn, run, back, backing_first, motion)
            for turn, run, back, backing_first in zip(
                m.turn.tolist(), m.run.tolist(), m.back.tolist(), m.backing_first.tolist(), strict=True
            )
        ]
        for first in range(0, len(commands), every):
            x, y, heading = m.pose[first]
            if not m.valid[first]:
                continue
            start = SpatialUncertaintyMap.from_pose(Pose(float(x), float(y), float(heading)), 0.0, 0.0)
            grown, composite = start, Composite()
            for done in range(1, min(longest, len(commands) - first) + 1):
                index = first + done - 1
                if not m.valid[index]:
                    break
                if anchor:
                    composite = composite.extended(commands[index], stats)
                    grown = grow_from_anchor(start, composite, stats, sigma, 64)
                else:
                    for command in commands[index]:
                        grown = grown.grow(command, stats, sigmas=sigma)
                for row, length in zip(rows, lengths, strict=True):
                    if length == done:
                        row.append(_judge(grown, m.pose[index + 1]))
    checks = []
    for horizon, row in zip(horizons, rows, strict=True):
        if not row:
            checks.append(HorizonCheck(float(horizon), 0, *([math.nan] * 5)))
            continue
        table = np.array(row, dtype=np.float64)
        checks.append(
            HorizonCheck(
                float(horizon),
                len(row),
                float(np.mean(table[:, 0])),
                float(np.quantile(table[:, 1], q)),
                float(np.median(table[:, 2])),
                float(np.quantile(table[:, 3], q)),
                float(np.median(table[:, 4])),
            )
        )
    return tuple(checks)


def _move_commands(
    turn: float, run: float, back: float, backing_first: bool, motion: MotionCalibration
) -> tuple[TurnAndRun, ...]:
    """Return the commands one move grows by in :func:`horizon_checks`, as a replay grows it.

    Half the turn before the run and half after: a move turns while it runs, and its chord
    points along the middle heading, not the last one. A move backing up is grown as
    ``replay --reverse flip`` grows it (``ReverseMotion.FLIP``): turn round, run, turn back.
    A move that both runs and backs up is the two in the order they began (the turn shared
    in proportion to their lengths); grown forward, a move backing up was judged against
    a truth on the far side of its start.
    """
    half = turn * motion.turn_scale / 2.0
    if not back > 0.0 or not run > 0.0:
        return (TurnAndRun(half, run * motion.run_scale), TurnAndRun(half, 0.0))
    ahead = max(run - back, 0.0)
    pieces = [(ahead, False), (back, True)]
    if backing_first:
        pieces.reverse()
    commands: list[TurnAndRun] = []
    for length, backing in pieces:
        if length > 0.0:
            share = half * length / run
            flip = math.pi if backing else 0.0
            commands += [TurnAndRun(share + flip, length * motion.run_scale), TurnAndRun(share - flip, 0.0)]
    return tuple(commands)


def _judge(
    grown: SpatialUncertaintyMap, truth: NDArray[np.float64]
) -> tuple[bool, float, float, float, float]:
    """Containment, heading error and half-width, position error and reach of one grown map."""
    x, y, heading = (float(v) for v in truth)
    wedge = grown.wedge
    middle = wedge.center + (wedge.ccw - wedge.cw) / 2.0
    cx, cy = (float(v) for v in grown.center)
    reach = float(np.max(np.hypot(grown.polygon.vertices[:, 0] - cx, grown.polygon.vertices[:, 1] - cy)))
    return (
        bool(grown.contains(x, y, heading)),
        abs(math.remainder(heading - middle, math.tau)),
        (wedge.cw + wedge.ccw) / 2.0,
        math.hypot(x - cx, y - cy),
        reach,
    )


def calibrate_logs(
    logs: Sequence[RobotLog],
    *,
    quantile: float = 0.99,
    move: float = 0.5,
    horizons: Sequence[float] = DEFAULT_HORIZONS,
    sigmas: float = 3.0,
    envelope_margin: float = 1.25,
    max_delay: float = 1.0,
    anchor: bool = False,
) -> Calibration:
    """Estimate terrain statistics, motion delay and scales, and sensor bounds from logs.

    **Motion** (pooled over the logs, which must share one terrain). The recorded motion is
    cut into moves of ``move`` seconds and set against the ground truth's over the same
    moves; the growth bound of a span is the sum of its moves' bounds, so it is fitted to
    the true error *accumulated* over windows of each of ``horizons`` seconds (the time
    a map goes without a correcting observation), never to one move's worst case:

    - the delay in ``[0, max_delay]`` (0.05 s steps) best aligns recorded and true
      heading changes per move (the shortest of those within 10% of the best alignment:
      a steady turn rate reveals no delay);
    - turns: the true heading change is ``k_t`` times the recorded turn on average
      (least squares), within a band ``k_t * [1 - e_t, 1 + e_t]`` of it per move, plus
      ``drift`` radians per metre actually run either side; for each band the drift is
      the smallest whose summed bound covers the ``quantile`` of the windows' heading
      errors at every horizon, and the band kept gives the smallest bound;
    - runs: the true path is ``k_r`` times the recorded run on average, within a band
      ``k_r * [1 - e_r, 1 + e_r]`` covering the ``quantile`` at every horizon;
    - a band becomes the paper's statistics at ``sigmas``: ``turn_scale = k_t (1 + e_t)``,
      ``rotation_loss = e_t / (1 + e_t)``, ``rotation_sd = rotation_loss / sigmas`` (the
      same for runs); skitter and inertial loss are 0 (not separable from the rest).

    Windows slower than 0.02 m/s do not fit drift or runs. :attr:`Calibration.checks`
    then grows a point map over every window and reports how the bound holds.

    **Motion from an anchor** (``anchor=True``, for ``ManagerSettings.anchor_growth``): the
    map grows once by the composite of the moves since its last correction
    (:func:`~aura_ums.uncertainty.anchor_bounds`), so the statistics bound a window's
    accumulated error as one move: the scales are the least-squares factors (no losses),
    and for each fixed distance ``L0`` per move (``translation_inertial_loss``) and turn band
    the drift is the smallest whose bound ``band * S + drift * (L + L0)`` covers the
    ``quantile`` of the heading errors at every horizon; likewise ``sigmas *
    translation_sd * (L + L0) + sigmas * skitter_sd * S`` for the position errors (in the
    frame of the true start heading). ``L0``, the turn band and the skitter kept give the
    smallest bounds, each horizon weighing the same.

    **Sensors** (every observation inside the ground truth): the working bearing bound is
    the ``quantile`` of |bearing error|; the working range bound is relative to the
    measured range plus absolute, ``fraction * range + range_error`` on each side: the
    fractions are the ``(1 - quantile) / 2`` and ``(1 + quantile) / 2`` quantiles of the
    relative range error, and ``range_error`` the median absolute range error of the shortest
    tenth of the ranges (so that short ranges never get a zero-width bound). The envelope
    bounds cover every relative error seen, times ``envelope_margin``, plus the absolute
    part times ``envelope_margin``. The filters' noise (:class:`FilterNoise`) is the standard deviation
    of the bearing errors and of the relative range errors.

    Parameters
    ----------
    logs : sequence of RobotLog
        Logs with ground truth, on the same terrain.
    quantile : float
        In (0.5, 1).
    move : float
        Seconds, > 0: the pieces the fit cuts the motion into. Replays cut at least as
        finely (at every observation), which only widens their bound.
    horizons : sequence of float
        Seconds, each >= ``move``: where the bound must hold.
    sigmas : float
        Standard deviations the replay's growth bounds (its ``sigmas`` setting), in [0.1, 100].
    envelope_margin : float
        >= 1.
    max_delay : float
        Seconds, >= 0.
    anchor : bool
        Fit the statistics for growth from an anchor rather than move by move.

    Returns
    -------
    Calibration

    Raises
    ------
    InputError
        For no logs, a log without ground truth, logs on different terrains, too few
        samples, or an argument out of range.

    Examples
    --------
    >>> import numpy as np
    >>> from aura_ums.logs import synthetic_log
    >>> log = synthetic_log(np.random.default_rng(0), duration=120.0)
    >>> calibration = calibrate_logs([log])
    >>> calibration.terrain, calibration.motion.run_scale <= 1.1, calibration.working.bearing_error < 0.05
    ('floor', True, True)
    >>> calibrate_logs([])
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: logs: expected at least one log with ground truth, got none
    """
    logs = list(items_of(logs, "logs", "a sequence of RobotLog"))
    if not logs:
        raise InputError("logs: expected at least one log with ground truth, got none")
    if not isinstance(anchor, bool):
        raise InputError(f"anchor: expected True or False, got {anchor!r}")
    for log in logs:
        if not isinstance(log, RobotLog):
            raise InputError(f"logs: expected RobotLog values, got {type(log).__name__}")
        if log.groundtruth is None:
            raise InputError(f"logs: expected logs with ground truth, got {log.meta.name!r} without")
    terrains = sorted({log.meta.terrain for log in logs})
    if len(terrains) != 1:
        raise InputError(f"logs: expected logs on one terrain, got {terrains}")
    q = finite_float(quantile, "quantile")
    if not 0.5 < q < 1.0:
        raise InputError(f"quantile: expected a number in (0.5, 1), got {q!r}")
    step = positive_float(move, "move")
    if step > MAX_HORIZON:
        longest = f"{MAX_HORIZON:g} (a day, the longest horizon)"
        raise InputError(f"move: expected seconds <= {longest}, got {step!r}")
    spans = tuple(
        finite_float(h, "horizons") for h in items_of(horizons, "horizons", "a sequence of seconds")
    )
    if not spans or min(spans) < step:
        raise InputError(f"horizons: expected seconds, each >= move ({step!r}), got {list(spans)}")
    if max(spans) > MAX_HORIZON:
        # a horizon of 1e308 s was an OverflowError traceback (its moves counted as an integer)
        raise InputError(f"horizons: expected seconds, each <= {MAX_HORIZON:g} (a day), got {list(spans)}")
    sigma = SIGMAS.check(sigmas, "sigmas")
    margin = finite_float(envelope_margin, "envelope_margin")
    if margin < 1.0:
        raise InputError(f"envelope_margin: expected a number >= 1, got {margin!r}")
    delay_limit = finite_float(max_delay, "max_delay")
    if delay_limit < 0.0:
        raise InputError(f"max_delay: expected a number >= 0, got {delay_limit!r}")

    # Arrays of a few floats per move are allocated per log: estimated before any.
    seconds = sum(_truth_span(log) for log in logs)
    if seconds / step > MAX_MOVES:
        raise InputError(
            f"move: expected at most {MAX_MOVES} moves over the logs' {seconds:g} s with ground truth, "
            f"got about {seconds / step:.3g} moves of {step:g} s"
        )
    # The check grows a map from each window's start over the longest horizon, move by move:
    # a 600 s horizon of 0.01 s moves was about 5e7 growths, hours without a sign.
    growths = seconds / _CHECK_STRIDE * min(max(spans), seconds) / step
    if growths > MAX_CHECK_GROWTHS:
        raise InputError(
            f"move: expected at most {MAX_CHECK_GROWTHS:,} growths in the check of the bounds (a map grown "
            f"from the true pose of every {_CHECK_STRIDE:g} s over the longest horizon, {max(spans):g} s), "
            f"got about {growths:.3g} with moves of {step:g} s: longer moves, or a shorter longest horizon"
        )
    delay = _fit_delay(logs, np.arange(0.0, delay_limit + 1e-9, _DELAY_STEP), step)
    moves = [_moves(log, delay, step) for log in logs]
    raw = [_windows(moves, max(1, round(h / step))) for h in spans]
    windows = [
        _Windows(*(getattr(w, f)[w.run > _MOVING * h] for f in _Windows.__slots__))
        for w, h in zip(raw, spans, strict=True)
    ]
    counted = sum(int(w.run.size) for w in windows)
    if windows[0].run.size < 10:
        # The logs are too short (or too still) for the first horizon: named as the
        # horizon, which the caller may shorten; the CLI blames the logs when it is a default.
        raise InputError(
            f"horizons: expected a horizon of which the logs hold at least 10 windows of motion, "
            f"got {spans[0]:g} s ({windows[0].run.size} windows in their {seconds:g} s with ground truth: "
            f"{'; '.join(_record_spans(log) for log in logs)})"
        )
    valid = np.concatenate([m.valid for m in moves])
    run_gain = _gain(
        np.concatenate([m.path for m in moves])[valid], np.concatenate([m.run for m in moves])[valid]
    )
    turn_gain = _gain(
        np.concatenate([m.heading for m in moves])[valid], np.concatenate([m.turn for m in moves])[valid]
    )
    if anchor:
        errors = [_position_errors(moves, max(1, round(h / step)), run_gain, turn_gain) for h in spans]
        errors = [e[w_all.run > _MOVING * h] for e, w_all, h in zip(errors, raw, spans, strict=True)]
        stats = _fit_anchor(windows, errors, run_gain, turn_gain, q, sigma)
        motion = MotionCalibration(delay, run_gain, turn_gain)
    else:
        turn_band, drift = _fit_turn_and_drift(windows, turn_gain, q)
        run_scale, translation_loss, translation_sd = _fit_run(windows, run_gain, q, sigma)
        turn_scale, rotation_loss, rotation_sd = _band_stats(turn_gain, turn_band, sigma)
        stats = TerrainStats(
            translation_loss=translation_loss,
            translation_inertial_loss=0.0,
            translation_sd=translation_sd,
            drift=drift,
            rotation_loss=rotation_loss,
            rotation_sd=rotation_sd,
            skitter=0.0,
            skitter_sd=0.0,
        )
        motion = MotionCalibration(delay, run_scale, turn_scale)
    checks = horizon_checks(
        logs, stats, motion, quantile=q, horizons=spans, move=step, sigmas=sigma, anchor=anchor
    )

    bearing_errors, range_errors, range_measured = _observation_errors(logs)
    if bearing_errors.size < 10:
        raise InputError(
            f"logs: expected at least 10 observations within the ground truth, got {bearing_errors.size}"
        )
    working, envelope = _sensor_bounds(bearing_errors, range_errors, range_measured, q, margin)
    noise = FilterNoise(
        max(float(np.std(bearing_errors)), 1e-6),
        max(float(np.std(range_errors / range_measured)), 1e-3) if range_errors.size > 1 else 0.05,
    )
    return Calibration(
        terrains[0],
        stats,
        motion,
        working,
        envelope,
        noise,
        q,
        step,
        spans,
        checks,
        counted,
        int(bearing_errors.size),
        anchor,
    )


def observation_errors(logs: Sequence[RobotLog]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return the observations' bearing errors (rad) and relative range errors against ground truth.

    Parameters
    ----------
    logs : sequence of RobotLog
        Logs with ground truth; observations outside it (or in one of its gaps) are skipped.

    Returns
    -------
    bearing_errors : ndarray, shape (n,)
        Measured minus true bearing, wrapped to (-pi, pi], radians.
    range_errors : ndarray, shape (k,)
        ``(measured - true) / measured`` for the observations with a range (k <= n).

    Examples
    --------
    >>> from aura_ums.logs import synthetic_log
    >>> log = synthetic_log(np.random.default_rng(0), duration=10.0)
    >>> bearing, relative = observation_errors([log])
    >>> bearing.size, relative.size
    (35, 35)
    >>> bool(np.abs(bearing).max() <= log.meta.bearing_error)     # within the log's own bound
    True
    >>> observation_errors([])                                    # no log: no error
    (array([], dtype=float64), array([], dtype=float64))
    """
    bearing, error, measured = _observation_errors(sequence_of(logs, RobotLog, "logs"))
    return bearing, error / measured


#: Shortest measured range whose error calibrates the range bounds, metres: the relative
#: error of a range of 1e-300 m overflowed, and no range sensor measures under a millimetre.
_SHORTEST_RANGE = 1e-3


def _observation_errors(
    logs: Sequence[RobotLog],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Bearing errors (rad), and range errors ``measured - true`` (m) with their measured ranges (m)."""
    bearing: list[NDArray[np.float64]] = []
    errors: list[NDArray[np.float64]] = []
    measured_ranges: list[NDArray[np.float64]] = []
    for log in logs:
        if log.groundtruth is None or not log.observations:
            continue
        times = np.array([o.time for o in log.observations])
        pose = log.groundtruth.at(times)
        keep = ~np.isnan(pose[:, 0])
        lx = np.array([log.landmark(o.landmark_id).x for o in log.observations])
        ly = np.array([log.landmark(o.landmark_id).y for o in log.observations])
        forward, left = log.meta.sensor_offset  # bearings and ranges are the sensor's
        cos, sin = np.cos(pose[:, 2]), np.sin(pose[:, 2])
        dx = lx - (pose[:, 0] + forward * cos - left * sin)
        dy = ly - (pose[:, 1] + forward * sin + left * cos)
        true_bearing = np.arctan2(dy, dx) - pose[:, 2]
        measured = np.array([o.bearing for o in log.observations])
        error = np.angle(np.exp(1j * (measured - true_bearing)))
        bearing.append(error[keep])
        measured_range = np.array([np.nan if o.range is None else o.range for o in log.observations])
        with_range = keep & ~np.isnan(measured_range) & (measured_range >= _SHORTEST_RANGE)
        errors.append(measured_range[with_range] - np.hypot(dx, dy)[with_range])
        measured_ranges.append(measured_range[with_range])
    empty = np.empty(0, dtype=np.float64)
    return (
        np.concatenate(bearing) if bearing else empty,
        np.concatenate(errors) if errors else empty,
        np.concatenate(measured_ranges) if measured_ranges else empty,
    )


def _sensor_bounds(
    bearing: NDArray[np.float64],
    errors: NDArray[np.float64],
    measured: NDArray[np.float64],
    q: float,
    margin: float,
) -> tuple[SensorBounds, SensorBounds]:
    magnitude = np.abs(bearing)
    working_bearing = max(float(np.quantile(magnitude, q)), 1e-6)
    envelope_bearing = max(float(magnitude.max()) * margin, working_bearing)
    if errors.size:
        relative = errors / measured
        low = min(max(0.0, -float(np.quantile(relative, (1.0 - q) / 2.0))), _FARTHEST)
        high = min(max(0.0, float(np.quantile(relative, (1.0 + q) / 2.0))), _NEAREST)
        # Plus an absolute part, so that short ranges never get a zero-width bound: the
        # median error of the shortest tenth of the ranges, where the relative part vanishes.
        shortest = measured <= float(np.quantile(measured, 0.1))
        absolute = float(np.median(np.abs(errors[shortest])))
        wide = absolute * margin
        env_low = min(max(0.0, -float(relative.min())) * margin, _FARTHEST)
        env_high = min(max(0.0, float(relative.max())) * margin, _NEAREST)
    else:
        absolute = wide = low = high = env_low = env_high = 0.0
    working = SensorBounds(working_bearing, absolute, low, high)
    envelope = SensorBounds(envelope_bearing, wide, max(env_low, low), max(env_high, high))
    return working, envelope
