"""The fast line finder: line-support regions of like gradient orientation, fitted by lines.

After Kahn, Kitchen & Riseman's fast line finder and Burns, Hanson & Riseman's
line-support regions:

1. gradient by a 3 x 3 Sobel operator, scaled by 1/8 so that its magnitude reads in gray
   levels per pixel (a step of height s gives magnitude s/2 on the two pixels beside it);
2. pixels whose gradient magnitude is below ``min_gradient`` are dropped;
3. the gradient *direction* (0 to 2 pi: the sign tells dark-to-light from light-to-dark)
   is quantized into ``buckets`` equal buckets. Tuned to a target ``orientation``, only
   the two buckets centred on the gradient directions perpendicular to the target line
   (one per polarity) are kept. Untuned, every bucket is used, and with ``overlap`` a
   second partition offset by half a bucket is built; each pixel votes for the longer of
   its two regions and a region survives when most of its pixels vote for it (Burns);
4. line-support regions are the 8-connected components of pixels in the same bucket;
5. a line is fitted to each region: through the centroid of its pixels weighted by
   gradient magnitude, along the principal axis of their weighted scatter; the endpoints
   are the extreme projections of the region's pixels on that axis;
6. lines are kept when long enough (``min_length``), contrasted enough (mean gradient
   magnitude of the region >= ``min_contrast``) and, tuned, within ``tolerance`` of the
   target direction.

Everything is vectorized (no per-pixel Python): the work per region is a few
``bincount`` and ``ufunc.at`` calls over all regions at once, and a tuned search labels
both polarities in one call. A window's search costs little beyond its pixels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import BLUR, Choice, finite_float, nonnegative_float, positive_float
from aura_ums.errors import InputError
from aura_ums.geometry import ImageWindow
from aura_ums.perception._image import prepare
from aura_ums.perception._opencv import import_cv2
from aura_ums.perception._segments import LineSegments, _orientation_difference

_EIGHT = np.ones((3, 3), dtype=bool)
#: Most gradient-direction buckets of :class:`FastLineFinder`: one-degree buckets, narrower
#: than a gradient's direction is known; each bucket holds a mask of the window and is
#: labelled on its own (10**6 buckets exhausted the memory).
MAX_BUCKETS = 360
#: Bytes of one bucket's mask per megapixel of window.
_MASK_BYTES_PER_MEGAPIXEL = 1_000_000


class LineBackend(Choice):
    """Which library computes gradients and connected components for :class:`FastLineFinder`.

    Both give the same segments (up to float rounding); OpenCV is faster on large images.

    Examples
    --------
    >>> [backend.value for backend in LineBackend]
    ['numpy', 'opencv']
    >>> FastLineFinder(backend=LineBackend("numpy")).backend
    <LineBackend.NUMPY: 'numpy'>
    >>> FastLineFinder(backend="numpy")                    # the name alone is refused
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: backend: expected a LineBackend, got 'numpy'
    """

    #: numpy differences and :func:`scipy.ndimage.label`: always available.
    NUMPY = "numpy"
    #: ``cv2.Sobel`` and ``cv2.connectedComponents``: needs the ``opencv`` extra.
    OPENCV = "opencv"


@dataclass(frozen=True, slots=True)
class _Regions:
    """Line fits of all line-support regions of one partition (arrays indexed by region)."""

    labels: NDArray[np.int32]  # label per support pixel (0 = pixel dropped), shape (m,)
    pixel_index: NDArray[np.intp]  # flat index of each support pixel in the window, (m,)
    region: NDArray[np.int64]  # label of each fitted region, (k,)
    count: NDArray[np.int64]  # pixels per fitted region
    segments: NDArray[np.float64]  # (k, 4), window pixel coordinates
    contrast: NDArray[np.float64]  # mean gradient magnitude
    label_count: int  # labels run 1 .. label_count


@dataclass(frozen=True, slots=True)
class FastLineFinder:
    """Find straight lines in an image (window) from regions of like gradient orientation.

    Parameters
    ----------
    orientation : float or None
        Target line direction in the image, radians: 0 horizontal, pi/2 vertical, taken
        modulo pi (the angle of (du, dv) with v down, so clockwise on the screen). The
        buckets are tuned so that one is centred on the gradient direction of such lines.
        None finds lines of every direction.
    tolerance : float
        Largest difference between a kept line's direction and ``orientation``, radians
        (ignored when ``orientation`` is None).
    min_length : float
        Shortest line kept, pixels.
    min_gradient : float
        Gradient magnitude below which a pixel supports no line, gray levels per pixel (> 0).
    min_contrast : float
        Lowest mean gradient magnitude of a kept line's region, gray levels per pixel.
    buckets : int
        Number of gradient-direction buckets over the full circle, in [4, 360]; the bucket
        width is ``2 pi / buckets`` (45 degrees for 8).
    overlap : bool
        Untuned only: also build the partition offset by half a bucket, so that lines whose
        gradient falls on a bucket border are not split (Burns' voting).
    smoothing : float
        Standard deviation of a Gaussian applied before the gradient, pixels, in [0, 100]
        (0 = none).
    backend : LineBackend
        Library for gradients and connected components.

    Raises
    ------
    InputError
        When a parameter is out of range.
    MissingDependencyError
        When ``backend`` is :attr:`LineBackend.OPENCV` and OpenCV is not installed.

    Examples
    --------
    >>> import numpy as np
    >>> image = np.zeros((60, 80), dtype=np.uint8)
    >>> image[:, 40:] = 200                      # a vertical step edge at u = 39.5
    >>> finder = FastLineFinder(orientation=np.pi / 2)
    >>> finder.find(image).round(1)
    array([[39.5,  1. , 39.5, 58. ]])
    >>> FastLineFinder(orientation=0.0).find(image).shape   # no horizontal line there
    (0, 4)
    >>> finder.find(image, ImageWindow(30, 10, 50, 20)).round(1)   # full-image coordinates
    array([[39.5, 10. , 39.5, 20. ]])
    """

    orientation: float | None = None
    tolerance: float = math.radians(10.0)
    min_length: float = 10.0
    min_gradient: float = 4.0
    min_contrast: float = 0.0
    buckets: int = 8
    overlap: bool = True
    smoothing: float = 0.0
    backend: LineBackend = LineBackend.NUMPY

    def __post_init__(self) -> None:
        if self.orientation is not None:
            object.__setattr__(self, "orientation", finite_float(self.orientation, "orientation") % math.pi)
        object.__setattr__(self, "tolerance", nonnegative_float(self.tolerance, "tolerance"))
        object.__setattr__(self, "min_length", nonnegative_float(self.min_length, "min_length"))
        object.__setattr__(self, "min_gradient", positive_float(self.min_gradient, "min_gradient"))
        object.__setattr__(self, "min_contrast", nonnegative_float(self.min_contrast, "min_contrast"))
        buckets = self.buckets
        if (
            isinstance(buckets, bool)
            or not isinstance(buckets, (int, np.integer))
            or not 4 <= buckets <= MAX_BUCKETS
        ):
            estimate = (
                f" (about {int(buckets) * _MASK_BYTES_PER_MEGAPIXEL / 1e9:.3g} GB of bucket masks per "
                "megapixel, and as many labellings)"
                if isinstance(buckets, (int, np.integer))
                and not isinstance(buckets, bool)
                and buckets > MAX_BUCKETS
                else ""
            )
            raise InputError(f"buckets: expected an integer in [4, {MAX_BUCKETS}], got {buckets!r}{estimate}")
        object.__setattr__(self, "buckets", int(buckets))
        if not isinstance(self.overlap, bool):
            raise InputError(f"overlap: expected a bool, got {self.overlap!r}")
        object.__setattr__(self, "smoothing", BLUR.check(self.smoothing, "smoothing"))
        if not isinstance(self.backend, LineBackend):
            raise InputError(f"backend: expected a LineBackend, got {self.backend!r}")
        if self.backend is LineBackend.OPENCV:
            import_cv2("FastLineFinder(backend=LineBackend.OPENCV)")

    def find(self, image: ArrayLike, window: ImageWindow | None = None) -> NDArray[np.float64]:
        """Return the lines found as segments ``(n, 4)``: ``x1, y1, x2, y2``, full-image pixels.

        See :meth:`find_detailed` for the parameters; no line gives shape ``(0, 4)``.
        """
        return self.find_detailed(image, window).segments

    def find_detailed(self, image: ArrayLike, window: ImageWindow | None = None) -> LineSegments:
        """Return the lines found, with their length, contrast and direction.

        Parameters
        ----------
        image : array_like, shape (h, w)
            Grayscale image: integers or finite floats (gray levels; the default
            thresholds assume 0-255).
        window : ImageWindow or None
            Only the pixels the window overlaps are processed (their gradients use the
            neighbouring pixels outside it where the image has them). None: the whole image.

        Returns
        -------
        LineSegments
            Segments in full-image pixel coordinates, sorted by decreasing strength
            (length times contrast).

        Raises
        ------
        InputError
            When the image is not a 2-D array of finite numbers, or the window misses it.
        """
        crop = prepare(image, window, context=1 + math.ceil(3.0 * self.smoothing))
        gx, gy = self._gradient(crop.pixels)
        inner = (slice(crop.row_lo, crop.row_hi), slice(crop.col_lo, crop.col_hi))
        gx, gy = gx[inner], gy[inner]
        magnitude = np.sqrt(gx * gx + gy * gy)
        strong = magnitude >= np.float32(self.min_gradient)
        if self.orientation is None:
            segments, contrast = self._untuned(gx, gy, magnitude, strong)
        else:
            segments, contrast = self._tuned(gx, gy, magnitude, strong, self.orientation)
        # Plain arrays until the end: a window's call is dominated by fixed costs, and
        # these are the lines' own fits, finite by construction.
        if len(segments) == 0:
            return LineSegments.empty()
        segments += np.array([crop.inner_u0, crop.inner_v0, crop.inner_u0, crop.inner_v0], dtype=np.float64)
        du, dv = segments[:, 2] - segments[:, 0], segments[:, 3] - segments[:, 1]
        length = np.hypot(du, dv)
        keep = length >= self.min_length
        if self.min_contrast > 0.0:  # contrasts are means of magnitudes: never below 0
            keep &= contrast >= self.min_contrast
        if self.orientation is not None:
            # The orientations LineSegments gives these segments, compared as it compares them.
            keep &= (
                _orientation_difference(np.mod(np.arctan2(dv, du), math.pi), self.orientation)
                <= self.tolerance
            )
        kept = np.flatnonzero(keep)
        order = kept[np.argsort(-(length[kept] * contrast[kept]), kind="stable")]
        return LineSegments._trusted(segments[order], contrast[order])

    # -- steps ------------------------------------------------------------------------

    def _gradient(self, pixels: NDArray[np.float32]) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
        """Sobel gradient / 8 of the crop; zero on its one-pixel border (no full neighbourhood)."""
        from scipy import ndimage  # deferred: scipy takes ~0.5 s to import

        if self.smoothing > 0.0:
            pixels = np.asarray(
                ndimage.gaussian_filter(pixels, self.smoothing, mode="nearest"), dtype=np.float32
            )
        h, w = pixels.shape
        gx = np.zeros((h, w), dtype=np.float32)
        gy = np.zeros((h, w), dtype=np.float32)
        if h < 3 or w < 3:
            return gx, gy
        if self.backend is LineBackend.OPENCV:
            cv2 = import_cv2("FastLineFinder(backend=LineBackend.OPENCV)")
            gx[1:-1, 1:-1] = np.asarray(cv2.Sobel(pixels, cv2.CV_32F, 1, 0, ksize=3, scale=0.125))[1:-1, 1:-1]
            gy[1:-1, 1:-1] = np.asarray(cv2.Sobel(pixels, cv2.CV_32F, 0, 1, ksize=3, scale=0.125))[1:-1, 1:-1]
            return gx, gy
        d = pixels[:, 2:] - pixels[:, :-2]
        gx[1:-1, 1:-1] = (d[:-2] + 2.0 * d[1:-1] + d[2:]) * np.float32(0.125)
        e = pixels[2:, :] - pixels[:-2, :]
        gy[1:-1, 1:-1] = (e[:, :-2] + 2.0 * e[:, 1:-1] + e[:, 2:]) * np.float32(0.125)
        return gx, gy

    def _label(self, masks: list[NDArray[np.bool_]]) -> tuple[NDArray[np.int32], int]:
        """Label the 8-connected components of each mask, numbering on across masks."""
        from scipy import ndimage

        total = np.zeros(masks[0].shape, dtype=np.int32)
        count = 0
        cv2: Any = import_cv2("FastLineFinder") if self.backend is LineBackend.OPENCV else None
        for mask in masks:
            if not mask.any():
                continue
            if cv2 is not None:
                n, labels = cv2.connectedComponents(mask.view(np.uint8), connectivity=8, ltype=cv2.CV_32S)
                labels = np.asarray(labels, dtype=np.int32)
                n = int(n) - 1
            else:
                labels = np.zeros(mask.shape, dtype=np.int32)
                n = int(ndimage.label(mask, structure=_EIGHT, output=labels))
            np.add(labels, count, out=labels, where=mask)
            total += labels  # masks are disjoint and labels are 0 outside their mask
            count += n
        return total, count

    def _label_one(self, mask: NDArray[np.bool_]) -> tuple[NDArray[np.int32], int]:
        """Label the 8-connected components of one mask: ``_label([mask])`` in fewer steps."""
        from scipy import ndimage

        if self.backend is LineBackend.OPENCV:
            return self._label([mask])
        labels = np.empty(mask.shape, dtype=np.int32)
        return labels, int(ndimage.label(mask, structure=_EIGHT, output=labels))

    def _fit(self, labels: NDArray[np.int32], count: int, magnitude: NDArray[np.float32]) -> _Regions:
        """Fit a line to every region of a labelled window with enough pixels to reach ``min_length``."""
        pixel_index = np.flatnonzero(labels)
        lab = labels.ravel()[pixel_index]
        ys, xs = np.divmod(pixel_index, labels.shape[1])
        wgt = magnitude.ravel()[pixel_index]
        region, sizes, segments, contrast = self._fit_support(lab, xs, ys, wgt, count)
        return _Regions(lab, pixel_index, region, sizes, segments, contrast, count)

    def _fit_support(
        self,
        lab: NDArray[np.int32],
        xs: NDArray[np.intp],
        ys: NDArray[np.intp],
        wgt: NDArray[np.float32],
        count: int,
    ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]]:
        """Fit lines to the regions of support pixels ``(lab, xs, ys)`` weighted by ``wgt``.

        Labels run 1 .. ``count``; returns the fitted regions' labels (increasing), pixel
        counts, segments ``(k, 4)`` in window pixels and contrasts.
        """
        n = count + 1
        sizes = np.bincount(lab, minlength=n)
        # An 8-connected region spanning a length L has at least L / sqrt(2) + 1 pixels.
        big = sizes >= max(2, int(self.min_length / math.sqrt(2.0)))
        big[0] = False
        region = np.flatnonzero(big)
        if region.size == 0:
            empty = np.zeros(0, dtype=np.int64)
            return empty, empty, np.zeros((0, 4)), np.zeros(0)
        use = big[lab]
        lab = lab[use]
        xs_f, ys_f = xs[use].astype(np.float64), ys[use].astype(np.float64)
        w = wgt[use].astype(np.float64)
        w_sum = np.bincount(lab, w, n)
        safe = np.where(w_sum > 0.0, w_sum, 1.0)
        cx = np.bincount(lab, w * xs_f, n) / safe
        cy = np.bincount(lab, w * ys_f, n) / safe
        dx, dy = xs_f - cx[lab], ys_f - cy[lab]
        wdx, wdy = w * dx, w * dy
        sxx = np.bincount(lab, wdx * dx, n)
        syy = np.bincount(lab, wdy * dy, n)
        sxy = np.bincount(lab, wdx * dy, n)
        # Direction in [0, pi): segments run from (x1, y1) to (x2, y2) along their orientation.
        theta = np.mod(0.5 * np.arctan2(2.0 * sxy, sxx - syy), math.pi)
        ux, uy = np.cos(theta), np.sin(theta)
        t = dx * ux[lab] + dy * uy[lab]
        t_min = np.empty(n)
        t_min.fill(np.inf)
        t_max = np.empty(n)
        t_max.fill(-np.inf)
        np.minimum.at(t_min, lab, t)
        np.maximum.at(t_max, lab, t)
        rx, ry, rux, ruy = cx[region], cy[region], ux[region], uy[region]
        lo, hi = t_min[region], t_max[region]
        segments = np.empty((region.size, 4))
        segments[:, 0] = rx + lo * rux
        segments[:, 1] = ry + lo * ruy
        segments[:, 2] = rx + hi * rux
        segments[:, 3] = ry + hi * ruy
        counts = sizes[region]
        return region.astype(np.int64), counts, segments, w_sum[region] / counts

    def _tuned(
        self,
        gx: NDArray[np.float32],
        gy: NDArray[np.float32],
        magnitude: NDArray[np.float32],
        strong: NDArray[np.bool_],
        orientation: float,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Regions of the two buckets centred on the gradient directions normal to ``orientation``."""
        nx, ny = np.float32(-math.sin(orientation)), np.float32(math.cos(orientation))
        dot = gx * nx + gy * ny
        bound = np.float32(math.cos(math.pi / self.buckets)) * magnitude
        # One labelling of both polarities: the dark-to-light mask above the light-to-dark
        # one, a row of background between them so that their regions never touch. The
        # labels come out as two separate labellings numbered on would give them.
        h, w = gx.shape
        stacked = np.zeros((2 * h + 1, w), dtype=bool)
        np.greater_equal(dot, bound, out=stacked[:h])
        np.less_equal(dot, -bound, out=stacked[h + 1 :])
        stacked[:h] &= strong
        stacked[h + 1 :] &= strong
        labels, count = self._label_one(stacked)
        pixel_index = np.flatnonzero(stacked)  # the labelled pixels; a bool scan is far cheaper
        lab = labels.ravel()[pixel_index]
        ys, xs = np.divmod(pixel_index, w)
        ys[ys > h] -= h + 1
        wgt = magnitude[ys, xs]
        _, _, segments, contrast = self._fit_support(lab, xs, ys, wgt, count)
        return segments, contrast

    def _untuned(
        self,
        gx: NDArray[np.float32],
        gy: NDArray[np.float32],
        magnitude: NDArray[np.float32],
        strong: NDArray[np.bool_],
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Regions of every bucket; with ``overlap``, two partitions reconciled by voting."""
        angle = np.arctan2(gy, gx) * np.float32(self.buckets / (2.0 * math.pi))  # in buckets
        partitions = [0.0, 0.5] if self.overlap else [0.0]
        fits: list[_Regions] = []
        for shift in partitions:
            bucket = np.floor(angle + np.float32(shift)).astype(np.int64) % self.buckets
            masks = [strong & (bucket == k) for k in range(self.buckets)]
            labels, count = self._label(masks)
            fits.append(self._fit(labels, count, magnitude))
        if len(fits) == 1:
            return fits[0].segments, fits[0].contrast
        first, second = fits
        lengths = []
        for fit in fits:
            by_label = np.zeros(fit.label_count + 1)
            d = fit.segments[:, 2:] - fit.segments[:, :2]
            by_label[fit.region] = np.hypot(d[:, 0], d[:, 1])
            lengths.append(by_label)
        # Both partitions hold the same support pixels, in the same (raster) order.
        len_first = lengths[0][first.labels]
        len_second = lengths[1][second.labels]
        votes_first = np.bincount(first.labels[len_first >= len_second], minlength=first.label_count + 1)
        votes_second = np.bincount(second.labels[len_second > len_first], minlength=second.label_count + 1)
        keep_first = 2 * votes_first[first.region] > first.count
        keep_second = 2 * votes_second[second.region] > second.count
        segments = np.vstack([first.segments[keep_first], second.segments[keep_second]])
        contrast = np.concatenate([first.contrast[keep_first], second.contrast[keep_second]])
        return segments, contrast
