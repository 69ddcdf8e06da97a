"""Poses and turn-and-run motion commands."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from aura_ums._validate import finite_float, nonnegative_float
from aura_ums.geometry import wrap_angle

#: One foot in metres, for the paper's experiment (which is in feet).
FOOT = 0.3048


@dataclass(frozen=True, slots=True)
class Pose:
    """A robot pose in the world frame.

    Parameters
    ----------
    x, y : float
        Position of the robot's reference point, metres (x east, y north).
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
        object.__setattr__(self, "x", finite_float(self.x, "Pose.x"))
        object.__setattr__(self, "y", finite_float(self.y, "Pose.y"))
        object.__setattr__(self, "heading", wrap_angle(finite_float(self.heading, "Pose.heading")))

    def as_array(self) -> NDArray[np.float64]:
        """Return ``[x, y, heading]`` as a float array of shape (3,)."""
        return np.array([self.x, self.y, self.heading])


@dataclass(frozen=True, slots=True)
class TurnAndRun:
    """A motion command: turn in place, then run straight ahead.

    Parameters
    ----------
    turn : float
        Commanded rotation, radians, counter-clockwise positive. Any finite amount
        (a turn of 3*pi/2 is a longer turn than one of -pi/2).
    run : float
        Commanded distance, metres, >= 0. Zero means "turn only".

    Raises
    ------
    InputError
        For a non-finite turn or run, or a negative run.

    Examples
    --------
    >>> TurnAndRun(0.5, 2.0)
    TurnAndRun(turn=0.5, run=2.0)
    >>> TurnAndRun(0.0, -1.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: TurnAndRun.run: expected a non-negative number, got -1.0
    """

    turn: float
    run: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "turn", finite_float(self.turn, "TurnAndRun.turn"))
        object.__setattr__(self, "run", nonnegative_float(self.run, "TurnAndRun.run"))
