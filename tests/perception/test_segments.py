"""orientation_difference: the difference of line orientations, built on geometry's angle_difference."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from aura_ums.geometry import angle_difference
from aura_ums.perception import orientation_difference

angles = st.floats(min_value=-20.0, max_value=20.0, allow_nan=False)


@given(angles, angles)
def test_is_the_smaller_turn_between_two_lines(a: float, b: float) -> None:
    difference = float(orientation_difference(a, b))
    assert 0.0 <= difference <= math.pi / 2
    assert math.isclose(difference, float(orientation_difference(b, a)), abs_tol=1e-12)
    # a line turned half a turn is the same line
    assert math.isclose(float(orientation_difference(a + math.pi, b)), difference, abs_tol=1e-12)
    # folded from the signed difference of directions
    turn = abs(angle_difference(a, b))
    assert difference == min(turn, math.pi - turn)


@given(angles, angles)
def test_agrees_with_the_difference_modulo_pi_to_rounding(a: float, b: float) -> None:
    modulo = math.fmod(a - b, math.pi) % math.pi
    assert math.isclose(float(orientation_difference(a, b)), min(modulo, math.pi - modulo), abs_tol=1e-12)


def test_broadcasts_like_its_arguments() -> None:
    result = orientation_difference(np.array([[0.1], [3.1]]), np.array([0.0, math.pi / 2]))
    assert result.shape == (2, 2)
    assert np.allclose(result, [[0.1, math.pi / 2 - 0.1], [math.pi - 3.1, 3.1 - math.pi / 2]])
