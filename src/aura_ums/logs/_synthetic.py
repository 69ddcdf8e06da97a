"""A clean synthetic log with known truth: for tests, tutorials and checking a pipeline end to end."""

from __future__ import annotations

import math

import numpy as np

from aura_ums._validate import LENGTH, SPEED, check_rng, finite_float, integer_at_least
from aura_ums.errors import InputError
from aura_ums.logs._log import GroundTruth, LogLandmark, LogMeta, LogObservation, RobotLog
from aura_ums.logs._odometry import MAX_REPORTS
from aura_ums.manager import PositionReport
from aura_ums.uncertainty import Pose, TerrainStats, TerrainTable, TurnAndRun

#: Seconds to drive and log one command, for the estimate in a refusal.
_SECONDS_PER_COMMAND = 1.1e-4

#: The eight landmarks of :func:`synthetic_log`, around a 10 m x 10 m arena centred on the origin.
_SYNTHETIC_LANDMARKS: tuple[tuple[str, float, float], ...] = (
    ("L1", -6.0, -6.0),
    ("L2", 0.0, -6.5),
    ("L3", 6.0, -6.0),
    ("L4", 6.5, 0.0),
    ("L5", 6.0, 6.0),
    ("L6", 0.0, 6.5),
    ("L7", -6.0, 6.0),
    ("L8", -6.5, 0.0),
)


def synthetic_log(
    rng: np.random.Generator,
    *,
    duration: float = 60.0,
    rate: float = 10.0,
    frame_every: int = 3,
    speed: float = 0.3,
    terrain: TerrainStats | None = None,
    bearing_noise: float = 0.01,
    range_noise: float = 0.02,
    field_of_view: float = 1.2,
    max_range: float = 9.0,
) -> RobotLog:
    """Drive a robot around a square arena of eight landmarks and log it, with its truth.

    The robot runs at ``speed`` and steers back towards the centre when it strays beyond
    3 m from it. Commands are recorded at ``rate`` Hz; the true motion of each comes from
    ``terrain.sample_motion`` truncated at 3 sigma (so the terrain's growth bound is sound
    for it). Every ``frame_every``-th command, each landmark within ``max_range`` and
    inside the camera's ``field_of_view`` is observed with bearing and range, their errors
    uniform within ``+-bearing_noise`` (rad) and ``+-range_noise`` (fraction of the true
    range): the log's meta gives exactly these bounds.

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of every random draw.
    duration : float
        Seconds, > 0.
    rate : float
        Commands per second, > 0.
    frame_every : int
        Commands per camera frame, >= 1.
    speed : float
        Metres per second, >= 0.
    terrain : TerrainStats or None
        The floor's statistics; default the built-in ``tile``.
    bearing_noise : float
        Radians, > 0.
    range_noise : float
        Fraction of the range, in [0, 0.5).
    field_of_view : float
        Radians, in (0, 2 pi].
    max_range : float
        Metres, > 0.

    Returns
    -------
    RobotLog
        Named ``"synthetic"`` on terrain ``"floor"``, with commands, observations of the
        eight poles ``L1`` to ``L8`` around a 10 m x 10 m arena centred on the origin, and
        ground truth at every command.

    Raises
    ------
    InputError
        For an argument out of range.

    Examples
    --------
    >>> log = synthetic_log(np.random.default_rng(1), duration=10.0)
    >>> len(log.commands), len(log.groundtruth), log.meta.bearing_error
    (100, 101, 0.01)
    >>> synthetic_log(np.random.default_rng(1), duration=0.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: duration: expected a positive number of seconds, got 0.0
    """
    check_rng(rng)
    seconds = finite_float(duration, "duration")
    if not seconds > 0.0:
        raise InputError(f"duration: expected a positive number of seconds, got {seconds!r}")
    hz = finite_float(rate, "rate")
    if not hz > 0.0:
        raise InputError(f"rate: expected a positive number of commands per second, got {hz!r}")
    integer_at_least(frame_every, "frame_every", 1)
    stats = TerrainTable.default()["tile"] if terrain is None else terrain
    if not isinstance(stats, TerrainStats):
        raise InputError(f"terrain: expected TerrainStats or None, got {type(stats).__name__}")
    noise_b = finite_float(bearing_noise, "bearing_noise")
    noise_r = finite_float(range_noise, "range_noise")
    if not noise_b > 0.0 or not 0.0 <= noise_r < 0.5:
        raise InputError(
            f"bearing_noise, range_noise: expected > 0 and in [0, 0.5), got {noise_b!r}, {noise_r!r}"
        )
    fov = finite_float(field_of_view, "field_of_view")
    reach = finite_float(max_range, "max_range")
    if not 0.0 < fov <= 2.0 * math.pi or not reach > 0.0:
        raise InputError(f"field_of_view, max_range: expected in (0, 2 pi] and > 0, got {fov!r}, {reach!r}")
    run_speed = SPEED.check(speed, "speed")
    if run_speed < 0.0:
        raise InputError(f"speed: expected a number >= 0, got {run_speed!r}")
    commands = seconds * hz  # inf when both are huge: refused below
    if not commands < MAX_REPORTS - 0.5:
        raise InputError(
            f"duration, rate: expected at most {MAX_REPORTS} commands (duration x rate; about "
            f"{_SECONDS_PER_COMMAND * 1e6:g} us each to drive and log), got {commands:.3g} "
            f"(about {commands * _SECONDS_PER_COMMAND:.3g} s)"
        )

    dt = 1.0 / hz
    if run_speed * dt > LENGTH.high:
        raise InputError(
            f"speed, rate: expected at most {LENGTH.high:g} m a command (speed / rate), "
            f"got {run_speed * dt:g} m ({run_speed!r} m/s at {hz!r} Hz)"
        )
    steps = max(1, round(commands))
    pose = Pose(0.0, 0.0, float(rng.uniform(-math.pi, math.pi)))
    times, xs, ys, headings = [0.0], [pose.x], [pose.y], [pose.heading]
    reports: list[PositionReport] = []
    observations: list[LogObservation] = []
    landmarks = tuple(LogLandmark(name, x, y, 0.01, 0.0, 2.0, "pole") for name, x, y in _SYNTHETIC_LANDMARKS)
    for step in range(1, steps + 1):
        time = round(step * dt, 9)
        if math.hypot(pose.x, pose.y) > 3.0:
            home = math.atan2(-pose.y, -pose.x)
            desired = math.remainder(home - pose.heading, 2.0 * math.pi)
            turn = max(-0.6 * dt, min(0.6 * dt, desired))
        else:
            turn = float(rng.normal(0.0, 0.2)) * dt
        command = TurnAndRun(turn, run_speed * dt)
        pose = stats.sample_motion(pose, command, rng, truncate=3.0)
        reports.append(PositionReport(time, command))
        times.append(time)
        xs.append(pose.x)
        ys.append(pose.y)
        headings.append(pose.heading)
        if step % frame_every:
            continue
        for landmark in landmarks:
            dx, dy = landmark.x - pose.x, landmark.y - pose.y
            distance = math.hypot(dx, dy)
            bearing = math.remainder(math.atan2(dy, dx) - pose.heading, 2.0 * math.pi)
            if distance > reach or abs(bearing) > fov / 2.0:
                continue
            measured_bearing = math.remainder(bearing + float(rng.uniform(-noise_b, noise_b)), 2.0 * math.pi)
            measured_range = distance * (1.0 + float(rng.uniform(-noise_r, noise_r)))
            observations.append(LogObservation(time, landmark.id, measured_bearing, measured_range))
    meta = LogMeta(
        "synthetic",
        terrain="floor",
        bearing_error=noise_b,
        range_error=0.0,
        # |measured - true| <= noise * true <= noise / (1 - noise) * measured
        range_error_fraction=noise_r / (1.0 - noise_r),
        start_radius=0.05,
        start_heading_halfwidth=0.02,
        source="aura_ums.logs.synthetic_log",
    )
    truth = GroundTruth(times, xs, ys, headings)
    return RobotLog(meta, landmarks, tuple(observations), commands=tuple(reports), groundtruth=truth)
