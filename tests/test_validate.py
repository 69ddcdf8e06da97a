"""The validators where data enters: finite_float's fast path for floats is the general path's result."""

from __future__ import annotations

import math
import struct

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums._validate import finite_float
from aura_ums.errors import InputError


class _Real(float):
    """A float subclass: not the fast path's exact float."""


def _bits(value: float) -> bytes:
    return struct.pack("<d", value)


@given(st.floats(allow_nan=False, allow_infinity=False))
def test_finite_float_returns_a_float_bit_for_bit(value: float) -> None:
    for given_value in (value, _Real(value), np.float64(value)):
        result = finite_float(given_value, "x")
        assert type(result) is float
        assert _bits(result) == _bits(value)


def test_finite_float_takes_integers_and_keeps_the_sign_of_zero() -> None:
    assert finite_float(3, "x") == 3.0
    assert type(finite_float(np.int32(3), "x")) is float
    assert math.copysign(1.0, finite_float(-0.0, "x")) == -1.0


@pytest.mark.parametrize(
    ("value", "message"),
    [
        (math.nan, r"x: expected a finite number, got nan"),
        (-math.inf, r"x: expected a finite number, got -inf"),
        (_Real(math.inf), r"x: expected a finite number, got inf"),
        (np.float64(math.nan), r"x: expected a finite number, got nan"),
        (True, r"x: expected a finite number, got True"),
        ("1.0", r"x: expected a finite number, got '1\.0'"),
    ],
)
def test_finite_float_refuses_what_is_not_a_finite_number(value: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        finite_float(value, "x")
