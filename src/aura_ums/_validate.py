"""Validation where data enters: turn user input into checked floats and arrays.

These helpers raise :class:`~aura_ums.errors.InputError` with messages that name
the argument, what was expected and what was found. Code behind them trusts
what they return.

The physical ranges shared by several inputs are defined here once (:class:`Range`
constants: :data:`COORDINATE`, :data:`START_RADIUS`, ...); the readers check every
numeric field against one, and the docs pages of the file formats list them.
"""

from __future__ import annotations

import enum
import math
import numbers
import sys
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any, NoReturn, TypeVar, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums.errors import InputError

_T = TypeVar("_T")


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


def gap_seconds(value: object, name: str) -> float:
    """Return ``value``, a longest interpolated interval (s, > 0, or ``math.inf``), as a float."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0.0:
        raise InputError(f"{name}: expected a positive number of seconds (or inf), got {value!r}")
    return float(value)


def integer_at_least(value: object, name: str, minimum: int) -> int:
    """Return ``value`` if it is an integer (not a bool) >= ``minimum``, or raise naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        raise InputError(f"{name}: expected an integer >= {minimum}, got {value!r}")
    return value


def bounded_count(value: object, name: str, minimum: int, maximum: int, cost: str) -> int:
    """Return a count, an integer (numpy's too; not a bool or float) in [minimum, maximum], or raise.

    ``maximum`` comes from a time or memory estimate, which ``cost`` states for the message
    (what the largest count is and costs): 10**12 sides asked for terabytes.

    Examples
    --------
    >>> bounded_count(16, "sides", 3, 1000, "sides (16 kB of vertices)")
    16
    >>> bounded_count(10**6, "sides", 3, 1000, "sides (16 kB of vertices)")
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: sides: expected at most 1,000 sides (16 kB of vertices), got 1000000
    """
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise InputError(f"{name}: expected an integer >= {minimum}, got {value!r}")
    if value > maximum:
        raise InputError(f"{name}: expected at most {maximum:,} {cost}, got {value!r}")
    return int(value)


def exact_text(value: float) -> str:
    """Return a number as it reads back exactly (its repr), without a trailing ``.0``.

    For times in messages: ``:g`` keeps six digits, and a log on Unix time read "1.7e+09 s is
    after the last frame (1.7e+09 s)".

    >>> exact_text(1700000197.8), exact_text(30000.0), exact_text(-5.0), exact_text(0.25)
    ('1700000197.8', '30000', '-5', '0.25')
    """
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text


def _refuse_choice(kind: type[enum.Enum], value: object) -> NoReturn:
    choices = ", ".join(repr(member.value) for member in kind)
    raise InputError(f"{kind.__name__}: expected one of {choices}, got {value!r}")


class Choice(enum.Enum):
    """An enum of fixed choices: looked up by an unknown value, it raises :class:`InputError`.

    (Python's own ValueError is not an :class:`~aura_ums.errors.AuraUmsError`.)

    Examples
    --------
    >>> class Side(Choice):
    ...     LEFT = "left"
    ...     RIGHT = "right"
    >>> Side("left") is Side.LEFT
    True
    >>> Side("up")
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: Side: expected one of 'left', 'right', got 'up'
    """

    @classmethod
    def _missing_(cls, value: object) -> NoReturn:
        _refuse_choice(cls, value)


class StrChoice(enum.StrEnum):
    """:class:`Choice` whose members are strings too (``enum.StrEnum``)."""

    @classmethod
    def _missing_(cls, value: object) -> NoReturn:
        _refuse_choice(cls, value)


def items_of(value: Iterable[_T], name: str, what: str) -> tuple[_T, ...]:
    """Return the items of an iterable that is not a string, or raise naming ``name`` and ``what``.

    For collections given to a constructor: ``tuple(None)`` would raise a TypeError from inside.

    Examples
    --------
    >>> items_of([1, 2], "ids", "a sequence of ids")
    (1, 2)
    >>> items_of(None, "meadows", "a sequence of Meadow")
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: meadows: expected a sequence of Meadow, got NoneType
    """
    checked: object = value  # typed as iterable; given anything at run time
    if isinstance(checked, (str, bytes)) or not isinstance(checked, Iterable):
        raise InputError(f"{name}: expected {what}, got {type(checked).__name__}")
    return tuple(value)


def sequence_of(value: Iterable[object], kind: type[_T], name: str) -> tuple[_T, ...]:
    """Return the items of an iterable (not a string), each a ``kind``, or raise naming ``name`` and the item.

    Examples
    --------
    >>> sequence_of([1, 2], int, "ids")
    (1, 2)
    >>> sequence_of([1, "2"], int, "ids")
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: ids[1]: expected a int, got str
    """
    items = items_of(value, name, f"a sequence of {kind.__name__}")
    for index, item in enumerate(items):
        if not isinstance(item, kind):
            raise InputError(f"{name}[{index}]: expected a {kind.__name__}, got {type(item).__name__}")
    return cast(tuple[_T, ...], items)


def check_rng(rng: object, name: str = "rng") -> None:
    """Refuse anything but a ``numpy.random.Generator`` (every random function takes one), naming ``name``."""
    if not isinstance(rng, np.random.Generator):
        raise InputError(f"{name}: expected a numpy.random.Generator, got {type(rng).__name__}")


def vertex_cap(value: object, name: str = "max_vertices") -> int:
    """Return a polygon's vertex cap, an integer in [3, 2**63 - 1], or raise naming ``name``.

    A cap only bounds what a polygon may keep (1,000,000: no cap at work), so any size the
    kernels can count (a Py_ssize_t) is a valid one; numpy integers are taken as Python's.
    """
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 3 <= value <= sys.maxsize:
        raise InputError(f"{name}: expected an integer in [3, 2**63 - 1], got {value!r}")
    return int(value)


@dataclass(frozen=True, slots=True)
class Range:
    """A physical range of a numeric field: ``low <= value <= high`` in ``unit``.

    Parameters
    ----------
    low, high : float
        The bounds (finite), ``low <= high``.
    unit : str
        The unit, for messages and docs ("m", "rad/m", "px", "" for none).
    low_open, high_open : bool
        Exclude the bound itself (``low < value``, ``value < high``).

    Examples
    --------
    >>> DRIFT = Range(0.0, 10.0, "rad/m")
    >>> DRIFT.check(0.02, "drift"), DRIFT.text()
    (0.02, 'a number in [0, 10] rad/m')
    >>> DRIFT.check(1e20, "drift")
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: drift: expected a number in [0, 10] rad/m, got 1e+20
    """

    low: float
    high: float
    unit: str = ""
    low_open: bool = False
    high_open: bool = False

    def contains(self, value: float) -> bool:
        """Whether the finite ``value`` is in the range."""
        above = value > self.low if self.low_open else value >= self.low
        below = value < self.high if self.high_open else value <= self.high
        return above and below

    def interval(self) -> str:
        """Write the range as an interval with its unit: ``"[0, 10] rad/m"`` (as the docs list it)."""
        left, right = "(" if self.low_open else "[", ")" if self.high_open else "]"
        unit = f" {self.unit}" if self.unit else ""
        return f"{left}{self.low:g}, {self.high:g}{right}{unit}"

    def text(self) -> str:
        """Describe the range in a message: ``"a number in [0, 10] rad/m"``."""
        return f"a number in {self.interval()}"

    def check(self, value: object, name: str) -> float:
        """Return ``value`` as a float in the range, or raise naming ``name``."""
        result = finite_float(value, name)
        if not self.contains(result):
            raise InputError(f"{name}: expected {self.text()}, got {result!r}")
        return result


#: Any position in a world frame, each coordinate, metres: a 2000 km square is far beyond a
#: mobile robot's work area, and keeps areas (m^2) and squared distances far from overflow.
COORDINATE = Range(-1e6, 1e6, "m")
#: Where a sensor sits in the robot frame (forward, left), metres.
SENSOR_OFFSET = Range(-100.0, 100.0, "m")
#: Radius of the start position's uncertainty, metres (10 km).
START_RADIUS = Range(0.0, 1e4, "m")
#: Radius of a landmark's position uncertainty, metres (1 km).
POSITION_UNCERTAINTY = Range(0.0, 1e3, "m")
#: A length a sensor measures or a bound on its error (range, range error, heights), metres.
LENGTH = Range(0.0, 1e4, "m")
#: A height above (or below) the ground, metres.
HEIGHT = Range(-1e4, 1e4, "m")
#: An angle as given (bearing, heading, turn), radians; wrapped where it is used.
ANGLE = Range(-1e3, 1e3, "rad")
#: A bound on an angle's error, radians, from a microradian (no robot's sensor bounds a
#: bearing closer; 1e-300 rad passed and bounded the map to nothing) to absurd magnitudes
#: (from pi on it says nothing, but a widened envelope may pass it).
ANGLE_ERROR = Range(1e-6, 1e3, "rad")
#: How near, metres, a find-landmark schema wakes (a landmark farther than 10 km is not seen).
ACTIVATION_RANGE = Range(0.0, 1e4, "m", low_open=True)
#: Most consecutive frames a discovery may need to be confirmed: 1,000 s of frames at 10 Hz.
MAX_CONFIRM_FRAMES = 10_000
#: An extent of a heading wedge as saved, radians: from 2 pi on it is the full circle (the
#: library saves that as pi and pi), so anything far beyond is not a wedge it wrote.
WEDGE_EXTENT = Range(0.0, 1e3, "rad")
#: A time stamp, seconds (Unix times run to 1e10 s in the year 2286).
TIME = Range(-1e10, 1e10, "s")
#: Forward velocity of a ground robot, m/s (100 m/s is 360 km/h).
SPEED = Range(-100.0, 100.0, "m/s")
#: Angular velocity, rad/s (100 rad/s is 16 turns a second).
ANGULAR_SPEED = Range(-100.0, 100.0, "rad/s")
#: A dimensionless factor (scales, fractions of a range), > 0.
FACTOR = Range(0.0, 100.0, "", low_open=True)
#: The particle filter's roughening constant K (each resampling jitters the particles by K
#: times the cloud's spread over the cube root of their count; Gordon et al. suggest about
#: 0.2): at 10 the jitter is ten times the cloud; 1e300 put the particles at 1e298 m.
ROUGHENING = Range(0.0, 10.0, "")
#: A scale on recorded odometry (``run_scale``, ``turn_scale``): near 1 when calibrated, 1e-3
#: or 1e3 for odometry in other units (millimetres, milliradians); 1e-300 passed and stopped
#: the map growing.
ODOMETRY_SCALE = Range(1e-3, 1e3, "")
#: Standard deviations of the motion model that a growth bounds, from a tenth (almost none)
#: to 100 (Chebyshev leaves 1e-4 outside): 1e300 overflowed the polygon's coordinates, 1e-300
#: bounded nothing.
SIGMAS = Range(0.1, 100.0, "")
#: Delay of recorded motion behind the true motion, seconds (an hour).
DELAY = Range(0.0, 3600.0, "s")
#: Seconds between two motion rows of a log: a longer gap is a clock jump, not a held velocity.
ROW_GAP = Range(0.0, 86_400.0, "s", low_open=True)
#: Pixels along one side of an image.
IMAGE_SIDE = Range(1, 20_000, "px")
#: One coefficient of a lens's OpenCV distortion (k1, k2, p1, p2 or k3), dimensionless: real
#: lenses fit within a few units, strong wide-angle fits reach tens; beyond 1000 is no lens.
DISTORTION = Range(-1000.0, 1000.0)
#: A focal length, pixels: from 1 px (a field of view of over 179 degrees on any image; 1e-300
#: gave windows of a nanopixel) to 1e6 px (1 mrad on a 1000 px image).
FOCAL_LENGTH = Range(1.0, 1e6, "px")
#: A principal point or pixel coordinate, pixels.
PIXEL = Range(-1e5, 1e5, "px")
#: Standard deviation of a Gaussian blur of an image, pixels: beyond 100 px it blurs a frame
#: to one grey, and its kernel grows with it (a sigma of 1e9 px asked for 59.6 GiB).
BLUR = Range(0.0, 100.0, "px")


def _numbers(
    make: Callable[[object], NDArray[Any]], value: object, name: str, expected: str
) -> NDArray[np.float64]:
    """Return ``make(value)`` (``np.array``, a copy, or ``np.asarray``) as floats: integers or floats only.

    ``np.array(value, dtype=np.float64)`` parsed numeric strings ("1.0") and bools, and dropped
    complex numbers' imaginary parts with a ComplexWarning. Objects (a list holding a Fraction, an
    int beyond int64, a None) are taken when each is a real number that is not a bool.
    """
    try:
        array = make(value)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name}: expected {expected}, got {value!r}") from exc
    kind = array.dtype.kind
    if kind not in "iuf" and not (kind == "O" and all(_real(item) for item in array.flat)):
        raise InputError(f"{name}: expected {expected}, got {_short(value)}")
    try:
        return array.astype(np.float64, copy=False)
    except (TypeError, ValueError, OverflowError) as exc:  # an object no float holds
        raise InputError(f"{name}: expected {expected}, got {_short(value)}") from exc


def _real(item: object) -> bool:
    return isinstance(item, numbers.Real) and not isinstance(item, (bool, np.bool_))


def _short(value: object) -> str:
    """``repr(value)`` on one line, cut to 200 characters: a refused array may be large."""
    text = " ".join(repr(value).split())
    return text if len(text) <= 200 else text[:197] + "..."


def number_array(value: ArrayLike, name: str, expected: str = "numbers") -> NDArray[np.float64]:
    """Return ``value`` as a float array of any shape, NaN and inf kept, or raise naming ``name``.

    Numbers only (integers and floats, not strings, bools or complex), for arrays whose
    non-finite values mean something (pixels of points behind a camera are NaN).

    Examples
    --------
    >>> number_array([1, float("nan")], "pixels").tolist()
    [1.0, nan]
    >>> number_array([True, False], "pixels")
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: pixels: expected numbers, got [True, False]
    """
    return _numbers(np.asarray, value, name, expected)


def points_array(value: ArrayLike, name: str, *, min_rows: int = 0) -> NDArray[np.float64]:
    """Return ``value`` as a finite ``(n, 2)`` float array, or raise naming ``name``."""
    array = _numbers(np.array, value, name, "an (n, 2) array of numbers")
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


def world_points(value: ArrayLike, name: str, *, min_rows: int = 0) -> NDArray[np.float64]:
    """Return ``value`` as ``(n, 2)`` positions in the world frame, each coordinate in :data:`COORDINATE`.

    :func:`points_array`, then the range: 1e300 m passed and overflowed a polygon's area.
    """
    array = points_array(value, name, min_rows=min_rows)
    outside = np.abs(array) > COORDINATE.high
    if np.any(outside):
        row = int(np.argwhere(outside)[0, 0])
        raise InputError(
            f"{name}: expected coordinates {COORDINATE.text()}, got {array[row].tolist()} at row {row}"
        )
    return array


def float_array(value: ArrayLike, name: str) -> NDArray[np.float64]:
    """Return ``value`` as a finite float array of any shape, or raise naming ``name``."""
    array = _numbers(np.asarray, value, name, "numbers")
    if not np.all(np.isfinite(array)):
        raise InputError(f"{name}: expected finite numbers, got non-finite values")
    return array


def read_only(array: NDArray[np.float64]) -> NDArray[np.float64]:
    """Mark ``array`` read-only and return it (values are immutable in aura-ums)."""
    array.setflags(write=False)
    return array
