"""Calibration from logs with ground truth: terrain statistics, motion delay and scales, sensor bounds.

The paper gathers its growth statistics from the robot's own runs ("Uncertainty Map Growth
Statistics"). Here the runs are logs with ground truth: the recorded motion is compared
with the true motion over windows of ``horizon`` seconds, and the observations with the
bearings and ranges the true poses imply.

Why windows, not single reports: the map's bound is a sum of per-report bounds, so it
needs to cover the accumulated error between two reductions, not every report's own
error; per-report errors of a 10 Hz velocity log are dominated by timing jitter that
averages out within a second.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

from aura_ums._files import Fields, key_path, load_toml
from aura_ums._validate import ANGLE_ERROR, DELAY, FACTOR, LENGTH, Range, finite_float, positive_float
from aura_ums.errors import InputError
from aura_ums.logs._log import RobotLog
from aura_ums.uncertainty import TerrainStats, TerrainTable

_SENSOR_KEYS = ("bearing_error", "range_error", "range_fraction_low", "range_fraction_high")
_MOTION_KEYS = ("delay_s", "run_scale", "turn_scale")
#: The physical range of every number of a sensor calibration file (docs/formats.md lists them).
KEY_RANGES: dict[str, Range] = {
    "delay_s": DELAY,
    "run_scale": FACTOR,
    "turn_scale": FACTOR,
    "bearing_error": ANGLE_ERROR,
    "range_error": LENGTH,
    "range_fraction_low": Range(0.0, 1.0, high_open=True),
    "range_fraction_high": Range(0.0, 1.0, high_open=True),
}
_KIND = "aura-ums/sensor-calibration"
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
    range_fraction_low, range_fraction_high : float
        Fractions of the measured range, in [0, 1).

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
            value = finite_float(getattr(self, name), f"SensorBounds.{name}")
            if not 0.0 <= value < 1.0:
                raise InputError(f"SensorBounds.{name}: expected a fraction in [0, 1), got {value!r}")
            object.__setattr__(self, name, value)

    def range_interval(self, measured: float) -> tuple[float, float]:
        """Return ``(range_min, range_max)``, metres, of the true range for a measured range (m)."""
        low = max(0.0, measured * (1.0 - self.range_fraction_high) - self.range_error)
        high = measured * (1.0 + self.range_fraction_low) + self.range_error
        return round(low, 12), round(high, 12)

    def widened(self, factor: float) -> SensorBounds:
        """Return these bounds times ``factor`` (>= 1), fractions capped below 1."""
        return SensorBounds(
            self.bearing_error * factor,
            self.range_error * factor,
            min(self.range_fraction_low * factor, 0.95),
            min(self.range_fraction_high * factor, 0.95),
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
    quantile : float
        The quantile the motion and working bounds cover.
    horizon : float
        Window length, seconds, of the motion fit.
    motion_windows, observations : int
        Samples the fit used.
    """

    terrain: str
    stats: TerrainStats
    motion: MotionCalibration
    working: SensorBounds
    envelope: SensorBounds
    quantile: float
    horizon: float
    motion_windows: int
    observations: int

    def terrain_table(self) -> TerrainTable:
        """Return a one-terrain table holding :attr:`stats` under :attr:`terrain`."""
        return TerrainTable({self.terrain: self.stats})

    def sensors_toml(self) -> str:
        """Return the motion calibration and both sensor bounds as TOML (read by :func:`load_sensors`)."""
        lines = [
            f"# aura-ums sensor calibration: quantile {self.quantile!r}, horizon {self.horizon!r} s,",
            f"# {self.motion_windows} motion windows, {self.observations} observations.",
            f'format = "{_KIND}"',
            "",
            "[motion]",
            *(f"{key} = {getattr(self.motion, key)!r}" for key in _MOTION_KEYS),
        ]
        for table, bounds in (("working", self.working), ("envelope", self.envelope)):
            lines += ["", f"[{table}]", *(f"{key} = {getattr(bounds, key)!r}" for key in _SENSOR_KEYS)]
        return "\n".join(lines) + "\n"


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
        or a value out of range.
    """
    source = str(path)
    document = load_toml(path, kind="sensor calibration TOML")
    reader = Fields(source)
    expected = {"format", "motion", "working", "envelope"}
    if set(document) != expected:
        missing, extra = sorted(expected - set(document)), sorted(set(document) - expected)
        raise reader.error("", f"expected keys {sorted(expected)}, got missing {missing}, unknown {extra}")
    if document["format"] != _KIND:
        raise reader.error("format", f"expected {_KIND!r}, got {reader.describe(document['format'])}")

    def table(name: str, keys: tuple[str, ...]) -> dict[str, float]:
        values = reader.table(document[name], f"[{name}]")
        if set(values) != set(keys):
            raise reader.error(f"[{name}]", f"expected keys {list(keys)}, got {sorted(values)}")
        return {key: reader.ranged(values[key], key_path(f"[{name}]", key), KEY_RANGES[key]) for key in keys}

    def build(name: str, keys: tuple[str, ...], make: Callable[..., _T]) -> _T:
        values = table(name, keys)
        try:
            return make(**values)
        except InputError as exc:  # named "SensorBounds.bearing_error": name the key instead
            field, _, message = str(exc).partition(": ")
            raise reader.error(key_path(f"[{name}]", field.rpartition(".")[2]), message) from None

    motion = build("motion", _MOTION_KEYS, MotionCalibration)
    working = build("working", _SENSOR_KEYS, SensorBounds)
    return motion, working, build("envelope", _SENSOR_KEYS, SensorBounds)


# --- the fit ---------------------------------------------------------------------------


def _cumulative_motion(log: RobotLog) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Return the times and cumulative recorded run and turn, before delay and scales (zero-order hold)."""
    if log.odometry is not None:
        time = log.odometry.time
        dt = np.diff(time)
        run = np.concatenate(([0.0], np.cumsum(np.abs(log.odometry.v[:-1]) * dt)))
        turn = np.concatenate(([0.0], np.cumsum(log.odometry.omega[:-1] * dt)))
        return time, run, turn
    assert log.commands is not None
    time = np.array([r.time for r in log.commands], dtype=np.float64)
    run = np.cumsum([r.command.run for r in log.commands], dtype=np.float64)
    turn = np.cumsum([r.command.turn for r in log.commands], dtype=np.float64)
    return time, run, turn


@dataclass(frozen=True, slots=True)
class _Windows:
    recorded_run: NDArray[np.float64]
    recorded_turn: NDArray[np.float64]
    actual_run: NDArray[np.float64]
    actual_turn: NDArray[np.float64]


def _windows(log: RobotLog, delay: float, horizon: float, step: float) -> _Windows:
    assert log.groundtruth is not None
    time, run, turn = _cumulative_motion(log)
    truth = log.groundtruth
    start = max(time[0] + delay, truth.time[0])
    end = min(time[-1] + delay, truth.time[-1])
    if end - start < 2 * horizon:
        empty = np.empty(0)
        return _Windows(empty, empty, empty, empty)
    grid = np.arange(start, end, step)
    lag = max(1, round(horizon / step))
    cum_run = np.interp(grid, time + delay, run)
    cum_turn = np.interp(grid, time + delay, turn)
    x = np.interp(grid, truth.time, truth.x)
    y = np.interp(grid, truth.time, truth.y)
    heading = np.interp(grid, truth.time, np.unwrap(truth.heading))
    return _Windows(
        cum_run[lag:] - cum_run[:-lag],
        cum_turn[lag:] - cum_turn[:-lag],
        np.hypot(x[lag:] - x[:-lag], y[lag:] - y[:-lag]),
        heading[lag:] - heading[:-lag],
    )


def _pool(logs: Sequence[RobotLog], delay: float, horizon: float, step: float) -> _Windows:
    parts = [_windows(log, delay, horizon, step) for log in logs]
    return _Windows(*(np.concatenate([getattr(p, f) for p in parts]) for f in _Windows.__slots__))


def _fit_delay(logs: Sequence[RobotLog], delays: NDArray[np.float64], horizon: float, step: float) -> float:
    # The delay that best aligns recorded and true heading changes (turns carry the timing).
    best, best_cost = 0.0, math.inf
    for delay in delays:
        w = _pool(logs, float(delay), horizon, step)
        if not w.actual_turn.size:
            continue
        cost = float(np.mean((w.recorded_turn - w.actual_turn) ** 2))
        if cost < best_cost:
            best, best_cost = float(delay), cost
    return best


def _ratio_fit(
    actual: NDArray[np.float64], recorded: NDArray[np.float64], quantile: float
) -> tuple[float, float, float]:
    """Scale, loss and sd such that scale*recorded*clip(1 - loss +- 3 sd, 0, 1) covers ``quantile``."""
    if actual.size < 10:
        return 1.0, 0.0, 0.0
    ratio = actual / recorded
    scale = max(float(np.quantile(ratio, quantile)), 1e-6)
    scaled = ratio / scale
    mean = float(np.mean(scaled))
    loss = min(max(0.0, 1.0 - mean), 0.99)
    sd = max(0.0, (1.0 - loss - float(np.quantile(scaled, 1.0 - quantile))) / 3.0)
    return scale, loss, sd


def calibrate_logs(
    logs: Sequence[RobotLog],
    *,
    quantile: float = 0.99,
    horizon: float = 1.0,
    envelope_margin: float = 1.25,
    max_delay: float = 1.0,
) -> Calibration:
    """Estimate terrain statistics, motion delay and scales, and sensor bounds from logs.

    Motion (pooled over the logs, which must share one terrain): the delay is the one in
    ``[0, max_delay]`` (0.05 s steps) that best aligns recorded and true heading changes
    over ``horizon``-second windows. Over the same windows (sampled every 0.05 s):
    ``run_scale`` is the ``quantile`` of actual/recorded run (windows that move), so that
    scaled runs bound actual ones, and ``translation_loss`` / ``translation_sd`` are
    the mean loss and the spread that puts the ``1 - quantile`` shortest runs within
    3 sd; turns likewise (windows that turn more than 0.1 rad/s). ``drift`` is the
    ``quantile`` of the heading change the turn bound leaves unexplained, per metre
    actually run. Skitter and inertial loss are 0 (not separable at this rate).

    Sensors (every observation inside the ground truth's span): the working bounds are
    the ``quantile`` of |bearing error|, and the ``(1 - quantile) / 2`` and ``(1 +
    quantile) / 2`` quantiles of the range error relative to the measured range; the
    envelope bounds are the largest errors seen, times ``envelope_margin``.

    Parameters
    ----------
    logs : sequence of RobotLog
        Logs with ground truth, on the same terrain.
    quantile : float
        In (0.5, 1).
    horizon : float
        Seconds, > 0.
    envelope_margin : float
        >= 1.
    max_delay : float
        Seconds, >= 0.

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
    >>> calibration.terrain, calibration.motion.run_scale <= 1.0, calibration.working.bearing_error < 0.05
    ('floor', True, True)
    >>> calibrate_logs([])
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: logs: expected at least one log with ground truth, got none
    """
    logs = list(logs)
    if not logs:
        raise InputError("logs: expected at least one log with ground truth, got none")
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
    span = finite_float(horizon, "horizon")
    if not span > 0.0:
        raise InputError(f"horizon: expected a positive number of seconds, got {span!r}")
    margin = finite_float(envelope_margin, "envelope_margin")
    if margin < 1.0:
        raise InputError(f"envelope_margin: expected a number >= 1, got {margin!r}")
    delay_limit = finite_float(max_delay, "max_delay")
    if delay_limit < 0.0:
        raise InputError(f"max_delay: expected a number >= 0, got {delay_limit!r}")

    step = 0.05
    delay = _fit_delay(logs, np.arange(0.0, delay_limit + 1e-9, step), span, step)
    w = _pool(logs, delay, span, step)
    moving = w.recorded_run > 0.02 * span
    if moving.sum() < 10:
        raise InputError(
            f"logs: expected at least 10 {span!r}-second windows of motion, got {int(moving.sum())}"
        )
    run_scale, translation_loss, translation_sd = _ratio_fit(w.actual_run[moving], w.recorded_run[moving], q)
    turning = np.abs(w.recorded_turn) > 0.1 * span
    turn_scale, rotation_loss, rotation_sd = _ratio_fit(w.actual_turn[turning], w.recorded_turn[turning], q)
    # Heading change outside the turn bound [scale*turn*low, scale*turn], per metre run.
    low = min(max(1.0 - rotation_loss - 3.0 * rotation_sd, 0.0), 1.0)
    commanded = w.recorded_turn * turn_scale
    lower, upper = np.minimum(commanded * low, commanded), np.maximum(commanded * low, commanded)
    unexplained = np.maximum(0.0, np.maximum(lower - w.actual_turn, w.actual_turn - upper))
    drift = float(np.quantile(unexplained[moving] / np.maximum(w.actual_run[moving], 1e-3), q))
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

    bearing_errors, range_errors = observation_errors(logs)
    if bearing_errors.size < 10:
        raise InputError(
            f"logs: expected at least 10 observations within the ground truth, got {bearing_errors.size}"
        )
    working, envelope = _sensor_bounds(bearing_errors, range_errors, q, margin)
    return Calibration(
        terrains[0],
        stats,
        MotionCalibration(delay, run_scale, turn_scale),
        working,
        envelope,
        q,
        span,
        int(moving.sum()),
        int(bearing_errors.size),
    )


def observation_errors(logs: Sequence[RobotLog]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return the observations' bearing errors (rad) and relative range errors against ground truth.

    Parameters
    ----------
    logs : sequence of RobotLog
        Logs with ground truth; observations outside its span are skipped.

    Returns
    -------
    bearing_errors : ndarray, shape (n,)
        Measured minus true bearing, wrapped to (-pi, pi], radians.
    range_errors : ndarray, shape (k,)
        ``(measured - true) / measured`` for the observations with a range (k <= n).
    """
    bearing: list[NDArray[np.float64]] = []
    ranges: list[NDArray[np.float64]] = []
    for log in logs:
        if log.groundtruth is None or not log.observations:
            continue
        times = np.array([o.time for o in log.observations])
        pose = log.groundtruth.at(times)
        keep = ~np.isnan(pose[:, 0])
        lx = np.array([log.landmark(o.landmark_id).x for o in log.observations])
        ly = np.array([log.landmark(o.landmark_id).y for o in log.observations])
        dx, dy = lx - pose[:, 0], ly - pose[:, 1]
        true_bearing = np.arctan2(dy, dx) - pose[:, 2]
        measured = np.array([o.bearing for o in log.observations])
        error = np.angle(np.exp(1j * (measured - true_bearing)))
        bearing.append(error[keep])
        measured_range = np.array([np.nan if o.range is None else o.range for o in log.observations])
        with_range = keep & ~np.isnan(measured_range) & (measured_range > 0.0)
        ranges.append(
            (measured_range[with_range] - np.hypot(dx, dy)[with_range]) / measured_range[with_range]
        )
    empty = np.empty(0, dtype=np.float64)
    return (
        np.concatenate(bearing) if bearing else empty,
        np.concatenate(ranges) if ranges else empty,
    )


def _sensor_bounds(
    bearing: NDArray[np.float64], ranges: NDArray[np.float64], q: float, margin: float
) -> tuple[SensorBounds, SensorBounds]:
    magnitude = np.abs(bearing)
    working_bearing = max(float(np.quantile(magnitude, q)), 1e-6)
    envelope_bearing = max(float(magnitude.max()) * margin, working_bearing)
    if ranges.size:
        low = max(0.0, -float(np.quantile(ranges, (1.0 - q) / 2.0)))
        high = max(0.0, float(np.quantile(ranges, (1.0 + q) / 2.0)))
        env_low = min(max(0.0, -float(ranges.min())) * margin, 0.95)
        env_high = min(max(0.0, float(ranges.max())) * margin, 0.95)
    else:
        low = high = env_low = env_high = 0.0
    working = SensorBounds(working_bearing, 0.0, min(low, 0.95), min(high, 0.95))
    envelope = SensorBounds(
        envelope_bearing,
        0.0,
        max(env_low, working.range_fraction_low),
        max(env_high, working.range_fraction_high),
    )
    return working, envelope
