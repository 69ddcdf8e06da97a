"""Line segments found in an image, with the attributes that evaluation needs."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import ANGLE, float_array, nonnegative_float, number_array
from aura_ums.errors import InputError
from aura_ums.geometry import angle_difference


def segment_orientation(segments: ArrayLike) -> NDArray[np.float64]:
    """Return the direction of each segment ``(n, 4)`` in ``[0, pi)``, radians.

    The angle of ``(x2 - x1, y2 - y1)`` in pixel coordinates (u right, v down), modulo
    pi: 0 is horizontal, pi/2 vertical; a segment going down and to the right has an
    angle in ``(0, pi/2)`` (clockwise on the screen).

    Examples
    --------
    >>> segments = np.array([[0.0, 0.0, 10.0, 0.0], [5.0, 0.0, 5.0, 8.0], [0.0, 0.0, 4.0, 4.0]])
    >>> segment_orientation(segments).round(4).tolist()   # horizontal, vertical, down-right
    [0.0, 1.5708, 0.7854]
    >>> float(segment_orientation(np.array([[10.0, 0.0, 0.0, 0.0]]))[0])   # either way round
    0.0
    >>> segment_orientation(np.zeros((0, 4)))              # no segment
    array([], dtype=float64)
    >>> segment_orientation([0.0, 0.0, 1.0, 1.0])
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: segments: expected an (n, 4) array of x1, y1, x2, y2 pixels, got shape (4,)
    """
    array = float_array(segments, "segments")
    if array.ndim != 2 or array.shape[1] != 4:
        raise InputError(
            f"segments: expected an (n, 4) array of x1, y1, x2, y2 pixels, got shape {array.shape}"
        )
    return _orientation(array)


def _orientation(segments: NDArray[np.float64]) -> NDArray[np.float64]:
    """:func:`segment_orientation` of a checked ``(n, 4)`` float array (a detector's, or checked data)."""
    angle = np.arctan2(segments[:, 3] - segments[:, 1], segments[:, 2] - segments[:, 0])
    return np.asarray(np.mod(angle, math.pi), dtype=np.float64)


def orientation_difference(a: ArrayLike, b: ArrayLike) -> NDArray[np.float64]:
    """Return the difference of line orientations ``a`` and ``b``, in ``[0, pi/2]`` radians.

    A line has no sense: orientations ``t`` and ``t + pi`` are the same line, so the
    difference is the smaller turn, either way, that brings one line onto the other (the
    signed difference of directions, :func:`aura_ums.geometry.angle_difference`, folded).

    Parameters
    ----------
    a, b : array_like
        Orientations, radians, broadcast against each other.

    Returns
    -------
    ndarray
        The differences, radians in ``[0, pi/2]``, of the broadcast shape.

    Examples
    --------
    >>> orientation_difference([0.1, 3.1], 0.0).round(4).tolist()
    [0.1, 0.0416]
    >>> float(orientation_difference(0.0, np.pi))   # the same line, either way round
    0.0
    >>> orientation_difference(None, [0.1])
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: a: expected orientations (numbers), got None
    """
    first, second = _orientations(a, "a"), _orientations(b, "b")
    try:
        np.broadcast_shapes(first.shape, second.shape)
    except ValueError as exc:
        raise InputError(
            f"b: expected a shape that broadcasts against a's {first.shape}, got {second.shape}"
        ) from exc
    return _orientation_difference(first, second)


def _orientations(value: ArrayLike, name: str) -> NDArray[np.float64]:
    """Return orientations as a float array, each finite and in :data:`~aura_ums._validate.ANGLE`."""
    array = float_array(number_array(value, name, "orientations (numbers)"), name)
    if np.any(np.abs(array) > ANGLE.high):
        raise InputError(
            f"{name}: expected orientations {ANGLE.text()}, got {float(np.max(np.abs(array)))!r}"
        )
    return array


def _orientation_difference(a: NDArray[np.float64], b: NDArray[np.float64] | float) -> NDArray[np.float64]:
    """:func:`orientation_difference` of trusted float orientations (detectors and evaluations, per frame)."""
    turn = np.abs(angle_difference(np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)))
    return np.asarray(np.minimum(turn, math.pi - turn), dtype=np.float64)


@dataclass(frozen=True, slots=True, eq=False, init=False)
class LineSegments:
    """Line segments in full-image pixel coordinates, with their contrast.

    Parameters
    ----------
    segments : array_like, shape (n, 4)
        ``x1, y1, x2, y2`` per segment, pixels (u, v; (0, 0) is the top-left pixel's centre).
    contrast : array_like, shape (n,)
        Mean gradient magnitude along each segment's support, gray levels per pixel.

    Raises
    ------
    InputError
        When the shapes disagree or a value is not finite.

    Notes
    -----
    Both arrays are read-only copies; values compare by identity (they hold arrays).

    Examples
    --------
    >>> lines = LineSegments([[10.0, 0.0, 10.0, 40.0], [0.0, 5.0, 3.0, 9.0]], [20.0, 4.0])
    >>> lines.length.tolist(), lines.orientation.round(4).tolist(), lines.strength.tolist()
    ([40.0, 5.0], [1.5708, 0.9273], [800.0, 20.0])
    >>> len(LineSegments.empty()), LineSegments.empty().segments.shape
    (0, (0, 4))
    """

    segments: NDArray[np.float64]
    contrast: NDArray[np.float64]

    def __init__(self, segments: ArrayLike, contrast: ArrayLike) -> None:
        try:
            array = np.array(segments, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise InputError(
                f"LineSegments.segments: expected an (n, 4) array of numbers, got {segments!r}"
            ) from exc
        try:
            values = np.array(contrast, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise InputError(
                f"LineSegments.contrast: expected an (n,) array of numbers, got {contrast!r}"
            ) from exc
        if array.size == 0:
            array = array.reshape(0, 4)
        if array.ndim != 2 or array.shape[1] != 4:
            raise InputError(f"LineSegments.segments: expected shape (n, 4), got {array.shape}")
        values = values.reshape(-1) if values.ndim == 0 else values
        if values.shape != (array.shape[0],):
            raise InputError(f"LineSegments.contrast: expected shape ({array.shape[0]},), got {values.shape}")
        if not (np.isfinite(array).all() and np.isfinite(values).all()):
            raise InputError("LineSegments: expected finite values, got NaN or infinity")
        array.setflags(write=False)
        values.setflags(write=False)
        object.__setattr__(self, "segments", array)
        object.__setattr__(self, "contrast", values)

    @classmethod
    def _trusted(cls, segments: NDArray[np.float64], contrast: NDArray[np.float64]) -> LineSegments:
        """Wrap arrays a detector has just computed (float64, ``(n, 4)`` and ``(n,)``, finite)."""
        lines = object.__new__(cls)
        segments.setflags(write=False)
        contrast.setflags(write=False)
        object.__setattr__(lines, "segments", segments)
        object.__setattr__(lines, "contrast", contrast)
        return lines

    @classmethod
    def empty(cls) -> LineSegments:
        """Return no segments: ``segments`` of shape ``(0, 4)``."""
        return cls(np.zeros((0, 4)), np.zeros(0))

    def __len__(self) -> int:
        return int(self.segments.shape[0])

    @property
    def length(self) -> NDArray[np.float64]:
        """Length of each segment, pixels, shape ``(n,)``."""
        d = self.segments[:, 2:] - self.segments[:, :2]
        return np.asarray(np.hypot(d[:, 0], d[:, 1]), dtype=np.float64)

    @property
    def orientation(self) -> NDArray[np.float64]:
        """Direction of each segment, radians in ``[0, pi)`` (see :func:`segment_orientation`)."""
        return _orientation(self.segments)

    @property
    def midpoints(self) -> NDArray[np.float64]:
        """Midpoint ``(u, v)`` of each segment, pixels, shape ``(n, 2)``."""
        return np.asarray(0.5 * (self.segments[:, :2] + self.segments[:, 2:]), dtype=np.float64)

    @property
    def strength(self) -> NDArray[np.float64]:
        """``length * contrast`` per segment: the paper's line strength (Class I)."""
        return np.asarray(self.length * self.contrast, dtype=np.float64)

    def select(self, keep: ArrayLike) -> LineSegments:
        """Return the segments picked by a boolean mask ``(n,)`` or a 1-D array of indices in ``[-n, n)``.

        Examples
        --------
        >>> lines = LineSegments([[0, 0, 10, 0], [0, 0, 0, 10]], [1.0, 2.0])
        >>> lines.select([True, False]).contrast.tolist(), lines.select([1]).contrast.tolist()
        ([1.0], [2.0])
        >>> len(lines.select([]))
        0
        >>> lines.select([0, 5])
        Traceback (most recent call last):
        ...
        aura_ums.errors.InputError: keep: expected indices in [-2, 2), got 5
        """
        index = self._index(keep)
        return LineSegments(self.segments[index], self.contrast[index])

    def _index(self, keep: ArrayLike) -> NDArray[np.bool_] | NDArray[np.intp]:
        """Check ``keep`` (a mask or indices) against the ``n`` segments, as :meth:`select` takes it."""
        n = len(self)
        try:
            index = np.asarray(keep)
        except (TypeError, ValueError) as exc:  # ragged sequences
            raise InputError(f"keep: expected a boolean mask or integer indices, got {keep!r}") from exc
        if index.size == 0 and index.ndim == 1:
            return np.zeros(0, dtype=np.intp)  # [] picks nothing (numpy reads it as float indices)
        if index.ndim != 1 or index.dtype.kind not in "biu":
            raise InputError(
                f"keep: expected a 1-D boolean mask or integer indices, "
                f"got {index.dtype} of shape {index.shape}"
            )
        if index.dtype.kind == "b":
            if index.shape != (n,):
                raise InputError(f"keep: expected a boolean mask of shape ({n},), got shape {index.shape}")
            return index
        outside = (index < -n) | (index >= n)
        if np.any(outside):
            raise InputError(f"keep: expected indices in [{-n}, {n}), got {int(index[np.argmax(outside)])}")
        return np.asarray(index, dtype=np.intp)

    def within(self, orientation: float, tolerance: float) -> LineSegments:
        """Return the segments within ``tolerance`` of direction ``orientation`` (radians, mod pi).

        ``orientation`` is finite, in [-1000, 1000] radians; ``tolerance`` finite and >= 0.

        Examples
        --------
        >>> lines = LineSegments([[0, 0, 10, 0], [0, 0, 0, 10]], [1.0, 2.0])
        >>> lines.within(np.pi / 2, 0.1).segments.tolist()
        [[0.0, 0.0, 0.0, 10.0]]
        >>> lines.within(0.0, float("nan"))
        Traceback (most recent call last):
        ...
        aura_ums.errors.InputError: tolerance: expected a finite number, got nan
        """
        target = ANGLE.check(orientation, "orientation")
        limit = nonnegative_float(tolerance, "tolerance")
        keep = _orientation_difference(self.orientation, target) <= limit
        return LineSegments(self.segments[keep], self.contrast[keep])
