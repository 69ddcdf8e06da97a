"""Validation where data enters: turn user input into checked floats and arrays.

These helpers raise :class:`~aura_ums.errors.InputError` with messages that name
the argument, what was expected and what was found. Code behind them trusts
what they return.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums.errors import InputError


def finite_float(value: object, name: str) -> float:
    """Return ``value`` as a finite float, or raise naming ``name``."""
    if type(value) is float and math.isfinite(value):
        return value  # what float(value) returns; a third of the cost (tens of calls per map update)
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InputError(f"{name}: expected a finite number, got {value!r}")
    result = float(value)
    if not math.isfinite(result):
        raise InputError(f"{name}: expected a finite number, got {result!r}")
    return result


def positive_float(value: object, name: str) -> float:
    """Return ``value`` as a finite float > 0, or raise naming ``name``."""
    result = finite_float(value, name)
    if result <= 0.0:
        raise InputError(f"{name}: expected a positive number, got {result!r}")
    return result


def nonnegative_float(value: object, name: str) -> float:
    """Return ``value`` as a finite float >= 0, or raise naming ``name``."""
    result = finite_float(value, name)
    if result < 0.0:
        raise InputError(f"{name}: expected a non-negative number, got {result!r}")
    return result


def integer_at_least(value: object, name: str, minimum: int) -> int:
    """Return ``value`` if it is an integer (not a bool) >= ``minimum``, or raise naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        raise InputError(f"{name}: expected an integer >= {minimum}, got {value!r}")
    return value


def points_array(value: ArrayLike, name: str, *, min_rows: int = 0) -> NDArray[np.float64]:
    """Return ``value`` as a finite ``(n, 2)`` float array, or raise naming ``name``."""
    try:
        array = np.array(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name}: expected an (n, 2) array of numbers, got {value!r}") from exc
    if array.size == 0:
        array = array.reshape(0, 2)
    if array.ndim == 1 and array.shape == (2,):
        array = array.reshape(1, 2)
    if array.ndim != 2 or array.shape[1] != 2:
        raise InputError(f"{name}: expected an (n, 2) array, got shape {array.shape}")
    if array.shape[0] < min_rows:
        raise InputError(f"{name}: expected at least {min_rows} points, got {array.shape[0]}")
    if not np.all(np.isfinite(array)):
        bad = int(np.argwhere(~np.isfinite(array))[0, 0])
        raise InputError(f"{name}: expected finite coordinates, got {array[bad].tolist()} at row {bad}")
    return array


def float_array(value: ArrayLike, name: str) -> NDArray[np.float64]:
    """Return ``value`` as a finite float array of any shape, or raise naming ``name``."""
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name}: expected numbers, got {value!r}") from exc
    if not np.all(np.isfinite(array)):
        raise InputError(f"{name}: expected finite numbers, got non-finite values")
    return array


def read_only(array: NDArray[np.float64]) -> NDArray[np.float64]:
    """Mark ``array`` read-only and return it (values are immutable in aura-ums)."""
    array.setflags(write=False)
    return array
