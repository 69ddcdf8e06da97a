"""Replay a robot log through the uncertainty map manager and measure it against ground truth."""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import math
import os
import time as _time
import types
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TextIO, TypeVar

import numpy as np
from numpy.typing import NDArray

from aura_ums._files import as_path, atomic_path
from aura_ums._metrics import STEPS_CSV, Metrics
from aura_ums._validate import ACTIVATION_RANGE, exact_text, finite_float, nonnegative_float, positive_float
from aura_ums.errors import FileFormatError, InputError
from aura_ums.geometry import POSITION_TOLERANCE, ConvexPolygon, edge_distances, polygon_area, wedges_contain
from aura_ums.logs._calibrate import MotionCalibration, SensorBounds
from aura_ums.logs._io import ODOMETRY, _given, reversed_at
from aura_ums.logs._log import GroundTruth, LogLandmark, LogMeta, LogObservation, RobotLog, _wrapped
from aura_ums.logs._odometry import ReverseMotion, ReversingError
from aura_ums.logs._state import ReplayState
from aura_ums.logs._stream import LogStream, OdometryReports, TruthWindow
from aura_ums.manager import (
    Blackboard,
    ManagerSettings,
    ManagerState,
    PositionReport,
    RejectReason,
    UncertaintyMapManager,
)
from aura_ums.uncertainty import (
    BearingObservation,
    LandmarkClass,
    Observation,
    PointLandmark,
    Pose,
    RangeBearingObservation,
    SpatialUncertaintyMap,
    TerrainTable,
    TurnAndRun,
    VerticalLineLandmark,
)
from aura_ums.world import LandmarkRecord, Meadow, MeadowMap, PerceptualStrategy

LogT = TypeVar("LogT", RobotLog, LogStream)

_REPLAY_CLASSES = (LandmarkClass.VERTICAL_LINE, LandmarkClass.POINT)

#: :func:`replay_log`'s ``before_frame``: called with a frame's time (s), the working map grown
#: to it (before the frame's observations reduce it), the frame's log rows, and the focus map
#: grown to it (:attr:`~aura_ums.manager.UncertaintyMapManager.focus_map`).
FrameHook = Callable[[float, SpatialUncertaintyMap, Sequence[LogObservation], SpatialUncertaintyMap], None]

# Header of the per-step CSV (``replay --steps-csv``): the metrics table's columns of that file.
STEPS_CSV_HEADER = ",".join(key.name for key in Metrics.table() if STEPS_CSV in key.written_by)

# Steps judged against the ground truth together (and written to the per-step CSV together):
# numpy over many maps at once costs far less than a call per map; the buffer stays small.
_CHUNK = 1024
# Polygons of more vertices are judged one by one (Polygon.contains' own dense branch holds
# up to 4096 point-edge pairs: below that, the batched arithmetic is the same, bit for bit).
_BATCHED_VERTICES = 1024
_STATES = tuple(ManagerState)
_STATE_INDEX = {state: index for index, state in enumerate(_STATES)}
_STATE_VALUES = tuple(state.value for state in _STATES)  # an enum's value is a property: read once
# HeadingWedge.width caps a wedge at the full circle.
_FULL_CIRCLE = 2.0 * math.pi


@dataclass(frozen=True, slots=True)
class ReplayOptions:
    """How :func:`replay_log` runs a log: the manager's settings and how the log is read.

    Parameters
    ----------
    settings : ManagerSettings
        The map manager's settings (sigmas, joint reduction, vertex caps, outlier
        recovery, ...); ``settings.envelope_factor`` also widens the working sensor bounds
        into the envelope's when ``envelope`` is None.
    landmark_class : LandmarkClass
        ``VERTICAL_LINE`` (Class I: bearings only) or ``POINT`` (Class II: range and bearing).
    max_interval : float
        Longest motion, seconds, grown in one position report (> 0).
    working : SensorBounds or None
        Typical sensor bounds of the working map; None takes the log's ``meta.toml``
        (``bearing_error``, ``range_error``, ``range_error_fraction`` both ways). Bounds a
        row of ``observations.csv`` gives itself take precedence.
    envelope : SensorBounds or None
        Worst-case bounds of the envelope map; None: the working bounds widened by
        ``settings.envelope_factor``.
    motion : MotionCalibration or None
        Delay and scales of the recorded motion; None takes the log's ``meta.toml``.
    reverse : ReverseMotion
        What to do with negative forward velocities (:class:`ReverseMotion`; default: refuse).
    arena_margin : float
        Metres, >= 0, by which the one meadow of the replay (the log's terrain) extends
        beyond the landmarks, the start and the ground truth.

    Examples
    --------
    >>> ReplayOptions(landmark_class=LandmarkClass.POINT).landmark_class.value
    'II'
    >>> ReplayOptions(settings=ManagerSettings(robust=False)).settings.robust
    False
    >>> ReplayOptions(landmark_class=LandmarkClass.GROUND_LINE)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: ReplayOptions.landmark_class: expected ... (Class II), got GROUND_LINE
    >>> ReplayOptions(landmark_class="II")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: ReplayOptions.landmark_class: expected ..., got 'II' (str)
    """

    settings: ManagerSettings = field(default_factory=ManagerSettings)
    landmark_class: LandmarkClass = LandmarkClass.VERTICAL_LINE
    max_interval: float = 0.25
    working: SensorBounds | None = None
    envelope: SensorBounds | None = None
    motion: MotionCalibration | None = None
    reverse: ReverseMotion = ReverseMotion.ERROR
    arena_margin: float = 5.0

    def __post_init__(self) -> None:
        if not isinstance(self.settings, ManagerSettings):
            raise InputError(
                f"ReplayOptions.settings: expected ManagerSettings, got {type(self.settings).__name__}"
            )
        _require_replay_class(self.landmark_class, "ReplayOptions.landmark_class")
        object.__setattr__(
            self, "max_interval", positive_float(self.max_interval, "ReplayOptions.max_interval")
        )
        margin = finite_float(self.arena_margin, "ReplayOptions.arena_margin")
        if margin < 0.0:
            raise InputError(f"ReplayOptions.arena_margin: expected a number >= 0, got {margin!r}")
        for name in ("working", "envelope"):
            value = getattr(self, name)
            if value is not None and not isinstance(value, SensorBounds):
                raise InputError(
                    f"ReplayOptions.{name}: expected SensorBounds or None, got {type(value).__name__}"
                )
        if not isinstance(self.reverse, ReverseMotion):
            raise InputError(f"ReplayOptions.reverse: expected a ReverseMotion, got {self.reverse!r}")
        if self.motion is not None and not isinstance(self.motion, MotionCalibration):
            raise InputError(
                f"ReplayOptions.motion: expected MotionCalibration or None, got {type(self.motion).__name__}"
            )


@dataclass(frozen=True, slots=True, eq=False)
class ReplayStep:
    """One time step of a replay: a camera frame (the observations sharing a time stamp).

    Attributes
    ----------
    time : float
        Seconds.
    map : SpatialUncertaintyMap
        The working map after the frame's observations.
    truth : Pose or None
        The ground-truth pose at ``time`` (None outside the ground truth).
    inside : bool or None
        Whether ``truth`` is inside ``map`` (None without truth).
    accepted, rejected : int
        Observations of the frame that reduced the map, and that were rejected.
    update_us : float
        Microseconds of the update (growth since the previous frame, and the reductions).
    state : ManagerState
        The manager's state.
    relocalized : bool
        Whether the working map was re-seeded from the envelope at this step.
    envelope_inside : bool or None
        Whether ``truth`` is inside the envelope map (None without truth or envelope).
    excluded : int
        Observations the relaxed intersection excluded at this step (``relaxed_q > 0``).

    Examples
    --------
    >>> from aura_ums.logs import synthetic_log
    >>> log = synthetic_log(np.random.default_rng(0), duration=5.0)
    >>> step = replay_log(log, TerrainTable({"floor": TerrainTable.default()["tile"]})).steps[0]
    >>> step.time, step.inside, step.accepted, step.rejected, step.state
    (0.3, True, 1, 0, <ManagerState.NOMINAL: 'nominal'>)
    >>> blind = ReplayStep(1.0, step.map, None, None, 0, 0, 0.0, ManagerState.NOMINAL)  # no truth
    >>> blind.inside, ReplayTrace.of_steps([blind]).inside.tolist()     # not judged: -1 in a trace
    (None, [-1])
    """

    time: float
    map: SpatialUncertaintyMap
    truth: Pose | None
    inside: bool | None
    accepted: int
    rejected: int
    update_us: float
    state: ManagerState
    relocalized: bool = False
    envelope_inside: bool | None = None
    excluded: int = 0


def _flags(values: Sequence[bool | None]) -> NDArray[np.int8]:
    return np.array([-1 if value is None else int(value) for value in values], dtype=np.int8)


@dataclass(frozen=True, slots=True, eq=False)
class ReplayTrace:
    """The figures of every step of a replay, column by column: all the metrics and the per-step CSV need.

    A few numbers a step, whatever the size of its map: a replay of 10^5 frames keeps
    about 10 MB here, where one map per step would take gigabytes.

    Attributes
    ----------
    time : ndarray, shape (n,)
        Seconds, one per frame, in time order.
    truth : ndarray, shape (n, 3)
        Ground-truth x (m), y (m), heading (rad) at each step; NaN rows without truth.
    inside, envelope_inside : ndarray of int8, shape (n,)
        1 when the truth is inside the working (envelope) map, 0 when not, -1 when not
        judged (no truth; for the envelope, no envelope map either).
    area_m2, wedge_width_rad : ndarray, shape (n,)
        The working map's area (m^2) and heading wedge width (rad) after the step.
    accepted, rejected : ndarray of int64, shape (n,)
        Observations of the step that reduced the map, and that were rejected.
    update_us : ndarray, shape (n,)
        Microseconds of each update.
    state : ndarray of int8, shape (n,)
        Index of the manager's state into ``tuple(ManagerState)`` (:attr:`states` gives them).
    relocalized : ndarray of bool, shape (n,)
        Whether the working map was re-seeded from the envelope at the step.
    excluded : ndarray of int64, shape (n,)
        Observations the relaxed intersection excluded at the step (``relaxed_q > 0``).

    Examples
    --------
    >>> from aura_ums.logs import synthetic_log
    >>> log = synthetic_log(np.random.default_rng(0), duration=5.0)
    >>> table = TerrainTable({"floor": TerrainTable.default()["tile"]})
    >>> trace = replay_log(log, table, keep_maps=False).trace
    >>> len(trace), trace.inside.tolist().count(1), trace.states()[0].value
    (16, 16, 'nominal')
    >>> trace.truth_pose(0) == Pose(*trace.truth[0])
    True
    >>> blank = ReplayTrace.empty(1)                  # nothing filled in: no truth, not judged
    >>> blank.truth_pose(0), blank.csv_lines()
    (None, ['0.0,,0.0,0.0,0,0,0.000,nominal,0'])
    """

    time: NDArray[np.float64]
    truth: NDArray[np.float64]
    inside: NDArray[np.int8]
    envelope_inside: NDArray[np.int8]
    area_m2: NDArray[np.float64]
    wedge_width_rad: NDArray[np.float64]
    accepted: NDArray[np.int64]
    rejected: NDArray[np.int64]
    update_us: NDArray[np.float64]
    state: NDArray[np.int8]
    relocalized: NDArray[np.bool_]
    excluded: NDArray[np.int64]

    def __len__(self) -> int:
        return len(self.time)

    @classmethod
    def empty(cls, count: int) -> ReplayTrace:
        """Return a trace of ``count`` steps to fill in (zeros; truth NaN, not judged)."""
        return cls(
            np.zeros(count),
            np.full((count, 3), np.nan),
            np.full(count, -1, dtype=np.int8),
            np.full(count, -1, dtype=np.int8),
            np.zeros(count),
            np.zeros(count),
            np.zeros(count, dtype=np.int64),
            np.zeros(count, dtype=np.int64),
            np.zeros(count),
            np.zeros(count, dtype=np.int8),
            np.zeros(count, dtype=bool),
            np.zeros(count, dtype=np.int64),
        )

    @classmethod
    def concatenate(cls, traces: Sequence[ReplayTrace]) -> ReplayTrace:
        """Return the steps of ``traces`` one after the other.

        Examples
        --------
        >>> len(ReplayTrace.concatenate([ReplayTrace.empty(2), ReplayTrace.empty(1)]))
        3
        >>> len(ReplayTrace.concatenate([]))
        0
        """
        if not traces:
            return cls.empty(0)
        return cls(
            *(np.concatenate([getattr(trace, name) for trace in traces]) for name in cls.__dataclass_fields__)
        )

    @classmethod
    def of_steps(cls, steps: Sequence[ReplayStep]) -> ReplayTrace:
        """Return the trace of a sequence of :class:`ReplayStep` s.

        Examples
        --------
        >>> ReplayTrace.of_steps(()).inside.tolist()
        []
        """
        trace = cls.empty(len(steps))
        for index, step in enumerate(steps):
            trace.time[index] = step.time
            if step.truth is not None:
                trace.truth[index] = (step.truth.x, step.truth.y, step.truth.heading)
            trace.area_m2[index] = step.map.area
            trace.wedge_width_rad[index] = step.map.wedge.width
            trace.accepted[index] = step.accepted
            trace.rejected[index] = step.rejected
            trace.update_us[index] = step.update_us
            trace.state[index] = _STATES.index(step.state)
            trace.relocalized[index] = step.relocalized
            trace.excluded[index] = step.excluded
        trace.inside[:] = _flags([step.inside for step in steps])
        trace.envelope_inside[:] = _flags([step.envelope_inside for step in steps])
        return trace

    def truth_pose(self, index: int) -> Pose | None:
        """Return the ground-truth pose of step ``index``, None without truth."""
        x, y, heading = self.truth[index].tolist()
        return None if math.isnan(x) else Pose(x, y, heading)

    def states(self) -> tuple[ManagerState, ...]:
        """Return the manager's state at each step."""
        return tuple(_STATES[code] for code in self.state.tolist())

    def csv_lines(self, start: int = 0, stop: int | None = None) -> list[str]:
        """Return the per-step CSV rows of steps ``start`` to ``stop`` (columns: ``docs/metrics.md``).

        Floats are ``repr``, ``update_us`` three decimals; ``inside`` is empty without truth.
        """
        last = len(self) if stop is None else stop
        lines = []
        for time, inside, area, width, accepted, rejected, update_us, state, relocalized in zip(
            self.time[start:last].tolist(),
            self.inside[start:last].tolist(),
            self.area_m2[start:last].tolist(),
            self.wedge_width_rad[start:last].tolist(),
            self.accepted[start:last].tolist(),
            self.rejected[start:last].tolist(),
            self.update_us[start:last].tolist(),
            self.state[start:last].tolist(),
            self.relocalized[start:last].tolist(),
            strict=True,
        ):
            judged = "" if inside < 0 else str(inside)
            lines.append(
                f"{time!r},{judged},{area!r},{width!r},{accepted},{rejected},"
                f"{update_us:.3f},{_STATE_VALUES[state]},{int(relocalized)}"
            )
        return lines


@dataclass(frozen=True, slots=True, eq=False)
class ReplayResult:
    """The outcome of :func:`replay_log`.

    Attributes
    ----------
    log : RobotLog or LogStream
        The log replayed (as given: loaded whole, or opened block by block).
    options : ReplayOptions
        How.
    trace : ReplayTrace
        The figures of every step (one per frame, in time order), column by column.
    rejected_counts : Mapping[RejectReason, int]
        Rejected observations by reason.
    relocalizations : int
        Times the working map was re-seeded from the envelope.
    maps : tuple of SpatialUncertaintyMap or None
        The working map after each step when the replay kept them (``keep_maps=True``),
        else None.
    state : ReplayState or None
        Where the replay stopped (the manager and blackboard after its last frame), to
        save and resume from; None when not recorded.
    start_time : float
        The replay's start, s: the motion's first time, or the ground truth's first row
        when that is later (NaN when not known). A replay whose frames all come before it
        has no step.
    early_observations : int
        Observations at or before :attr:`start_time`, which no frame replays (of a log
        opened block by block: those read).
    cut_short : bool
        Whether ``until`` left frames of the log unreplayed (False: the replay reached the
        log's last frame).
    own_bounds : int
        Observations replayed with a bound of their own (an ``observations.csv`` row's
        ``bearing_error`` or ``range_error``), which takes precedence over
        :attr:`ReplayOptions.working` and the meta's.

    Examples
    --------
    >>> from aura_ums.logs import synthetic_log
    >>> log = synthetic_log(np.random.default_rng(0), duration=5.0)
    >>> table = TerrainTable({"floor": TerrainTable.default()["tile"]})
    >>> result = replay_log(log, table)
    >>> len(result.trace), result.containment_rate, result.relocalizations, result.start_time
    (16, 1.0, 0, 0.0)
    >>> len(result.steps) == len(result.maps) == result.metrics()["steps"]
    True
    >>> replay_log(log, table, keep_maps=False).steps  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: ReplayResult.steps: expected ... (keep_maps=True), got one without ...
    """

    log: RobotLog | LogStream
    options: ReplayOptions
    trace: ReplayTrace
    rejected_counts: Mapping[RejectReason, int]
    relocalizations: int
    maps: tuple[SpatialUncertaintyMap, ...] | None = None

    @property
    def steps(self) -> tuple[ReplayStep, ...]:
        """One :class:`ReplayStep` per frame, in time order (built on each access).

        Raises
        ------
        InputError
            When the replay kept no maps (``keep_maps=False``): its figures are in :attr:`trace`.
        """
        if self.maps is None:
            raise InputError(
                "ReplayResult.steps: expected a replay that kept its maps (keep_maps=True), "
                "got one without (its figures are in .trace)"
            )
        trace = self.trace
        inside = trace.inside.tolist()
        envelope = trace.envelope_inside.tolist()
        excluded = trace.excluded.tolist()
        return tuple(
            ReplayStep(
                time,
                step_map,
                trace.truth_pose(index),
                None if inside[index] < 0 else bool(inside[index]),
                accepted,
                rejected,
                update_us,
                state,
                relocalized,
                None if envelope[index] < 0 else bool(envelope[index]),
                excluded[index],
            )
            for index, (time, step_map, accepted, rejected, update_us, state, relocalized) in enumerate(
                zip(
                    trace.time.tolist(),
                    self.maps,
                    trace.accepted.tolist(),
                    trace.rejected.tolist(),
                    trace.update_us.tolist(),
                    trace.states(),
                    trace.relocalized.tolist(),
                    strict=True,
                )
            )
        )

    state: ReplayState | None = None
    start_time: float = math.nan
    early_observations: int = 0
    cut_short: bool = False
    own_bounds: int = 0

    def require_steps(self, until: float | None = None) -> None:
        """Refuse a replay that made no step: its figures would all be undefined.

        A log's frames may all come before the replay's start (a ground truth that begins
        after the last observation) or after ``until`` (the replay's own argument, named in
        the message); a command that reports figures calls this first.

        Raises
        ------
        InputError
            When :attr:`trace` holds no step.

        Examples
        --------
        >>> import dataclasses, numpy as np
        >>> from aura_ums.logs import synthetic_log
        >>> from aura_ums.uncertainty import TerrainTable
        >>> log = synthetic_log(np.random.default_rng(0), duration=2.0)
        >>> table = TerrainTable({"floor": TerrainTable.default()["tile"]})
        >>> replay_log(log, table).require_steps()  # frames after the start: nothing raised
        >>> replay_log(dataclasses.replace(log, observations=()), table).require_steps()  # the edge
        Traceback (most recent call last):
        ...
        aura_ums.errors.InputError: log 'synthetic': expected a frame ... the log has no observation at all
        """
        if self.trace.time.size:
            return
        if until is not None:
            raise InputError(
                f"until: expected a frame (an observation time) between the replay's start "
                f"({exact_text(self.start_time)} s) and {exact_text(until)} s, got none"
            )
        why = (
            "the log has no observation at all"
            if isinstance(self.log, RobotLog) and not self.log.observations
            else "the log has no observation after it (the start is the motion's first time, or the "
            "ground truth's first row when that is later)"
        )
        raise InputError(
            f"log {self.log.meta.name!r}: expected a frame (an observation time) after the replay's start, "
            f"{exact_text(self.start_time)} s, got none: {why}"
        )

    @property
    def containment_rate(self) -> float:
        """Fraction of the steps with ground truth whose truth is inside the map (nan without)."""
        judged = self.trace.inside[self.trace.inside >= 0].astype(bool)
        return float(np.mean(judged)) if judged.size else math.nan

    @property
    def median_area_m2(self) -> float:
        """Median area of the map over the steps, m^2."""
        return float(np.median(self.trace.area_m2)) if len(self.trace) else math.nan

    @property
    def median_wedge_width_rad(self) -> float:
        """Median width of the heading wedge over the steps, radians."""
        return float(np.median(self.trace.wedge_width_rad)) if len(self.trace) else math.nan

    @property
    def inconsistent_observations(self) -> int:
        """Observations rejected, all reasons together."""
        return sum(self.rejected_counts.values())

    @property
    def median_update_us(self) -> float:
        """Median microseconds per step's update."""
        return float(np.median(self.trace.update_us)) if len(self.trace) else math.nan

    def metrics(self) -> Metrics:
        """Return the options and figures of the replay (keys: ``docs/metrics.md``).

        Undefined figures (no steps, no ground truth, no envelope) are ``None``.
        """
        trace = self.trace
        envelope = trace.envelope_inside[trace.envelope_inside >= 0].astype(bool)
        return Metrics(
            {
                "log": self.log.meta.name,
                "landmark_class": self.options.landmark_class.value,
                "sigmas": self.options.settings.sigmas,
                "robust": self.options.settings.robust,
                "joint_above_rad": self.options.settings.joint_above,
                "max_vertices": self.options.settings.max_vertices,
                "envelope_max_vertices": self.options.settings.envelope_max_vertices,
                "steps": len(trace),
                "steps_with_truth": int(np.count_nonzero(trace.inside >= 0)),
                "containment_rate": self.containment_rate,
                "envelope_containment_rate": float(np.mean(envelope)) if envelope.size else None,
                "median_area_m2": self.median_area_m2,
                "median_wedge_width_rad": self.median_wedge_width_rad,
                "accepted_observations": int(trace.accepted.sum()),
                "inconsistent_observations": self.inconsistent_observations,
                "rejected_by_reason": {reason.value: count for reason, count in self.rejected_counts.items()},
                "relocalizations": self.relocalizations,
                "observations_before_start": self.early_observations,
                "slice_width_rad": self.options.settings.slice_width,
                "relaxed_q": self.options.settings.relaxed_q,
                "relaxed_window": self.options.settings.relaxed_window,
                "excluded_observations": int(self.trace.excluded.sum()),
                "median_update_us": self.median_update_us,
            }
        )


def replay_start(log: RobotLog) -> tuple[float, Pose]:
    """Return the replay's start time (s) and start pose: ``meta.start``, else the ground truth's.

    The start time is the later of the motion's first (delayed) time and the ground
    truth's first time (when the start comes from it).

    Raises
    ------
    InputError
        When the log has neither a start pose in its meta nor ground truth.
    """
    first_motion = log.motion_span[0] + log.meta.delay_s
    if log.commands:
        # A command is the motion *ending* at its time: the first one starts a period earlier.
        period = log.commands[1].time - log.commands[0].time if len(log.commands) > 1 else 1e-6
        first_motion -= period
    if log.meta.start is not None:
        return first_motion, log.meta.start
    if log.groundtruth is None:
        raise InputError(
            f"log {log.meta.name!r}: expected a [start] pose in meta.toml or a groundtruth.csv, got neither"
        )
    start = max(first_motion, float(log.groundtruth.time[0]))
    pose = log.groundtruth.at([start])[0]
    return start, _truth_start(log.meta, start, pose, log.groundtruth.max_gap)


def _truth_start(meta: LogMeta, start: float, pose: NDArray[np.float64], max_gap: float) -> Pose:
    """Return the start pose taken from the ground truth at ``start``; refuse one in a gap of it.

    The truth is NaN strictly inside two rows more than ``max_gap`` apart (a lost track)
    and after its last row: the log then has no start pose, and the message says where the
    start fell, and that a motion delay moved it there.
    """
    x, y, heading = (float(value) for value in pose)
    if math.isnan(x):
        delayed = (
            f"; the motion's delay_s ({meta.delay_s:g} s, of the sensors file or meta.toml) "
            "moved the start there"
            if meta.delay_s > 0.0
            else ""
        )
        raise InputError(
            f"log {meta.name!r}: groundtruth.csv: expected a ground-truth pose at the replay's start, "
            f"{exact_text(start)} s (meta.toml gives no [start] pose), got none: the start lies between two "
            f"rows more than {max_gap:g} s apart (--max-truth-gap) or after the last row{delayed}"
        )
    return Pose(x, y, heading)


def _require_replay_class(landmark_class: object, name: str = "landmark_class") -> None:
    """Refuse a class a replay cannot turn log rows into (Class III: ground lines), naming ``name``."""
    if not isinstance(landmark_class, LandmarkClass) or landmark_class not in _REPLAY_CLASSES:
        got = (
            landmark_class.name
            if isinstance(landmark_class, LandmarkClass)
            else f"{landmark_class!r} ({type(landmark_class).__name__})"
        )
        raise InputError(
            f"{name}: expected LandmarkClass.VERTICAL_LINE (Class I) or LandmarkClass.POINT (Class II), "
            f"got {got}"
        )


def log_meadow_map(log: RobotLog, landmark_class: LandmarkClass, *, margin: float = 5.0) -> MeadowMap:
    """Return a meadow map for replaying ``log``: one meadow of its terrain, its landmarks.

    The meadow is the bounding box of the landmarks, the start and the ground truth,
    grown by ``margin`` metres (>= 0) and 1 m more. Landmarks become
    :class:`~aura_ums.uncertainty.VerticalLineLandmark` (Class I, heights from the row or the
    meta) or :class:`~aura_ums.uncertainty.PointLandmark` (Class II, at the row's mid height).

    Examples
    --------
    >>> import dataclasses
    >>> from aura_ums.logs import synthetic_log
    >>> log = synthetic_log(np.random.default_rng(0), duration=5.0)
    >>> world = log_meadow_map(log, LandmarkClass.POINT)
    >>> world.bounds, world.meadows[0].terrain, len(world.landmarks)
    ((-12.5, -12.5, 12.5, 12.5), 'floor', 8)
    >>> world.landmark("L1").landmark
    PointLandmark(id='L1', x=-6.0, y=-6.0, z=1.0, symbol='pole', position_uncertainty=0.01)
    >>> bare = dataclasses.replace(log, landmarks=(), observations=(), groundtruth=None)
    >>> log_meadow_map(bare, LandmarkClass.POINT).bounds          # nothing to hold: around the origin
    (-6.0, -6.0, 6.0, 6.0)
    >>> log_meadow_map(log, LandmarkClass.POINT, margin=-10.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: margin: expected a non-negative number, got -10.0
    """
    if not isinstance(log, RobotLog):
        raise InputError(f"log: expected a RobotLog, got {type(log).__name__}")
    _require_replay_class(landmark_class)
    margin = nonnegative_float(margin, "margin")
    truth = log.groundtruth
    box = None
    if truth is not None:
        box = (float(truth.x.min()), float(truth.y.min()), float(truth.x.max()), float(truth.y.max()))
    return _meadow_map(log.meta, log.landmarks, box, landmark_class, margin)


def _meadow_map(
    meta: LogMeta,
    landmarks: Sequence[LogLandmark],
    truth_box: tuple[float, float, float, float] | None,
    landmark_class: LandmarkClass,
    margin: float,
) -> MeadowMap:
    """:func:`log_meadow_map` from the log's parts (the ground truth's extent, not its rows)."""
    points = [(lm.x, lm.y) for lm in landmarks]
    if meta.start is not None:
        points.append((meta.start.x, meta.start.y))
    if truth_box is not None:
        points += [(truth_box[0], truth_box[1]), (truth_box[2], truth_box[3])]
    xy = np.array(points, dtype=np.float64).reshape(-1, 2)
    if not xy.size:
        xy = np.zeros((1, 2))
    (x0, y0), (x1, y1) = xy.min(axis=0) - margin - 1.0, xy.max(axis=0) + margin + 1.0
    records = []
    for lm in landmarks:
        bottom, top = lm.heights(meta)
        landmark: VerticalLineLandmark | PointLandmark
        if landmark_class is LandmarkClass.VERTICAL_LINE:
            landmark = VerticalLineLandmark(
                lm.id, lm.x, lm.y, bottom, top, lm.symbol, lm.position_uncertainty
            )
        else:
            landmark = PointLandmark(
                lm.id, lm.x, lm.y, (bottom + top) / 2.0, lm.symbol, lm.position_uncertainty
            )
        # Every landmark always awake: a log's sightings come from its own sensor, not from schemas.
        records.append(
            LandmarkRecord(
                landmark, PerceptualStrategy.for_class(landmark_class)[0], {}, ACTIVATION_RANGE.high, 0.0
            )
        )
    arena = ConvexPolygon([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])
    meadow = Meadow("arena", arena, meta.terrain, tuple(lm.id for lm in landmarks))
    return MeadowMap([meadow], records)


def observation_for(
    row: LogObservation,
    landmark_class: LandmarkClass,
    bounds: SensorBounds,
    *,
    factor: float = 1.0,
    sensor_offset: tuple[float, float] = (0.0, 0.0),
) -> Observation:
    """Turn a log row into a bounded observation of the replay's landmark class.

    The row's own ``bearing_error`` / ``range_error`` (absolute, metres) take precedence
    over ``bounds``; ``factor`` (>= 1) widens whichever is used. A row without a range
    gives a bearing observation in a Class II replay too: a bearing to the point landmark
    (:meth:`LandmarkClass.observes <aura_ums.uncertainty.LandmarkClass.observes>`).
    ``sensor_offset`` (forward, left; metres) is where the sensor sits in the robot frame
    (the log's ``meta.sensor_offset``).

    Examples
    --------
    >>> bounds = SensorBounds(0.05, 0.0, 0.1, 0.1)
    >>> row = LogObservation(2.5, "pole", 0.25, range=4.0)
    >>> seen = observation_for(row, LandmarkClass.POINT, bounds)
    >>> type(seen).__name__, seen.bearing_error, seen.range_min, seen.range_max
    ('RangeBearingObservation', 0.05, 3.6, 4.4)
    >>> wide = observation_for(row, LandmarkClass.POINT, bounds, factor=2.0)
    >>> wide.bearing_error, wide.range_min, wide.range_max
    (0.1, 3.2, 4.8)
    >>> no_range = LogObservation(2.5, "pole", 0.25)      # Class II: a bearing to the point
    >>> type(observation_for(no_range, LandmarkClass.POINT, bounds)).__name__
    'BearingObservation'
    >>> observation_for(row, LandmarkClass.POINT, bounds, factor=0.5)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: factor: expected a number >= 1, got 0.5
    """
    if not isinstance(row, LogObservation):
        raise InputError(f"row: expected a LogObservation, got {type(row).__name__}")
    if not isinstance(bounds, SensorBounds):
        raise InputError(f"bounds: expected SensorBounds, got {type(bounds).__name__}")
    _require_replay_class(landmark_class)
    factor = finite_float(factor, "factor")  # an array compared with != 1.0 leaked numpy's ValueError
    if factor < 1.0:
        raise InputError(f"factor: expected a number >= 1, got {factor!r}")
    return _observation_for(row, landmark_class, bounds, factor, sensor_offset)


def _observation_for(
    row: LogObservation,
    landmark_class: LandmarkClass,
    bounds: SensorBounds,
    factor: float,
    sensor_offset: tuple[float, float],
) -> Observation:
    """:func:`observation_for` of checked arguments: a replay's own rows, class and bounds, row by row."""
    bearing_error = (bounds.bearing_error if row.bearing_error is None else row.bearing_error) * factor
    if landmark_class is LandmarkClass.VERTICAL_LINE or row.range is None:
        return BearingObservation(row.landmark_id, row.time, row.bearing, bearing_error, sensor_offset)
    if row.range_error is not None:
        error = row.range_error * factor
        low, high = max(0.0, row.range - error), row.range + error
    else:
        low, high = (bounds.widened(factor) if factor > 1.0 else bounds).range_interval(row.range)
    return RangeBearingObservation(
        row.landmark_id, row.time, row.bearing, bearing_error, low, high, sensor_offset
    )


def _observations(
    rows: Sequence[_Row], bearing_only: bool, bounds: SensorBounds, offset: tuple[float, float]
) -> list[Observation]:
    """:func:`observation_for` of each row (``factor`` 1), without checking again what the log checked."""
    found: list[Observation] = []
    for time, landmark_id, bearing, measured, row_bearing_error, row_range_error in rows:
        bearing_error = bounds.bearing_error if row_bearing_error is None else row_bearing_error
        if bearing_only or measured is None:
            found.append(BearingObservation._trusted(landmark_id, time, bearing, bearing_error, offset))
            continue
        if row_range_error is not None:
            low, high = max(0.0, measured - row_range_error), measured + row_range_error
        else:
            low, high = bounds.range_interval(measured)
        found.append(
            RangeBearingObservation._trusted(landmark_id, time, bearing, bearing_error, low, high, offset)
        )
    return found


def meta_bounds(log: RobotLog | LogStream) -> SensorBounds:
    """Return the sensor bounds a log's ``meta.toml`` states (its range fraction both ways)."""
    meta = log.meta
    return SensorBounds(
        meta.bearing_error, meta.range_error, meta.range_error_fraction, meta.range_error_fraction
    )


def replay_log(
    log: RobotLog | LogStream,
    table: TerrainTable,
    options: ReplayOptions | None = None,
    *,
    before_frame: FrameHook | None = None,
    keep_maps: bool = True,
    steps_csv: str | os.PathLike[str] | None = None,
    progress: Callable[[int, int], None] | None = None,
    until: float | None = None,
    resume: ReplayState | None = None,
    save_state: bool = False,
    after_step: Callable[[ReplayStep], None] | None = None,
) -> ReplayResult:
    """Run the uncertainty map manager over a log, frame by frame, and judge it against ground truth.

    The start map is ``meta.start`` (or the ground truth's first pose) with the meta's
    start uncertainty. The motion becomes position reports cut at every observation time
    and at least every ``max_interval`` seconds (:meth:`RobotLog.position_reports`, with
    the options' :class:`MotionCalibration` when given). Each frame (the observations
    sharing a time stamp) is one step: its observations are posted with the working
    bounds, and their twins under the envelope bounds are given to
    :meth:`~aura_ums.manager.UncertaintyMapManager.update`, which grows the map to the
    frame, reduces it (re-localizing from its envelope when the settings are robust);
    the ground truth at that time is checked against the map.

    With ``before_frame``, each frame's update is made in two: the manager first grows
    the map to the frame's time (an update without observations), ``before_frame`` sees
    that map, then the observations reduce it. The maps are the same as in one update;
    the hook's time is not counted in ``update_us``.

    Memory: the position reports are made one at a time from arrays, and each step
    keeps a few numbers (:class:`ReplayTrace`); only ``keep_maps`` keeps a map per step.
    A :class:`LogStream` (:func:`~aura_ums.logs.open_log`) is read block by block as the
    frames reach its rows, a chunk of frames at a time: its observations, odometry and
    ground truth are never in memory whole, and the replay gives exactly the figures
    (and maps) of the whole log's. It cannot ``resume`` or ``save_state`` (their digest
    covers the whole log: :meth:`LogStream.load` it).

    Parameters
    ----------
    log : RobotLog or LogStream
        The log, loaded whole (:func:`~aura_ums.logs.load_log`) or opened to be read block
        by block (:func:`~aura_ums.logs.open_log`).
    table : TerrainTable
        Must hold the log's terrain (``meta.terrain``).
    options : ReplayOptions or None
        How; default :class:`ReplayOptions`.
    before_frame : callable or None
        Called once per frame, in time order, as ``before_frame(time, grown_map, rows,
        focus_map)``: seconds, the working map grown to ``time``, the frame's
        :class:`LogObservation` s, and the manager's focus map grown to ``time``
        (:attr:`~aura_ums.manager.UncertaintyMapManager.focus_map`: ``grown_map`` itself
        without the relaxed intersection). :func:`~aura_ums.logs.replay_windows` asks the
        Expecter there.
    keep_maps : bool
        Keep the working map of every step (:attr:`ReplayResult.maps`, and
        :attr:`ReplayResult.steps`, which needs them). A long log's replay that only wants
        the figures passes False: its memory then stays a few numbers per step.
    steps_csv : path-like or None
        Write the per-step CSV (the ``replay --steps-csv`` columns of ``docs/metrics.md``,
        one row per step) here, row blocks as the replay makes them: into a hidden scratch
        file beside it, renamed onto it at the end, so a replay that fails or is
        interrupted leaves no partial file under that name. Its folder is created when
        missing.
    progress : callable or None
        Called as ``progress(done, total)`` after each frame (``total`` frames of the log
        after its start; 0 for a :class:`LogStream`, whose frames are counted only as they
        are read); nothing is printed here.
    until : float or None
        Stop after the last frame at or before this time, s (None: replay to the end);
        the result's ``state`` then resumes from there.
    resume : ReplayState or None
        Continue a replay of this same log from a saved :class:`ReplayState` (the
        manager and blackboard as they were, its settings included): the steps are those
        after it, and the last map is bit for bit that of an uninterrupted replay. The
        saved settings replace ``options.settings`` (the result reports them).
    save_state : bool
        Record where the replay stopped (:attr:`ReplayResult.state`, the manager's and
        blackboard's JSON, which grows with the log), to save and resume from.
    after_step : callable or None
        Called after each step, in time order, with its :class:`ReplayStep` (the map, the
        truth judged against it at once), to watch a replay while it computes (the live
        view). Its time is not counted in ``update_us``.

    Returns
    -------
    ReplayResult

    Raises
    ------
    InputError
        For a bad argument, a terrain missing from ``table``, a log without a start, a
        ``resume`` state saved from another log, or an ``until`` before that state's last frame.
    FileFormatError
        When ``steps_csv`` cannot be written.

    Examples
    --------
    >>> from aura_ums.logs import synthetic_log
    >>> log = synthetic_log(np.random.default_rng(3), duration=30.0)
    >>> result = replay_log(log, TerrainTable({"floor": TerrainTable.default()["tile"]}))
    >>> result.containment_rate, result.inconsistent_observations
    (1.0, 0)
    >>> lean = replay_log(log, TerrainTable({"floor": TerrainTable.default()["tile"]}), keep_maps=False)
    >>> lean.maps is None, lean.metrics()["steps"] == len(result.steps)
    (True, True)
    >>> replay_log(log, TerrainTable.default())  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.UnknownTerrainError: table: expected the terrain 'floor' of the log (its meta.toml), ...
    """
    if not isinstance(log, (RobotLog, LogStream)):
        raise InputError(f"log: expected a RobotLog or a LogStream, got {type(log).__name__}")
    if not isinstance(table, TerrainTable):
        raise InputError(f"table: expected a TerrainTable, got {type(table).__name__}")
    opts = ReplayOptions() if options is None else options
    if not isinstance(opts, ReplayOptions):
        raise InputError(f"options: expected ReplayOptions or None, got {type(opts).__name__}")
    table.require(log.meta.terrain, where="table", whose="the log (its meta.toml)")
    if not isinstance(keep_maps, bool):
        raise InputError(f"keep_maps: expected True or False, got {keep_maps!r}")
    if not isinstance(save_state, bool):
        raise InputError(f"save_state: expected True or False, got {save_state!r}")
    if progress is not None and not callable(progress):
        raise InputError(f"progress: expected a callable or None, got {type(progress).__name__}")
    if after_step is not None and not callable(after_step):
        raise InputError(f"after_step: expected a callable or None, got {type(after_step).__name__}")
    if before_frame is not None and not callable(before_frame):
        raise InputError(f"before_frame: expected a callable or None, got {type(before_frame).__name__}")
    if steps_csv is not None:
        as_path(steps_csv, "steps_csv")
    stop = math.inf if until is None else finite_float(until, "until")
    if resume is not None and not isinstance(resume, ReplayState):
        raise InputError(f"resume: expected a ReplayState or None, got {type(resume).__name__}")
    if resume is not None and stop < resume.last_time:
        # Nothing after the state would be replayed: an empty result is no answer.
        raise InputError(
            f"until: expected a time at or after the resumed state's last frame "
            f"({resume.last_time!r} s), got {stop!r}"
        )
    if save_state and opts.settings.anchor_growth:
        # The manager's JSON holds its maps, not the anchors they grow from: resumed, the maps
        # grew from the saved one alone and differed by up to 29% in area (helper-64).
        raise InputError(
            "save_state: expected a replay without anchor_growth (a saved state does not hold the "
            "anchors, so a resumed replay would not end with the map of an uninterrupted one), got "
            "anchor_growth True"
        )
    if isinstance(log, LogStream) and (resume is not None or save_state):
        raise InputError(
            "log: expected a RobotLog (load_log) to resume or save a replay's state "
            "(its digest covers the whole log), got a LogStream"
        )
    log = dataclasses.replace(log, meta=_motion_meta(log.meta, opts.motion))
    working_bounds = opts.working if opts.working is not None else meta_bounds(log)
    source = (
        _stream_source(log, opts, stop, keep_rows=before_frame is not None)
        if isinstance(log, LogStream)
        else _whole_source(log, opts, stop, resume)
    )
    if stop < source.start_time and not save_state:
        # Nothing would be replayed: metrics of no frame are no answer (a state saved before
        # any frame is one: the start map, resumable).
        raise InputError(
            f"until: expected a time at or after the replay's start ({source.start_time!r} s), got {stop!r}"
        )
    initial = SpatialUncertaintyMap.from_pose(
        source.start_pose, log.meta.start_radius, log.meta.start_heading_halfwidth
    )
    manager = UncertaintyMapManager(initial, source.meadow_map, table, opts.settings)
    board = Blackboard()
    if resume is not None:
        _same_inputs(resume, opts, table)
        manager = UncertaintyMapManager.from_json(
            resume.manager_json, source.meadow_map, table, source="resume"
        )
        board = Blackboard.from_json(resume.blackboard_json, source="resume")
        # The saved settings run the rest: the envelope's observations pair with them, and
        # the result reports them (an uninterrupted replay had them from its first frame).
        opts = dataclasses.replace(opts, settings=manager.settings)
    # The manager's counters run from the log's first frame; a resumed replay reports its own
    # frames (its trace's), so the counts it restored are taken off (helper-64: 3 relocalizations
    # reported where its own steps had none).
    rejected_before = dict(manager.rejected_counts)
    relocalized_before = manager.relocalizations
    robust = opts.settings.robust
    envelope_bounds = (
        opts.envelope if opts.envelope is not None else working_bounds.widened(opts.settings.envelope_factor)
    )
    trace = _TraceBuilder()
    maps: list[SpatialUncertaintyMap] = []
    offset = log.meta.sensor_offset
    bearing_only = opts.landmark_class is LandmarkClass.VERTICAL_LINE
    reports = source.reports
    done = source.first
    identified = board.identified
    nominal = _STATES[0]
    own_bounds = 0
    with _StepsCsv(steps_csv) as writer:
        for chunk in source.chunks:
            due_arrays = reports.until(chunk.times)
            # Checked once for the chunk (finite, runs >= 0, in time order), the reports are
            # made at once without checking each again, and each frame's posted in one call;
            # else each is made checked, and a bad one refused as it was.
            checked = _reports_valid(*due_arrays)
            report_times, report_turns, report_runs = (values.tolist() for values in due_arrays)
            due_count = len(report_times)
            next_report = 0
            if checked:
                made = list(map(PositionReport._trusted, report_times, report_turns, report_runs))
                # Where each frame's reports end: those at or before its time (the times are in order).
                cuts = np.searchsorted(due_arrays[0], chunk.times, side="right").tolist()
            count = len(chunk.times)
            part = trace.start(count)
            part.time[:] = chunk.times
            part.truth[:] = source.truth(chunk.times)
            judge = _Judge(part)
            rows, offsets = chunk.rows, chunk.offsets
            # The chunk's observations at once (each frame's are a slice): a call a chunk, not a frame.
            chunk_working = _observations(rows, bearing_only, working_bounds, offset)
            own_bounds += sum(1 for row in rows if row[4] is not None or row[5] is not None)
            chunk_envelope = _observations(rows, bearing_only, envelope_bounds, offset) if robust else None
            # Each step's figures, into the trace's arrays once the chunk is done (or at
            # once for after_step, which reads them).
            update_us, accepted, rejected, states, relocalized, excluded = [], [], [], [], [], []
            for index, frame_time in enumerate(chunk.times.tolist()):
                begin, end = offsets[index], offsets[index + 1]
                working = chunk_working[begin:end]
                envelope = None if chunk_envelope is None else chunk_envelope[begin:end]
                if checked:
                    due = made[next_report : cuts[index]]
                    next_report = cuts[index]
                else:
                    due = []
                    while next_report < due_count and report_times[next_report] <= frame_time:
                        due.append(
                            PositionReport(
                                report_times[next_report],
                                TurnAndRun(report_turns[next_report], report_runs[next_report]),
                            )
                        )
                        next_report += 1
                began = _time.perf_counter()
                if checked:
                    board._post_in_order(due)
                else:
                    for report in due:
                        board.post_report(report)
                if before_frame is not None:
                    grown = manager.update(board, now=frame_time)
                    paused = _time.perf_counter()
                    assert chunk.logged is not None
                    logged = chunk.logged[begin:end]
                    before_frame(frame_time, grown.map, logged, grown.focus)
                    began += _time.perf_counter() - paused
                identified._post_in_order(working)  # a frame's: one time, made by _observations
                step = manager.update(board, now=frame_time, envelope=envelope)
                update_us.append((_time.perf_counter() - began) * 1e6)
                # len(step.accepted) and len(step.rejected), without building either tuple.
                taken = 0
                for outcome in step.outcomes:
                    if outcome.accepted:
                        taken += 1
                accepted.append(taken)
                rejected.append(len(step.outcomes) - taken)
                # An enum's hash is computed in Python: the usual state is told by identity.
                states.append(0 if step.state is nominal else _STATE_INDEX[step.state])
                relocalized.append(step.relocalized)
                excluded.append(len(step.excluded))
                judge.add(index, step.map, step.envelope_map)
                if keep_maps:
                    maps.append(step.map)
                if after_step is not None:
                    _fill(part, index, update_us, accepted, rejected, states, relocalized, excluded)
                    after_step(_step_now(part, index, step.map, step.envelope_map))
                done += 1
                if progress is not None:
                    progress(done, source.total)
            _fill(part, slice(0, count), update_us, accepted, rejected, states, relocalized, excluded)
            judge.flush()
            writer.write(part)
            reports.posted += next_report
            # The reports the manager consumed are not read again (but for the last, which it
            # checks): a long log's replay keeps its memory, not every report since the start.
            board.forget_reports_before(max(board.released_reports, manager.consumed_reports - 1))
            # Nor are this chunk's reports and observations: not held while the next chunk's are made.
            made, chunk_working, chunk_envelope = [], [], None
        source.finish()
    result_trace = trace.build()
    state = None
    if save_state:
        assert isinstance(log, RobotLog)
        assert source.frames is not None
        frame_times = source.frame_times
        last = done
        state = ReplayState(
            log.meta.name,
            last,
            reports.posted,
            float(frame_times[last - 1]) if last else math.nan,
            _digest(source.frames, frame_times[:last]),
            manager.to_json(),
            board.to_json(),
            types.MappingProxyType(_inputs(opts, table)),
        )
    return ReplayResult(
        log,
        opts,
        result_trace,
        types.MappingProxyType(
            {
                reason: count - rejected_before.get(reason, 0)
                for reason, count in manager.rejected_counts.items()
            }
        ),
        manager.relocalizations - relocalized_before,
        tuple(maps) if keep_maps else None,
        state,
        source.start_time,
        source.early[0],
        source.cut[0],
        own_bounds,
    )


def _reports_valid(times: NDArray[np.float64], turns: NDArray[np.float64], runs: NDArray[np.float64]) -> bool:
    """Whether every report's time and turn is finite, its run finite and >= 0 (as checked), in time order."""
    return bool(
        np.isfinite(times).all()
        and np.isfinite(turns).all()
        and np.isfinite(runs).all()
        and (runs >= 0.0).all()
        and (times[1:] >= times[:-1]).all()
    )


def _fill(
    part: ReplayTrace,
    at: int | slice,
    update_us: list[float],
    accepted: list[int],
    rejected: list[int],
    states: list[int],
    relocalized: list[bool],
    excluded: list[int],
) -> None:
    """Write the figures of the chunk's steps so far (``at`` an index: the last step's) into its trace."""
    if isinstance(at, int):
        last = len(update_us) - 1
        part.update_us[at], part.accepted[at], part.rejected[at] = (
            update_us[last],
            accepted[last],
            rejected[last],
        )
        part.state[at], part.relocalized[at], part.excluded[at] = (
            states[last],
            relocalized[last],
            excluded[last],
        )
        return
    part.update_us[at] = update_us
    part.accepted[at] = accepted
    part.rejected[at] = rejected
    part.state[at] = states
    part.relocalized[at] = relocalized
    part.excluded[at] = excluded


# One row of observations.csv as the replay reads it: time (s), landmark id, bearing (rad),
# range (m), bearing_error (rad) and range_error (m), None where not given.
_Row = tuple[float, str, float, "float | None", "float | None", "float | None"]


@dataclass(frozen=True, slots=True, eq=False)
class _FrameChunk:
    """A few frames in time order: their times, and their rows one after the other."""

    times: NDArray[np.float64]
    offsets: list[int]  # frame i's rows are rows[offsets[i] : offsets[i + 1]]
    rows: list[_Row]
    logged: list[LogObservation] | None  # the rows as log rows, for before_frame


class _WholeReports:
    """The position reports of a whole log, made at once (:meth:`RobotLog.position_report_arrays`)."""

    def __init__(
        self, times: NDArray[np.float64], turns: NDArray[np.float64], runs: NDArray[np.float64], posted: int
    ):
        self.times, self.turns, self.runs = times, turns, runs
        self.posted = posted

    def until(self, frames: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
        """Return the reports not posted yet up to the last of ``frames``."""
        stop = int(np.searchsorted(self.times, frames[-1], side="right"))
        begin = self.posted
        return self.times[begin:stop], self.turns[begin:stop], self.runs[begin:stop]

    def finish(self) -> None:
        """Nothing left to read."""


class _StreamReports:
    """:class:`OdometryReports` counting the reports posted."""

    def __init__(self, reports: OdometryReports) -> None:
        self.reports = reports
        self.posted = 0

    def until(self, frames: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
        return self.reports.until(frames)

    def finish(self) -> None:
        self.reports.finish()


@dataclass(slots=True, eq=False)
class _Source:
    """What a replay reads of a log: its start, arena, frames, reports and truth."""

    start_time: float
    start_pose: Pose
    meadow_map: MeadowMap
    chunks: Iterator[_FrameChunk]
    reports: _WholeReports | _StreamReports
    truth: Callable[[NDArray[np.float64]], NDArray[np.float64]]
    total: int  # frames of the log after its start (0 when not known before the end)
    first: int = 0  # frames done before (a resumed replay)
    frames: Mapping[float, list[LogObservation]] | None = None
    frame_times: NDArray[np.float64] = field(default_factory=lambda: np.empty(0))
    # Observations at or before the start, which no frame replays (a stream counts them as read).
    early: list[int] = field(default_factory=lambda: [0])
    # Whether ``until`` left frames unreplayed (a stream finds out as it reads them).
    cut: list[bool] = field(default_factory=lambda: [False])

    def finish(self) -> None:
        self.reports.finish()


def _row_of(row: LogObservation) -> _Row:
    return (row.time, row.landmark_id, row.bearing, row.range, row.bearing_error, row.range_error)


def _truth_at(
    truth: GroundTruth | TruthWindow | None,
) -> Callable[[NDArray[np.float64]], NDArray[np.float64]]:
    """Return the lookup of the true poses at given times: rows of NaN where the log has no truth."""
    if truth is None:
        return lambda times: np.full((len(times), 3), np.nan)
    return truth.at


def _whole_source(log: RobotLog, opts: ReplayOptions, stop: float, resume: ReplayState | None) -> _Source:
    """Read a whole log in memory: its frames, reports and truth as :func:`replay_log` always made them."""
    start_time, start_pose = replay_start(log)
    meadow_map = log_meadow_map(log, opts.landmark_class, margin=opts.arena_margin)
    frames = frames_after(log, start_time)
    frame_times = np.array(sorted(frames), dtype=np.float64)
    end = float(frame_times[-1]) if frame_times.size else start_time
    with _reversal_named(log):
        report_arrays = log.position_report_arrays(
            frame_times, max_interval=opts.max_interval, start=start_time, end=end, reverse=opts.reverse
        )
    first, posted = 0, 0
    if resume is not None:
        first, posted = _resumed_at(resume, log, frames, frame_times, int(report_arrays[0].size))
    # The frames this replay makes: those after a resumed state's, up to ``until``.
    last = int(np.searchsorted(frame_times, stop, side="right")) if math.isfinite(stop) else frame_times.size
    last = max(last, first)

    def chunks() -> Iterator[_FrameChunk]:
        for begin in range(first, last, _CHUNK):
            times = frame_times[begin : min(begin + _CHUNK, last)]
            logged = [row for frame_time in times.tolist() for row in frames[frame_time]]
            offsets = [0]
            for frame_time in times.tolist():
                offsets.append(offsets[-1] + len(frames[frame_time]))
            yield _FrameChunk(times, offsets, [_row_of(row) for row in logged], logged)

    truth = log.groundtruth

    return _Source(
        start_time,
        start_pose,
        meadow_map,
        chunks(),
        _WholeReports(*report_arrays, posted),
        _truth_at(truth),
        int(frame_times.size),
        first,
        frames,
        frame_times,
        [sum(row.time <= start_time for row in log.observations)],
        [last < frame_times.size],
    )


def _stream_source(stream: LogStream, opts: ReplayOptions, stop: float, *, keep_rows: bool) -> _Source:
    """Read a :class:`LogStream` block by block: the same frames, reports and truth, in bounded memory."""
    truth = None
    if stream.truth_box is not None:
        truth = TruthWindow(stream.groundtruth_blocks(), stream.max_gap)
    odometry = None
    meta = stream.meta
    if stream.commands is None:
        odometry = OdometryReports(
            stream.odometry_blocks(), meta, 0.0, opts.max_interval, opts.reverse, stream.path / ODOMETRY
        )
        first_motion = odometry.first_time
    else:
        commands = stream.commands
        first_motion = (commands[0].time if commands else math.nan) + meta.delay_s
        if commands:
            period = commands[1].time - commands[0].time if len(commands) > 1 else 1e-6
            first_motion -= period
    if meta.start is not None:
        start_time, start_pose = first_motion, meta.start
    elif truth is None:
        raise InputError(
            f"log {meta.name!r}: expected a [start] pose in meta.toml or a groundtruth.csv, got neither"
        )
    else:
        start_time = max(first_motion, truth.first)
        start_pose = _truth_start(meta, start_time, truth.at(np.array([start_time]))[0], truth.max_gap)
    meadow_map = _meadow_map(meta, stream.landmarks, stream.truth_box, opts.landmark_class, opts.arena_margin)
    reports: _WholeReports | _StreamReports
    if odometry is not None:
        odometry.low = start_time
        reports = _StreamReports(odometry)
    else:
        whole = RobotLog(meta, stream.landmarks, (), commands=stream.commands)
        reports = _WholeReports(*whole.position_report_arrays(start=start_time), 0)

    early, cut = [0], [False]
    return _Source(
        start_time,
        start_pose,
        meadow_map,
        _stream_chunks(stream, start_time, stop, keep_rows, early, cut),
        reports,
        _truth_at(truth),
        0,
        early=early,
        cut=cut,
    )


def _stream_chunks(
    stream: LogStream, start: float, stop: float, keep_rows: bool, early: list[int], cut: list[bool]
) -> Iterator[_FrameChunk]:
    """Yield the frames after ``start`` up to ``stop`` of a streamed log, :data:`_CHUNK` at a time.

    ``early[0]`` counts the observations read at or before ``start``; ``cut[0]`` becomes
    True when an observation after ``stop`` is read.
    """
    pending: list[_Row] = []
    lines: list[int] = []
    for times, ids, bearing, measured, bearing_error, range_error, line in stream.observation_blocks():
        early[0] += int(np.count_nonzero(times <= start))
        beyond = bool(times.size) and float(times[-1]) > stop
        wanted = (times > start) & (times <= stop)
        if not np.all(wanted):
            keep = np.flatnonzero(wanted)
            times, bearing, measured = times[keep], bearing[keep], measured[keep]
            bearing_error, range_error, line = bearing_error[keep], range_error[keep], line[keep]
            ids = [ids[index] for index in keep.tolist()]
        bearings = bearing.tolist()
        if not np.all((bearing > -math.pi) & (bearing <= math.pi)):  # else each is as _wrapped leaves it
            bearings = [_wrapped(value) for value in bearings]
        pending.extend(
            zip(
                times.tolist(),
                ids,
                bearings,
                _given(measured),
                _given(bearing_error),
                _given(range_error),
                strict=True,
            )
        )
        if keep_rows:
            lines.extend(line.tolist())
        # Whole frames only: the last time of the block may go on in the next one.
        while pending:
            chunk, pending, lines = _take_frames(pending, lines, keep_rows, ended=False)
            if chunk is None:
                break
            yield chunk
        if beyond:
            cut[0] = True
            break
    while pending:
        chunk, pending, lines = _take_frames(pending, lines, keep_rows, ended=True)
        assert chunk is not None
        yield chunk


def _take_frames(
    rows: list[_Row], lines: list[int], keep_rows: bool, *, ended: bool
) -> tuple[_FrameChunk | None, list[_Row], list[int]]:
    """Split up to :data:`_CHUNK` whole frames off ``rows``; the last one only when ``ended``."""
    times: list[float] = []
    offsets: list[int] = []  # where each frame's rows start
    for index, row in enumerate(rows):
        if not times or row[0] != times[-1]:
            if len(times) == _CHUNK:
                offsets.append(index)
                return (
                    _chunk(times, offsets, rows[:index], lines[:index], keep_rows),
                    rows[index:],
                    lines[index:],
                )
            offsets.append(index)
            times.append(row[0])
    if ended:
        offsets.append(len(rows))
        return _chunk(times, offsets, rows, lines, keep_rows), [], []
    if len(times) <= 1:  # the last frame may go on in the next block
        return None, rows, lines
    times.pop()
    cut = offsets[-1]
    return _chunk(times, offsets, rows[:cut], lines[:cut], keep_rows), rows[cut:], lines[cut:]


def _chunk(
    times: list[float], offsets: list[int], rows: list[_Row], lines: list[int], keep_rows: bool
) -> _FrameChunk:
    logged = None
    if keep_rows:
        logged = [LogObservation._checked(*row, line) for row, line in zip(rows, lines, strict=True)]
    return _FrameChunk(np.array(times, dtype=np.float64), offsets, rows, logged)


class _TraceBuilder:
    """The trace, a chunk of steps at a time."""

    def __init__(self) -> None:
        self.parts: list[ReplayTrace] = []

    def start(self, count: int) -> ReplayTrace:
        part = ReplayTrace.empty(count)
        self.parts.append(part)
        return part

    def build(self) -> ReplayTrace:
        if len(self.parts) == 1:
            return self.parts[0]
        return ReplayTrace.concatenate(self.parts)


def _step_now(
    trace: ReplayTrace,
    index: int,
    working: SpatialUncertaintyMap,
    envelope: SpatialUncertaintyMap | None,
) -> ReplayStep:
    """Return step ``index`` as it stands, its truth judged now (the trace judges it later, in a batch)."""
    truth = trace.truth_pose(index)
    return ReplayStep(
        float(trace.time[index]),
        working,
        truth,
        None if truth is None else bool(working.contains(truth)),
        int(trace.accepted[index]),
        int(trace.rejected[index]),
        float(trace.update_us[index]),
        _STATES[int(trace.state[index])],
        bool(trace.relocalized[index]),
        None if truth is None or envelope is None else bool(envelope.contains(truth)),
        int(trace.excluded[index]),
    )


class _Judge:
    """Collects the maps of a chunk of steps, then measures and judges them all at once.

    Gives exactly :attr:`SpatialUncertaintyMap.area`, ``wedge.width`` and
    :meth:`SpatialUncertaintyMap.contains`: the same arithmetic, element by element (and
    the area's two dot products by the same BLAS dot, polygon by polygon, see ``_areas``),
    over the vertices of many polygons together instead of a few calls per map (which cost
    more than the map's update on a long log).
    """

    def __init__(self, trace: ReplayTrace) -> None:
        self.trace = trace
        self.working: list[SpatialUncertaintyMap] = []
        self.envelope: list[tuple[int, SpatialUncertaintyMap]] = []

    def add(self, index: int, working: SpatialUncertaintyMap, envelope: SpatialUncertaintyMap | None) -> None:
        """Keep step ``index``'s maps (steps are added in order from 0)."""
        self.working.append(working)
        if envelope is not None:
            self.envelope.append((index, envelope))

    def flush(self) -> None:
        """Measure the collected steps' working maps and judge the truth against both maps."""
        trace = self.trace
        count = len(self.working)
        if count:
            vertices = [step_map.polygon.vertices for step_map in self.working]
            rings = _Rings(vertices)  # shared by the areas and the containment
            wedges = _wedges(self.working)
            trace.area_m2[:count] = _areas(vertices, rings)
            trace.wedge_width_rad[:count] = np.minimum(wedges[:, 1] + wedges[:, 2], _FULL_CIRCLE)
            known = np.flatnonzero(~np.isnan(trace.truth[:count, 0]))
            if known.size == count:  # the truth at every step: no lists to gather
                trace.inside[:count] = _contains(
                    self.working, trace.truth[:count], vertices, trace.area_m2[:count], wedges, rings
                )
            elif known.size:
                chosen = known.tolist()
                trace.inside[known] = _contains(
                    [self.working[i] for i in chosen],
                    trace.truth[known],
                    [vertices[i] for i in chosen],
                    trace.area_m2[known],
                    wedges[known],
                )
        with_envelope = [(i, m) for i, m in self.envelope if not math.isnan(trace.truth[i, 0])]
        if with_envelope:
            at = np.array([i for i, _ in with_envelope])
            maps = [m for _, m in with_envelope]
            vertices = [m.polygon.vertices for m in maps]
            rings = _Rings(vertices)
            # The envelope's areas are not reported: only whether each is surely positive.
            trace.envelope_inside[at] = _contains(
                maps, trace.truth[at], vertices, _surely_positive(vertices, rings), _wedges(maps), rings
            )
        self.working, self.envelope = [], []


def _wedges(maps: Sequence[SpatialUncertaintyMap]) -> NDArray[np.float64]:
    """Each map's wedge: rows of centre, clockwise and counter-clockwise extents (rad)."""
    wedges = [step_map.wedge for step_map in maps]
    return np.array([(w.center, w.cw, w.ccw) for w in wedges], dtype=np.float64).reshape(-1, 3)


class _Rings:
    """Polygons' vertices one after another, for arithmetic over all of them at once.

    Made once for the maps a flush judges, and shared by the computations that read all
    their vertices (each gathered them from the polygons again, and found each vertex's
    follower again).
    """

    __slots__ = ("_ahead", "counts", "every", "first")

    def __init__(self, vertices: Sequence[NDArray[np.float64]]) -> None:
        self.counts = np.fromiter(map(len, vertices), dtype=np.int64, count=len(vertices))
        self.every = np.concatenate(vertices) if len(vertices) else np.empty((0, 2))
        self.first = np.cumsum(self.counts) - self.counts  # each polygon's first row in ``every``
        self._ahead: NDArray[np.float64] | None = None

    def ahead(self) -> NDArray[np.float64]:
        """Each vertex's follower (:func:`_ahead`); every polygon must have a vertex."""
        if self._ahead is None:
            self._ahead = _ahead(self.every, self.first, self.first + self.counts - 1)
        return self._ahead


def _areas(vertices: Sequence[NDArray[np.float64]], rings: _Rings | None = None) -> NDArray[np.float64]:
    """Each polygon's area, m^2: :func:`aura_ums.geometry.polygon_area` of each, bit for bit.

    The polygons of each vertex count are measured together: their coordinates relative to
    their first vertex (the same subtractions), in rows, and the two dot products of each
    row by one ``matmul`` of a row by a column, which numpy computes by the very BLAS dot
    ``polygon_area``'s ``np.dot`` calls on the same contiguous numbers. Each group is
    gathered from the rows of ``rings`` (of ``vertices``; made here when not given).
    """
    if rings is None:
        rings = _Rings(vertices)
    counts = rings.counts
    areas = np.zeros(len(vertices), dtype=np.float64)  # a point or a segment: 0.0, as polygon_area
    for count in np.unique(counts[counts >= 3]).tolist():
        chosen = np.flatnonzero(counts == count)
        stack = rings.every[rings.first[chosen][:, None] + np.arange(count)]  # (polygons, count, 2)
        relative = stack - stack[:, :1, :]
        x, y = np.ascontiguousarray(relative[:, :, 0]), np.ascontiguousarray(relative[:, :, 1])
        x_ahead = np.concatenate((x[:, 1:], x[:, :1]), axis=1)
        y_ahead = np.concatenate((y[:, 1:], y[:, :1]), axis=1)
        forward = np.matmul(x[:, None, :], y_ahead[:, :, None])[:, 0, 0]
        backward = np.matmul(y[:, None, :], x_ahead[:, :, None])[:, 0, 0]
        areas[chosen] = 0.5 * (forward - backward)
    return areas


def _surely_positive(
    vertices: Sequence[NDArray[np.float64]], rings: _Rings | None = None
) -> NDArray[np.float64]:
    """1.0 where a polygon's area is surely above 0, else 0.0: the shoelace of all at once.

    Summed otherwise than :func:`~aura_ums.geometry.polygon_area` (whose two dot products
    give the reported areas), so a value is trusted only beyond a bound on its rounding; a
    polygon within it (a degenerate one, or nearly) is then judged by ``contains`` itself.
    """
    if rings is None:
        rings = _Rings(vertices)
    counts = rings.counts
    result = np.zeros(len(vertices))
    if not len(vertices) or counts.min() < 3:
        return np.array([polygon_area(v) > 0.0 for v in vertices], dtype=np.float64)
    every, first = rings.every, rings.first
    origin = np.repeat(every[first], counts, axis=0)  # each polygon's first vertex, as polygon_area
    relative = every - origin
    # The followers of ``relative``: those of ``every`` less the same origin (a polygon's own).
    ahead = rings.ahead() - origin
    forward, backward = relative[:, 0] * ahead[:, 1], relative[:, 1] * ahead[:, 0]
    total = np.add.reduceat(forward - backward, first)
    size = np.add.reduceat(np.abs(forward) + np.abs(backward), first)
    # Either sum's error, whatever its order (and fused or not), is below (n + 2) units in the
    # last place of the sum of the products' sizes: beyond twice that, both are above 0.
    result[total > 4.0 * np.finfo(np.float64).eps * (counts + 2) * size] = 1.0
    return result


def _ahead(
    rows: NDArray[np.float64], first: NDArray[np.int64], last: NDArray[np.int64]
) -> NDArray[np.float64]:
    """Rows of polygons one after another, each moved to its predecessor's place (cyclically per polygon).

    Row ``i`` of the result is row ``i + 1``, but at a polygon's ``last`` row, which gets its
    ``first``: indexing by each row's follower, in two copies instead of a gather.
    """
    ahead = np.empty_like(rows)
    ahead[:-1] = rows[1:]
    ahead[last] = rows[first]
    return ahead


def _contains(
    maps: Sequence[SpatialUncertaintyMap],
    poses: NDArray[np.float64],
    vertices: Sequence[NDArray[np.float64]] | None = None,
    areas: NDArray[np.float64] | None = None,
    wedges: NDArray[np.float64] | None = None,
    rings: _Rings | None = None,
) -> NDArray[np.int8]:
    """Return 1 where ``poses[i]`` (x, y, heading) lies in ``maps[i]``, else 0 (as ``contains``).

    ``vertices``, ``areas``, ``wedges`` and ``rings`` (of ``vertices``) are those of each
    map's polygon and wedge, when the caller has them already; only whether each area is
    above 0 counts (a polygon without one is judged by ``contains`` itself).
    """
    if vertices is None:
        vertices = [step_map.polygon.vertices for step_map in maps]
    if areas is None:
        areas = _areas(vertices)
    if wedges is None:
        wedges = _wedges(maps)
    result = np.zeros(len(maps), dtype=np.int8)
    counts = np.array([len(v) for v in vertices], dtype=np.int64) if rings is None else rings.counts
    sliced = np.array([step_map.is_sliced for step_map in maps], dtype=bool)
    # A sliced map is judged by its slices (its polygon and wedge are only their summary).
    batch = ~sliced & (counts >= 3) & (counts <= _BATCHED_VERTICES) & (areas > 0.0)
    for index in np.flatnonzero(~batch).tolist():  # a sliced map, a point, a segment, or a huge polygon
        x, y, heading = poses[index].tolist()
        result[index] = maps[index].contains(x, y, heading)
    batched = np.flatnonzero(batch)
    if not batched.size:
        return result
    if rings is not None and batched.size == len(maps):  # every polygon: their rows as they are
        chosen, every, first = rings.counts, rings.every, rings.first
        edge = rings.ahead() - every
    else:
        chosen = counts[batched]
        every = np.concatenate([vertices[index] for index in batched.tolist()])
        first = np.cumsum(chosen) - chosen
        edge = _ahead(every, first, first + chosen - 1) - every
    length = np.hypot(edge[:, 0], edge[:, 1])
    pose = poses[batched]
    relative_x = np.repeat(pose[:, 0], chosen) - every[:, 0]
    relative_y = np.repeat(pose[:, 1], chosen) - every[:, 1]
    signed = edge_distances(edge[:, 0] * relative_y - edge[:, 1] * relative_x, length)
    in_polygon = np.logical_and.reduceat(signed >= -POSITION_TOLERANCE, first)
    result[batched] = in_polygon & wedges_contain(wedges[batched], pose[:, 2])
    return result


class _StepsCsv:
    """The per-step CSV, written block by block through :func:`atomic_path`: whole, or not at all."""

    def __init__(self, target: str | os.PathLike[str] | None) -> None:
        self.target = None if target is None else Path(target)
        self.stream: TextIO | None = None
        # The scratch file (and any folder made for it) and its stream, closed in that order's reverse.
        self._held = contextlib.ExitStack()

    def __enter__(self) -> _StepsCsv:
        if self.target is not None:
            try:
                scratch = self._held.enter_context(atomic_path(self.target))
                # "x": a fresh file that honours the umask (tempfile.mkstemp's 0600 would stay).
                self.stream = self._held.enter_context(scratch.open("x", encoding="utf-8", newline=""))
                self.stream.write(STEPS_CSV_HEADER + "\n")
            except BaseException as exc:
                # A with statement whose __enter__ raises never calls __exit__: the scratch file
                # made so far goes here (a Ctrl-C or SIGTERM too, not when it is collected).
                with contextlib.suppress(OSError):
                    self._held.__exit__(type(exc), exc, exc.__traceback__)
                if isinstance(exc, OSError):
                    raise FileFormatError.unwritable(str(self.target), exc) from None
                raise
        return self

    def write(self, trace: ReplayTrace) -> None:
        if self.stream is not None and len(trace):
            self.stream.write("".join(line + "\n" for line in trace.csv_lines()))

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        traceback: types.TracebackType | None,
    ) -> None:
        try:
            # Closing writes the last buffered lines (on a full disk it fails as a write does),
            # then the scratch file is renamed onto the target, or removed on any error.
            self._held.__exit__(kind, error, traceback)
        except OSError as exc:
            if error is None:
                raise FileFormatError.unwritable(str(self.target), exc) from None
            # Otherwise the error already on its way (maybe this same one, from a write) says more.


#: The inputs of :func:`_inputs` recorded as a SHA-256 of their text, not as it is.
DIGESTED_INPUTS = ("sensor bounds", "terrain table")


def _inputs(opts: ReplayOptions, table: TerrainTable) -> dict[str, str]:
    """Return what a replay runs with besides its manager's settings, as text (``ReplayState.inputs``).

    The manager's JSON holds its settings and maps, not what the replay feeds it: a state
    resumed with another landmark class or other sensor bounds ran on, silently, as a mix
    of two replays (helper-63).
    """
    sensors = repr((opts.working, opts.envelope, opts.motion)).encode("utf-8")
    return {
        "landmark_class": opts.landmark_class.value,
        "reverse": opts.reverse.value,
        "max_interval": repr(opts.max_interval),
        "arena_margin": repr(opts.arena_margin),
        DIGESTED_INPUTS[0]: hashlib.sha256(sensors).hexdigest(),
        DIGESTED_INPUTS[1]: hashlib.sha256(table.to_toml().encode("utf-8")).hexdigest(),
    }


def _same_inputs(state: ReplayState, opts: ReplayOptions, table: TerrainTable) -> None:
    """Refuse to resume ``state`` with other inputs than it was saved with (those it recorded)."""
    for name, given in _inputs(opts, table).items():
        saved = state.inputs.get(name)
        if saved is None or saved == given:
            continue
        if name in DIGESTED_INPUTS:
            raise InputError(
                f"resume: expected the {name} the state was saved with (SHA-256 {saved[:12]}...), "
                f"got others ({given[:12]}...)"
            )
        raise InputError(f"resume: expected {name} {saved!r}, as the state was saved with, got {given!r}")


def _digest(frames: Mapping[float, list[LogObservation]], times: np.ndarray) -> str:
    """SHA-256 of the observations of the frames at ``times``: what a saved state was replayed on."""
    digest = hashlib.sha256()
    for frame_time in times:
        for row in frames[float(frame_time)]:
            digest.update(repr((row.time, row.landmark_id, row.bearing, row.range)).encode("utf-8"))
    return digest.hexdigest()


def _resumed_at(
    state: ReplayState,
    log: RobotLog,
    frames: Mapping[float, list[LogObservation]],
    frame_times: np.ndarray,
    reports: int,
) -> tuple[int, int]:
    """Return the frame and report indices to resume at; a state from another log is refused."""
    done = state.frames_done
    if state.log_name != log.meta.name:
        why = f"another log's name, {state.log_name!r}"
    elif done > frame_times.size:
        why = f"{done} frames done, more than the log has"
    elif state.log_digest != _digest(frames, frame_times[:done]):
        why = f"a digest of other observations than those of the log's first {done} frames"
    elif state.reports_posted > reports:
        why = f"reports_posted {state.reports_posted}, more than the log's {reports} position reports"
    elif not (math.isnan(state.last_time) if done == 0 else float(frame_times[done - 1]) == state.last_time):
        where = "no frame done" if done == 0 else f"its frame {done} at {float(frame_times[done - 1])!r} s"
        why = f"a last frame at {state.last_time!r} s, where the log has {where}"
    else:
        return done, state.reports_posted
    raise InputError(
        f"resume: expected a state saved from a replay of log {log.meta.name!r} ({frame_times.size} frames, "
        f"{reports} position reports), got one after {done} frames at {state.last_time!r} s with {why}"
    )


def with_motion(log: LogT, motion: MotionCalibration | None) -> LogT:
    """Return ``log`` with its meta's delay and scales replaced by ``motion`` (unchanged for None)."""
    return log if motion is None else dataclasses.replace(log, meta=_motion_meta(log.meta, motion))


def _motion_meta(meta: LogMeta, motion: MotionCalibration | None) -> LogMeta:
    """Return ``meta`` with its delay and scales replaced by ``motion`` (unchanged for None)."""
    if motion is None:
        return meta
    return dataclasses.replace(
        meta, delay_s=motion.delay_s, run_scale=motion.run_scale, turn_scale=motion.turn_scale
    )


def frames_after(log: RobotLog, start: float) -> dict[float, list[LogObservation]]:
    """Group the observations after ``start`` (s) into frames: time stamp -> rows, in time order."""
    frames: dict[float, list[LogObservation]] = {}
    for row in log.observations:
        if row.time > start:
            frames.setdefault(row.time, []).append(row)
    return frames


def position_reports_for(log: RobotLog, options: ReplayOptions) -> tuple[PositionReport, ...]:
    """Return the position reports :func:`replay_log` grows by, cut at the log's frame times.

    The options' motion calibration is applied as :func:`replay_log` applies it.
    """
    log = with_motion(log, options.motion)
    start_time, _ = replay_start(log)
    times = np.array(sorted(frames_after(log, start_time)), dtype=np.float64)
    end = float(times[-1]) if times.size else start_time
    with _reversal_named(log):
        return log.position_reports(
            times, max_interval=options.max_interval, start=start_time, end=end, reverse=options.reverse
        )


@contextlib.contextmanager
def _reversal_named(log: RobotLog) -> Iterator[None]:
    """Name the odometry file and line of a refused reverse (the motion knows only its row)."""
    try:
        yield
    except ReversingError as refused:
        if log.path is None or log.odometry is None:
            raise
        raise reversed_at(log.path / ODOMETRY, refused) from None
