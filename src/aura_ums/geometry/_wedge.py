"""The compass wedge: the interval of headings the robot may be facing."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import finite_float, float_array, nonnegative_float
from aura_ums.errors import InputError
from aura_ums.geometry._angles import TWO_PI, wrap_angle

# Headings within this many radians of a wedge's edge count as inside it, so that
# a bound computed in floating point is not refused by its own rounding.
ANGLE_TOLERANCE = 1e-9


@dataclass(frozen=True, slots=True)
class HeadingWedge:
    """A compass wedge of headings: a centre and clockwise / counter-clockwise extents.

    The wedge holds every heading from ``center - cw`` counter-clockwise to
    ``center + ccw``. A wedge whose ``cw + ccw >= 2*pi`` is the full circle: a
    valid state meaning "any heading".

    Parameters
    ----------
    center : float
        Most probable heading, radians, counter-clockwise from world +x. Wrapped to
        (-pi, pi] on construction.
    cw : float
        Clockwise extent from the centre, radians, >= 0.
    ccw : float
        Counter-clockwise extent from the centre, radians, >= 0.

    Examples
    --------
    >>> import math
    >>> wedge = HeadingWedge(math.pi, cw=0.1, ccw=0.2)   # straddles the +-pi seam
    >>> bool(wedge.contains(-math.pi + 0.15)), bool(wedge.contains(math.pi - 0.15))
    (True, False)
    >>> HeadingWedge(0.0, cw=4.0, ccw=3.0).is_full_circle
    True
    """

    center: float
    cw: float
    ccw: float

    def __post_init__(self) -> None:
        center = finite_float(self.center, "HeadingWedge.center")
        cw = nonnegative_float(self.cw, "HeadingWedge.cw")
        ccw = nonnegative_float(self.ccw, "HeadingWedge.ccw")
        object.__setattr__(self, "center", wrap_angle(center))
        object.__setattr__(self, "cw", cw)
        object.__setattr__(self, "ccw", ccw)

    @classmethod
    def _trusted(cls, center: float, cw: float, ccw: float) -> HeadingWedge:
        """Build from values the library computed: finite, extents >= 0; wraps the centre."""
        # wrap_angle written out, and the slots' own setters: every growth and reduction
        # builds a wedge.
        wrapped = math.pi - (math.pi - center) % TWO_PI
        wedge = object.__new__(cls)
        _set_center(wedge, wrapped + TWO_PI if wrapped <= -math.pi else wrapped)
        _set_cw(wedge, cw)
        _set_ccw(wedge, ccw)
        return wedge

    @classmethod
    def _restored(cls, center: float, cw: float, ccw: float) -> HeadingWedge:
        """Rebuild a saved wedge, validated as the constructor does but with the centre kept bit for bit.

        The centre must already be in (-pi, pi]: wrapping it again (the constructor does)
        can move it by one unit in the last place, and a restored manager must go on
        exactly as the saved one would have.
        """
        heading = finite_float(center, "HeadingWedge.center")
        if not -math.pi < heading <= math.pi:
            raise InputError(f"HeadingWedge.center: expected radians in (-pi, pi], got {heading!r}")
        wedge = object.__new__(cls)
        _set_center(wedge, heading)
        _set_cw(wedge, nonnegative_float(cw, "HeadingWedge.cw"))
        _set_ccw(wedge, nonnegative_float(ccw, "HeadingWedge.ccw"))
        return wedge

    @classmethod
    def full_circle(cls, center: float = 0.0) -> HeadingWedge:
        """Return the wedge of every heading, with the given most probable heading."""
        return cls(center, math.pi, math.pi)

    @classmethod
    def from_bounds(cls, lo: float, hi: float, center: float | None = None) -> HeadingWedge:
        """Return the wedge from heading ``lo`` counter-clockwise to heading ``hi``.

        Parameters
        ----------
        lo, hi : float
            Clockwise-most and counter-clockwise-most headings, radians. The wedge runs
            counter-clockwise from ``lo`` to ``hi`` (so ``lo = 3``, ``hi = -3`` is a
            narrow wedge across the +-pi seam).
        center : float, optional
            Most probable heading; must lie in the wedge. Defaults to the bisector.

        Examples
        --------
        >>> w = HeadingWedge.from_bounds(3.0, -3.0)
        >>> round(w.width, 6), round(w.center, 6)
        (0.283185, 3.141593)
        """
        lo = finite_float(lo, "lo")
        hi = finite_float(hi, "hi")
        width = (hi - lo) % TWO_PI
        if center is None:
            return cls(lo + width / 2.0, width / 2.0, width / 2.0)
        center = finite_float(center, "center")
        offset = (center - lo) % TWO_PI
        if offset > width + ANGLE_TOLERANCE:
            raise InputError(f"center: expected a heading inside [{lo}, {hi}], got {center}")
        offset = min(offset, width)
        return cls(lo + offset, offset, width - offset)

    @property
    def is_full_circle(self) -> bool:
        """True when the wedge holds every heading."""
        return self.cw + self.ccw >= TWO_PI

    @property
    def width(self) -> float:
        """Angular width in radians, at most 2*pi."""
        return min(self.cw + self.ccw, TWO_PI)

    @property
    def lo(self) -> float:
        """Clockwise-most heading, wrapped to (-pi, pi] radians."""
        return wrap_angle(self.center - self.cw)

    @property
    def hi(self) -> float:
        """Counter-clockwise-most heading, wrapped to (-pi, pi] radians."""
        return wrap_angle(self.center + self.ccw)

    @overload
    def contains(self, heading: float) -> bool: ...
    @overload
    def contains(self, heading: ArrayLike) -> bool | NDArray[np.bool_]: ...
    def contains(self, heading: ArrayLike) -> bool | NDArray[np.bool_]:
        """Tell whether heading(s), in radians and any winding, lie in the wedge.

        Returns a Python ``bool`` for a scalar and a boolean array otherwise.
        """
        if type(heading) is float and math.isfinite(heading):
            return _heading_in(self.center, self.cw, self.ccw, heading)
        headings = float_array(heading, "heading")
        inside = wedges_contain(np.array([self.center, self.cw, self.ccw]), headings)
        if inside.ndim == 0:
            return bool(inside)
        return inside

    def widened(self, cw: float, ccw: float) -> HeadingWedge:
        """Return the wedge with ``cw`` and ``ccw`` radians (finite, >= 0) added to its extents.

        Extents that add up to ``2*pi`` or more are the full circle, however large (finite:
        the constructor's extents are finite too).

        Examples
        --------
        >>> HeadingWedge(0.0, 0.1, 0.1).widened(1e300, 0.0).is_full_circle
        True
        >>> HeadingWedge(0.0, 0.1, 0.1).widened(float("nan"), 0.0)
        Traceback (most recent call last):
        ...
        aura_ums.errors.InputError: cw: expected a finite number, got nan
        """
        more_cw = nonnegative_float(cw, "cw")
        more_ccw = nonnegative_float(ccw, "ccw")
        return _normalized(self.center, self.cw + more_cw, self.ccw + more_ccw)

    def rotated(self, angle: float) -> HeadingWedge:
        """Return the wedge turned by ``angle`` radians (finite; counter-clockwise positive)."""
        return _normalized(self.center + finite_float(angle, "angle"), self.cw, self.ccw)


def _heading_in(center: float, cw: float, ccw: float, heading: float) -> bool:
    """:func:`wedges_contain` for one wedge and one heading, with the same operations on floats.

    Python's ``%`` on floats and ``np.mod`` give the same bits (both take ``fmod``, then add
    the divisor when the signs differ), so this agrees with the array form exactly.
    """
    extent = cw + ccw
    offset = (heading - (center - cw)) % TWO_PI
    inside = offset <= min(extent, TWO_PI) + ANGLE_TOLERANCE or offset >= TWO_PI - ANGLE_TOLERANCE
    return inside or extent >= TWO_PI


def wedges_contain(wedges: NDArray[np.float64], headings: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Tell whether headings lie in wedges, element-wise: :meth:`HeadingWedge.contains` for many wedges.

    Parameters
    ----------
    wedges : ndarray, shape (..., 3)
        Each wedge's centre, clockwise and counter-clockwise extents, radians (as
        :class:`HeadingWedge` holds them: finite, extents >= 0); trusted, not checked.
    headings : ndarray
        Radians, any winding; broadcast against ``wedges[..., 0]``.

    Returns
    -------
    ndarray of bool
        True where the heading is in its wedge (within ``ANGLE_TOLERANCE``).

    Examples
    --------
    >>> import math
    >>> wedges = np.array([[0.0, 0.1, 0.1], [math.pi, 0.1, 0.2], [1.0, 4.0, 3.0]])
    >>> wedges_contain(wedges, np.array([0.2, -math.pi + 0.15, -2.0])).tolist()   # the last: full circle
    [False, True, True]
    """
    center, cw, ccw = wedges[..., 0], wedges[..., 1], wedges[..., 2]
    extent = cw + ccw
    offset = np.mod(headings - (center - cw), TWO_PI)
    # Offsets just below 2*pi are headings a hair clockwise of lo.
    inside = (offset <= np.minimum(extent, TWO_PI) + ANGLE_TOLERANCE) | (offset >= TWO_PI - ANGLE_TOLERANCE)
    full: NDArray[np.bool_] = inside | (extent >= TWO_PI)
    return full


# Setters of the slots (frozen: the dataclass's own __setattr__ refuses).
_set_center: Callable[[HeadingWedge, float], None] = HeadingWedge.__dict__["center"].__set__
_set_cw: Callable[[HeadingWedge, float], None] = HeadingWedge.__dict__["cw"].__set__
_set_ccw: Callable[[HeadingWedge, float], None] = HeadingWedge.__dict__["ccw"].__set__


def _normalized(center: float, cw: float, ccw: float) -> HeadingWedge:
    """Build a wedge, folding any full circle to the canonical extents (pi, pi)."""
    if cw + ccw >= TWO_PI:
        return HeadingWedge(center, math.pi, math.pi)
    return HeadingWedge(center, cw, ccw)
