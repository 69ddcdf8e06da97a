from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums import HeadingWedge, InputError
from aura_ums.geometry import wedges_contain, wrap_angle

angles = st.floats(min_value=-4 * math.pi, max_value=4 * math.pi, allow_nan=False)
extents = st.floats(min_value=0.0, max_value=3.5, allow_nan=False)


def test_wedge_across_the_seam() -> None:
    wedge = HeadingWedge(math.pi - 0.05, cw=0.1, ccw=0.2)
    assert wedge.contains(math.pi)
    assert wedge.contains(-math.pi)
    assert wedge.contains(-math.pi + 0.14)
    assert not wedge.contains(-math.pi + 0.16)
    assert wedge.contains(math.pi - 0.15)
    assert not wedge.contains(math.pi - 0.16)
    assert math.isclose(wedge.width, 0.3)


def test_lo_hi_are_wrapped() -> None:
    wedge = HeadingWedge(3.0, cw=0.1, ccw=0.5)
    assert math.isclose(wedge.lo, 2.9)
    assert math.isclose(wedge.hi, 3.5 - 2 * math.pi)


def test_full_circle_contains_everything() -> None:
    wedge = HeadingWedge(0.3, cw=4.0, ccw=3.0)
    assert wedge.is_full_circle
    assert wedge.width == 2 * math.pi
    assert np.all(wedge.contains(np.linspace(-10, 10, 101)))
    assert HeadingWedge.full_circle().is_full_circle


def test_zero_width_wedge_holds_its_centre_only() -> None:
    wedge = HeadingWedge(1.0, 0.0, 0.0)
    assert wedge.contains(1.0)
    assert wedge.contains(1.0 + 2 * math.pi)
    assert not wedge.contains(1.0 + 1e-6)


def test_contains_returns_bool_for_scalars_and_arrays_for_arrays() -> None:
    wedge = HeadingWedge(0.0, 0.1, 0.1)
    assert wedge.contains(0.0) is True
    result = wedge.contains(np.array([[0.0, 1.0]]))
    assert isinstance(result, np.ndarray)
    assert result.shape == (1, 2)


@given(angles, extents, extents, st.floats(min_value=0.0, max_value=1.0), st.integers(-3, 3))
def test_every_heading_between_lo_and_hi_is_inside_at_any_winding(
    center: float, cw: float, ccw: float, fraction: float, turns: int
) -> None:
    wedge = HeadingWedge(center, cw, ccw)
    heading = center - cw + fraction * (cw + ccw) + turns * 2 * math.pi
    assert wedge.contains(heading)


@given(angles, extents, extents, st.floats(min_value=1e-6, max_value=1.0))
def test_headings_outside_are_refused(center: float, cw: float, ccw: float, fraction: float) -> None:
    wedge = HeadingWedge(center, cw, ccw)
    gap = 2 * math.pi - (cw + ccw)
    if gap <= 1e-6:
        assert wedge.is_full_circle or wedge.contains(center + ccw + fraction * gap)
        return
    outside = center + ccw + 1e-7 + fraction * (gap - 2e-7)
    assert not wedge.contains(outside)


@given(angles, extents, extents)
def test_extents_stay_non_negative_and_centre_wrapped(center: float, cw: float, ccw: float) -> None:
    wedge = HeadingWedge(center, cw, ccw).widened(0.1, 0.2).rotated(5.0)
    assert wedge.cw >= 0
    assert wedge.ccw >= 0
    assert -math.pi < wedge.center <= math.pi
    assert wedge.contains(wedge.center)


def test_from_bounds_across_seam_and_with_centre() -> None:
    wedge = HeadingWedge.from_bounds(3.0, -3.0)
    assert math.isclose(wedge.width, 2 * math.pi - 6.0)
    assert wedge.contains(math.pi)
    off_centre = HeadingWedge.from_bounds(3.0, -3.0, center=3.1)
    assert math.isclose(off_centre.cw, 0.1)
    with pytest.raises(InputError, match=r"center: expected a heading inside"):
        HeadingWedge.from_bounds(0.0, 1.0, center=2.0)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"center": float("nan"), "cw": 0.1, "ccw": 0.1}, r"HeadingWedge.center: expected a finite number"),
        ({"center": 0.0, "cw": -0.1, "ccw": 0.1}, r"HeadingWedge.cw: expected a non-negative number"),
        ({"center": 0.0, "cw": 0.1, "ccw": float("inf")}, r"HeadingWedge.ccw: expected a finite number"),
    ],
)
def test_bad_wedges_are_refused(kwargs: dict[str, float], message: str) -> None:
    with pytest.raises(InputError, match=message):
        HeadingWedge(**kwargs)


def test_contains_refuses_nan() -> None:
    with pytest.raises(InputError, match=r"heading: expected finite numbers"):
        HeadingWedge(0.0, 0.1, 0.1).contains(float("nan"))


@given(
    st.one_of(
        st.floats(-50.0, 50.0), st.sampled_from([math.pi, -math.pi, 3 * math.pi, -3 * math.pi, 0.0, -0.0])
    )
)
def test_trusted_wraps_the_centre_as_wrap_angle_does(center: float) -> None:
    """The library's unchecked constructor wraps exactly as wrap_angle and HeadingWedge() do."""
    wedge = HeadingWedge._trusted(center, 0.25, 0.5)
    assert wedge == HeadingWedge(center, 0.25, 0.5)
    assert math.copysign(1.0, wedge.center) == math.copysign(1.0, wrap_angle(center))


def test_restored_keeps_the_centre_bit_for_bit_where_wrapping_would_move_it() -> None:
    center = next(h for h in np.linspace(0.01, 0.5, 1000).tolist() if wrap_angle(h) != h)
    wedge = HeadingWedge._restored(center, 0.25, 0.5)
    assert (wedge.center, wedge.cw, wedge.ccw) == (center, 0.25, 0.5)
    assert HeadingWedge(center, 0.25, 0.5).center != center  # the constructor would move it
    assert HeadingWedge._restored(math.pi, 0.0, 0.0) == HeadingWedge(math.pi, 0.0, 0.0)


@pytest.mark.parametrize(
    ("center", "cw", "ccw", "message"),
    [
        (-math.pi, 0.1, 0.1, r"HeadingWedge\.center: expected radians in \(-pi, pi\], got -3\.14159"),
        (4.0, 0.1, 0.1, r"HeadingWedge\.center: expected radians in \(-pi, pi\], got 4\.0"),
        (math.nan, 0.1, 0.1, r"HeadingWedge\.center: expected a finite number, got nan"),
        (0.0, -0.1, 0.1, r"HeadingWedge\.cw: expected a non-negative number, got -0\.1"),
        (0.0, 0.1, math.inf, r"HeadingWedge\.ccw: expected a finite number, got inf"),
    ],
)
def test_restored_validates_as_the_constructor_does(
    center: float, cw: float, ccw: float, message: str
) -> None:
    with pytest.raises(InputError, match=message):
        HeadingWedge._restored(center, cw, ccw)


@given(st.lists(st.tuples(angles, extents, extents, angles), min_size=1, max_size=20))
def test_many_wedges_at_once_say_what_each_says(cases: list[tuple[float, float, float, float]]) -> None:
    wedges = [HeadingWedge(center, cw, ccw) for center, cw, ccw, _ in cases]
    bounds = np.array([(w.center, w.cw, w.ccw) for w in wedges])
    # Headings on the edges too, where the tolerance decides.
    for headings in (
        np.array([heading for *_, heading in cases]),
        np.array([w.center - w.cw for w in wedges]),
        np.array([w.center + w.ccw + 1e-9 for w in wedges]),
    ):
        expected = [_one_by_one(w, h) for w, h in zip(wedges, headings.tolist(), strict=True)]
        assert wedges_contain(bounds, headings).tolist() == expected
        assert [w.contains(h) for w, h in zip(wedges, headings.tolist(), strict=True)] == expected


def _one_by_one(wedge: HeadingWedge, heading: float) -> bool:
    """The wedge test for one heading, in Python floats: offset from lo within the width."""
    if wedge.cw + wedge.ccw >= 2 * math.pi:
        return True
    offset = float(np.mod(heading - (wedge.center - wedge.cw), 2 * math.pi))
    return offset <= wedge.width + 1e-9 or offset >= 2 * math.pi - 1e-9


@given(
    st.floats(-10.0, 10.0),
    st.floats(0.0, 4.0),
    st.floats(0.0, 4.0),
    st.sampled_from([0.0, 1e-9, -1e-9, 2e-9, -2e-9, 1e-6, 2.0 * math.pi, -2.0 * math.pi]),
    st.sampled_from(["lo", "hi", "center"]),
)
def test_one_heading_as_a_float_answers_as_an_array(
    center: float, cw: float, ccw: float, nudge: float, where: str
) -> None:
    """The float path of ``contains`` gives the array path's answer, at the ends and past them."""
    wedge = HeadingWedge(center, cw, ccw)
    base = {"lo": wedge.center - wedge.cw, "hi": wedge.center + wedge.ccw, "center": wedge.center}[where]
    heading = base + nudge
    assert wedge.contains(heading) == bool(np.asarray(wedge.contains(np.array([heading])))[0])


@pytest.mark.parametrize(
    ("angle", "message"),
    [
        (None, r"angle: expected a finite number, got None"),
        ("1.0", r"angle: expected a finite number, got '1\.0'"),
        (math.nan, r"angle: expected a finite number, got nan"),
        (True, r"angle: expected a finite number, got True"),
        (np.array([1.0, 2.0]), r"angle: expected a finite number, got array"),
    ],
)
def test_rotated_names_a_bad_angle(angle: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        HeadingWedge(0.0, 0.1, 0.1).rotated(angle)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("cw", "ccw", "message"),
    [
        (None, 0.1, r"cw: expected a finite number, got None"),
        (np.array([1.0, 2.0]), 0.1, r"cw: expected a finite number, got array"),
        (1 + 0j, 0.1, r"cw: expected a finite number, got \(1\+0j\)"),
        (math.inf, 0.1, r"cw: expected a finite number, got inf"),
        (0.1, math.nan, r"ccw: expected a finite number, got nan"),
        (0.1, -0.5, r"ccw: expected a non-negative number, got -0\.5"),
    ],
)
def test_widened_names_a_bad_extent(cw: object, ccw: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        HeadingWedge(0.0, 0.1, 0.1).widened(cw, ccw)  # type: ignore[arg-type]


def test_widened_by_a_huge_extent_is_the_full_circle_and_rotated_keeps_its_bits() -> None:
    wedge = HeadingWedge(0.5, 0.1, 0.2)
    assert wedge.widened(1e300, 0.0) == HeadingWedge(0.5, math.pi, math.pi)
    assert wedge.widened(1, np.float64(0.25)) == HeadingWedge(0.5, 0.1 + 1.0, 0.2 + 0.25)
    assert wedge.rotated(np.float64(3.0)) == HeadingWedge(0.5 + 3.0, 0.1, 0.2)


@pytest.mark.parametrize("heading", ["0.0", True, [0.0, 1 + 1j]])
def test_contains_refuses_headings_that_are_no_numbers(heading: object) -> None:
    with pytest.raises(
        InputError, match=r"heading: expected numbers, got ('0\.0'|True|\[0\.0, \(1\+1j\)\])$"
    ):
        HeadingWedge(0.0, 0.1, 0.1).contains(heading)  # type: ignore[call-overload]
