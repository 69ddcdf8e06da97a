"""orientation_difference (from geometry's angle_difference), and LineSegments' select and within."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums.errors import InputError
from aura_ums.geometry import angle_difference
from aura_ums.perception import LineSegments, orientation_difference

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


NONE: Any = None
LINES = LineSegments([[0.0, 0.0, 10.0, 0.0], [0.0, 0.0, 0.0, 10.0]], [10.0, 10.0])


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: orientation_difference(NONE, [0.1]), "^a: expected orientations \\(numbers\\), got None$"),
        (lambda: orientation_difference([0.1], "x"), "^b: expected orientations \\(numbers\\), got 'x'$"),
        (
            lambda: orientation_difference([np.nan], [0.1]),
            "^a: expected finite numbers, got non-finite values$",
        ),
        (
            lambda: orientation_difference([0.1], 1e300),
            r"^b: expected orientations a number in \[-1000, 1000\] rad, got 1e\+300$",
        ),
        (
            lambda: orientation_difference([0.1, 0.2], [0.1, 0.2, 0.3]),
            r"^b: expected a shape that broadcasts against a's \(2,\), got \(3,\)$",
        ),
        (
            lambda: LINES.select([[0, 0], [1, 0]]),
            r"^keep: expected a 1-D boolean mask or integer indices, got int64",
        ),
        (lambda: LINES.select([0, 5]), r"^keep: expected indices in \[-2, 2\), got 5$"),
        (lambda: LINES.select([0.5]), r"^keep: expected a 1-D boolean mask or integer indices, got float64"),
        (lambda: LINES.select([True]), r"^keep: expected a boolean mask of shape \(2,\), got shape \(1,\)$"),
        (lambda: LINES.within(0.0, NONE), "^tolerance: expected a finite number, got None$"),
        (lambda: LINES.within(0.0, math.nan), "^tolerance: expected a finite number, got nan$"),
        (lambda: LINES.within(0.0, -0.1), "^tolerance: expected a non-negative number, got -0.1$"),
        (lambda: LINES.within(NONE, 0.1), "^orientation: expected a finite number, got None$"),
        (lambda: LINES.within(math.inf, 0.1), "^orientation: expected a finite number, got inf$"),
        (
            lambda: LINES.within(1e300, 0.1),
            r"^orientation: expected a number in \[-1000, 1000\] rad, got 1e\+300$",
        ),
        (
            lambda: LineSegments([[0.0, 0.0, 1.0, 1.0]], "abc"),
            r"^LineSegments\.contrast: expected an \(n,\) array of numbers, got 'abc'$",
        ),
        (
            lambda: LineSegments([[0.0, 0.0, "a", 1.0]], [1.0]),  # type: ignore[arg-type]
            r"^LineSegments\.segments: expected an \(n, 4\) array of numbers, got",
        ),
    ],
)
def test_bad_input_is_refused_naming_the_argument(call: object, match: str) -> None:
    assert callable(call)
    with pytest.raises(InputError, match=match):
        call()


def test_select_and_within_take_what_they_took() -> None:
    assert len(LINES.select([])) == 0
    assert LINES.select([-1]).segments.tolist() == [[0.0, 0.0, 0.0, 10.0]]
    assert LINES.select(np.array([False, True])).segments.tolist() == [[0.0, 0.0, 0.0, 10.0]]
    assert LINES.within(math.pi / 2 + math.pi, 0.1).segments.tolist() == [[0.0, 0.0, 0.0, 10.0]]
    assert len(LINES.within(0.7, 0.1)) == 0
