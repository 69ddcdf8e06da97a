"""ImageWindow._trusted, the Expecter's and schemas' unchecked window, against the validated constructor."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums.errors import InputError
from aura_ums.geometry import UNBOUNDED_PIXELS, ImageWindow

bound = st.floats(min_value=-UNBOUNDED_PIXELS, max_value=UNBOUNDED_PIXELS, allow_nan=False)


@given(bound, bound, bound, bound)
def test_equals_the_validated_window(a: float, b: float, c: float, d: float) -> None:
    u0, u1, v0, v1 = min(a, b), max(a, b), min(c, d), max(c, d)
    fast, checked = ImageWindow._trusted(u0, v0, u1, v1), ImageWindow(u0, v0, u1, v1)
    assert fast == checked
    assert repr(fast) == repr(checked)
    assert all(type(getattr(fast, name)) is float for name in ("u_min", "v_min", "u_max", "v_max"))


@pytest.mark.parametrize(
    ("bounds", "message"),
    [
        ((5.0, 0.0, 4.0, 1.0), "u_max: expected >= u_min"),
        ((0.0, 5.0, 4.0, 1.0), "v_max: expected >= v_min"),
        ((0.0, 0.0, math.inf, 1.0), "u_max: expected a finite number"),
        ((-math.inf, 0.0, 1.0, 1.0), "u_min: expected a finite number"),
        ((0.0, math.nan, 1.0, 1.0), "v_min: expected a finite number"),
    ],
)
def test_bad_bounds_raise_as_the_constructor_does(
    bounds: tuple[float, float, float, float], message: str
) -> None:
    with pytest.raises(InputError, match=message):
        ImageWindow._trusted(*bounds)
