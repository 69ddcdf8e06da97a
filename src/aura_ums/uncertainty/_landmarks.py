"""Landmarks of the three classes, and the bounded observations made of them."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import (
    COORDINATE,
    HEIGHT,
    POSITION_UNCERTAINTY,
    Choice,
    finite_float,
    float_array,
    nonnegative_float,
    read_only,
)
from aura_ums.errors import InputError


class LandmarkClass(Choice):
    """The paper's three landmark classes.

    Examples
    --------
    >>> LandmarkClass("II"), LandmarkClass.GROUND_LINE.value
    (<LandmarkClass.POINT: 'II'>, 'III')
    >>> PointLandmark("corner_3", 5.0, 2.0, 3.5).landmark_class is LandmarkClass.POINT
    True
    >>> LandmarkClass("IV")
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: LandmarkClass: expected one of 'I', 'II', 'III', got 'IV'
    """

    #: Class I: a vertical line (pole, door edge, building side); gives a bearing ray.
    VERTICAL_LINE = "I"
    #: Class II: an identifiable point of known height; gives bearing and bounded range.
    POINT = "II"
    #: Class III: a line on the ground (path edge); gives offset and relative angle.
    GROUND_LINE = "III"

    def observes(self, landmark_class: LandmarkClass) -> bool:
        """Tell whether an observation of this class can name a landmark of ``landmark_class``.

        Each class observes its own. A bearing (Class I) also observes a point (Class II):
        it needs only the landmark's ground position, and the bearing to a point is the
        bearing to the vertical line through it (a sighting whose range was not measured).

        Examples
        --------
        >>> LandmarkClass.VERTICAL_LINE.observes(LandmarkClass.POINT)
        True
        >>> LandmarkClass.POINT.observes(LandmarkClass.VERTICAL_LINE)  # a range needs a point
        False
        """
        bearing_to_point = self is LandmarkClass.VERTICAL_LINE and landmark_class is LandmarkClass.POINT
        return landmark_class is self or bearing_to_point


def _identifier(value: object, name: str) -> str:
    if not isinstance(value, str) or not value:
        raise InputError(f"{name}: expected a non-empty string, got {value!r}")
    return value


def _symbol(value: object, name: str) -> str:
    """Return the landmark's symbol (a description, possibly empty), refusing anything but a string."""
    if not isinstance(value, str):
        raise InputError(f"{name}: expected a string, got {type(value).__name__}")
    return value


@dataclass(frozen=True, slots=True)
class VerticalLineLandmark:
    """A Class I landmark: a vertical segment standing at (x, y).

    Parameters
    ----------
    id : str
        Instance name, e.g. ``"lamppost_107"``.
    x, y : float
        Position in the world frame, metres.
    z_bottom, z_top : float
        Heights of the segment's ends above the ground plane, metres, bottom <= top.
    symbol : str
        Symbolic class, e.g. ``"lamppost"``.
    position_uncertainty : float
        Radius (m) of the disk in which the landmark truly stands, >= 0.

    Examples
    --------
    >>> VerticalLineLandmark("pole_1", 3.0, 4.0, 0.0, 6.0, symbol="telephone pole").landmark_class
    <LandmarkClass.VERTICAL_LINE: 'I'>
    """

    id: str
    x: float
    y: float
    z_bottom: float
    z_top: float
    symbol: str = ""
    position_uncertainty: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "id", _identifier(self.id, "id"))
        object.__setattr__(self, "symbol", _symbol(self.symbol, f"{self.id}.symbol"))
        for name, bounds in (("x", COORDINATE), ("y", COORDINATE), ("z_bottom", HEIGHT), ("z_top", HEIGHT)):
            object.__setattr__(self, name, bounds.check(getattr(self, name), f"{self.id}.{name}"))
        if self.z_top < self.z_bottom:
            raise InputError(f"{self.id}.z_top: expected >= z_bottom ({self.z_bottom}), got {self.z_top}")
        object.__setattr__(
            self,
            "position_uncertainty",
            POSITION_UNCERTAINTY.check(self.position_uncertainty, f"{self.id}.position_uncertainty"),
        )

    @property
    def landmark_class(self) -> LandmarkClass:
        """Always :attr:`LandmarkClass.VERTICAL_LINE`."""
        return LandmarkClass.VERTICAL_LINE

    @property
    def position(self) -> NDArray[np.float64]:
        """Ground position (x, y), metres."""
        return np.array([self.x, self.y])


@dataclass(frozen=True, slots=True)
class PointLandmark:
    """A Class II landmark: an identifiable point at (x, y, z).

    Parameters
    ----------
    id : str
        Instance name, e.g. ``"building_corner_3"``.
    x, y, z : float
        Position in the world frame, metres (z above the ground plane).
    symbol : str
        Symbolic class.
    position_uncertainty : float
        Radius (m) of the disk (in x, y) in which the point truly lies, >= 0.

    Examples
    --------
    >>> corner = PointLandmark("building_corner_3", 5.0, 2.0, 3.5, symbol="building corner")
    >>> corner.landmark_class, corner.position.tolist()
    (<LandmarkClass.POINT: 'II'>, [5.0, 2.0])
    >>> PointLandmark("corner_4", 5.0, 2.0, 3.5, position_uncertainty=-0.1)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: corner_4.position_uncertainty: expected a number in [0, 1000] m, got -0.1
    """

    id: str
    x: float
    y: float
    z: float
    symbol: str = ""
    position_uncertainty: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "id", _identifier(self.id, "id"))
        object.__setattr__(self, "symbol", _symbol(self.symbol, f"{self.id}.symbol"))
        for name, bounds in (("x", COORDINATE), ("y", COORDINATE), ("z", HEIGHT)):
            object.__setattr__(self, name, bounds.check(getattr(self, name), f"{self.id}.{name}"))
        object.__setattr__(
            self,
            "position_uncertainty",
            POSITION_UNCERTAINTY.check(self.position_uncertainty, f"{self.id}.position_uncertainty"),
        )

    @property
    def landmark_class(self) -> LandmarkClass:
        """Always :attr:`LandmarkClass.POINT`."""
        return LandmarkClass.POINT

    @property
    def position(self) -> NDArray[np.float64]:
        """Ground position (x, y), metres."""
        return np.array([self.x, self.y])


@dataclass(frozen=True, slots=True, init=False)
class GroundLineLandmark:
    """A Class III landmark: a segment on the ground plane from ``start`` to ``end``.

    Parameters
    ----------
    id : str
        Instance name, e.g. ``"sidewalk_left_edge"``.
    start, end : array_like, shape (2,)
        Ends (x, y) in the world frame, metres; distinct.
    symbol : str
        Symbolic class.
    position_uncertainty : float
        Distance (m) by which the true line may lie off the mapped one, >= 0.

    Examples
    --------
    >>> edge = GroundLineLandmark("sidewalk_left_edge", (0, 1), (0, 11), symbol="sidewalk edge")
    >>> edge.start.tolist(), edge.length, round(edge.direction, 4), edge.landmark_class
    ([0.0, 1.0], 10.0, 1.5708, <LandmarkClass.GROUND_LINE: 'III'>)
    >>> GroundLineLandmark("dot", (2, 3), (2, 3))   # a line needs two distinct ends
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: dot.end: expected a point distinct from start, got [2.0, 3.0]
    """

    id: str
    start: NDArray[np.float64]
    end: NDArray[np.float64]
    symbol: str
    position_uncertainty: float

    def __init__(
        self,
        id: str,
        start: ArrayLike,
        end: ArrayLike,
        symbol: str = "",
        position_uncertainty: float = 0.0,
    ) -> None:
        ident = _identifier(id, "id")
        a = _one_point(start, f"{ident}.start", "an (x, y) point in metres")
        b = _one_point(end, f"{ident}.end", "an (x, y) point in metres")
        for name, point in (("start", a), ("end", b)):
            if not (COORDINATE.contains(float(point[0, 0])) and COORDINATE.contains(float(point[0, 1]))):
                raise InputError(
                    f"{ident}.{name}: expected coordinates {COORDINATE.text()}, got {point[0].tolist()}"
                )
        if np.array_equal(a, b):
            raise InputError(f"{ident}.end: expected a point distinct from start, got {b[0].tolist()}")
        object.__setattr__(self, "id", ident)
        object.__setattr__(self, "start", read_only(a[0].copy()))
        object.__setattr__(self, "end", read_only(b[0].copy()))
        object.__setattr__(self, "symbol", _symbol(symbol, f"{ident}.symbol"))
        object.__setattr__(
            self,
            "position_uncertainty",
            POSITION_UNCERTAINTY.check(position_uncertainty, f"{ident}.position_uncertainty"),
        )

    @property
    def landmark_class(self) -> LandmarkClass:
        """Always :attr:`LandmarkClass.GROUND_LINE`."""
        return LandmarkClass.GROUND_LINE

    @property
    def direction(self) -> float:
        """World direction of start -> end, radians in (-pi, pi]."""
        d = self.end - self.start
        return float(np.arctan2(d[1], d[0]))

    @property
    def length(self) -> float:
        """Length in metres."""
        return float(np.hypot(*(self.end - self.start)))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, GroundLineLandmark):
            return NotImplemented
        return (
            self.id == other.id
            and np.array_equal(self.start, other.start)
            and np.array_equal(self.end, other.end)
            and self.symbol == other.symbol
            and self.position_uncertainty == other.position_uncertainty
        )

    def __hash__(self) -> int:
        return hash((self.id, tuple(self.start), tuple(self.end)))


#: Any landmark that a reduction or the Expecter accepts.
Landmark = VerticalLineLandmark | PointLandmark | GroundLineLandmark


def _sensor_offset(value: ArrayLike, name: str) -> tuple[float, float]:
    if isinstance(value, tuple) and len(value) == 2:
        forward, left = value
        if type(forward) is float and type(left) is float and math.isfinite(forward + left):
            # The common case (the default (0.0, 0.0)): no array built, twice per log row.
            return (forward, left)
    offset = _one_point(value, name, "(forward, left) metres")
    return (float(offset[0, 0]), float(offset[0, 1]))


def _one_point(value: ArrayLike, name: str, what: str) -> NDArray[np.float64]:
    """Return one point given as two numbers, as a (1, 2) array; refuse any other shape, naming ``what``."""
    point = float_array(value, name)
    if point.shape not in ((2,), (1, 2)):
        raise InputError(f"{name}: expected {what}, got shape {point.shape}")
    return point.reshape(1, 2)


_COMMON = ("landmark_id", "time", "sensor_offset")


def _common(landmark_id: object, time: object, offset: ArrayLike) -> tuple[str, float, tuple[float, float]]:
    """Check the fields every observation has; their values in the order of ``_COMMON``."""
    return (
        _identifier(landmark_id, "landmark_id"),
        finite_float(time, "time"),
        _sensor_offset(offset, "sensor_offset"),
    )


@dataclass(frozen=True, slots=True)
class BearingObservation:
    """A Class I observation: the bearing to a landmark, within +-``bearing_error``.

    Parameters
    ----------
    landmark_id : str
        Which landmark was seen.
    time : float
        When, seconds.
    bearing : float
        Angle from the robot's heading to the landmark, radians, counter-clockwise positive.
    bearing_error : float
        Bound on the bearing's error, radians, >= 0.
    sensor_offset : tuple of float
        Where the sensor sits on the robot (forward, left), metres.

    Examples
    --------
    >>> seen = BearingObservation("lamppost_107", 12.5, 0.3, 0.01, sensor_offset=(0.2, 0.0))
    >>> seen.landmark_class, seen.sensor_offset
    (<LandmarkClass.VERTICAL_LINE: 'I'>, (0.2, 0.0))
    >>> BearingObservation("lamppost_107", 12.5, 0.3, -0.01)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: bearing_error: expected a non-negative number, got -0.01
    """

    landmark_id: str
    time: float
    bearing: float
    bearing_error: float
    sensor_offset: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        for name, value in zip(
            _COMMON, _common(self.landmark_id, self.time, self.sensor_offset), strict=True
        ):
            object.__setattr__(self, name, value)
        object.__setattr__(self, "bearing", finite_float(self.bearing, "bearing"))
        object.__setattr__(self, "bearing_error", nonnegative_float(self.bearing_error, "bearing_error"))

    @classmethod
    def _trusted(
        cls,
        landmark_id: str,
        time: float,
        bearing: float,
        bearing_error: float,
        sensor_offset: tuple[float, float],
    ) -> BearingObservation:
        """Build from values the library checked already (a log's rows): a long replay builds two per row."""
        # One setter call per slot, written out: a loop over them costs twice as much.
        observation = object.__new__(cls)
        _set_bearing_id(observation, landmark_id)
        _set_bearing_time(observation, time)
        _set_bearing_bearing(observation, bearing)
        _set_bearing_error(observation, bearing_error)
        _set_bearing_offset(observation, sensor_offset)
        return observation

    @property
    def landmark_class(self) -> LandmarkClass:
        """Always :attr:`LandmarkClass.VERTICAL_LINE`."""
        return LandmarkClass.VERTICAL_LINE


@dataclass(frozen=True, slots=True)
class RangeBearingObservation:
    """A Class II observation: bearing within +-``bearing_error`` and range in [range_min, range_max].

    ``range`` is the horizontal distance (m) from the sensor to the landmark's (x, y).

    Examples
    --------
    >>> seen = RangeBearingObservation("building_corner_3", 4.0, -0.2, 0.02, 4.5, 5.0)
    >>> seen.landmark_class, seen.range_max - seen.range_min
    (<LandmarkClass.POINT: 'II'>, 0.5)
    >>> RangeBearingObservation("building_corner_3", 4.0, -0.2, 0.02, 5.0, 4.5)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: range_max: expected >= range_min (5.0), got 4.5
    """

    landmark_id: str
    time: float
    bearing: float
    bearing_error: float
    range_min: float
    range_max: float
    sensor_offset: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        for name, value in zip(
            _COMMON, _common(self.landmark_id, self.time, self.sensor_offset), strict=True
        ):
            object.__setattr__(self, name, value)
        object.__setattr__(self, "bearing", finite_float(self.bearing, "bearing"))
        object.__setattr__(self, "bearing_error", nonnegative_float(self.bearing_error, "bearing_error"))
        object.__setattr__(self, "range_min", nonnegative_float(self.range_min, "range_min"))
        object.__setattr__(self, "range_max", nonnegative_float(self.range_max, "range_max"))
        if self.range_max < self.range_min:
            raise InputError(f"range_max: expected >= range_min ({self.range_min}), got {self.range_max}")

    @classmethod
    def _trusted(
        cls,
        landmark_id: str,
        time: float,
        bearing: float,
        bearing_error: float,
        range_min: float,
        range_max: float,
        sensor_offset: tuple[float, float],
    ) -> RangeBearingObservation:
        """Build from values the library checked already (a log's rows): a long replay builds two per row."""
        # One setter call per slot, written out: a loop over them costs twice as much.
        observation = object.__new__(cls)
        _set_range_bearing_id(observation, landmark_id)
        _set_range_bearing_time(observation, time)
        _set_range_bearing_bearing(observation, bearing)
        _set_range_bearing_error(observation, bearing_error)
        _set_range_bearing_offset(observation, sensor_offset)
        _set_range_min(observation, range_min)
        _set_range_max(observation, range_max)
        return observation

    @property
    def landmark_class(self) -> LandmarkClass:
        """Always :attr:`LandmarkClass.POINT`."""
        return LandmarkClass.POINT


# The slots' own setters (frozen: the dataclass's __setattr__ refuses), for the _trusted builders.
_OBSERVATION_FIELDS = ("landmark_id", "time", "bearing", "bearing_error", "sensor_offset")
_BEARING_SETTERS = tuple(BearingObservation.__dict__[name].__set__ for name in _OBSERVATION_FIELDS)
_RANGE_BEARING_SETTERS = tuple(
    RangeBearingObservation.__dict__[name].__set__
    for name in (*_OBSERVATION_FIELDS, "range_min", "range_max")
)
_set_bearing_id, _set_bearing_time, _set_bearing_bearing, _set_bearing_error, _set_bearing_offset = (
    _BEARING_SETTERS
)
(
    _set_range_bearing_id,
    _set_range_bearing_time,
    _set_range_bearing_bearing,
    _set_range_bearing_error,
    _set_range_bearing_offset,
    _set_range_min,
    _set_range_max,
) = _RANGE_BEARING_SETTERS


@dataclass(frozen=True, slots=True)
class GroundLineObservation:
    """A Class III observation of a ground line.

    ``offset`` is the signed distance (m) from the sensor to the line, positive when
    the sensor is to the left of start -> end, within +-``offset_error``; ``angle`` is
    the direction start -> end relative to the heading (rad), within +-``angle_error``.

    Examples
    --------
    >>> seen = GroundLineObservation("sidewalk_left_edge", 3.0, 1.2, 0.05, -0.1, 0.02)
    >>> seen.landmark_class, seen.offset, seen.angle
    (<LandmarkClass.GROUND_LINE: 'III'>, 1.2, -0.1)
    >>> GroundLineObservation("sidewalk_left_edge", 3.0, 1.2, 0.05, float("nan"), 0.02)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: angle: expected a finite number, got nan
    """

    landmark_id: str
    time: float
    offset: float
    offset_error: float
    angle: float
    angle_error: float
    sensor_offset: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        for name, value in zip(
            _COMMON, _common(self.landmark_id, self.time, self.sensor_offset), strict=True
        ):
            object.__setattr__(self, name, value)
        object.__setattr__(self, "offset", finite_float(self.offset, "offset"))
        object.__setattr__(self, "offset_error", nonnegative_float(self.offset_error, "offset_error"))
        object.__setattr__(self, "angle", finite_float(self.angle, "angle"))
        object.__setattr__(self, "angle_error", nonnegative_float(self.angle_error, "angle_error"))

    @property
    def landmark_class(self) -> LandmarkClass:
        """Always :attr:`LandmarkClass.GROUND_LINE`."""
        return LandmarkClass.GROUND_LINE


#: Any observation a reduction accepts.
Observation = BearingObservation | RangeBearingObservation | GroundLineObservation
