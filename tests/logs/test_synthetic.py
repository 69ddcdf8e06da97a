"""synthetic_log: its arguments are checked and bounded before the drive starts."""

from __future__ import annotations

import numpy as np
import pytest

from aura_ums.errors import InputError
from aura_ums.logs import synthetic_log


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        # these never ended: 1e300 s and 5e6 commands
        (
            {"duration": 1e300},
            r"duration, rate: expected at most 2000000 commands \(duration x rate; .*got 1e\+301",
        ),
        (
            {"duration": 5.0, "rate": 1e6},
            r"duration, rate: expected at most 2000000 commands .*got 5e\+06 \(about",
        ),
        ({"duration": 1e300, "rate": 1e300}, r"duration, rate: expected at most 2000000 commands .*got inf"),
        # named TurnAndRun.run before
        ({"duration": 5.0, "speed": 1e6}, r"speed: expected a number in \[-100, 100\] m/s, got 1000000\.0"),
        (
            {"duration": 5.0, "speed": 100.0, "rate": 1e-3},
            r"speed, rate: expected at most 10000 m a command \(speed / rate\)",
        ),
    ],
)
def test_bad_arguments_are_refused_naming_them(kwargs: dict[str, float], match: str) -> None:
    with pytest.raises(InputError, match=match):
        synthetic_log(np.random.default_rng(1), **kwargs)  # type: ignore[arg-type]
