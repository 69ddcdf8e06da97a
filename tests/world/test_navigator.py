from __future__ import annotations

import inspect
import itertools
import math
import time
from typing import Any

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from aura_ums import (
    ConvexPolygon,
    InputError,
    Pose,
    SpatialUncertaintyMap,
    TerrainStats,
    TerrainTable,
    TurnAndRun,
    UnknownTerrainError,
)
from aura_ums._native import motion_bounds
from aura_ums.errors import OutsideMapError
from aura_ums.sim import SimulatedRobot
from aura_ums.world import (
    Meadow,
    MeadowMap,
    Route,
    RunPiece,
    commands_for,
    grow_through,
    make_grid_world,
    meadows_in_reach,
    outer_terrain,
    plan_route,
    sample_world,
    split_run,
)

# A 25 x 42 grid with two walls (each with one gap) removed: exactly 1,000 meadows.
WALL_A = [(r, 14) for r in range(25) if r != 3]  # 24 cells, gap at row 3
WALL_B = [(r, 28) for r in range(25) if r not in (21, 22)]  # 23 cells, gap at rows 21-22
OBSTACLES = [*WALL_A, *WALL_B, (10, 5), (11, 5), (12, 5)]


def box(x0: float, y0: float, x1: float, y1: float) -> ConvexPolygon:
    return ConvexPolygon([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])


@pytest.fixture(scope="module")
def big_world() -> MeadowMap:
    world = make_grid_world(25, 42, cell=5.0, remove=OBSTACLES)
    assert len(world) == 1000
    return world


def assert_route_in_free_space(world: MeadowMap, route: Route) -> None:
    assert all(m is not None for m in world.meadows_at(route.waypoints))
    union = shapely.union_all([world.shape(m.id) for m in world.meadows]).buffer(1e-9)
    for (a, b), meadow_id in zip(route.legs, route.meadow_ids, strict=True):
        polygon = world.meadow(meadow_id).polygon
        along = a + np.linspace(0.0, 1.0, 11)[:, None] * (b - a)
        assert polygon.contains(along).all(), f"leg {a} -> {b} leaves {meadow_id}"
        assert union.covers(shapely.LineString([a, b]))
    for first, second in zip(route.meadow_ids, route.meadow_ids[1:], strict=False):
        if first != second:
            assert second in [m.id for m in world.neighbours(first)]


# --- routes ------------------------------------------------------------------------------------


def test_route_through_a_thousand_meadows(big_world: MeadowMap) -> None:
    start, goal = (2.5, 2.5), (207.5, 122.5)
    began = time.perf_counter()
    route = plan_route(big_world, start, goal)
    elapsed = time.perf_counter() - began
    assert elapsed < 2.0
    np.testing.assert_array_equal(route.waypoints[0], start)
    np.testing.assert_array_equal(route.waypoints[-1], goal)
    assert route.meadow_ids[0] == "cell_0_0"
    assert route.meadow_ids[-1] == "cell_24_41"
    assert route.length >= math.dist(start, goal)
    assert len(route.legs) == len(route.meadow_ids) == len(route.waypoints) - 1
    assert route.length == pytest.approx(route.leg_lengths.sum())
    # The walls force the route through their gaps.
    assert "cell_3_14" in route.meadow_ids
    assert {"cell_21_28", "cell_22_28"} & set(route.meadow_ids)
    assert_route_in_free_space(big_world, route)


def test_route_is_shortest_through_portal_midpoints() -> None:
    # An L-shaped corridor: the route turns the corner through the portals.
    world = MeadowMap(
        [
            Meadow("south", box(0, 0, 10, 2), "tile"),
            Meadow("corner", box(10, 0, 12, 2), "tile"),
            Meadow("east", box(10, 2, 12, 12), "tile"),
            Meadow("shortcut_blocked", box(4, 6, 8, 12), "tile"),
        ]
    )
    route = plan_route(world, (1, 1), (11, 11))
    assert route.meadow_ids == ("south", "corner", "east")
    np.testing.assert_array_equal(route.waypoints, [[1, 1], [10, 1], [11, 2], [11, 11]])
    with pytest.raises(InputError, match=r"goal: expected a point reachable from start .* \(6.0, 8.0\) in"):
        plan_route(world, (1, 1), (6, 8))


def test_unreachable_goal_is_an_input_error() -> None:
    sealed = make_grid_world(5, 5, remove=[(r, 2) for r in range(5)])
    with pytest.raises(
        InputError,
        match=r"^goal: expected a point reachable from start through adjacent meadows, "
        r"got \(22.5, 2.5\) in 'cell_0_4', not connected to 'cell_0_0'",
    ):
        plan_route(sealed, (2.5, 2.5), (22.5, 2.5))


def test_start_or_goal_outside_every_meadow_is_an_input_error() -> None:
    world = make_grid_world(2, 2)
    with pytest.raises(InputError, match=r"^start: expected a point inside a meadow, got \(-1.0, 2.0\)"):
        plan_route(world, (-1, 2), (2, 2))
    with pytest.raises(InputError, match=r"^goal: expected a point inside a meadow, got \(2.0, 30.0\)"):
        plan_route(world, (2, 2), (2, 30))
    with pytest.raises(InputError, match=r"^start: expected one \(x, y\) point, got shape \(2, 2\)"):
        plan_route(world, [(1, 1), (2, 2)], (2, 2))
    with pytest.raises(InputError, match="meadow_map: expected a MeadowMap, got str"):
        plan_route("map", (1, 1), (2, 2))  # type: ignore[arg-type]


def test_routes_within_one_meadow() -> None:
    world = make_grid_world(2, 2)
    direct = plan_route(world, (1, 1), (4, 3))
    np.testing.assert_array_equal(direct.waypoints, [[1, 1], [4, 3]])
    assert direct.meadow_ids == ("cell_0_0",)
    stay = plan_route(world, (1, 1), (1, 1))
    assert (len(stay.waypoints), len(stay.legs), stay.length, stay.meadow_ids) == (1, 0, 0.0, ("cell_0_0",))
    # On a shared boundary, start and goal share a meadow even if meadow_at picks another.
    assert plan_route(world, (5, 2), (8, 2)).meadow_ids == ("cell_0_1",)


def test_start_on_a_portal_midpoint_gives_no_empty_leg() -> None:
    world = make_grid_world(1, 3)
    route = plan_route(world, (5.0, 2.5), (12.5, 2.5))
    np.testing.assert_array_equal(route.waypoints, [[5.0, 2.5], [10.0, 2.5], [12.5, 2.5]])
    assert route.meadow_ids == ("cell_0_1", "cell_0_2")
    assert np.all(route.leg_lengths > 0)


def test_sidewalk_route_follows_the_walk() -> None:
    world = sample_world("paper_sidewalk")
    route = plan_route(world, (0.0, 0.0), (12.192, 0.0))
    assert route.meadow_ids == ("sidewalk_west", "sidewalk_middle", "sidewalk_east")
    assert route.length == pytest.approx(12.192)


def test_route_validates_and_compares() -> None:
    route = Route([(0, 0), (3, 4)], ("a",))
    assert route == Route(np.array([[0.0, 0.0], [3.0, 4.0]]), ["a"])
    assert route != Route([(0, 0), (3, 4)], ("b",))
    assert route != "route"
    assert not route.waypoints.flags.writeable
    assert "1 legs, 5 m" in repr(route)
    with pytest.raises(InputError, match="meadow_ids: expected 1 ids"):
        Route([(0, 0), (3, 4)], ("a", "b"))
    with pytest.raises(InputError, match="expected no two consecutive waypoints equal"):
        Route([(0, 0), (0, 0)], ("a",))
    with pytest.raises(InputError, match=r"meadow_ids\[0\]: expected a non-empty string"):
        Route([(0, 0)], ("",))


# --- terrain along a run ---------------------------------------------------------------------------


def test_run_crossing_three_terrains_is_split_in_three() -> None:
    world = make_grid_world(1, 4, cell=5.0)  # concrete, grass, gravel, tile
    pieces = split_run(world, (2.5, 2.5), 0.0, 10.0)
    assert pieces == [
        RunPiece(2.5, "concrete", "cell_0_0"),
        RunPiece(5.0, "grass", "cell_0_1"),
        RunPiece(2.5, "gravel", "cell_0_2"),
    ]


def test_sidewalk_run_from_the_grass_over_the_walk_onto_gravel() -> None:
    world = sample_world("paper_sidewalk")
    heading = math.atan2(2.0, 10.0)
    pieces = split_run(world, (10.0, -2.0), heading, math.hypot(10.0, 2.0))
    assert [(p.terrain, p.meadow_id) for p in pieces] == [
        ("grass", "grass_south"),
        ("concrete", "sidewalk_east"),
        ("gravel", "gravel_path"),
    ]
    scale = math.hypot(10.0, 2.0) / 10.0
    np.testing.assert_allclose([p.distance for p in pieces], [5 * scale, 1 * scale, 4 * scale], rtol=1e-12)


def test_growing_through_commands_equals_growing_piecewise(terrains: TerrainTable) -> None:
    world = make_grid_world(1, 4, cell=5.0)
    pose = Pose(2.5, 2.5, 0.3)
    command = TurnAndRun(-0.3, 10.0)
    steps = commands_for(world, pose, command, terrains)
    assert [step for step, _ in steps] == [TurnAndRun(-0.3, 2.5), TurnAndRun(0.0, 5.0), TurnAndRun(0.0, 2.5)]
    assert [stats for _, stats in steps] == [terrains["concrete"], terrains["grass"], terrains["gravel"]]

    start = SpatialUncertaintyMap.from_pose(pose, 0.2, math.radians(2.0))
    by_hand = (
        start.grow(TurnAndRun(-0.3, 2.5), terrains["concrete"])
        .grow(TurnAndRun(0.0, 5.0), terrains["grass"])
        .grow(TurnAndRun(0.0, 2.5), terrains["gravel"])
    )
    through = start
    for step, stats in steps:
        through = through.grow(step, stats)
    np.testing.assert_array_equal(through.polygon.vertices, by_hand.polygon.vertices)
    np.testing.assert_array_equal(through.center, by_hand.center)
    assert through.wedge == by_hand.wedge
    # The split map holds the one-step map's mean position.
    single = start.grow(command, terrains["concrete"])
    assert through.polygon.contains(single.center)[0]
    # grow_through does not split by the most probable run (unsound for runs crossing
    # elsewhere, test_growth_through_meadows_holds_every_true_run_wherever_it_crosses); its
    # map still holds that split's most probable pose.
    helped = grow_through(start, world, command, terrains)
    assert helped.contains(by_hand.most_probable_pose())


def test_grow_through_defaults_are_the_maps() -> None:
    # The world layer writes the map's defaults again (it may not import the uncertainty
    # layer's private constants): here the two are held equal.
    ours = inspect.signature(grow_through).parameters
    theirs = inspect.signature(SpatialUncertaintyMap.grow).parameters
    for name in ("sigmas", "max_vertices"):
        assert ours[name].default == theirs[name].default, name


def test_a_turn_only_command_uses_the_start_meadow(terrains: TerrainTable) -> None:
    steps = commands_for(make_grid_world(1, 2), Pose(7, 2, 0), TurnAndRun(1.0, 0.0), terrains)
    assert steps == [(TurnAndRun(1.0, 0.0), terrains["grass"])]


def test_run_along_a_shared_boundary_goes_to_the_first_meadow() -> None:
    world = make_grid_world(2, 3)
    pieces = split_run(world, (1.0, 5.0), 0.0, 12.0)
    assert [p.meadow_id for p in pieces] == ["cell_0_0", "cell_0_1", "cell_0_2"]
    assert sum(p.distance for p in pieces) == pytest.approx(12.0)


def test_parts_outside_every_meadow_take_the_last_meadow() -> None:
    world = MeadowMap([Meadow("a", box(0, 0, 4, 2), "tile"), Meadow("b", box(6, 0, 10, 2), "grass")])
    # Gap between a and b, and a run past the end of b.
    assert split_run(world, (1, 1), 0.0, 12.0) == [RunPiece(5.0, "tile", "a"), RunPiece(7.0, "grass", "b")]
    # A run starting in the gap takes the first meadow it enters.
    assert split_run(world, (5, 1), 0.0, 3.0) == [RunPiece(3.0, "grass", "b")]
    with pytest.raises(InputError, match=r"^start, heading, distance: expected a run that meets a meadow"):
        split_run(world, (1, 5), 0.0, 3.0)
    with pytest.raises(InputError, match=r"^start: expected a point inside a meadow for a zero-length run"):
        split_run(world, (5, 1), 0.0, 0.0)


def test_piece_distances_add_up_along_random_runs(rng: np.random.Generator) -> None:
    world = make_grid_world(6, 6, cell=3.0, rng=rng, remove=[(2, 2), (3, 3)])
    for _ in range(200):
        start = rng.uniform(0.0, 18.0, 2)
        heading = rng.uniform(-math.pi, math.pi)
        distance = rng.uniform(0.0, 25.0)
        try:
            pieces = split_run(world, start, heading, distance)
        except InputError:
            continue
        assert sum(p.distance for p in pieces) == pytest.approx(distance, abs=1e-9)
        assert all(p.distance >= 0.0 for p in pieces)
        assert all(a.meadow_id != b.meadow_id for a, b in itertools.pairwise(pieces))


def test_split_run_validates_its_arguments() -> None:
    world = make_grid_world(1, 1)
    with pytest.raises(InputError, match=r"distance: expected a non-negative number, got -1\.0"):
        split_run(world, (1, 1), 0.0, -1.0)
    with pytest.raises(InputError, match="heading: expected a finite number, got nan"):
        split_run(world, (1, 1), math.nan, 1.0)
    with pytest.raises(InputError, match="meadow_map: expected a MeadowMap"):
        split_run(None, (1, 1), 0.0, 1.0)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"RunPiece\.distance: expected a non-negative number"):
        RunPiece(-1.0, "tile", "a")


def test_commands_for_needs_every_terrain_in_the_table(terrains: TerrainTable) -> None:
    world = MeadowMap([Meadow("a", box(0, 0, 4, 2), "tile"), Meadow("b", box(4, 0, 8, 2), "sand")])
    with pytest.raises(
        UnknownTerrainError, match="terrain: expected one of concrete, grass, gravel, tile, got 'sand'"
    ):
        commands_for(world, Pose(1, 1, 0), TurnAndRun(0.0, 5.0), terrains)
    with pytest.raises(InputError, match="pose: expected a Pose, got tuple"):
        commands_for(world, (1, 1, 0), TurnAndRun(0.0, 5.0), terrains)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="command: expected a TurnAndRun, got float"):
        commands_for(world, Pose(1, 1, 0), 5.0, terrains)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="uncertainty_map: expected a SpatialUncertaintyMap"):
        grow_through(None, world, TurnAndRun(0.0, 1.0), terrains)  # type: ignore[arg-type]


@pytest.mark.parametrize("distance", [1e-12, 5e-324, 1e-9])
def test_a_run_shorter_than_the_tolerance_is_one_piece_in_its_meadow(distance: float) -> None:
    world = make_grid_world(1, 3, cell=5.0)
    pieces = split_run(world, (2.5, 2.5), 0.0, distance)
    assert [(piece.distance, piece.meadow_id) for piece in pieces] == [(distance, "cell_0_0")]


def _shapely_spans(
    world: MeadowMap, start: tuple[float, float], heading: float, length: float
) -> list[tuple[float, float, int]]:
    """The parts of a run in each meadow by shapely intersections (the reference)."""
    direction = np.array([math.cos(heading), math.sin(heading)])
    origin = np.array(start)
    line = shapely.LineString([origin, origin + length * direction])
    spans = []
    for index, meadow in enumerate(world.meadows):
        coordinates = shapely.get_coordinates(
            shapely.intersection(line, shapely.Polygon(meadow.polygon.vertices))
        )
        if len(coordinates):
            along = (coordinates - origin) @ direction
            lo, hi = max(float(along.min()), 0.0), min(float(along.max()), length)
            if hi - lo > 1e-9:
                spans.append((lo, hi, index))
    return spans


def _tilted_world() -> MeadowMap:
    """Convex meadows with slanted shared edges (no axis-aligned shortcut)."""
    fan = [(0.0, 0.0), (6.0, -1.0), (7.0, 4.0), (2.0, 6.0), (-3.0, 3.0)]
    meadows = [
        Meadow(f"m{i}", ConvexPolygon([(2.0, 2.0), fan[i], fan[(i + 1) % len(fan)]]), "concrete")
        for i in range(len(fan))
    ]
    return MeadowMap(meadows)


@pytest.mark.parametrize("name", ["tilted", "grid_1000", "indoor_corridor", "paper_sidewalk"])
def test_run_clipping_matches_shapely_intersections(name: str) -> None:
    from aura_ums.world._navigator import _run_spans

    if name == "tilted":
        world = _tilted_world()
    elif name == "grid_1000":
        world = make_grid_world(25, 42, cell=5.0, remove=OBSTACLES)
    else:
        world = sample_world(name)
    rng = np.random.default_rng(11)
    lo = np.min([m.polygon.vertices.min(axis=0) for m in world.meadows], axis=0) - 1.0
    hi = np.max([m.polygon.vertices.max(axis=0) for m in world.meadows], axis=0) + 1.0
    compared = 0
    for _ in range(150):
        x, y = rng.uniform(lo, hi)
        heading = float(rng.uniform(-math.pi, math.pi))
        length = float(rng.uniform(0.0, 0.5 * float(np.max(hi - lo))))
        ours = _run_spans(world, float(x), float(y), heading, length)
        reference = _shapely_spans(world, (float(x), float(y)), heading, length)
        assert [i for _, _, i in ours] == [i for _, _, i in reference]
        for (a, b, _), (c, d, _) in zip(ours, reference, strict=True):
            assert a == pytest.approx(c, abs=1e-9)
            assert b == pytest.approx(d, abs=1e-9)
        compared += len(ours)
    assert compared > 50  # the runs do cross meadows


def test_a_run_off_the_map_is_worded_for_the_function_called() -> None:
    """commands_for and grow_through name their own arguments, not split_run's."""
    world = make_grid_world(1, 3)
    far = Pose(50.0, 50.0, 0.0)
    with pytest.raises(
        OutsideMapError, match=r"^pose, command: expected a run that meets a meadow, got one from \(50"
    ):
        commands_for(world, far, TurnAndRun(0.0, 1.0), TerrainTable.default())
    start = SpatialUncertaintyMap.from_pose(far, 0.1, 0.01)
    with pytest.raises(
        OutsideMapError, match=r"^uncertainty_map, command: expected a map within reach of a meadow, got one "
    ):
        grow_through(start, world, TurnAndRun(0.0, 1.0), TerrainTable.default())


# --- growth through meadows: sound for every pose of the map -------------------------


def test_growth_through_meadows_holds_every_true_run_wherever_it_crosses(rng: np.random.Generator) -> None:
    """The true robot cuts its run where *its* straight run crosses a boundary (SimulatedRobot).

    Maps straddling small meadows of mixed terrains (product and sliced, some reaching past
    the world's edge, where a robot that left every meadow moves on the terrain of the one
    it was last in), one to three commands, true motions at the growth's sigmas: every true
    end pose stays inside. Splitting by the most probable pose's run (the paper's
    commands_for) left 28 of 2000 out on two meadows of one terrain: each piece paid the
    fixed inertial loss again; and 7 of 3600 here.
    """
    table = TerrainTable.default()
    outside = total = crossing = 0
    for _ in range(60):
        cell = float(rng.uniform(0.5, 3.0))
        world = make_grid_world(3, 3, cell=cell, rng=rng)
        x, y = rng.uniform(0.2 * cell, 2.8 * cell, 2).tolist()
        centre = Pose(x, y, float(rng.uniform(-math.pi, math.pi)))
        start = SpatialUncertaintyMap.from_pose(
            centre, float(rng.uniform(0.01, 0.3 * cell)), float(rng.uniform(0.0, 0.5))
        )
        if rng.uniform() < 0.3:
            start = start.with_slices(math.radians(2.0))
        sigmas = float(rng.choice([1.0, 3.0]))
        commands = [
            TurnAndRun(float(rng.uniform(-1.5, 1.5)), float(rng.uniform(0.0, 2.0 * cell)))
            for _ in range(int(rng.integers(1, 4)))
        ]
        grown = start
        try:
            for command in commands:
                crossing += len(meadows_in_reach(world, grown, command, table, sigmas)) > 1
                grown = grow_through(grown, world, command, table, sigmas=sigmas)
        except OutsideMapError:
            continue  # grown beyond reach of every meadow: refused, not bounded
        for pose in start.sample_poses(40, rng):
            truth = Pose(*pose.tolist())
            if world.meadow_at(truth.x, truth.y) is None:
                continue  # a robot starts in a meadow
            robot = SimulatedRobot(world, table, truth, rng, truncate=sigmas)
            for command in commands:
                truth = robot.execute(command)
            outside += not grown.contains(truth)
            total += 1
    assert crossing > 30  # most maps do reach other meadows
    assert total > 2000
    assert outside == 0, f"{outside} of {total} true poses outside"


def test_growth_through_two_meadows_of_one_terrain_pays_the_inertial_loss_once() -> None:
    gravel = TerrainTable.default()["gravel"]
    world = MeadowMap(
        [
            Meadow("A", ConvexPolygon([(0, 0), (1, 0), (1, 2), (0, 2)]), "gravel"),
            Meadow("B", ConvexPolygon([(1, 0), (6, 0), (6, 2), (1, 2)]), "gravel"),
        ],
        [],
    )
    start = SpatialUncertaintyMap.from_pose(Pose(0.5, 1.0, 0.0), 0.8, 0.0)
    grown = grow_through(start, world, TurnAndRun(0.0, 1.0), TerrainTable.default())
    # A pose of the map's east edge runs in B alone: one inertial loss, at most 3 sigmas kept.
    east = float(start.polygon.vertices[:, 0].max())
    longest = (
        1.0 * (1.0 - gravel.translation_loss + 3.0 * gravel.translation_sd) - gravel.translation_inertial_loss
    )
    assert grown.contains(Pose(east + longest, 1.0, 0.0))
    # The same terrain on both sides: the outer terrain is that terrain, but for the loss paid once.
    assert outer_terrain([gravel, gravel], 1, TurnAndRun(0.0, 1.0), 3.0).drift == gravel.drift


@settings(max_examples=200, deadline=None)
@given(
    st.lists(st.sampled_from(sorted(TerrainTable.default())), min_size=1, max_size=4),
    st.integers(1, 5),
    st.floats(-3.0, 3.0),
    st.floats(0.0, 20.0),
    st.sampled_from([0.5, 1.0, 3.0]),
)
def test_the_outer_terrain_bounds_every_terrain_and_every_split(
    names: list[str], pieces: int, turn: float, run: float, sigmas: float
) -> None:
    table = TerrainTable.default()
    terrains = [table[name] for name in names]
    command = TurnAndRun(turn, run)
    outer = motion_bounds(outer_terrain(terrains, pieces, command, sigmas), turn, run, sigmas)
    for terrain in terrains:
        one = motion_bounds(terrain, turn, run, sigmas)
        assert outer.turn_min <= one.turn_min + 1e-12
        assert outer.turn_max >= one.turn_max - 1e-12
        assert outer.run_max >= one.run_max - 1e-12  # one piece: the longest run
        assert outer.skitter_radius >= one.skitter_radius
        assert outer.drift_max >= one.drift_max or outer.run_max == 0.0
    # The shortest: every piece pays the largest inertial loss.
    worst = min(1.0 - t.translation_loss - sigmas * t.translation_sd for t in terrains)
    largest = max(t.translation_inertial_loss for t in terrains)
    assert outer.run_min <= max(0.0, run * worst - pieces * largest) + 1e-12


def _rect(name: str, x0: float, y0: float, x1: float, y1: float, terrain: str) -> Meadow:
    return Meadow(name, ConvexPolygon([(x0, y0), (x1, y0), (x1, y1), (x0, y1)]), terrain)


def test_the_first_metres_in_the_start_meadow_pay_no_inertial_loss_of_their_own() -> None:
    """One true run of 3 m on grass keeps all 3 m at +3 sigmas (1.02 kept, less 0.03 m, clipped).

    Grown as 0.5 m on grass with its inertial loss and the rest on the outer terrain, the
    map fell short of it by the loss: 4 of 2000 SimulatedRobot runs outside.
    """
    table = TerrainTable.default()
    world = MeadowMap([_rect("A", 0, 0, 10, 10, "grass"), _rect("B", 10, 0, 20, 10, "grass")], [])
    pose = Pose(9.5, 5.0, math.pi / 2)
    start = SpatialUncertaintyMap.from_pose(pose, 0.0, 1.0)
    grown = grow_through(start, world, TurnAndRun(0.0, 3.0), table)
    assert [m.id for m in meadows_in_reach(world, start, TurnAndRun(0.0, 3.0), table, 3.0)] == ["A", "B"]
    assert grown.contains(Pose(9.5, 8.0, math.pi / 2))
    outside = sum(
        not grown.contains(
            SimulatedRobot(world, table, pose, np.random.default_rng(seed), truncate=3.0).execute(
                TurnAndRun(0.0, 3.0)
            )
        )
        for seed in range(300)
    )
    assert outside == 0


def _east_from_nine(run: float) -> tuple[MeadowMap, TerrainTable, SpatialUncertaintyMap, Pose]:
    """Meadows A (x 0 to 10 m) and B (10 to 20 m) losing 0.5 m per piece, nothing else; a point map
    at (9, 2) facing east, grown by ``run`` metres, and a true robot's end pose."""
    table = TerrainTable({"t": TerrainStats(0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)})
    world = MeadowMap([_rect("A", 0, 0, 10, 4, "t"), _rect("B", 10, 0, 20, 4, "t")], [])
    pose = Pose(9.0, 2.0, 0.0)
    command = TurnAndRun(0.0, run)
    grown = grow_through(SpatialUncertaintyMap.from_pose(pose, 0.0, 0.0), world, command, table)
    truth = SimulatedRobot(world, table, pose, np.random.default_rng(0), truncate=3.0).execute(command)
    return world, table, grown, truth


def test_a_rest_too_short_to_pay_the_inertial_losses_leaves_them_to_the_first_metres() -> None:
    """A true piece cut just past the first part loses its whole inertial loss there.

    The run of 1.05 m crosses at 1 m: the first part is 1 m in A, the rest 0.05 m, too short
    to lose the 0.5 m a piece loses. The rest's growth clipped its shortest run at 0, and the
    map held only 10.0 to 10.05 m, while the robot's 1 m piece in A keeps 0.5 m and its
    0.05 m piece in B nothing: it stops at 9.5 m.
    """
    _, _, grown, truth = _east_from_nine(1.05)
    assert truth.x == pytest.approx(9.5)
    assert grown.contains(truth)
    # The least run: the first metre less A's own loss, the rest nothing (not the 1 m of the first part).
    assert grown.polygon.vertices[:, 0].min() == pytest.approx(9.5)


def test_small_maps_whose_runs_end_just_past_a_boundary_hold_every_true_run() -> None:
    """The same on the built-in terrains, for maps of up to 2 cm: 11 of 36,000 runs were outside."""
    rng = np.random.default_rng(3)
    table = TerrainTable.default()
    names = sorted(table)
    outside = total = 0
    for _ in range(200):
        first, second = (str(name) for name in rng.choice(names, 2))
        world = MeadowMap([_rect("A", 0, -5, 10, 5, first), _rect("B", 10, -5, 20, 5, second)], [])
        radius = float(rng.uniform(0.0, 0.02))
        x = float(rng.uniform(7.0, 9.5))
        command = TurnAndRun(0.0, 10.0 - x + radius + float(rng.uniform(0.0, 0.2)))
        start = SpatialUncertaintyMap.from_pose(Pose(x, 0.0, 0.0), radius, float(rng.uniform(0.0, 0.01)))
        grown = grow_through(start, world, command, table)
        for pose in start.sample_poses(30, rng):
            truth = SimulatedRobot(world, table, Pose(*pose.tolist()), rng, truncate=3.0).execute(command)
            outside += not grown.contains(truth)
            total += 1
    assert outside == 0, f"{outside} of {total} true poses outside"


def test_a_run_across_boundaries_loses_one_inertial_loss_per_meadow() -> None:
    """Crossing from A into B, a true run is two pieces: two losses, not the 2 n + 1 of a run along an edge.

    From 9 m, 3 m east: 0.5 m kept of the 1 m in A, 1.5 m of the 2 m in B, so 11 m. The
    map's least run is the first metre less A's loss and the other 2 m less two losses
    (A's counted twice: the rest does not know where A's piece ends), 1.5 m, where five
    losses would leave nothing of the rest. A run along the edge the two meadows share
    (heading north on x = 10) may alternate between them: five losses.
    """
    world, table, grown, truth = _east_from_nine(3.0)
    assert truth.x == pytest.approx(11.0)
    assert grown.polygon.vertices[:, 0].min() == pytest.approx(10.5)
    assert grown.contains(truth)
    along = SpatialUncertaintyMap.from_pose(Pose(10.0, 0.5, math.pi / 2), 0.0, 0.0)
    north = grow_through(along, world, TurnAndRun(0.0, 3.0), table)
    assert north.polygon.vertices[:, 1].min() == pytest.approx(1.0)  # 3 m less five losses: 0.5 m


def _runs_outside(
    grown: SpatialUncertaintyMap,
    world: MeadowMap,
    table: TerrainTable,
    pose: Pose,
    command: TurnAndRun,
    rng: np.random.Generator,
    runs: int,
) -> int:
    """How many of ``runs`` true robots from ``pose`` (at 3 sigmas) end outside ``grown``."""
    return sum(
        not grown.contains(SimulatedRobot(world, table, pose, rng, truncate=3.0).execute(command))
        for _ in range(runs)
    )


def test_a_first_piece_that_loses_its_length_leaves_the_drift_of_the_next_meadow_all_of_the_run() -> None:
    """The first 0.3 m are in A (no drift, 0.5 m lost per piece), the rest on ice (drift 0.3 rad/m).

    The first part grew a straight 0.3 m, then the rest's arc. The robot's piece in A loses
    all 0.3 m, so its whole arc on the ice starts 0.3 m further back: 204 of 2000 ended
    outside, up to 0.12 m (helper-54's repro_prefix_drift.py).
    """
    table = TerrainTable(
        {
            "slab": TerrainStats(0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
            "ice": TerrainStats(0.0, 0.0, 0.0, 0.3, 0.0, 0.0, 0.0, 0.0),
        }
    )
    world = MeadowMap([_rect("A", 0, -5, 1, 5, "slab"), _rect("B", 1, -5, 10, 5, "ice")], [])
    pose = Pose(0.7, 0.0, 0.0)
    command = TurnAndRun(0.0, 3.0)
    grown = grow_through(SpatialUncertaintyMap.from_pose(pose, 0.0, 0.0), world, command, table)
    assert _runs_outside(grown, world, table, pose, command, np.random.default_rng(1), 500) == 0


def test_a_start_within_the_tolerance_of_a_meadow_turns_on_its_terrain() -> None:
    """5e-10 m outside A, the robot stands in A (MeadowMap.meadow_at's tolerance) and skitters on gravel.

    The growth took only the meadows the map exactly meets (B), so the bog within A's skitter
    was out of reach: 347 of 1000 runs outside, up to 0.98 m (repro_standing_tolerance.py).
    """
    table = TerrainTable(
        {
            "gravel": TerrainStats(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.2, 0.0),
            "slab": TerrainStats(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
            "bog": TerrainStats(0.0, 1.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0),
        }
    )
    world = MeadowMap(
        [
            _rect("A", 0, -1, 1, 1, "gravel"),
            _rect("B", 1, -0.05, 3, 1, "slab"),
            _rect("C", 1, -1, 3, -0.05, "bog"),
        ],
        [],
    )
    pose = Pose(1.0 + 5e-10, 0.0, -0.5)
    command = TurnAndRun(0.5, 1.5)
    standing = world.meadow_at(pose.x, pose.y)
    assert standing is not None
    assert standing.id == "A"
    start = SpatialUncertaintyMap.from_pose(pose, 0.0, 0.0)
    assert [m.id for m in meadows_in_reach(world, start, command, table, 3.0)] == ["A", "B", "C"]
    grown = grow_through(start, world, command, table)
    assert _runs_outside(grown, world, table, pose, command, np.random.default_rng(3), 300) == 0


def test_meadows_that_overlap_within_the_tolerance_may_cut_a_run_into_more_pieces() -> None:
    """B, first in map order, bulges 1.5e-7 m into A (7.5e-7 m^2, accepted): a run north along it is A, B, A.

    Three pieces of 1 m loss each, where the growth counted one (it took A alone): the
    robot ran 5.25 m of 8, the map held only 7 m (repro_overlap_bulge.py).
    """
    bulge = 1.5e-7
    b = Meadow("B", ConvexPolygon([(5, 0), (10, 0), (10, 10), (5, 10), (5 - bulge, 5)]), "t")
    world = MeadowMap([b, _rect("A", 0, 0, 5, 10, "t")], [])
    table = TerrainTable({"t": TerrainStats(0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)})
    pose = Pose(5 - 1e-7, 1.0, math.pi / 2 + 1e-8)
    command = TurnAndRun(0.0, 8.0)
    assert [p.meadow_id for p in split_run(world, (pose.x, pose.y), pose.heading, 8.0)] == ["A", "B", "A"]
    grown = grow_through(SpatialUncertaintyMap.from_pose(pose, 0.0, 0.0), world, command, table)
    truth = SimulatedRobot(world, table, pose, np.random.default_rng(47), truncate=3.0).execute(command)
    assert truth.y == pytest.approx(6.25)
    assert grown.contains(truth)


def test_a_run_along_a_shared_boundary_may_cross_a_meadow_twice() -> None:
    """A small meadow earlier in map order on a long one's edge: the run along it is A, B, A."""
    table = TerrainTable({"t": TerrainStats(0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)})  # 0.5 m per piece
    world = MeadowMap([_rect("B", 3, 2, 5, 4, "t"), _rect("A", 0, 0, 12, 2, "t")], [])
    pose = Pose(0.5, 2.0, 0.0)
    assert [p.meadow_id for p in split_run(world, (0.5, 2.0), 0.0, 10.0)] == ["A", "B", "A"]
    grown = grow_through(SpatialUncertaintyMap.from_pose(pose, 0.0, 0.0), world, TurnAndRun(0.0, 10.0), table)
    truth = SimulatedRobot(world, table, pose, np.random.default_rng(0), truncate=3.0).execute(
        TurnAndRun(0.0, 10.0)
    )
    assert truth.x == pytest.approx(9.0)  # three inertial losses
    assert grown.contains(truth)


def test_a_map_off_every_meadow_reaches_as_far_as_its_skitter() -> None:
    """40 m off the map, a turn of 3 pi skitters up to 94 m: into two meadows, two inertial losses."""
    table = TerrainTable({"t": TerrainStats(0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 10.0, 0.0)})
    world = MeadowMap(
        [
            _rect("S", 0, 0, 2, 2, "t"),
            _rect("M1", -119, 26, -115, 48, "t"),
            _rect("M2", -115, 26, -111, 48, "t"),
        ],
        [],
    )
    away = SpatialUncertaintyMap.from_pose(Pose(-39.0, 1.0, math.pi), 0.0, 0.0)
    spin = TurnAndRun(3 * math.pi, 20.0)
    assert [m.id for m in meadows_in_reach(world, away, spin, table, 3.0)] == ["S", "M1", "M2"]
    grown = grow_through(away, world, spin, table)
    start = Pose(1.0, 1.0, math.pi)
    outside = 0
    for seed in range(300):
        robot = SimulatedRobot(world, table, start, np.random.default_rng(seed), truncate=3.0)
        robot.execute(TurnAndRun(0.0, 41.0))  # 40 m: 1 m of it lost
        outside += not grown.contains(robot.execute(spin))
    assert outside == 0


def test_a_route_of_one_waypoint_names_one_meadow() -> None:
    # no leg, one id: Route([p], []) was refused as "expected 1 ids (one per leg)"
    assert Route([(1.0, 2.0)], ["a"]).meadow_ids == ("a",)
    with pytest.raises(
        InputError, match=r"meadow_ids: expected 1 id \(a route of one waypoint, no leg, .*got 0"
    ):
        Route([(1.0, 2.0)], [])
    with pytest.raises(InputError, match=r"meadow_ids: expected 1 id \(a route of one waypoint.*got 2"):
        Route([(1.0, 2.0)], ["a", "b"])


@pytest.mark.parametrize(
    ("arguments", "match"),
    [
        ((1.0, None, "a"), "RunPiece.terrain: expected a non-empty string, got None"),
        ((1.0, "grass", ["a"]), r"RunPiece.meadow_id: expected a non-empty string, got \['a'\]"),
        ((1.0, "", "a"), "RunPiece.terrain: expected a non-empty string, got ''"),
    ],
)
def test_a_run_piece_names_a_terrain_and_a_meadow(arguments: tuple[object, ...], match: str) -> None:
    with pytest.raises(InputError, match=match):
        RunPiece(*arguments)  # type: ignore[arg-type]


_TABLE = TerrainTable.default()
_CMD = TurnAndRun(0.1, 1.0)
_TILE = _TABLE["tile"]


@pytest.mark.parametrize(
    ("arguments", "match"),
    [
        (([_TILE], 1, _CMD, 0.0), r"sigmas: expected a number in \[0\.1, 100\], got 0\.0"),
        (([_TILE], 1, _CMD, math.nan), "sigmas: expected a finite number, got nan"),
        (([], 1, _CMD, 3.0), "terrains: expected at least one TerrainStats, got none"),
        ((None, 1, _CMD, 3.0), "terrains: expected a sequence of TerrainStats, got NoneType"),
        (([None], 1, _CMD, 3.0), r"terrains\[0\]: expected a TerrainStats, got NoneType"),
        (([_TILE], math.nan, _CMD, 3.0), "pieces: expected an integer >= 1, got nan"),
        (([_TILE], None, _CMD, 3.0), "pieces: expected an integer >= 1, got None"),
        (([_TILE], 0, _CMD, 3.0), "pieces: expected an integer >= 1, got 0"),
        (([_TILE], 1, None, 3.0), "command: expected a TurnAndRun, got NoneType"),
    ],
)
def test_outer_terrain_refuses_bad_arguments(arguments: tuple[object, ...], match: str) -> None:
    # 0.0 sigmas divided by zero, [] took min() of nothing, None an AttributeError, nan pieces passed
    with pytest.raises(InputError, match=match):
        outer_terrain(*arguments)  # type: ignore[arg-type]


def test_meadows_in_reach_refuses_bad_arguments() -> None:
    world = make_grid_world(1, 2)
    start = SpatialUncertaintyMap.from_pose(Pose(2.5, 2.5, 0.0), 0.1, 0.01)
    nothing: Any = None
    with pytest.raises(InputError, match="sigmas: expected a finite number, got nan"):
        meadows_in_reach(world, start, _CMD, _TABLE, math.nan)
    with pytest.raises(InputError, match="sigmas: expected a finite number, got None"):
        meadows_in_reach(world, start, _CMD, _TABLE, nothing)
    with pytest.raises(InputError, match="meadow_map: expected a MeadowMap, got NoneType"):
        meadows_in_reach(nothing, start, _CMD, _TABLE, 3.0)
    with pytest.raises(InputError, match="uncertainty_map: expected a SpatialUncertaintyMap, got NoneType"):
        meadows_in_reach(world, nothing, _CMD, _TABLE, 3.0)
    with pytest.raises(InputError, match="command: expected a TurnAndRun, got NoneType"):
        meadows_in_reach(world, start, nothing, _TABLE, 3.0)
    with pytest.raises(InputError, match="table: expected a TerrainTable, got NoneType"):
        meadows_in_reach(world, start, _CMD, nothing, 3.0)
