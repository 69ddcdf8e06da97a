"""Merging heading slices: the numpy reference and the compiled kernel behind one call.

A sliced map's growth puts each grown slice back on the heading grid; the polygons that
meet one cell merge into their convex hull, capped at a vertex count by an outer polygon
(and neighbouring slices merge so under the slice cap). Every group of a redistribution
goes through one call: its points concatenated, with the number of points of each group.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from aura_ums._native import _extension
from aura_ums.geometry import convex_hull, simplify_outer

if _extension.BUILT:
    from aura_ums._native._kernels import merge_groups as _compiled_merge_groups

Array = NDArray[np.float64]


def merge_groups_reference(points: Array, counts: Sequence[int], max_vertices: int) -> tuple[Array, ...]:
    """Return the convex hull of each group of consecutive points, capped at ``max_vertices``.

    The numpy reference, the specification ``slices.c`` follows: ``aura_ums._native.merge_groups``
    is this function, or :func:`merge_groups_compiled` when the kernels run compiled.

    Parameters
    ----------
    points : ndarray, shape (n, 2)
        Finite points, metres: the groups one after the other.
    counts : sequence of int
        Points in each group, each >= 1, adding up to n.
    max_vertices : int
        Cap on each hull's vertex count (>= 3); beyond it an outer polygon
        (``geometry.simplify_outer``).

    Returns
    -------
    tuple of ndarray, shape (m, 2)
        Each group's hull, counter-clockwise, starting from its lowest-leftmost vertex.

    Examples
    --------
    >>> from aura_ums import _native
    >>> square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> hulls = _native.merge_groups(np.vstack([square, square + 2.0, square]), [8, 4], 8)
    >>> [len(h) for h in hulls], hulls[1].tolist() == square.tolist()
    ([6, 4], True)
    >>> _native.merge_groups(np.zeros((2, 2)), [1, 1], 3)[0].tolist()   # a point is its own hull
    [[0.0, 0.0]]
    """
    if any(count < 1 for count in counts) or sum(counts) != len(points):
        raise ValueError(
            f"counts: expected group sizes adding up to the {len(points)} rows, got {list(counts)}"
        )
    if max_vertices < 3:
        raise ValueError(f"max_vertices: expected at least 3, got {max_vertices}")
    hulls = []
    start = 0
    for count in counts:
        hull = convex_hull(points[start : start + count])
        if len(hull) > max_vertices:
            hull = simplify_outer(hull, max_vertices)
        hulls.append(hull)
        start += count
    return tuple(hulls)


def merge_groups_compiled(points: Array, counts: Sequence[int], max_vertices: int) -> tuple[Array, ...]:
    """Compiled :func:`merge_groups_reference` (needs the extension module: ``_extension.BUILT``)."""
    if not points.flags.c_contiguous:
        points = np.ascontiguousarray(points, dtype=np.float64)
    # Bytes are immutable, so the arrays are read-only as map values must be.
    return tuple(
        np.frombuffer(raw, dtype=np.float64).reshape(-1, 2)
        for raw in _compiled_merge_groups(points, counts, max_vertices)
    )
