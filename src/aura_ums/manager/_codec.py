"""JSON encoding and strict decoding of the manager's state: maps, commands, observations.

Floats are written by :func:`json.dumps`, which uses ``repr``: the shortest text that
reads back as the very same double, so what is saved is restored bit for bit. Decoding
refuses what it does not expect (a missing or unknown key, a wrong type, a non-finite
number) with a :class:`~aura_ums.errors.FileFormatError` naming the source, the place
(``"map.vertices[3]"``) and what was expected. No pickle, no eval.
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Iterable, Mapping
from typing import Any, NoReturn

import numpy as np

from aura_ums._files import Fields, describe, parse_json
from aura_ums._validate import WEDGE_EXTENT
from aura_ums.errors import FileFormatError, InputError
from aura_ums.geometry import ConvexPolygon, HeadingWedge
from aura_ums.manager._relaxed import Branch, RelaxedState, Sighting
from aura_ums.uncertainty import (
    BearingObservation,
    GroundLineObservation,
    HeadingSlice,
    Observation,
    RangeBearingObservation,
    SpatialUncertaintyMap,
    TurnAndRun,
)

#: Version of the JSON documents written here; bump it when their layout changes.
FORMAT_VERSION = 1

_OBSERVATION_CLASSES: dict[str, type[Observation]] = {
    cls.__name__: cls for cls in (BearingObservation, RangeBearingObservation, GroundLineObservation)
}


def dump_document(kind: str, body: Mapping[str, object]) -> str:
    """Return a JSON document of ``kind`` holding ``body`` (floats written with ``repr``)."""
    return json.dumps({"format": kind, "version": FORMAT_VERSION, **body}, indent=1, allow_nan=False)


class Reader:
    """Strict readers of decoded JSON values that fail naming ``source`` and the place.

    Parameters
    ----------
    source : str
        What is being read (a file name, or a description such as ``"<manager JSON>"``).
    """

    __slots__ = ("fields", "source")

    def __init__(self, source: str) -> None:
        self.source = source
        self.fields = Fields(source, "json")

    def fail(self, where: str, message: str) -> NoReturn:
        """Raise the :class:`FileFormatError` for ``where``."""
        raise FileFormatError(self.source, where, message)

    def document(self, text: object, kind: str) -> dict[str, Any]:
        """Parse ``text`` and check that it is a ``kind`` document of a known version."""
        if not isinstance(text, str):
            self.fail("", f"expected JSON text (str), got {type(text).__name__}")
        top = self.mapping(parse_json(text, self.source), "")
        found = top.get("format")
        if found != kind:
            self.fail("format", f"expected {kind!r}, got {_found(top, 'format')}")
        version = top.get("version")
        if isinstance(version, bool) or version != FORMAT_VERSION:  # JSON true == 1 in Python
            self.fail("version", f"expected {FORMAT_VERSION}, got {_found(top, 'version')}")
        return top

    def mapping(
        self, value: object, where: str, keys: Iterable[str] = (), optional: Iterable[str] = ()
    ) -> dict[str, Any]:
        """Return ``value`` as a JSON object; with ``keys``, exactly those (plus ``optional``)."""
        checked: dict[str, Any] = self.fields.table(value, where)
        required = list(keys)
        if required:
            allowed = {*required, *optional}
            for key in required:
                if key not in checked:
                    self.fail(where, f"expected a key {key!r}, got none")
            for key in checked:
                if key not in allowed:
                    self.fail(where, f"expected only the keys {sorted(allowed)}, got {describe(key)}")
        return checked

    def array(self, value: object, where: str) -> list[Any]:
        """Return ``value`` as a JSON array."""
        return self.fields.array(value, where)

    def number(self, value: object, where: str) -> float:
        """Return ``value`` as a finite float (a JSON number, not a boolean)."""
        return self.fields.number(value, where)

    def optional_number(self, value: object, where: str) -> float | None:
        """Return ``value`` as a finite float, or None for JSON ``null``."""
        return None if value is None else self.number(value, where)

    def integer(self, value: object, where: str, minimum: int = 0) -> int:
        """Return ``value`` as an integer >= ``minimum``."""
        return self.fields.integer(value, where, minimum)

    def string(self, value: object, where: str) -> str:
        """Return ``value`` as a string."""
        return self.fields.string(value, where)

    # --- values of aura-ums ------------------------------------------------------------

    def command(self, value: object, where: str) -> TurnAndRun:
        """Decode a :class:`TurnAndRun` written by :func:`encode_command`."""
        data = self.mapping(value, where, ("turn", "run"))
        turn = self.number(data["turn"], f"{where}.turn")
        run = self.number(data["run"], f"{where}.run")
        try:
            return TurnAndRun(turn, run)
        except InputError as exc:
            self.fail(where, str(exc))

    def observation(self, value: object, where: str) -> Observation:
        """Decode an observation written by :func:`encode_observation` (its class is named)."""
        data = self.mapping(value, where)
        name = data.get("class")
        cls = _OBSERVATION_CLASSES.get(name) if isinstance(name, str) else None
        if cls is None:
            self.fail(
                f"{where}.class",
                f"expected one of {sorted(_OBSERVATION_CLASSES)}, got {self.fields.describe(name)}",
            )
        names = [field.name for field in dataclasses.fields(cls)]
        self.mapping(data, where, ["class", *names])
        kwargs: dict[str, object] = {}
        for field_name in names:
            item, place = data[field_name], f"{where}.{field_name}"
            if field_name == "landmark_id":
                kwargs[field_name] = self.string(item, place)
            elif field_name == "sensor_offset":
                pair = self.array(item, place)
                if len(pair) != 2:
                    self.fail(place, f"expected [forward, left], got {len(pair)} numbers")
                kwargs[field_name] = (
                    self.number(pair[0], f"{place}[0]"),
                    self.number(pair[1], f"{place}[1]"),
                )
            else:
                kwargs[field_name] = self.number(item, place)
        try:
            return cls(**kwargs)  # type: ignore[arg-type]
        except InputError as exc:
            self.fail(where, str(exc))

    def uncertainty_map(self, value: object, where: str) -> SpatialUncertaintyMap:
        """Decode a map written by :func:`encode_map`, bit for bit.

        The values are validated as the public constructors validate them, and the exact
        saved numbers are kept where a constructor would normalize them: the polygon's
        collinear vertices stay, and the wedge centre is not wrapped again (re-wrapping a
        centre already in (-pi, pi] can move it by one unit in the last place).
        """
        data = self.mapping(value, where, ("vertices", "center", "wedge"), optional=("slices",))
        polygon = self.polygon(data["vertices"], f"{where}.vertices")
        center_list = self.array(data["center"], f"{where}.center")
        if len(center_list) != 2:
            self.fail(f"{where}.center", f"expected [x, y], got {len(center_list)} numbers")
        center = (
            self.number(center_list[0], f"{where}.center[0]"),
            self.number(center_list[1], f"{where}.center[1]"),
        )
        wedge_data = self.mapping(data["wedge"], f"{where}.wedge", ("center", "cw", "ccw"))
        heading = self.number(wedge_data["center"], f"{where}.wedge.center")
        if not -math.pi < heading <= math.pi:
            self.fail(f"{where}.wedge.center", f"expected a heading in (-pi, pi], got {heading!r}")
        cw = self.fields.ranged(wedge_data["cw"], f"{where}.wedge.cw", WEDGE_EXTENT)
        ccw = self.fields.ranged(wedge_data["ccw"], f"{where}.wedge.ccw", WEDGE_EXTENT)
        try:
            wedge = HeadingWedge._restored(heading, cw, ccw)
        except InputError as exc:
            self.fail(f"{where}.wedge", str(exc))
        if "slices" in data:
            return self._sliced_map(data["slices"], f"{where}.slices", center, wedge)
        try:
            return SpatialUncertaintyMap.from_polygon(polygon, center, wedge)
        except InputError as exc:
            self.fail(f"{where}.center", str(exc))

    def polygon(self, value: object, where: str) -> ConvexPolygon:
        """Decode a polygon's vertex list, bit for bit (collinear vertices kept)."""
        rows = self.array(value, where)
        if not rows:
            self.fail(where, "expected at least one vertex, got none")
        points: list[tuple[float, float]] = []
        for k, row in enumerate(rows):
            place = f"{where}[{k}]"
            pair = self.array(row, place)
            if len(pair) != 2:
                self.fail(place, f"expected [x, y], got {len(pair)} numbers")
            points.append((self.number(pair[0], f"{place}[0]"), self.number(pair[1], f"{place}[1]")))
        vertices = np.array(points, dtype=np.float64)
        try:
            ConvexPolygon(vertices)  # validates; it would drop collinear vertices the map kept
        except InputError as exc:
            self.fail(where, str(exc))
        return ConvexPolygon._trusted(vertices)

    def _sliced_map(
        self, value: object, where: str, center: tuple[float, float], wedge: HeadingWedge
    ) -> SpatialUncertaintyMap:
        """Decode the slices written by :func:`encode_map` and build the sliced map."""
        data = self.mapping(value, where, ("slice_width", "max_slices", "pieces"))
        width = self.number(data["slice_width"], f"{where}.slice_width")
        cap = self.integer(data["max_slices"], f"{where}.max_slices", 1)
        pieces: list[HeadingSlice] = []
        for k, item in enumerate(self.array(data["pieces"], f"{where}.pieces")):
            place = f"{where}.pieces[{k}]"
            piece = self.mapping(item, place, ("lo", "width", "vertices"))
            pieces.append(
                HeadingSlice(
                    self.polygon(piece["vertices"], f"{place}.vertices"),
                    self.number(piece["lo"], f"{place}.lo"),
                    self.number(piece["width"], f"{place}.width"),
                )
            )
        try:
            return SpatialUncertaintyMap.from_slices(pieces, center, wedge, slice_width=width, max_slices=cap)
        except InputError as exc:
            self.fail(where, str(exc))


def encode_command(command: TurnAndRun) -> dict[str, float]:
    """Return a :class:`TurnAndRun` as a JSON object."""
    return {"turn": command.turn, "run": command.run}


def encode_observation(observation: Observation) -> dict[str, object]:
    """Return an observation as a JSON object naming its class."""
    data: dict[str, object] = {"class": type(observation).__name__}
    for field in dataclasses.fields(observation):
        value = getattr(observation, field.name)
        data[field.name] = list(value) if field.name == "sensor_offset" else value
    return data


def encode_map(uncertainty_map: SpatialUncertaintyMap) -> dict[str, object]:
    """Return a map as a JSON object: vertices, centre, wedge (and slices), every float exact."""
    wedge = uncertainty_map.wedge
    data: dict[str, object] = {
        "vertices": uncertainty_map.polygon.vertices.tolist(),
        "center": uncertainty_map.center.tolist(),
        "wedge": {"center": wedge.center, "cw": wedge.cw, "ccw": wedge.ccw},
    }
    if uncertainty_map.is_sliced:
        data["slices"] = {
            "slice_width": uncertainty_map.slice_width,
            "max_slices": uncertainty_map.max_slices,
            "pieces": [
                {"lo": piece.lo, "width": piece.width, "vertices": piece.polygon.vertices.tolist()}
                for piece in uncertainty_map.slices
            ],
        }
    return data


def _found(table: Mapping[str, object], key: str) -> str:
    return describe(table[key], "json") if key in table else "nothing"


def encode_relaxed(state: RelaxedState) -> dict[str, object]:
    """Return the relaxed intersection's branches and window as a JSON object, every float exact."""
    return {
        "branches": [
            {
                "excluded": sorted(branch.excluded),
                "map": encode_map(branch.map),
                # Only when some: documents without carried sightings read as they always did.
                **({"carried": sorted(branch.carried)} if branch.carried else {}),
            }
            for branch in state.branches
        ],
        "window": [
            {"serial": sighting.serial, "observation": encode_observation(sighting.observation)}
            for sighting in state.window
        ],
        "reported": sorted(state.reported),
        "next_serial": state.next_serial,
    }


def decode_relaxed(reader: Reader, value: object, where: str, q: int, window: int) -> RelaxedState:
    """Decode what :func:`encode_relaxed` wrote, checked against ``q`` and ``window`` (N)."""
    data = reader.mapping(value, where, ("branches", "window", "reported", "next_serial"))
    next_serial = reader.integer(data["next_serial"], f"{where}.next_serial")
    sightings: list[Sighting] = []
    for k, item in enumerate(reader.array(data["window"], f"{where}.window")):
        place = f"{where}.window[{k}]"
        entry = reader.mapping(item, place, ("serial", "observation"))
        serial = reader.integer(entry["serial"], f"{place}.serial")
        if serial >= next_serial or (sightings and serial <= sightings[-1].serial):
            reader.fail(f"{place}.serial", f"expected increasing serials below next_serial, got {serial}")
        sightings.append(Sighting(serial, reader.observation(entry["observation"], f"{place}.observation")))
    if len(sightings) > window:
        reader.fail(
            f"{where}.window", f"expected at most {window} sightings (relaxed_window), got {len(sightings)}"
        )
    serials = {sighting.serial for sighting in sightings}

    def serial_set(item: object, place: str, most: int) -> frozenset[int]:
        found = frozenset(reader.integer(x, f"{place}[{k}]") for k, x in enumerate(reader.array(item, place)))
        if not found <= serials or len(found) > most:
            reader.fail(place, f"expected at most {most} serials of the window, got {len(found)}")  # not each
        return found

    branches: list[Branch] = []
    for k, item in enumerate(reader.array(data["branches"], f"{where}.branches")):
        place = f"{where}.branches[{k}]"
        entry = reader.mapping(item, place, ("excluded", "map"), optional=("carried",))
        excluded = serial_set(entry["excluded"], f"{place}.excluded", q)
        carried = serial_set(entry.get("carried", []), f"{place}.carried", len(serials))
        if both := sorted(carried & excluded):
            reader.fail(f"{place}.carried", f"expected no serial of excluded, got {both}")
        if any((branch.excluded, branch.carried) == (excluded, carried) for branch in branches):
            reader.fail(
                f"{place}.excluded",
                f"expected excluded and carried sets no other branch has, got excluded {sorted(excluded)} "
                f"and carried {sorted(carried)} twice",
            )
        branches.append(Branch(excluded, reader.uncertainty_map(entry["map"], f"{place}.map"), carried))
    if not branches:
        reader.fail(f"{where}.branches", "expected at least one branch, got none")
    reported = serial_set(data["reported"], f"{where}.reported", len(serials))
    return RelaxedState(tuple(branches), tuple(sightings), reported, next_serial)
