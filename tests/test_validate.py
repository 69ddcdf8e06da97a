"""The validators where data enters: finite_float's fast path for floats is the general path's result."""

from __future__ import annotations

import math
import struct
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums._validate import bounded_count, finite_float, float_array, points_array
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


@pytest.mark.parametrize(
    ("value", "message"),
    [
        (
            [["0", "0"], ["1", "0"]],
            r"p: expected an \(n, 2\) array of numbers, got \[\['0', '0'\], \['1', '0'\]\]",
        ),
        ([[True, False], [True, True]], r"p: expected an \(n, 2\) array of numbers, got \[\[True, False\]"),
        (
            np.array([[0, 0], [1, 0]], dtype=complex),
            r"p: expected an \(n, 2\) array of numbers, got array\(\[\[0\.\+0\.j, 0\.\+0\.j\], \[1",
        ),
        ([[1, None]], r"p: expected an \(n, 2\) array of numbers, got \[\[1, None\]\]"),
        (
            np.zeros((2, 2), dtype="datetime64[s]"),
            r"p: expected an \(n, 2\) array of numbers, got array\(\[\['1970-01-01T00:00:00'",
        ),
    ],
)
def test_points_array_refuses_strings_bools_and_complex(value: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        points_array(value, "p")  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("value", "message"),
    [
        ("1.0", r"h: expected numbers, got '1\.0'"),
        (True, r"h: expected numbers, got True"),
        ([0.5, 1 + 2j], r"h: expected numbers, got \[0\.5, \(1\+2j\)\]"),
        (np.array(["x"] * 100), r"h: expected numbers, got array\(\['x', .*', \.\.\.$"),
    ],
)
def test_float_array_refuses_strings_bools_and_complex(value: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        float_array(value, "h")  # type: ignore[arg-type]


def test_numbers_arrays_take_integers_floats_and_real_objects_bit_for_bit() -> None:
    assert points_array([[0, 1], [2, 3]], "p").tolist() == [[0.0, 1.0], [2.0, 3.0]]
    objects: object = [(Fraction(1, 3), 2**70)]
    assert points_array(objects, "p").tolist() == [[1 / 3, float(2**70)]]  # type: ignore[arg-type]
    assert points_array(np.array([[1, 2]], dtype=np.uint8), "p").dtype == np.float64
    given = np.array([[0.1, 0.2]])
    assert points_array(given, "p") is not given  # a copy, as ever
    same = np.array([0.1, 0.2])
    assert float_array(same, "h") is same  # no copy of floats, as ever
    assert float_array(np.float32(0.1), "h") == np.float64(np.float32(0.1))


def test_bounded_count_takes_integers_in_range_only() -> None:
    assert bounded_count(np.int64(5), "n", 0, 10, "things") == 5
    assert type(bounded_count(np.int64(5), "n", 0, 10, "things")) is int
    for bad in (3.0, True, None, "3", -1):
        with pytest.raises(InputError, match=r"n: expected an integer >= 0, got"):
            bounded_count(bad, "n", 0, 10, "things")
    with pytest.raises(InputError, match=r"n: expected at most 10 things \(a kB\), got 11"):
        bounded_count(11, "n", 0, 10, "things (a kB)")
