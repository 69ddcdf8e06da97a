"""The pose: a position and a heading in the world frame."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from aura_ums._validate import COORDINATE, finite_float
from aura_ums.geometry._angles import wrap_angle


@dataclass(frozen=True, slots=True)
class Pose:
    """A robot pose in the world frame.

    Parameters
    ----------
    x, y : float
        Position of the robot's reference point, metres (x east, y north), each in
        [-1e6, 1e6] (the coordinates' range: subtract a local origin from UTM-sized ones).
    heading : float
        Radians counter-clockwise from world +x; wrapped to (-pi, pi].

    Examples
    --------
    >>> import math
    >>> Pose(1.0, 2.0, 3 * math.pi).heading == math.pi
    True
    """

    x: float
    y: float
    heading: float

    def __post_init__(self) -> None:
        # Within the coordinates' range: a pose at 1e16 m made a map of one point.
        object.__setattr__(self, "x", COORDINATE.check(self.x, "Pose.x"))
        object.__setattr__(self, "y", COORDINATE.check(self.y, "Pose.y"))
        object.__setattr__(self, "heading", wrap_angle(finite_float(self.heading, "Pose.heading")))

    def as_array(self) -> NDArray[np.float64]:
        """Return ``[x, y, heading]`` as a float array of shape (3,)."""
        return np.array([self.x, self.y, self.heading])
