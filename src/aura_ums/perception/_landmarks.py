"""Evaluation functions: how strongly a window's features show a landmark of each class.

Each function takes what a perceptual strategy found in the Expecter's window and
returns a value type whose ``value`` (a float, larger is stronger, 0 when nothing fits)
the find-landmark schema compares with the landmark's recognition threshold, and the
image location it found (None when nothing fits). Following the paper:

- Class I (a vertical line, e.g. a lamppost): the strongest line of the right direction,
  strength = length x mean gradient magnitude (:func:`evaluate_vertical_line`);
- Class II (a point, e.g. a building corner): the strongest interest point, preferring
  one supported by the intersection of two lines of different directions (mutual
  concurrent discovery by two perceptual strategies; :func:`evaluate_corner`);
- Class III (a ground line, e.g. a path edge): the strongest long line within the
  tolerance of its expected image direction (:func:`evaluate_path_edge`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import finite_float, nonnegative_float
from aura_ums.errors import InputError
from aura_ums.perception._segments import LineSegments, _orientation_difference

#: At most this many of the strongest lines are intersected pairwise by :func:`evaluate_corner`.
MAX_CORNER_LINES = 64


@dataclass(frozen=True, slots=True)
class LineEvidence:
    """The line that best shows a Class I or Class III landmark.

    Parameters
    ----------
    value : float
        Its strength, ``length * contrast`` (pixels times gray levels per pixel); 0 when
        no line fits.
    segment : tuple of float or None
        ``(x1, y1, x2, y2)``, full-image pixels.
    point : tuple of float or None
        ``(u, v)``: its midpoint, full-image pixels.

    Examples
    --------
    >>> found = LineEvidence(960.0, (50.0, 10.0, 51.0, 90.0), (50.5, 50.0))
    >>> found.found, found.column
    (True, 50.5)
    >>> nothing = LineEvidence(0.0, None, None)               # no line fits
    >>> nothing.found, nothing.column
    (False, None)
    """

    value: float
    segment: tuple[float, float, float, float] | None
    point: tuple[float, float] | None

    @property
    def found(self) -> bool:
        """Whether a line fits at all."""
        return self.segment is not None

    @property
    def column(self) -> float | None:
        """Image column ``u`` of the midpoint, pixels (what a Class I bearing needs)."""
        return None if self.point is None else self.point[0]


@dataclass(frozen=True, slots=True)
class CornerEvidence:
    """The interest point that best shows a Class II landmark.

    Parameters
    ----------
    value : float
        The interest point's response (gray levels squared, see :class:`MoravecOperator`);
        0 when there is no point.
    point : tuple of float or None
        ``(u, v)``, full-image pixels.
    supported : bool
        Whether two lines of different directions intersect within the support radius of
        the point.
    intersection : tuple of float or None
        ``(u, v)`` of that intersection, full-image pixels.

    Examples
    --------
    >>> corner = CornerEvidence(400.0, (12.0, 11.0), True, (10.0, 10.0))
    >>> corner.point, corner.supported, corner.intersection
    ((12.0, 11.0), True, (10.0, 10.0))
    >>> CornerEvidence(900.0, (30.0, 30.0), False, None).intersection is None   # a point alone
    True
    >>> evaluate_corner(np.zeros((0, 3)))                     # no interest point at all
    CornerEvidence(value=0.0, point=None, supported=False, intersection=None)
    """

    value: float
    point: tuple[float, float] | None
    supported: bool
    intersection: tuple[float, float] | None


def _check_lines(lines: object) -> None:
    if not isinstance(lines, LineSegments):
        raise InputError(f"lines: expected LineSegments, got {type(lines).__name__}")


def _best_line(lines: LineSegments, keep: NDArray[np.bool_]) -> LineEvidence:
    strength = np.where(keep, lines.strength, -np.inf)
    if strength.size == 0 or not np.isfinite(strength).any():
        return LineEvidence(0.0, None, None)
    best = int(np.argmax(strength))
    x1, y1, x2, y2 = (float(v) for v in lines.segments[best])
    return LineEvidence(float(strength[best]), (x1, y1, x2, y2), (0.5 * (x1 + x2), 0.5 * (y1 + y2)))


def evaluate_vertical_line(
    lines: LineSegments, *, orientation: float = math.pi / 2, tolerance: float = math.radians(10.0)
) -> LineEvidence:
    """Class I: the strongest line within ``tolerance`` of ``orientation``.

    Parameters
    ----------
    lines : LineSegments
        Lines found in the window (e.g. by :meth:`FastLineFinder.find_detailed`).
    orientation : float
        Expected image direction of the landmark, radians (pi/2: vertical; a camera that
        rolls or tilts sees world verticals a few degrees off).
    tolerance : float
        Largest difference of direction, radians.

    Returns
    -------
    LineEvidence
        Strength (``length * contrast``), segment, midpoint and its column.

    Examples
    --------
    >>> lines = LineSegments([[50, 10, 51, 90], [20, 5, 90, 6], [30, 40, 30, 50]], [12.0, 40.0, 30.0])
    >>> found = evaluate_vertical_line(lines)
    >>> found.value.__round__(1), found.column
    (960.1, 50.5)
    >>> evaluate_vertical_line(LineSegments.empty())        # nothing in the window
    LineEvidence(value=0.0, segment=None, point=None)
    """
    _check_lines(lines)
    target = finite_float(orientation, "orientation")
    limit = nonnegative_float(tolerance, "tolerance")
    return _strongest_within(lines, target, limit)


def strongest_within(lines: LineSegments, orientation: float, tolerance: float) -> LineEvidence:
    """Return the strongest line within ``tolerance`` of ``orientation``.

    :func:`evaluate_vertical_line` with positional arguments and no defaults (a schema
    evaluates every frame with the same ones); the checks of its arguments are cheap.

    Parameters
    ----------
    lines : LineSegments
        Lines found in the window.
    orientation : float
        Expected image direction, radians, finite.
    tolerance : float
        Largest difference of direction, radians, >= 0.

    Returns
    -------
    LineEvidence
        As :func:`evaluate_vertical_line`.

    Examples
    --------
    >>> lines = LineSegments([[50, 10, 51, 90], [20, 5, 90, 6]], [12.0, 40.0])
    >>> strongest_within(lines, math.pi / 2, 0.1).column
    50.5
    >>> strongest_within(lines, 0.7, 0.1).segment is None   # no line that direction
    True
    >>> strongest_within(None, 0.7, 0.1)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: lines: expected LineSegments, got NoneType
    """
    _check_lines(lines)
    target = finite_float(orientation, "orientation")
    limit = nonnegative_float(tolerance, "tolerance")
    return _strongest_within(lines, target, limit)


def _strongest_within(lines: LineSegments, orientation: float, tolerance: float) -> LineEvidence:
    """:func:`strongest_within` of checked arguments."""
    return _best_line(lines, _orientation_difference(lines.orientation, orientation) <= tolerance)


def evaluate_path_edge(
    lines: LineSegments,
    orientation: float,
    *,
    tolerance: float = math.radians(10.0),
    min_length: float = 40.0,
) -> LineEvidence:
    """Class III: the strongest line at least ``min_length`` long within ``tolerance`` of ``orientation``.

    Parameters
    ----------
    lines : LineSegments
        Lines found in the window.
    orientation : float
        Expected image direction of the path edge, radians (from the Expecter's
        prediction of the ground line's projection).
    tolerance : float
        Largest difference of direction, radians.
    min_length : float
        Shortest line that counts as a path edge, pixels.

    Returns
    -------
    LineEvidence
        Strength (``length * contrast``), segment and midpoint.

    Examples
    --------
    >>> lines = LineSegments([[0, 100, 80, 60], [10, 10, 20, 5]], [20.0, 90.0])
    >>> evaluate_path_edge(lines, orientation=math.atan2(-40, 80)).segment
    (0.0, 100.0, 80.0, 60.0)
    >>> evaluate_path_edge(lines, orientation=0.0).found      # no long line that way
    False
    """
    _check_lines(lines)
    target = finite_float(orientation, "orientation")
    limit = nonnegative_float(tolerance, "tolerance")
    shortest = nonnegative_float(min_length, "min_length")
    keep = (_orientation_difference(lines.orientation, target) <= limit) & (lines.length >= shortest)
    return _best_line(lines, keep)


def line_intersections(lines: LineSegments, *, radius: float, min_angle: float) -> NDArray[np.float64]:
    """Return the intersections ``(k, 2)`` of pairs of lines whose directions differ by ``min_angle`` or more.

    Only intersections within ``radius`` pixels of both segments count (lines that meet
    at a corner, not far away on their extensions).

    Examples
    --------
    >>> lines = LineSegments([[10, 10, 10, 40], [11, 10, 40, 10], [60, 0, 60, 5]], [1.0, 1.0, 1.0])
    >>> line_intersections(lines, radius=2.0, min_angle=0.5)
    array([[10., 10.]])
    >>> line_intersections(lines, radius=None, min_angle=0.5)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: radius: expected a finite number, got None
    """
    _check_lines(lines)
    return _line_intersections(
        lines, nonnegative_float(radius, "radius"), nonnegative_float(min_angle, "min_angle")
    )


def _line_intersections(lines: LineSegments, radius: float, min_angle: float) -> NDArray[np.float64]:
    """:func:`line_intersections` of checked arguments."""
    order = np.argsort(-lines.strength, kind="stable")[:MAX_CORNER_LINES]
    seg = lines.segments[order]
    n = seg.shape[0]
    if n < 2:
        return np.zeros((0, 2))
    i, j = np.triu_indices(n, k=1)
    angles = lines.orientation[order]
    pairs = _orientation_difference(angles[i], angles[j]) >= min_angle
    i, j = i[pairs], j[pairs]
    p, r = seg[i, :2], seg[i, 2:] - seg[i, :2]
    q, s = seg[j, :2], seg[j, 2:] - seg[j, :2]
    cross = r[:, 0] * s[:, 1] - r[:, 1] * s[:, 0]
    qp = q - p
    t = (qp[:, 0] * s[:, 1] - qp[:, 1] * s[:, 0]) / np.where(cross == 0.0, 1.0, cross)
    point = p + t[:, None] * r
    near = (cross != 0.0) & (_distance_to_segments(point, seg[i]) <= radius)
    near &= _distance_to_segments(point, seg[j]) <= radius
    return np.asarray(point[near], dtype=np.float64)


def _distance_to_segments(points: NDArray[np.float64], segments: NDArray[np.float64]) -> NDArray[np.float64]:
    """Distance from each point to the segment of the same row."""
    a, d = segments[:, :2], segments[:, 2:] - segments[:, :2]
    dd = np.maximum(np.einsum("ij,ij->i", d, d), 1e-12)
    t = np.clip(np.einsum("ij,ij->i", points - a, d) / dd, 0.0, 1.0)
    e = points - a - t[:, None] * d
    return np.asarray(np.hypot(e[:, 0], e[:, 1]), dtype=np.float64)


def evaluate_corner(
    points: ArrayLike,
    lines: LineSegments | None = None,
    *,
    support_radius: float = 4.0,
    min_angle: float = math.radians(30.0),
) -> CornerEvidence:
    """Class II: the strongest interest point, preferring one supported by two lines meeting near it.

    Parameters
    ----------
    points : array_like, shape (n, 3)
        Interest points ``x, y, response`` (e.g. from :meth:`MoravecOperator.find`).
    lines : LineSegments or None
        Lines found in the same window; None: interest points alone.
    support_radius : float
        How near (pixels) the two lines must pass to each other's intersection and the
        intersection to the point.
    min_angle : float
        Smallest difference of direction between the two lines, radians.

    Returns
    -------
    CornerEvidence
        The strongest supported point when there is one, else the strongest point.

    Examples
    --------
    >>> points = [[30.0, 30.0, 900.0], [12.0, 11.0, 400.0]]
    >>> evaluate_corner(points).point                       # the strongest point
    (30.0, 30.0)
    >>> lines = LineSegments([[10, 10, 10, 40], [10, 10, 40, 10]], [20.0, 20.0])
    >>> corner = evaluate_corner(points, lines)             # the point where two lines meet
    >>> corner.point, corner.value, corner.supported
    ((12.0, 11.0), 400.0, True)
    >>> evaluate_corner(np.zeros((0, 3))).value             # no interest point
    0.0
    """
    try:
        array = np.array(points, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"points: expected an (n, 3) array of numbers, got {points!r}") from exc
    if array.size == 0:
        array = array.reshape(0, 3)
    if array.ndim != 2 or array.shape[1] != 3 or not np.isfinite(array).all():
        raise InputError(f"points: expected a finite (n, 3) array (x, y, response), got shape {array.shape}")
    radius = nonnegative_float(support_radius, "support_radius")
    angle = nonnegative_float(min_angle, "min_angle")
    if lines is not None:
        _check_lines(lines)
    if array.shape[0] == 0:
        return CornerEvidence(0.0, None, False, None)
    order = np.argsort(-array[:, 2], kind="stable")
    array = array[order]
    if lines is not None:
        crossings = _line_intersections(lines, radius, angle)
        if crossings.shape[0]:
            gap = np.hypot(
                array[:, None, 0] - crossings[None, :, 0], array[:, None, 1] - crossings[None, :, 1]
            )
            supported = (gap <= radius).any(axis=1)
            if supported.any():
                k = int(np.argmax(supported))  # the first supported point is the strongest
                c = crossings[int(np.argmin(gap[k]))]
                return CornerEvidence(
                    float(array[k, 2]),
                    (float(array[k, 0]), float(array[k, 1])),
                    True,
                    (float(c[0]), float(c[1])),
                )
    return CornerEvidence(float(array[0, 2]), (float(array[0, 0]), float(array[0, 1])), False, None)
