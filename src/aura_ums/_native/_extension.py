"""Whether the extension module of the compiled kernels was built, and how its bytes are read."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

_POINT = np.dtype((np.float64, (2,)))


def points_view(raw: bytes) -> NDArray[np.float64]:
    """Return a kernel's points, x y float64 pairs as bytes, as a read-only array of shape (n, 2).

    One array over the bytes (``np.frombuffer(raw).reshape(-1, 2)`` makes two); bytes are
    immutable, so the array is read-only, as map values must be.

    Examples
    --------
    >>> points = points_view(np.array([[0.0, 1.0], [2.0, 3.0]]).tobytes())
    >>> points.tolist(), points.flags.writeable
    ([[0.0, 1.0], [2.0, 3.0]], False)
    >>> points_view(b"").shape  # no point
    (0, 2)
    """
    return np.ndarray((len(raw) // _POINT.itemsize, 2), np.float64, raw)


def _built() -> bool:
    try:
        from aura_ums._native import _kernels  # noqa: F401
    except ImportError:
        return False
    return True


#: Whether the extension module ``aura_ums._native._kernels`` was built (and imports).
BUILT = _built()
