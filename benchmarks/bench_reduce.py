"""Benchmark: the three landmark reductions against filterpy's EKF range-bearing update.

Run ``python benchmarks/bench_reduce.py``. Prints the median time of one reduction of
each class on a 16- and a 64-vertex map, with the compiled kernels (when the C
extension was built) and with the numpy reference, next to the median time of one
``ExtendedKalmanFilter.update`` (3 states: x, y, heading) with a range-bearing
measurement of a landmark, its Jacobian and measurement function written in Python
as a user would write them, measured in the same run.

Then the joint reduction of two and of three bearings taken at one instant by a map
whose heading may be anything (72 sectors of 5 degrees): with the sectors kernel
(``_native.reduce_sectors``, one call for every sector and observation) against the same
loop run in Python over the compiled single-reduction kernels (one call per sector and
observation, the joint reduction before the sectors kernel), in the same run.

With ``--replay LOG_DIR ... --terrain T.toml --sensors T.sensors.toml`` it also replays each
log (``--classes``, ``--profile``) with the sectors kernel and with the loop, alternately,
``--rounds`` times each in one process, and prints the update's total and median time.

Measured 28 November 2026 on the shared 2-core machine, three runs (its speed drifts):
two bearings 343-630 µs with the sectors kernel against 751-1,380 µs looped (2.2-2.3x),
three bearings 274-408 µs against 638-1,258 µs (2.3-3.1x).
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from filterpy.kalman import ExtendedKalmanFilter
from numpy.typing import NDArray

from aura_ums import _native
from aura_ums._native import _reduce as native_reduce
from aura_ums.geometry import HeadingWedge, regular_polygon
from aura_ums.manager import MapProfile
from aura_ums.uncertainty import (
    BearingObservation,
    GroundLineLandmark,
    GroundLineObservation,
    PointLandmark,
    Pose,
    RangeBearingObservation,
    SpatialUncertaintyMap,
    VerticalLineLandmark,
    reduce_jointly,
)

REPEATS = 2000
ROUNDS = 7

LANDMARK = np.array([20.0, 5.0])


def median_microseconds(call: Callable[[], object], repeats: int = REPEATS, rounds: int = ROUNDS) -> float:
    """Median over ``rounds`` of the mean time per call of ``repeats`` calls, microseconds."""
    for _ in range(50):
        call()
    samples = []
    for _ in range(rounds):
        start = time.perf_counter()
        for _ in range(repeats):
            call()
        samples.append((time.perf_counter() - start) / repeats * 1e6)
    return statistics.median(samples)


def prior_map(sides: int) -> SpatialUncertaintyMap:
    polygon = regular_polygon((0.0, 0.0), 2.0, sides, phase=0.1)
    return SpatialUncertaintyMap.from_polygon(polygon, (0.0, 0.0), HeadingWedge(0.0, 0.05, 0.05))


def reduction_calls(prior: SpatialUncertaintyMap) -> dict[str, Callable[[], object]]:
    bearing = math.atan2(LANDMARK[1] - 0.3, LANDMARK[0] - 0.2) - 0.05  # true pose (0.2, 0.3, 0.05)
    distance = math.hypot(LANDMARK[0] - 0.2, LANDMARK[1] - 0.3)
    x, y = float(LANDMARK[0]), float(LANDMARK[1])
    pole = VerticalLineLandmark("pole", x, y, 0.0, 6.0, "lamppost", 0.05)
    corner = PointLandmark("corner", x, y, 3.0, "building corner", 0.05)
    edge = GroundLineLandmark("edge", (-10.0, -1.0), (30.0, 1.0), "path edge", 0.05)
    normal = np.array([-math.sin(edge.direction), math.cos(edge.direction)])
    offset = float(normal @ (np.array([0.2, 0.3]) - edge.start))
    class_one = BearingObservation("pole", 0.0, bearing, math.radians(1.0))
    class_two = RangeBearingObservation(
        "corner", 0.0, bearing, math.radians(1.0), distance - 1.0, distance + 1.0
    )
    class_three = GroundLineObservation("edge", 0.0, offset, 0.3, edge.direction - 0.05, math.radians(2.0))
    return {
        "Class I": lambda: prior.reduce(class_one, pole),
        "Class II": lambda: prior.reduce(class_two, corner),
        "Class III": lambda: prior.reduce(class_three, edge),
    }


def ekf_update_call() -> Callable[[], object]:
    ekf = ExtendedKalmanFilter(dim_x=3, dim_z=2)
    ekf.x = np.array([0.0, 0.0, 0.0])
    ekf.P = np.diag([0.5**2, 0.5**2, 0.05**2])
    ekf.R = np.diag([0.3**2, math.radians(1.0) ** 2])
    state = (ekf.x.copy(), ekf.P.copy())
    z = np.array(
        [math.hypot(*(LANDMARK - [0.2, 0.3])), math.atan2(LANDMARK[1] - 0.3, LANDMARK[0] - 0.2) - 0.05]
    )

    def jacobian(x: NDArray[np.float64]) -> NDArray[np.float64]:
        dx, dy = LANDMARK[0] - x[0], LANDMARK[1] - x[1]
        q = dx * dx + dy * dy
        r = math.sqrt(q)
        return np.array([[-dx / r, -dy / r, 0.0], [dy / q, -dx / q, -1.0]])

    def measure(x: NDArray[np.float64]) -> NDArray[np.float64]:
        dx, dy = LANDMARK[0] - x[0], LANDMARK[1] - x[1]
        return np.array([math.hypot(dx, dy), math.atan2(dy, dx) - x[2]])

    def residual(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
        y = a - b
        y[1] = (y[1] + math.pi) % (2 * math.pi) - math.pi
        return y

    def update() -> None:
        # Reset so every call updates the same prior (as every reduction does).
        ekf.x, ekf.P = state[0].copy(), state[1].copy()
        ekf.update(z, jacobian, measure, residual=residual)

    return update


def numpy_only(call: Callable[[], object]) -> Callable[[], object]:
    """Return ``call`` run with the compiled reduction kernels switched off (the numpy reference)."""

    def run() -> object:
        # The kernels the package bound (AURA_UMS_NATIVE=0 binds these for a whole process).
        saved = _native.reduce_cone, _native.reduce_strip
        _native.reduce_cone = native_reduce.reduce_cone_reference
        _native.reduce_strip = native_reduce.reduce_strip_reference
        try:
            return call()
        finally:
            _native.reduce_cone, _native.reduce_strip = saved

    return run


def joint_calls() -> dict[str, Callable[[], object]]:
    """The joint reduction of two and of three bearings by a map whose heading may be anything."""
    truth = Pose(3.0, 4.0, 1.0)
    lost = SpatialUncertaintyMap.from_pose(Pose(5.0, 5.0, 0.0), 15.0, math.pi)
    poles = [
        VerticalLineLandmark(name, x, y, 0.0, 5.0)
        for name, x, y in (("a", 12, 4), ("b", 3, 14), ("c", -4, 2))
    ]
    seen = [
        (BearingObservation(p.id, 0.0, math.atan2(p.y - truth.y, p.x - truth.x) - truth.heading, 0.02), p)
        for p in poles
    ]
    return {
        "2 bearings": lambda: reduce_jointly(lost, seen[:2]),
        "3 bearings": lambda: reduce_jointly(lost, seen),
    }


def looped_sectors(call: Callable[[], object]) -> Callable[[], object]:
    """Return ``call`` with the sectors reduced by the Python loop over the compiled single kernels."""

    def sectors(*arguments: Any) -> native_reduce.ReducedSectors:
        saved = native_reduce.reduce_cone_reference, native_reduce.reduce_strip_reference
        native_reduce.reduce_cone_reference = native_reduce.reduce_cone_compiled  # type: ignore[assignment]
        native_reduce.reduce_strip_reference = native_reduce.reduce_strip_compiled  # type: ignore[assignment]
        try:
            return native_reduce.reduce_sectors_reference(*arguments)
        finally:
            native_reduce.reduce_cone_reference, native_reduce.reduce_strip_reference = saved

    def run() -> object:
        saved = _native.reduce_sectors
        _native.reduce_sectors = sectors  # type: ignore[assignment]
        try:
            return call()
        finally:
            _native.reduce_sectors = saved

    return run


def main() -> None:
    ekf = median_microseconds(ekf_update_call())
    compiled = _native.NATIVE
    print(f"filterpy ExtendedKalmanFilter.update (range-bearing, 3 states): {ekf:8.1f} us")
    if not compiled:
        print("(the C kernels are not in use: the compiled columns repeat the numpy reference)")
    print()
    print(
        f"{'reduction':<12}{'vertices':>9}{'compiled us':>13}{'vs EKF':>8}{'numpy us':>10}{'vs EKF':>8}"
        f"{'speed-up':>10}{'area after/before':>19}"
    )
    for sides in (16, 64):
        prior = prior_map(sides)
        for name, call in reduction_calls(prior).items():
            reduction = call()
            fast = median_microseconds(call)
            slow = median_microseconds(numpy_only(call), repeats=REPEATS // 4)
            ratio = reduction.area_after / reduction.area_before  # type: ignore[attr-defined]
            print(
                f"{name:<12}{sides:>9}{fast:>13.1f}{fast / ekf:>7.2f}x{slow:>10.1f}{slow / ekf:>7.2f}x"
                f"{slow / fast:>9.1f}x{ratio:>19.3f}"
            )
    if not compiled:
        return
    print()
    print(f"{'joint reduction, 72 sectors':<30}{'sectors kernel us':>19}{'looped us':>11}{'speed-up':>10}")
    for name, call in joint_calls().items():
        # Alternate the two, round by round: the shared machine's speed drifts.
        kernel_times, looped_times = [], []
        for _ in range(ROUNDS):
            kernel_times.append(median_microseconds(call, repeats=50, rounds=1))
            looped_times.append(median_microseconds(looped_sectors(call), repeats=50, rounds=1))
        fast, slow = statistics.median(kernel_times), statistics.median(looped_times)
        print(f"{name:<30}{fast:>19.0f}{slow:>11.0f}{slow / fast:>9.1f}x")


def replay_side_by_side(args: argparse.Namespace) -> None:
    """Replay each log with the sectors kernel and with the loop, alternately; print the update times."""
    from aura_ums.logs import ReplayOptions, load_sensors, open_log, replay_log
    from aura_ums.manager import MapProfile
    from aura_ums.uncertainty import LandmarkClass, TerrainTable

    table = TerrainTable.from_toml(args.terrain)
    motion, working, envelope = load_sensors(args.sensors)
    kind = LandmarkClass.POINT if args.classes == "II" else LandmarkClass.VERTICAL_LINE
    options = ReplayOptions(
        landmark_class=kind,
        motion=motion,
        working=working,
        envelope=envelope,
        settings=MapProfile(args.profile).settings(),
    )
    print(f"{'log':<28}{'reductions':<16}{'update s (each round)':<30}{'median us per frame'}")
    for folder in args.replay:
        log = open_log(folder)
        times: dict[str, list[tuple[float, float]]] = {"sectors kernel": [], "looped": []}

        def replay(log: Any = log) -> object:
            return replay_log(log, table, options, keep_maps=False)

        for _ in range(args.rounds):
            for name, run in (("sectors kernel", replay), ("looped", looped_sectors(replay))):
                result: Any = run()
                update_us = result.trace.update_us
                times[name].append((float(update_us.sum()) / 1e6, float(np.median(update_us))))
        for name, runs in times.items():
            totals = " / ".join(f"{total:.2f}" for total, _ in runs)
            medians = " / ".join(f"{median:.0f}" for _, median in runs)
            print(f"{Path(folder).name:<28}{name:<16}{totals:<30}{medians}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--replay", nargs="+", default=[], metavar="LOG_DIR", help="logs to replay both ways")
    parser.add_argument("--terrain", help="terrain table TOML of the logs")
    parser.add_argument("--sensors", help="sensors TOML of the logs")
    parser.add_argument("--classes", choices=["I", "II"], default="I")
    parser.add_argument("--profile", choices=[p.value for p in MapProfile], default="product")
    parser.add_argument("--rounds", type=int, default=3)
    arguments = parser.parse_args()
    main()
    if arguments.replay:
        if not (arguments.terrain and arguments.sensors):
            parser.error("--replay: expected --terrain and --sensors too")
        print()
        replay_side_by_side(arguments)
