"""Where images enter perception: validation, windows to pixel ranges, and reading files.

An image is a 2-D grayscale array ``(h, w)`` of integers or floats (gray levels; the
default thresholds of the detectors assume the 0-255 range of 8-bit images), each in
:data:`GRAY_LEVEL` (+-1e12: 8- to 32-bit images and floats of any usual scale). Pixel
``(u, v)`` = ``(column, row)``, with ``(0, 0)`` at the centre of the top-left pixel
(DESIGN §1); pixel ``(u, v)`` covers ``[u - 0.5, u + 0.5] x [v - 0.5, v + 0.5]``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import Range
from aura_ums.errors import FileFormatError, InputError
from aura_ums.geometry import ImageWindow

#: A gray level the detectors take: every integer of 8- to 32-bit images, and floats of any
#: usual scale. The detectors work in float32 (largest 3.4e38): their gradients and squared
#: magnitudes stay far from overflow within it, where 1e300 overflowed the cast itself.
GRAY_LEVEL = Range(-1e12, 1e12)

#: ITU-R BT.601 luma weights (red, green, blue), as OpenCV's ``COLOR_RGB2GRAY`` uses.
_LUMA = np.array([0.299, 0.587, 0.114])


def as_image(image: ArrayLike, name: str = "image") -> NDArray[Any]:
    """Return ``image`` as a 2-D numeric array (no copy when possible), or raise.

    Integers and floats are accepted (not booleans, complex numbers or objects). The
    finiteness of float pixels is checked where they are used (:func:`prepare`).
    """
    try:
        array = np.asarray(image)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name}: expected a 2-D grayscale array, got {type(image).__name__}") from exc
    if array.dtype == np.bool_ or array.dtype.kind not in "uif":
        raise InputError(f"{name}: expected integers or floats (gray levels), got dtype {array.dtype}")
    if array.ndim != 2:
        raise InputError(f"{name}: expected a 2-D grayscale array (h, w), got shape {array.shape}")
    return array


def int_at_least(value: object, name: str, lowest: int) -> int:
    """Return ``value`` as an int ``>= lowest`` (not a bool), or raise naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < lowest:
        raise InputError(f"{name}: expected an integer >= {lowest}, got {value!r}")
    return int(value)


def window_pixels(window: ImageWindow, width: int, height: int) -> tuple[int, int, int, int]:
    """Return the pixels a window overlaps as ``(col_lo, row_lo, col_hi, row_hi)``, hi exclusive.

    A pixel is processed when its square overlaps the window (so the pixel holding a point
    on the window's border is included). Raises :class:`InputError` when the window misses
    a ``width`` x ``height`` image.

    Examples
    --------
    >>> window_pixels(ImageWindow(10.2, 0.0, 20.5, 4.6), 640, 480)
    (10, 0, 21, 6)
    """
    if not isinstance(window, ImageWindow):
        raise InputError(f"window: expected an ImageWindow or None, got {window!r}")
    if width <= 0 or height <= 0:
        raise InputError(f"window: expected a window inside the {width} x {height} image, got {window}")
    # ImageWindow.clipped's bounds, without building a window (this runs for every search).
    u_lo, u_hi = max(window.u_min, -0.5), min(window.u_max, width - 0.5)
    v_lo, v_hi = max(window.v_min, -0.5), min(window.v_max, height - 0.5)
    if u_lo > u_hi or v_lo > v_hi:
        raise InputError(f"window: expected a window overlapping the {width} x {height} image, got {window}")
    col_lo = min(max(math.floor(u_lo + 0.5), 0), width - 1)
    row_lo = min(max(math.floor(v_lo + 0.5), 0), height - 1)
    col_hi = max(min(math.ceil(u_hi - 0.5), width - 1), col_lo) + 1
    row_hi = max(min(math.ceil(v_hi - 0.5), height - 1), row_lo) + 1
    return col_lo, row_lo, col_hi, row_hi


@dataclass(frozen=True, slots=True)
class Crop:
    """The part of an image a detector processes, with some context around it.

    ``pixels[r, c]`` is the image's pixel ``(u0 + c, v0 + r)``; the window proper is
    ``pixels[row_lo:row_hi, col_lo:col_hi]`` (indices into ``pixels``).
    """

    pixels: NDArray[np.float32]
    u0: int
    v0: int
    col_lo: int
    row_lo: int
    col_hi: int
    row_hi: int

    @property
    def inner_u0(self) -> int:
        """Image column of the window's first column."""
        return self.u0 + self.col_lo

    @property
    def inner_v0(self) -> int:
        """Image row of the window's first row."""
        return self.v0 + self.row_lo


def prepare(image: ArrayLike, window: ImageWindow | None, *, context: int) -> Crop:
    """Validate ``image`` and ``window`` and cut out the window plus ``context`` pixels around it.

    The context is taken where the image has it (detectors need neighbours to compute
    gradients or sums at the window's border). Float pixels must be finite.
    """
    array = as_image(image)
    height, width = array.shape
    if window is None:
        col_lo, row_lo, col_hi, row_hi = 0, 0, width, height
    else:
        col_lo, row_lo, col_hi, row_hi = window_pixels(window, width, height)
    c0, r0 = max(col_lo - context, 0), max(row_lo - context, 0)
    c1, r1 = min(col_hi + context, width), min(row_hi + context, height)
    region = array[r0:r1, c0:c1]
    # min and max are NaN when a pixel is: one test for NaN, infinity and range (per window).
    if (
        region.size
        and _may_exceed(region.dtype)
        and not (GRAY_LEVEL.low <= region.min() and region.max() <= GRAY_LEVEL.high)
    ):
        if region.dtype.kind == "f" and not np.isfinite(region).all():
            bad = np.argwhere(~np.isfinite(region))[0]
            raise InputError(
                f"image: expected finite gray levels, got {region[bad[0], bad[1]]} at pixel "
                f"(u={int(bad[1]) + c0}, v={int(bad[0]) + r0})"
            )
        bad = np.argwhere(np.abs(region.astype(np.float64)) > GRAY_LEVEL.high)[0]
        raise InputError(
            f"image: expected gray levels {GRAY_LEVEL.text()}, got {region[bad[0], bad[1]]} at pixel "
            f"(u={int(bad[1]) + c0}, v={int(bad[0]) + r0})"
        )
    pixels = np.asarray(region, dtype=np.float32)
    return Crop(pixels, c0, r0, col_lo - c0, row_lo - r0, col_hi - c0, row_hi - r0)


def _may_exceed(dtype: np.dtype[Any]) -> bool:
    """Whether values of ``dtype`` may lie outside :data:`GRAY_LEVEL` (floats, 64-bit integers)."""
    if dtype.kind == "f":
        return True
    info = np.iinfo(dtype)
    return bool(info.min < GRAY_LEVEL.low or info.max > GRAY_LEVEL.high)


def read_gray_image(path: str | PathLike[str]) -> NDArray[np.uint8]:
    """Read an image file (PNG, JPEG, ...) as an 8-bit grayscale array ``(h, w)``.

    Uses matplotlib (JPEG through Pillow, which matplotlib requires), so OpenCV is not
    needed. Colour is converted with the ITU-R BT.601 luma weights, as OpenCV does.

    Parameters
    ----------
    path : str or PathLike
        The image file.

    Returns
    -------
    numpy.ndarray
        ``uint8`` array of shape ``(h, w)``, gray levels 0-255.

    Raises
    ------
    InputError
        When ``path`` is not a str or PathLike.
    FileFormatError
        When the file is missing or is not a readable image.

    Examples
    --------
    >>> import tempfile
    >>> import matplotlib.image
    >>> path = Path(tempfile.mkdtemp()) / "step.png"
    >>> pixels = np.zeros((4, 6), dtype=np.uint8)
    >>> pixels[:, 3:] = 200                                  # a vertical step edge
    >>> matplotlib.image.imsave(path, pixels, cmap="gray", vmin=0, vmax=255)   # RGBA PNG
    >>> gray = read_gray_image(path)
    >>> gray.dtype, gray.shape, gray[0].tolist()
    (dtype('uint8'), (4, 6), [0, 0, 0, 200, 200, 200])
    >>> read_gray_image(path.with_name("missing.png"))      # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: ...missing.png: expected a readable image file, got [Errno 2] No such ...
    """
    if not isinstance(path, (str, PathLike)):
        raise InputError(f"path: expected a str or PathLike, got {type(path).__name__}")
    import matplotlib.image  # deferred: only loaders need it

    try:
        raw = np.asarray(matplotlib.image.imread(Path(path)))
    except (OSError, ValueError, SyntaxError) as exc:
        raise FileFormatError(str(path), "", f"expected a readable image file, got {exc}") from exc
    if raw.dtype.kind == "f":  # PNG: floats in [0, 1]
        raw = raw * 255.0
    if raw.ndim == 3:
        raw = raw[..., :3].astype(np.float64) @ _LUMA
    if raw.ndim != 2:
        raise FileFormatError(str(path), "", f"expected a grayscale or colour image, got shape {raw.shape}")
    return np.asarray(np.clip(np.rint(raw), 0, 255), dtype=np.uint8)
