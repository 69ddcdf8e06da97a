"""Plain geometry for the exported scene: wedge fans, yaw quaternions, colours, image rectangles.

Small numpy functions with no dependency on the Foxglove SDK, so that what is drawn can
be checked on its own.
"""

from __future__ import annotations

import colorsys
import math
from collections.abc import Mapping
from types import MappingProxyType

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import finite_float, points_array
from aura_ums.errors import InputError
from aura_ums.geometry import HeadingWedge, ImageWindow

#: Shortest ray (m) of the drawn heading wedge.
WEDGE_MIN_RADIUS = 1.0
#: Metres the drawn wedge's rays reach beyond the polygon's farthest vertex from the centre.
_WEDGE_REACH = 0.5
#: Largest angle (rad) between two consecutive points of a drawn arc.
ARC_STEP = math.radians(5.0)
#: Metres between two drawn heading slices stacked above the ground, and below the first.
SLICE_STEP = 0.05

#: RGBA (each in [0, 1]) of the meadow fill per terrain name; other terrains use
#: ``_OTHER_TERRAIN_COLOR``. Read-only.
_TERRAIN_COLORS: Mapping[str, tuple[float, float, float, float]] = MappingProxyType(
    {
        "tile": (0.80, 0.80, 0.75, 0.35),
        "floor": (0.80, 0.80, 0.75, 0.35),
        "concrete": (0.62, 0.62, 0.62, 0.35),
        "gravel": (0.70, 0.58, 0.40, 0.35),
        "grass": (0.30, 0.65, 0.25, 0.35),
    }
)
#: RGBA of a meadow whose terrain is not in ``_TERRAIN_COLORS``.
_OTHER_TERRAIN_COLOR = (0.55, 0.45, 0.70, 0.35)


def terrain_color(terrain: str) -> tuple[float, float, float, float]:
    """Return the RGBA fill colour of a meadow of this terrain.

    Examples
    --------
    >>> terrain_color("grass")
    (0.3, 0.65, 0.25, 0.35)
    >>> terrain_color("moon dust") == _OTHER_TERRAIN_COLOR      # not in the table
    True
    """
    return _TERRAIN_COLORS.get(terrain, _OTHER_TERRAIN_COLOR)


def yaw_quaternion(heading: float) -> tuple[float, float, float, float]:
    """Return the unit quaternion ``(x, y, z, w)`` of a rotation by ``heading`` (rad) about +z.

    Examples
    --------
    >>> [round(q, 6) for q in yaw_quaternion(math.pi / 2)]
    [0.0, 0.0, 0.707107, 0.707107]
    >>> yaw_quaternion(0.0)
    (0.0, 0.0, 0.0, 1.0)
    """
    h = finite_float(heading, "heading")
    return (0.0, 0.0, math.sin(h / 2.0), math.cos(h / 2.0))


def heading_color(heading: float) -> tuple[float, float, float, float]:
    """Return the RGBA colour of a heading (rad): a full-saturation hue, red at 0, once round the wheel.

    Examples
    --------
    >>> heading_color(0.0)
    (1.0, 0.0, 0.0, 1.0)
    >>> heading_color(2.0 * math.pi) == heading_color(0.0)       # a whole turn: the same colour
    True
    """
    hue = (finite_float(heading, "heading") / (2.0 * math.pi)) % 1.0
    r, g, b = colorsys.hsv_to_rgb(hue, 1.0, 1.0)
    return (r, g, b, 1.0)


def slice_height(index: int) -> float:
    """Return the height (m) at which heading slice ``index`` (0-based, in heading order) is drawn.

    Examples
    --------
    >>> slice_height(0), slice_height(3)
    (0.05, 0.2)
    """
    return SLICE_STEP * (index + 1)


def wedge_radius(center: ArrayLike, vertices: ArrayLike) -> float:
    """Return the length (m) of the drawn wedge's rays for a map.

    ``max(WEDGE_MIN_RADIUS, farthest vertex distance from the centre + _WEDGE_REACH)``: the
    rays always reach past the polygon, so the wedge stays visible over it.

    Examples
    --------
    >>> wedge_radius((0, 0), [(3, 0), (0, 4), (-1, 0)])
    4.5
    >>> wedge_radius((0, 0), [(0, 0)])          # a point map: the shortest ray
    1.0
    """
    c = points_array(center, "center", min_rows=1)[0]
    v = points_array(vertices, "vertices")
    far = float(np.max(np.hypot(*(v - c).T))) if len(v) else 0.0
    return max(WEDGE_MIN_RADIUS, far + _WEDGE_REACH)


def wedge_fan(center: ArrayLike, wedge: HeadingWedge, radius: float) -> NDArray[np.float64]:
    """Return the closed outline ``(n, 2)`` (m) of a heading wedge drawn as a fan.

    The fan starts at ``center``, runs along the clockwise bound (``wedge.center - cw``) to
    ``radius``, follows the arc counter-clockwise (a point every ``ARC_STEP`` at most)
    to the counter-clockwise bound, and is closed back to the centre by the line loop that
    draws it. A full-circle wedge is a circle of that radius (no centre point).

    Examples
    --------
    >>> fan = wedge_fan((0, 0), HeadingWedge(0.0, cw=0.1, ccw=0.1), 2.0)
    >>> fan[0].tolist(), fan.shape[0]
    ([0.0, 0.0], 5)
    >>> bool(np.allclose(np.hypot(*fan[1:].T), 2.0))
    True
    >>> wedge_fan((1, 1), HeadingWedge.full_circle(), 1.0).shape    # a circle of 72 points
    (72, 2)
    """
    c = points_array(center, "center", min_rows=1)[0]
    r = finite_float(radius, "radius")
    if wedge.is_full_circle:
        count = math.ceil(2.0 * math.pi / ARC_STEP)
        angles = np.linspace(0.0, 2.0 * math.pi, count, endpoint=False)
        return np.column_stack((c[0] + r * np.cos(angles), c[1] + r * np.sin(angles)))
    lo = wedge.center - wedge.cw
    count = max(2, math.ceil(wedge.width / ARC_STEP) + 1)
    angles = lo + np.linspace(0.0, wedge.width, count)
    arc = np.column_stack((c[0] + r * np.cos(angles), c[1] + r * np.sin(angles)))
    return np.vstack((c[None, :], arc))


def window_rectangle(window: ImageWindow, width: int, height: int) -> NDArray[np.float64]:
    """Return the corners ``(4, 2)`` of a window in Foxglove's image coordinates (pixels).

    The window is first clamped to the image (``[-0.5, width - 0.5] x [-0.5, height - 0.5]``
    in aura-ums pixels, whose (0, 0) is the top-left pixel's centre), then shifted by half a
    pixel: Foxglove's origin is the top-left pixel's outer corner. Corners run top-left,
    top-right, bottom-right, bottom-left. A window off the image collapses onto its border.

    Examples
    --------
    >>> window_rectangle(ImageWindow(10, 20, 50, 40), 640, 480).tolist()
    [[10.5, 20.5], [50.5, 20.5], [50.5, 40.5], [10.5, 40.5]]
    >>> window_rectangle(ImageWindow(-100, -0.5, 700, 10), 640, 480)[:2].tolist()   # clamped
    [[0.0, 0.0], [640.0, 0.0]]
    """
    u0, u1 = np.clip((window.u_min, window.u_max), -0.5, width - 0.5) + 0.5
    v0, v1 = np.clip((window.v_min, window.v_max), -0.5, height - 0.5) + 0.5
    return np.array([(u0, v0), (u1, v0), (u1, v1), (u0, v1)], dtype=np.float64)


def seconds_to_nanoseconds(time: float, name: str = "time") -> int:
    """Return a time in seconds (finite, >= 0) as integer nanoseconds, rounded.

    Exact for times that are whole nanoseconds in the double (epoch times included).

    Raises
    ------
    InputError
        For a negative or non-finite time: MCAP log times are unsigned.

    Examples
    --------
    >>> seconds_to_nanoseconds(1.5), seconds_to_nanoseconds(0.0)
    (1500000000, 0)
    >>> seconds_to_nanoseconds(1_700_000_000.25)
    1700000000250000000
    >>> seconds_to_nanoseconds(-1.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: time: expected a time >= 0 s (MCAP log times are unsigned), got -1.0
    """
    t = finite_float(time, name)
    if t < 0.0:
        raise InputError(f"{name}: expected a time >= 0 s (MCAP log times are unsigned), got {t!r}")
    whole = math.floor(t)  # split first: epoch times * 1e9 lose nanoseconds in a double
    return whole * 1_000_000_000 + round((t - whole) * 1e9)
