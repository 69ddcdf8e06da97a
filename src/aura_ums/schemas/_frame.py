"""One camera frame as the find-landmark schemas see it: time, image and the map snapshot."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import finite_float
from aura_ums.errors import InputError
from aura_ums.expecter import ImageWindow
from aura_ums.perception import FastLineFinder, LineSegments
from aura_ums.uncertainty import SpatialUncertaintyMap


@dataclass(frozen=True, slots=True, eq=False, init=False)
class Frame:
    """A time-stamped grayscale image with the spatial uncertainty map at that time.

    Parameters
    ----------
    time : float
        When the image was taken, seconds.
    image : array_like, shape (h, w)
        Grayscale image: integers or finite floats (gray levels, 0-255 for the default
        thresholds). Kept as a read-only array (copied when the caller's is writable).
    map : SpatialUncertaintyMap
        The map snapshot for that time (read-only: the schemas never change it).
    window_scale : float
        Factor (>= 1) by which the schemas widen the Expecter's windows about their
        centres (the map manager's :attr:`~aura_ums.manager.UncertaintyMapManager.window_scale`
        while lost); ``inf`` searches the whole image, tracking included (the full-frame
        baseline). Default 1: the Expecter's windows as they are.
    focus : SpatialUncertaintyMap or None
        A map inside ``map`` whose windows a discovering schema searches first, falling
        back on ``map``'s (the guaranteed ones) where the landmark is not found: the
        manager's :attr:`~aura_ums.manager.UncertaintyMapManager.focus_map`. None (the
        default), or ``map`` itself: the guaranteed windows only. A match in the focus
        window is taken without looking for rivals in the rest of the guaranteed one.

    Notes
    -----
    Frames compare by identity (they hold an image array). A frame remembers the lines
    found in it (:meth:`lines`), so that schemas sharing a line finder and a window (the
    full-frame baseline; windows widened to the whole image while lost) share its work.

    Raises
    ------
    InputError
        For a non-finite time, an image that is not a 2-D array of numbers (finite ones,
        for floats), or a map of the wrong type.

    Examples
    --------
    >>> from aura_ums.uncertainty import Pose
    >>> snapshot = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.2, 0.05)
    >>> frame = Frame(0.5, np.zeros((48, 64), dtype=np.uint8), snapshot)
    >>> frame.image.shape, frame.image.flags.writeable
    ((48, 64), False)
    >>> Frame(0.5, np.zeros(64), snapshot)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: image: expected a 2-D grayscale array (h, w), got shape (64,)
    """

    time: float
    image: NDArray[np.generic]
    map: SpatialUncertaintyMap
    window_scale: float
    focus: SpatialUncertaintyMap | None
    _lines: dict[tuple[FastLineFinder, ImageWindow], LineSegments] = field(repr=False)

    def __init__(
        self,
        time: float,
        image: ArrayLike,
        map: SpatialUncertaintyMap,
        *,
        window_scale: float = 1.0,
        focus: SpatialUncertaintyMap | None = None,
    ) -> None:
        when = finite_float(time, "time")
        scale = float(window_scale) if isinstance(window_scale, (int, float)) else math.nan
        if isinstance(window_scale, bool) or not scale >= 1.0:
            raise InputError(f"window_scale: expected a number >= 1 (or inf), got {window_scale!r}")
        try:
            array = np.asarray(image)
        except (TypeError, ValueError) as exc:  # pragma: no cover - numpy accepts nearly anything
            raise InputError(f"image: expected a 2-D grayscale array (h, w), got {image!r}") from exc
        if array.ndim != 2:
            raise InputError(f"image: expected a 2-D grayscale array (h, w), got shape {array.shape}")
        if array.dtype.kind not in "uif" or array.size == 0:
            raise InputError(
                f"image: expected a non-empty array of integers or floats, got dtype {array.dtype} "
                f"and shape {array.shape}"
            )
        if array.dtype.kind == "f" and not np.isfinite(array).all():
            bad = np.argwhere(~np.isfinite(array))[0]
            raise InputError(
                f"image: expected finite gray levels, got {array[bad[0], bad[1]]} at pixel "
                f"(u={int(bad[1])}, v={int(bad[0])})"
            )
        if array.flags.writeable:
            array = array.copy()
            array.setflags(write=False)
        if not isinstance(map, SpatialUncertaintyMap):
            raise InputError(f"map: expected a SpatialUncertaintyMap, got {type(map).__name__}")
        if focus is not None and not isinstance(focus, SpatialUncertaintyMap):
            raise InputError(f"focus: expected a SpatialUncertaintyMap or None, got {type(focus).__name__}")
        object.__setattr__(self, "time", when)
        object.__setattr__(self, "image", array)
        object.__setattr__(self, "map", map)
        object.__setattr__(self, "window_scale", scale)
        object.__setattr__(self, "focus", None if focus is map else focus)
        object.__setattr__(self, "_lines", {})

    def lines(self, finder: FastLineFinder, window: ImageWindow) -> LineSegments:
        """Return ``finder.find_detailed(self.image, window)``, computed once per equal finder and window.

        The result is immutable (read-only arrays), so callers may share it.

        Examples
        --------
        >>> from aura_ums.uncertainty import Pose
        >>> image = np.zeros((60, 80), dtype=np.uint8)
        >>> image[:, 40:] = 200
        >>> frame = Frame(0.0, image, SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.2, 0.05))
        >>> whole = ImageWindow(-0.5, -0.5, 79.5, 59.5)
        >>> first = frame.lines(FastLineFinder(orientation=np.pi / 2), whole)
        >>> frame.lines(FastLineFinder(orientation=np.pi / 2), whole) is first    # equal finder: shared
        True
        >>> frame.lines(FastLineFinder(orientation=0.0), whole).segments.shape     # another finder
        (0, 4)
        """
        key = (finder, window)
        found = self._lines.get(key)
        if found is None:
            found = self._lines[key] = finder.find_detailed(self.image, window)
        return found

    @property
    def width(self) -> int:
        """Image width, pixels."""
        return int(self.image.shape[1])

    @property
    def height(self) -> int:
        """Image height, pixels."""
        return int(self.image.shape[0])

    def __repr__(self) -> str:
        return f"Frame(time={self.time:g}, image={self.width}x{self.height}, map={self.map!r})"
