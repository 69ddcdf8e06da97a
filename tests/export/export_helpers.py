"""Read MCAP files back in tests: messages per topic, decoded with the schemas the file carries.

The Foxglove SDK writes protobuf messages and embeds each schema as a serialized
``FileDescriptorSet``. The ``protobuf`` package is not a dependency, so this helper decodes
the wire format itself, driven by the descriptors read from the file (field names, types
and nesting all come from the schema, nothing is hard-coded): what it decodes is what
Foxglove would see. JSON channels are parsed with :mod:`json`.
"""

from __future__ import annotations

import json
import struct
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mcap.reader import make_reader

# FieldDescriptorProto.Type values (descriptor.proto)
_DOUBLE, _FLOAT, _INT64, _UINT64, _INT32, _FIXED64, _FIXED32, _BOOL, _STRING = range(1, 10)
_MESSAGE, _BYTES, _UINT32, _ENUM, _SFIXED32, _SFIXED64, _SINT32, _SINT64 = range(11, 19)
_REPEATED = 3


def _varint(data: bytes, pos: int) -> tuple[int, int]:
    result = shift = 0
    while True:
        byte = data[pos]
        pos += 1
        result |= (byte & 0x7F) << shift
        if not byte & 0x80:
            return result, pos
        shift += 7


def _fields(data: bytes) -> list[tuple[int, int, Any]]:
    """Raw (field number, wire type, value) triples: varints as int, fixed as bytes, len as bytes."""
    out: list[tuple[int, int, Any]] = []
    pos = 0
    while pos < len(data):
        key, pos = _varint(data, pos)
        number, wire = key >> 3, key & 7
        value: Any
        if wire == 0:
            value, pos = _varint(data, pos)
        elif wire == 1:
            value, pos = data[pos : pos + 8], pos + 8
        elif wire == 5:
            value, pos = data[pos : pos + 4], pos + 4
        elif wire == 2:
            length, pos = _varint(data, pos)
            value, pos = data[pos : pos + length], pos + length
        else:
            raise ValueError(f"unsupported wire type {wire}")
        out.append((number, wire, value))
    return out


@dataclass(frozen=True)
class _Field:
    name: str
    type: int
    type_name: str
    repeated: bool


def descriptors(file_descriptor_set: bytes) -> dict[str, dict[int, _Field]]:
    """Message types by full name ("foxglove.SceneUpdate") -> field number -> field."""
    types: dict[str, dict[int, _Field]] = {}

    def message(data: bytes, prefix: str) -> None:
        name, fields, nested = "", {}, []
        for number, _, value in _fields(data):
            if number == 1:
                name = value.decode()
            elif number == 2:  # FieldDescriptorProto
                info: dict[int, Any] = {n: v for n, _, v in _fields(value)}
                fields[info[3]] = _Field(
                    info[1].decode(), info[5], info.get(6, b"").decode().lstrip("."), info.get(4) == _REPEATED
                )
            elif number == 3:
                nested.append(value)
        full = f"{prefix}.{name}" if prefix else name
        types[full] = fields
        for child in nested:
            message(child, full)

    for number, _, file in _fields(file_descriptor_set):
        if number != 1:
            continue
        package = next((v.decode() for n, _, v in _fields(file) if n == 2), "")
        for n, _, value in _fields(file):
            if n == 4:
                message(value, package)
    return types


def _scalar(kind: int, wire: int, value: Any) -> Any:
    if kind == _DOUBLE:
        return struct.unpack("<d", value)[0]
    if kind == _FLOAT:
        return struct.unpack("<f", value)[0]
    if kind == _BOOL:
        return bool(value)
    if kind in (_INT32, _INT64) and value >= 1 << 63:
        return value - (1 << 64)
    if kind in (_SINT32, _SINT64):
        return (value >> 1) ^ -(value & 1)
    if kind in (_FIXED32, _SFIXED32, _FIXED64, _SFIXED64):
        return int.from_bytes(value, "little", signed=kind in (_SFIXED32, _SFIXED64))
    return value


def _packed(kind: int, data: bytes) -> list[Any]:
    if kind == _DOUBLE:
        return list(struct.unpack(f"<{len(data) // 8}d", data))
    if kind == _FLOAT:
        return list(struct.unpack(f"<{len(data) // 4}f", data))
    values, pos = [], 0
    while pos < len(data):
        value, pos = _varint(data, pos)
        values.append(_scalar(kind, 0, value))
    return values


def decode(types: dict[str, dict[int, _Field]], type_name: str, data: bytes) -> dict[str, Any]:
    """Decode one protobuf message to a dict (repeated fields as lists, absent fields absent)."""
    fields = types[type_name]
    out: dict[str, Any] = {}
    for number, wire, value in _fields(data):
        field = fields.get(number)
        if field is None:
            continue
        if field.type == _MESSAGE:
            item: Any = decode(types, field.type_name, value)
        elif field.type == _STRING:
            item = value.decode()
        elif field.type == _BYTES:
            item = bytes(value)
        elif wire == 2 and field.repeated:  # packed scalars
            out.setdefault(field.name, []).extend(_packed(field.type, value))
            continue
        else:
            item = _scalar(field.type, wire, value)
        if field.repeated:
            out.setdefault(field.name, []).append(item)
        else:
            out[field.name] = item
    return out


@dataclass(frozen=True)
class Message:
    """One message read back: its channel, schema, log time (ns) and decoded content."""

    topic: str
    schema_name: str
    schema_encoding: str
    message_encoding: str
    log_time: int
    data: dict[str, Any]


def read_messages(path: Path) -> dict[str, list[Message]]:
    """Every message of an MCAP file, decoded, by topic, in log-time order."""
    by_topic: dict[str, list[Message]] = defaultdict(list)
    cache: dict[int, dict[str, dict[int, _Field]]] = {}
    with path.open("rb") as stream:
        for schema, channel, message in make_reader(stream).iter_messages(log_time_order=True):
            assert schema is not None
            if channel.message_encoding == "json":
                content = json.loads(message.data)
            else:
                assert channel.message_encoding == "protobuf"
                assert schema.encoding == "protobuf"
                if schema.id not in cache:
                    cache[schema.id] = descriptors(schema.data)
                content = decode(cache[schema.id], schema.name, message.data)
            by_topic[channel.topic].append(
                Message(
                    channel.topic,
                    schema.name,
                    schema.encoding,
                    channel.message_encoding,
                    message.log_time,
                    content,
                )
            )
    return dict(by_topic)


def points_xy(line: dict[str, Any]) -> list[tuple[float, float]]:
    """(x, y) of the points of a decoded line primitive or points annotation (0 when absent)."""
    return [(float(p.get("x", 0.0)), float(p.get("y", 0.0))) for p in line.get("points", [])]
