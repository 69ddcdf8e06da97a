from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import aura_ums as ums
from aura_ums import (
    ConvexPolygon,
    HeadingWedge,
    InputError,
    Pose,
    SpatialUncertaintyMap,
    TerrainStats,
    TerrainTable,
    TurnAndRun,
)
from aura_ums.geometry import angle_difference, regular_polygon
from aura_ums.geometry._convex import convexity_defect
from aura_ums.uncertainty import growth_tightness, simulate_containment
from aura_ums.uncertainty._growth import DEFAULT_MAX_VERTICES

TERRAINS = TerrainTable.default()
NAMES = sorted(TERRAINS)


def random_start(rng: np.random.Generator, index: int) -> SpatialUncertaintyMap:
    """Alternate points, disks and random polygons; wedges of every width, across the seam too."""
    heading = float(rng.choice([math.pi, -math.pi + 1e-3, rng.uniform(-math.pi, math.pi)]))
    kind = index % 3
    position = (float(rng.uniform(-5, 5)), float(rng.uniform(-5, 5)))
    if kind == 0:
        return SpatialUncertaintyMap.from_pose(Pose(*position, heading), 0.0, 0.0)
    if kind == 1:
        return SpatialUncertaintyMap.from_pose(
            Pose(*position, heading), rng.uniform(0.0, 1.0), rng.uniform(0.0, 0.6)
        )
    polygon = ConvexPolygon.from_points(rng.normal(0.0, 1.0, (10, 2)) * rng.uniform(0.1, 2.0, 2))
    wedge = HeadingWedge(heading, *rng.uniform(0.0, 1.5, 2))
    return SpatialUncertaintyMap.from_polygon(polygon, polygon.centroid, wedge)


def random_moves(rng: np.random.Generator) -> list[tuple[TurnAndRun, TerrainStats]]:
    moves = []
    for _ in range(int(rng.integers(1, 21))):
        turn = float(rng.choice([0.0, math.pi, -math.pi, rng.uniform(-math.pi, math.pi)]))
        run = float(rng.choice([0.0, rng.uniform(0.0, 10.0), rng.uniform(0.0, 10.0)]))
        moves.append((TurnAndRun(turn, run), TERRAINS[NAMES[int(rng.integers(4))]]))
    return moves


# --- acceptance: soundness, calibration, tightness -------------------------------------------------


def test_soundness_every_truncated_outcome_is_inside() -> None:
    """>= 300 random sequences of 1-20 moves, all terrains, >= 20,000 true poses: 100 % inside."""
    rng = np.random.default_rng(2026)
    inside = total = 0
    terrains_used: set[int] = set()
    for index in range(300):
        moves = random_moves(rng)
        terrains_used.update(id(terrain) for _, terrain in moves)
        result = simulate_containment(random_start(rng, index), moves, rng, poses=40, truncate=3.0)
        inside += result.inside
        total += result.total
    assert len(terrains_used) == 4
    assert total >= 20_000
    assert inside == total


@pytest.mark.parametrize("sigmas", [1.0, 2.0, 3.0])
def test_soundness_holds_at_every_sigma(sigmas: float) -> None:
    rng = np.random.default_rng(int(sigmas * 10))
    for index in range(40):
        result = simulate_containment(
            random_start(rng, index), random_moves(rng), rng, poses=30, sigmas=sigmas, truncate=sigmas
        )
        assert result.rate == 1.0


def calibration_rate(sigmas: float) -> float:
    rng = np.random.default_rng(7)
    inside = total = 0
    for index in range(200):
        start = random_start(rng, index)
        result = simulate_containment(
            start, random_moves(rng), rng, poses=60, sigmas=sigmas, include_extremes=False
        )
        inside += result.inside
        total += result.total
    return inside / total


def test_calibration_at_three_sigma_keeps_99_percent() -> None:
    assert calibration_rate(3.0) >= 0.99


def test_calibration_at_two_sigma_keeps_95_percent() -> None:
    assert calibration_rate(2.0) >= 0.95


@pytest.mark.parametrize("name", NAMES)
def test_tightness_of_one_move_from_a_point(name: str, point_map: SpatialUncertaintyMap) -> None:
    result = growth_tightness(
        point_map, TurnAndRun(math.radians(45), 30 * ums.FOOT), TERRAINS[name], np.random.default_rng(1)
    )
    assert 1.0 <= result.ratio <= 1.5


# --- invariants as properties ----------------------------------------------------------------------

commands = st.builds(
    TurnAndRun,
    st.one_of(st.sampled_from([0.0, math.pi, -math.pi]), st.floats(-2 * math.pi, 2 * math.pi)),
    st.one_of(st.just(0.0), st.floats(0.0, 50.0)),
)
terrain_names = st.sampled_from(NAMES)
seeds = st.integers(0, 2**32 - 1)


@given(seeds, st.lists(st.tuples(commands, terrain_names), min_size=1, max_size=8))
def test_growth_keeps_polygon_convex_ccw_and_wedge_valid(
    seed: int, moves: list[tuple[TurnAndRun, str]]
) -> None:
    current = random_start(np.random.default_rng(seed), seed)
    for command, name in moves:
        current = current.grow(command, TERRAINS[name])
        assert convexity_defect(current.polygon.vertices) is None
        assert current.polygon.vertex_count <= DEFAULT_MAX_VERTICES
        assert current.wedge.cw >= 0.0
        assert current.wedge.ccw >= 0.0
        assert -math.pi < current.wedge.center <= math.pi
        assert current.contains(current.most_probable_pose())


@given(seeds, st.floats(-2 * math.pi, 2 * math.pi), terrain_names)
def test_turning_in_place_never_shrinks_the_polygon(seed: int, turn: float, name: str) -> None:
    start = random_start(np.random.default_rng(seed), seed)
    grown = start.grow(TurnAndRun(turn, 0.0), TERRAINS[name])
    assert np.all(grown.polygon.contains(start.polygon.vertices, tolerance=1e-9))


@given(seeds)
def test_zero_command_on_a_zero_loss_terrain_contains_the_old_map(seed: int) -> None:
    rng = np.random.default_rng(seed)
    start = random_start(rng, seed)
    sd = [float(value) for value in rng.uniform(0.0, 0.1, 5)]
    zero_loss = TerrainStats(0.0, 0.0, sd[0], sd[1], 0.0, sd[2], sd[3], sd[4])
    grown = start.grow(TurnAndRun(0.0, 0.0), zero_loss)
    poses = start.sample_poses(200, rng)
    assert np.all(grown.contains(poses[:, 0], poses[:, 1], poses[:, 2]))
    assert grown.area >= start.area - 1e-12


@given(st.floats(-math.pi, math.pi), st.floats(0.0, 1.0), st.floats(0.0, 1.0), st.floats(-10.0, 10.0))
def test_turns_rotate_the_wedge_exactly_across_the_seam(
    center: float, cw: float, ccw: float, turn: float
) -> None:
    polygon = ConvexPolygon([(0.0, 0.0)])
    start = SpatialUncertaintyMap.from_polygon(polygon, (0.0, 0.0), HeadingWedge(center, cw, ccw))
    grown = start.grow(TurnAndRun(turn, 0.0), TerrainStats.zero())
    assert angle_difference(grown.wedge.center, center + turn) == pytest.approx(0.0, abs=1e-9)
    assert grown.wedge.cw == pytest.approx(cw, abs=1e-12)
    assert grown.wedge.ccw == pytest.approx(ccw, abs=1e-12)


# --- the paper's figures, qualitatively ------------------------------------------------------------


def test_figure5_point_transform(figure5_map: SpatialUncertaintyMap) -> None:
    # A 45 degree turn then a 30 ft run from the origin: centre moved by the mean motion,
    # orientation uncertainty introduced, polygon grown from a point.
    assert figure5_map.area > 0.0
    assert figure5_map.wedge.width > 0.0
    assert math.hypot(*figure5_map.center) < 30 * ums.FOOT
    assert math.atan2(figure5_map.center[1], figure5_map.center[0]) < math.radians(45)


def test_figure6_ccw_turn_grows_the_clockwise_extent_most() -> None:
    start = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.0, math.radians(5))
    grown = start.grow(TurnAndRun(math.radians(90), 20 * ums.FOOT), TERRAINS["concrete"])
    cw_growth = grown.wedge.cw - start.wedge.cw
    ccw_growth = grown.wedge.ccw - start.wedge.ccw
    assert cw_growth > 2 * ccw_growth > 0.0
    drift_only = TERRAINS["concrete"].drift * 20 * ums.FOOT * (1 - 0.03 + 3 * 0.015)
    assert ccw_growth == pytest.approx(math.radians(90) * 0.02 + drift_only, rel=0.05)


def test_figure7_map_transform_from_a_polygon(figure5_map: SpatialUncertaintyMap) -> None:
    turned = figure5_map.grow(TurnAndRun(math.radians(45), 30 * ums.FOOT), TERRAINS["concrete"])
    assert turned.area > figure5_map.area
    forward = figure5_map.grow(TurnAndRun(0.0, 30 * ums.FOOT), TERRAINS["concrete"])
    back = forward.grow(TurnAndRun(math.pi, 30 * ums.FOOT), TERRAINS["concrete"])
    assert back.area > forward.area
    # A 180 degree turn and run comes back near where the forward run started.
    assert np.linalg.norm(back.center - figure5_map.center) < 2.0


# --- edge cases ------------------------------------------------------------------------------------


def test_zero_length_run_and_zero_turn_change_nothing(point_map: SpatialUncertaintyMap) -> None:
    grown = point_map.grow(TurnAndRun(0.0, 0.0), TERRAINS["grass"])
    assert grown.polygon == point_map.polygon
    assert grown.wedge == point_map.wedge


def test_full_circle_wedge_grows_into_a_ring_hull() -> None:
    start = SpatialUncertaintyMap.from_pose(Pose(1.0, 2.0, 0.5), 0.0, math.pi)
    assert start.wedge.is_full_circle
    grown = start.grow(TurnAndRun(0.3, 5.0), TERRAINS["tile"])
    assert grown.wedge.is_full_circle
    # Any direction is possible: the polygon surrounds the start at about the run's reach.
    for angle in np.linspace(-math.pi, math.pi, 16, endpoint=False):
        assert grown.polygon.contains([(1.0 + 4.9 * math.cos(angle), 2.0 + 4.9 * math.sin(angle))])[0]


def test_wedge_that_grows_past_a_full_circle_becomes_the_full_circle() -> None:
    start = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.0, 3.0)
    grown = start.grow(TurnAndRun(math.pi, 1.0), TERRAINS["grass"])
    assert grown.wedge.is_full_circle
    assert (grown.wedge.cw, grown.wedge.ccw) == (math.pi, math.pi)


def test_vertex_cap_is_respected_for_large_maps() -> None:
    polygon = regular_polygon((0.0, 0.0), 3.0, 64)
    start = SpatialUncertaintyMap.from_polygon(polygon, (0.0, 0.0), HeadingWedge(0.0, 0.4, 0.4))
    grown = start.grow(TurnAndRun(1.0, 5.0), TERRAINS["gravel"], max_vertices=16)
    assert grown.polygon.vertex_count <= 16
    assert np.all(
        grown.polygon.contains(start.grow(TurnAndRun(1.0, 5.0), TERRAINS["gravel"]).polygon.vertices)
    )


def test_maps_are_immutable(figure5_map: SpatialUncertaintyMap) -> None:
    with pytest.raises(AttributeError, match=r"cannot assign to field"):
        figure5_map.center = np.zeros(2)  # type: ignore[misc]
    with pytest.raises(ValueError, match=r"read-only"):
        figure5_map.center[0] = 1.0


# --- contains and construction ---------------------------------------------------------------------


def test_contains_takes_a_pose_or_arrays(figure5_map: SpatialUncertaintyMap) -> None:
    centre = figure5_map.most_probable_pose()
    assert figure5_map.contains(centre) is True
    assert figure5_map.contains(centre.x, centre.y, centre.heading) is True
    result = figure5_map.contains(
        np.array([centre.x, 100.0]), np.array([centre.y, 0.0]), np.array([centre.heading] * 2)
    )
    assert isinstance(result, np.ndarray)
    assert result.tolist() == [True, False]
    assert not figure5_map.contains(Pose(centre.x, centre.y, centre.heading + math.pi))


def test_contains_refuses_half_a_pose(figure5_map: SpatialUncertaintyMap) -> None:
    with pytest.raises(
        InputError, match=r"expected a Pose, x, y and heading, or poses of shape \(3,\) or \(n, 3\), got \(\)"
    ):
        figure5_map.contains(1.0)
    with pytest.raises(InputError, match=r"or poses of shape \(3,\) or \(n, 3\), got \(4, 2\)"):
        figure5_map.contains(np.zeros((4, 2)))
    with pytest.raises(InputError, match=r"got x and only one of them"):
        figure5_map.contains(1.0, 2.0)
    with pytest.raises(InputError, match=r"expected x, y and heading of one shape"):
        figure5_map.contains(np.zeros(2), np.zeros(3), np.zeros(2))
    with pytest.raises(InputError, match=r"got a Pose and more"):
        figure5_map.contains(Pose(0, 0, 0), 1.0)  # type: ignore[call-overload]


def test_from_polygon_refuses_a_centre_outside() -> None:
    square = ConvexPolygon([(0, 0), (1, 0), (1, 1), (0, 1)])
    with pytest.raises(InputError, match=r"center: expected a point inside the polygon, got \[2.0, 2.0\]"):
        SpatialUncertaintyMap.from_polygon(square, (2.0, 2.0), HeadingWedge(0, 0, 0))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"sigmas": 0.0}, r"sigmas: expected a number in \[0\.1, 100\], got 0\.0"),
        ({"sigmas": 1e300}, r"sigmas: expected a number in \[0\.1, 100\], got 1e\+300"),
        ({"sigmas": float("nan")}, r"sigmas: expected a finite number, got nan"),
        ({"sigmas": "3"}, r"sigmas: expected a finite number, got '3'"),
        ({"max_vertices": 2}, r"max_vertices: expected an integer in \[3, 2\*\*63 - 1\], got 2"),
        ({"max_vertices": 3.5}, r"max_vertices: expected an integer in \[3, 2\*\*63 - 1\], got 3.5"),
        (
            {"max_vertices": 2**70},
            r"max_vertices: expected an integer in \[3, 2\*\*63 - 1\], got 1180591620717411303424",
        ),
    ],
)
def test_grow_refuses_bad_arguments(
    figure5_map: SpatialUncertaintyMap, kwargs: dict[str, float], message: str
) -> None:
    with pytest.raises(InputError, match=message):
        figure5_map.grow(TurnAndRun(0, 1), TERRAINS["tile"], **kwargs)  # type: ignore[arg-type]


def test_grow_takes_numpy_scalars(figure5_map: SpatialUncertaintyMap) -> None:
    # sigmas=np.float32(3.0) was refused, where every other number took numpy scalars
    plain = figure5_map.grow(TurnAndRun(0, 1), TERRAINS["tile"], sigmas=3.0, max_vertices=64)
    sigmas: Any = np.float32(3.0)  # numpy scalars, as a config read into arrays gives them
    cap: Any = np.int64(64)
    scalar = figure5_map.grow(TurnAndRun(0, 1), TERRAINS["tile"], sigmas=sigmas, max_vertices=cap)
    assert np.array_equal(plain.polygon.vertices, scalar.polygon.vertices)


def test_grow_refuses_a_terrain_name_instead_of_statistics(figure5_map: SpatialUncertaintyMap) -> None:
    with pytest.raises(InputError, match=r"terrain: expected TerrainStats, got str"):
        figure5_map.grow(TurnAndRun(0, 1), "tile")  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"command: expected a TurnAndRun, got tuple"):
        figure5_map.grow((0, 1), TERRAINS["tile"])  # type: ignore[arg-type]


def test_sample_poses_lie_in_the_map(figure5_map: SpatialUncertaintyMap, rng: np.random.Generator) -> None:
    poses = figure5_map.sample_poses(2000, rng)
    assert poses.shape == (2000, 3)
    assert np.all(figure5_map.contains(poses[:, 0], poses[:, 1], poses[:, 2]))


def test_simulate_containment_refuses_zero_poses(
    point_map: SpatialUncertaintyMap, rng: np.random.Generator
) -> None:
    with pytest.raises(InputError, match=r"poses: expected at least 1, got 0"):
        simulate_containment(point_map, [], rng, poses=0)


@given(st.floats(-50, 50), st.floats(-50, 50), st.floats(-4.0, 4.0), st.floats(0.0, 0.3))
def test_most_probable_pose_is_built_once_and_equals_a_fresh_pose(
    x: float, y: float, heading: float, halfwidth: float
) -> None:
    """The cached pose is the validated one: the centre and the wedge's (wrapped) centre."""
    start = SpatialUncertaintyMap.from_pose(Pose(x, y, heading), 0.2, halfwidth)
    grown = start.grow(TurnAndRun(0.3, 1.0), TerrainTable.default()["grass"])
    for uncertainty_map in (start, grown):
        pose = uncertainty_map.most_probable_pose()
        fresh = Pose(
            float(uncertainty_map.center[0]), float(uncertainty_map.center[1]), uncertainty_map.wedge.center
        )
        assert pose == fresh
        assert uncertainty_map.most_probable_pose() is pose
    assert grown.most_probable_pose() != start.most_probable_pose()


def test_bad_arguments_get_the_library_error() -> None:
    # these raised AttributeError, a numpy ValueError or TypeError from deep inside
    start = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.5, 0.2)
    rng = np.random.default_rng(0)
    pose: Any = (0, 0, 0)
    with pytest.raises(InputError, match=r"pose: expected a Pose, got tuple \(0, 0, 0\)"):
        SpatialUncertaintyMap.from_pose(pose, 0.5, 0.2)
    for count in (-1, 2.5):
        bad: Any = count
        with pytest.raises(InputError, match=rf"count: expected an integer >= 0, got {count}"):
            start.sample_poses(bad, rng)
    no_rng: Any = None
    with pytest.raises(InputError, match=r"rng: expected a numpy.random.Generator, got NoneType"):
        start.sample_poses(3, no_rng)
    # in the ranges the files have: a pose at 1e16 m made a one-point map, a radius of 1e300 a NaN area
    with pytest.raises(InputError, match=r"Pose.x: expected a number in \[-1e\+06, 1e\+06\] m, got 1e\+16"):
        Pose(1e16, 1e16, 0.3)
    with pytest.raises(
        InputError, match=r"position_radius: expected a number in \[0, 10000\] m, got 1e\+300"
    ):
        SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 1e300, 0.1)


def test_contains_takes_the_pose_arrays_the_library_gives(figure5_map: SpatialUncertaintyMap) -> None:
    # sample_poses and sample_motions give (n, 3) arrays, which contains refused
    rows = figure5_map.sample_poses(50, np.random.default_rng(3))
    inside = figure5_map.contains(rows)
    assert isinstance(inside, np.ndarray)
    assert inside.tolist() == figure5_map.contains(rows[:, 0], rows[:, 1], rows[:, 2]).tolist()  # type: ignore[union-attr]
    assert inside.all()
    assert figure5_map.contains(rows[0]) is True


def test_sample_poses_caps_the_count() -> None:
    # 10**12 poses: a MemoryError asking for 7.28 TiB before
    start = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.5, 0.2)
    with pytest.raises(
        InputError, match=r"count: expected at most 10000000 poses \(about 240 MB\), got 1000000000000"
    ):
        start.sample_poses(10**12, np.random.default_rng(0))


def test_the_monte_carlo_checks_name_their_own_arguments() -> None:
    start = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.5, 0.2)
    rng = np.random.default_rng(0)
    moves = [(TurnAndRun(0.1, 1.0), TERRAINS["tile"])]
    anything: Any = None
    half: Any = 1.5
    with pytest.raises(InputError, match=r"samples: expected an integer >= 0, got 1\.5"):
        growth_tightness(start, TurnAndRun(0.1, 1.0), TERRAINS["tile"], rng, samples=half)
    with pytest.raises(InputError, match="start: expected a SpatialUncertaintyMap, got NoneType"):
        growth_tightness(anything, TurnAndRun(0.1, 1.0), TERRAINS["tile"], rng)
    with pytest.raises(InputError, match=r"poses: expected an integer >= 0, got 1\.5"):
        simulate_containment(start, moves, rng, poses=half)
    with pytest.raises(InputError, match="poses: expected at most 10000000 poses"):
        simulate_containment(start, moves, rng, poses=10**12)
    with pytest.raises(InputError, match=r"moves: expected a sequence of .*, got NoneType"):
        simulate_containment(start, anything, rng)
    with pytest.raises(
        InputError, match=r"moves\[0\]: expected a \(TurnAndRun, TerrainStats\) pair, got None"
    ):
        simulate_containment(start, [anything], rng)
    with pytest.raises(InputError, match="start: expected a SpatialUncertaintyMap, got NoneType"):
        simulate_containment(anything, moves, rng)
    with pytest.raises(InputError, match=r"rng: expected a numpy\.random\.Generator, got NoneType"):
        simulate_containment(start, moves, anything)
