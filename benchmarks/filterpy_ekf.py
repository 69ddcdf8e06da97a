"""filterpy's ExtendedKalmanFilter with aura-ums's motion and sensor model, written as a user would.

The benchmarks' off-the-shelf EKF: the same mean motion and moments
(:func:`aura_ums.baselines.motion_moments`), the same analytic Jacobians and filterpy's own
Joseph update, with F, Q, H and R built with numpy per call. ``FilterpyLogEkf`` adds what
a replay needs: any landmark, bearing-only or range-and-bearing observations, and the same
99.9% Mahalanobis gate as :class:`aura_ums.baselines.ExtendedKalmanFilter` (computed from
filterpy's state with numpy before its update, as a user adds a gate to filterpy), and
the confidence region (:meth:`aura_ums.baselines.ConfidenceRegion.gaussian`), so that it
is an :class:`aura_ums.baselines.Estimator` that :func:`aura_ums.logs.compare_on_log`
steps next to ours. The sensor sits at the robot's reference point (as on the MRCLAM robots).
"""

from __future__ import annotations

import math

import numpy as np
from filterpy.kalman import ExtendedKalmanFilter as FilterpyEkf
from numpy.typing import NDArray

from aura_ums.baselines import ConfidenceRegion, chi2_quantile, motion_moments
from aura_ums.uncertainty import (
    BearingObservation,
    Pose,
    RangeBearingObservation,
    TerrainStats,
    TurnAndRun,
)

Array = NDArray[np.float64]


class FilterpyPose(FilterpyEkf):  # type: ignore[misc]
    """filterpy's EKF on (x, y, heading); ``predict_x`` moves the mean by the model's mean motion."""

    x: Array

    def __init__(self) -> None:
        super().__init__(dim_x=3, dim_z=2)
        self.motion = (0.0, 0.0)

    def predict_x(self, u: object = 0) -> None:
        turn_mean, run_mean = self.motion
        heading = float(self.x[2]) + turn_mean
        self.x = np.array(
            [
                self.x[0] + run_mean * math.cos(heading),
                self.x[1] + run_mean * math.sin(heading),
                math.remainder(heading, 2 * math.pi),
            ]
        )


def filterpy_predict(ekf: FilterpyPose, command: TurnAndRun, terrain: TerrainStats) -> None:
    """Predict with F and Q of the model's moments (as aura-ums's EKF, in matrices)."""
    moments = motion_moments(terrain, command)
    heading = float(ekf.x[2]) + moments.turn_mean
    c, s, m = math.cos(heading), math.sin(heading), moments.run_mean
    ekf.F = np.array([[1.0, 0.0, -m * s], [0.0, 1.0, m * c], [0.0, 0.0, 1.0]])
    noise = np.array([[-m * s, c, -m * s / 2], [m * c, s, m * c / 2], [1.0, 0.0, 1.0]])
    variances = np.diag([moments.turn_var, moments.run_var, moments.drift_var])
    ekf.Q = noise @ variances @ noise.T + np.diag([moments.skitter_var, moments.skitter_var, 0.0])
    ekf.motion = (moments.turn_mean, moments.run_mean)
    ekf.predict()


def measure(x: Array, landmark: tuple[float, float]) -> Array:
    """Range (m) and bearing (rad) of ``landmark`` from pose ``x``."""
    dx, dy = landmark[0] - x[0], landmark[1] - x[1]
    return np.array([math.hypot(dx, dy), math.atan2(dy, dx) - x[2]])


def jacobian(x: Array, landmark: tuple[float, float]) -> Array:
    """d(range, bearing) / d(x, y, heading)."""
    dx, dy = landmark[0] - x[0], landmark[1] - x[1]
    q = dx * dx + dy * dy
    r = math.sqrt(q)
    return np.array([[-dx / r, -dy / r, 0.0], [dy / q, -dx / q, -1.0]])


def residual(a: Array, b: Array) -> Array:
    """Measurement difference with the bearing wrapped."""
    y = a - b
    y[-1] = math.remainder(float(y[-1]), 2 * math.pi)
    return y


class FilterpyLogEkf:
    """filterpy's EKF over a log: ``predict`` per position report, gated ``update`` per observation.

    Parameters mirror :class:`aura_ums.baselines.ExtendedKalmanFilter` (sensor offset zero).
    """

    def __init__(
        self,
        initial: Pose,
        *,
        position_sd: float,
        heading_sd: float,
        bearing_sd: float,
        range_sd: float,
        range_sd_fraction: float,
        gate_probability: float = 0.999,
    ) -> None:
        self.ekf = FilterpyPose()
        self.ekf.x = np.array([initial.x, initial.y, initial.heading])
        self.ekf.P = np.diag([position_sd**2, position_sd**2, heading_sd**2])
        self.bearing_var = bearing_sd**2
        self.range_var = range_sd**2
        self.range_fraction_sq = range_sd_fraction**2
        self.gates = (chi2_quantile(gate_probability, 1), chi2_quantile(gate_probability, 2))
        self.rejected_count = 0

    @property
    def mean(self) -> Pose:
        x, y, heading = self.ekf.x
        return Pose(float(x), float(y), math.remainder(float(heading), 2 * math.pi))

    def predict(self, command: TurnAndRun, terrain: TerrainStats) -> None:
        filterpy_predict(self.ekf, command, terrain)

    def region(self, probability: float = 0.99) -> ConfidenceRegion:
        return ConfidenceRegion.gaussian(self.ekf.x, self.ekf.P, probability)

    def update(
        self, observation: BearingObservation | RangeBearingObservation, landmark: tuple[float, float]
    ) -> bool:
        x = self.ekf.x
        if isinstance(observation, RangeBearingObservation):
            measured = 0.5 * (observation.range_min + observation.range_max)
            z = np.array([measured, observation.bearing])
            r = np.diag([self.range_var + self.range_fraction_sq * measured**2, self.bearing_var])
            h = jacobian(x, landmark)
            predicted = measure(x, landmark)
            gate = self.gates[1]
        else:
            z = np.array([observation.bearing])
            r = np.array([[self.bearing_var]])
            h = jacobian(x, landmark)[1:]
            predicted = measure(x, landmark)[1:]
            gate = self.gates[0]
        innovation = residual(z, predicted)
        s = h @ self.ekf.P @ h.T + r
        if float(innovation @ np.linalg.solve(s, innovation)) > gate:
            self.rejected_count += 1
            return False
        if isinstance(observation, RangeBearingObservation):
            self.ekf.update(
                z, lambda x: jacobian(x, landmark), lambda x: measure(x, landmark), R=r, residual=residual
            )
        else:
            self.ekf.update(
                z,
                lambda x: jacobian(x, landmark)[1:],
                lambda x: measure(x, landmark)[1:],
                R=r,
                residual=residual,
            )
        return True
