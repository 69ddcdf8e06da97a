"""compare_on_log: our map next to the EKF, the particle filter and estimators of the user's."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from aura_ums.baselines import ExtendedKalmanFilter
from aura_ums.errors import InputError
from aura_ums.logs import MethodSummary, RobotLog, compare_on_log, filter_settings, synthetic_log
from aura_ums.uncertainty import Pose, TerrainTable

FLOOR = TerrainTable({"floor": TerrainTable.default()["tile"]})
BEARING_SD, RANGE_SD_FRACTION = 0.006, 0.012


@pytest.fixture(scope="module")
def log() -> RobotLog:
    return synthetic_log(np.random.default_rng(11), duration=30.0)


def _as_built_in(start: Pose, log: RobotLog) -> ExtendedKalmanFilter:
    settings = filter_settings(log, bearing_sd=BEARING_SD, range_sd_fraction=RANGE_SD_FRACTION)
    return ExtendedKalmanFilter(start, gate_probability=0.999, **settings)


def compare(log: RobotLog, *, particles: int, others: object) -> tuple[MethodSummary, ...]:
    return compare_on_log(
        log,
        FLOOR,
        bearing_sd=BEARING_SD,
        range_sd_fraction=RANGE_SD_FRACTION,
        rng=np.random.default_rng(0),
        particles=particles,
        others=others,  # type: ignore[arg-type]
    )


def gating_everything_out(ekf: ExtendedKalmanFilter) -> ExtendedKalmanFilter:
    mean, sd = ekf.mean, np.sqrt(np.diag(ekf.covariance))
    return ExtendedKalmanFilter(
        mean,
        position_sd=float(sd[0]),
        heading_sd=float(sd[2]),
        bearing_sd=BEARING_SD,
        range_sd=0.01,
        range_sd_fraction=RANGE_SD_FRACTION,
        gate_probability=1e-9,
    )


def test_an_estimator_of_ones_own_is_stepped_and_judged_as_the_ekf(log: RobotLog) -> None:
    starts: list[Pose] = []

    def twin(start: Pose) -> ExtendedKalmanFilter:
        starts.append(start)
        return _as_built_in(start, log)

    def blind(start: Pose) -> ExtendedKalmanFilter:  # the same EKF gating every update out
        return gating_everything_out(_as_built_in(start, log))

    rows = compare(log, particles=100, others={"twin EKF": twin, "blind EKF": blind})
    assert [row.method for row in rows] == ["aura-ums", "EKF", "PF (100)", "twin EKF", "blind EKF"]
    assert len(starts) == 1
    truth = log.groundtruth
    assert truth is not None
    # The start pose is the ground truth's at the replay's start (within the log's first second).
    x, y, _ = truth.at([float(truth.time[0])])[0]
    assert math.hypot(starts[0].x - x, starts[0].y - y) < 1.0
    ekf, twin_row, blind_row = rows[1], rows[3], rows[4]
    # Same filter, same steps: the same figures, bit for bit (only the timing differs).
    assert (twin_row.containment_rate, twin_row.median_area_m2, twin_row.median_wedge_width_rad) == (
        ekf.containment_rate,
        ekf.median_area_m2,
        ekf.median_wedge_width_rad,
    )
    assert (twin_row.position_rmse_m, twin_row.inconsistent_observations) == (
        ekf.position_rmse_m,
        ekf.inconsistent_observations,
    )
    assert twin_row.median_update_us > 0.0
    assert blind_row.inconsistent_observations > 0
    assert blind_row.median_area_m2 > ekf.median_area_m2  # never corrected: it only grows
    assert blind_row.median_wedge_width_rad > ekf.median_wedge_width_rad


class _NotAnEstimator:
    def predict(self) -> None:
        """Has a predict, and nothing else an estimator needs."""


@pytest.mark.parametrize(
    ("others", "match"),
    [
        (
            [("mine", ExtendedKalmanFilter)],
            "others: expected a mapping of names to estimator factories, got list",
        ),
        ({"EKF": ExtendedKalmanFilter}, r"others: expected names that are new non-empty strings .*got 'EKF'"),
        ({"": ExtendedKalmanFilter}, "others: expected names that are new non-empty strings"),
        ({"mine": 3}, r"others\['mine'\]: expected a callable taking the start Pose, got 3"),
        (
            {"mine": lambda start: _NotAnEstimator()},
            r"others\['mine'\]: expected a factory returning an Estimator .*got _NotAnEstimator",
        ),
    ],
)
def test_bad_others_are_named(log: RobotLog, others: object, match: str) -> None:
    with pytest.raises(InputError, match=match):
        compare(log, particles=10, others=others)


def test_a_particle_filter_too_costly_is_refused_with_the_estimate_before_any_work() -> None:
    # a million particles ran past a minute on the sample log; on a real log, hours
    long_log = synthetic_log(np.random.default_rng(5), duration=600.0)
    with pytest.raises(
        InputError,
        match=r"^particles: expected a particle filter of at most 600 s \(at most \d+ particles over this "
        r"log's \d+ reports and \d+ updates\), got 1000000: about [\d.e+]+ s$",
    ):
        compare_on_log(
            long_log, FLOOR, bearing_sd=0.01, range_sd_fraction=0.01, rng=np.random.default_rng(0),
            particles=1_000_000,
        )  # fmt: skip
    with pytest.raises(InputError, match=r"^particles: expected an integer >= 1, got 0$"):
        compare_on_log(
            long_log,
            FLOOR,
            bearing_sd=0.01,
            range_sd_fraction=0.01,
            rng=np.random.default_rng(0),
            particles=0,
        )


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"bearing_sd": 1e300}, r"bearing_sd: expected a number in \[1e-06, 1000\] rad, got 1e\+300"),
        ({"range_sd_fraction": 1e300}, r"range_sd_fraction: expected a number in \(0, 100\], got 1e\+300"),
    ],
)
def test_noise_past_its_range_is_refused(log: RobotLog, kwargs: dict[str, Any], match: str) -> None:
    # an OverflowError from the EKF's variances before
    arguments = {"bearing_sd": 0.006, "range_sd_fraction": 0.012, **kwargs}
    with pytest.raises(InputError, match=match):
        compare_on_log(
            log,
            TerrainTable({"floor": TerrainTable.default()["tile"]}),
            rng=np.random.default_rng(0),
            particles=10,
            **arguments,
        )
