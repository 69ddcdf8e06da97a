"""Image windows: axis-aligned rectangles in pixel coordinates.

Pixel (0, 0) is the centre of the top-left pixel (DESIGN §1), so an image of width w
spans u in [-0.5, w - 0.5]. Plain image geometry: used by the Expecter to say where a
landmark must appear and by perception to say where to look.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import IMAGE_SIDE, finite_float, nonnegative_float, number_array
from aura_ums.errors import InputError

#: Stand-in (pixels) for a window side that is unbounded: the largest finite float.
#: :meth:`Expecter.bounds` uses it (with its sign) when a bound overflows, which only
#: happens when part of the landmark may touch the camera's near plane under distortion.
UNBOUNDED_PIXELS = sys.float_info.max


@dataclass(frozen=True, slots=True)
class ImageWindow:
    """An axis-aligned rectangle of the image, in pixels, bounds included.

    Pixel (0, 0) is the centre of the top-left pixel (DESIGN §1): ``u`` runs right and
    ``v`` down.

    Parameters
    ----------
    u_min, v_min, u_max, v_max : float
        Bounds, pixels, finite, ``u_min <= u_max`` and ``v_min <= v_max``. A side that is
        unbounded is :data:`UNBOUNDED_PIXELS` (with its sign).

    Raises
    ------
    InputError
        When a bound is not a finite number, or the bounds are out of order.

    Examples
    --------
    >>> w = ImageWindow(10.0, 20.0, 50.0, 40.0)
    >>> w.width, w.height, w.area
    (40.0, 20.0, 800.0)
    >>> w.contains([(30.0, 30.0), (60.0, 30.0), (float("nan"), 30.0)]).tolist()
    [True, False, False]
    >>> w.expanded(5.0).clipped(640, 480)
    ImageWindow(u_min=5.0, v_min=15.0, u_max=55.0, v_max=45.0)
    >>> ImageWindow(700.0, 0.0, 800.0, 10.0).clipped(640, 480) is None   # off the image
    True
    """

    u_min: float
    v_min: float
    u_max: float
    v_max: float

    def __post_init__(self) -> None:
        for name in ("u_min", "v_min", "u_max", "v_max"):
            object.__setattr__(self, name, finite_float(getattr(self, name), f"ImageWindow.{name}"))
        if self.u_max < self.u_min:
            raise InputError(f"ImageWindow.u_max: expected >= u_min ({self.u_min}), got {self.u_max}")
        if self.v_max < self.v_min:
            raise InputError(f"ImageWindow.v_max: expected >= v_min ({self.v_min}), got {self.v_max}")

    @classmethod
    def _trusted(cls, u_min: float, v_min: float, u_max: float, v_max: float) -> ImageWindow:
        """Build a window from bounds computed inside aura-ums, skipping validation.

        For internal paths only (the Expecter and the schemas build one per landmark and
        frame): the bounds must be Python floats. Bounds that are not finite or out of
        order go through the validated constructor, which raises; otherwise the result
        equals ``ImageWindow(u_min, v_min, u_max, v_max)``.
        """
        if not (-math.inf < u_min <= u_max < math.inf and -math.inf < v_min <= v_max < math.inf):
            return cls(u_min, v_min, u_max, v_max)
        window = object.__new__(cls)
        setattr_ = object.__setattr__
        setattr_(window, "u_min", u_min)
        setattr_(window, "v_min", v_min)
        setattr_(window, "u_max", u_max)
        setattr_(window, "v_max", v_max)
        return window

    @property
    def width(self) -> float:
        """Horizontal extent ``u_max - u_min``, pixels (inf when both sides are unbounded)."""
        return self.u_max - self.u_min

    @property
    def height(self) -> float:
        """Vertical extent ``v_max - v_min``, pixels."""
        return self.v_max - self.v_min

    @property
    def area(self) -> float:
        """``width * height``, square pixels."""
        return self.width * self.height

    def contains(self, pixels: ArrayLike) -> NDArray[np.bool_]:
        """Tell which pixels ``(..., 2)`` (u, v) lie in the window, bounds included.

        NaN pixels (points behind the camera, as :meth:`Camera.project` gives them) are
        outside. Returns a boolean array of shape ``(...)``.
        """
        u, v = _pixel_points(pixels)
        inside = (u >= self.u_min) & (u <= self.u_max) & (v >= self.v_min) & (v <= self.v_max)
        return np.asarray(inside, dtype=np.bool_)

    def meets_pixel_of(self, pixels: ArrayLike) -> NDArray[np.bool_]:
        """Tell, for points ``(..., 2)`` (u, v), whether the window meets the pixel each falls in.

        Pixel ``(i, j)`` is the unit square centred on ``(i, j)``; a point on the edge
        between two pixels falls in the one to its right (or below). A perception module
        scans whole pixels, so it scans every pixel the window meets, and finds a feature
        whose pixel is one of them even where the window's bound cuts that pixel: this is
        :meth:`contains` widened by less than a pixel on each side. NaN points are outside.
        Returns a boolean array of shape ``(...)``.

        Examples
        --------
        >>> w = ImageWindow(10.2, 20.0, 50.0, 40.0)
        >>> w.contains([(9.7, 30.0), (9.4, 30.0)]).tolist()
        [False, False]
        >>> w.meets_pixel_of([(9.7, 30.0), (9.4, 30.0)]).tolist()   # pixel 10 (9.5 to 10.5) meets it
        [True, False]
        >>> ImageWindow(3.5, 0.0, 3.5, 0.0).meets_pixel_of([(3.5, 0.0), (3.49, 0.0)]).tolist()
        [True, True]
        """
        u, v = _pixel_points(pixels)
        column = np.floor(u + 0.5)
        row = np.floor(v + 0.5)
        meets = (
            (column + 0.5 >= self.u_min)
            & (column - 0.5 <= self.u_max)
            & (row + 0.5 >= self.v_min)
            & (row - 0.5 <= self.v_max)
        )
        return np.asarray(meets, dtype=np.bool_)

    def expanded(self, margin: float) -> ImageWindow:
        """Return the window grown by ``margin`` pixels on every side, at most an image's longest side.

        A margin beyond 20,000 px (``IMAGE_SIDE``) reaches past any
        image: 1e300 made a window of area inf.
        """
        m = nonnegative_float(margin, "margin")
        if m > IMAGE_SIDE.high:
            raise InputError(
                f"margin: expected at most {IMAGE_SIDE.high:g} pixels (an image's longest side), got {m!r}"
            )
        return ImageWindow(
            _saturate(self.u_min - m),
            _saturate(self.v_min - m),
            _saturate(self.u_max + m),
            _saturate(self.v_max + m),
        )

    def clipped(self, width: int, height: int) -> ImageWindow | None:
        """Return the part of the window inside a ``width`` x ``height`` image, or None.

        The image covers ``[-0.5, width - 0.5] x [-0.5, height - 0.5]`` pixels (the outer
        edges of its border pixels). None when the window misses the image.
        """
        for name, value in (("width", width), ("height", height)):
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value <= 0:
                raise InputError(f"{name}: expected a positive integer, got {value!r}")
        u_lo, u_hi = max(self.u_min, -0.5), min(self.u_max, float(width) - 0.5)
        v_lo, v_hi = max(self.v_min, -0.5), min(self.v_max, float(height) - 0.5)
        if u_lo > u_hi or v_lo > v_hi:
            return None
        return ImageWindow(u_lo, v_lo, u_hi, v_hi)


def _pixel_points(pixels: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return the u and v of points ``(..., 2)``, pixels, checked for numbers (NaN kept) and shape."""
    points = number_array(pixels, "pixels", "an (n, 2) array of numbers")
    if points.ndim == 0 or points.shape[-1] != 2:
        raise InputError(f"pixels: expected shape (..., 2), got {points.shape}")
    return points[..., 0], points[..., 1]


def _saturate(value: float) -> float:
    """Keep a bound finite: overflow past the largest float stays at :data:`UNBOUNDED_PIXELS`."""
    if math.isinf(value):
        return math.copysign(UNBOUNDED_PIXELS, value)
    return value
