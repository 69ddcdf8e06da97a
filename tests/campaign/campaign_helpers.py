"""Tasks that misbehave on purpose, to test a campaign's retries, and run comparisons.

They are test hooks only: a task wrapper the test hands to the engine, never an option a
user can set. Each keeps its "first attempt" marker in a file, since the attempt that
misbehaves and the one that succeeds run in different worker processes.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from aura_ums.errors import InputError
from aura_ums.sim import RunResult

#: Seconds a hanging attempt sleeps: far beyond any test's timeout.
HANG_S = 600.0


def _first_attempt(marker: Path) -> bool:
    try:
        marker.touch(exist_ok=False)
    except FileExistsError:
        return False
    return True


def _key(item: Any) -> Any:
    if isinstance(item, tuple):  # a batch of seeds
        return tuple(_key(part) for part in item)
    return getattr(item, "spawn_key", item)


@dataclass(frozen=True)
class KillOnce:
    """Run ``task``, but the first attempt on item number ``victim`` kills its worker process."""

    task: Callable[[Any], Any]
    victim: int
    marker: Path
    items: Sequence[Any]

    def __call__(self, item: Any) -> Any:
        # A seed arrives as a copy on the worker: it is told by its spawn key.
        if _key(item) == _key(self.items[self.victim]) and _first_attempt(self.marker):
            os._exit(1)  # the worker dies as on a crash: no cleanup, no exception
        return self.task(item)


@dataclass(frozen=True)
class KillAlways:
    """Kill the worker on every attempt at ``victim``: a run that can never finish."""

    victim: int

    def __call__(self, item: int) -> int:
        if item == self.victim:
            os._exit(1)
        return item


@dataclass(frozen=True)
class HangOnce:
    """Sleep :data:`HANG_S` on the first attempt at ``victim`` (a stuck run); else square the item."""

    victim: int
    marker: Path

    def __call__(self, item: int) -> int:
        if item == self.victim and _first_attempt(self.marker):
            time.sleep(HANG_S)
        return item * item


@dataclass(frozen=True)
class FailOn:
    """Raise an error of the run's own at ``victim`` (bad input): not a lost worker."""

    victim: int

    def __call__(self, item: int) -> int:
        if item == self.victim:
            raise InputError(f"item: expected anything but {self.victim}, got it")
        return item


def run_figures(result: RunResult) -> list[tuple[object, ...]]:
    """Everything a run decided, frame by frame (not its timings): equal runs give equal lists."""
    return [
        (
            r.index,
            r.time,
            r.true_pose,
            r.inside,
            r.map_after.polygon.vertices.tobytes(),
            r.map_after.wedge,
            r.found,
            r.accepted,
            r.rejected,
            r.state,
            r.injected,
            r.excluded,
        )
        for r in result.records
    ] + [(result.completed, result.predictions, result.hits)]
