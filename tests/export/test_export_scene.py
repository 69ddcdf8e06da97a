"""The plain geometry behind the exported scene: wedge fans, quaternions, image rectangles, times."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums.errors import InputError
from aura_ums.export._scene import (
    ARC_STEP,
    WEDGE_MIN_RADIUS,
    seconds_to_nanoseconds,
    terrain_color,
    wedge_fan,
    wedge_radius,
    window_rectangle,
    yaw_quaternion,
)
from aura_ums.geometry import HeadingWedge, ImageWindow

angles = st.floats(-math.pi, math.pi)
extents = st.floats(0.0, 3.5)


@given(center=angles, cw=extents, ccw=extents, x=st.floats(-50, 50), radius=st.floats(0.5, 100))
def test_the_fan_covers_exactly_the_wedge(
    center: float, cw: float, ccw: float, x: float, radius: float
) -> None:
    wedge = HeadingWedge(center, cw=cw, ccw=ccw)
    fan = wedge_fan((x, 1.0), wedge, radius)
    if wedge.is_full_circle:
        np.testing.assert_allclose(np.hypot(fan[:, 0] - x, fan[:, 1] - 1.0), radius)
        return
    np.testing.assert_allclose(fan[0], (x, 1.0))
    rays = fan[1:] - (x, 1.0)
    np.testing.assert_allclose(np.hypot(*rays.T), radius, rtol=1e-9)
    # every arc point's heading lies in the wedge; the first and last are its bounds
    headings = np.arctan2(rays[:, 1], rays[:, 0])
    assert all(wedge.contains(float(h)) for h in headings)
    assert math.isclose(math.remainder(headings[0] - (wedge.center - wedge.cw), math.tau), 0.0, abs_tol=1e-9)
    assert math.isclose(
        math.remainder(headings[-1] - (wedge.center + wedge.ccw), math.tau), 0.0, abs_tol=1e-9
    )
    steps = np.abs(np.remainder(np.diff(headings) + math.pi, math.tau) - math.pi)
    assert np.all(steps <= ARC_STEP + 1e-12)


def test_a_point_wedge_is_a_single_ray() -> None:
    fan = wedge_fan((0.0, 0.0), HeadingWedge(math.pi / 2, cw=0.0, ccw=0.0), 2.0)
    np.testing.assert_allclose(fan, [(0, 0), (0, 2), (0, 2)], atol=1e-12)


def test_wedge_radius_reaches_past_the_polygon() -> None:
    assert wedge_radius((1.0, 1.0), [(1.0, 1.0)]) == WEDGE_MIN_RADIUS
    assert wedge_radius((0.0, 0.0), [(6.0, 8.0), (0.0, 1.0)]) > 10.0


@given(heading=angles)
def test_yaw_quaternion_rotates_x_onto_the_heading(heading: float) -> None:
    x, y, z, w = yaw_quaternion(heading)
    assert (x, y) == (0.0, 0.0)
    assert math.isclose(z * z + w * w, 1.0)
    # rotating (1, 0, 0) by the quaternion gives (cos h, sin h, 0)
    assert math.isclose(w * w - z * z, math.cos(heading), abs_tol=1e-12)
    assert math.isclose(2 * w * z, math.sin(heading), abs_tol=1e-12)


def test_window_rectangle_clamps_and_shifts_half_a_pixel() -> None:
    corners = window_rectangle(ImageWindow(-0.5, -0.5, 639.5, 479.5), 640, 480)
    np.testing.assert_array_equal(corners, [(0, 0), (640, 0), (640, 480), (0, 480)])
    off = window_rectangle(ImageWindow(700.0, 10.0, 800.0, 20.0), 640, 480)  # right of the image
    assert set(off[:, 0]) == {640.0}
    unbounded = window_rectangle(ImageWindow(-1e308, 5.0, 1e308, 6.0), 640, 480)
    assert np.all(np.isfinite(unbounded))


def test_times_and_colors() -> None:
    assert seconds_to_nanoseconds(1e-9) == 1
    assert seconds_to_nanoseconds(1_700_000_000.25) == 1_700_000_000_250_000_000
    with pytest.raises(InputError, match=r"t: expected a finite number, got nan"):
        seconds_to_nanoseconds(math.nan, "t")
    assert terrain_color("concrete") != terrain_color("grass")
    assert all(0.0 <= c <= 1.0 for c in terrain_color("anything"))
