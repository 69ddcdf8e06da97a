"""Moravec's interest operator: points where the image changes in every direction."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import nonnegative_float
from aura_ums.errors import InputError
from aura_ums.geometry import ImageWindow
from aura_ums.perception._image import int_at_least, prepare

#: Four of the eight shifts (rows, columns) of Moravec's operator; the other four are their opposites.
_SHIFTS = ((0, 1), (1, 0), (1, 1), (1, -1))


@dataclass(frozen=True, slots=True)
class MoravecOperator:
    """Moravec's interest operator, with thresholding and non-maximum suppression.

    At each pixel, for each of the eight shifts by one pixel (right, down and the
    diagonals, and their opposites) the mean over a ``size`` x ``size`` window of the squared difference
    between the image and its shifted copy is computed; the response is the minimum over
    the shifts, so it is high only where the image changes in every direction (a
    corner), not along an edge. Points are local maxima of the response within
    ``suppression`` pixels (Chebyshev distance) whose response is at least ``threshold``;
    a plateau of equal maxima gives one point, at its centroid. Windows that hold more
    of the two edges respond more, so a point lies within ``size // 2`` pixels of the
    corner, towards the inside of its sharper (convex) side.

    Parameters
    ----------
    size : int
        Side of the window, pixels (odd, >= 3).
    threshold : float
        Lowest response kept: mean squared difference, gray levels squared (100 = an
        RMS difference of 10 gray levels).
    suppression : int
        Radius of non-maximum suppression, pixels (>= 1).

    Raises
    ------
    InputError
        When a parameter is out of range.

    Examples
    --------
    >>> import numpy as np
    >>> image = np.zeros((40, 40), dtype=np.uint8)
    >>> image[20:, 20:] = 200                       # a corner at (19.5, 19.5)
    >>> MoravecOperator().find(image)
    array([[  21.,   21., 6400.]])
    >>> MoravecOperator().find(np.full((40, 40), 7.0)).shape   # flat image: no corner
    (0, 3)
    """

    size: int = 5
    threshold: float = 100.0
    suppression: int = 3

    def __post_init__(self) -> None:
        object.__setattr__(self, "size", int_at_least(self.size, "size", 3))
        object.__setattr__(self, "suppression", int_at_least(self.suppression, "suppression", 1))
        if self.size % 2 == 0:
            raise InputError(f"size: expected an odd integer, got {self.size}")
        object.__setattr__(self, "threshold", nonnegative_float(self.threshold, "threshold"))

    def response(self, image: ArrayLike) -> NDArray[np.float64]:
        """Return Moravec's response ``(h, w)`` of a whole image, gray levels squared.

        Zero where the window and its shifts do not fit inside the image.
        """
        crop = prepare(image, None, context=0)
        return self._response(crop.pixels.astype(np.float64))

    def _response(self, pixels: NDArray[np.float64]) -> NDArray[np.float64]:
        from scipy import ndimage  # deferred: scipy takes ~0.5 s to import

        h, w = pixels.shape
        half = self.size // 2
        result = np.zeros((h, w))
        if h < self.size + 2 or w < self.size + 2:
            return result
        responses = []
        for dr, dc in _SHIFTS:
            diff = np.zeros((h, w))
            c0, c1 = max(0, -dc), w - max(0, dc)
            shifted = pixels[dr:h, c0 + dc : c1 + dc]
            diff[: h - dr, c0:c1] = (shifted - pixels[: h - dr, c0:c1]) ** 2
            forward = ndimage.uniform_filter(diff, size=self.size, mode="constant")
            # The opposite shift -s gives forward(x - s): use both, so the operator is symmetric.
            backward = np.zeros((h, w))
            backward[dr:, c0 + dc : c1 + dc] = forward[: h - dr, c0:c1]
            responses.append(np.minimum(forward, backward))
        result = np.minimum.reduce(responses)
        # Keep only pixels whose window and shifts lie inside the crop.
        border = half + 2
        result[:border] = 0.0
        result[-border:] = 0.0
        result[:, :border] = 0.0
        result[:, -border:] = 0.0
        return np.asarray(result, dtype=np.float64)

    def find(self, image: ArrayLike, window: ImageWindow | None = None) -> NDArray[np.float64]:
        """Return interest points ``(n, 3)``: ``x, y, response``, sorted by decreasing response.

        Parameters
        ----------
        image : array_like, shape (h, w)
            Grayscale image, integers or finite floats (gray levels).
        window : ImageWindow or None
            Only points in the pixels the window overlaps are returned (the response
            there uses neighbouring pixels outside it where the image has them).

        Returns
        -------
        numpy.ndarray
            ``x, y`` in full-image pixels and the response (gray levels squared);
            shape ``(0, 3)`` when there is none.

        Raises
        ------
        InputError
            When the image is not a 2-D array of finite numbers, or the window misses it.
        """
        from scipy import ndimage

        crop = prepare(image, window, context=self.size // 2 + 1 + self.suppression)
        response = self._response(crop.pixels.astype(np.float64))
        local_max = ndimage.maximum_filter(response, size=2 * self.suppression + 1, mode="constant")
        peaks = (response >= local_max) & (response >= self.threshold) & (response > 0.0)
        inner = np.zeros_like(peaks)
        inner[crop.row_lo : crop.row_hi, crop.col_lo : crop.col_hi] = True
        peaks &= inner
        labels, count = ndimage.label(peaks, structure=np.ones((3, 3), dtype=bool))
        if count == 0:
            return np.zeros((0, 3))
        rows, cols = np.nonzero(labels)
        lab = labels[rows, cols]
        n = np.bincount(lab, minlength=count + 1)[1:]
        x = np.bincount(lab, cols.astype(np.float64), count + 1)[1:] / n + crop.u0
        y = np.bincount(lab, rows.astype(np.float64), count + 1)[1:] / n + crop.v0
        value = np.zeros(count + 1)
        np.maximum.at(value, lab, response[rows, cols])
        points = np.column_stack([x, y, value[1:]])
        return np.asarray(points[np.argsort(-points[:, 2], kind="stable")], dtype=np.float64)
