"""Image windows on a replayed log: the Expecter's, an EKF's 3-sigma box's and the disk model's.

A log from a robot without a camera model (or with one) is replayed through a camera of
the user's choosing. Before each frame's observations reduce the map, the Expecter is
asked for each observed landmark's window from the map of that moment (grown to the
frame's time, not yet reduced), and from the focus map of that moment (with the relaxed
intersection, the poses that agree with every recent sighting: the window to search
first, the map's being the one guaranteed); the EKF, run alongside on the same position reports and
observations, gives its 3-sigma box's window, and the disk model the window of the circle
around the same map. Each real observation is then judged: does its measured pixel lie
inside each window? A window is judged as a set of whole pixels, as a perception module
scans it: an observation is inside when the window meets the pixel its point falls in
(:meth:`~aura_ums.geometry.ImageWindow.meets_pixel_of`).

The measured pixel is the landmark's image where the observation puts it: the point at
the measured bearing, at the measured range (Class I rows without a range: the distance
from the map's centre to the landmark) and at the landmark's height, projected through
the camera. Class I landmarks are vertical lines, so only the column is judged, at the
line's height nearest the camera's (the column of a vertical line seen by a level camera
is the same at every height); Class II points are judged by column and row, the row from
the range and the point's known height.
"""

from __future__ import annotations

import math
import os
import statistics
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from aura_ums._metrics import Metrics
from aura_ums._validate import finite_float
from aura_ums.baselines import ExtendedKalmanFilter
from aura_ums.camera import CalibrationBounds, Camera
from aura_ums.errors import InputError
from aura_ums.expecter import Expecter, ImageWindow, disk_model_window, gaussian_window, margin_pixels
from aura_ums.logs._calibrate import SensorBounds
from aura_ums.logs._compare import filter_settings
from aura_ums.logs._log import LogObservation, RobotLog
from aura_ums.logs._replay import (
    ReplayOptions,
    ReplayResult,
    ReplayStep,
    _observation_for,
    log_meadow_map,
    meta_bounds,
    position_reports_for,
    replay_log,
    replay_start,
    with_motion,
)
from aura_ums.logs._state import ReplayState
from aura_ums.uncertainty import (
    BearingObservation,
    LandmarkClass,
    PointLandmark,
    Pose,
    RangeBearingObservation,
    SpatialUncertaintyMap,
    TerrainTable,
    VerticalLineLandmark,
)
from aura_ums.world import PerceptualStrategy

#: The methods whose windows are judged, in the order of the rows and of the CSV.
OURS = "aura-ums"
#: The Expecter's window from the focus map (:attr:`UncertaintyMapManager.focus_map`).
FOCUS = "aura-ums focus"
EKF_BOX = "EKF 3-sigma box"
DISK_MODEL = "disk model"
WINDOW_METHODS: tuple[str, ...] = (OURS, FOCUS, EKF_BOX, DISK_MODEL)

#: Columns of :meth:`WindowReport.to_csv`, each a key of the metrics table.
CSV_COLUMNS: tuple[str, ...] = (
    "time",
    "landmark_id",
    "landmark_class",
    "method",
    "u_min_px",
    "v_min_px",
    "u_max_px",
    "v_max_px",
    "measured_u_px",
    "measured_v_px",
    "in_view",
    "in_window",
    "truth_in_window",
    "window_width_frac",
    "window_area_frac",
)

#: Standard normal quantile of 0.995: a Gaussian's 99% two-sided interval is +-2.576 sd.
_Z99 = statistics.NormalDist().inv_cdf(0.995)
#: The robot's own frame, where a measured landmark is placed to find its pixel.
_ROBOT_ORIGIN = Pose(0.0, 0.0, 0.0)
#: Heights of a vertical line projected to tell whether any of it images within the rows.
_POLE_SAMPLES = 65


@dataclass(frozen=True, slots=True)
class WindowRow:
    """One method's window for one real observation, and whether the observation fell inside.

    Attributes
    ----------
    time : float
        Seconds: the observation's (its frame's) time stamp.
    landmark_id : str
        The landmark observed.
    landmark_class : LandmarkClass
        ``VERTICAL_LINE`` (Class I, judged by column) or ``POINT`` (Class II, by column and row).
    method : str
        One of :attr:`WindowReport.methods`.
    window : ImageWindow or None
        The window searched, pixels: grown by the margin and clipped to the image; None when
        the method says the landmark cannot be in view.
    measured_u, measured_v : float
        The measured pixel, pixels; NaN where the observation gives none (behind the
        camera; ``measured_v`` for Class I, or a Class II row without a range).
    in_view : bool
        Whether the measured pixel lies in the image (Class I: its column): only those
        observations are judged.
    inside : bool or None
        Whether the measured pixel lies in ``window``; None when not judged.
    truth_inside : bool or None
        Whether the landmark, projected from the true pose, lies in ``window``; None when
        not judged, without ground truth at ``time``, or when that projection is out of
        the image.
    width_frac, area_frac : float
        The window's width over the image's, and its area over the image's (0 without a
        window).

    Examples
    --------
    >>> from aura_ums.camera import CameraIntrinsics, CameraMount
    >>> from aura_ums.logs import synthetic_log
    >>> camera = Camera(CameraIntrinsics(554.26, 554.26, 319.5, 239.5, 640, 480), CameraMount(0.3))
    >>> log = synthetic_log(np.random.default_rng(0), duration=5.0)
    >>> _, report = replay_windows(log, TerrainTable({"floor": TerrainTable.default()["tile"]}), camera)
    >>> row = report.rows[0]
    >>> row.landmark_id, row.landmark_class.value, row.method, row.in_view, row.inside, row.truth_inside
    ('L5', 'I', 'aura-ums', True, True, True)
    >>> 0.0 < row.width_frac < 0.1, math.isnan(row.measured_v)          # Class I: judged by column
    (True, True)
    >>> unseen = WindowRow(1.0, "L1", LandmarkClass.VERTICAL_LINE, "disk model", None, math.nan, math.nan,
    ...                    False, None, None, 0.0, 0.0)                  # no window: cannot be in view
    >>> WindowReport(camera, 0.0, (unseen,)).judged("disk model")          # so not judged
    ()
    """

    time: float
    landmark_id: str
    landmark_class: LandmarkClass
    method: str
    window: ImageWindow | None
    measured_u: float
    measured_v: float
    in_view: bool
    inside: bool | None
    truth_inside: bool | None
    width_frac: float
    area_frac: float


@dataclass(frozen=True, slots=True, eq=False)
class WindowReport:
    """Every window :func:`replay_windows` asked for, judged against the real observations.

    Attributes
    ----------
    camera : Camera
        The camera the windows were computed for.
    margin : float
        Pixels added on every side of each window before clipping it to the image.
    rows : tuple of WindowRow
        One per observation and method, in time order, the methods in :attr:`methods` order.
    methods : tuple of str
        Class attribute: the methods judged, ``("aura-ums", "aura-ums focus", "EKF 3-sigma box",
        "disk model")``.
    csv_columns : tuple of str
        Class attribute: the columns of :meth:`to_csv`, each a key of the metrics table.

    Examples
    --------
    >>> from aura_ums.camera import CameraIntrinsics, CameraMount
    >>> camera = Camera(CameraIntrinsics(554.26, 554.26, 319.5, 239.5, 640, 480), CameraMount(0.3))
    >>> report = WindowReport(camera, 0.0, ())
    >>> report.metrics()["window_containment"] is None      # nothing judged: undefined
    True
    >>> report.to_csv().splitlines()[0].split(",")[:4]
    ['time', 'landmark_id', 'landmark_class', 'method']
    """

    camera: Camera
    margin: float
    rows: tuple[WindowRow, ...]
    methods: ClassVar[tuple[str, ...]] = WINDOW_METHODS
    csv_columns: ClassVar[tuple[str, ...]] = CSV_COLUMNS

    def judged(self, method: str) -> tuple[WindowRow, ...]:
        """Return the rows of ``method`` whose observation is judged (measured pixel in the image)."""
        if method not in WINDOW_METHODS:
            raise InputError(f"method: expected one of {list(WINDOW_METHODS)}, got {method!r}")
        return tuple(row for row in self.rows if row.method == method and row.inside is not None)

    def figures(self, method: str) -> Metrics:
        """Return one method's figures: containment (measured, true) and median window size.

        Undefined figures (nothing judged; no ground truth) are None.
        """
        rows = self.judged(method)
        truths = [row.truth_inside for row in rows if row.truth_inside is not None]
        return Metrics(
            {
                "window_containment": float(np.mean([row.inside for row in rows])) if rows else None,
                "window_truth_containment": float(np.mean(truths)) if truths else None,
                "median_window_width_frac": float(np.median([r.width_frac for r in rows])) if rows else None,
                "median_window_area_frac": float(np.median([r.area_frac for r in rows])) if rows else None,
            }
        )

    def metrics(self) -> Metrics:
        """Return the window metrics (keys: ``docs/metrics.md``): ours, the focus map's, the baselines'."""
        ours = self.figures(OURS)
        focus = self.figures(FOCUS)
        baselines = tuple(
            Metrics({"method": method, **self.figures(method)})
            for method in WINDOW_METHODS
            if method not in (OURS, FOCUS)
        )
        return Metrics(
            {
                "window_margin_px": self.margin,
                "window_observations": len(self.judged(OURS)),
                **ours,
                "focus_window_containment": focus["window_containment"],
                "focus_window_truth_containment": focus["window_truth_containment"],
                "median_focus_window_width_frac": focus["median_window_width_frac"],
                "median_searched_width_frac": self._searched_width(),
                "window_baselines": baselines,
            }
        )

    def _searched_width(self) -> float | None:
        """Median width searched focus first: the focus window's if the observation is in it, else ours."""
        searched = [
            focus.width_frac if focus.inside else ours.width_frac
            for ours, focus in zip(self.judged(OURS), self.judged(FOCUS), strict=True)
        ]
        return float(np.median(searched)) if searched else None

    def to_csv(self) -> str:
        """Return the rows as CSV text: :attr:`csv_columns`, one line per observation and method.

        Numbers are written with ``repr`` precision; an undefined cell (no window, no
        measured row, not judged) is empty; flags are 1 or 0.
        """
        lines = [",".join(CSV_COLUMNS)]
        for row in self.rows:
            w = row.window
            bounds = (
                ("", "", "", "")
                if w is None
                else (repr(w.u_min), repr(w.v_min), repr(w.u_max), repr(w.v_max))
            )
            cells = (
                repr(row.time),
                _csv_text(row.landmark_id),
                row.landmark_class.value,
                row.method,
                *bounds,
                _csv_number(row.measured_u),
                _csv_number(row.measured_v),
                _csv_flag(row.in_view),
                _csv_flag(row.inside),
                _csv_flag(row.truth_inside),
                repr(row.width_frac),
                repr(row.area_frac),
            )
            lines.append(",".join(cells))
        return "\n".join(lines) + "\n"


def ekf_noise(bounds: SensorBounds) -> tuple[float, float]:
    """Return ``(bearing_sd, range_sd_fraction)`` whose Gaussian 99% interval is ``bounds``.

    The EKF beside our map gets the same information: a standard deviation of the bound
    over 2.576 (rad; and the mean of the two range fractions over 2.576, at least 1e-3).

    Examples
    --------
    >>> [round(x, 4) for x in ekf_noise(SensorBounds(0.05, 0.0, 0.1, 0.1))]
    [0.0194, 0.0388]
    >>> ekf_noise(SensorBounds(0.05))[1]                      # no range fraction: a floor
    0.001
    """
    if not isinstance(bounds, SensorBounds):
        raise InputError(f"bounds: expected SensorBounds, got {type(bounds).__name__}")
    fraction = (bounds.range_fraction_low + bounds.range_fraction_high) / 2.0
    return bounds.bearing_error / _Z99, max(fraction / _Z99, 1e-3)


def replay_windows(
    log: RobotLog,
    table: TerrainTable,
    camera: Camera,
    options: ReplayOptions | None = None,
    *,
    margin: float | PerceptualStrategy = 0.0,
    bearing_sd: float | None = None,
    range_sd_fraction: float | None = None,
    sigmas: float = 3.0,
    keep_maps: bool = True,
    steps_csv: str | os.PathLike[str] | None = None,
    progress: Callable[[int, int], None] | None = None,
    until: float | None = None,
    resume: ReplayState | None = None,
    save_state: bool = False,
    after_step: Callable[[ReplayStep, tuple[WindowRow, ...]], None] | None = None,
    calibration_bounds: CalibrationBounds | None = None,
) -> tuple[ReplayResult, WindowReport]:
    """Replay a log and judge, for each real observation, the image windows of four methods.

    :func:`replay_log` runs as usual; before each frame's observations reduce the map, the
    :class:`~aura_ums.expecter.Expecter` gives each observed landmark's window from the map
    grown to that time (``aura-ums``) and from the focus map grown to that time
    (``aura-ums focus``: :attr:`~aura_ums.manager.UncertaintyMapManager.focus_map`, the
    same window without the relaxed intersection); an :class:`~aura_ums.baselines.ExtendedKalmanFilter`,
    predicted by the same position reports up to that time, gives its ``sigmas`` box's
    window (:func:`~aura_ums.expecter.gaussian_window`); and the disk model gives the window
    of the circle around the same map (:func:`~aura_ums.expecter.disk_model_window`). The
    EKF then takes the frame's observations, as :func:`compare_on_log` feeds it. Windows
    are grown by ``margin`` and clipped to the image; see the module notes for the
    measured pixel each is judged by.

    Parameters
    ----------
    log : RobotLog
        The log; ground truth, when present, also judges where the landmark truly appeared.
    table : TerrainTable
        Must hold the log's terrain.
    camera : Camera
        The camera on the robot (or a virtual one, for a log without).
    options : ReplayOptions or None
        As for :func:`replay_log`.
    margin : float or PerceptualStrategy
        Pixels (>= 0) added on every side of every window, or a strategy's margin.
    bearing_sd, range_sd_fraction : float or None
        The EKF's measurement noise (rad; fraction of the range); None: :func:`ekf_noise` of
        the replay's working bounds.
    sigmas : float
        Half-width of the EKF's box in standard deviations, > 0.
    keep_maps, steps_csv, progress, until, resume, save_state
        As for :func:`replay_log`.
    after_step : callable or None
        As for :func:`replay_log`, called as ``after_step(step, rows)`` with the step's
        window rows too (one per observation of the frame and method).
    calibration_bounds : CalibrationBounds or None
        How far the true camera may be from ``camera`` (a camera file's
        ``[calibration_bounds]``): every method's windows then hold for every camera within
        them (:class:`~aura_ums.expecter.Expecter`). None: the camera is exact.

    Returns
    -------
    (ReplayResult, WindowReport)
        The replay, exactly as :func:`replay_log` returns it, and its windows.

    Raises
    ------
    InputError
        For a bad argument (as :func:`replay_log`, and a camera that is not a Camera, a
        negative margin, non-positive noise or sigmas).

    Examples
    --------
    >>> from aura_ums.camera import CameraIntrinsics, CameraMount
    >>> from aura_ums.logs import synthetic_log
    >>> camera = Camera(CameraIntrinsics(554.26, 554.26, 319.5, 239.5, 640, 480), CameraMount(0.3))
    >>> log = synthetic_log(np.random.default_rng(3), duration=20.0)
    >>> table = TerrainTable({"floor": TerrainTable.default()["tile"]})
    >>> result, windows = replay_windows(log, table, camera)
    >>> figures = windows.metrics()
    >>> figures["window_truth_containment"], figures["median_window_width_frac"] < 0.5
    (1.0, True)
    >>> [row["method"] for row in figures["window_baselines"]]
    ['EKF 3-sigma box', 'disk model']
    >>> replay_windows(log, table, camera, margin=-1.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: margin: expected a non-negative number, got -1.0
    """
    if not isinstance(camera, Camera):
        raise InputError(f"camera: expected a Camera, got {type(camera).__name__}")
    pixels = margin_pixels(margin)
    box_sigmas = finite_float(sigmas, "sigmas")
    if not box_sigmas > 0.0:
        raise InputError(f"sigmas: expected a positive number, got {box_sigmas!r}")
    opts = ReplayOptions() if options is None else options
    if not isinstance(opts, ReplayOptions):
        raise InputError(f"options: expected ReplayOptions or None, got {type(opts).__name__}")
    if not isinstance(log, RobotLog):
        raise InputError(f"log: expected a RobotLog, got {type(log).__name__}")
    if not isinstance(table, TerrainTable):
        raise InputError(f"table: expected a TerrainTable, got {type(table).__name__}")
    table.require(log.meta.terrain, where="table", whose="the log (its meta.toml)")
    bounds = opts.working if opts.working is not None else meta_bounds(log)
    default_b, default_r = ekf_noise(bounds)
    b_sd = default_b if bearing_sd is None else finite_float(bearing_sd, "bearing_sd")
    r_sd = default_r if range_sd_fraction is None else finite_float(range_sd_fraction, "range_sd_fraction")
    if not b_sd > 0.0 or not r_sd > 0.0:
        raise InputError(f"bearing_sd, range_sd_fraction: expected positive numbers, got {b_sd!r}, {r_sd!r}")

    if after_step is not None and not callable(after_step):
        raise InputError(f"after_step: expected a callable or None, got {type(after_step).__name__}")
    expecter = Expecter(camera, calibration_bounds)
    judge = _Judge(log, table, expecter, opts, pixels, box_sigmas, b_sd, r_sd, bounds)
    forward = None if after_step is None else _with_rows(after_step, judge)
    result = replay_log(
        log, table, opts, before_frame=judge, keep_maps=keep_maps, steps_csv=steps_csv, progress=progress,
        until=until, resume=resume, save_state=save_state, after_step=forward,
    )  # fmt: skip
    return result, WindowReport(camera, pixels, tuple(judge.rows))


def _with_rows(
    after_step: Callable[[ReplayStep, tuple[WindowRow, ...]], None], judge: _Judge
) -> Callable[[ReplayStep], None]:
    """Return the replay's ``after_step`` that hands on each step with the window rows judged for it."""
    shown = 0

    def forward(step: ReplayStep) -> None:
        nonlocal shown
        rows, shown = tuple(judge.rows[shown:]), len(judge.rows)
        after_step(step, rows)

    return forward


class _Judge:
    """The replay's ``before_frame``: steps the EKF and judges the four windows of each row."""

    def __init__(
        self,
        log: RobotLog,
        table: TerrainTable,
        expecter: Expecter,
        options: ReplayOptions,
        margin: float,
        sigmas: float,
        bearing_sd: float,
        range_sd_fraction: float,
        bounds: SensorBounds,
    ) -> None:
        moved = with_motion(log, options.motion)
        self._log = moved
        self._class = options.landmark_class
        self._bounds = bounds
        self._terrain = table[moved.meta.terrain]
        self._reports = position_reports_for(log, options)
        self._next = 0
        _, start = replay_start(moved)
        common = filter_settings(moved, bearing_sd=bearing_sd, range_sd_fraction=range_sd_fraction)
        self._ekf = ExtendedKalmanFilter(start, gate_probability=0.999, **common)
        meadows = log_meadow_map(moved, options.landmark_class, margin=options.arena_margin)
        self._landmarks = {
            lm.id: _judged_landmark(meadows.landmark(lm.id).landmark) for lm in moved.landmarks
        }
        self._sensor = moved.meta.sensor_offset
        self._camera = expecter.camera
        self._expecter = expecter
        self._margin = margin
        self._sigmas = sigmas
        self.rows: list[WindowRow] = []

    def __call__(
        self,
        time: float,
        grown: SpatialUncertaintyMap,
        rows: Sequence[LogObservation],
        focus: SpatialUncertaintyMap,
    ) -> None:
        ekf, reports = self._ekf, self._reports
        while self._next < len(reports) and reports[self._next].time <= time:
            ekf.predict(reports[self._next].command, self._terrain)
            self._next += 1
        mean, covariance = ekf.mean, ekf.covariance
        truth = self._truth(time)
        expecter, margin = self._expecter, self._margin
        # A landmark's windows and true pixel are the frame's, whatever the sighting: once per
        # landmark (a frame of 100,000 sightings of one pole took 80 s, window by window).
        seen: dict[str, tuple[tuple[ImageWindow | None, ...], tuple[float, float] | None]] = {}
        for row in rows:
            landmark = self._landmarks[row.landmark_id]
            measured = self._measured(row, landmark, grown)
            if row.landmark_id not in seen:
                ours = expecter.window(grown, landmark, margin=margin)
                seen[row.landmark_id] = (
                    (
                        ours,
                        ours if focus is grown else expecter.window(focus, landmark, margin=margin),
                        gaussian_window(expecter, mean, covariance, landmark, self._sigmas, margin=margin),
                        disk_model_window(expecter, grown, landmark, margin=margin),
                    ),
                    None if truth is None else self._projected(truth, landmark),
                )
            windows, true_pixel = seen[row.landmark_id]
            for method, window in zip(WINDOW_METHODS, windows, strict=True):
                self.rows.append(self._row(time, row.landmark_id, method, window, measured, true_pixel))
        for row in rows:
            observation = _observation_for(row, self._class, self._bounds, 1.0, self._sensor)
            if isinstance(observation, (BearingObservation, RangeBearingObservation)):
                landmark = self._landmarks[row.landmark_id]
                ekf.update(observation, (landmark.x, landmark.y))

    def _truth(self, time: float) -> Pose | None:
        truth = self._log.groundtruth
        if truth is None:
            return None
        x, y, heading = truth.at([time])[0]
        return None if math.isnan(x) else Pose(float(x), float(y), float(heading))

    def _height(self, landmark: VerticalLineLandmark | PointLandmark) -> float:
        """Return the landmark's height judged (m): the point's; the line's nearest the camera's."""
        if isinstance(landmark, PointLandmark):
            return landmark.z
        return min(max(self._camera.mount.height, landmark.z_bottom), landmark.z_top)

    def _measured(
        self,
        row: LogObservation,
        landmark: VerticalLineLandmark | PointLandmark,
        grown: SpatialUncertaintyMap,
    ) -> tuple[float, float]:
        """Return the measured pixel (u, v); v is NaN for Class I, both NaN without a usable range."""
        forward, left = self._sensor
        distance = row.range
        if distance is None:
            if self._class is LandmarkClass.POINT:
                return math.nan, math.nan
            # Bearings are the sensor's: its distance from the landmark at the map's centre pose.
            cx, cy = grown.center
            heading = grown.wedge.center
            sx = cx + forward * math.cos(heading) - left * math.sin(heading)
            sy = cy + forward * math.sin(heading) + left * math.cos(heading)
            distance = math.hypot(landmark.x - sx, landmark.y - sy)
        # The landmark in the robot frame: measured from the sensor, which sits at (forward, left).
        x, y = forward + distance * math.cos(row.bearing), left + distance * math.sin(row.bearing)
        if not self._pole_in_rows(_ROBOT_ORIGIN, x, y, landmark):
            return math.nan, math.nan
        u, v = self._camera.project(_ROBOT_ORIGIN, [(x, y, self._height(landmark))])[0]
        return float(u), float(v) if self._class is LandmarkClass.POINT else math.nan

    def _projected(self, pose: Pose, landmark: VerticalLineLandmark | PointLandmark) -> tuple[float, float]:
        """Return where the landmark truly appeared from ``pose`` (u, v); v NaN for Class I."""
        if not self._pole_in_rows(pose, landmark.x, landmark.y, landmark):
            return math.nan, math.nan
        point = (landmark.x, landmark.y, self._height(landmark))
        u, v = self._camera.project(pose, [point])[0]
        return float(u), float(v) if self._class is LandmarkClass.POINT else math.nan

    def _pole_in_rows(
        self, pose: Pose, x: float, y: float, landmark: VerticalLineLandmark | PointLandmark
    ) -> bool:
        """Whether some height of a vertical line at (x, y) images within the image's rows.

        A Class I observation is judged by its column only; a tilted camera can see that
        column while the whole pole lies above or below the image, where the Expecter rightly
        gives no window, and such a row was counted a miss (helper-62: 157 of 175 misses at a
        tilt of 0.5 rad). Heights imaged nowhere (behind the camera) leave the column to decide.
        """
        if not isinstance(landmark, VerticalLineLandmark):
            return True
        # Its height nearest the camera's first: a pole just ahead of a level camera is seen
        # in a band of millimetres around it, which evenly spaced heights would step over.
        heights = np.append(
            self._height(landmark), np.linspace(landmark.z_bottom, landmark.z_top, _POLE_SAMPLES)
        )
        points = np.column_stack([np.full(len(heights), x), np.full(len(heights), y), heights])
        rows = self._camera.project(pose, points)[:, 1]
        rows = rows[np.isfinite(rows)]
        last = self._camera.intrinsics.height - 0.5
        return not rows.size or bool(np.any((rows >= -0.5) & (rows <= last)))

    def _in_image(self, pixel: tuple[float, float]) -> bool:
        k = self._camera.intrinsics
        u, v = pixel
        if not -0.5 <= u <= k.width - 0.5:  # NaN: behind the camera, not in view
            return False
        return self._class is not LandmarkClass.POINT or -0.5 <= v <= k.height - 0.5

    def _row(
        self,
        time: float,
        landmark_id: str,
        method: str,
        window: ImageWindow | None,
        measured: tuple[float, float],
        true_pixel: tuple[float, float] | None,
    ) -> WindowRow:
        k = self._camera.intrinsics
        in_view = self._in_image(measured)
        inside = (window is not None and self._contains(window, measured)) if in_view else None
        truth_inside: bool | None = None
        if in_view and true_pixel is not None and self._in_image(true_pixel):
            truth_inside = window is not None and self._contains(window, true_pixel)
        width = 0.0 if window is None else window.width / k.width
        area = 0.0 if window is None else window.area / (k.width * k.height)
        return WindowRow(
            time,
            landmark_id,
            self._class,
            method,
            window,
            measured[0],
            measured[1],
            in_view,
            inside,
            truth_inside,
            width,
            area,
        )

    def _contains(self, window: ImageWindow, pixel: tuple[float, float]) -> bool:
        u, v = pixel
        if self._class is not LandmarkClass.POINT:
            v = window.v_min  # a vertical line: its column alone is judged
        return bool(window.meets_pixel_of((u, v)))


def _judged_landmark(landmark: object) -> VerticalLineLandmark | PointLandmark:
    """Return the landmark, checked: the replay's are Class I or II (:func:`log_meadow_map`)."""
    if not isinstance(landmark, (VerticalLineLandmark, PointLandmark)):
        raise InputError(f"landmark: expected a vertical line or a point, got {type(landmark).__name__}")
    return landmark


def _csv_number(value: float) -> str:
    return "" if math.isnan(value) else repr(value)


def _csv_flag(value: bool | None) -> str:
    return "" if value is None else str(int(value))


def _csv_text(text: str) -> str:
    """Quote a cell as RFC 4180 does when it holds a comma, a quote or a line break."""
    if any(c in text for c in ',"\r\n'):
        return '"' + text.replace('"', '""') + '"'
    return text
