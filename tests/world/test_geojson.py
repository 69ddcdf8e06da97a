from __future__ import annotations

import copy
import json
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from aura_ums import FileFormatError, TerrainTable
from aura_ums.world import MeadowMap, make_grid_world, sample_world
from aura_ums.world._samples import SAMPLE_WORLDS

Document = dict[str, Any]


def write(path: Path, document: object) -> Path:
    path.write_text(json.dumps(document), encoding="utf-8")
    return path


def base_document() -> Document:
    """A small valid map: two meadows, one landmark of each class."""
    return {
        "type": "FeatureCollection",
        "features": [
            {
                "type": "Feature",
                "geometry": {"type": "Polygon", "coordinates": [[[0, 0], [4, 0], [4, 2], [0, 2], [0, 0]]]},
                "properties": {
                    "kind": "meadow",
                    "id": "walk",
                    "terrain": "concrete",
                    "landmarks": ["pole", "edge"],
                },
            },
            {
                "type": "Feature",
                "geometry": {"type": "Polygon", "coordinates": [[[4, 0], [8, 0], [8, 2], [4, 2], [4, 0]]]},
                "properties": {"kind": "meadow", "id": "lawn", "terrain": "grass", "landmarks": ["corner"]},
            },
            {
                "type": "Feature",
                "geometry": {"type": "Point", "coordinates": [2.0, 3.0]},
                "properties": {
                    "kind": "landmark",
                    "id": "pole",
                    "class": "I",
                    "symbol": "telephone pole",
                    "z_bottom": 0.0,
                    "z_top": 9.0,
                    "strategy": "line_finder",
                    "parameters": {"orientation": 1.5707963267948966, "tolerance": 0.17},
                    "activation_range": 25.0,
                    "recognition_threshold": 0.6,
                },
            },
            {
                "type": "Feature",
                "geometry": {"type": "Point", "coordinates": [12.0, 5.0]},
                "properties": {
                    "kind": "landmark",
                    "id": "corner",
                    "class": "II",
                    "z": 7.0,
                    "strategy": "interest_operator",
                    "activation_range": 40.0,
                    "recognition_threshold": 0.5,
                    "confirm_frames": 5,
                },
            },
            {
                "type": "Feature",
                "geometry": {"type": "LineString", "coordinates": [[0, 2], [8, 2]]},
                "properties": {
                    "kind": "landmark",
                    "id": "edge",
                    "class": "III",
                    "strategy": "line_finder",
                    "activation_range": 4.0,
                    "recognition_threshold": 0.5,
                    "position_uncertainty": 0.05,
                },
            },
        ],
    }


def assert_round_trip(world: MeadowMap, folder: Path, **load: Any) -> None:
    path = folder / "saved.geojson"
    world.to_geojson(path)
    again = MeadowMap.from_geojson(path, **load)
    assert again == world
    for a, b in zip(again.meadows, world.meadows, strict=True):
        assert np.array_equal(a.polygon.vertices, b.polygon.vertices)  # exact, not approximately
    for ra, rb in zip(again.landmarks, world.landmarks, strict=True):
        assert ra == rb
        assert dict(ra.parameters) == dict(rb.parameters)
    # Saving the loaded map gives the same file.
    second = folder / "again.geojson"
    again.to_geojson(second)
    assert second.read_text(encoding="utf-8") == path.read_text(encoding="utf-8")
    assert MeadowMap.from_geojson_dict(world.to_geojson_dict(), base=folder, **load) == world


# --- round trips -------------------------------------------------------------------------------


@pytest.mark.parametrize("name", SAMPLE_WORLDS)
def test_sample_worlds_round_trip_exactly(name: str, tmp_path: Path) -> None:
    assert_round_trip(sample_world(name), tmp_path, terrain_table=TerrainTable.default())


def test_generated_map_with_awkward_floats_round_trips_exactly(
    tmp_path: Path, rng: np.random.Generator
) -> None:
    world = make_grid_world(6, 7, cell=1.0 / 3.0, rng=rng, remove=[(2, 2), (3, 4)])
    assert_round_trip(world, tmp_path)


def test_small_document_loads_with_defaults(tmp_path: Path) -> None:
    world = MeadowMap.from_geojson(write(tmp_path / "m.geojson", base_document()))
    assert [m.id for m in world.meadows] == ["walk", "lawn"]
    assert world.landmark("pole").symbol == "telephone pole"
    assert world.landmark("pole").confirm_frames == 3
    assert world.landmark("corner").confirm_frames == 5
    assert world.landmark("corner").parameters == {}
    assert world.landmark("edge").symbol == ""
    assert world.landmark("edge").landmark.position_uncertainty == 0.05
    assert [m.id for m in world.neighbours("walk")] == ["lawn"]
    assert_round_trip(world, tmp_path)


def test_clockwise_and_unclosed_rings_are_accepted(tmp_path: Path) -> None:
    ccw = MeadowMap.from_geojson(write(tmp_path / "ccw.geojson", base_document()))
    document = base_document()
    document["features"][0]["geometry"]["coordinates"] = [[[0, 0], [0, 2], [4, 2], [4, 0], [0, 0]]]
    document["features"][1]["geometry"]["coordinates"] = [[[4, 0], [8, 0], [8, 2], [4, 2]]]
    other = MeadowMap.from_geojson(write(tmp_path / "cw.geojson", document))
    assert other == ccw
    np.testing.assert_array_equal(other.meadow("walk").polygon.vertices[0], [0.0, 0.0])


def test_null_properties_and_foreign_members_are_ignored(tmp_path: Path) -> None:
    document = base_document()
    document["crs"] = {"type": "name", "properties": {"name": "EPSG:3857"}}
    document["features"][0]["properties"].update({"class": None, "z": None})
    document["features"][0]["id"] = 17
    document["features"][3]["properties"]["symbol"] = None
    world = MeadowMap.from_geojson(write(tmp_path / "m.geojson", document))
    assert world == MeadowMap.from_geojson(write(tmp_path / "base.geojson", base_document()))


def test_terrain_table_file_is_read_relative_to_the_map(tmp_path: Path) -> None:
    table = TerrainTable.from_mapping(
        {"concrete": dict.fromkeys(TerrainTable.default()["concrete"].__dataclass_fields__, 0.01)}
    )
    (tmp_path / "tables").mkdir()
    (tmp_path / "tables" / "mine.toml").write_text(table.to_toml(), encoding="utf-8")
    document = base_document()
    document["terrain_table"] = "tables/mine.toml"
    document["features"][1]["properties"]["terrain"] = "concrete"
    world = MeadowMap.from_geojson(write(tmp_path / "m.geojson", document))
    assert world.terrain_table_file == "tables/mine.toml"
    assert world.terrain_table == table
    assert_round_trip(world, tmp_path)


# --- bad files ---------------------------------------------------------------------------------


def feature(index: int, **properties: Any) -> Callable[[Document], None]:
    def change(document: Document) -> None:
        document["features"][index]["properties"].update(properties)

    return change


def geometry(index: int, value: Any) -> Callable[[Document], None]:
    def change(document: Document) -> None:
        document["features"][index]["geometry"] = value

    return change


def drop(index: int, key: str) -> Callable[[Document], None]:
    def change(document: Document) -> None:
        del document["features"][index]["properties"][key]

    return change


def append(new: Document) -> Callable[[Document], None]:
    def change(document: Document) -> None:
        document["features"].append(new)

    return change


def whole(value: Any) -> Callable[[Document], Any]:
    return lambda document: value


NOT_CONVEX = {"type": "Polygon", "coordinates": [[[0, 0], [4, 0], [1, 1], [0, 2], [0, 0]]]}
HOLED = {
    "type": "Polygon",
    "coordinates": [[[0, 0], [4, 0], [4, 2], [0, 2], [0, 0]], [[1, 0.5], [2, 0.5], [2, 1], [1, 0.5]]],
}
OVERLAPPING = {
    "type": "Feature",
    "geometry": {"type": "Polygon", "coordinates": [[[3, 0], [5, 0], [5, 1], [3, 1], [3, 0]]]},
    "properties": {"kind": "meadow", "id": "patch", "terrain": "tile"},
}

BAD_DOCUMENTS: list[tuple[str, Callable[[Document], Any], str, str]] = [
    ("not a collection", whole([1, 2]), "", "expected a GeoJSON object, got an array"),
    ("wrong type", whole({"type": "Feature"}), "type", "expected 'FeatureCollection', got 'Feature'"),
    (
        "no features",
        whole({"type": "FeatureCollection"}),
        "features",
        "expected a list of features, got nothing",
    ),
    (
        "no meadow",
        whole({"type": "FeatureCollection", "features": []}),
        "features",
        "expected at least one meadow feature, got none",
    ),
    (
        "feature not a feature",
        lambda d: d["features"].append(3),
        "features[5]",
        "expected a GeoJSON Feature, got 3",
    ),
    (
        "properties missing",
        lambda d: d["features"][0].update(properties=None),
        "features[0] properties",
        "expected an object, got nothing",
    ),
    ("missing id", drop(0, "id"), "features[0] properties.id", "expected a non-empty string, got nothing"),
    (
        "missing kind",
        drop(2, "kind"),
        "features[2] (id 'pole') properties.kind",
        "expected 'meadow' or 'landmark', got nothing",
    ),
    (
        "duplicate ids",
        feature(1, id="walk"),
        "features[1] (id 'walk') properties.id",
        "expected a unique id, got 'walk' again (first at features[0])",
    ),
    (
        "landmark id reused by a meadow",
        feature(4, id="lawn"),
        "features[4] (id 'lawn') properties.id",
        "expected a unique id, got 'lawn' again (first at features[1])",
    ),
    (
        "non-convex meadow",
        geometry(0, NOT_CONVEX),
        "features[0] (id 'walk') geometry",
        "expected a convex polygon, got a reflex (non-convex) corner at vertex 2 [1.0, 1.0]",
    ),
    (
        "meadow with a hole",
        geometry(0, HOLED),
        "features[0] (id 'walk') geometry.coordinates",
        "expected a Polygon without holes (1 ring), got 2 rings",
    ),
    (
        "flat meadow",
        geometry(0, {"type": "Polygon", "coordinates": [[[0, 0], [1, 1], [2, 2], [0, 0]]]}),
        "features[0] (id 'walk') geometry",
        "expected a convex polygon of positive area, got area 0",
    ),
    (
        "meadow as a point",
        geometry(0, {"type": "Point", "coordinates": [0, 0]}),
        "features[0] (id 'walk') geometry",
        "expected a Polygon for a meadow, got 'Point'",
    ),
    (
        "meadow with a 3-d position",
        geometry(0, {"type": "Polygon", "coordinates": [[[0, 0, 5], [4, 0], [4, 2], [0, 0]]]}),
        "features[0] (id 'walk') geometry.coordinates[0][0]",
        "expected an [x, y] position in metres (2 values, no altitude), got 3 values",
    ),
    (
        "meadow with a string coordinate",
        geometry(0, {"type": "Polygon", "coordinates": [[[0, "0"], [4, 0], [4, 2], [0, 0]]]}),
        "features[0] (id 'walk') geometry.coordinates[0][0]",
        "expected a finite number, got '0'",
    ),
    (
        "overlapping meadows",
        append(OVERLAPPING),
        "features[0] (id 'walk') polygon and features[5] (id 'patch') polygon",
        "expected meadows that do not overlap, got an overlap of 1 m^2",
    ),
    (
        "unknown landmark id",
        feature(0, landmarks=["pole", "ghost"]),
        "features[0] (id 'walk') properties.landmarks[1]",
        "expected the id of a landmark feature, got 'ghost'",
    ),
    (
        "landmark listed twice",
        feature(0, landmarks=["pole", "pole"]),
        "features[0] (id 'walk') properties.landmarks[1]",
        "expected each landmark id once, got 'pole' again",
    ),
    (
        "landmarks not a list",
        feature(0, landmarks="pole"),
        "features[0] (id 'walk') properties.landmarks",
        "expected a list of landmark ids, got 'pole'",
    ),
    (
        "missing terrain",
        drop(1, "terrain"),
        "features[1] (id 'lawn') properties.terrain",
        "expected a terrain name, got nothing",
    ),
    (
        "unknown meadow property",
        feature(1, terain="grass"),
        "features[1] (id 'lawn') properties.terain",
        "expected one of kind, id, terrain, landmarks, got unknown property 'terain'",
    ),
    (
        "bad class",
        feature(2, **{"class": "IV"}),
        "features[2] (id 'pole') properties.class",
        "expected 'I', 'II' or 'III', got 'IV'",
    ),
    (
        "Class I as a line",
        geometry(2, {"type": "LineString", "coordinates": [[0, 0], [1, 1]]}),
        "features[2] (id 'pole') geometry",
        "expected a Point for a Class I landmark, got 'LineString'",
    ),
    (
        "Class III as a point",
        geometry(4, {"type": "Point", "coordinates": [0, 0]}),
        "features[4] (id 'edge') geometry",
        "expected a LineString for a Class III landmark, got 'Point'",
    ),
    (
        "Class III with three positions",
        geometry(4, {"type": "LineString", "coordinates": [[0, 0], [1, 1], [2, 2]]}),
        "features[4] (id 'edge') geometry.coordinates",
        "expected 2 positions (start, end), got 3",
    ),
    (
        "Class III of zero length",
        geometry(4, {"type": "LineString", "coordinates": [[1, 1], [1, 1]]}),
        "features[4] (id 'edge') geometry.coordinates",
        "expected a point distinct from start, got [1.0, 1.0]",
    ),
    (
        "missing z_top",
        drop(2, "z_top"),
        "features[2] (id 'pole') properties.z_top",
        "expected a finite number, got nothing",
    ),
    (
        "z_top below z_bottom",
        feature(2, z_top=-1.0),
        "features[2] (id 'pole') properties.z_top",
        "expected >= z_bottom (0.0), got -1.0",
    ),
    (
        "z on a Class I landmark",
        feature(2, z=3.0),
        "features[2] (id 'pole') properties.z",
        "expected one of kind, id, class, symbol, position_uncertainty, strategy, parameters, "
        "activation_range, recognition_threshold, confirm_frames, z_bottom, z_top, got unknown property 'z'",
    ),
    (
        "missing z",
        drop(3, "z"),
        "features[3] (id 'corner') properties.z",
        "expected a finite number, got nothing",
    ),
    (
        "missing activation range",
        drop(2, "activation_range"),
        "features[2] (id 'pole') properties.activation_range",
        "expected a finite number, got nothing",
    ),
    (
        "zero activation range",
        feature(2, activation_range=0),
        "features[2] (id 'pole') properties.activation_range",
        "expected a number in (0, 10000] m, got 0.0",
    ),
    (
        "threshold as a string",
        feature(2, recognition_threshold="high"),
        "features[2] (id 'pole') properties.recognition_threshold",
        "expected a finite number, got 'high'",
    ),
    (
        "threshold as a boolean",
        feature(2, recognition_threshold=True),
        "features[2] (id 'pole') properties.recognition_threshold",
        "expected a finite number, got true",
    ),
    (
        "negative position uncertainty",
        feature(2, position_uncertainty=-0.5),
        "features[2] (id 'pole') properties.position_uncertainty",
        "expected a number in [0, 1000] m, got -0.5",
    ),
    (
        "unknown strategy",
        feature(2, strategy="LINE_FINDER"),
        "features[2] (id 'pole') properties.strategy",
        "expected line_finder or region_segmenter for a Class I landmark, got 'LINE_FINDER'",
    ),
    (
        # Naming the three strategies sent a point's author to line_finder, refused in turn.
        "a point without a strategy",
        drop(3, "strategy"),
        "features[3] (id 'corner') properties.strategy",
        "expected interest_operator for a Class II landmark, got nothing",
    ),
    (
        "parameters not an object",
        feature(2, parameters=[1]),
        "features[2] (id 'pole') properties.parameters",
        "expected an object of numbers, got an array",
    ),
    (
        "parameter not a number",
        feature(2, parameters={"tolerance": "wide"}),
        "features[2] (id 'pole') properties.parameters.tolerance",
        "expected a finite number, got 'wide'",
    ),
    (
        "confirm frames zero",
        feature(3, confirm_frames=0),
        "features[3] (id 'corner') properties.confirm_frames",
        "expected an integer in [1, 10000], got 0",
    ),
    (
        "confirm frames a billion",
        feature(3, confirm_frames=10**9),
        "features[3] (id 'corner') properties.confirm_frames",
        "expected an integer in [1, 10000], got 1000000000",
    ),
    (
        "activation range 1e300",
        feature(2, activation_range=1e300),
        "features[2] (id 'pole') properties.activation_range",
        "expected a number in (0, 10000] m, got 1e+300",
    ),
    (
        "symbol not a string",
        feature(2, symbol=5),
        "features[2] (id 'pole') properties.symbol",
        "expected a string, got 5",
    ),
    (
        "terrain table not a name",
        lambda d: d.update(terrain_table=3),
        "terrain_table",
        "expected the name of a TOML file, got 3",
    ),
    (
        "terrain table missing",
        lambda d: d.update(terrain_table="nowhere.toml"),
        "terrain_table",
        "expected a terrain table file, got no file at",
    ),
]


@pytest.mark.parametrize(
    ("change", "where", "message"),
    [pytest.param(change, where, message, id=name) for name, change, where, message in BAD_DOCUMENTS],
)
def test_bad_documents_name_feature_and_property(
    change: Callable[[Document], Any], where: str, message: str, tmp_path: Path
) -> None:
    document = copy.deepcopy(base_document())
    replaced = change(document)
    path = write(tmp_path / "bad.geojson", document if replaced is None else replaced)
    prefix = f"{path}: {where}: " if where else f"{path}: "
    with pytest.raises(FileFormatError, match="^" + re.escape(prefix + message)) as caught:
        MeadowMap.from_geojson(path)
    assert caught.value.path == str(path)
    assert caught.value.where == where


def test_unknown_terrain_is_refused_when_a_table_is_given(tmp_path: Path) -> None:
    document = base_document()
    document["features"][1]["properties"]["terrain"] = "sand"
    path = write(tmp_path / "sand.geojson", document)
    assert MeadowMap.from_geojson(path).meadow("lawn").terrain == "sand"
    with pytest.raises(
        FileFormatError,
        match=re.escape(
            "features[1] (id 'lawn') properties.terrain: expected one of concrete, grass, gravel, tile"
        ),
    ):
        MeadowMap.from_geojson(path, terrain_table=TerrainTable.default())


@pytest.mark.parametrize(
    ("text", "place", "message"),
    [
        (
            '{"type": "FeatureCollection", "features": [',
            ":1:44",
            "expected valid JSON, got Expecting value",
        ),
        ('{"type": "FeatureCollection",\n "features": [}', ":2:15", "expected valid JSON"),
        ('{"x": NaN}', "", "expected valid JSON, got the non-standard number NaN"),
        ('{"x": 1e400}', "", "expected valid JSON, got the number '1e400', beyond the largest float"),
        ('{"type": 1, "type": 2}', "", "expected valid JSON, got the key 'type' twice in one object"),
        ("", ":1:1", "expected valid JSON, got Expecting value"),
    ],
)
def test_malformed_json_is_a_file_format_error(text: str, place: str, message: str, tmp_path: Path) -> None:
    path = tmp_path / "broken.geojson"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(FileFormatError, match="^" + re.escape(f"{path}{place}: {message}")) as caught:
        MeadowMap.from_geojson(path)
    assert caught.value.where == ""


def test_unreadable_files_are_file_format_errors(tmp_path: Path) -> None:
    with pytest.raises(
        FileFormatError, match=r"missing\.geojson: expected an existing GeoJSON file, got no such file"
    ):
        MeadowMap.from_geojson(tmp_path / "missing.geojson")
    binary = tmp_path / "binary.geojson"
    binary.write_bytes(b"\xff\xfe\x00")
    with pytest.raises(FileFormatError, match="expected UTF-8 text"):
        MeadowMap.from_geojson(binary)
    (tmp_path / "a_file").write_text("")
    with pytest.raises(FileFormatError, match="expected a writable file, got Not a directory"):
        make_grid_world(1, 1).to_geojson(tmp_path / "a_file" / "map.geojson")
    # A missing folder is made (as for every file aura-ums writes), and only the file lands there.
    make_grid_world(1, 1).to_geojson(tmp_path / "no" / "such" / "folder.geojson")
    assert [path.name for path in (tmp_path / "no" / "such").iterdir()] == ["folder.geojson"]


def test_dict_documents_name_their_source() -> None:
    with pytest.raises(FileFormatError, match=r"^<geojson>: type: expected 'FeatureCollection', got nothing"):
        MeadowMap.from_geojson_dict({})
    with pytest.raises(FileFormatError, match=r"^mine: type: "):
        MeadowMap.from_geojson_dict({}, source="mine")


def test_saved_file_is_a_readable_feature_collection(tmp_path: Path) -> None:
    path = tmp_path / "grid.geojson"
    world = make_grid_world(2, 2)
    world.to_geojson(path)
    document = json.loads(path.read_text(encoding="utf-8"))
    assert document["type"] == "FeatureCollection"
    kinds = [f["properties"]["kind"] for f in document["features"]]
    assert kinds == ["meadow"] * 4 + ["landmark"] * 4
    ring = document["features"][0]["geometry"]["coordinates"][0]
    assert ring[0] == ring[-1]
    assert document["features"][4]["properties"]["strategy"] == "line_finder"
    assert len(path.read_text(encoding="utf-8").splitlines()) == 3 + 8 + 2  # one feature per line


# --- encodings and limits (the loading layer) ---------------------------------------------------


def test_a_map_with_a_byte_order_mark_reads_the_same(tmp_path: Path) -> None:
    world = make_grid_world(2, 2)
    path = tmp_path / "grid.geojson"
    world.to_geojson(path)
    (tmp_path / "bom.geojson").write_bytes(b"\xef\xbb\xbf" + path.read_bytes())
    assert MeadowMap.from_geojson(tmp_path / "bom.geojson") == world


def test_latin1_map_is_refused_naming_file_line_and_byte(tmp_path: Path) -> None:
    path = tmp_path / "latin.geojson"
    path.write_bytes('{"type": "FeatureCollection",\n "name": "Z\u00fcrich"}'.encode("latin-1"))
    with pytest.raises(
        FileFormatError, match=re.escape(f"{path}:2: byte 41: expected UTF-8 text, got the byte 0xfc")
    ):
        MeadowMap.from_geojson(path)


def test_over_size_map_is_refused_stating_the_limit(tmp_path: Path) -> None:
    path = tmp_path / "huge.geojson"
    with path.open("wb") as handle:
        handle.truncate(64 * 1024 * 1024 + 1)
    with pytest.raises(FileFormatError, match=r"huge\.geojson: expected a GeoJSON file of at most 64 MiB"):
        MeadowMap.from_geojson(path)


def test_nan_in_a_coordinate_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "nan.geojson"
    path.write_text(json.dumps(base_document()).replace("0.0", "NaN", 1))
    with pytest.raises(
        FileFormatError, match=r"nan\.geojson: expected valid JSON, got the non-standard number NaN"
    ):
        MeadowMap.from_geojson(path)
