"""What the exporters read from a replay, as structural types (no import of :mod:`aura_ums.logs`).

:func:`~aura_ums.export.write_replay_mcap` reads only these attributes, so it works on
:class:`aura_ums.logs.ReplayResult` and on any object shaped like it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

from aura_ums.manager import ManagerState
from aura_ums.uncertainty import Pose, SpatialUncertaintyMap


class LogLandmarkLike(Protocol):
    """A landmark of a log: id, position (m), uncertainty radius (m), heights (m, None: unknown), symbol."""

    @property
    def id(self) -> str: ...

    @property
    def x(self) -> float: ...

    @property
    def y(self) -> float: ...

    @property
    def position_uncertainty(self) -> float: ...

    @property
    def z_bottom(self) -> float | None: ...

    @property
    def z_top(self) -> float | None: ...

    @property
    def symbol(self) -> str: ...


class LogMetaLike(Protocol):
    """A log's metadata: only its name is read."""

    @property
    def name(self) -> str: ...


class RobotLogLike(Protocol):
    """A robot log: its metadata and landmark list are read."""

    @property
    def meta(self) -> LogMetaLike: ...

    @property
    def landmarks(self) -> Sequence[LogLandmarkLike]: ...


class ReplayStepLike(Protocol):
    """One step of a replay: the map after the step, the true pose when known, counters."""

    @property
    def time(self) -> float: ...

    @property
    def map(self) -> SpatialUncertaintyMap: ...

    @property
    def truth(self) -> Pose | None: ...

    @property
    def inside(self) -> bool | None: ...

    @property
    def accepted(self) -> int: ...

    @property
    def rejected(self) -> int: ...

    @property
    def update_us(self) -> float: ...

    @property
    def state(self) -> ManagerState: ...


class ReplayLike(Protocol):
    """A replay of a log (:class:`aura_ums.logs.ReplayResult`): the log and its steps."""

    @property
    def log(self) -> RobotLogLike: ...

    @property
    def steps(self) -> Sequence[ReplayStepLike]: ...
