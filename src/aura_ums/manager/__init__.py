"""The map manager's side of the uncertainty subsystem (the paper's cartographer processes).

- :class:`Blackboard`: time-stamped :class:`PositionReport` s from the shaft encoders, the
  :class:`IdentifiedLandmarkBuffer` where find-landmark schemas post the observations of
  the landmarks they identify, and the command buffer.
- :class:`UncertaintyMapManager`: the only writer of the spatial uncertainty map, and the
  localizer. It grows the map by the position reports up to each identified
  observation's time, reduces it by the observation (or rejects it, saying why:
  :class:`RejectReason`), keeps an envelope map under worst-case bounds and re-localizes
  from it when outliers have led the map astray, and declares the robot lost
  (:class:`ManagerState`) when the map grows too large or predicted landmarks keep being
  missed. Each update returns a :class:`ManagerStep`. The same in simulation, replay and
  live use. The manager and the blackboard save to and restore from JSON.
- :class:`ManagerSettings`: every setting of the manager, with its unit, range and help
  (:class:`SettingInfo`), from which the command line, scenario files, replay options and
  saved state are built. :class:`MapProfile` names the three representations measured on
  real logs (the paper's product map, heading slices, slices with the relaxed intersection).
"""

from aura_ums.manager._blackboard import Blackboard, PositionReport
from aura_ums.manager._buffer import IdentifiedLandmarkBuffer
from aura_ums.manager._map_manager import (
    ManagerState,
    ManagerStep,
    ObservationOutcome,
    UncertaintyMapManager,
)
from aura_ums.manager._reasons import RejectReason
from aura_ums.manager._settings import ManagerSettings, MapProfile, SettingInfo

__all__ = [
    "Blackboard",
    "IdentifiedLandmarkBuffer",
    "ManagerSettings",
    "ManagerState",
    "ManagerStep",
    "MapProfile",
    "ObservationOutcome",
    "PositionReport",
    "RejectReason",
    "SettingInfo",
    "UncertaintyMapManager",
]
