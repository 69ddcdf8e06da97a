from __future__ import annotations

import math
from importlib import resources

import numpy as np
import pytest

from aura_ums import (
    FOOT,
    GroundLineLandmark,
    InputError,
    LandmarkClass,
    PerceptualStrategy,
    PointLandmark,
    TerrainTable,
    VerticalLineLandmark,
)
from aura_ums.world import MeadowMap, make_grid_world, plan_route, sample_world
from aura_ums.world._samples import SAMPLE_WORLDS


@pytest.mark.parametrize("name", SAMPLE_WORLDS)
def test_sample_worlds_load_and_are_consistent(name: str) -> None:
    world = sample_world(name)
    assert world.terrain_table == TerrainTable.default()
    ids = {record.id for record in world.landmarks}
    referenced = {i for meadow in world.meadows for i in meadow.landmark_ids}
    assert referenced <= ids  # every id a meadow lists exists
    assert referenced == ids  # and every landmark is visible from somewhere
    assert all(meadow.terrain in TerrainTable.default() for meadow in world.meadows)
    # The meadows are connected: every one reachable from the first.
    start = world.meadows[0].polygon.centroid
    for meadow in world.meadows[1:]:
        route = plan_route(world, start, meadow.polygon.centroid)
        assert route.meadow_ids[-1] == meadow.id


@pytest.mark.parametrize("name", SAMPLE_WORLDS)
def test_sample_files_are_package_data(name: str) -> None:
    resource = resources.files("aura_ums.world").joinpath("data", f"{name}.geojson")
    assert resource.is_file()
    with resources.as_file(resource) as path:
        assert MeadowMap.from_geojson(path) == sample_world(name)


@pytest.mark.parametrize("name", SAMPLE_WORLDS)
def test_perceptual_strategies_suit_the_landmark_classes(name: str) -> None:
    for record in sample_world(name).landmarks:
        assert record.activation_range > 0.0
        # On the evaluation functions' scale: length x contrast for lines, Moravec response
        # for corners; a threshold that any detection passes would confirm clutter.
        assert record.recognition_threshold >= 100.0
        if record.landmark_class is LandmarkClass.VERTICAL_LINE:
            assert record.strategy is PerceptualStrategy.LINE_FINDER
            assert record.parameters["orientation"] == pytest.approx(math.pi / 2)
        elif record.landmark_class is LandmarkClass.POINT:
            assert record.strategy is PerceptualStrategy.INTEREST_OPERATOR
        else:
            assert record.strategy is PerceptualStrategy.LINE_FINDER


def test_paper_sidewalk_matches_the_experiment() -> None:
    world = sample_world("paper_sidewalk")
    walk = plan_route(world, (0.0, 0.0), (40 * FOOT, 0.0))
    assert walk.length == pytest.approx(12.192)
    assert {world.meadow(i).terrain for i in walk.meadow_ids} == {"concrete"}
    pole = world.landmark("telephone_pole_12").landmark
    lamppost = world.landmark("lamppost_107").landmark
    assert isinstance(pole, VerticalLineLandmark)
    assert isinstance(lamppost, VerticalLineLandmark)
    assert (pole.symbol, lamppost.symbol) == ("telephone pole", "lamppost")
    assert pole.y > 1.0 > -1.0 > lamppost.y  # beside the walk, on either side
    corner = world.landmark("east_engineering_corner").landmark
    edge = world.landmark("east_engineering_edge").landmark
    assert isinstance(corner, PointLandmark)  # Class II, with a Class I variant
    assert isinstance(edge, VerticalLineLandmark)
    assert (corner.x, corner.y) == (edge.x, edge.y)
    assert edge.z_top == corner.z
    for side in ("sidewalk_north_edge", "sidewalk_south_edge"):
        line = world.landmark(side).landmark
        assert isinstance(line, GroundLineLandmark)
        assert line.length >= 40 * FOOT
    assert {world.meadow(i).terrain for i in ("grass_north_west", "grass_south")} == {"grass"}
    assert len(world.neighbours("sidewalk_middle")) == 5  # walk on both sides, two lawns north, grass south
    # Every meadow of the walk sees an edge of it.
    for ident in walk.meadow_ids:
        assert "sidewalk_north_edge" in world.meadow(ident).landmark_ids


def test_indoor_corridor_rooms_open_through_doorways() -> None:
    world = sample_world("indoor_corridor")
    x0, _, x1, _ = world.bounds
    corridor = [world.meadow(f"corridor_{part}") for part in ("west", "middle", "east")]
    assert sum(m.polygon.bounds[2] - m.polygon.bounds[0] for m in corridor) == pytest.approx(30.0)
    assert {m.terrain for m in corridor} == {"tile"}
    assert world.meadow("lobby").terrain == "concrete"
    assert x1 - x0 >= 30.0
    for room in ("101", "102", "103"):
        assert [m.id for m in world.neighbours(f"room_{room}")] == [f"door_{room}"]
        for side in ("west", "east"):
            jamb = world.landmark(f"door_{room}_{side}_edge").landmark
            assert isinstance(jamb, VerticalLineLandmark)
            assert (jamb.z_bottom, jamb.z_top) == (0.0, 2.1)
        width = np.hypot(*np.subtract(*world.portal(f"door_{room}", f"room_{room}")))
        assert width == pytest.approx(1.0)
    route = plan_route(world, (5.0, 5.0), (24.0, -3.0))  # room 101 to room 103
    assert route.meadow_ids[:2] == ("room_101", "door_101")
    assert route.meadow_ids[-2:] == ("door_103", "room_103")
    assert world.landmarks_visible_from("lobby") == ()


def test_unknown_sample_is_an_input_error() -> None:
    with pytest.raises(InputError, match="name: expected one of indoor_corridor, paper_sidewalk, got 'moon'"):
        sample_world("moon")


def test_grid_world_layout() -> None:
    world = make_grid_world(3, 4, cell=2.0, remove=[(1, 1)])
    assert len(world) == 11
    assert world.meadow("cell_2_3").polygon.bounds == (6.0, 4.0, 8.0, 6.0)
    assert [world.meadow(f"cell_0_{c}").terrain for c in range(4)] == ["concrete", "grass", "gravel", "tile"]
    assert world.meadow("cell_1_0").terrain == "grass"
    assert world.meadow("cell_1_2").landmark_ids == ("pole_2_2",)
    assert [m.id for m in world.neighbours("cell_0_1")] == ["cell_0_0", "cell_0_2"]
    pole = world.landmark("pole_2_2")
    assert isinstance(pole.landmark, VerticalLineLandmark)
    assert (pole.landmark.x, pole.landmark.y) == (4.0, 4.0)


def test_grid_world_random_terrains_are_reproducible() -> None:
    first = make_grid_world(4, 4, rng=np.random.default_rng(3))
    again = make_grid_world(4, 4, rng=np.random.default_rng(3))
    assert first == again
    assert len({m.terrain for m in first.meadows}) > 1


@pytest.mark.parametrize(
    ("args", "kwargs", "message"),
    [
        ((0, 3), {}, "rows: expected an integer >= 1, got 0"),
        ((2, 2.0), {}, "cols: expected an integer >= 1, got 2.0"),
        ((2, 2), {"cell": 0.0}, "cell: expected a positive number, got 0.0"),
        ((1, 1), {"remove": [(0, 0)]}, "remove: expected at least one cell left"),
    ],
)
def test_grid_world_validates(args: tuple[object, ...], kwargs: dict[str, object], message: str) -> None:
    with pytest.raises(InputError, match=message):
        make_grid_world(*args, **kwargs)  # type: ignore[arg-type]


def test_a_grid_world_is_bounded_in_size() -> None:
    # 10**12 cells never ended (1000 x 1000 ran past 20 s)
    with pytest.raises(
        InputError,
        match=r"rows, cols: expected at most 10000 cells .*got 1000000000000 x 1 = 1000000000000 cells",
    ):
        make_grid_world(10**12, 1)


@pytest.mark.parametrize(
    ("remove", "match"),
    [
        ([(5, 5)], r"remove\[0\]: expected a \(row, col\) cell of the 1 x 2 grid, got \(5, 5\)"),
        ([(0, -1)], r"remove\[0\]: expected a \(row, col\) cell of the 1 x 2 grid, got \(0, -1\)"),
        ([None], r"remove\[0\]: expected a \(row, col\) cell of the 1 x 2 grid, got None"),
        ([(0, 0), (0, 1, 2)], r"remove\[1\]: expected a \(row, col\) cell .*, got \(0, 1, 2\)"),
        ([(0.5, 0)], r"remove\[0\]: expected a \(row, col\) cell .*, got \(0\.5, 0\)"),
    ],
)
def test_a_removed_cell_must_be_a_cell_of_the_grid(remove: list[object], match: str) -> None:
    # (5, 5) was ignored without a word, None a TypeError
    with pytest.raises(InputError, match=match):
        make_grid_world(1, 2, remove=remove)  # type: ignore[arg-type]
