"""The optional OpenCV backend (the ``opencv`` extra): lazy import, and LSD behind the same interface."""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import ModuleType

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import finite_float, nonnegative_float
from aura_ums.errors import MissingDependencyError
from aura_ums.geometry import ImageWindow
from aura_ums.perception._image import prepare
from aura_ums.perception._segments import LineSegments, _orientation_difference


def import_cv2(what: str) -> ModuleType:
    """Import OpenCV, or raise :class:`MissingDependencyError` naming the ``opencv`` extra."""
    try:
        import cv2
    except ImportError as exc:
        raise MissingDependencyError(
            f"{what}: expected OpenCV from the optional 'opencv' extra "
            f"(pip install 'aura-ums[opencv]'), got {exc}"
        ) from exc
    return cv2


def sample_contrast(
    magnitude: NDArray[np.float32], segments: NDArray[np.float64], *, step: float = 1.0
) -> NDArray[np.float64]:
    """Mean of ``magnitude`` (h, w) at points every ``step`` pixels along each segment (nearest pixel)."""
    if segments.shape[0] == 0:
        return np.zeros(0)
    d = segments[:, 2:] - segments[:, :2]
    counts = np.floor(np.hypot(d[:, 0], d[:, 1]) / step).astype(np.int64) + 1
    owner = np.repeat(np.arange(segments.shape[0]), counts)
    first = np.cumsum(counts) - counts
    t = (np.arange(owner.size) - first[owner]) / np.maximum(counts[owner] - 1, 1)
    points = segments[owner, :2] + t[:, None] * d[owner]
    h, w = magnitude.shape
    cols = np.clip(np.rint(points[:, 0]).astype(np.int64), 0, w - 1)
    rows = np.clip(np.rint(points[:, 1]).astype(np.int64), 0, h - 1)
    sums = np.bincount(owner, magnitude[rows, cols].astype(np.float64), minlength=segments.shape[0])
    return np.asarray(sums / counts, dtype=np.float64)


@dataclass(frozen=True, slots=True)
class OpenCvLineFinder:
    """OpenCV's Line Segment Detector (LSD, von Gioi et al.) behind :class:`FastLineFinder`'s interface.

    The baseline the fast line finder is compared against; needs the ``opencv`` extra.
    Segments are filtered like the fast line finder's: by direction (within ``tolerance``
    of ``orientation``), by length and by contrast (mean Sobel gradient magnitude sampled
    along the segment, gray levels per pixel).

    Parameters
    ----------
    orientation : float or None
        Target line direction in the image, radians (0 horizontal, pi/2 vertical; see
        :func:`segment_orientation`); None keeps every direction.
    tolerance : float
        Largest difference between a segment's direction and ``orientation``, radians.
    min_length : float
        Shortest segment kept, pixels.
    min_contrast : float
        Lowest mean gradient magnitude kept, gray levels per pixel.

    Raises
    ------
    MissingDependencyError
        When OpenCV is not installed (on first use).

    Examples
    --------
    >>> import numpy as np
    >>> image = np.zeros((60, 80), dtype=np.uint8)
    >>> image[:, 40:] = 200
    >>> finder = OpenCvLineFinder(orientation=np.pi / 2)
    >>> lines = finder.find(image)                                   # doctest: +SKIP
    >>> finder.find(np.zeros((30, 30))).shape                        # doctest: +SKIP
    (0, 4)
    """

    orientation: float | None = None
    tolerance: float = math.radians(10.0)
    min_length: float = 10.0
    min_contrast: float = 0.0

    def __post_init__(self) -> None:
        if self.orientation is not None:
            object.__setattr__(self, "orientation", finite_float(self.orientation, "orientation") % math.pi)
        object.__setattr__(self, "tolerance", nonnegative_float(self.tolerance, "tolerance"))
        object.__setattr__(self, "min_length", nonnegative_float(self.min_length, "min_length"))
        object.__setattr__(self, "min_contrast", nonnegative_float(self.min_contrast, "min_contrast"))

    def find(self, image: ArrayLike, window: ImageWindow | None = None) -> NDArray[np.float64]:
        """Return segments ``(n, 4)``: ``x1, y1, x2, y2``, full-image pixels (see :meth:`find_detailed`)."""
        return self.find_detailed(image, window).segments

    def find_detailed(self, image: ArrayLike, window: ImageWindow | None = None) -> LineSegments:
        """Run LSD on the window (or the whole image) and return the kept segments.

        Parameters
        ----------
        image : array_like, shape (h, w)
            Grayscale gray levels; rounded and clipped to 0-255 for LSD.
        window : ImageWindow or None
            Only the pixels this window overlaps are processed; segments are in full-image
            pixel coordinates.
        """
        cv2 = import_cv2("OpenCvLineFinder")
        crop = prepare(image, window, context=0)
        gray = np.ascontiguousarray(np.clip(np.rint(crop.pixels), 0, 255).astype(np.uint8))
        if gray.shape[0] < 2 or gray.shape[1] < 2:
            return LineSegments.empty()
        raw = cv2.createLineSegmentDetector().detect(gray)[0]
        if raw is None:
            return LineSegments.empty()
        segments = np.asarray(raw, dtype=np.float64).reshape(-1, 4)
        # LSD puts (0, 0) at the centre of the top-left pixel too (checked on step edges).
        gx = np.asarray(cv2.Sobel(crop.pixels, cv2.CV_32F, 1, 0, ksize=3, scale=0.125), dtype=np.float32)
        gy = np.asarray(cv2.Sobel(crop.pixels, cv2.CV_32F, 0, 1, ksize=3, scale=0.125), dtype=np.float32)
        contrast = sample_contrast(np.hypot(gx, gy), segments)
        offset = np.array([crop.u0, crop.v0, crop.u0, crop.v0], dtype=np.float64)
        lines = LineSegments(segments + offset, contrast)
        keep = (lines.length >= self.min_length) & (lines.contrast >= self.min_contrast)
        if self.orientation is not None:
            keep &= _orientation_difference(lines.orientation, self.orientation) <= self.tolerance
        return lines.select(keep)
