"""Replay a robot log through the uncertainty map manager and measure it against ground truth."""

from __future__ import annotations

import dataclasses
import math
import time as _time
import types
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from aura_ums._metrics import Metrics
from aura_ums._validate import finite_float, positive_float
from aura_ums.errors import InputError
from aura_ums.expecter import PerceptualStrategy
from aura_ums.geometry import ConvexPolygon
from aura_ums.logs._calibrate import MotionCalibration, SensorBounds
from aura_ums.logs._log import LogObservation, RobotLog
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
    VerticalLineLandmark,
)
from aura_ums.world import LandmarkRecord, Meadow, MeadowMap

_REPLAY_CLASSES = (LandmarkClass.VERTICAL_LINE, LandmarkClass.POINT)


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
    arena_margin : float
        Metres, >= 0, by which the one meadow of the replay (the log's terrain) extends
        beyond the landmarks, the start and the ground truth.

    Examples
    --------
    >>> ReplayOptions(landmark_class=LandmarkClass.POINT).landmark_class.value
    'II'
    >>> ReplayOptions(settings=ManagerSettings(robust=False)).settings.robust
    False
    >>> ReplayOptions(landmark_class=LandmarkClass.GROUND_LINE)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: ReplayOptions.landmark_class: expected Class I or II, got GROUND_LINE
    """

    settings: ManagerSettings = field(default_factory=ManagerSettings)
    landmark_class: LandmarkClass = LandmarkClass.VERTICAL_LINE
    max_interval: float = 0.25
    working: SensorBounds | None = None
    envelope: SensorBounds | None = None
    motion: MotionCalibration | None = None
    arena_margin: float = 5.0

    def __post_init__(self) -> None:
        if not isinstance(self.settings, ManagerSettings):
            raise InputError(
                f"ReplayOptions.settings: expected ManagerSettings, got {type(self.settings).__name__}"
            )
        if self.landmark_class not in _REPLAY_CLASSES:
            raise InputError(
                f"ReplayOptions.landmark_class: expected Class I or II, got {self.landmark_class.name}"
            )
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


@dataclass(frozen=True, slots=True, eq=False)
class ReplayResult:
    """The outcome of :func:`replay_log`.

    Attributes
    ----------
    log : RobotLog
        The log replayed.
    options : ReplayOptions
        How.
    steps : tuple of ReplayStep
        One per frame, in time order.
    rejected_counts : Mapping[RejectReason, int]
        Rejected observations by reason.
    relocalizations : int
        Times the working map was re-seeded from the envelope.
    """

    log: RobotLog
    options: ReplayOptions
    steps: tuple[ReplayStep, ...]
    rejected_counts: Mapping[RejectReason, int]
    relocalizations: int

    @property
    def containment_rate(self) -> float:
        """Fraction of the steps with ground truth whose truth is inside the map (nan without)."""
        judged = [s.inside for s in self.steps if s.inside is not None]
        return float(np.mean(judged)) if judged else math.nan

    @property
    def median_area_m2(self) -> float:
        """Median area of the map over the steps, m^2."""
        return float(np.median([s.map.area for s in self.steps])) if self.steps else math.nan

    @property
    def median_wedge_width_rad(self) -> float:
        """Median width of the heading wedge over the steps, radians."""
        return float(np.median([s.map.wedge.width for s in self.steps])) if self.steps else math.nan

    @property
    def inconsistent_observations(self) -> int:
        """Observations rejected, all reasons together."""
        return sum(self.rejected_counts.values())

    @property
    def median_update_us(self) -> float:
        """Median microseconds per step's update."""
        return float(np.median([s.update_us for s in self.steps])) if self.steps else math.nan

    def metrics(self) -> Metrics:
        """Return the options and figures of the replay (keys: ``docs/metrics.md``).

        Undefined figures (no steps, no ground truth, no envelope) are ``None``.
        """
        envelope = [s.envelope_inside for s in self.steps if s.envelope_inside is not None]
        return Metrics(
            {
                "log": self.log.meta.name,
                "landmark_class": self.options.landmark_class.value,
                "sigmas": self.options.settings.sigmas,
                "robust": self.options.settings.robust,
                "joint_above_rad": self.options.settings.joint_above,
                "max_vertices": self.options.settings.max_vertices,
                "envelope_max_vertices": self.options.settings.envelope_max_vertices,
                "steps": len(self.steps),
                "steps_with_truth": sum(1 for s in self.steps if s.inside is not None),
                "containment_rate": self.containment_rate,
                "envelope_containment_rate": float(np.mean(envelope)) if envelope else None,
                "median_area_m2": self.median_area_m2,
                "median_wedge_width_rad": self.median_wedge_width_rad,
                "accepted_observations": sum(s.accepted for s in self.steps),
                "inconsistent_observations": self.inconsistent_observations,
                "rejected_by_reason": {reason.value: count for reason, count in self.rejected_counts.items()},
                "relocalizations": self.relocalizations,
                "relaxed_q": self.options.settings.relaxed_q,
                "relaxed_window": self.options.settings.relaxed_window,
                "excluded_observations": sum(s.excluded for s in self.steps),
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
    x, y, heading = log.groundtruth.at([start])[0]
    return start, Pose(float(x), float(y), float(heading))


def log_meadow_map(log: RobotLog, landmark_class: LandmarkClass, *, margin: float = 5.0) -> MeadowMap:
    """Return a meadow map for replaying ``log``: one meadow of its terrain, its landmarks.

    The meadow is the bounding box of the landmarks, the start and the ground truth,
    grown by ``margin`` metres. Landmarks become :class:`~aura_ums.uncertainty.VerticalLineLandmark`
    (Class I, heights from the row or the meta) or :class:`~aura_ums.uncertainty.PointLandmark`
    (Class II, at the row's mid height).
    """
    points = [(lm.x, lm.y) for lm in log.landmarks]
    if log.meta.start is not None:
        points.append((log.meta.start.x, log.meta.start.y))
    if log.groundtruth is not None:
        truth = log.groundtruth
        points += [(float(truth.x.min()), float(truth.y.min())), (float(truth.x.max()), float(truth.y.max()))]
    xy = np.array(points, dtype=np.float64).reshape(-1, 2)
    if not xy.size:
        xy = np.zeros((1, 2))
    (x0, y0), (x1, y1) = xy.min(axis=0) - margin - 1.0, xy.max(axis=0) + margin + 1.0
    records = []
    for lm in log.landmarks:
        bottom, top = lm.heights(log.meta)
        landmark: VerticalLineLandmark | PointLandmark
        if landmark_class is LandmarkClass.VERTICAL_LINE:
            landmark = VerticalLineLandmark(
                lm.id, lm.x, lm.y, bottom, top, lm.symbol, lm.position_uncertainty
            )
        else:
            landmark = PointLandmark(
                lm.id, lm.x, lm.y, (bottom + top) / 2.0, lm.symbol, lm.position_uncertainty
            )
        records.append(LandmarkRecord(landmark, PerceptualStrategy.LINE_FINDER, {}, 1.0e6, 0.0))
    arena = ConvexPolygon([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])
    meadow = Meadow("arena", arena, log.meta.terrain, tuple(lm.id for lm in log.landmarks))
    return MeadowMap([meadow], records)


def observation_for(
    row: LogObservation, landmark_class: LandmarkClass, bounds: SensorBounds, *, factor: float = 1.0
) -> Observation:
    """Turn a log row into a bounded observation of the replay's landmark class.

    The row's own ``bearing_error`` / ``range_error`` (absolute, metres) take precedence
    over ``bounds``; ``factor`` (>= 1) widens whichever is used. A Class II replay skips
    rows without a range (returns a bearing observation, which the manager rejects as of
    the wrong class and counts).
    """
    bearing_error = (bounds.bearing_error if row.bearing_error is None else row.bearing_error) * factor
    if landmark_class is LandmarkClass.VERTICAL_LINE or row.range is None:
        return BearingObservation(row.landmark_id, row.time, row.bearing, bearing_error)
    if row.range_error is not None:
        error = row.range_error * factor
        low, high = max(0.0, row.range - error), row.range + error
    else:
        low, high = (bounds.widened(factor) if factor > 1.0 else bounds).range_interval(row.range)
    return RangeBearingObservation(row.landmark_id, row.time, row.bearing, bearing_error, low, high)


def meta_bounds(log: RobotLog) -> SensorBounds:
    """Return the sensor bounds a log's ``meta.toml`` states (its range fraction both ways)."""
    meta = log.meta
    return SensorBounds(
        meta.bearing_error, meta.range_error, meta.range_error_fraction, meta.range_error_fraction
    )


def replay_log(log: RobotLog, table: TerrainTable, options: ReplayOptions | None = None) -> ReplayResult:
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

    Parameters
    ----------
    log : RobotLog
        The log.
    table : TerrainTable
        Must hold the log's terrain (``meta.terrain``).
    options : ReplayOptions or None
        How; default :class:`ReplayOptions`.

    Returns
    -------
    ReplayResult

    Raises
    ------
    InputError
        For a bad argument, a terrain missing from ``table``, or a log without a start.

    Examples
    --------
    >>> from aura_ums.logs import synthetic_log
    >>> log = synthetic_log(np.random.default_rng(3), duration=30.0)
    >>> result = replay_log(log, TerrainTable({"floor": TerrainTable.default()["tile"]}))
    >>> result.containment_rate, result.inconsistent_observations
    (1.0, 0)
    >>> replay_log(log, TerrainTable.default())
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: table: expected a terrain 'floor' (the log's), got none of that name
    """
    if not isinstance(log, RobotLog):
        raise InputError(f"log: expected a RobotLog, got {type(log).__name__}")
    if not isinstance(table, TerrainTable):
        raise InputError(f"table: expected a TerrainTable, got {type(table).__name__}")
    opts = ReplayOptions() if options is None else options
    if not isinstance(opts, ReplayOptions):
        raise InputError(f"options: expected ReplayOptions or None, got {type(opts).__name__}")
    if log.meta.terrain not in table:
        raise InputError(f"table: expected a terrain {log.meta.terrain!r} (the log's), got none of that name")
    log = with_motion(log, opts.motion)
    working_bounds = opts.working if opts.working is not None else meta_bounds(log)
    robust = opts.settings.robust
    envelope_bounds = (
        opts.envelope if opts.envelope is not None else working_bounds.widened(opts.settings.envelope_factor)
    )

    start_time, start_pose = replay_start(log)
    initial = SpatialUncertaintyMap.from_pose(
        start_pose, log.meta.start_radius, log.meta.start_heading_halfwidth
    )
    meadow_map = log_meadow_map(log, opts.landmark_class, margin=opts.arena_margin)
    manager = UncertaintyMapManager(initial, meadow_map, table, opts.settings)
    board = Blackboard()
    frames = frames_after(log, start_time)
    frame_times = np.array(sorted(frames), dtype=np.float64)
    end = float(frame_times[-1]) if frame_times.size else start_time
    reports = log.position_reports(frame_times, max_interval=opts.max_interval, start=start_time, end=end)
    truth_at = (
        log.groundtruth.at(frame_times)
        if log.groundtruth is not None
        else np.full((frame_times.size, 3), np.nan)
    )

    steps: list[ReplayStep] = []
    next_report = 0
    for index, frame_time in enumerate(frame_times):
        rows = frames[float(frame_time)]
        working = [observation_for(r, opts.landmark_class, working_bounds) for r in rows]
        envelope = (
            [observation_for(r, opts.landmark_class, envelope_bounds) for r in rows] if robust else None
        )
        began = _time.perf_counter()
        while next_report < len(reports) and reports[next_report].time <= frame_time:
            board.post_report(reports[next_report])
            next_report += 1
        for observation in working:
            board.identified.post(observation)
        step = manager.update(board, now=float(frame_time), envelope=envelope)
        elapsed = (_time.perf_counter() - began) * 1e6
        x, y, heading = truth_at[index]
        truth = None if math.isnan(x) else Pose(float(x), float(y), float(heading))
        inside = None if truth is None else bool(step.map.contains(truth.x, truth.y, truth.heading))
        envelope_map = step.envelope_map
        envelope_inside = (
            None
            if truth is None or envelope_map is None
            else bool(envelope_map.contains(truth.x, truth.y, truth.heading))
        )
        steps.append(
            ReplayStep(
                float(frame_time),
                step.map,
                truth,
                inside,
                len(step.accepted),
                len(step.rejected),
                elapsed,
                step.state,
                step.relocalized,
                envelope_inside,
                len(step.excluded),
            )
        )
    return ReplayResult(
        log,
        opts,
        tuple(steps),
        types.MappingProxyType(dict(manager.rejected_counts)),
        manager.relocalizations,
    )


def with_motion(log: RobotLog, motion: MotionCalibration | None) -> RobotLog:
    """Return ``log`` with its meta's delay and scales replaced by ``motion`` (unchanged for None)."""
    if motion is None:
        return log
    meta = dataclasses.replace(
        log.meta, delay_s=motion.delay_s, run_scale=motion.run_scale, turn_scale=motion.turn_scale
    )
    return dataclasses.replace(log, meta=meta)


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
    return log.position_reports(times, max_interval=options.max_interval, start=start_time, end=end)
