"""The spatial uncertainty map next to an EKF, a particle filter and (optionally) a Codac box, on one log."""

from __future__ import annotations

import math
import time as _time
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from aura_ums._metrics import Metrics
from aura_ums._validate import ANGLE_ERROR, FACTOR, finite_float, positive_float
from aura_ums.baselines import CodacLocalizer, Estimator, ExtendedKalmanFilter, ParticleFilter
from aura_ums.errors import InputError
from aura_ums.logs._log import RobotLog
from aura_ums.logs._replay import (
    ReplayOptions,
    ReplayResult,
    _observation_for,
    frames_after,
    meta_bounds,
    position_reports_for,
    replay_log,
    replay_start,
    with_motion,
)
from aura_ums.uncertainty import BearingObservation, Pose, RangeBearingObservation, TerrainTable


@dataclass(frozen=True, slots=True)
class MethodSummary:
    """One row of :func:`compare_on_log`'s table.

    Its fields carry the keys of the metrics table (``docs/metrics.md``) that ``simulate``
    and ``replay`` use for the same figures; :meth:`metrics` returns them as
    :class:`~aura_ums.Metrics`.

    Attributes
    ----------
    method : str
        ``"aura-ums"``, ``"EKF"``, ``"PF (n)"``, ``"codac"``, or the name of one of ``others``.
    containment_rate : float
        Fraction of the steps whose ground truth is inside the method's region (our map;
        the filters' 99% regions; the Codac box).
    median_area_m2 : float
        Median area of the position region, m^2.
    median_wedge_width_rad : float
        Median width of the heading region (our wedge; the filters' confidence
        intervals), radians.
    position_rmse_m : float
        Root mean square distance from our map's centre (its most probable position, kept
        inside the polygon; not the polygon's centroid) or the mean (the filters) to the true
        position, metres.
    median_update_us : float
        Median microseconds per step (growth or prediction since the previous step, and
        the step's observations).
    inconsistent_observations : int
        Observations rejected (our gate; the filters' Mahalanobis gates); for the Codac
        box, its re-initialisations (:attr:`~aura_ums.baselines.CodacLocalizer.reinitialisations`).

    Examples
    --------
    >>> row = MethodSummary("EKF", 0.5, 2.0, 0.1, float("nan"), 12.0, 3)
    >>> row.metrics()["position_rmse_m"] is None, row.metrics()["inconsistent_observations"]
    (True, 3)
    """

    method: str
    containment_rate: float
    median_area_m2: float
    median_wedge_width_rad: float
    position_rmse_m: float
    median_update_us: float
    inconsistent_observations: int

    def metrics(self) -> Metrics:
        """Return the row as metrics (undefined figures, NaN here, become ``None``)."""
        return Metrics(
            {
                "method": self.method,
                "containment_rate": self.containment_rate,
                "median_area_m2": self.median_area_m2,
                "median_wedge_width_rad": self.median_wedge_width_rad,
                "position_rmse_m": self.position_rmse_m,
                "median_update_us": self.median_update_us,
                "inconsistent_observations": self.inconsistent_observations,
            }
        )


def _ours(result: ReplayResult) -> MethodSummary:
    errors = [
        math.hypot(s.map.center[0] - s.truth.x, s.map.center[1] - s.truth.y)
        for s in result.steps
        if s.truth is not None
    ]
    return MethodSummary(
        "aura-ums",
        result.containment_rate,
        result.median_area_m2,
        result.median_wedge_width_rad,
        float(np.sqrt(np.mean(np.square(errors)))) if errors else math.nan,
        result.median_update_us,
        result.inconsistent_observations,
    )


def filter_settings(log: RobotLog, *, bearing_sd: float, range_sd_fraction: float) -> dict[str, float]:
    """Return the start spread and noise :func:`compare_on_log` gives its filters, as keyword arguments.

    ``position_sd`` and ``heading_sd`` are a third of the log's start bounds (at least
    1e-3), ``range_sd`` is 0.01 m; ``bearing_sd`` (rad) and ``range_sd_fraction`` are
    passed through. Give them to a filter of yours to start it as the EKF starts.

    Examples
    --------
    >>> from aura_ums.logs import synthetic_log
    >>> settings = filter_settings(synthetic_log(np.random.default_rng(3), duration=5.0),
    ...                            bearing_sd=0.006, range_sd_fraction=0.012)
    >>> sorted(settings), settings["range_sd"]
    (['bearing_sd', 'heading_sd', 'position_sd', 'range_sd', 'range_sd_fraction'], 0.01)
    >>> filter_settings("log", bearing_sd=0.006, range_sd_fraction=0.012)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: log: expected a RobotLog, got str
    """
    if not isinstance(log, RobotLog):
        raise InputError(f"log: expected a RobotLog, got {type(log).__name__}")
    bearing_sd = positive_float(bearing_sd, "bearing_sd")
    range_sd_fraction = positive_float(range_sd_fraction, "range_sd_fraction")
    return {
        "position_sd": max(log.meta.start_radius / 3.0, 1e-3),
        "heading_sd": max(log.meta.start_heading_halfwidth / 3.0, 1e-3),
        "bearing_sd": bearing_sd,
        "range_sd": 0.01,
        "range_sd_fraction": range_sd_fraction,
    }


def compare_on_log(
    log: RobotLog,
    table: TerrainTable,
    options: ReplayOptions | None = None,
    *,
    bearing_sd: float,
    range_sd_fraction: float,
    rng: np.random.Generator,
    particles: int = 1000,
    probability: float = 0.99,
    others: Mapping[str, Callable[[Pose], Estimator]] | None = None,
    codac: bool = False,
    progress: Callable[[int, int], None] | None = None,
) -> tuple[MethodSummary, ...]:
    """Run our map, an EKF, a particle filter (and a Codac box) over one log; judge each against its truth.

    All three see the same position reports (those :func:`replay_log` grows by), the same
    terrain statistics and the same observations, step by step. The filters start from
    the same pose with standard deviations of a third of our start bounds, use
    ``bearing_sd`` (rad) and ``range_sd_fraction`` (of the range) as their measurement
    noise (:func:`filter_settings`), and gate at 99.9%; their region is the
    ``probability`` confidence region.
    With ``codac``, a :class:`~aura_ums.baselines.CodacLocalizer` joins as the row
    ``"codac"``: it starts from our start bounds (a box around our start disk and wedge),
    bounds the commands at our ``settings.sigmas`` and runs its relaxed intersection with our
    ``settings.relaxed_q`` and ``settings.relaxed_window``, on our working sensor bounds.
    Your own estimators join through ``others``: each is built from the start pose and
    stepped, timed and judged exactly as the EKF is.

    Parameters
    ----------
    log : RobotLog
        A log with ground truth.
    table : TerrainTable
        Must hold the log's terrain.
    options : ReplayOptions or None
        Our replay's options (landmark class, bounds, motion calibration).
    bearing_sd : float
        Radians, > 0.
    range_sd_fraction : float
        Fraction of the range, > 0.
    rng : numpy.random.Generator
        The particle filter's randomness.
    particles : int
        Particles, >= 1.
    probability : float
        Probability of the filters' confidence regions, in (0, 1).
    others : mapping of str to callable, or None
        More methods: name -> factory taking the start :class:`~aura_ums.uncertainty.Pose`
        and returning an :class:`~aura_ums.baselines.Estimator` (a filter of yours;
        :meth:`ConfidenceRegion.gaussian <aura_ums.baselines.ConfidenceRegion.gaussian>`
        gives a Gaussian one its region). Its start spread and noise are its own.
    codac : bool
        Add the Codac row (needs the ``codac`` extra: :func:`~aura_ums.baselines.codac_available`).
    progress : callable or None
        Called as ``progress(done, total)`` as the work advances: after each frame of our
        replay, then after each filter's pass (``total`` is the frames times the methods);
        nothing is printed here.

    Returns
    -------
    tuple of MethodSummary
        Ours, the EKF's, the particle filter's, the Codac box's (with ``codac``), then one
        per entry of ``others``.

    Raises
    ------
    InputError
        For a bad argument or a log without ground truth.
    MissingDependencyError
        With ``codac`` when Codac is not installed.

    Examples
    --------
    >>> from aura_ums.logs import synthetic_log
    >>> log = synthetic_log(np.random.default_rng(3), duration=20.0)
    >>> rows = compare_on_log(log, TerrainTable({"floor": TerrainTable.default()["tile"]}),
    ...                       bearing_sd=0.006, range_sd_fraction=0.012,
    ...                       rng=np.random.default_rng(0), particles=200)
    >>> [row.method for row in rows], rows[0].containment_rate
    (['aura-ums', 'EKF', 'PF (200)'], 1.0)
    >>> rows = compare_on_log(log, TerrainTable({"floor": TerrainTable.default()["tile"]}),
    ...                       bearing_sd=0.006, range_sd_fraction=0.012,
    ...                       rng=np.random.default_rng(0), particles=200, codac=True)
    >>> rows[3].method, rows[3].containment_rate, rows[3].inconsistent_observations
    ('codac', 1.0, 0)

    A filter of your own, here a second EKF that trusts its bearings ten times more:

    >>> def confident(start):
    ...     return ExtendedKalmanFilter(start, position_sd=0.1, heading_sd=0.02,
    ...                                 bearing_sd=0.0006, range_sd=0.01, gate_probability=0.999)
    >>> rows = compare_on_log(log, TerrainTable({"floor": TerrainTable.default()["tile"]}),
    ...                       bearing_sd=0.006, range_sd_fraction=0.012, rng=np.random.default_rng(0),
    ...                       particles=200, others={"confident EKF": confident})
    >>> rows[-1].method, rows[-1].containment_rate < rows[1].containment_rate
    ('confident EKF', True)
    """
    if not isinstance(log, RobotLog):
        raise InputError(f"log: expected a RobotLog, got {type(log).__name__}")
    if log.groundtruth is None:
        raise InputError(f"log {log.meta.name!r}: expected ground truth to compare against, got none")
    opts = ReplayOptions() if options is None else options
    if not isinstance(opts, ReplayOptions):
        raise InputError(f"options: expected ReplayOptions or None, got {type(opts).__name__}")
    b_sd = finite_float(bearing_sd, "bearing_sd")
    r_sd = finite_float(range_sd_fraction, "range_sd_fraction")
    if not b_sd > 0.0 or not r_sd > 0.0:
        raise InputError(f"bearing_sd, range_sd_fraction: expected positive numbers, got {b_sd!r}, {r_sd!r}")
    # 1e300 overflowed the filters' variances (an OverflowError from the EKF)
    for name, value, limits in (("bearing_sd", b_sd, ANGLE_ERROR), ("range_sd_fraction", r_sd, FACTOR)):
        if value > limits.high:
            raise InputError(f"{name}: expected {limits.text()}, got {value!r}")
    if not isinstance(codac, bool):
        raise InputError(f"codac: expected True or False, got {codac!r}")
    extra = _check_others(others, {"aura-ums", "EKF", f"PF ({particles})", *(("codac",) if codac else ())})
    if progress is not None and not callable(progress):
        raise InputError(f"progress: expected a callable or None, got {type(progress).__name__}")
    methods = 3 + int(codac) + len(extra)

    def tick(done: int, frames: int) -> None:
        if progress is not None:
            progress(done, frames * methods)

    moved = with_motion(log, opts.motion)
    start_time, start_pose = replay_start(moved)
    reports = position_reports_for(moved, opts)
    frames = frames_after(moved, start_time)
    _refuse_a_costly_filter(particles, len(reports), sum(map(len, frames.values())) + len(frames))
    ours = replay_log(log, table, opts, progress=tick)
    log = moved
    terrain = table[log.meta.terrain]
    bounds = opts.working if opts.working is not None else meta_bounds(log)
    common = filter_settings(log, bearing_sd=b_sd, range_sd_fraction=r_sd)
    filters: list[tuple[str, Estimator]] = [
        ("EKF", ExtendedKalmanFilter(start_pose, gate_probability=0.999, **common)),
        (
            f"PF ({particles})",
            ParticleFilter(start_pose, rng, particles=particles, gate_probability=0.999, **common),
        ),
    ]
    if codac:
        settings = opts.settings
        box = CodacLocalizer(
            start_pose,
            position_halfwidth=log.meta.start_radius,
            heading_halfwidth=log.meta.start_heading_halfwidth,
            sigmas=settings.sigmas,
            q=settings.relaxed_q,
            window=settings.relaxed_window,
        )
        filters.append(("codac", box))
    for name, factory in extra:
        built = factory(start_pose)
        if not isinstance(built, Estimator):
            raise InputError(
                f"others[{name!r}]: expected a factory returning an Estimator (predict, update, region, "
                f"mean, rejected_count), got {type(built).__name__}"
            )
        filters.append((name, built))
    landmarks = {lm.id: (lm.x, lm.y) for lm in log.landmarks}
    truth = log.groundtruth
    if truth is None:  # replaced above by the motion calibration, never dropped
        raise InputError(f"log {log.meta.name!r}: expected ground truth to compare against, got none")
    summaries = [_ours(ours)]
    done = len(frames)
    for name, estimator in filters:
        inside: list[bool] = []
        areas: list[float] = []
        widths: list[float] = []
        errors: list[float] = []
        micros: list[float] = []
        next_report = 0
        for frame_time in sorted(frames):
            # Built before the clock starts, as replay_log builds ours: only the update is timed.
            seen = [
                (observation, landmarks[row.landmark_id])
                for row in frames[frame_time]
                if isinstance(
                    observation := _observation_for(
                        row, opts.landmark_class, bounds, 1.0, log.meta.sensor_offset
                    ),
                    (BearingObservation, RangeBearingObservation),
                )
            ]
            began = _time.perf_counter()
            while next_report < len(reports) and reports[next_report].time <= frame_time:
                estimator.predict(reports[next_report].command, terrain)
                next_report += 1
            for observation, landmark_xy in seen:
                estimator.update(observation, landmark_xy)
            micros.append((_time.perf_counter() - began) * 1e6)
            region = estimator.region(probability)
            x, y, heading = truth.at([frame_time])[0]
            areas.append(region.area)
            widths.append(region.heading_width)
            if math.isnan(x):
                continue
            inside.append(bool(region.contains(x, y, heading)))
            mean = estimator.mean
            errors.append(math.hypot(mean.x - x, mean.y - y))
        done += len(frames)
        tick(done, len(frames))
        summaries.append(
            MethodSummary(
                name,
                float(np.mean(inside)) if inside else math.nan,
                float(np.median(areas)) if areas else math.nan,
                float(np.median(widths)) if widths else math.nan,
                float(np.sqrt(np.mean(np.square(errors)))) if errors else math.nan,
                float(np.median(micros)) if micros else math.nan,
                estimator.rejected_count,
            )
        )
    return tuple(summaries)


#: Seconds of the particle filter per particle and event (a prediction, an update, a region):
#: 100,000 particles over a 60 s log (600 reports, 203 observations, 66 frames) took 28 s.
_SECONDS_PER_PARTICLE_EVENT = 3.2e-7
#: Longest estimated particle filter of one comparison, seconds (as a simulated run's limit).
MAX_FILTER_SECONDS = 600.0


def _refuse_a_costly_filter(particles: int, reports: int, updates: int) -> None:
    """Refuse a particle filter estimated to run past :data:`MAX_FILTER_SECONDS`, with the estimate.

    A million particles on the sample log ran past a minute with no sign of the end.
    """
    if isinstance(particles, bool) or not isinstance(particles, int) or particles < 1:
        raise InputError(f"particles: expected an integer >= 1, got {particles!r}")
    seconds = float(particles) * float(reports + updates) * _SECONDS_PER_PARTICLE_EVENT
    if seconds > MAX_FILTER_SECONDS:
        fewest = max(1, int(MAX_FILTER_SECONDS / (float(reports + updates) * _SECONDS_PER_PARTICLE_EVENT)))
        raise InputError(
            f"particles: expected a particle filter of at most {MAX_FILTER_SECONDS:g} s (at most {fewest} "
            f"particles over this log's {reports} reports and {updates} updates), got {particles}: "
            f"about {seconds:.3g} s"
        )


def _check_others(others: object, taken: set[str]) -> list[tuple[str, Callable[[Pose], Estimator]]]:
    """Check :func:`compare_on_log`'s ``others``; return its (name, factory) pairs in order."""
    if others is None:
        return []
    if not isinstance(others, Mapping):
        raise InputError(
            f"others: expected a mapping of names to estimator factories, got {type(others).__name__}"
        )
    checked: list[tuple[str, Callable[[Pose], Estimator]]] = []
    for name, factory in others.items():
        if not isinstance(name, str) or not name or name in taken:
            raise InputError(
                f"others: expected names that are new non-empty strings (not {sorted(taken)}), got {name!r}"
            )
        if not callable(factory):
            raise InputError(f"others[{name!r}]: expected a callable taking the start Pose, got {factory!r}")
        checked.append((name, factory))
    return checked
