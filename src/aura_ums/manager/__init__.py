"""The map manager's side of the uncertainty subsystem (the paper's cartographer processes).

- :class:`Blackboard`: time-stamped :class:`PositionReport` s from the shaft encoders, the
  :class:`IdentifiedLandmarkBuffer` where find-landmark schemas post the observations of
  the landmarks they identify, and the command buffer.
- :class:`UncertaintyMapManager`: the only writer of the spatial uncertainty map. It grows
  the map by the position reports up to each identified observation's time, reduces it
  by the observation, and declares the robot lost (:class:`ManagerState`) when the map
  grows too large or predicted landmarks keep being missed. Each update returns a
  :class:`ManagerStep`. The manager and the blackboard save to and restore from JSON.
"""

from aura_ums.manager._blackboard import Blackboard, PositionReport
from aura_ums.manager._buffer import IdentifiedLandmarkBuffer
from aura_ums.manager._map_manager import (
    REJECT_CLASS_MISMATCH,
    REJECT_STALE,
    REJECT_UNKNOWN_LANDMARK,
    ManagerState,
    ManagerStep,
    ObservationOutcome,
    UncertaintyMapManager,
)

__all__ = [
    "REJECT_CLASS_MISMATCH",
    "REJECT_STALE",
    "REJECT_UNKNOWN_LANDMARK",
    "Blackboard",
    "IdentifiedLandmarkBuffer",
    "ManagerState",
    "ManagerStep",
    "ObservationOutcome",
    "PositionReport",
    "UncertaintyMapManager",
]
