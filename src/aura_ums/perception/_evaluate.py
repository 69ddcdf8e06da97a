"""Accuracy of detected line segments against annotated ones (e.g. the York Urban database).

The metric, pixel-based and symmetric:

- **recall**: points sampled every ``step`` (1) pixel along the ground-truth segments
  (both endpoints included) are *recalled* when some detected segment of similar
  direction (within ``angle_tolerance``, modulo pi) passes within ``distance`` pixels of
  the point (distance to the segment, not to its infinite line);
- **precision**: points sampled likewise along the detected segments are *precise* when
  some reference segment of similar direction passes within ``distance`` pixels.

Both are ratios of point counts, so long segments weigh more than short ones, and
counts pool across images by adding :class:`RecallPrecision` values. When annotations
are incomplete (York Urban annotates only segments aligned with the three Manhattan
directions) precision is a lower bound: unannotated true lines count against it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import nonnegative_float, positive_float
from aura_ums.errors import InputError
from aura_ums.perception._segments import _orientation, _orientation_difference

_CHUNK = 2048
#: Most sample points one call of :func:`sample_points` makes (all segments together): each
#: takes about 48 bytes while it is built, so 0.48 GB; a step of 1e-300 px asked for far more.
MAX_SAMPLE_POINTS = 10_000_000
#: Bytes per sample point while :func:`sample_points` builds them (coordinates, owner, parameter).
_SAMPLE_BYTES = 48


@dataclass(frozen=True, slots=True)
class RecallPrecision:
    """Point counts of :func:`segment_recall_precision`; add values to pool images.

    Parameters
    ----------
    recalled, ground_truth_points : int
        Ground-truth sample points recalled, and all of them.
    precise, detected_points : int
        Detected sample points near a reference segment, and all of them.

    Examples
    --------
    >>> total = RecallPrecision(3, 4, 1, 2) + RecallPrecision(1, 4, 1, 2)
    >>> total.recall, total.precision
    (0.5, 0.5)
    >>> RecallPrecision(0, 0, 0, 0).recall        # nothing to recall: undefined
    nan
    """

    recalled: int
    ground_truth_points: int
    precise: int
    detected_points: int

    @property
    def recall(self) -> float:
        """``recalled / ground_truth_points`` (NaN when there are no ground-truth points)."""
        return self.recalled / self.ground_truth_points if self.ground_truth_points else math.nan

    @property
    def precision(self) -> float:
        """``precise / detected_points`` (NaN when nothing was detected)."""
        return self.precise / self.detected_points if self.detected_points else math.nan

    def __add__(self, other: RecallPrecision) -> RecallPrecision:
        return RecallPrecision(
            self.recalled + other.recalled,
            self.ground_truth_points + other.ground_truth_points,
            self.precise + other.precise,
            self.detected_points + other.detected_points,
        )


def _segments(value: ArrayLike, name: str) -> NDArray[np.float64]:
    try:
        array = np.array(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name}: expected an (n, 4) array of numbers, got {value!r}") from exc
    if array.size == 0:
        array = array.reshape(0, 4)
    if array.ndim != 2 or array.shape[1] != 4:
        raise InputError(f"{name}: expected shape (n, 4), got {array.shape}")
    if not np.isfinite(array).all():
        raise InputError(f"{name}: expected finite coordinates, got NaN or infinity")
    return array


def sample_points(segments: ArrayLike, step: float = 1.0) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
    """Points every ``step`` pixels along each segment, endpoints included, and their segment index.

    ``segments`` is a finite ``(n, 4)`` array (``x1, y1, x2, y2``, pixels); ``step`` > 0
    pixels. At most 10,000,000 points are made.

    Examples
    --------
    >>> points, owner = sample_points(np.array([[0.0, 0.0, 2.0, 0.0]]))
    >>> points.tolist(), owner.tolist()
    ([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]], [0, 0, 0])
    >>> sample_points([[0.0, 0.0, 2.0, 0.0]], 0.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: step: expected a positive number, got 0.0
    """
    return _sample_points(_segments(segments, "segments"), positive_float(step, "step"))


def _sample_points(
    segments: NDArray[np.float64], step: float
) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
    """:func:`sample_points` of checked segments and step; refuses more than :data:`MAX_SAMPLE_POINTS`."""
    d = segments[:, 2:] - segments[:, :2]
    steps = np.ceil(np.hypot(d[:, 0], d[:, 1]) / step - 1e-9)
    total = float(np.sum(np.maximum(steps, 1.0) + 1.0))
    if total > MAX_SAMPLE_POINTS:
        raise InputError(
            f"step: expected a step that makes at most {MAX_SAMPLE_POINTS} sample points "
            f"(about {MAX_SAMPLE_POINTS * _SAMPLE_BYTES / 1e9:.2g} GB), got {step!r}, which makes "
            f"{total:.3g} (about {total * _SAMPLE_BYTES / 1e9:.3g} GB)"
        )
    counts = np.maximum(steps.astype(np.intp), 1) + 1
    owner = np.repeat(np.arange(segments.shape[0]), counts)
    first = np.cumsum(counts) - counts
    t = (np.arange(owner.size) - first[owner]) / (counts[owner] - 1)
    return np.asarray(segments[owner, :2] + t[:, None] * d[owner], dtype=np.float64), owner


def _matched(
    points: NDArray[np.float64],
    point_angle: NDArray[np.float64],
    segments: NDArray[np.float64],
    distance: float,
    angle_tolerance: float,
) -> int:
    """Count the points within ``distance`` of a segment of similar direction."""
    if points.shape[0] == 0 or segments.shape[0] == 0:
        return 0
    a = segments[:, :2]
    d = segments[:, 2:] - a
    dd = np.maximum(np.einsum("ij,ij->i", d, d), 1e-12)
    seg_angle = _orientation(segments)
    found = 0
    for lo in range(0, points.shape[0], _CHUNK):
        p = points[lo : lo + _CHUNK]
        rel_x = p[:, None, 0] - a[None, :, 0]
        rel_y = p[:, None, 1] - a[None, :, 1]
        t = np.clip((rel_x * d[None, :, 0] + rel_y * d[None, :, 1]) / dd[None, :], 0.0, 1.0)
        ex = rel_x - t * d[None, :, 0]
        ey = rel_y - t * d[None, :, 1]
        close = ex * ex + ey * ey <= distance * distance
        close &= (
            _orientation_difference(point_angle[lo : lo + _CHUNK, None], seg_angle[None, :])
            <= angle_tolerance
        )
        found += int(close.any(axis=1).sum())
    return found


def segment_recall_precision(
    detected: ArrayLike,
    ground_truth: ArrayLike,
    *,
    distance: float = 2.0,
    angle_tolerance: float = math.radians(5.0),
    step: float = 1.0,
    reference: ArrayLike | None = None,
) -> RecallPrecision:
    """Compare detected segments with annotated ones, point by point (see the module's metric).

    Parameters
    ----------
    detected : array_like, shape (n, 4)
        Detected segments ``x1, y1, x2, y2``, pixels.
    ground_truth : array_like, shape (m, 4)
        Annotated segments whose recall is measured, pixels.
    distance : float
        Largest distance from a sample point to a matching segment, pixels.
    angle_tolerance : float
        Largest difference of direction (modulo pi) between matching segments, radians.
    step : float
        Spacing of the sample points along segments, pixels (> 0).
    reference : array_like, shape (k, 4), optional
        Segments against which precision is measured; default ``ground_truth``. Pass all
        annotated segments when recall is measured on a subset of them (e.g. verticals).

    Returns
    -------
    RecallPrecision
        The four point counts, with ``recall`` and ``precision``.

    Examples
    --------
    >>> truth = [[10.0, 0.0, 10.0, 40.0]]
    >>> found = [[11.0, 0.0, 11.0, 20.0], [30.0, 0.0, 30.0, 10.0]]
    >>> result = segment_recall_precision(found, truth)
    >>> result.recalled, result.ground_truth_points, result.precise, result.detected_points
    (22, 41, 21, 32)
    >>> segment_recall_precision(np.zeros((0, 4)), truth).recall     # nothing detected
    0.0
    """
    found = _segments(detected, "detected")
    truth = _segments(ground_truth, "ground_truth")
    against = truth if reference is None else _segments(reference, "reference")
    distance = nonnegative_float(distance, "distance")
    angle_tolerance = nonnegative_float(angle_tolerance, "angle_tolerance")
    step = nonnegative_float(step, "step")
    if step == 0.0:
        raise InputError(f"step: expected a positive number, got {step!r}")
    truth_points, truth_owner = _sample_points(truth, step)
    found_points, found_owner = _sample_points(found, step)
    recalled = _matched(truth_points, _orientation(truth)[truth_owner], found, distance, angle_tolerance)
    precise = _matched(found_points, _orientation(found)[found_owner], against, distance, angle_tolerance)
    return RecallPrecision(recalled, int(truth_points.shape[0]), precise, int(found_points.shape[0]))
