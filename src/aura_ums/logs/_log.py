"""The value types of a robot log: metadata, landmarks, observations, odometry and ground truth."""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import (
    ROW_GAP,
    Choice,
    finite_float,
    float_array,
    gap_seconds,
    integer_at_least,
    read_only,
    sequence_of,
)
from aura_ums.errors import InputError, UnknownLandmarkError
from aura_ums.geometry import wrap_angle
from aura_ums.logs._odometry import ReverseMotion, odometry_report_arrays, reports_of
from aura_ums.manager import PositionReport
from aura_ums.uncertainty import Pose, TurnAndRun

#: Seconds: the longest interval between two ground-truth rows interpolated across by
#: default (:attr:`GroundTruth.max_gap`); motion capture records at 50-100 Hz, so a longer
#: interval is a lost track, not a slow sampler.
DEFAULT_MAX_TRUTH_GAP = 0.5


class ObservationKind(Choice):
    """What a log observation measured: a bearing only, or a range and a bearing.

    Examples
    --------
    >>> ObservationKind("range_bearing")
    <ObservationKind.RANGE_BEARING: 'range_bearing'>
    """

    BEARING = "bearing"
    RANGE_BEARING = "range_bearing"


def _text(value: object, name: str, *, empty: bool = False) -> str:
    if not isinstance(value, str):
        raise InputError(f"{name}: expected a string, got {value!r}")
    if not empty and (not value or value != value.strip()):
        raise InputError(f"{name}: expected a non-empty string without surrounding spaces, got {value!r}")
    if not value.isprintable():  # a name is printed: control characters would reach the terminal
        raise InputError(f"{name}: expected printable characters (no line breaks or tabs), got {value!r}")
    return value


def printable(text: str) -> str:
    r"""Return ``text`` with each character that is not printable (a line break, an escape) as ``_``.

    For names made from file names, which may hold what a log's name may not.

    Examples
    --------
    >>> printable("run\n2"), printable("hall")
    ('run_2', 'hall')
    """
    return "".join(c if c.isprintable() else "_" for c in text)


def _bounded(value: object, name: str, *, positive: bool = False) -> float:
    result = finite_float(value, name)
    if positive and result <= 0.0:
        raise InputError(f"{name}: expected a positive number, got {result!r}")
    if result < 0.0:
        raise InputError(f"{name}: expected a non-negative number, got {result!r}")
    return result


@dataclass(frozen=True, slots=True)
class LogMeta:
    """What a robot log says about itself: name, terrain, sensor bounds, motion and start.

    Parameters
    ----------
    name : str
        The log's name.
    terrain : str
        Name of the terrain the robot drives on (a key into a
        :class:`~aura_ums.uncertainty.TerrainTable`).
    bearing_error : float
        Bound on the bearing error, radians, > 0, for observations that give none.
    range_error : float
        Absolute part of the range error bound, metres, >= 0.
    range_error_fraction : float
        Relative part of the range error bound, >= 0: the bound is
        ``range_error + range_error_fraction * range``.
    sensor_forward, sensor_left : float
        Metres: where the landmark sensor sits in the robot frame (x forward, y left);
        bearings and ranges are measured from there, not from the robot's reference point.
    delay_s : float
        Seconds, >= 0, by which the motion rows lag: the motion recorded at ``t``
        happens at ``t + delay_s``.
    run_scale, turn_scale : float
        Factors, > 0, that turn recorded runs and turns into bounds of the actual ones.
    start : Pose or None
        Start pose; None lets the replay take it from the ground truth.
    start_radius : float
        Start position uncertainty, metres, >= 0.
    start_heading_halfwidth : float
        Start heading uncertainty either side, radians, >= 0.
    landmark_z_bottom, landmark_z_top : float
        Heights, metres, of vertical-line landmarks whose row gives none
        (``landmark_z_top >= landmark_z_bottom``).
    source : str
        Citation or provenance text.

    Raises
    ------
    InputError
        "LogMeta.<field>: expected ..., got ..." for a value of the wrong type or out of range.

    Examples
    --------
    >>> LogMeta("hall", bearing_error=0.02).range_bound(4.0)
    0.1
    >>> LogMeta("hall", run_scale=0.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: LogMeta.run_scale: expected a positive number, got 0.0
    """

    name: str
    terrain: str = "floor"
    bearing_error: float = 0.05
    range_error: float = 0.1
    range_error_fraction: float = 0.0
    sensor_forward: float = 0.0
    sensor_left: float = 0.0
    delay_s: float = 0.0
    run_scale: float = 1.0
    turn_scale: float = 1.0
    start: Pose | None = None
    start_radius: float = 0.1
    start_heading_halfwidth: float = 0.05
    landmark_z_bottom: float = 0.0
    landmark_z_top: float = 1.0
    source: str = ""

    def __post_init__(self) -> None:
        _text(self.name, "LogMeta.name", empty=True)
        _text(self.terrain, "LogMeta.terrain")
        _text(self.source, "LogMeta.source", empty=True)
        for name in ("bearing_error", "run_scale", "turn_scale"):
            object.__setattr__(self, name, _bounded(getattr(self, name), f"LogMeta.{name}", positive=True))
        for name in (
            "range_error",
            "range_error_fraction",
            "delay_s",
            "start_radius",
            "start_heading_halfwidth",
        ):
            object.__setattr__(self, name, _bounded(getattr(self, name), f"LogMeta.{name}"))
        for name in ("landmark_z_bottom", "landmark_z_top", "sensor_forward", "sensor_left"):
            object.__setattr__(self, name, finite_float(getattr(self, name), f"LogMeta.{name}"))
        if self.landmark_z_top < self.landmark_z_bottom:
            raise InputError(
                f"LogMeta.landmark_z_top: expected >= landmark_z_bottom ({self.landmark_z_bottom!r}), "
                f"got {self.landmark_z_top!r}"
            )
        if self.start is not None and not isinstance(self.start, Pose):
            raise InputError(f"LogMeta.start: expected a Pose or None, got {type(self.start).__name__}")

    @property
    def sensor_offset(self) -> tuple[float, float]:
        """``(sensor_forward, sensor_left)``, metres: the sensor's place in the robot frame."""
        return self.sensor_forward, self.sensor_left

    def range_bound(self, measured_range: float) -> float:
        """Return the range error bound, metres, for a measured range (metres) given without one."""
        return self.range_error + self.range_error_fraction * measured_range


@dataclass(frozen=True, slots=True)
class LogLandmark:
    """A landmark of a log's landmark list.

    Parameters
    ----------
    id : str
        The id observations name it by (non-empty, no surrounding spaces).
    x, y : float
        Position, metres, world frame.
    position_uncertainty : float
        Radius, metres, >= 0, of where it truly is.
    z_bottom, z_top : float or None
        Heights, metres, of a vertical-line landmark; None takes the log's defaults
        (:attr:`LogMeta.landmark_z_bottom`, :attr:`LogMeta.landmark_z_top`).
    symbol : str
        What it is ("lamppost", "cylinder").

    Examples
    --------
    >>> LogLandmark("6", 0.5, -4.2, position_uncertainty=0.001).symbol
    'landmark'
    >>> LogLandmark("", 0.0, 0.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: LogLandmark.id: expected a non-empty string without surrounding spaces, got ''
    """

    id: str
    x: float
    y: float
    position_uncertainty: float = 0.0
    z_bottom: float | None = None
    z_top: float | None = None
    symbol: str = "landmark"

    def __post_init__(self) -> None:
        _text(self.id, "LogLandmark.id")
        _text(self.symbol, "LogLandmark.symbol")
        object.__setattr__(self, "x", finite_float(self.x, "LogLandmark.x"))
        object.__setattr__(self, "y", finite_float(self.y, "LogLandmark.y"))
        object.__setattr__(
            self,
            "position_uncertainty",
            _bounded(self.position_uncertainty, "LogLandmark.position_uncertainty"),
        )
        for name in ("z_bottom", "z_top"):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, finite_float(value, f"LogLandmark.{name}"))
        if self.z_bottom is not None and self.z_top is not None and self.z_top < self.z_bottom:
            raise InputError(
                f"LogLandmark.z_top: expected >= z_bottom ({self.z_bottom!r}), got {self.z_top!r}"
            )

    def heights(self, meta: LogMeta) -> tuple[float, float]:
        """Return ``(z_bottom, z_top)`` in metres, taking the missing ones from ``meta``."""
        bottom = meta.landmark_z_bottom if self.z_bottom is None else self.z_bottom
        top = meta.landmark_z_top if self.z_top is None else self.z_top
        return bottom, max(top, bottom)


@dataclass(frozen=True, slots=True)
class LogObservation:
    """One landmark measurement of a log, in the robot frame.

    Parameters
    ----------
    time : float
        Seconds.
    landmark_id : str
        Id of the landmark measured (listed in the log's landmarks).
    bearing : float
        Radians from the robot's heading to the landmark, counter-clockwise positive;
        wrapped to (-pi, pi].
    range : float or None
        Horizontal distance, metres, >= 0; None for a bearing-only observation.
    bearing_error : float or None
        Bound on the bearing error, radians, > 0; None takes :attr:`LogMeta.bearing_error`.
    range_error : float or None
        Bound on the range error, metres, >= 0; None takes :meth:`LogMeta.range_bound`.
    line : int
        Line of the row in ``observations.csv`` (or the dataset file it came from), 0 if none.

    Examples
    --------
    >>> obs = LogObservation(2.5, "6", 0.25, range=3.0)
    >>> obs.kind, obs.bearing_bound(LogMeta("hall")), obs.range_bound(LogMeta("hall"))
    (<ObservationKind.RANGE_BEARING: 'range_bearing'>, 0.05, 0.1)
    >>> LogObservation(2.5, "6", 0.25).range_bound(LogMeta("hall")) is None   # bearing only
    True
    """

    time: float
    landmark_id: str
    bearing: float
    range: float | None = None
    bearing_error: float | None = None
    range_error: float | None = None
    line: int = 0

    def __post_init__(self) -> None:
        object.__setattr__(self, "time", finite_float(self.time, "LogObservation.time"))
        _text(self.landmark_id, "LogObservation.landmark_id")
        object.__setattr__(self, "bearing", _wrapped(finite_float(self.bearing, "LogObservation.bearing")))
        if self.range is not None:
            object.__setattr__(self, "range", _bounded(self.range, "LogObservation.range"))
        if self.bearing_error is not None:
            object.__setattr__(
                self,
                "bearing_error",
                _bounded(self.bearing_error, "LogObservation.bearing_error", positive=True),
            )
        if self.range_error is not None:
            object.__setattr__(self, "range_error", _bounded(self.range_error, "LogObservation.range_error"))
        integer_at_least(self.line, "LogObservation.line", 0)

    @classmethod
    def _checked(
        cls,
        time: float,
        landmark_id: str,
        bearing: float,
        range: float | None,
        bearing_error: float | None,
        range_error: float | None,
        line: int,
    ) -> LogObservation:
        """Build one from values a reader has already checked column by column.

        The log reader validates every column at once (finite, in range, a listed
        landmark id); a 10^6-row file then does not check each value a second time here.
        Only the bearing is wrapped, as :meth:`__post_init__` wraps it.
        """
        # One setter call per slot, written out: a loop over them costs twice as much.
        observation = object.__new__(cls)
        _set_time(observation, time)
        _set_landmark_id(observation, landmark_id)
        _set_bearing(observation, _wrapped(bearing))
        _set_range(observation, range)
        _set_bearing_error(observation, bearing_error)
        _set_range_error(observation, range_error)
        _set_line(observation, line)
        return observation

    @property
    def kind(self) -> ObservationKind:
        """:attr:`ObservationKind.RANGE_BEARING` when a range is given, else ``BEARING``."""
        return ObservationKind.BEARING if self.range is None else ObservationKind.RANGE_BEARING

    def bearing_bound(self, meta: LogMeta) -> float:
        """Return the bound on the bearing error, radians: the row's, else ``meta.bearing_error``."""
        return meta.bearing_error if self.bearing_error is None else self.bearing_error

    def range_bound(self, meta: LogMeta) -> float | None:
        """Return the bound on the range error, metres (the row's, else the meta's); None without range."""
        if self.range is None:
            return None
        return meta.range_bound(self.range) if self.range_error is None else self.range_error


def _wrapped(angle: float) -> float:
    """Wrap to (-pi, pi], leaving angles already there exactly as they are."""
    return angle if -math.pi < angle <= math.pi else wrap_angle(angle)


def _series(value: ArrayLike, name: str) -> NDArray[np.float64]:
    array = float_array(value, name)
    if array.ndim != 1:
        raise InputError(f"{name}: expected a 1-D array, got shape {array.shape}")
    return read_only(array.copy())


def _increasing(time: NDArray[np.float64], name: str) -> None:
    if len(time) == 0:
        raise InputError(f"{name}: expected at least one row, got none")
    steps = np.diff(time)
    if np.any(steps <= 0.0):
        row = int(np.argmax(steps <= 0.0)) + 1
        raise InputError(
            f"{name}: expected strictly increasing times, "
            f"got {float(time[row])!r} after {float(time[row - 1])!r} at row {row}"
        )


def _same_length(name: str, **columns: NDArray[np.float64]) -> None:
    lengths = {key: len(value) for key, value in columns.items()}
    if len(set(lengths.values())) > 1:
        shown = ", ".join(f"{key} {length}" for key, length in lengths.items())
        raise InputError(f"{name}: expected columns of equal length, got {shown}")


# The slots' own setters in field order (frozen: the dataclass's __setattr__ refuses), for _checked.
_OBSERVATION_SETTERS = tuple(
    LogObservation.__dict__[name].__set__
    for name in ("time", "landmark_id", "bearing", "range", "bearing_error", "range_error", "line")
)
_set_time, _set_landmark_id, _set_bearing, _set_range, _set_bearing_error, _set_range_error, _set_line = (
    _OBSERVATION_SETTERS
)


@dataclass(frozen=True, slots=True, eq=False, init=False)
class Odometry:
    """Recorded forward and angular velocities, held constant from each row to the next.

    Parameters
    ----------
    time : array_like, shape (n,)
        Seconds, strictly increasing, n >= 1.
    v : array_like, shape (n,)
        Forward velocity, m/s, held from ``time[i]`` until ``time[i + 1]`` (zero-order hold).
        The last row only marks the end of the record.
    omega : array_like, shape (n,)
        Angular velocity, rad/s, counter-clockwise positive, held like ``v``.

    Examples
    --------
    >>> odometry = Odometry([0.0, 1.0, 2.0], [0.5, 0.5, 0.0], [0.0, 0.1, 0.0])
    >>> odometry.time.flags.writeable, odometry.duration
    (False, 2.0)
    >>> Odometry([0.0, 0.0], [0.5, 0.5], [0.0, 0.0])
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: Odometry.time: expected strictly increasing times, got 0.0 after 0.0 at row 1
    """

    time: NDArray[np.float64]
    v: NDArray[np.float64]
    omega: NDArray[np.float64]

    def __init__(self, time: ArrayLike, v: ArrayLike, omega: ArrayLike) -> None:
        for name, value in (("time", time), ("v", v), ("omega", omega)):
            object.__setattr__(self, name, _series(value, f"Odometry.{name}"))
        _same_length("Odometry", time=self.time, v=self.v, omega=self.omega)
        _increasing(self.time, "Odometry.time")

    def __len__(self) -> int:
        return len(self.time)

    @property
    def duration(self) -> float:
        """Seconds from the first row to the last."""
        return float(self.time[-1] - self.time[0])


@dataclass(frozen=True, slots=True, eq=False, init=False)
class GroundTruth:
    """The true poses of the robot (e.g. from a motion-capture system), time-stamped.

    Parameters
    ----------
    time : array_like, shape (n,)
        Seconds, strictly increasing, n >= 1.
    x, y : array_like, shape (n,)
        Position, metres, world frame.
    heading : array_like, shape (n,)
        Radians counter-clockwise from +x; stored wrapped to (-pi, pi].
    max_gap : float
        Seconds, > 0 (``math.inf`` for no limit): the longest interval between two rows
        that :meth:`at` interpolates across. Times strictly inside a longer interval are a
        gap in the record (a lost motion-capture track, say) and get no pose; default
        0.5 s.

    Examples
    --------
    >>> import math
    >>> truth = GroundTruth([0.0, 1.0], [0.0, 2.0], [0.0, 0.0], [3.0, -3.0], max_gap=2.0)
    >>> pose = truth.at([0.5, 2.0])     # the heading turns through pi, not through 0
    >>> bool(abs(pose[0, 2]) == math.pi), bool(np.isnan(pose[1]).all())
    (True, True)
    >>> GroundTruth([0.0, 1.0], [0.0, 2.0], [0.0, 0.0], [0.0, 0.0]).at([0.0, 0.5, 1.0])[:, 0]
    array([ 0., nan,  2.])
    """

    time: NDArray[np.float64]
    x: NDArray[np.float64]
    y: NDArray[np.float64]
    heading: NDArray[np.float64]
    max_gap: float
    _unwrapped: NDArray[np.float64] = field(init=False, repr=False)

    def __init__(
        self,
        time: ArrayLike,
        x: ArrayLike,
        y: ArrayLike,
        heading: ArrayLike,
        *,
        max_gap: float = DEFAULT_MAX_TRUTH_GAP,
    ) -> None:
        for name, value in (("time", time), ("x", x), ("y", y), ("heading", heading)):
            object.__setattr__(self, name, _series(value, f"GroundTruth.{name}"))
        object.__setattr__(self, "max_gap", gap_seconds(max_gap, "GroundTruth.max_gap"))
        _same_length("GroundTruth", time=self.time, x=self.x, y=self.y, heading=self.heading)
        _increasing(self.time, "GroundTruth.time")
        outside = (self.heading <= -math.pi) | (self.heading > math.pi)
        if np.any(outside):
            heading = self.heading.copy()
            heading[outside] = wrap_angle(heading[outside])
            object.__setattr__(self, "heading", read_only(heading))
        object.__setattr__(self, "_unwrapped", read_only(np.unwrap(self.heading)))

    def __len__(self) -> int:
        return len(self.time)

    def at(self, times: ArrayLike) -> NDArray[np.float64]:
        """Interpolate the pose at ``times``.

        Parameters
        ----------
        times : array_like, shape (n,) or scalar
            Seconds, finite.

        Returns
        -------
        ndarray, shape (n, 3)
            Rows of x (m), y (m), heading (rad, wrapped to (-pi, pi]) interpolated
            linearly (the heading along the shorter way round); NaN rows for times outside
            ``[time[0], time[-1]]`` and for times strictly inside a gap (two rows more than
            :attr:`max_gap` apart).
        """
        query = float_array(times, "times").reshape(-1)
        out = np.empty((len(query), 3))
        out[:, 0] = np.interp(query, self.time, self.x)
        out[:, 1] = np.interp(query, self.time, self.y)
        out[:, 2] = wrap_angle(np.interp(query, self.time, self._unwrapped))
        out[(query < self.time[0]) | (query > self.time[-1])] = np.nan
        out[self._in_gap(query)] = np.nan
        return out

    def _in_gap(self, query: NDArray[np.float64]) -> NDArray[np.bool_]:
        """Whether each query time lies strictly between two rows more than ``max_gap`` apart."""
        after = np.searchsorted(self.time, query, side="right")
        inner = (after > 0) & (after < len(self.time))
        gap = np.zeros(len(query), dtype=bool)
        before = after[inner] - 1
        gap[inner] = (self.time[before + 1] - self.time[before] > self.max_gap) & (
            query[inner] > self.time[before]
        )
        return gap

    def with_max_gap(self, max_gap: float) -> GroundTruth:
        """Return this record with another :attr:`max_gap` (seconds, > 0, or ``math.inf``)."""
        return GroundTruth(self.time, self.x, self.y, self.heading, max_gap=max_gap)


def unaligned_spans(spans: Sequence[tuple[str, float, float]]) -> str | None:
    """Return why records of one run disagree in their clocks, or None.

    ``spans``: each record's name (a file, a topic), first and last time, seconds. Two
    records more than a day (``ROW_GAP``) apart are a clock offset between them.
    """
    for (name, start, end), (other, other_start, other_end) in itertools.combinations(spans, 2):
        gap = max(start - other_end, other_start - end)
        if gap > ROW_GAP.high:
            return (
                f"expected the times of {name} and {other} to overlap (at most "
                f"{ROW_GAP.high:g} s apart), "
                f"got {start:.17g} to {end:.17g} s and {other_start:.17g} to {other_end:.17g} s, "
                f"{gap:.6g} s apart: a clock offset between them"
            )
    return None


@dataclass(frozen=True, slots=True, eq=False)
class RobotLog:
    """A recorded run of a robot: its motion, its landmark observations and the landmarks.

    Read one with :func:`load_log`, write one with :func:`write_log`; the folder format is
    described in ``docs/log-format.md``.

    Parameters
    ----------
    meta : LogMeta
        Name, terrain, bounds and start.
    landmarks : sequence of LogLandmark
        The landmarks observations may name; ids unique.
    observations : sequence of LogObservation
        Sorted by time (equal times allowed: several landmarks per frame), each naming a
        listed landmark.
    odometry : Odometry or None
        Recorded velocities; exactly one of ``odometry`` and ``commands``.
    commands : sequence of PositionReport or None
        Recorded motions, each executed ending at its time; times strictly increasing.
    groundtruth : GroundTruth or None
        True poses, when known.
    path : Path or None
        The folder the log was loaded from.

    Raises
    ------
    InputError
        For values of the wrong type, both or neither of odometry and commands, duplicate
        landmark ids, unsorted observations or observations of unknown landmarks.

    Examples
    --------
    >>> log = RobotLog(
    ...     LogMeta("tiny"),
    ...     (LogLandmark("a", 2.0, 0.0),),
    ...     (LogObservation(0.5, "a", 0.0, range=2.0),),
    ...     odometry=Odometry([0.0, 1.0], [1.0, 0.0], [0.0, 0.0]),
    ... )
    >>> [(r.time, r.command.run) for r in log.position_reports([0.5], max_interval=1.0)]
    [(0.5, 0.5), (1.0, 0.5)]
    >>> log.landmark("b")
    Traceback (most recent call last):
    ...
    aura_ums.errors.UnknownLandmarkError: landmark_id: expected one of the log's landmark ids (a), got 'b'
    """

    meta: LogMeta
    landmarks: tuple[LogLandmark, ...]
    observations: tuple[LogObservation, ...]
    odometry: Odometry | None = None
    commands: tuple[PositionReport, ...] | None = None
    groundtruth: GroundTruth | None = None
    path: Path | None = None
    _by_id: dict[str, LogLandmark] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if not isinstance(self.meta, LogMeta):
            raise InputError(f"RobotLog.meta: expected a LogMeta, got {type(self.meta).__name__}")
        landmarks = sequence_of(self.landmarks, LogLandmark, "RobotLog.landmarks")
        observations = sequence_of(self.observations, LogObservation, "RobotLog.observations")
        object.__setattr__(self, "landmarks", landmarks)
        object.__setattr__(self, "observations", observations)
        by_id: dict[str, LogLandmark] = {}
        for index, landmark in enumerate(landmarks):
            if landmark.id in by_id:
                raise InputError(
                    f"RobotLog.landmarks[{index}]: expected a unique id, got {landmark.id!r} again"
                )
            by_id[landmark.id] = landmark
        object.__setattr__(self, "_by_id", by_id)
        previous = -math.inf
        for index, observation in enumerate(observations):
            if observation.landmark_id not in by_id:
                raise InputError(
                    f"RobotLog.observations[{index}]: expected a landmark id listed in landmarks, "
                    f"got {observation.landmark_id!r}"
                )
            if observation.time < previous:
                raise InputError(
                    f"RobotLog.observations[{index}]: expected times in order, "
                    f"got {observation.time!r} after {previous!r}"
                )
            previous = observation.time
        if (self.odometry is None) == (self.commands is None):
            got = "both" if self.odometry is not None else "neither"
            raise InputError(f"RobotLog: expected exactly one of odometry and commands, got {got}")
        if self.odometry is not None and not isinstance(self.odometry, Odometry):
            raise InputError(
                f"RobotLog.odometry: expected an Odometry or None, got {type(self.odometry).__name__}"
            )
        if self.commands is not None:
            commands = sequence_of(self.commands, PositionReport, "RobotLog.commands")
            for index in range(1, len(commands)):
                before, after = commands[index - 1], commands[index]
                if after.time <= before.time:
                    raise InputError(
                        f"RobotLog.commands[{index}]: expected strictly increasing times, "
                        f"got {after.time!r} after {before.time!r}"
                    )
            object.__setattr__(self, "commands", commands)
        if self.groundtruth is not None and not isinstance(self.groundtruth, GroundTruth):
            raise InputError(
                f"RobotLog.groundtruth: expected a GroundTruth or None, got {type(self.groundtruth).__name__}"
            )
        if self.path is not None:
            object.__setattr__(self, "path", Path(self.path))

    def landmark(self, landmark_id: str) -> LogLandmark:
        """Return the landmark with id ``landmark_id``.

        Raises
        ------
        UnknownLandmarkError
            (an :class:`InputError` and a ``KeyError``) naming the id when the log lists no
            such landmark.
        """
        try:
            return self._by_id[landmark_id]
        except KeyError:
            known = ", ".join(list(self._by_id)[:20]) + (", ..." if len(self._by_id) > 20 else "")
            raise UnknownLandmarkError(
                f"landmark_id: expected one of the log's landmark ids ({known}), got {landmark_id!r}"
            ) from None

    @property
    def motion_span(self) -> tuple[float, float]:
        """First and last time, seconds, of the motion record (delay not applied).

        For a commands log without commands, ``(nan, nan)``.
        """
        if self.odometry is not None:
            return float(self.odometry.time[0]), float(self.odometry.time[-1])
        assert self.commands is not None
        if not self.commands:
            return math.nan, math.nan
        return self.commands[0].time, self.commands[-1].time

    def unaligned_clocks(self, names: Mapping[str, str]) -> str | None:
        """Return why the record's clocks disagree, or None when they agree.

        Motion, observations and ground truth are of one run: a record that starts more
        than a day (``ROW_GAP``) after another ends is a clock offset between the files
        (a whole file shifted 30 days was imported and replayed as a run without sightings).
        ``names`` names each record in the message: ``"motion"``, ``"observations"`` and
        ``"ground truth"`` to a file or topic.
        """
        spans: list[tuple[str, float, float]] = []
        first, last = self.motion_span
        if not math.isnan(first):
            spans.append((names["motion"], first, last))
        if self.observations:
            spans.append((names["observations"], self.observations[0].time, self.observations[-1].time))
        if self.groundtruth is not None:
            truth = self.groundtruth.time
            spans.append((names["ground truth"], float(truth[0]), float(truth[-1])))
        return unaligned_spans(spans)

    def position_reports(
        self,
        cut_times: ArrayLike = (),
        *,
        max_interval: float = 0.25,
        start: float | None = None,
        end: float | None = None,
        reverse: ReverseMotion = ReverseMotion.ERROR,
    ) -> tuple[PositionReport, ...]:
        """Turn the log's motion into position reports (see :func:`odometry_to_commands`).

        Odometry is delayed by ``meta.delay_s``, integrated and cut at every time of
        ``cut_times`` within ``(start, end]`` and at least every ``max_interval`` seconds;
        each report is ``TurnAndRun(turn_scale * integral(omega), run_scale * integral(|v|))``.
        Recorded commands are delayed the same way, scaled by ``meta.turn_scale`` and
        ``meta.run_scale`` and kept when their (delayed) time is in ``(start, end]``;
        ``cut_times``, ``max_interval`` and ``reverse`` do not apply to them.

        Parameters
        ----------
        cut_times : array_like, shape (k,)
            Seconds at which a report must end (e.g. the observation times).
        max_interval : float
            Longest time, seconds (> 0, inf for none), a report may cover.
        start, end : float or None
            Seconds; default the first and last (delayed) motion time.
        reverse : ReverseMotion
            What to do with negative forward velocities (odometry only).

        Returns
        -------
        tuple of PositionReport
            Runs >= 0; times increasing (strictly, except for the ``ReverseMotion.FLIP`` pairs).
        """
        if self.odometry is None:
            assert self.commands is not None
            # Not applied to recorded commands, but checked all the same: a bad value is a mistake.
            float_array(cut_times, "cut_times")
            gap_seconds(max_interval, "max_interval")
            if not isinstance(reverse, ReverseMotion):
                raise InputError(f"reverse: expected a ReverseMotion, got {reverse!r}")
            low, high = self._span(start, end)
            meta = self.meta
            reports = []
            for report in self.commands:
                time = report.time + meta.delay_s
                if low < time <= high:
                    command = TurnAndRun(
                        report.command.turn * meta.turn_scale, report.command.run * meta.run_scale
                    )
                    reports.append(PositionReport(time, command))
            return tuple(reports)
        return tuple(
            reports_of(
                *self.position_report_arrays(
                    cut_times, max_interval=max_interval, start=start, end=end, reverse=reverse
                )
            )
        )

    def position_report_arrays(
        self,
        cut_times: ArrayLike = (),
        *,
        max_interval: float = 0.25,
        start: float | None = None,
        end: float | None = None,
        reverse: ReverseMotion = ReverseMotion.ERROR,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Return :meth:`position_reports` as three arrays: no Python object per report.

        A long log's replay builds each report only when it posts it
        (:func:`~aura_ums.logs.odometry_report_arrays`).

        Returns
        -------
        times, turns, runs : ndarray, shape (m,)
            Seconds, radians, metres (>= 0): report ``i`` is
            ``PositionReport(times[i], TurnAndRun(turns[i], runs[i]))``.

        Examples
        --------
        >>> log = RobotLog(LogMeta("tiny"), (), (), odometry=Odometry([0.0, 1.0], [1.0, 0.0], [0.0, 0.0]))
        >>> [array.tolist() for array in log.position_report_arrays([0.5], max_interval=1.0)]
        [[0.5, 1.0], [0.0, 0.0], [0.5, 0.5]]
        >>> [array.tolist() for array in log.position_report_arrays(start=1.0)]   # nothing after 1 s
        [[], [], []]
        """
        meta = self.meta
        if self.odometry is not None:
            return odometry_report_arrays(
                self.odometry.time,
                self.odometry.v,
                self.odometry.omega,
                cut_times,
                max_interval=max_interval,
                delay_s=meta.delay_s,
                run_scale=meta.run_scale,
                turn_scale=meta.turn_scale,
                start=start,
                end=end,
                reverse=reverse,
            )
        reports = self.position_reports(
            cut_times, max_interval=max_interval, start=start, end=end, reverse=reverse
        )
        return (
            np.array([report.time for report in reports], dtype=np.float64),
            np.array([report.command.turn for report in reports], dtype=np.float64),
            np.array([report.command.run for report in reports], dtype=np.float64),
        )

    @staticmethod
    def _span(start: float | None, end: float | None) -> tuple[float, float]:
        low = -math.inf if start is None else finite_float(start, "start")
        high = math.inf if end is None else finite_float(end, "end")
        if high < low:
            raise InputError(f"end: expected a time >= start ({low!r}), got {high!r}")
        return low, high
