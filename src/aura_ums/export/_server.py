"""The Foxglove WebSocket server behind the live view (needs ``foxglove-sdk``).

Imported only by :mod:`aura_ums.export._live` after it has checked that the optional
dependency is installed. The server runs on the SDK's own threads; the computing thread
publishes on the channels of the server's private context and is paced here.
"""

from __future__ import annotations

import collections
import math
import threading
import time
from collections.abc import Iterable

import foxglove
from foxglove.websocket import ChannelView, Client, ServerListener

from aura_ums.errors import InputError

#: Seconds between two looks at the clock while waiting for a client (Ctrl-C lands between them).
_POLL = 0.1
#: A client's subscriptions reach the listener one channel at a time: streaming waits until
#: none came for this many seconds (at most :data:`_SETTLE_MAX` after the first), or the
#: first messages would reach only the channels subscribed so far.
_SETTLE = 0.25
_SETTLE_MAX = 2.0


class _Subscriptions(ServerListener):
    """Records the topics clients subscribe to, and who still watches (called on the server's threads)."""

    def __init__(self) -> None:
        self.first = threading.Event()
        self.last = 0.0  # time.monotonic() of the latest subscription
        self.topics: collections.deque[str] = collections.deque()
        self._lock = threading.Lock()
        self._active: set[tuple[int, int]] = set()

    def on_subscribe(self, client: Client, channel: ChannelView) -> None:
        with self._lock:
            self._active.add((client.id, channel.id))
        self.topics.append(channel.topic)
        self.last = time.monotonic()
        self.first.set()

    def on_unsubscribe(self, client: Client, channel: ChannelView) -> None:
        # also called for each subscription of a client that disconnects
        with self._lock:
            self._active.discard((client.id, channel.id))

    @property
    def watched(self) -> bool:
        """Whether some client is subscribed to some channel."""
        with self._lock:
            return bool(self._active)


class LiveServer:
    """A Foxglove WebSocket server on a private SDK context, with its subscriptions and pacing.

    Parameters
    ----------
    name : str
        The server's name, shown by Foxglove.
    host : str
        Address to listen on.
    port : int
        Port to listen on (0: any free port; :attr:`port` tells which).
    rate : float
        Real-time factor of :meth:`pace`: 1 follows the log times, 0 does not wait.

    Raises
    ------
    InputError
        When the server cannot listen there: ``port: ...`` for a port in use, ``host: ...``
        for any other refusal.
    """

    def __init__(self, name: str, host: str, port: int, rate: float) -> None:
        self.context = foxglove.Context()
        self._listener = _Subscriptions()
        try:
            self._server = foxglove.start_server(
                name=name, host=host, port=port, context=self.context, server_listener=self._listener
            )
        except RuntimeError as exc:
            if "in use" in str(exc).lower():
                message = f"port: expected a free port on {host}, got {port}, which is in use"
                raise InputError(message) from exc
            raise InputError(f"host: expected an address to listen on, got {host}:{port} ({exc})") from exc
        self.host = host
        self._rate = rate
        self._origin: tuple[int, float] | None = None

    @property
    def port(self) -> int:
        """The port the server listens on."""
        return int(self._server.port)

    def wait_for_client(self, timeout: float | None) -> bool:
        """Block until a client subscribes and its subscriptions settle (True), or ``timeout`` s (False)."""
        deadline = math.inf if timeout is None else time.monotonic() + timeout
        while not self._listener.first.is_set():
            left = deadline - time.monotonic()
            if left <= 0.0:
                return False
            self._listener.first.wait(min(_POLL, left))
        settled = time.monotonic() + _SETTLE_MAX
        while time.monotonic() < min(settled, self._listener.last + _SETTLE):
            time.sleep(_SETTLE / 5)
        return True

    def wait_while_watched(self, timeout: float | None) -> bool:
        """Block while a client is subscribed (True once none is), or ``timeout`` seconds (False)."""
        deadline = math.inf if timeout is None else time.monotonic() + timeout
        while self._listener.watched:
            left = deadline - time.monotonic()
            if left <= 0.0:
                return False
            time.sleep(min(_POLL, left))
        return True

    def subscribed_since(self, topics: Iterable[str]) -> set[str]:
        """Return which of ``topics`` clients subscribed to since the last call (each call drains)."""
        wanted, seen = set(topics), set()
        queue = self._listener.topics
        while queue:
            topic = queue.popleft()
            if topic in wanted:
                seen.add(topic)
        return seen

    def pace(self, ns: int) -> None:
        """Sleep until log time ``ns`` (nanoseconds) is due at the rate; the first call sets the origin."""
        if self._rate <= 0.0:
            return
        now = time.monotonic()
        if self._origin is None:
            self._origin = (ns, now)
            return
        log0, wall0 = self._origin
        due = wall0 + (ns - log0) / 1e9 / self._rate
        if due > now:
            time.sleep(due - now)

    def stop(self) -> None:
        """Stop the server (clients are disconnected)."""
        self._server.stop()
