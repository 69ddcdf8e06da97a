"""Rigorous bounds of OpenCV's lens distortion over a convex region of normalized coordinates.

The camera images only the rays within its lens's fold (:func:`~aura_ums.camera.fold_radius`),
so the region is first cut to an outer polygon of that disk: the window need not hold the
pixels the polynomial would give beyond it, which no ray reaches.

The distortion map (k1, k2, p1, p2, k3) is a polynomial in (x, y). Its range over a
convex polygon ``C`` is bounded by branch and bound on axis-aligned cells:

* cells that a separating axis proves disjoint from ``C`` are dropped;
* on each cell, interval arithmetic bounds the partial derivatives; where a partial
  derivative has a constant sign, the extreme lies on the corresponding side of the cell,
  so the cell collapses to that side (to a corner when both signs are known) before the
  natural interval extension bounds the value there (exact at a corner);
* the polynomial in r^2 = x^2 + y^2 is bounded exactly on an interval of r^2 (its
  critical points are checked), so only the products with x and y lose correlation;
* values attained at points of ``C`` (its vertices, cell centres inside it) are lower
  bounds of the maximum: a cell whose upper bound is below one cannot hold the maximum
  and is dropped; the others are split in four, a fixed number of rounds.

Every cell ever dropped is either disjoint from ``C`` or provably below (above) an
attained value, so the maximum (minimum) over the remaining cells bounds the range.
Arithmetic is in double precision without directed rounding; the caller adds a relative
slack far above the rounding error. Overflow (only for gigantic regions, near the
camera plane) gives infinite bounds, never NaN.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

# camera.distort checks its arguments; the points here always pass: in front of the near plane
# (1e-6 m) and within the world's coordinates they lie within about 1e13 of the axis, far
# inside the 1e30 it takes. One formula for the projections and their bounds.
from aura_ums.camera import distort, fold_radius
from aura_ums.geometry import clip_halfplane, convex_hull, polygon_area, simplify_outer

Array = NDArray[np.float64]
Interval = tuple[Array, Array]
Coefficients = tuple[float, float, float, float, float]

_INITIAL_SPLIT = 4
_MAX_ROUNDS = 12
_MAX_CELLS = 2048
#: The hull is replaced by an outer polygon of at most this many vertices (fewer edges)...
_HULL_VERTICES = 10
#: ...when that polygon's area is at most this fraction larger than the hull's.
_HULL_GROWTH = 0.05
#: Sides of the polygon around the fold's disk that cuts the region (their distance from the
#: centre is the fold radius, rounded outwards): at most 0.5% wider than the disk.
_FOLD_SIDES = 32
_FOLD_NORMALS = np.array(
    [
        (math.cos(2.0 * math.pi * i / _FOLD_SIDES), math.sin(2.0 * math.pi * i / _FOLD_SIDES))
        for i in range(_FOLD_SIDES)
    ]
)
#: Rounding slack, relative to the sum of the absolute values of the terms: 20 operations
#: at 2**-53 each, for our evaluation and the camera's, with a safety factor of ten.
_ROUNDING = 5e-14
#: Degree of the distortion along a line, and the monomial-to-Bernstein matrix (b = a @ M).
_DEGREE = 7
_BERNSTEIN = np.array(
    [
        [math.comb(j, i) / math.comb(_DEGREE, i) if i <= j else 0.0 for j in range(_DEGREE + 1)]
        for i in range(_DEGREE + 1)
    ]
)


def distorted_range(
    points: Array, coefficients: Coefficients, tolerance: float
) -> tuple[Array, Array] | None:
    """Bound the distortion of the imaged part of the convex hull of ``points`` (normalized coordinates).

    The imaged part is the hull within the lens's fold (:func:`~aura_ums.camera.fold_radius`),
    taken as the hull cut by a polygon around the fold's disk: None when nothing of it is.

    When interval arithmetic proves that a coordinate of the distortion has no critical
    point in the hull (the usual case), its extremes lie on the hull's boundary and are
    bounded edge by edge (:func:`_boundary_range`); otherwise by 2-D branch and bound
    (:func:`_box_range`).

    Parameters
    ----------
    points : ndarray, shape (n, 2)
        Finite normalized coordinates (x/z, y/z), n >= 1.
    coefficients : tuple of 5 floats
        OpenCV's (k1, k2, p1, p2, k3).
    tolerance : float
        Stop refining once every bound is within this of a value attained (normalized units).

    Returns
    -------
    lower, upper : ndarray, shape (2,), or None
        Bounds of (x_d, y_d) over the imaged part of the hull; may be infinite, never NaN.
        None when the whole hull lies beyond the fold.
    """
    with np.errstate(all="ignore"):
        hull = _within_fold(_hull(points), fold_radius(coefficients))
        if not len(hull):
            return None
        lower, upper = _boundary_range(hull, coefficients, tolerance)
        free = _free_of_critical_points(hull, coefficients)
        if not np.all(free):
            box_lower, box_upper = _box_range(hull, coefficients, tolerance)
            lower = np.where(free, lower, box_lower)
            upper = np.where(free, upper, box_upper)
        return lower, upper


def _within_fold(hull: Array, limit: float) -> Array:
    """Return the convex polygon ``hull`` cut to a polygon around the disk of radius ``limit``.

    Sound: the polygon holds the disk. A hull of fewer than 3 vertices (a point, a segment)
    is kept whole unless it lies beyond, where the camera images none of it.
    """
    if not math.isfinite(limit):
        return hull
    offset = limit * (1.0 + 1e-12)
    reach = hull @ _FOLD_NORMALS.T  # (vertex, side)
    if len(hull) < 3:
        return hull[:0] if np.any(reach.min(axis=0) > offset) else hull
    for side in np.flatnonzero(reach.max(axis=0) > offset):
        hull = clip_halfplane(hull, _FOLD_NORMALS[side], offset)
        if not len(hull):
            break
    return hull


def _hull(points: Array) -> Array:
    """Return a convex polygon with few vertices that contains the points (an outer one).

    The hull itself when an outer polygon of few vertices would be much larger: the hull of
    a thin set (a vertical line seen from a narrow map) has nearly parallel edges, whose
    extensions meet far away, and the bounds over such a polygon were up to 4 times wider
    than the distortion's reach.
    """
    # Every vertex the chain keeps: the points may span 1e12 (cut-plane crossings of a landmark
    # partly behind the camera), and merging vertices straight to within that extent's
    # rounding dropped extreme ones, which the windows then missed by up to 56 px (helper-62).
    hull = convex_hull(points, straight=True)
    if len(hull) > _HULL_VERTICES:
        fewer = simplify_outer(hull, _HULL_VERTICES)
        if polygon_area(fewer) <= (1.0 + _HULL_GROWTH) * polygon_area(hull):
            return fewer
    return hull


def _free_of_critical_points(hull: Array, c: Coefficients) -> NDArray[np.bool_]:
    """Tell, for x_d and y_d, whether interval arithmetic proves no critical point in the hull.

    Cells covering the hull are checked (split up to three times where undecided): a
    cell is free when a partial derivative has a constant, non-zero sign on all of it.
    """
    axes, hull_lo, hull_hi = _separating_axes(hull)
    if len(hull) < 3:
        return np.ones(2, dtype=bool)  # a point or a segment: its boundary is all of it
    cells = _grid(hull, _INITIAL_SPLIT)
    free = np.ones(2, dtype=bool)
    for _ in range(4):
        cells = cells[_touches(cells, axes, hull_lo, hull_hi)]
        sxx, sxy, syx, syy = _signs((cells[:, 0], cells[:, 1]), (cells[:, 2], cells[:, 3]), c, strict=True)
        undecided_x = (sxx == 0.0) & (sxy == 0.0)
        undecided_y = (syx == 0.0) & (syy == 0.0)
        undecided = (undecided_x & free[0]) | (undecided_y & free[1])
        if not np.any(undecided):
            return free
        if len(cells) > _MAX_CELLS // 4:
            break
        cells = _split(cells[undecided])
    cells = cells[_touches(cells, axes, hull_lo, hull_hi)]
    sxx, sxy, syx, syy = _signs((cells[:, 0], cells[:, 1]), (cells[:, 2], cells[:, 3]), c, strict=True)
    free[0] &= not bool(np.any((sxx == 0.0) & (sxy == 0.0)))
    free[1] &= not bool(np.any((syx == 0.0) & (syy == 0.0)))
    return free


def _grid(hull: Array, count: int) -> Array:
    lo = hull.min(axis=0)
    hi = hull.max(axis=0)
    edges_x = np.linspace(lo[0], hi[0], count + 1)
    edges_y = np.linspace(lo[1], hi[1], count + 1)
    gx, gy = np.meshgrid(np.arange(count), np.arange(count), indexing="ij")
    return np.column_stack(
        [edges_x[gx.ravel()], edges_x[gx.ravel() + 1], edges_y[gy.ravel()], edges_y[gy.ravel() + 1]]
    )


def _widened(attained: Array, x_low: Array, x_high: Array, y_low: Array, y_high: Array) -> Array:
    """Return the attained (x lo, x hi, y lo, y hi) widened by newly attained values."""
    return np.array(
        [
            min(attained[0], x_low.min()),
            max(attained[1], x_high.max()),
            min(attained[2], y_low.min()),
            max(attained[3], y_high.max()),
        ]
    )


def _round_outcome(bounds: Array, attained: Array) -> tuple[Array, Array, NDArray[np.bool_]]:
    """Combine one refinement round: its bound, the bound's gaps to the attained values, live cells.

    A cell stays live while it may hold an extreme (its bound reaches past an attained value).
    """
    relevant = np.column_stack(
        [
            bounds[:, 0] <= attained[0],
            bounds[:, 1] >= attained[1],
            bounds[:, 2] <= attained[2],
            bounds[:, 3] >= attained[3],
        ]
    )
    result = _combine(bounds, relevant)
    gaps = np.array(
        [attained[0] - result[0], result[1] - attained[1], attained[2] - result[2], result[3] - attained[3]]
    )
    return result, gaps, np.asarray(np.any(relevant, axis=1))


def _boundary_range(hull: Array, c: Coefficients, tolerance: float) -> tuple[Array, Array]:
    """Bound x_d and y_d over the hull's boundary (its vertices and edges).

    Along a piece of an edge, each coordinate is a polynomial of degree 7 in the
    parameter t in [0, 1]; its Bernstein coefficients bound it (convex hull property),
    with the two end coefficients equal to the values at the ends. Pieces that cannot
    hold an extreme are dropped; the others are halved until the bound is within
    ``tolerance`` of a value attained at a piece's end.
    """
    if len(hull) == 1:
        x, y = distort(hull[:, 0], hull[:, 1], c)
        slack = _ROUNDING * _magnitude((hull[:, 0], hull[:, 0]), (hull[:, 1], hull[:, 1]), c)
        value = np.array([x[0], y[0]])
        return value - slack[0], value + slack[0]
    start = np.repeat(hull, _INITIAL_SPLIT, axis=0)
    step = np.repeat(np.roll(hull, -1, axis=0) - hull, _INITIAL_SPLIT, axis=0) / _INITIAL_SPLIT
    start = start + np.tile(np.arange(_INITIAL_SPLIT), len(hull))[:, None] * step
    pieces = np.hstack([start, step])  # rows: a (start point), d (end - start)
    attained = np.array([np.inf, -np.inf, np.inf, -np.inf])
    for round_index in range(_MAX_ROUNDS + 1):
        bounds, ends = _piece_bounds(pieces, c)  # (m, 4) bounds; (m, 4) end values (min/max)
        attained = _widened(attained, ends[:, 0], ends[:, 1], ends[:, 2], ends[:, 3])
        result, gaps, keep = _round_outcome(bounds, attained)
        if round_index == _MAX_ROUNDS or bool(np.all(gaps <= tolerance)) or 2 * int(keep.sum()) > _MAX_CELLS:
            return np.array([result[0], result[2]]), np.array([result[1], result[3]])
        kept = pieces[keep]
        half = kept[:, 2:] / 2.0
        pieces = np.vstack([np.hstack([kept[:, :2], half]), np.hstack([kept[:, :2] + half, half])])
    raise AssertionError("unreachable")  # pragma: no cover


def _piece_bounds(pieces: Array, c: Coefficients) -> tuple[Array, Array]:
    """Bernstein bounds of x_d, y_d on segment pieces (a, d): rows of lo/hi, and end values."""
    m = len(pieces)
    both = np.vstack([pieces, np.abs(pieces)])  # the pieces, then their majorants
    sign = np.concatenate([np.ones(m), np.zeros(m)])
    k1, k2, p1, p2, k3 = (np.where(sign > 0.0, value, abs(value)).astype(np.float64) for value in c)
    c_rows = (k1, k2, p1, p2, k3)
    xd_all, yd_all = _piece_polynomials(both[:, 0], both[:, 1], both[:, 2], both[:, 3], c_rows)
    xd, yd = xd_all[:m], yd_all[:m]
    slack = _ROUNDING * (xd_all[m:].sum(axis=1) + yd_all[m:].sum(axis=1))
    bx = xd @ _BERNSTEIN
    by = yd @ _BERNSTEIN
    bounds = np.column_stack(
        [bx.min(axis=1) - slack, bx.max(axis=1) + slack, by.min(axis=1) - slack, by.max(axis=1) + slack]
    )
    bounds = np.where(np.isnan(bounds), np.array([-np.inf, np.inf, -np.inf, np.inf]), bounds)
    # End values, moved inward by the slack: each is then at most (least) the exact value
    # there, whatever rounding did, so that pruning against it is sound.
    ex = bx[:, [0, -1]]
    ey = by[:, [0, -1]]
    ends = np.column_stack(
        [ex.min(axis=1) + slack, ex.max(axis=1) - slack, ey.min(axis=1) + slack, ey.max(axis=1) - slack]
    )
    ends = np.where(np.isfinite(ends), ends, np.array([np.inf, -np.inf, np.inf, -np.inf]))
    return bounds, ends


def _pmul(a: Array, b: Array) -> Array:
    """Multiply rows of polynomial coefficients (ascending powers)."""
    out = np.zeros((a.shape[0], a.shape[1] + b.shape[1] - 1))
    for i in range(a.shape[1]):
        out[:, i : i + b.shape[1]] += a[:, i : i + 1] * b
    return out


def _pad(a: Array, width: int) -> Array:
    out = np.zeros((a.shape[0], width))
    out[:, : a.shape[1]] = a
    return out


def _piece_polynomials(
    ax: Array, ay: Array, dx: Array, dy: Array, c: tuple[Array, Array, Array, Array, Array]
) -> tuple[Array, Array]:
    """Coefficients (m, 8) of x_d(t), y_d(t) along x = ax + t dx, y = ay + t dy.

    ``c`` holds (k1, k2, p1, p2, k3), one value per row.
    """
    k1, k2, p1, p2, k3 = (value[:, None] for value in c)
    x = np.column_stack([ax, dx])
    y = np.column_stack([ay, dy])
    x2 = _pmul(x, x)
    y2 = _pmul(y, y)
    xy = _pmul(x, y)
    r2 = x2 + y2
    r4 = _pmul(r2, r2)
    r6 = _pmul(r4, r2)
    radial = _pad(np.column_stack([np.ones(len(ax)), np.zeros(len(ax))]), 7)
    radial = radial + k1 * _pad(r2, 7) + k2 * _pad(r4, 7) + k3 * r6
    xd = _pmul(x, radial) + _pad(2.0 * p1 * xy + p2 * (r2 + 2.0 * x2), 8)
    yd = _pmul(y, radial) + _pad(p1 * (r2 + 2.0 * y2) + 2.0 * p2 * xy, 8)
    return xd, yd


def _box_range(hull: Array, coefficients: Coefficients, tolerance: float) -> tuple[Array, Array]:
    """Bound the distortion over the hull by 2-D branch and bound on cells (see module doc)."""
    axes, hull_lo, hull_hi = _separating_axes(hull)
    cells = _grid(hull, _INITIAL_SPLIT)
    hx, hy = distort(hull[:, 0], hull[:, 1], coefficients)
    attained = np.array([hx.min(), hx.max(), hy.min(), hy.max()])
    for round_index in range(_MAX_ROUNDS + 1):
        cells = cells[_touches(cells, axes, hull_lo, hull_hi)]
        bounds = _cell_bounds(cells, coefficients)  # (m, 4): x lo, x hi, y lo, y hi
        centres_x = 0.5 * (cells[:, 0] + cells[:, 1])
        centres_y = 0.5 * (cells[:, 2] + cells[:, 3])
        inside = _inside(np.column_stack([centres_x, centres_y]), hull)
        if np.any(inside):
            cx, cy = distort(centres_x[inside], centres_y[inside], coefficients)
            attained = _widened(attained, cx, cx, cy, cy)
        result, gaps, keep = _round_outcome(bounds, attained)
        if round_index == _MAX_ROUNDS or bool(np.all(gaps <= tolerance)) or 4 * int(keep.sum()) > _MAX_CELLS:
            return np.array([result[0], result[2]]), np.array([result[1], result[3]])
        cells = _split(cells[keep])
    raise AssertionError("unreachable")  # pragma: no cover


def _combine(bounds: Array, relevant: NDArray[np.bool_]) -> Array:
    """Return (x lo, x hi, y lo, y hi) over the cells relevant to each extreme."""
    result = np.empty(4)
    for k, pick in enumerate((np.min, np.max, np.min, np.max)):
        column = bounds[relevant[:, k], k]
        # A relevant cell always exists: the one holding the attained extreme.
        result[k] = pick(column) if len(column) else pick(bounds[:, k])
    return result


def _split(cells: Array) -> Array:
    xm = 0.5 * (cells[:, 0] + cells[:, 1])
    ym = 0.5 * (cells[:, 2] + cells[:, 3])
    return np.concatenate(
        [
            np.column_stack([cells[:, 0], xm, cells[:, 2], ym]),
            np.column_stack([xm, cells[:, 1], cells[:, 2], ym]),
            np.column_stack([cells[:, 0], xm, ym, cells[:, 3]]),
            np.column_stack([xm, cells[:, 1], ym, cells[:, 3]]),
        ]
    )


def _separating_axes(hull: Array) -> tuple[Array, Array, Array]:
    """Return candidate separating axes of a convex polygon and its extent along each."""
    axes = [np.array([1.0, 0.0]), np.array([0.0, 1.0])]
    if len(hull) >= 2:
        edge = np.roll(hull, -1, axis=0) - hull
        axes.extend(np.column_stack([edge[:, 1], -edge[:, 0]]))
    stacked = np.asarray(axes, dtype=np.float64)
    projection = hull @ stacked.T
    return stacked, projection.min(axis=0), projection.max(axis=0)


def _touches(cells: Array, axes: Array, hull_lo: Array, hull_hi: Array) -> NDArray[np.bool_]:
    """Tell which cells may meet the polygon (False only when an axis separates them)."""
    corners_x = cells[:, [0, 1, 0, 1]]
    corners_y = cells[:, [2, 2, 3, 3]]
    projection = (
        corners_x[:, :, None] * axes[None, None, :, 0] + corners_y[:, :, None] * axes[None, None, :, 1]
    )
    separated = (projection.max(axis=1) < hull_lo) | (projection.min(axis=1) > hull_hi)
    return np.asarray(~np.any(separated, axis=1))


def _inside(points: Array, hull: Array) -> NDArray[np.bool_]:
    """Tell which points lie in a convex counter-clockwise polygon (False for degenerate ones)."""
    if len(hull) < 3:
        return np.zeros(len(points), dtype=bool)
    edge = np.roll(hull, -1, axis=0) - hull
    rel_x = points[:, 0, None] - hull[None, :, 0]
    rel_y = points[:, 1, None] - hull[None, :, 1]
    return np.asarray(np.all(edge[None, :, 0] * rel_y - edge[None, :, 1] * rel_x >= 0.0, axis=1))


# --- interval arithmetic on arrays of intervals --------------------------------------------


def _clean(lo: Array, hi: Array) -> Interval:
    """Replace NaN (from inf - inf or 0 * inf) by the widest interval."""
    return np.where(np.isnan(lo), -np.inf, lo), np.where(np.isnan(hi), np.inf, hi)


def _widest_where_nan(values: Array) -> Interval:
    """Range over the first axis; the widest interval where any value is NaN."""
    bad = np.any(np.isnan(values), axis=0)
    return np.where(bad, -np.inf, values.min(axis=0)), np.where(bad, np.inf, values.max(axis=0))


def _add(a: Interval, b: Interval) -> Interval:
    return _clean(a[0] + b[0], a[1] + b[1])


def _scale(c: float, a: Interval) -> Interval:
    if c >= 0.0:
        return _clean(c * a[0], c * a[1])
    return _clean(c * a[1], c * a[0])


def _mul(a: Interval, b: Interval) -> Interval:
    products = np.stack([a[0] * b[0], a[0] * b[1], a[1] * b[0], a[1] * b[1]])
    return _widest_where_nan(products)


def _square(a: Interval) -> Interval:
    lo2 = a[0] * a[0]
    hi2 = a[1] * a[1]
    low = np.where(a[0] > 0.0, lo2, np.where(a[1] < 0.0, hi2, 0.0))
    return low, np.maximum(lo2, hi2)


#: Largest ratio of a derivative's coefficients to its leading one whose roots are computed.
_ROOTS_CONDITION = 1e12


def _horner_range(coefficients: Array, t: Interval) -> Interval:
    """Enclose a polynomial (ascending coefficients) over intervals of t by interval Horner."""
    value: Interval = (np.full(t[0].shape, coefficients[-1]), np.full(t[0].shape, coefficients[-1]))
    for coefficient in coefficients[-2::-1]:
        value = _add(_mul(value, t), (np.full(t[0].shape, coefficient), np.full(t[0].shape, coefficient)))
    return value


def _poly_range(coefficients: Array, t: Interval) -> Interval:
    """Exact range of a polynomial (ascending coefficients) over intervals of t."""
    derivative = np.polynomial.polynomial.polyder(coefficients)
    candidates = [t[0], t[1]]
    if len(derivative) and np.any(derivative != 0.0):
        trimmed = np.trim_zeros(derivative, "b")
        if np.max(np.abs(trimmed)) > _ROOTS_CONDITION * abs(trimmed[-1]):
            # A leading coefficient this small next to the others (1e-300, say) gives roots
            # the companion matrix cannot resolve, or overflows it: bound the polynomial by
            # Horner's scheme in interval arithmetic instead (wider, sound).
            return _horner_range(coefficients, t)
        roots = np.polynomial.polynomial.polyroots(trimmed)
        # Every root's real part is a candidate: extra points inside the interval are
        # harmless, and a real root computed with a spurious imaginary part is not lost.
        for root in np.real(roots):
            candidates.append(np.clip(np.full(t[0].shape, float(root)), t[0], t[1]))
    values = np.stack([np.polynomial.polynomial.polyval(c, coefficients) for c in candidates])
    return _widest_where_nan(np.asarray(values, dtype=np.float64))


def _natural(x: Interval, y: Interval, c: Coefficients) -> tuple[Interval, Interval]:
    """Natural interval extension of the distortion map over boxes x by y."""
    k1, k2, p1, p2, k3 = c
    x2 = _square(x)
    y2 = _square(y)
    r2 = _add(x2, y2)
    radial = _poly_range(np.array([1.0, k1, k2, k3]), r2)
    xy = _mul(x, y)
    r2_2x2 = _add(r2, _scale(2.0, x2))
    r2_2y2 = _add(r2, _scale(2.0, y2))
    xd = _add(_add(_mul(x, radial), _scale(2.0 * p1, xy)), _scale(p2, r2_2x2))
    yd = _add(_add(_mul(y, radial), _scale(p1, r2_2y2)), _scale(2.0 * p2, xy))
    return xd, yd


def _signs(
    x: Interval, y: Interval, c: Coefficients, *, strict: bool = False
) -> tuple[Array, Array, Array, Array]:
    """Signs (+1, -1, 0 unknown) of d xd/dx, d xd/dy, d yd/dx, d yd/dy over each box.

    Not ``strict``: +1 for >= 0 on the box (monotone: its extremes are on a side). ``strict``:
    +1 only for > 0, as the proof of no critical point needs (a derivative that reaches 0
    on a box's edge may vanish there together with the other one).
    """
    k1, k2, p1, p2, k3 = c
    x2 = _square(x)
    y2 = _square(y)
    r2 = _add(x2, y2)
    radial = _poly_range(np.array([1.0, k1, k2, k3]), r2)
    slope = _poly_range(np.array([k1, 2.0 * k2, 3.0 * k3]), r2)
    xy = _mul(x, y)
    dxx = _add(_add(radial, _mul(_scale(2.0, x2), slope)), _add(_scale(2.0 * p1, y), _scale(6.0 * p2, x)))
    cross = _add(_mul(_scale(2.0, xy), slope), _add(_scale(2.0 * p1, x), _scale(2.0 * p2, y)))
    dyy = _add(_add(radial, _mul(_scale(2.0, y2), slope)), _add(_scale(6.0 * p1, y), _scale(2.0 * p2, x)))

    def sign(d: Interval) -> Array:
        if strict:
            return np.where(d[0] > 0.0, 1.0, np.where(d[1] < 0.0, -1.0, 0.0))
        return np.where(d[0] >= 0.0, 1.0, np.where(d[1] <= 0.0, -1.0, 0.0))

    return sign(dxx), sign(cross), sign(cross), sign(dyy)


def _side(lo: Array, hi: Array, sign: Array, upper: bool) -> Interval:
    """Collapse an interval to the end where a function of known monotonicity is extreme."""
    toward_hi = sign > 0.0 if upper else sign < 0.0
    toward_lo = sign < 0.0 if upper else sign > 0.0
    return np.where(toward_lo, lo, np.where(toward_hi, hi, lo)), np.where(
        toward_hi, hi, np.where(toward_lo, lo, hi)
    )


def _cell_bounds(cells: Array, c: Coefficients) -> Array:
    """Return (m, 4) bounds x lo, x hi, y lo, y hi of the distortion on each cell."""
    x = (cells[:, 0], cells[:, 1])
    y = (cells[:, 2], cells[:, 3])
    sxx, sxy, syx, syy = _signs(x, y, c)
    out = np.empty((len(cells), 4))
    for column, (sign_x, sign_y, upper, coordinate) in enumerate(
        ((sxx, sxy, False, 0), (sxx, sxy, True, 0), (syx, syy, False, 1), (syx, syy, True, 1))
    ):
        box_x = _side(x[0], x[1], sign_x, upper)
        box_y = _side(y[0], y[1], sign_y, upper)
        value = _natural(box_x, box_y, c)[coordinate]
        out[:, column] = value[1] if upper else value[0]
    slack = _ROUNDING * _magnitude(x, y, c)
    out[:, 0] -= slack
    out[:, 1] += slack
    out[:, 2] -= slack
    out[:, 3] += slack
    return np.where(np.isnan(out), np.array([-np.inf, np.inf, -np.inf, np.inf]), out)


def _magnitude(x: Interval, y: Interval, c: Coefficients) -> Array:
    """Bound the sum of the absolute values of the distortion's terms over each box.

    Floating-point evaluation of the polynomial (ours, or the camera's own) errs by at
    most a few ulps of this sum; far outside the lens's field it dwarfs the result.
    """
    k1, k2, p1, p2, k3 = c
    ax = np.maximum(np.abs(x[0]), np.abs(x[1]))
    ay = np.maximum(np.abs(y[0]), np.abs(y[1]))
    r2 = ax * ax + ay * ay
    radial = 1.0 + r2 * (abs(k1) + r2 * (abs(k2) + r2 * abs(k3)))
    return np.asarray((ax + ay) * radial + 2.0 * (abs(p1) + abs(p2)) * (ax * ay + 1.5 * r2), dtype=np.float64)
