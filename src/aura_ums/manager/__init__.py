"""The map manager's side of the uncertainty subsystem.

For now the :class:`IdentifiedLandmarkBuffer`, where find-landmark schemas post the
time-stamped observations of the landmarks they identify and from which the uncertainty
map manager takes them in time order.
"""

from aura_ums.manager._buffer import IdentifiedLandmarkBuffer

__all__ = ["IdentifiedLandmarkBuffer"]
