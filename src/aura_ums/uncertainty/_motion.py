"""Turn-and-run motion commands (and the pose, which geometry defines)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from aura_ums._validate import ANGLE, LENGTH
from aura_ums.geometry import Pose as Pose  # geometry's; uncertainty/_terrain.py imports it from here

#: One foot in metres, for the paper's experiment (which is in feet).
FOOT = 0.3048


@dataclass(frozen=True, slots=True)
class TurnAndRun:
    """A motion command: turn in place, then run straight ahead.

    Parameters
    ----------
    turn : float
        Commanded rotation, radians, counter-clockwise positive, in [-1000, 1000] (a turn
        of 3*pi/2 is a longer turn than one of -pi/2).
    run : float
        Commanded distance, metres, in [0, 10000]. Zero means "turn only".

    Raises
    ------
    InputError
        For a turn or run out of its range (the files' ranges for angles and lengths).

    Examples
    --------
    >>> TurnAndRun(0.5, 2.0)
    TurnAndRun(turn=0.5, run=2.0)
    >>> TurnAndRun(0.0, -1.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: TurnAndRun.run: expected a number in [0, 10000] m, got -1.0
    """

    turn: float
    run: float

    def __post_init__(self) -> None:
        # The ranges of every reader's angles and lengths: a run of 1e300 m grew a NaN area.
        object.__setattr__(self, "turn", ANGLE.check(self.turn, "TurnAndRun.turn"))
        object.__setattr__(self, "run", LENGTH.check(self.run, "TurnAndRun.run"))

    @classmethod
    def _trusted(cls, turn: float, run: float) -> TurnAndRun:
        """Build from floats already checked (finite, ``run >= 0``): a long replay makes one per report."""
        command = object.__new__(cls)
        _set_turn(command, turn)
        _set_run(command, run)
        return command


# The slots' own setters (frozen: the dataclass's __setattr__ refuses), for TurnAndRun._trusted.
_set_turn: Callable[[TurnAndRun, float], None] = TurnAndRun.__dict__["turn"].__set__
_set_run: Callable[[TurnAndRun, float], None] = TurnAndRun.__dict__["run"].__set__
