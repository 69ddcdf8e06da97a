from __future__ import annotations

import pytest

from aura_ums import FOOT, InputError, TurnAndRun


def test_foot_is_exact() -> None:
    assert FOOT == 0.3048


def test_zero_command_is_valid() -> None:
    assert TurnAndRun(0.0, 0.0) == TurnAndRun(0, 0)


@pytest.mark.parametrize(
    ("turn", "run", "message"),
    [
        (float("nan"), 1.0, r"TurnAndRun.turn: expected a finite number, got nan"),
        (0.0, float("inf"), r"TurnAndRun.run: expected a finite number, got inf"),
        (0.0, -0.5, r"TurnAndRun.run: expected a number in \[0, 10000\] m, got -0.5"),
        (0.0, 1e300, r"TurnAndRun.run: expected a number in \[0, 10000\] m, got 1e\+300"),
        (1e300, 1.0, r"TurnAndRun.turn: expected a number in \[-1000, 1000\] rad, got 1e\+300"),
        ("1", 1.0, r"TurnAndRun.turn: expected a finite number, got '1'"),
        (True, 1.0, r"TurnAndRun.turn: expected a finite number, got True"),
    ],
)
def test_bad_commands_are_refused(turn: object, run: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        TurnAndRun(turn, run)  # type: ignore[arg-type]
