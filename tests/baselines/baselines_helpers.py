"""A simulated drive for the baseline estimators: true motion from the terrain model, noisy observations."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from aura_ums.baselines import Estimator
from aura_ums.uncertainty import (
    BearingObservation,
    Pose,
    RangeBearingObservation,
    TerrainStats,
    TurnAndRun,
)

#: Landmarks (x, y) around the loop the drive follows.
LANDMARKS: tuple[tuple[float, float], ...] = ((12.0, 4.0), (4.0, 14.0), (-6.0, 6.0), (6.0, -4.0))

BEARING_SD = 0.01
RANGE_SD = 0.15
START_POSITION_SD = 0.2
START_HEADING_SD = 0.02

Observed = BearingObservation | RangeBearingObservation


@dataclass(frozen=True)
class Step:
    """One step of a drive: the command, the true pose after it, and what was observed there."""

    command: TurnAndRun
    truth: Pose
    observations: tuple[tuple[Observed, tuple[float, float]], ...]


def observe(
    truth: Pose,
    landmark: tuple[float, float],
    rng: np.random.Generator,
    *,
    ranged: bool,
    bearing_sd: float = BEARING_SD,
    range_sd: float = RANGE_SD,
    sensor_offset: tuple[float, float] = (0.0, 0.0),
    time: float = 0.0,
) -> Observed:
    """A noisy observation of ``landmark`` from the true pose (Gaussian bearing and range noise)."""
    c, s = math.cos(truth.heading), math.sin(truth.heading)
    forward, left = sensor_offset
    sx = truth.x + forward * c - left * s
    sy = truth.y + forward * s + left * c
    dx, dy = landmark[0] - sx, landmark[1] - sy
    bearing = math.atan2(dy, dx) - truth.heading + bearing_sd * float(rng.standard_normal())
    if not ranged:
        return BearingObservation("lm", time, bearing, 3 * bearing_sd, sensor_offset)
    distance = math.hypot(dx, dy) + range_sd * float(rng.standard_normal())
    return RangeBearingObservation(
        "lm",
        time,
        bearing,
        3 * bearing_sd,
        max(distance - 3 * range_sd, 0.0),
        distance + 3 * range_sd,
        sensor_offset,
    )


def simulate_drive(
    rng: np.random.Generator,
    terrain: TerrainStats,
    *,
    steps: int = 24,
    ranged: bool = True,
    bearing_sd: float = BEARING_SD,
    range_sd: float = RANGE_SD,
    sensor_offset: tuple[float, float] = (0.0, 0.0),
) -> tuple[Pose, list[Step]]:
    """Drive a loop of turn-and-run commands; return the true start pose and the steps.

    The true start is drawn around (0, 0, 0) with the estimators' initial standard
    deviations; the truth then moves by :meth:`TerrainStats.sample_motion` (untruncated).
    """
    noise = rng.standard_normal(3)
    truth = Pose(
        START_POSITION_SD * float(noise[0]),
        START_POSITION_SD * float(noise[1]),
        START_HEADING_SD * float(noise[2]),
    )
    start = truth
    result = []
    for k in range(steps):
        command = TurnAndRun(0.0 if k == 0 else math.pi / 6, 3.0)
        truth = terrain.sample_motion(truth, command, rng)
        seen = tuple(
            (
                observe(
                    truth,
                    lm,
                    rng,
                    ranged=ranged,
                    bearing_sd=bearing_sd,
                    range_sd=range_sd,
                    sensor_offset=sensor_offset,
                    time=float(k),
                ),
                lm,
            )
            for lm in LANDMARKS
        )
        result.append(Step(command, truth, seen))
    return start, result


@dataclass(frozen=True)
class Tally:
    """Per-step outcome of running an estimator over a drive."""

    covered: int
    steps: int
    position_errors: tuple[float, ...]
    heading_errors: tuple[float, ...]

    @property
    def coverage(self) -> float:
        return self.covered / self.steps

    @property
    def mean_position_error(self) -> float:
        return float(np.mean(self.position_errors))

    @property
    def mean_heading_error(self) -> float:
        return float(np.mean(self.heading_errors))


def run_drive(
    estimator: Estimator, steps: list[Step], terrain: TerrainStats, probability: float = 0.99
) -> Tally:
    """Feed the drive to ``estimator``; count the steps whose region contains the truth."""
    covered = 0
    position_errors = []
    heading_errors = []
    for step in steps:
        estimator.predict(step.command, terrain)
        for observation, landmark in step.observations:
            estimator.update(observation, landmark)
        truth = step.truth
        covered += bool(estimator.region(probability).contains(truth.x, truth.y, truth.heading))
        mean = estimator.mean
        position_errors.append(math.hypot(mean.x - truth.x, mean.y - truth.y))
        heading_errors.append(abs(math.remainder(mean.heading - truth.heading, 2 * math.pi)))
    return Tally(covered, len(steps), tuple(position_errors), tuple(heading_errors))
