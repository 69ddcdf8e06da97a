"""The extended Kalman filter baseline: model moments, updates against filterpy, drives, gate, edges."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest
from filterpy.kalman import ExtendedKalmanFilter as FilterpyEkf
from numpy.typing import NDArray

from aura_ums.baselines import Estimator, ExtendedKalmanFilter, motion_moments
from aura_ums.baselines._moments import clipped_normal_moments
from aura_ums.errors import InputError
from aura_ums.uncertainty import (
    BearingObservation,
    GroundLineObservation,
    Pose,
    RangeBearingObservation,
    TerrainStats,
    TerrainTable,
    TurnAndRun,
)
from tests.baselines.baselines_helpers import (
    START_HEADING_SD,
    START_POSITION_SD,
    run_drive,
    simulate_drive,
)

Array = NDArray[np.float64]

SDS = {"position_sd": 0.3, "heading_sd": 0.03, "bearing_sd": 0.02, "range_sd": 0.2}


ORIGIN = Pose(0.0, 0.0, 0.0)


def make(pose: Pose = ORIGIN, **overrides: object) -> ExtendedKalmanFilter:
    kwargs: dict[str, object] = dict(SDS)
    kwargs.update(overrides)
    return ExtendedKalmanFilter(pose, **kwargs)  # type: ignore[arg-type]


def test_is_an_estimator() -> None:
    assert isinstance(make(), Estimator)


def test_clipped_normal_moments_match_sampling() -> None:
    rng = np.random.default_rng(3)
    z = rng.standard_normal(1_000_000)
    for mu, sigma, lo, hi in [(0.98, 0.02, 0.0, 1.0), (9.0, 0.4, 0.0, 10.0), (0.02, 0.03, 0.0, math.inf)]:
        values = np.clip(mu + sigma * z, lo, hi)
        mean, var = clipped_normal_moments(mu, sigma, lo, hi)
        assert mean == pytest.approx(values.mean(), abs=5 * sigma / 1000)
        assert var == pytest.approx(values.var(), rel=0.01)


@pytest.mark.parametrize(
    ("terrain_name", "command"),
    [("grass", TurnAndRun(0.6, 6.0)), ("gravel", TurnAndRun(-2.5, 2.0)), ("tile", TurnAndRun(0.0, 12.0))],
)
def test_prediction_matches_the_generative_model(
    terrains: TerrainTable, terrain_name: str, command: TurnAndRun
) -> None:
    """Mean and covariance after one predict agree with Monte Carlo of TerrainStats.sample_motions."""
    terrain = terrains[terrain_name]
    start = Pose(2.0, -1.0, 2.9)  # the turn may cross +-pi
    ekf = make(start)
    ekf.predict(command, terrain)
    rng = np.random.default_rng(11)
    initial = rng.multivariate_normal(start.as_array(), np.diag([0.09, 0.09, 0.0009]), 200_000)
    moved = terrain.sample_motions(initial, command, rng)
    heading = math.atan2(np.sin(moved[:, 2]).mean(), np.cos(moved[:, 2]).mean())
    deviation = moved - [moved[:, 0].mean(), moved[:, 1].mean(), heading]
    deviation[:, 2] = np.remainder(deviation[:, 2] + math.pi, 2 * math.pi) - math.pi
    sample_cov = deviation.T @ deviation / len(moved)
    mean = ekf.mean
    scale = np.sqrt(np.diag(sample_cov))
    # First order in the heading spread: allow a few percent of a standard deviation.
    assert abs(mean.x - moved[:, 0].mean()) < 0.05 * scale[0] + 0.01
    assert abs(mean.y - moved[:, 1].mean()) < 0.05 * scale[1] + 0.01
    assert abs(math.remainder(mean.heading - heading, 2 * math.pi)) < 0.05 * scale[2]
    correlation = ekf.covariance / np.outer(scale, scale)
    assert np.abs(correlation - sample_cov / np.outer(scale, scale)).max() < 0.05


def test_zero_command_changes_nothing(terrains: TerrainTable) -> None:
    ekf = make(Pose(1.0, 2.0, -math.pi + 0.01))
    before = ekf.covariance.copy()
    ekf.predict(TurnAndRun(0.0, 0.0), terrains["grass"])
    assert ekf.mean == Pose(1.0, 2.0, -math.pi + 0.01)
    assert np.array_equal(ekf.covariance, before)
    assert motion_moments(terrains["grass"], TurnAndRun(0.0, 0.0)) == (0.0,) * 6


def test_perfect_terrain_moves_exactly_and_keeps_a_point_region() -> None:
    ekf = make(Pose(0.0, 0.0, math.pi - 0.1), position_sd=0.0, heading_sd=0.0)
    ekf.predict(TurnAndRun(0.2, 5.0), TerrainStats.zero())
    mean = ekf.mean
    assert mean.heading == pytest.approx(-math.pi + 0.1)  # wrapped across the seam
    assert (mean.x, mean.y) == pytest.approx((5 * math.cos(math.pi + 0.1), 5 * math.sin(math.pi + 0.1)))
    region = ekf.region()
    assert region.area == 0.0
    assert region.polygon.vertex_count == 1
    assert region.contains(mean.x, mean.y, math.pi + 0.1) is True


# --- updates against filterpy's generic EKF with the same analytic model ------------------


def _sensor(x: Array, offset: tuple[float, float]) -> tuple[float, float, float, float]:
    c, s = math.cos(x[2]), math.sin(x[2])
    ox, oy = offset[0] * c - offset[1] * s, offset[0] * s + offset[1] * c
    return x[0] + ox, x[1] + oy, ox, oy


def _models(
    landmark: tuple[float, float], offset: tuple[float, float]
) -> tuple[Callable[[Array], Array], Callable[[Array], Array]]:
    def measure(x: Array) -> Array:
        sx, sy, _, _ = _sensor(x, offset)
        dx, dy = landmark[0] - sx, landmark[1] - sy
        return np.array([math.hypot(dx, dy), math.atan2(dy, dx) - x[2]])

    def jacobian(x: Array) -> Array:
        sx, sy, ox, oy = _sensor(x, offset)
        dx, dy = landmark[0] - sx, landmark[1] - sy
        q = dx * dx + dy * dy
        r = math.sqrt(q)
        return np.array(
            [[-dx / r, -dy / r, (dx * oy - dy * ox) / r], [dy / q, -dx / q, -(dx * ox + dy * oy) / q - 1.0]]
        )

    return measure, jacobian


def _wrapped(a: Array, b: Array) -> Array:
    y = np.asarray(a - b, dtype=np.float64)
    y[-1] = math.remainder(float(y[-1]), 2 * math.pi)
    return y


@pytest.mark.parametrize("offset", [(0.0, 0.0), (0.4, -0.15)])
def test_updates_match_filterpy(terrains: TerrainTable, offset: tuple[float, float]) -> None:
    ekf = make(Pose(1.0, 2.0, math.pi - 0.02), range_sd_fraction=0.02, gate_probability=None)
    ekf.predict(TurnAndRun(0.3, 4.0), terrains["grass"])  # correlated prior
    reference = FilterpyEkf(dim_x=3, dim_z=2)
    reference.x = ekf.mean.as_array()
    reference.P = ekf.covariance.copy()
    landmark = (-12.0, -3.0)
    measure, jacobian = _models(landmark, offset)
    range_var = 0.2**2 + (0.02 * 10.5) ** 2
    reference.update(
        np.array([10.5, -0.4]), jacobian, measure, R=np.diag([range_var, 0.02**2]), residual=_wrapped
    )
    assert ekf.update(RangeBearingObservation("c", 0.0, -0.4, 0.06, 10.0, 11.0, offset), landmark)
    np.testing.assert_allclose(ekf.mean.as_array(), reference.x, rtol=0, atol=1e-12)
    np.testing.assert_allclose(ekf.covariance, reference.P, rtol=1e-9, atol=1e-15)
    reference.update(
        np.array([-0.3]),
        lambda x: jacobian(x)[1:],
        lambda x: measure(x)[1:],
        R=np.array([[0.02**2]]),
        residual=_wrapped,
    )
    assert ekf.update(BearingObservation("c", 0.0, -0.3, 0.06, offset), landmark)
    np.testing.assert_allclose(ekf.mean.as_array(), reference.x, rtol=0, atol=1e-12)
    np.testing.assert_allclose(ekf.covariance, reference.P, rtol=1e-9, atol=1e-15)
    assert np.all(np.linalg.eigvalsh(ekf.covariance) > 0.0)


def test_bearing_innovation_is_wrapped_at_pi() -> None:
    ekf = make(Pose(0.0, 0.0, math.pi - 0.01))
    # The landmark's direction is just below -pi's side of the seam, the heading just above
    # pi's: atan2 - heading is about -2*pi + 0.01, which only a wrapped innovation reads as 0.01.
    assert ekf.update(BearingObservation("p", 0.0, -0.01, 0.03), (-10.0, -1e-4))
    assert ekf.rejected_count == 0
    assert 0.0 < math.remainder(ekf.mean.heading - (math.pi - 0.01), 2 * math.pi) < 0.03


# --- drives ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("terrain_name", "ranged", "offset"),
    [("grass", True, (0.0, 0.0)), ("concrete", True, (0.4, -0.1)), ("grass", False, (0.0, 0.0))],
)
def test_drive_regions_contain_the_truth(
    terrains: TerrainTable, terrain_name: str, ranged: bool, offset: tuple[float, float]
) -> None:
    terrain = terrains[terrain_name]
    covered = steps = 0
    position_errors: list[float] = []
    heading_errors: list[float] = []
    for seed in range(8):
        _, drive = simulate_drive(np.random.default_rng(seed), terrain, ranged=ranged, sensor_offset=offset)
        ekf = make(position_sd=START_POSITION_SD, heading_sd=START_HEADING_SD, bearing_sd=0.01, range_sd=0.15)
        tally = run_drive(ekf, drive, terrain)
        covered += tally.covered
        steps += tally.steps
        position_errors.extend(tally.position_errors)
        heading_errors.extend(tally.heading_errors)
        assert ekf.rejected_count <= 2
    assert covered / steps >= 0.95
    assert float(np.mean(position_errors)) < 0.12
    assert float(np.mean(heading_errors)) < 0.01


def test_without_observations_the_region_grows_and_still_covers(terrains: TerrainTable) -> None:
    terrain = terrains["gravel"]
    rng = np.random.default_rng(5)
    covered = 0
    areas = []
    trials = 200
    for _ in range(trials):
        ekf = make(position_sd=0.0, heading_sd=0.0)
        truth = Pose(0.0, 0.0, 0.0)
        for command in (TurnAndRun(0.5, 4.0), TurnAndRun(-1.0, 3.0), TurnAndRun(0.2, 5.0)):
            ekf.predict(command, terrain)
            truth = terrain.sample_motion(truth, command, rng)
        region = ekf.region(0.9)
        covered += region.contains(truth.x, truth.y, truth.heading)
        areas.append(region.area)
    assert covered / trials >= 0.85  # nominal 0.9, binomial sd 0.02
    assert min(areas) > 0.0


# --- the gate -------------------------------------------------------------------------------


def test_gate_rejects_a_gross_outlier_and_counts_it() -> None:
    ekf = make()
    before = (ekf.mean, ekf.covariance.copy())
    landmark = (10.0, 0.0)
    outlier = RangeBearingObservation("c", 0.0, 0.8, 0.06, 4.0, 4.2)
    assert ekf.update(outlier, landmark) is False
    assert ekf.update(BearingObservation("c", 0.0, -1.0, 0.06), landmark) is False
    assert ekf.rejected_count == 2
    assert ekf.mean == before[0]
    assert np.array_equal(ekf.covariance, before[1])
    assert ekf.update(RangeBearingObservation("c", 0.0, 0.01, 0.06, 9.8, 10.2), landmark) is True
    assert ekf.rejected_count == 2


def test_no_gate_accepts_the_outlier_and_is_dragged_off() -> None:
    ekf = make(gate_probability=None)
    assert ekf.update(RangeBearingObservation("c", 0.0, 0.8, 0.06, 4.0, 4.2), (10.0, 0.0)) is True
    assert ekf.rejected_count == 0
    assert math.hypot(ekf.mean.x, ekf.mean.y) > 0.5


def test_landmark_at_the_sensor_is_rejected() -> None:
    ekf = make(Pose(1.0, 1.0, 0.5))
    sensor = (1.0 + 0.3 * math.cos(0.5), 1.0 + 0.3 * math.sin(0.5))
    assert ekf.update(BearingObservation("c", 0.0, 0.0, 0.06, (0.3, 0.0)), sensor) is False
    assert ekf.rejected_count == 1


# --- bad arguments --------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("overrides", "match"),
    [
        ({"position_sd": -0.1}, r"position_sd: expected a number in \[0, 10000\] m, got -0.1"),
        ({"position_sd": 1e300}, r"position_sd: expected a number in \[0, 10000\] m, got 1e\+300"),
        ({"heading_sd": math.nan}, "heading_sd: expected a finite number"),
        ({"heading_sd": 1e300}, r"heading_sd: expected a number in \[0, 1000\] rad, got 1e\+300"),
        ({"bearing_sd": 0.0}, r"bearing_sd: expected a number in \[1e-06, 1000\] rad, got 0.0"),
        ({"bearing_sd": 1e300}, r"bearing_sd: expected a number in \[1e-06, 1000\] rad, got 1e\+300"),
        ({"range_sd": -1.0}, r"range_sd: expected a number in \[1e-06, 10000\] m, got -1.0"),
        ({"range_sd": 1e300}, r"range_sd: expected a number in \[1e-06, 10000\] m, got 1e\+300"),
        ({"range_sd_fraction": -0.1}, r"range_sd_fraction: expected a number in \[0, 10\], got -0.1"),
        ({"range_sd_fraction": 1e300}, r"range_sd_fraction: expected a number in \[0, 10\], got 1e\+300"),
        ({"gate_probability": 1.0}, r"gate_probability: expected a probability in \(0, 1\)"),
        ({"process_noise_scale": 0.0}, r"process_noise_scale: expected a number in \(0, 100\], got 0.0"),
        # 1e300 gave a covariance of 1e296 m^2 after three predictions, and inf after a fourth
        (
            {"process_noise_scale": 1e300},
            r"process_noise_scale: expected a number in \(0, 100\], got 1e\+300",
        ),
    ],
)
def test_bad_constructor_arguments(overrides: dict[str, object], match: str) -> None:
    with pytest.raises(InputError, match=match):
        make(ORIGIN, **overrides)


def test_bad_call_arguments(terrains: TerrainTable) -> None:
    with pytest.raises(InputError, match="initial: expected a Pose"):
        ExtendedKalmanFilter((0, 0, 0), **SDS)  # type: ignore[arg-type]
    ekf = make()
    with pytest.raises(InputError, match="command: expected a TurnAndRun"):
        ekf.predict((0.0, 1.0), terrains["grass"])  # type: ignore[arg-type]
    with pytest.raises(InputError, match="terrain: expected TerrainStats"):
        ekf.predict(TurnAndRun(0.0, 1.0), "grass")  # type: ignore[arg-type]
    line = GroundLineObservation("l", 0.0, 1.0, 0.1, 0.0, 0.01)
    with pytest.raises(InputError, match="observation: expected a BearingObservation or RangeBearing"):
        ekf.update(line, (1.0, 1.0))  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"landmark_xy: expected \(x, y\)"):
        ekf.update(BearingObservation("c", 0.0, 0.0, 0.1), (1.0, 2.0, 3.0))  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"landmark_xy\[1\]: expected a finite number"):
        ekf.update(BearingObservation("c", 0.0, 0.0, 0.1), (1.0, math.inf))
    with pytest.raises(InputError, match=r"probability: expected a probability in \(0, 1\)"):
        ekf.region(1.5)
