"""ImageWindow.meets_pixel_of: a window judged as the set of whole pixels it meets."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums.errors import InputError
from aura_ums.geometry import ImageWindow

coordinate = st.floats(min_value=-1e4, max_value=1e4, allow_nan=False)


def window_of(a: float, b: float, c: float, d: float) -> ImageWindow:
    return ImageWindow(min(a, b), min(c, d), max(a, b), max(c, d))


@given(coordinate, coordinate, coordinate, coordinate, coordinate, coordinate)
def test_meets_the_pixel_exactly_when_its_square_overlaps_the_window(
    a: float, b: float, c: float, d: float, u: float, v: float
) -> None:
    window = window_of(a, b, c, d)
    # The unit square of the pixel the point falls in, from its corners on the integer-and-a-half grid.
    left, top = math.floor(u + 0.5) - 0.5, math.floor(v + 0.5) - 0.5
    overlaps = max(left, window.u_min) <= min(left + 1.0, window.u_max) and max(top, window.v_min) <= min(
        top + 1.0, window.v_max
    )
    assert bool(window.meets_pixel_of((u, v))) == overlaps


@given(coordinate, coordinate, coordinate, coordinate, coordinate, coordinate)
def test_holds_every_point_it_contains_and_none_a_pixel_or_more_away(
    a: float, b: float, c: float, d: float, u: float, v: float
) -> None:
    window = window_of(a, b, c, d)
    if window.contains((u, v)):
        assert window.meets_pixel_of((u, v))
    grown = window.expanded(1.0)
    if window.meets_pixel_of((u, v)):
        assert grown.contains((u, v))


def test_a_bound_inside_a_pixel_keeps_the_whole_pixel() -> None:
    window = ImageWindow(10.2, 20.0, 50.0, 40.7)
    points = [(9.6, 30.0), (9.4, 30.0), (50.0, 41.4), (50.0, 41.5), (30.0, float("nan"))]
    assert window.meets_pixel_of(points).tolist() == [True, False, True, False, False]
    assert window.contains(points).tolist() == [False, False, False, False, False]


def test_keeps_the_shape_of_its_input() -> None:
    window = ImageWindow(0.0, 0.0, 10.0, 10.0)
    points = np.zeros((3, 4, 2))
    assert window.meets_pixel_of(points).shape == (3, 4)


@pytest.mark.parametrize(
    ("pixels", "message"), [(5.0, r"expected shape \(\.\.\., 2\)"), ("x", "expected an")]
)
def test_refuses_what_is_not_points(pixels: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        ImageWindow(0.0, 0.0, 1.0, 1.0).meets_pixel_of(pixels)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("pixels", "message"),
    [
        ([[True, False]], r"pixels: expected an \(n, 2\) array of numbers, got \[\[True, False\]\]"),
        ([["1", "2"]], r"pixels: expected an \(n, 2\) array of numbers, got \[\['1', '2'\]\]"),
        (
            np.array([[1 + 0j, 2]]),
            r"pixels: expected an \(n, 2\) array of numbers, got array\(\[\[1\.\+0\.j, 2\.\+0\.j\]\]\)",
        ),
        (5.0, r"pixels: expected shape \(\.\.\., 2\), got \(\)"),
        ([[1.0, 2.0, 3.0]], r"pixels: expected shape \(\.\.\., 2\), got \(1, 3\)"),
    ],
)
def test_pixel_tests_refuse_what_is_no_pixel(pixels: object, message: str) -> None:
    window = ImageWindow(0.0, 0.0, 10.0, 10.0)
    with pytest.raises(InputError, match=message):
        window.contains(pixels)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=message):
        window.meets_pixel_of(pixels)  # type: ignore[arg-type]


def test_pixel_tests_keep_nan_and_integer_pixels() -> None:
    window = ImageWindow(0.0, 0.0, 10.0, 10.0)
    pixels = [[5, 5], [math.nan, 5.0], [math.inf, 5.0]]
    assert window.contains(pixels).tolist() == [True, False, False]  # type: ignore[arg-type]
    assert window.meets_pixel_of(pixels).tolist() == [True, False, False]  # type: ignore[arg-type]


def test_expanded_refuses_a_margin_beyond_any_image() -> None:
    window = ImageWindow(0.0, 0.0, 10.0, 10.0)
    assert window.expanded(20_000).u_min == -20_000.0
    with pytest.raises(
        InputError, match=r"margin: expected at most 20000 pixels \(an image's longest side\), got 1e\+300"
    ):
        window.expanded(1e300)
    with pytest.raises(InputError, match=r"margin: expected a finite number, got nan"):
        window.expanded(math.nan)
