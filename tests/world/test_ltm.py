from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
import pytest

from aura_ums import (
    ConvexPolygon,
    GroundLineLandmark,
    InputError,
    LandmarkClass,
    PerceptualStrategy,
    PointLandmark,
    TerrainTable,
    UnknownTerrainError,
    VerticalLineLandmark,
    expecter,
    world,
)
from aura_ums.world import LandmarkRecord, Meadow, MeadowMap, make_grid_world

LINE = PerceptualStrategy.LINE_FINDER


def box(x0: float, y0: float, x1: float, y1: float) -> ConvexPolygon:
    return ConvexPolygon([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])


def pole(ident: str = "lamppost_107", x: float = 1.0, y: float = 2.0) -> VerticalLineLandmark:
    return VerticalLineLandmark(ident, x, y, 0.0, 4.5, symbol="lamppost")


def record(ident: str = "lamppost_107", **overrides: object) -> LandmarkRecord:
    values: dict[str, object] = {
        "landmark": pole(ident),
        "strategy": LINE,
        "parameters": {"orientation": math.pi / 2},
        "activation_range": 20.0,
        "recognition_threshold": 0.6,
    }
    values.update(overrides)
    return LandmarkRecord(**values)  # type: ignore[arg-type]


# --- LandmarkRecord ----------------------------------------------------------------------------


def test_record_exposes_what_ltm_holds_about_a_landmark() -> None:
    rec = record(parameters={"orientation": math.pi / 2, "tolerance": 0.1, "min_length": 40})
    assert (rec.id, rec.symbol, rec.landmark_class) == (
        "lamppost_107",
        "lamppost",
        LandmarkClass.VERTICAL_LINE,
    )
    assert rec.strategy is LINE
    assert rec.confirm_frames == 3
    assert rec.parameters == {"orientation": math.pi / 2, "tolerance": 0.1, "min_length": 40.0}
    assert isinstance(rec.parameters["min_length"], float)


def test_record_parameters_are_a_read_only_copy() -> None:
    given = {"tolerance": 0.1}
    rec = record(parameters=given)
    given["tolerance"] = 9.0
    assert rec.parameters["tolerance"] == 0.1
    with pytest.raises(TypeError, match="does not support item assignment"):
        rec.parameters["tolerance"] = 1.0  # type: ignore[index]
    with pytest.raises(dataclasses.FrozenInstanceError, match="cannot assign"):
        rec.activation_range = 1.0  # type: ignore[misc]


def test_record_class_follows_the_landmark_type() -> None:
    point = record(
        landmark=PointLandmark("corner", 0.0, 0.0, 7.0),
        strategy=PerceptualStrategy.INTEREST_OPERATOR,
        parameters={},
    )
    line = record(landmark=GroundLineLandmark("edge", (0, 0), (5, 0)))
    assert point.landmark_class is LandmarkClass.POINT
    assert line.landmark_class is LandmarkClass.GROUND_LINE


def test_records_compare_and_hash_by_value() -> None:
    assert record() == record()
    assert hash(record()) == hash(record())
    assert record() != record(confirm_frames=4)
    assert len({record(), record()}) == 1


_FRAMES = r"lamppost_107.confirm_frames: expected an integer in \[1, 10000\], got"
_ACTIVATION = r"lamppost_107.activation_range: expected a number in \(0, 10000\] m"


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        (
            {"landmark": "pole"},
            "landmark: expected a VerticalLineLandmark, PointLandmark or GroundLineLandmark",
        ),
        ({"strategy": "line_finder"}, "lamppost_107.strategy: expected a PerceptualStrategy"),
        ({"parameters": [1.0]}, "lamppost_107.parameters: expected a mapping"),
        (
            {"parameters": {"tolerance": "wide"}},
            "lamppost_107.parameters.tolerance: expected a finite number",
        ),
        (
            {"parameters": {"tolerance": math.nan}},
            "lamppost_107.parameters.tolerance: expected a finite number",
        ),
        ({"parameters": {"": 1.0}}, "lamppost_107.parameters key: expected a non-empty string"),
        ({"activation_range": 0.0}, _ACTIVATION + r", got 0.0"),
        ({"activation_range": 1e300}, _ACTIVATION + r", got 1e\+300"),
        ({"activation_range": math.inf}, "lamppost_107.activation_range: expected a finite number"),
        ({"recognition_threshold": -0.1}, "lamppost_107.recognition_threshold: expected a non-negative"),
        ({"confirm_frames": 0}, _FRAMES + r" 0"),
        ({"confirm_frames": 10**9}, _FRAMES + r" 1000000000"),
        ({"confirm_frames": 2.0}, _FRAMES + r" 2.0"),
        ({"confirm_frames": True}, _FRAMES + r" True"),
        # Refused where the record is made (a map file's landmark: naming the file), not when
        # a run builds the landmark's schema.
        (
            {"strategy": PerceptualStrategy.INTEREST_OPERATOR, "parameters": {}},
            "lamppost_107.strategy: expected line_finder, region_segmenter for a Class I landmark, got "
            "interest_operator",
        ),
        (
            {"landmark": PointLandmark("corner", 12.0, 2.0, 3.0), "parameters": {}},
            "corner.strategy: expected interest_operator for a Class II landmark, got line_finder",
        ),
        (
            {
                "landmark": GroundLineLandmark("edge", (0.0, -1.0), (20.0, -1.0)),
                "strategy": PerceptualStrategy.REGION_SEGMENTER,
                "parameters": {},
            },
            "edge.strategy: expected line_finder for a Class III landmark, got region_segmenter",
        ),
        (
            {"parameters": {"orientaton": 1.0}},
            "lamppost_107.parameters: expected names among orientation, tolerance, min_length, "
            "min_gradient, min_contrast, smoothing, buckets, got 'orientaton'",
        ),
        (
            {"strategy": PerceptualStrategy.REGION_SEGMENTER, "parameters": {"window": 5.0}},
            "lamppost_107.parameters: expected names among threshold, min_area, min_aspect, got 'window'",
        ),
    ],
)
def test_record_validates_on_construction(overrides: dict[str, Any], message: str) -> None:
    with pytest.raises(InputError, match=f"^{message}"):
        record(**overrides)


@pytest.mark.parametrize(
    ("landmark", "points", "expected"),
    [
        (VerticalLineLandmark("p", 1.0, 1.0, 0.0, 3.0), [(4.0, 5.0), (1.0, 1.0)], [5.0, 0.0]),
        (PointLandmark("c", 0.0, 0.0, 7.0), [(3.0, 4.0)], [5.0]),
        (GroundLineLandmark("e", (0, 0), (10, 0)), [(5, -2), (-3, 4), (14, 3)], [2.0, 5.0, 5.0]),
    ],
)
def test_record_distance_to_points(
    landmark: VerticalLineLandmark | PointLandmark | GroundLineLandmark,
    points: list[tuple[float, float]],
    expected: list[float],
) -> None:
    rec = LandmarkRecord(landmark, PerceptualStrategy.for_class(landmark.landmark_class)[0], {}, 10.0, 0.5)
    np.testing.assert_allclose(rec.distance(points), expected)


# --- Meadow -----------------------------------------------------------------------------------


def test_meadow_stores_landmark_ids_as_a_tuple() -> None:
    meadow = Meadow("m", box(0, 0, 1, 1), "tile", ["a", "b"])  # type: ignore[arg-type]
    assert meadow.landmark_ids == ("a", "b")
    assert hash(meadow) == hash(Meadow("m", box(0, 0, 1, 1), "tile", ("a", "b")))
    assert meadow == Meadow("m", box(0, 0, 1, 1), "tile", ("a", "b"))
    assert Meadow("m", box(0, 0, 1, 1), "tile").landmark_ids == ()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("", box(0, 0, 1, 1), "tile"), "Meadow.id: expected a non-empty string"),
        (("m", [(0, 0), (1, 0), (0, 1)], "tile"), "m.polygon: expected a ConvexPolygon, got list"),
        (("m", ConvexPolygon([(0, 0), (1, 1)]), "tile"), "m.polygon: expected a polygon of positive area"),
        (("m", box(0, 0, 1, 1), ""), "m.terrain: expected a non-empty string"),
        (("m", box(0, 0, 1, 1), "tile", "pole"), "m.landmark_ids: expected a sequence of ids, got 'pole'"),
        (("m", box(0, 0, 1, 1), "tile", ("a", "")), r"m.landmark_ids\[1\]: expected a non-empty string"),
        (("m", box(0, 0, 1, 1), "tile", ("a", "a")), r"m.landmark_ids\[1\]: expected each id once"),
    ],
)
def test_meadow_validates_on_construction(args: tuple[object, ...], message: str) -> None:
    with pytest.raises(InputError, match=message):
        Meadow(*args)  # type: ignore[arg-type]


# --- MeadowMap: validation ----------------------------------------------------------------------


def test_map_refuses_duplicate_and_unknown_ids() -> None:
    a = Meadow("a", box(0, 0, 1, 1), "tile", ("lamppost_107",))
    with pytest.raises(InputError, match="'a' id: expected a unique meadow id"):
        MeadowMap([a, Meadow("a", box(1, 0, 2, 1), "tile")], [record()])
    with pytest.raises(InputError, match="'lamppost_107' id: expected a unique id"):
        MeadowMap([a], [record(), record()])
    with pytest.raises(InputError, match="'a' id: expected a unique id"):
        MeadowMap([a], [record(), record("a")])
    with pytest.raises(InputError, match=r"'a' landmark_ids\[0\]: expected the id of a landmark of the map"):
        MeadowMap([a])


def test_map_checks_terrains_only_against_a_given_table() -> None:
    sand = Meadow("dune", box(0, 0, 1, 1), "sand")
    assert MeadowMap([sand]).terrain_table is None
    with pytest.raises(UnknownTerrainError, match="'dune' terrain: expected one of concrete, grass"):
        MeadowMap([sand], terrain_table=TerrainTable.default())


def test_map_refuses_overlapping_meadows_but_accepts_touching_ones() -> None:
    with pytest.raises(
        InputError, match=r"'a' and 'b' polygon: expected meadows that do not overlap, got .* 0\.5 m"
    ):
        MeadowMap([Meadow("a", box(0, 0, 1, 1), "tile"), Meadow("b", box(0.5, 0, 2, 1), "tile")])
    touching = MeadowMap([Meadow("a", box(0, 0, 1, 1), "tile"), Meadow("b", box(1, 0, 2, 1), "tile")])
    assert [m.id for m in touching.neighbours("a")] == ["b"]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (([],), "meadows: expected at least one meadow, got none"),
        ((["m"],), r"meadows\[0\]: expected a Meadow, got str"),
        (([Meadow("m", box(0, 0, 1, 1), "tile")], ["r"]), r"landmarks\[0\]: expected a LandmarkRecord"),
    ],
)
def test_map_checks_item_types(args: tuple[object, ...], message: str) -> None:
    with pytest.raises(InputError, match=message):
        MeadowMap(*args)  # type: ignore[arg-type]


def test_map_checks_its_keyword_arguments() -> None:
    meadows = [Meadow("m", box(0, 0, 1, 1), "tile")]
    with pytest.raises(InputError, match="terrain_table: expected a TerrainTable or None"):
        MeadowMap(meadows, terrain_table={"tile": 1})  # type: ignore[arg-type]
    with pytest.raises(InputError, match="terrain_table_file: expected a non-empty string"):
        MeadowMap(meadows, terrain_table_file="")


# --- MeadowMap: adjacency ----------------------------------------------------------------------


def test_adjacency_needs_a_shared_segment_not_a_corner() -> None:
    world = MeadowMap(
        [
            Meadow("sw", box(0, 0, 1, 1), "tile"),
            Meadow("se", box(1, 0, 2, 1), "tile"),
            Meadow("ne", box(1, 1, 2, 2), "tile"),
            Meadow("far", box(5, 5, 6, 6), "tile"),
        ]
    )
    assert [m.id for m in world.neighbours("sw")] == ["se"]  # "ne" only touches at (1, 1)
    assert [m.id for m in world.neighbours("se")] == ["sw", "ne"]
    assert world.neighbours("far") == ()
    with pytest.raises(InputError, match="expected two adjacent meadows, got 'sw' and 'ne'"):
        world.portal("sw", "ne")


def test_portal_is_the_shared_part_of_the_boundaries() -> None:
    room = Meadow("room", box(0, 2, 6, 8), "tile")
    door = Meadow("door", box(2, 1.8, 3, 2), "tile")
    world = MeadowMap([room, door])
    np.testing.assert_array_equal(world.portal("door", "room"), [[2.0, 2.0], [3.0, 2.0]])
    np.testing.assert_array_equal(world.portal("room", "door"), world.portal("door", "room"))
    assert not world.portal("room", "door").flags.writeable
    assert [(a, b) for a, b, _ in world.portals()] == [("room", "door")]


def test_rounding_gaps_are_closed_and_real_gaps_are_not() -> None:
    tiny = MeadowMap([Meadow("a", box(0, 0, 1, 1), "tile"), Meadow("b", box(1 + 1e-9, 0, 2, 1), "tile")])
    assert [m.id for m in tiny.neighbours("a")] == ["b"]
    portal = tiny.portal("a", "b")
    assert np.hypot(*(portal[1] - portal[0])) == pytest.approx(1.0, abs=1e-5)
    gap = MeadowMap([Meadow("a", box(0, 0, 1, 1), "tile"), Meadow("b", box(1.01, 0, 2, 1), "tile")])
    assert gap.neighbours("a") == ()


def test_adjacency_of_a_tilted_partition() -> None:
    # Two triangles splitting a rotated square along its diagonal share that diagonal.
    c, s = math.cos(0.3), math.sin(0.3)
    square = [(c * x - s * y, s * x + c * y) for x, y in [(0, 0), (3, 0), (3, 3), (0, 3)]]
    world = MeadowMap(
        [
            Meadow("lower", ConvexPolygon([square[0], square[1], square[2]]), "grass"),
            Meadow("upper", ConvexPolygon([square[0], square[2], square[3]]), "grass"),
        ]
    )
    portal = world.portal("lower", "upper")
    assert np.hypot(*(portal[1] - portal[0])) == pytest.approx(3 * math.sqrt(2), rel=1e-12)


# --- MeadowMap: lookups and spatial queries --------------------------------------------------------


def test_lookups_by_id() -> None:
    world = make_grid_world(2, 2)
    assert world.meadow("cell_1_0").terrain == "grass"
    assert world.landmark("pole_0_0").symbol == "pole"
    assert [r.id for r in world.landmarks_visible_from("cell_1_1")] == ["pole_2_2"]
    with pytest.raises(UnknownTerrainError, match="meadow: expected the id of a meadow of this map, got 'x'"):
        world.meadow("x")
    with pytest.raises(KeyError, match="landmark: expected the id of a landmark of this map, got 'y'"):
        world.landmark("y")
    assert world.bounds == (0.0, 0.0, 10.0, 10.0)
    assert len(world) == 4
    assert repr(world) == "MeadowMap(4 meadows, 4 landmarks)"


def test_point_queries_agree_with_the_polygons(rng: np.random.Generator) -> None:
    world = make_grid_world(4, 5, cell=2.0, remove=[(1, 1), (2, 3)])
    points = rng.uniform(-1.0, 11.0, size=(500, 2))
    found = world.meadows_at(points)
    for point, meadow in zip(points, found, strict=True):
        assert meadow == world.meadow_at(*point)
        inside = [m for m in world.meadows if m.polygon.contains(point)[0]]
        assert (meadow is None) == (not inside)
        if meadow is not None:
            assert meadow == inside[0]
    assert world.meadows_at(np.empty((0, 2))) == ()


def test_points_on_shared_boundaries_belong_to_every_meadow_there() -> None:
    world = make_grid_world(2, 2)
    assert [m.id for m in world.meadows_containing(5.0, 5.0)] == [
        "cell_0_0",
        "cell_0_1",
        "cell_1_0",
        "cell_1_1",
    ]
    assert world.meadow_at(5.0, 2.0).id == "cell_0_0"  # type: ignore[union-attr]
    assert [m.id if m else None for m in world.meadows_at([(5.0, 2.0), (5.0, 7.0)])] == [
        "cell_0_0",
        "cell_1_0",
    ]


def test_meadows_near_a_polyline() -> None:
    world = make_grid_world(1, 6)
    assert [m.id for m in world.meadows_near([(1.0, 2.5)], 0.0)] == ["cell_0_0"]
    assert [m.id for m in world.meadows_near([(1.0, 2.5), (7.0, 2.5)], 3.0)] == [
        "cell_0_0",
        "cell_0_1",
        "cell_0_2",
    ]
    with pytest.raises(InputError, match=r"distance: expected a non-negative number, got -1\.0"):
        world.meadows_near([(0.0, 0.0)], -1.0)


def test_maps_are_immutable_values() -> None:
    world = make_grid_world(1, 2)
    assert world == make_grid_world(1, 2)
    assert world != make_grid_world(1, 3)
    assert world != "a map"
    with pytest.raises(dataclasses.FrozenInstanceError, match="cannot assign"):
        world.meadows = ()  # type: ignore[misc]
    with pytest.raises(TypeError, match="unhashable"):
        hash(world)


def test_the_strategy_lives_with_the_records_and_the_expecter_re_exports_it() -> None:
    assert world.PerceptualStrategy is PerceptualStrategy
    assert expecter.PerceptualStrategy is PerceptualStrategy
    assert PerceptualStrategy("region_segmenter") is PerceptualStrategy.REGION_SEGMENTER


def test_a_lookup_by_what_is_not_an_id_is_refused() -> None:
    # unhashable type: 'list', a TypeError, before
    grid = make_grid_world(1, 2)
    wrong: Any = ["a"]
    with pytest.raises(InputError, match=r"meadow: expected a meadow id \(a str\), got list"):
        grid.meadow(wrong)
    with pytest.raises(InputError, match=r"landmark: expected a landmark id \(a str\), got list"):
        grid.landmark(wrong)
    with pytest.raises(InputError, match=r"meadow: expected a meadow id \(a str\), got list"):
        grid.portal(wrong, "cell_0_1")
    with pytest.raises(
        UnknownTerrainError, match="meadow: expected the id of a meadow of this map, got 'nope'"
    ):
        grid.meadow("nope")


def test_every_class_has_a_usual_strategy_and_every_strategy_its_parameters() -> None:
    found = {LandmarkClass(c): PerceptualStrategy.for_class(LandmarkClass(c)) for c in ("I", "II", "III")}
    assert all(strategies for strategies in found.values())
    # Every strategy finds some class.
    assert {s for strategies in found.values() for s in strategies} == set(PerceptualStrategy)
    assert all(strategy.parameters for strategy in PerceptualStrategy)
    with pytest.raises(InputError, match="landmark_class: expected a LandmarkClass, got 'II'"):
        PerceptualStrategy.for_class("II")  # type: ignore[arg-type]
