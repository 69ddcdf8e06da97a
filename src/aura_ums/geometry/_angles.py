"""Angle arithmetic on the compass: wrapping to (-pi, pi] and signed differences."""

from __future__ import annotations

import math
from typing import overload

import numpy as np
from numpy.typing import NDArray

from aura_ums._validate import finite_float, float_array
from aura_ums.errors import InputError

TWO_PI = 2.0 * math.pi


@overload
def wrap_angle(angle: float) -> float: ...
@overload
def wrap_angle(angle: NDArray[np.float64]) -> NDArray[np.float64]: ...
def wrap_angle(angle: float | NDArray[np.float64]) -> float | NDArray[np.float64]:
    """Wrap an angle to the interval (-pi, pi].

    Parameters
    ----------
    angle : float or ndarray
        Angle(s) in radians, any finite value.

    Returns
    -------
    float or ndarray
        The same direction expressed in (-pi, pi] radians; the type follows the input.

    Raises
    ------
    InputError
        When an angle is not a finite number (NaN and inf have no direction).

    Examples
    --------
    >>> import math
    >>> wrap_angle(3 * math.pi / 2) == -math.pi / 2
    True
    >>> wrap_angle(-math.pi)  # the boundary maps to +pi, never -pi
    3.141592653589793
    >>> wrap_angle(math.inf)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: angle: expected a finite number, got inf
    """
    # Floating-point modulo can return exactly 2*pi for a tiny negative remainder,
    # which would map to -pi; fold that one case back onto +pi.
    if isinstance(angle, np.ndarray):
        if not np.all(np.isfinite(angle)):  # inf: numpy's RuntimeWarning, and NaN out
            raise InputError(
                f"angle: expected finite numbers, got {float(angle[~np.isfinite(angle)][0])!r} among them"
            )
        wrapped = np.pi - np.mod(np.pi - angle, TWO_PI)
        return np.asarray(np.where(wrapped <= -np.pi, wrapped + TWO_PI, wrapped), dtype=np.float64)
    if type(angle) is not float:  # ints, numpy scalars (kept, as their arithmetic); not None, str, bool
        finite_float(angle, "angle")
    result = math.pi - (math.pi - angle) % TWO_PI
    if result > -math.pi:
        return result
    if result <= -math.pi:
        return result + TWO_PI
    raise InputError(f"angle: expected a finite number, got {angle!r}")  # NaN: a float NaN or inf


@overload
def angle_difference(a: float, b: float) -> float: ...
@overload
def angle_difference(
    a: NDArray[np.float64] | float, b: NDArray[np.float64] | float
) -> NDArray[np.float64] | float: ...
def angle_difference(
    a: NDArray[np.float64] | float, b: NDArray[np.float64] | float
) -> NDArray[np.float64] | float:
    """Return the signed angle from ``b`` to ``a``, wrapped to (-pi, pi] radians.

    Examples
    --------
    >>> import math
    >>> round(angle_difference(-3.0, 3.0), 6)  # across the +-pi seam: a short step
    0.283185
    >>> angle_difference("1.0", 0.1)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: a: expected a finite number, got '1.0'
    """
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return wrap_angle(float_array(a, "a") - float_array(b, "b"))
    return wrap_angle(finite_float(a, "a") - finite_float(b, "b"))
