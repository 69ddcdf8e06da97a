"""A small client of the Foxglove WebSocket protocol, to watch the live view in tests.

It speaks the protocol of Foxglove's ws-protocol spec (``foxglove.websocket.v1``; the
Foxglove SDK's server names the same protocol ``foxglove.sdk.v1``, and the client offers
both): it reads the server's ``advertise`` operations, subscribes to channels, and decodes
each binary ``Message Data`` frame (opcode 1: subscription id, log time, payload) with the
schema its channel advertised: protobuf through the descriptors the server sent
(:mod:`tests.export.export_helpers`), JSON with :mod:`json`.
"""

from __future__ import annotations

import base64
import contextlib
import json
import struct
import time
from dataclasses import dataclass
from typing import Any

from websockets.exceptions import ConnectionClosed
from websockets.sync.client import ClientConnection, connect

from tests.export.export_helpers import decode, descriptors

#: The protocol names a client offers, the SDK's first.
SUBPROTOCOLS = ("foxglove.sdk.v1", "foxglove.websocket.v1")
_MESSAGE_DATA = 0x01
_HEADER = struct.Struct("<BIQ")


@dataclass(frozen=True)
class Channel:
    """A channel as the server advertised it."""

    id: int
    topic: str
    encoding: str
    schema_name: str
    schema_encoding: str
    schema: bytes


@dataclass(frozen=True)
class Received:
    """One message as the client received and decoded it."""

    topic: str
    schema_name: str
    log_time: int
    data: dict[str, Any]


class LiveClient:
    """A connection to a live view: advertised channels, subscriptions, decoded messages."""

    def __init__(self, url: str) -> None:
        self._stack = contextlib.ExitStack()
        self.socket: ClientConnection = self._stack.enter_context(
            connect(url, subprotocols=list(SUBPROTOCOLS), proxy=None, open_timeout=10)  # type: ignore[arg-type]
        )
        self.channels: dict[int, Channel] = {}
        self.server_info: dict[str, Any] = {}
        self._subscribed: dict[int, Channel] = {}
        self._types: dict[int, Any] = {}
        self._pending: list[Received] = []

    def close(self) -> None:
        self._stack.close()

    def __enter__(self) -> LiveClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _text(self, text: str) -> None:
        message = json.loads(text)
        if message["op"] == "serverInfo":
            self.server_info = message
        elif message["op"] == "advertise":
            for c in message["channels"]:
                schema = c["schema"]
                raw = base64.b64decode(schema) if c["schemaEncoding"] == "protobuf" else schema.encode()
                self.channels[c["id"]] = Channel(
                    c["id"], c["topic"], c["encoding"], c["schemaName"], c["schemaEncoding"], raw
                )

    def _binary(self, data: bytes) -> None:
        if data[0] != _MESSAGE_DATA:
            return
        _, subscription, log_time = _HEADER.unpack_from(data)
        payload = data[_HEADER.size :]
        channel = self._subscribed[subscription]
        if channel.encoding == "json":
            content = json.loads(payload)
        else:
            if channel.id not in self._types:
                self._types[channel.id] = descriptors(channel.schema)
            content = decode(self._types[channel.id], channel.schema_name, payload)
        self._pending.append(Received(channel.topic, channel.schema_name, log_time, content))

    def pump(self, timeout: float) -> bool:
        """Read one frame (up to ``timeout`` s); False when none came or the server closed."""
        try:
            frame = self.socket.recv(timeout=timeout)
        except (TimeoutError, ConnectionClosed):
            return False
        if isinstance(frame, str):
            self._text(frame)
        else:
            self._binary(frame)
        return True

    def advertised(self, topics: set[str], timeout: float = 10.0) -> dict[str, Channel]:
        """Wait until every topic is advertised; return the channels by topic."""
        deadline = time.monotonic() + timeout
        while not topics <= {c.topic for c in self.channels.values()} and time.monotonic() < deadline:
            self.pump(0.2)
        return {c.topic: c for c in self.channels.values()}

    def subscribe(self, topics: set[str]) -> None:
        """Subscribe to the advertised channels of these topics (subscription id = channel id)."""
        chosen = [c for c in self.channels.values() if c.topic in topics]
        for channel in chosen:
            self._subscribed[channel.id] = channel
        subscriptions = [{"id": c.id, "channelId": c.id} for c in chosen]
        self.socket.send(json.dumps({"op": "subscribe", "subscriptions": subscriptions}))

    def take(self) -> list[Received]:
        """Return the messages decoded so far and forget them."""
        taken, self._pending = self._pending, []
        return taken
