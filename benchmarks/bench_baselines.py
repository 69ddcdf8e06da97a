"""Benchmark: the map's growth and reductions against the baseline estimators, same inputs, same run.

Run ``.venv/bin/python benchmarks/bench_baselines.py``. Prints the median time (µs) of one
predict and one update (bearing; range and bearing) of

- ``SpatialUncertaintyMap``: ``grow`` and ``reduce`` Class I / Class II on a 16-vertex map;
- aura-ums's ``ExtendedKalmanFilter`` (the reference of the ratios);
- filterpy's ``ExtendedKalmanFilter`` with the same model (same moments, same analytic
  Jacobians, same Joseph update; F, Q and H built with numpy per call, as a user writes them);
- aura-ums's ``ParticleFilter`` with 1,000 particles;

and the time of ``region(0.99)`` of the two aura-ums filters. Every call starts from the
same prior (stateful filters are restored before each call, outside the timed region),
is timed alone, and the timer's own overhead is subtracted. Nothing is asserted: speed
is reported. Before timing, the script checks that filterpy's filter and ours agree.
"""

from __future__ import annotations

import copy
import math
import statistics
import time
from collections.abc import Callable
from typing import TypedDict

import numpy as np
from numpy.typing import NDArray

from aura_ums.baselines import ExtendedKalmanFilter, ParticleFilter
from aura_ums.geometry import HeadingWedge, regular_polygon
from aura_ums.uncertainty import (
    BearingObservation,
    PointLandmark,
    Pose,
    RangeBearingObservation,
    SpatialUncertaintyMap,
    TerrainTable,
    TurnAndRun,
    VerticalLineLandmark,
)
from filterpy_ekf import FilterpyPose, filterpy_predict, jacobian, measure, residual

Array = NDArray[np.float64]

REPEATS = 3000
LANDMARK = (20.0, 5.0)
TRUTH = (0.2, 0.3, 0.05)
BEARING_ERROR = math.radians(1.0)  # the observation's bound: 3 standard deviations
RANGE_ERROR = 1.0
COMMAND = TurnAndRun(0.3, 5.0)
TERRAIN = TerrainTable.default()["concrete"]
SIDES = 16


def timer_overhead_ns() -> float:
    samples = []
    for _ in range(REPEATS):
        start = time.perf_counter_ns()
        samples.append(time.perf_counter_ns() - start)
    return statistics.median(samples)


def median_us(call: Callable[[], object], reset: Callable[[], None] | None = None) -> float:
    """Median of single timed calls, microseconds, each after ``reset`` (untimed), net of the timer."""
    for _ in range(50):
        if reset is not None:
            reset()
        call()
    samples = []
    for _ in range(REPEATS):
        if reset is not None:
            reset()
        start = time.perf_counter_ns()
        call()
        samples.append(time.perf_counter_ns() - start)
    return max(statistics.median(samples) - OVERHEAD_NS, 0.0) / 1000.0


def observations() -> tuple[BearingObservation, RangeBearingObservation]:
    x, y, heading = TRUTH
    bearing = math.atan2(LANDMARK[1] - y, LANDMARK[0] - x) - heading
    distance = math.hypot(LANDMARK[0] - x, LANDMARK[1] - y)
    return (
        BearingObservation("lm", 0.0, bearing, BEARING_ERROR),
        RangeBearingObservation(
            "lm", 0.0, bearing, BEARING_ERROR, distance - RANGE_ERROR, distance + RANGE_ERROR
        ),
    )


class Sds(TypedDict):
    position_sd: float
    heading_sd: float
    bearing_sd: float
    range_sd: float


SDS: Sds = {
    "position_sd": 2.0 / 3.0,  # the map's 2 m polygon as 3 standard deviations
    "heading_sd": 0.05 / 3.0,
    "bearing_sd": BEARING_ERROR / 3.0,
    "range_sd": RANGE_ERROR / 3.0,
}


# --- filterpy with the same model (benchmarks/filterpy_ekf.py) ---------------------------------


def _measure(x: Array) -> Array:
    return measure(x, LANDMARK)


def _jacobian(x: Array) -> Array:
    return jacobian(x, LANDMARK)


def filterpy_bearing(ekf: FilterpyPose, observation: BearingObservation) -> None:
    ekf.update(
        np.array([observation.bearing]),
        lambda x: _jacobian(x)[1:],
        lambda x: _measure(x)[1:],
        R=np.array([[SDS["bearing_sd"] ** 2]]),
        residual=residual,
    )


def filterpy_range_bearing(ekf: FilterpyPose, observation: RangeBearingObservation) -> None:
    z = np.array([0.5 * (observation.range_min + observation.range_max), observation.bearing])
    r = np.diag([SDS["range_sd"] ** 2, SDS["bearing_sd"] ** 2])
    ekf.update(z, _jacobian, _measure, R=r, residual=residual)


# --- the run ----------------------------------------------------------------------------------


def check_agreement(bearing: BearingObservation, ranged: RangeBearingObservation) -> float:
    ours = ExtendedKalmanFilter(Pose(0.0, 0.0, 0.0), gate_probability=None, **SDS)
    theirs = FilterpyPose()
    theirs.x = np.zeros(3)
    theirs.P = np.diag([SDS["position_sd"] ** 2, SDS["position_sd"] ** 2, SDS["heading_sd"] ** 2])
    worst = 0.0
    for step in range(3):
        ours.predict(COMMAND, TERRAIN)
        filterpy_predict(theirs, COMMAND, TERRAIN)
        if step == 1:
            ours.update(bearing, LANDMARK)
            filterpy_bearing(theirs, bearing)
        else:
            ours.update(ranged, LANDMARK)
            filterpy_range_bearing(theirs, ranged)
        worst = max(
            worst,
            float(np.abs(ours.mean.as_array() - theirs.x).max()),
            float(np.abs(ours.covariance - theirs.P).max()),
        )
    return worst


def main() -> None:
    bearing, ranged = observations()
    difference = check_agreement(bearing, ranged)
    print(f"agreement with filterpy after 3 predict+update steps: max |difference| {difference:.1e}")

    # The map: a 16-vertex polygon of radius 2 m, wedge +-0.05 rad (as bench_reduce).
    polygon = regular_polygon((0.0, 0.0), 2.0, SIDES, phase=0.1)
    prior_map = SpatialUncertaintyMap.from_polygon(polygon, (0.0, 0.0), HeadingWedge(0.0, 0.05, 0.05))
    pole = VerticalLineLandmark("lm", *LANDMARK, 0.0, 6.0, "lamppost", 0.05)
    corner = PointLandmark("lm", *LANDMARK, 3.0, "building corner", 0.05)
    map_times = (
        median_us(lambda: prior_map.grow(COMMAND, TERRAIN)),
        median_us(lambda: prior_map.reduce(bearing, pole)),
        median_us(lambda: prior_map.reduce(ranged, corner)),
        math.nan,
    )

    # Ours: every call from the same prior (a copy restored before each timed call).
    ekf_prior = ExtendedKalmanFilter(Pose(0.0, 0.0, 0.0), **SDS)
    ekf = [ekf_prior]

    def reset_ekf() -> None:
        ekf[0] = copy.copy(ekf_prior)

    ekf_times = (
        median_us(lambda: ekf[0].predict(COMMAND, TERRAIN), reset_ekf),
        median_us(lambda: ekf[0].update(bearing, LANDMARK), reset_ekf),
        median_us(lambda: ekf[0].update(ranged, LANDMARK), reset_ekf),
        median_us(lambda: ekf_prior.region(0.99)),
    )
    assert copy.copy(ekf_prior).update(ranged, LANDMARK)  # the timed updates are accepted, not gated

    fp = FilterpyPose()

    def reset_filterpy() -> None:
        fp.x = np.zeros(3)
        fp.P = np.diag([SDS["position_sd"] ** 2, SDS["position_sd"] ** 2, SDS["heading_sd"] ** 2])

    filterpy_times = (
        median_us(lambda: filterpy_predict(fp, COMMAND, TERRAIN), reset_filterpy),
        median_us(lambda: filterpy_bearing(fp, bearing), reset_filterpy),
        median_us(lambda: filterpy_range_bearing(fp, ranged), reset_filterpy),
        math.nan,
    )

    # The particle filter, from its initial Gaussian cloud (the same prior as the EKF's);
    # updates do not resample (that happens at the next predict), so every timed update
    # does the same work.
    pf_prior = ParticleFilter(Pose(0.0, 0.0, 0.0), np.random.default_rng(0), **SDS)
    pf = [pf_prior]

    def reset_pf() -> None:
        pf[0] = copy.copy(pf_prior)

    pf_times = (
        median_us(lambda: pf[0].predict(COMMAND, TERRAIN), reset_pf),
        median_us(lambda: pf[0].update(bearing, LANDMARK), reset_pf),
        median_us(lambda: pf[0].update(ranged, LANDMARK), reset_pf),
        median_us(lambda: pf_prior.region(0.99)),
    )
    seen = copy.copy(pf_prior)
    for _ in range(3):
        seen.update(ranged, LANDMARK)
    assert seen.effective_sample_size < 500  # so the next predict resamples
    resampling = median_us(
        lambda: pf[0].predict(COMMAND, TERRAIN), lambda: pf.__setitem__(0, copy.copy(seen))
    )

    print(f"timer overhead subtracted: {OVERHEAD_NS:.0f} ns per call; {REPEATS} calls per cell\n")
    header = f"{'estimator':<34}{'predict':>9}{'vs EKF':>8}{'bearing':>9}{'vs EKF':>8}"
    header += f"{'range+bearing':>15}{'vs EKF':>8}{'region':>9}{'vs EKF':>8}"
    print(header + "     (us)")
    rows = [
        (f"SpatialUncertaintyMap ({SIDES} vertices)", map_times),
        ("aura-ums ExtendedKalmanFilter", ekf_times),
        ("filterpy ExtendedKalmanFilter", filterpy_times),
        ("aura-ums ParticleFilter (1000)", pf_times),
    ]
    widths = (9, 9, 15, 9)
    for name, times in rows:
        line = f"{name:<34}"
        for value, reference, width in zip(times, ekf_times, widths, strict=True):
            if math.isnan(value):
                line += f"{'-':>{width}}{'':>8}"
            else:
                line += f"{value:>{width}.1f}{value / reference:>7.1f}x"
        print(line)
    print(
        "\nmap columns: grow / reduce Class I / reduce Class II (no region: the map is its region);"
        f"\nParticleFilter predict that first resamples (after 3 updates): {resampling:.1f} us"
    )


OVERHEAD_NS = timer_overhead_ns()

if __name__ == "__main__":
    main()
