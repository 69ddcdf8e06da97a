"""The data rows of a numeric CSV block as floats: numpy's loadtxt (the reference), and ``csv.c``.

The reference is :func:`aura_ums._files.parse_float_rows`, what the file readers use by
default; the log readers, whose odometry and ground truth run to millions of rows, pass
``aura_ums._native.parse_float_rows``: the compiled kernel, or that reference with
``AURA_UMS_NATIVE=0``. The compiled one reads the plain decimal form only and gives None
for anything else, as the reference does for what it cannot read: the caller then reads the
block the slow, exact way (``aura_ums._files.parse_csv``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from aura_ums._files import parse_float_rows as parse_float_rows_reference
from aura_ums._native import _extension

if _extension.BUILT:
    from aura_ums._native._kernels import parse_float_rows as _compiled_parse_float_rows

__all__ = ["parse_float_rows_compiled", "parse_float_rows_reference"]


def parse_float_rows_compiled(data: bytes, rows: int, columns: int) -> NDArray[np.float64] | None:
    r""":func:`~aura_ums._files.parse_float_rows`, compiled (``csv.c``): plain decimal cells only, else None.

    Plain: blanks, an optional sign, digits with an optional point (a digit on one side at
    least), an optional exponent, blanks. ``nan``, ``inf``, hex, ``1_0`` or a cell of over
    400 bytes give None (the caller then reads the block the slow way), where the reference
    may read some of them. Every number read is the correctly rounded double, as the
    reference's.

    Examples
    --------
    >>> parse_float_rows_compiled(b"1e3, -0\n.5,2.\n", 2, 2).tolist()
    [[1000.0, -0.0], [0.5, 2.0]]
    >>> parse_float_rows_compiled(b"nan,1\n", 1, 2) is None   # the slow way says what it is
    True
    """
    found = _compiled_parse_float_rows(data, rows, columns)
    if found is None:
        return None
    return np.frombuffer(found, dtype=np.float64).reshape(rows, columns)
