"""The particle filter baseline: drives, robustness to outliers, resampling, regions and edges."""

from __future__ import annotations

import math

import numpy as np
import pytest

from aura_ums.baselines import Estimator, ExtendedKalmanFilter, ParticleFilter
from aura_ums.baselines._particle import systematic_resample
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
from tests.baselines.baselines_helpers import START_HEADING_SD, START_POSITION_SD, run_drive, simulate_drive

SDS = {"position_sd": 0.3, "heading_sd": 0.03, "bearing_sd": 0.02, "range_sd": 0.2}


ORIGIN = Pose(0.0, 0.0, 0.0)


def make(pose: Pose = ORIGIN, seed: int = 0, **overrides: object) -> ParticleFilter:
    kwargs: dict[str, object] = dict(SDS)
    kwargs.update(overrides)
    return ParticleFilter(pose, np.random.default_rng(seed), **kwargs)  # type: ignore[arg-type]


def test_is_an_estimator_with_a_normalised_cloud() -> None:
    pf = make(Pose(1.0, 2.0, math.pi), particles=500)
    assert isinstance(pf, Estimator)
    assert pf.particles.shape == (500, 3)
    assert pf.weights.sum() == pytest.approx(1.0)
    assert pf.effective_sample_size == pytest.approx(500)
    assert np.all(np.abs(pf.particles[:, 2]) <= math.pi)
    mean = pf.mean  # circular mean across the seam, not ~0
    assert abs(math.remainder(mean.heading - math.pi, 2 * math.pi)) < 0.01
    with pytest.raises(ValueError, match="read-only"):
        pf.particles[0, 0] = 5.0


def test_same_seed_same_run(terrains: TerrainTable) -> None:
    runs = []
    for _ in range(2):
        pf = make(seed=42)
        pf.predict(TurnAndRun(0.3, 5.0), terrains["grass"])
        pf.update(RangeBearingObservation("c", 0.0, 0.1, 0.06, 4.0, 4.4), (9.0, 1.0))
        pf.predict(TurnAndRun(0.0, 2.0), terrains["grass"])
        runs.append(pf.mean.as_array())
    np.testing.assert_array_equal(runs[0], runs[1])


@pytest.mark.parametrize(
    ("terrain_name", "ranged", "offset", "coverage"),
    [
        ("grass", True, (0.0, 0.0), 0.95),
        ("tile", True, (0.4, -0.1), 0.95),
        ("tile", False, (0.0, 0.0), 0.90),
    ],
)
def test_drive_regions_contain_the_truth(
    terrains: TerrainTable, terrain_name: str, ranged: bool, offset: tuple[float, float], coverage: float
) -> None:
    # Sensor noise of 0.02 rad / 0.3 m. With sharper sensors, or bearings only, 1,000
    # particles under-cover: after a step's updates only a few dozen particles carry the
    # weight, and the hull of a few points is smaller than the region they sample.
    terrain = terrains[terrain_name]
    covered = steps = 0
    position_errors: list[float] = []
    ekf_errors: list[float] = []
    for seed in range(8):
        _, drive = simulate_drive(
            np.random.default_rng(seed),
            terrain,
            ranged=ranged,
            bearing_sd=0.02,
            range_sd=0.3,
            sensor_offset=offset,
        )
        sds: dict[str, float] = {
            "position_sd": START_POSITION_SD,
            "heading_sd": START_HEADING_SD,
            "bearing_sd": 0.02,
            "range_sd": 0.3,
        }
        pf = ParticleFilter(ORIGIN, np.random.default_rng(100 + seed), **sds)  # type: ignore[arg-type]
        tally = run_drive(pf, drive, terrain)
        covered += tally.covered
        steps += tally.steps
        position_errors.extend(tally.position_errors)
        ekf = ExtendedKalmanFilter(ORIGIN, **sds)
        ekf_errors.extend(run_drive(ekf, drive, terrain).position_errors)
        assert pf.resample_count > 0
        assert pf.rejected_count == 0
    assert covered / steps >= coverage
    assert float(np.mean(position_errors)) < 0.15
    assert float(np.mean(position_errors)) < 1.2 * float(np.mean(ekf_errors))


def test_survives_a_gross_outlier(terrains: TerrainTable) -> None:
    terrain = terrains["concrete"]
    rng = np.random.default_rng(9)
    _, drive = simulate_drive(rng, terrain, steps=8, bearing_sd=0.02, range_sd=0.3)
    pf = make(seed=1, position_sd=START_POSITION_SD, heading_sd=START_HEADING_SD, range_sd=0.3)
    ekf = ExtendedKalmanFilter(
        Pose(0.0, 0.0, 0.0),
        position_sd=START_POSITION_SD,
        heading_sd=START_HEADING_SD,
        bearing_sd=0.02,
        range_sd=0.3,
        gate_probability=None,
    )
    for k, step in enumerate(drive):
        for estimator in (pf, ekf):
            estimator.predict(step.command, terrain)
            for observation, landmark in step.observations:
                estimator.update(observation, landmark)
        if k == 4:  # a misidentified landmark: wrong bearing and range
            outlier = RangeBearingObservation("c", float(k), 2.0, 0.06, 3.0, 4.0)
            for estimator in (pf, ekf):
                assert estimator.update(outlier, (5.0, 5.0)) is True
            truth = step.truth
            pf_error = math.hypot(pf.mean.x - truth.x, pf.mean.y - truth.y)
            ekf_error = math.hypot(ekf.mean.x - truth.x, ekf.mean.y - truth.y)
            assert pf_error < 0.2
            assert ekf_error > max(0.5, 3 * pf_error)  # an ungated EKF is dragged off
            assert pf.region().contains(truth.x, truth.y, truth.heading)
    truth = drive[-1].truth
    assert math.hypot(pf.mean.x - truth.x, pf.mean.y - truth.y) < 0.2
    assert pf.rejected_count == 0


def test_optional_gate_rejects_unexplained_observations() -> None:
    pf = make(gate_probability=0.999)
    before = pf.weights
    assert pf.update(BearingObservation("c", 0.0, 1.5, 0.06), (10.0, 0.0)) is False
    assert pf.update(RangeBearingObservation("c", 0.0, 0.0, 0.06, 3.0, 3.2), (10.0, 0.0)) is False
    assert pf.rejected_count == 2
    np.testing.assert_array_equal(pf.weights, before)
    assert pf.update(BearingObservation("c", 0.0, 0.0, 0.06), (10.0, 0.0)) is True


def test_no_floor_and_no_explanation_is_rejected() -> None:
    pf = make(outlier_floor=0.0, position_sd=0.0, heading_sd=0.0)
    assert pf.update(BearingObservation("c", 0.0, math.pi, 0.06), (10.0, 0.0)) is False
    assert pf.rejected_count == 1
    assert pf.weights.sum() == pytest.approx(1.0)


def test_resampling_happens_at_the_next_predict(terrains: TerrainTable) -> None:
    pf = make(particles=400)
    for _ in range(3):
        pf.update(BearingObservation("c", 0.0, 0.0, 0.06), (10.0, 0.0))
    assert pf.resample_count == 0
    assert pf.effective_sample_size < 200
    pf.predict(TurnAndRun(0.0, 0.0), TerrainStats.zero())
    assert pf.resample_count == 1
    assert pf.effective_sample_size == pytest.approx(400)
    assert len(np.unique(pf.particles, axis=0)) < 400  # copies of the heavy particles
    rough = make(particles=400, roughening=0.2)
    for _ in range(3):
        rough.update(BearingObservation("c", 0.0, 0.0, 0.06), (10.0, 0.0))
    rough.predict(TurnAndRun(0.0, 0.0), TerrainStats.zero())
    assert len(np.unique(rough.particles, axis=0)) == 400  # roughening separates the copies
    never = make(particles=400, resample_threshold=0.0)
    never.update(BearingObservation("c", 0.0, 0.0, 0.06), (10.0, 0.0))
    assert never.effective_sample_size < 0.9 * 400
    never.predict(TurnAndRun(0.0, 1.0), terrains["tile"])
    assert never.resample_count == 0


def test_systematic_resample_counts() -> None:
    rng = np.random.default_rng(2)
    weights = rng.uniform(size=50)
    weights /= weights.sum()
    counts = np.bincount(systematic_resample(weights, rng), minlength=50)
    assert np.all(np.abs(counts - 50 * weights) < 1.0 + 1e-9)


def test_degenerate_cloud_gives_a_point_region(terrains: TerrainTable) -> None:
    pf = make(Pose(3.0, -1.0, -math.pi + 0.02), position_sd=0.0, heading_sd=0.0, particles=50)
    pf.predict(TurnAndRun(0.0, 0.0), terrains["grass"])  # a zero command moves nothing
    region = pf.region()
    assert region.polygon.vertex_count == 1
    assert region.area == 0.0
    assert region.heading_halfwidth == 0.0
    assert region.contains(3.0, -1.0, math.pi + 0.02) is True
    assert region.contains(3.0, -1.0, math.pi) is False
    assert pf.mean.x == pytest.approx(3.0)


def test_turn_only_spreads_headings_across_the_seam(terrains: TerrainTable) -> None:
    # grass: the actual turn is 0.1 * clip(0.94 + 0.06 z, 0, 1), about 0.076 to 0.1 rad.
    pf = make(Pose(0.0, 0.0, math.pi - 0.09), position_sd=0.0, heading_sd=0.0, particles=2000)
    pf.predict(TurnAndRun(0.1, 0.0), terrains["grass"])
    headings = pf.particles[:, 2]
    assert headings.min() < -3.0 < 3.0 < headings.max()  # on both sides of +-pi
    region = pf.region(0.9)
    assert region.heading_halfwidth < 0.05  # the short arc across the seam, not the long way round
    inside = region.contains(pf.particles[:, 0], pf.particles[:, 1], headings)
    assert float(pf.weights[np.asarray(inside)].sum()) >= 2 * math.sqrt(0.9) - 1


def test_region_holds_its_weight(terrains: TerrainTable) -> None:
    pf = make(particles=1000)
    pf.predict(TurnAndRun(1.0, 8.0), terrains["gravel"])
    pf.update(BearingObservation("c", 0.0, 0.5, 0.06), (2.0, 9.0))
    for p in (0.5, 0.9, 0.99):
        region = pf.region(p)
        particles = pf.particles
        inside = region.contains(particles[:, 0], particles[:, 1], particles[:, 2])
        held = float(pf.weights[np.asarray(inside)].sum())
        assert held >= 2 * math.sqrt(p) - 1  # Bonferroni on the two factors of sqrt(p)
        assert region.probability == p
    assert pf.region(0.5).area < pf.region(0.99).area


@pytest.mark.parametrize(
    ("overrides", "match"),
    [
        ({"particles": 0}, "particles: expected an integer >= 1"),
        ({"particles": 10.5}, "particles: expected an integer >= 1"),
        ({"particles": 10**12}, r"particles: expected at most 1,000,000 particles \(about 350 bytes.*GB"),
        ({"position_sd": -1.0}, r"position_sd: expected a number in \[0, 10000\] m, got -1.0"),
        ({"position_sd": 1e300}, r"position_sd: expected a number in \[0, 10000\] m, got 1e\+300"),
        ({"heading_sd": 1e300}, r"heading_sd: expected a number in \[0, 1000\] rad, got 1e\+300"),
        ({"bearing_sd": 0.0}, r"bearing_sd: expected a number in \[1e-06, 1000\] rad, got 0.0"),
        ({"bearing_sd": 1e300}, r"bearing_sd: expected a number in \[1e-06, 1000\] rad, got 1e\+300"),
        ({"range_sd": 1e300}, r"range_sd: expected a number in \[1e-06, 10000\] m, got 1e\+300"),
        ({"range_sd_fraction": 11.0}, r"range_sd_fraction: expected a number in \[0, 10\], got 11.0"),
        ({"range_sd": math.inf}, "range_sd: expected a finite number"),
        ({"outlier_floor": -1e-3}, "outlier_floor: expected a non-negative number"),
        ({"gate_probability": 0.0}, r"gate_probability: expected a probability in \(0, 1\)"),
        ({"resample_threshold": 1.5}, r"resample_threshold: expected a fraction in \[0, 1\]"),
        ({"roughening": -0.1}, r"roughening: expected a number in \[0, 10\], got -0.1"),
        # 1e300 put the resampled particles at 1e298 m: the mean was refused as a Pose
        ({"roughening": 1e300}, r"roughening: expected a number in \[0, 10\], got 1e\+300"),
    ],
)
def test_bad_constructor_arguments(overrides: dict[str, object], match: str) -> None:
    with pytest.raises(InputError, match=match):
        make(ORIGIN, 0, **overrides)


def test_bad_call_arguments(terrains: TerrainTable) -> None:
    with pytest.raises(InputError, match=r"rng: expected a numpy\.random\.Generator"):
        ParticleFilter(Pose(0, 0, 0), 3, **SDS)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="initial: expected a Pose"):
        ParticleFilter(None, np.random.default_rng(0), **SDS)  # type: ignore[arg-type]
    pf = make(particles=10)
    with pytest.raises(InputError, match="command: expected a TurnAndRun"):
        pf.predict(None, terrains["grass"])  # type: ignore[arg-type]
    with pytest.raises(InputError, match="terrain: expected TerrainStats"):
        pf.predict(TurnAndRun(0.0, 1.0), None)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="observation: expected a BearingObservation or RangeBearing"):
        pf.update(GroundLineObservation("l", 0.0, 1.0, 0.1, 0.0, 0.01), (0.0, 0.0))  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"landmark_xy: expected \(x, y\)"):
        pf.update(BearingObservation("c", 0.0, 0.0, 0.1), 5.0)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"probability: expected a probability in \(0, 1\)"):
        pf.region(0.0)
