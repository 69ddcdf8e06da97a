"""A replay's saved state: where in the log it stopped, with the manager and blackboard as JSON.

The document wraps the manager's and the blackboard's own versioned JSON
(:meth:`UncertaintyMapManager.to_json`, :meth:`Blackboard.to_json`), whose floats are
written with ``repr``: what is restored is bit for bit what was saved, so a resumed
replay ends with exactly the map of an uninterrupted one.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

from aura_ums._files import Fields, parse_json, read_text, write_text_atomic
from aura_ums.errors import InputError

#: The ``format`` of a saved replay state.
STATE_FORMAT = "aura_ums.ReplayState"
#: Its version; bumped when the layout or the meaning of a field changes (2: a piece of
#: odometry that turns while it runs is two position reports, so ``reports_posted`` counts
#: them both; 3: ``inputs``, what else the replay ran with). Version 2 still reads, with no
#: inputs to check.
STATE_VERSION = 3
_READ_VERSIONS = (2, 3)
_KEYS = (
    "format",
    "version",
    "log",
    "frames_done",
    "reports_posted",
    "last_time",
    "log_digest",
    "manager",
    "blackboard",
    "inputs",
)


@dataclass(frozen=True, slots=True)
class ReplayState:
    """Where a replay stopped, to resume it with ``replay_log(..., resume=state)``.

    Attributes
    ----------
    log_name : str
        ``meta.name`` of the log replayed.
    frames_done : int
        Frames replayed (>= 0); the resumed replay starts at the next one.
    reports_posted : int
        Position reports posted to the blackboard so far.
    last_time : float
        Time of the last frame replayed, s (nan when none was).
    log_digest : str
        SHA-256 (hex) of the observations replayed (times, landmark ids, bearings,
        ranges): a state is resumed only on the log it was saved from.
    manager_json : str
        :meth:`UncertaintyMapManager.to_json` after that frame.
    blackboard_json : str
        :meth:`Blackboard.to_json` after that frame.
    inputs : mapping of str to str
        What else the replay ran with, that its manager's JSON does not hold (the landmark
        class, the sensor bounds, the terrain table...), each as text: a resumed replay
        must run with the same (empty: not recorded, a version 2 file).

    Examples
    --------
    >>> import numpy as np
    >>> from aura_ums.logs import replay_log, synthetic_log
    >>> from aura_ums.uncertainty import TerrainTable
    >>> log = synthetic_log(np.random.default_rng(3), duration=20.0)
    >>> table = TerrainTable({"floor": TerrainTable.default()["tile"]})
    >>> whole = replay_log(log, table)
    >>> half = replay_log(log, table, until=10.0, save_state=True)
    >>> saved = ReplayState.from_json(half.state.to_json())
    >>> rest = replay_log(log, table, resume=saved)
    >>> rest.steps[-1].map.polygon.vertices.tobytes() == whole.steps[-1].map.polygon.vertices.tobytes()
    True
    >>> ReplayState.from_json('{"format": "aura_ums.ReplayState", "version": 9}')
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: <replay state JSON>: version: expected 3, got 9
    """

    log_name: str
    frames_done: int
    reports_posted: int
    last_time: float
    log_digest: str
    manager_json: str
    blackboard_json: str
    inputs: Mapping[str, str] = field(default_factory=lambda: MappingProxyType({}))

    def to_json(self) -> str:
        """Return the state as strict JSON text (no NaN: a missing time is ``null``)."""
        body = {
            "format": STATE_FORMAT,
            "version": STATE_VERSION,
            "log": self.log_name,
            "frames_done": self.frames_done,
            "reports_posted": self.reports_posted,
            "last_time": self.last_time if math.isfinite(self.last_time) else None,
            "log_digest": self.log_digest,
            "manager": json.loads(self.manager_json),
            "blackboard": json.loads(self.blackboard_json),
            "inputs": dict(self.inputs),
        }
        return json.dumps(body, indent=1, allow_nan=False) + "\n"

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write :meth:`to_json` to ``path`` atomically (the old file or the whole new one)."""
        return write_text_atomic(path, self.to_json())

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> ReplayState:
        """Read a state saved by :meth:`save`; a bad file fails naming it and the place."""
        return cls.from_json(read_text(path, kind="replay state JSON"), source=str(path))

    @classmethod
    def from_json(cls, text: str, *, source: str = "<replay state JSON>") -> ReplayState:
        """Parse :meth:`to_json`'s text; anything else fails naming ``source`` and the place."""
        if not isinstance(text, str):
            raise InputError(f"text: expected JSON text (str), got {type(text).__name__}")
        fields = Fields(source, "json")
        top: dict[str, Any] = fields.table(parse_json(text, source), "")
        if top.get("format") != STATE_FORMAT:
            fields.fail("format", f"expected {STATE_FORMAT!r}, got {fields.describe(top.get('format'))}")
        version = top.get("version")
        if version not in _READ_VERSIONS or isinstance(version, bool):
            fields.fail("version", f"expected {STATE_VERSION}, got {fields.describe(version)}")
        keys = _KEYS if version == STATE_VERSION else _KEYS[:-1]
        for key in top:
            if key not in keys:
                fields.fail("", f"expected only the keys {list(keys)}, got {fields.describe(key)}")
        for key in keys:
            if key not in top:
                fields.fail("", f"expected a key {key!r}, got none")
        inputs = {
            name: fields.string(value, f"inputs.{name}")
            for name, value in fields.table(top.get("inputs", {}), "inputs").items()
        }
        last = top["last_time"]
        return cls(
            fields.string(top["log"], "log"),
            fields.integer(top["frames_done"], "frames_done", minimum=0),
            fields.integer(top["reports_posted"], "reports_posted", minimum=0),
            math.nan if last is None else fields.number(last, "last_time"),
            fields.string(top["log_digest"], "log_digest"),
            json.dumps(fields.table(top["manager"], "manager")),
            json.dumps(fields.table(top["blackboard"], "blackboard")),
            MappingProxyType(dict(inputs)),
        )
