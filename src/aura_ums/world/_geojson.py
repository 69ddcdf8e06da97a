"""The meadow map's file format: a GeoJSON FeatureCollection (see the package docstring).

Reading validates every feature once and fails with a :class:`FileFormatError` that names
the file, the feature (index and id) and the property. Writing keeps floats exact (``json``
writes them with ``repr`` precision), so a saved map reads back equal.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import NoReturn

import numpy as np

from aura_ums._files import Fields, describe, load_json, regular_file, write_text_atomic
from aura_ums._validate import ANGLE, COORDINATE, HEIGHT, MAX_CONFIRM_FRAMES, POSITION_UNCERTAINTY, Range
from aura_ums.errors import FileFormatError, InputError
from aura_ums.geometry import ConvexPolygon
from aura_ums.uncertainty import (
    GroundLineLandmark,
    Landmark,
    PointLandmark,
    TerrainTable,
    VerticalLineLandmark,
)
from aura_ums.world._ltm import LandmarkRecord, Meadow, MeadowMap, PerceptualStrategy, _MapError

#: The range of a perceptual strategy's parameter (docs/formats.md): counts, pixel sizes and
#: thresholds, within 1e9 (the area of a 20000 x 20000 px image is 4e8 px^2) ...
PARAMETER_RANGE = Range(-1e9, 1e9)
#: ... but the angles, in radians: a line's image orientation, and a tolerance at most pi
#: (orientations repeat every pi, so pi/2 already admits every line).
PARAMETER_RANGES: dict[str, Range] = {"orientation": ANGLE, "tolerance": Range(0.0, math.pi, "rad")}

_MEADOW_KEYS = ("kind", "id", "terrain", "landmarks")
_COMMON_LANDMARK_KEYS = (
    "kind",
    "id",
    "class",
    "symbol",
    "position_uncertainty",
    "strategy",
    "parameters",
    "activation_range",
    "recognition_threshold",
    "confirm_frames",
)
_CLASS_KEYS = {"I": ("z_bottom", "z_top"), "II": ("z",), "III": ()}
_CLASS_GEOMETRY = {"I": "Point", "II": "Point", "III": "LineString"}
_STRATEGIES = {strategy.value: strategy for strategy in PerceptualStrategy}


class _Reader:
    """Reads one document; ``source`` names it in errors."""

    def __init__(self, source: str, base: Path, terrain_table: TerrainTable | None) -> None:
        self.source = source
        self.fields = Fields(source, "json")
        self.base = base
        self.terrain_table = terrain_table
        self.table = terrain_table

    def fail(self, where: str, message: str) -> NoReturn:
        self.fields.fail(where, message)

    # --- the collection --------------------------------------------------------------------

    def read(self, document: object) -> MeadowMap:
        if not isinstance(document, Mapping):
            self.fail("", f"expected a GeoJSON object, got {_kind(document)}")
        if document.get("type") != "FeatureCollection":
            self.fail("type", f"expected 'FeatureCollection', got {_kind(document.get('type'))}")
        features = document.get("features")
        if not isinstance(features, list):
            self.fail("features", f"expected a list of features, got {_kind(features)}")
        table_file = document.get("terrain_table")
        table = self.terrain_table
        if table_file is not None:
            if not isinstance(table_file, str) or not table_file:
                self.fail("terrain_table", f"expected the name of a TOML file, got {_kind(table_file)}")
            path = self.base / table_file
            # Read though a table given by the caller overrides it: a broken reference (no
            # file, or a file that is no terrain table) is a broken file, not a silent fallback.
            if not regular_file(path):
                self.fail("terrain_table", f"expected a terrain table file, got no file at {path}")
            referenced = TerrainTable.from_toml(path)
            if table is None:
                table = referenced
        self.table = table

        places: dict[str, tuple[int, str]] = {}
        meadows: list[tuple[str, Meadow]] = []
        landmarks: list[LandmarkRecord] = []
        for index, feature in enumerate(features):
            where = f"features[{index}]"
            if not isinstance(feature, Mapping) or feature.get("type") != "Feature":
                self.fail(where, f"expected a GeoJSON Feature, got {_kind(feature)}")
            properties = feature.get("properties")
            if not isinstance(properties, Mapping):
                self.fail(f"{where} properties", f"expected an object, got {_kind(properties)}")
            props = {key: value for key, value in properties.items() if value is not None}
            ident = props.get("id")
            if not isinstance(ident, str) or not ident:
                self.fail(f"{where} properties.id", f"expected a non-empty string, got {_kind(ident)}")
            where = f"{where} (id {describe(ident)})"
            if ident in places:
                first = places[ident][0]
                self.fail(
                    f"{where} properties.id",
                    f"expected a unique id, got {describe(ident)} again (first at features[{first}])",
                )
            places[ident] = (index, where)
            kind = props.get("kind")
            if kind == "meadow":
                meadows.append((where, self.meadow(where, feature.get("geometry"), props)))
            elif kind == "landmark":
                landmarks.append(self.landmark(where, feature.get("geometry"), props))
            else:
                self.fail(f"{where} properties.kind", f"expected 'meadow' or 'landmark', got {_kind(kind)}")
        if not meadows:
            self.fail("features", "expected at least one meadow feature, got none")

        known = {record.id for record in landmarks}
        for where, meadow in meadows:
            for position, landmark_id in enumerate(meadow.landmark_ids):
                if landmark_id not in known:
                    self.fail(
                        f"{where} properties.landmarks[{position}]",
                        f"expected the id of a landmark feature, got {describe(landmark_id)}",
                    )
        try:
            return MeadowMap._create([meadow for _, meadow in meadows], landmarks, table, table_file)
        except _MapError as exc:
            self.fail(" and ".join(f"{places[i][1]} {exc.field}" for i in exc.ids), exc.detail)

    # --- features --------------------------------------------------------------------------

    def check_keys(self, where: str, props: Mapping[str, object], allowed: tuple[str, ...]) -> None:
        self.fields.keys(props, allowed, f"{where} properties", noun="property")

    def meadow(self, where: str, geometry: object, props: Mapping[str, object]) -> Meadow:
        self.check_keys(where, props, _MEADOW_KEYS)
        ring = self.polygon_ring(where, geometry)
        terrain = props.get("terrain")
        if not isinstance(terrain, str) or not terrain:
            self.fail(f"{where} properties.terrain", f"expected a terrain name, got {_kind(terrain)}")
        if self.table is not None and terrain not in self.table:
            self.fail(
                f"{where} properties.terrain",
                f"expected one of {', '.join(sorted(self.table))}, got {describe(terrain)}",
            )
        listed = props.get("landmarks", [])
        if not isinstance(listed, list):
            self.fail(
                f"{where} properties.landmarks", f"expected a list of landmark ids, got {_kind(listed)}"
            )
        seen: set[str] = set()
        for position, landmark_id in enumerate(listed):
            item = f"{where} properties.landmarks[{position}]"
            if not isinstance(landmark_id, str) or not landmark_id:
                self.fail(item, f"expected a landmark id (string), got {_kind(landmark_id)}")
            if landmark_id in seen:
                self.fail(item, f"expected each landmark id once, got {describe(landmark_id)} again")
            seen.add(landmark_id)
        try:
            polygon = ConvexPolygon(ring)
        except InputError as exc:
            detail = str(exc).split("got ", 1)[-1]
            self.fail(f"{where} geometry", f"expected a convex polygon, got {detail}")
        return Meadow(str(props["id"]), polygon, terrain, tuple(listed))

    def polygon_ring(self, where: str, geometry: object) -> np.ndarray:
        place = f"{where} geometry"
        if not isinstance(geometry, Mapping) or geometry.get("type") != "Polygon":
            self.fail(place, f"expected a Polygon for a meadow, got {_geometry_kind(geometry)}")
        rings = geometry.get("coordinates")
        if not isinstance(rings, list) or not rings:
            self.fail(f"{place}.coordinates", f"expected a list of linear rings, got {_kind(rings)}")
        if len(rings) != 1:
            self.fail(
                f"{place}.coordinates", f"expected a Polygon without holes (1 ring), got {len(rings)} rings"
            )
        ring = self.positions(f"{place}.coordinates[0]", rings[0])
        if len(ring) >= 2 and np.array_equal(ring[0], ring[-1]):
            ring = ring[:-1]
        if len(ring) < 3:
            self.fail(f"{place}.coordinates[0]", f"expected at least 3 distinct vertices, got {len(ring)}")
        x, y = ring[:, 0], ring[:, 1]
        twice_area = float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))
        if twice_area == 0.0:
            self.fail(place, "expected a convex polygon of positive area, got area 0")
        if twice_area < 0.0:
            # GeoJSON tools write either orientation; keep the first vertex first.
            ring = np.concatenate([ring[:1], ring[:0:-1]])
        return ring

    def positions(self, where: str, value: object) -> np.ndarray:
        if not isinstance(value, list):
            self.fail(where, f"expected a list of [x, y] positions, got {_kind(value)}")
        return np.array([self.position(f"{where}[{i}]", item) for i, item in enumerate(value)]).reshape(-1, 2)

    def position(self, where: str, value: object) -> tuple[float, float]:
        if not isinstance(value, list) or len(value) != 2:
            # GIS tools often write a third value (an altitude): say how many there are.
            got = f"{len(value)} values" if isinstance(value, list) else _kind(value)
            self.fail(where, f"expected an [x, y] position in metres (2 values, no altitude), got {got}")
        return (
            self.fields.ranged(value[0], where, COORDINATE),
            self.fields.ranged(value[1], where, COORDINATE),
        )

    def number(self, where: str, value: object) -> float:
        return self.fields.number(value, where)

    def landmark(self, where: str, geometry: object, props: Mapping[str, object]) -> LandmarkRecord:
        ident = str(props["id"])
        klass = props.get("class")
        if not isinstance(klass, str) or klass not in _CLASS_KEYS:
            self.fail(f"{where} properties.class", f"expected 'I', 'II' or 'III', got {_kind(klass)}")
        self.check_keys(where, props, _COMMON_LANDMARK_KEYS + _CLASS_KEYS[klass])

        def required_number(key: str) -> float:
            value = self.fields.field(props, key, float, f"{where} properties")
            if key.startswith("z"):
                return self.fields.ranged(value, f"{where} properties.{key}", HEIGHT)
            return value

        symbol = props.get("symbol", "")
        if not isinstance(symbol, str):
            self.fail(f"{where} properties.symbol", f"expected a string, got {_kind(symbol)}")
        uncertainty = self.fields.ranged(
            props.get("position_uncertainty", 0.0),
            f"{where} properties.position_uncertainty",
            POSITION_UNCERTAINTY,
        )
        expected = _CLASS_GEOMETRY[klass]
        place = f"{where} geometry"
        if not isinstance(geometry, Mapping) or geometry.get("type") != expected:
            self.fail(
                place, f"expected a {expected} for a Class {klass} landmark, got {_geometry_kind(geometry)}"
            )
        coordinates = geometry.get("coordinates")
        landmark: Landmark
        try:
            if klass == "III":
                ends = self.positions(f"{place}.coordinates", coordinates)
                if len(ends) != 2:
                    self.fail(f"{place}.coordinates", f"expected 2 positions (start, end), got {len(ends)}")
                landmark = GroundLineLandmark(ident, ends[0], ends[1], symbol, uncertainty)
            else:
                x, y = self.position(f"{place}.coordinates", coordinates)
                if klass == "I":
                    bottom, top = required_number("z_bottom"), required_number("z_top")
                    landmark = VerticalLineLandmark(ident, x, y, bottom, top, symbol, uncertainty)
                else:
                    landmark = PointLandmark(ident, x, y, required_number("z"), symbol, uncertainty)
        except FileFormatError:
            raise
        except InputError as exc:
            self.fail_from(where, exc)

        strategy_name = props.get("strategy")
        if not isinstance(strategy_name, str) or strategy_name not in _STRATEGIES:
            # Those the landmark's class supports: naming all three sent a Class II point's
            # author from a missing strategy to "line_finder", refused in turn.
            supported = PerceptualStrategy.for_class(landmark.landmark_class)
            self.fail(
                f"{where} properties.strategy",
                f"expected {' or '.join(item.value for item in supported)} for a Class {klass} "
                f"landmark, got {_kind(strategy_name)}",
            )
        parameters = props.get("parameters", {})
        if not isinstance(parameters, Mapping):
            self.fail(
                f"{where} properties.parameters", f"expected an object of numbers, got {_kind(parameters)}"
            )
        checked = {
            str(key): self.fields.ranged(
                value,
                f"{where} properties.parameters.{key}",
                PARAMETER_RANGES.get(str(key), PARAMETER_RANGE),
            )
            for key, value in parameters.items()
        }
        frames = props.get("confirm_frames", 3)
        if isinstance(frames, bool) or not isinstance(frames, int) or not 1 <= frames <= MAX_CONFIRM_FRAMES:
            self.fail(
                f"{where} properties.confirm_frames",
                f"expected an integer in [1, {MAX_CONFIRM_FRAMES}], got {_kind(frames)}",
            )
        activation = required_number("activation_range")
        threshold = required_number("recognition_threshold")
        try:
            return LandmarkRecord(
                landmark, _STRATEGIES[strategy_name], checked, activation, threshold, frames
            )
        except InputError as exc:
            self.fail_from(where, exc)

    def fail_from(self, where: str, exc: InputError) -> NoReturn:
        """Re-raise a validation error of a landmark or record as a file error at its property."""
        key, _, message = str(exc).partition(": ")
        prop = key.split(".", 1)[1] if "." in key else key
        place = f"{where} geometry.coordinates" if prop in ("start", "end") else f"{where} properties.{prop}"
        raise FileFormatError(self.source, place, message) from exc


def _kind(value: object) -> str:
    """Describe a JSON value for an error message (absent properties are None: "nothing")."""
    return "nothing" if value is None else describe(value, "json")


def _geometry_kind(geometry: object) -> str:
    if isinstance(geometry, Mapping):
        return repr(geometry.get("type"))
    return _kind(geometry)


def parse_geojson(
    document: object, *, source: str, base: Path, terrain_table: TerrainTable | None
) -> MeadowMap:
    """Build a meadow map from a parsed GeoJSON document; ``base`` resolves a terrain table file."""
    return _Reader(source, base, terrain_table).read(document)


def read_geojson(path: str | Path, *, terrain_table: TerrainTable | None) -> MeadowMap:
    """Read and validate a meadow map file (see :meth:`MeadowMap.from_geojson`)."""
    document = load_json(path, kind="GeoJSON")
    return parse_geojson(document, source=str(path), base=Path(path).parent, terrain_table=terrain_table)


def _landmark_feature(record: LandmarkRecord) -> dict[str, object]:
    landmark = record.landmark
    props: dict[str, object] = {
        "kind": "landmark",
        "id": landmark.id,
        "class": landmark.landmark_class.value,
        "symbol": landmark.symbol,
        "position_uncertainty": float(landmark.position_uncertainty),
    }
    geometry: dict[str, object]
    if isinstance(landmark, GroundLineLandmark):
        geometry = {"type": "LineString", "coordinates": [_xy(landmark.start), _xy(landmark.end)]}
    else:
        geometry = {"type": "Point", "coordinates": [float(landmark.x), float(landmark.y)]}
        if isinstance(landmark, VerticalLineLandmark):
            props["z_bottom"] = float(landmark.z_bottom)
            props["z_top"] = float(landmark.z_top)
        else:
            props["z"] = float(landmark.z)
    props["strategy"] = record.strategy.value
    props["parameters"] = {key: float(value) for key, value in record.parameters.items()}
    props["activation_range"] = float(record.activation_range)
    props["recognition_threshold"] = float(record.recognition_threshold)
    props["confirm_frames"] = int(record.confirm_frames)
    return {"type": "Feature", "geometry": geometry, "properties": props}


def _xy(point: np.ndarray) -> list[float]:
    return [float(point[0]), float(point[1])]


def to_document(meadow_map: MeadowMap) -> dict[str, object]:
    """Return a meadow map as a GeoJSON FeatureCollection of plain Python values."""
    document = _header(meadow_map)
    document["features"] = _features(meadow_map)
    return document


def _header(meadow_map: MeadowMap) -> dict[str, object]:
    document: dict[str, object] = {"type": "FeatureCollection"}
    if meadow_map.terrain_table_file is not None:
        document["terrain_table"] = meadow_map.terrain_table_file
    return document


def _features(meadow_map: MeadowMap) -> list[dict[str, object]]:
    features: list[dict[str, object]] = []
    for meadow in meadow_map.meadows:
        ring = [_xy(v) for v in meadow.polygon.vertices]
        ring.append(list(ring[0]))
        features.append(
            {
                "type": "Feature",
                "geometry": {"type": "Polygon", "coordinates": [ring]},
                "properties": {
                    "kind": "meadow",
                    "id": meadow.id,
                    "terrain": meadow.terrain,
                    "landmarks": list(meadow.landmark_ids),
                },
            }
        )
    features.extend(_landmark_feature(record) for record in meadow_map.landmarks)
    return features


def write_geojson(meadow_map: MeadowMap, path: str | Path) -> None:
    """Write a meadow map as GeoJSON, one feature per line, floats exact."""
    features = _features(meadow_map)
    lines = ["{"]
    lines.extend(f"  {json.dumps(key)}: {json.dumps(value)}," for key, value in _header(meadow_map).items())
    lines.append('  "features": [')
    lines.append(",\n".join(f"    {json.dumps(feature, allow_nan=False)}" for feature in features))
    lines.append("  ]")
    lines.append("}")
    try:
        write_text_atomic(path, "\n".join(lines) + "\n")
    except OSError as exc:
        raise FileFormatError.unwritable(str(path), exc) from exc
