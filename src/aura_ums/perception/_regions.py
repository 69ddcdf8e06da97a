"""A simple region segmenter: one intensity threshold, then connected components."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from aura_ums._validate import finite_float
from aura_ums.errors import InputError
from aura_ums.geometry import ImageWindow
from aura_ums.perception._image import as_image, int_at_least, prepare

_EIGHT = np.ones((3, 3), dtype=bool)
#: Most histogram bins of :func:`otsu_threshold`: about 48 bytes each for the histogram and
#: its sums, so 48 MB (a gray level of a 16-bit image has 65,536; 10**12 asked for 7 TiB).
MAX_OTSU_BINS = 1_000_000
_BIN_BYTES = 48


def otsu_threshold(image: ArrayLike, bins: int = 256) -> float:
    """Return Otsu's threshold of an image's gray levels: it maximizes the between-class variance.

    Pixels ``> threshold`` form the bright class. The histogram has ``bins`` bins (an
    integer in [2, 1000000]) over the image's range; when several thresholds separate the
    classes equally well (an empty stretch of histogram) the middle one is taken. A flat
    image gives its one gray level (every pixel is then dark).

    Examples
    --------
    >>> otsu_threshold([[10, 10, 200, 200]])
    105.0
    >>> otsu_threshold(np.full((3, 3), 5.0))
    5.0
    >>> otsu_threshold([[10, 10, 200, 200]], bins=1)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: bins: expected an integer in [2, 1000000], got 1
    """
    if isinstance(bins, bool) or not isinstance(bins, (int, np.integer)) or not 2 <= bins <= MAX_OTSU_BINS:
        estimate = (
            f" (about {int(bins) * _BIN_BYTES / 1e9:.3g} GB of histogram)"
            if isinstance(bins, (int, np.integer)) and not isinstance(bins, bool) and bins > MAX_OTSU_BINS
            else ""
        )
        raise InputError(f"bins: expected an integer in [2, {MAX_OTSU_BINS}], got {bins!r}{estimate}")
    pixels = np.asarray(prepare(as_image(image), None, context=0).pixels, dtype=np.float64)
    if pixels.size == 0:
        raise InputError("image: expected at least one pixel, got an empty image")
    lo, hi = float(pixels.min()), float(pixels.max())
    if hi <= lo:
        return lo
    hist, edges = np.histogram(pixels, bins=bins, range=(lo, hi))
    centres = 0.5 * (edges[:-1] + edges[1:])
    weight = np.cumsum(hist)[:-1].astype(np.float64)
    total = float(pixels.size)
    mass = np.cumsum(hist * centres)[:-1]
    mean_all = float(np.dot(hist, centres)) / total
    between = (mean_all * weight - mass) ** 2 / np.maximum(weight * (total - weight), 1e-12)
    # Equal maxima (an empty stretch of histogram between the classes): take the middle one.
    best = np.flatnonzero(between >= between.max() * (1.0 - 1e-12))
    return float(edges[(int(best[0]) + int(best[-1])) // 2 + 1])


@dataclass(frozen=True, slots=True)
class Region:
    """A connected region of pixels on one side of the threshold.

    Parameters
    ----------
    area : int
        Number of pixels.
    mean_intensity : float
        Mean gray level of its pixels.
    bbox : tuple of int
        ``(u_min, v_min, u_max, v_max)``: the first and last columns and rows it covers,
        full-image pixels, bounds included.
    centroid : tuple of float
        ``(u, v)``: mean pixel position, full-image pixels.
    bright : bool
        True when its pixels are above the threshold, False when at or below it.

    Examples
    --------
    >>> image = np.zeros((20, 30), dtype=np.uint8)
    >>> image[5:10, 8:20] = 180                       # a bright 12 x 5 block
    >>> block = RegionSegmenter(threshold=90.0).find(image)[1]
    >>> block.area, block.mean_intensity, block.bbox, block.centroid, block.bright
    (60, 180.0, (8, 5, 19, 9), (13.5, 7.0), True)
    >>> RegionSegmenter().find(np.zeros((0, 5)))      # an empty image has no region
    ()
    """

    area: int
    mean_intensity: float
    bbox: tuple[int, int, int, int]
    centroid: tuple[float, float]
    bright: bool


@dataclass(frozen=True, slots=True)
class RegionSegmenter:
    """Split an image (window) into bright and dark connected regions.

    Pixels above ``threshold`` (Otsu's, computed on the window, when None) are bright,
    the others dark; regions are the 8-connected components of each class. Regions
    smaller than ``min_area`` pixels are dropped.

    Parameters
    ----------
    threshold : float or None
        Gray level separating dark (``<=``) from bright (``>``); None: Otsu's on the window.
    min_area : int
        Smallest region kept, pixels (>= 1).

    Raises
    ------
    InputError
        When a parameter is out of range.

    Examples
    --------
    >>> import numpy as np
    >>> image = np.zeros((20, 30), dtype=np.uint8)
    >>> image[5:10, 8:20] = 180                       # a bright 12 x 5 block
    >>> [(r.area, r.bright, r.bbox) for r in RegionSegmenter().find(image)]
    [(540, False, (0, 0, 29, 19)), (60, True, (8, 5, 19, 9))]
    >>> RegionSegmenter(min_area=1000).find(image)    # everything too small
    ()
    """

    threshold: float | None = None
    min_area: int = 20

    def __post_init__(self) -> None:
        if self.threshold is not None:
            object.__setattr__(self, "threshold", finite_float(self.threshold, "threshold"))
        object.__setattr__(self, "min_area", int_at_least(self.min_area, "min_area", 1))

    def find(self, image: ArrayLike, window: ImageWindow | None = None) -> tuple[Region, ...]:
        """Return the regions of the window (or image), largest first.

        Parameters
        ----------
        image : array_like, shape (h, w)
            Grayscale image, integers or finite floats (gray levels).
        window : ImageWindow or None
            Only the pixels the window overlaps are segmented; coordinates are full-image.

        Returns
        -------
        tuple of Region
            Sorted by decreasing area (then bright before dark, then by position).

        Raises
        ------
        InputError
            When the image is not a 2-D array of finite numbers, or the window misses it.
        """
        from scipy import ndimage  # deferred: scipy takes ~0.5 s to import

        crop = prepare(image, window, context=0)
        pixels = np.asarray(crop.pixels, dtype=np.float64)
        if pixels.size == 0:
            return ()
        threshold = otsu_threshold(pixels) if self.threshold is None else self.threshold
        bright = pixels > threshold
        regions: list[Region] = []
        for is_bright, mask in ((True, bright), (False, ~bright)):
            labels, count = ndimage.label(mask, structure=_EIGHT)
            if count == 0:
                continue
            lab = labels.ravel()
            area = np.bincount(lab, minlength=count + 1)
            total = np.bincount(lab, pixels.ravel(), count + 1)
            rows, cols = np.indices(pixels.shape)
            sum_u = np.bincount(lab, cols.ravel().astype(np.float64), count + 1)
            sum_v = np.bincount(lab, rows.ravel().astype(np.float64), count + 1)
            for k, box in enumerate(ndimage.find_objects(labels), start=1):
                if box is None or area[k] < self.min_area:
                    continue
                n = float(area[k])
                regions.append(
                    Region(
                        int(area[k]),
                        float(total[k] / n),
                        (
                            box[1].start + crop.u0,
                            box[0].start + crop.v0,
                            box[1].stop - 1 + crop.u0,
                            box[0].stop - 1 + crop.v0,
                        ),
                        (float(sum_u[k] / n) + crop.u0, float(sum_v[k] / n) + crop.v0),
                        is_bright,
                    )
                )
        regions.sort(key=lambda r: (-r.area, not r.bright, r.bbox))
        return tuple(regions)
