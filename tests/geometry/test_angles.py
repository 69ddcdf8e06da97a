from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums.errors import InputError
from aura_ums.geometry import angle_difference, wrap_angle

finite_angles = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False)


@given(finite_angles)
def test_wrap_lands_in_half_open_interval(angle: float) -> None:
    wrapped = wrap_angle(angle)
    assert -math.pi < wrapped <= math.pi


@given(finite_angles)
def test_wrap_preserves_direction(angle: float) -> None:
    wrapped = wrap_angle(angle)
    assert math.isclose(math.cos(wrapped), math.cos(angle), abs_tol=1e-9)
    assert math.isclose(math.sin(wrapped), math.sin(angle), abs_tol=1e-9)


@given(st.floats(min_value=-math.pi, max_value=math.pi), st.integers(min_value=-50, max_value=50))
def test_wrap_is_invariant_to_whole_turns(angle: float, turns: int) -> None:
    assert math.isclose(wrap_angle(angle + turns * 2 * math.pi), wrap_angle(angle), abs_tol=1e-9) or (
        # +-pi are the same direction; the seam maps both to +pi up to rounding.
        abs(abs(wrap_angle(angle)) - math.pi) < 1e-9
    )


def test_seam_maps_to_plus_pi() -> None:
    assert wrap_angle(-math.pi) == math.pi
    assert wrap_angle(math.pi) == math.pi
    assert wrap_angle(np.array([-math.pi, math.pi, 3 * math.pi])).tolist() == [math.pi] * 3


def test_tiny_negative_remainder_does_not_give_minus_pi() -> None:
    # (pi - angle) % 2pi rounds up to 2pi here; the result must still be in (-pi, pi].
    angle = math.pi + 2 * math.pi - 1e-17
    assert -math.pi < wrap_angle(angle) <= math.pi
    assert -math.pi < float(wrap_angle(np.array([angle]))[0]) <= math.pi


def test_array_and_scalar_agree() -> None:
    angles = np.linspace(-20, 20, 1001)
    scalar = np.array([wrap_angle(float(a)) for a in angles])
    assert np.allclose(wrap_angle(angles), scalar, atol=1e-12)


def test_difference_takes_the_short_way_across_the_seam() -> None:
    assert math.isclose(angle_difference(-3.0, 3.0), 2 * math.pi - 6.0)
    assert math.isclose(angle_difference(3.0, -3.0), 6.0 - 2 * math.pi)
    assert np.allclose(angle_difference(np.array([0.1]), 0.0), [0.1])


@pytest.mark.parametrize(
    ("angle", "message"),
    [
        (math.nan, r"angle: expected a finite number, got nan"),
        (math.inf, r"angle: expected a finite number, got inf"),
        (np.float64(-math.inf), r"angle: expected a finite number, got -inf"),
        (None, r"angle: expected a finite number, got None"),
        ("1.0", r"angle: expected a finite number, got '1\.0'"),
        (True, r"angle: expected a finite number, got True"),
        (np.array([0.0, np.inf]), r"angle: expected finite numbers, got inf among them"),
        (np.array([[np.nan]]), r"angle: expected finite numbers, got nan among them"),
    ],
)
def test_wrap_angle_refuses_what_has_no_direction(angle: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        wrap_angle(angle)  # type: ignore[call-overload]


@given(finite_angles)
def test_wrap_angle_keeps_its_arithmetic_and_types(angle: float) -> None:
    expected = math.pi - (math.pi - angle) % (2 * math.pi)
    expected = expected + 2 * math.pi if expected <= -math.pi else expected
    assert wrap_angle(angle) == expected
    assert type(wrap_angle(np.float64(angle))) is np.float64
    assert wrap_angle(np.float64(angle)) == expected
    assert wrap_angle(np.array([angle])).tolist() == [expected]


@pytest.mark.parametrize(
    ("a", "b", "message"),
    [
        (math.nan, 0.0, r"a: expected a finite number, got nan"),
        (None, 0.0, r"a: expected a finite number, got None"),
        ("1.0", 0.1, r"a: expected a finite number, got '1\.0'"),
        (0.1, True, r"b: expected a finite number, got True"),
        (np.array([0.1]), "0.2", r"b: expected numbers, got '0\.2'"),
        (np.array([np.inf]), 0.2, r"a: expected finite numbers, got non-finite values"),
    ],
)
def test_angle_difference_names_a_bad_angle(a: object, b: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        angle_difference(a, b)  # type: ignore[call-overload]
