"""Confidence regions of probabilistic estimators, and the small functions that build them.

A :class:`ConfidenceRegion` is a convex position polygon and a heading interval, the
same shape as a :class:`~aura_ums.uncertainty.SpatialUncertaintyMap`, so that an EKF's
or a particle filter's belief can be drawn, measured and tested next to the map.

Probability convention (both filters): a region of probability ``p`` is the product of
a position region and a heading interval that each hold ``q = sqrt(p)`` of the marginal
probability. The joint probability of the product region is then

- exactly ``p`` when position and heading are independent;
- at least ``p`` for any Gaussian belief, by the Gaussian correlation inequality (Royen
  2014: two centred symmetric convex sets, here the elliptic cylinder and the heading
  slab, are positively correlated);
- at least ``2*sqrt(p) - 1`` for any belief at all (Bonferroni), e.g. 0.98997 for p = 0.99.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from statistics import NormalDist
from typing import cast, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import COORDINATE, Range, finite_float, float_array, items_of
from aura_ums.errors import InputError
from aura_ums.geometry import POSITION_TOLERANCE, ConvexPolygon, HeadingWedge, wrap_angle

Array = NDArray[np.float64]

#: Vertices of the outer polygon that stands for a Gaussian confidence ellipse.
_ELLIPSE_SIDES = 64
#: Most vertices :func:`ellipse_polygon` makes: 16 bytes each, 16 MB (64 stand for an ellipse).
MAX_ELLIPSE_SIDES = 1_000_000
#: A variance of a position, m^2: up to the square of the coordinate range (1e300 overflowed).
_VARIANCE = Range(0.0, COORDINATE.high**2, "m^2")
#: A squared Mahalanobis radius (a chi-square quantile: 73.7 at p = 1 - 1e-16), up to 100 sigmas.
_SCALE = Range(0.0, 1e4, "", low_open=True)

_TWO_PI = 2.0 * math.pi

# Headings within this many radians of a region's interval count as inside it, as they do
# for a HeadingWedge (tests/baselines/test_confidence_region.py holds the two equal), so that the
# baselines and the map judge a pose on a boundary alike.
_HEADING_TOLERANCE = 1e-9

# A covariance whose eigenvalue ratio is below this is treated as rank one (collinear points).
_RANK_TOLERANCE = 1e-12

# Point sets larger than this are thinned (Akl-Toussaint) before the exact hull.
_PREFILTER_FROM = 32
_STANDARD_NORMAL = NormalDist()


def check_probability(probability: object, name: str = "probability") -> float:
    """Return ``probability`` as a float in the open interval (0, 1), or raise naming ``name``."""
    value = finite_float(probability, name)
    if not 0.0 < value < 1.0:
        raise InputError(f"{name}: expected a probability in (0, 1), got {value!r}")
    return value


def marginal_probability(probability: float) -> float:
    """Return the probability ``sqrt(p)`` each factor of a product region holds (module docstring).

    Examples
    --------
    >>> round(marginal_probability(0.99), 6)
    0.994987
    """
    return math.sqrt(probability)


def chi2_quantile(probability: float, dof: int) -> float:
    """Return the ``probability`` quantile of the chi-square distribution with 1 or 2 degrees of freedom.

    Closed forms: ``z((1 + p)/2)**2`` for one degree of freedom, ``-2 ln(1 - p)`` for two.

    Examples
    --------
    >>> round(chi2_quantile(0.99, 2), 4), round(chi2_quantile(0.95, 1), 4)
    (9.2103, 3.8415)
    >>> chi2_quantile(0.5, 3)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: dof: expected 1 or 2, got 3
    >>> chi2_quantile(float("nan"), 2)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: probability: expected a finite number, got nan
    """
    if isinstance(dof, bool) or dof not in (1, 2):
        raise InputError(f"dof: expected 1 or 2, got {dof!r}")
    probability = finite_float(probability, "probability")
    if not 0.0 < probability < 1.0:
        raise InputError(f"probability: expected a number in (0, 1), got {probability!r}")
    if dof == 1:
        return _STANDARD_NORMAL.inv_cdf(0.5 + 0.5 * probability) ** 2
    return -2.0 * math.log1p(-probability)


def normal_halfwidth(probability: float) -> float:
    """Return z such that a standard normal lies in [-z, z] with ``probability``.

    Examples
    --------
    >>> round(normal_halfwidth(0.9973), 3)
    3.0
    """
    return _STANDARD_NORMAL.inv_cdf(0.5 + 0.5 * probability)


def ellipse_polygon(
    center: tuple[float, float],
    covariance: tuple[float, float, float],
    scale: float,
    sides: int = _ELLIPSE_SIDES,
) -> Array:
    """Return the vertices of a polygon circumscribing the ellipse ``d' C^-1 d <= scale``.

    The polygon is the affine image of the regular ``sides``-gon circumscribing the unit
    circle, so it contains the ellipse (its vertices lie ``1/cos(pi/sides) - 1`` outside,
    0.12 % for 64 sides). A singular covariance gives a segment or a point (repeated rows).

    Parameters
    ----------
    center : tuple of float
        Centre (x, y), metres, each in [-1e6, 1e6].
    covariance : tuple of float
        ``(cxx, cxy, cyy)``, m^2, positive semi-definite (``cxy**2 <= cxx * cyy``), the
        variances at most 1e12.
    scale : float
        Squared Mahalanobis radius, in (0, 1e4] (a chi-square quantile).
    sides : int
        Number of vertices, in [3, 1000000].

    Returns
    -------
    ndarray, shape (sides, 2)
        Counter-clockwise vertices (x, y), metres.

    Examples
    --------
    >>> v = ellipse_polygon((0.0, 0.0), (4.0, 0.0, 1.0), 1.0, sides=4)
    >>> np.round(np.abs(v).max(axis=0), 4).tolist()    # semi-axes 2 and 1, times sqrt(2)
    [2.8284, 1.4142]
    >>> float(np.abs(ellipse_polygon((1.0, 2.0), (0.0, 0.0, 0.0), 9.0, sides=4) - [1, 2]).max())
    0.0
    >>> ellipse_polygon((0.0, 0.0), (1.0, 5.0, 1.0), 9.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: covariance: expected a positive semi-definite (cxx, cxy, cyy), \
cxy**2 <= cxx * cyy, got (1.0, 5.0, 1.0)
    """
    x, y = _pair(center, "center", "(x, y) in metres")
    cxx, cxy, cyy = _covariance(covariance)
    scale = _SCALE.check(scale, "scale")
    count: object = sides
    whole = isinstance(count, (int, np.integer)) and not isinstance(count, bool)
    if not whole or not 3 <= cast(int, count) <= MAX_ELLIPSE_SIDES:
        raise InputError(
            f"sides: expected an integer in [3, {MAX_ELLIPSE_SIDES}] (16 bytes a vertex: 16 MB), "
            f"got {sides!r}"
        )
    return _ellipse_polygon((x, y), (cxx, cxy, cyy), scale, int(sides))


def _pair(value: object, name: str, what: str) -> tuple[float, float]:
    """Return ``value`` as two coordinates in the coordinate range, or raise naming ``name``."""
    items: tuple[object, ...] = items_of(cast("Iterable[object]", value), name, what)
    if len(items) != 2:
        raise InputError(f"{name}: expected {what}, got {value!r}")
    return (COORDINATE.check(items[0], f"{name}[0]"), COORDINATE.check(items[1], f"{name}[1]"))


def _covariance(value: object) -> tuple[float, float, float]:
    """Return ``(cxx, cxy, cyy)`` checked: variances in range, positive semi-definite (to rounding)."""
    what = "(cxx, cxy, cyy) in m^2"
    items: tuple[object, ...] = items_of(cast("Iterable[object]", value), "covariance", what)
    if len(items) != 3:
        raise InputError(f"covariance: expected {what}, got {value!r}")
    cxx = _VARIANCE.check(items[0], "covariance[0]")
    cxy = finite_float(items[1], "covariance[1]")
    cyy = _VARIANCE.check(items[2], "covariance[2]")
    if cxy * cxy > cxx * cyy * (1.0 + 1e-9):
        raise InputError(
            f"covariance: expected a positive semi-definite (cxx, cxy, cyy), cxy**2 <= cxx * cyy, "
            f"got {(cxx, cxy, cyy)!r}"
        )
    return (cxx, cxy, cyy)


def _ellipse_polygon(
    center: tuple[float, float], covariance: tuple[float, float, float], scale: float, sides: int
) -> Array:
    """:func:`ellipse_polygon` on checked numbers."""
    cxx, cxy, cyy = covariance
    half_trace = 0.5 * (cxx + cyy)
    spread = math.hypot(0.5 * (cxx - cyy), cxy)
    major = max(half_trace + spread, 0.0)
    minor = max(half_trace - spread, 0.0)
    angle = 0.5 * math.atan2(2.0 * cxy, cxx - cyy)
    reach = 1.0 / math.cos(math.pi / sides)
    a = math.sqrt(scale * major) * reach
    b = math.sqrt(scale * minor) * reach
    t = np.arange(sides) * (_TWO_PI / sides)
    u, v = a * np.cos(t), b * np.sin(t)
    c, s = math.cos(angle), math.sin(angle)
    return np.column_stack([center[0] + c * u - s * v, center[1] + s * u + c * v])


def _pseudo_inverse(cxx: float, cxy: float, cyy: float) -> tuple[float, float, float]:
    """Return the Moore-Penrose pseudo-inverse ``(ixx, ixy, iyy)`` of a symmetric PSD 2x2 matrix."""
    half_trace = 0.5 * (cxx + cyy)
    spread = math.hypot(0.5 * (cxx - cyy), cxy)
    major = half_trace + spread
    if not major > 0.0:
        return (0.0, 0.0, 0.0)
    minor = half_trace - spread
    if minor > _RANK_TOLERANCE * major:
        det = cxx * cyy - cxy * cxy
        return (cyy / det, -cxy / det, cxx / det)
    # Rank one: C = major v v', pinv = v v' / major, v the major axis.
    angle = 0.5 * math.atan2(2.0 * cxy, cxx - cyy)
    c, s = math.cos(angle), math.sin(angle)
    return (c * c / major, c * s / major, s * s / major)


def convex_hull_polygon(points: Array) -> ConvexPolygon:
    """Return the convex hull of ``(n, 2)`` points (m), n >= 1, as a ConvexPolygon.

    Points strictly inside the polygon of the extreme points in eight directions
    (Akl-Toussaint) cannot be hull vertices and are dropped before the exact hull.

    Examples
    --------
    >>> grid = np.stack(np.meshgrid(np.arange(5.0), np.arange(5.0)), axis=-1).reshape(-1, 2)
    >>> convex_hull_polygon(grid).vertex_count, convex_hull_polygon(grid).area
    (4, 16.0)
    >>> convex_hull_polygon(np.ones((3, 2))).vertex_count      # identical points: a point
    1
    """
    if len(points) > _PREFILTER_FROM:
        x, y = points[:, 0], points[:, 1]
        indices = [
            int(np.argmin(y)),
            int(np.argmax(x - y)),
            int(np.argmax(x)),
            int(np.argmax(x + y)),
            int(np.argmax(y)),
            int(np.argmin(x - y)),
            int(np.argmin(x)),
            int(np.argmin(x + y)),
        ]
        corners = points[indices]
        following = np.roll(corners, -1, axis=0)
        edges = following - corners
        useful = np.hypot(edges[:, 0], edges[:, 1]) > 0.0
        if np.count_nonzero(useful) >= 3:
            starts, edges = corners[useful], edges[useful]
            scale = float(np.abs(points).max()) + float(np.ptp(points, axis=0).max())
            # Strictly left of every edge of the (convex, counter-clockwise) octagon: interior.
            cross = edges[None, :, 0] * (y[:, None] - starts[None, :, 1]) - edges[None, :, 1] * (
                x[:, None] - starts[None, :, 0]
            )
            margin = 1e-9 * scale * np.hypot(edges[:, 0], edges[:, 1])
            inside = np.all(cross > margin[None, :], axis=1)
            points = points[~inside]
    return ConvexPolygon.from_points(points)


def mahalanobis_core(points: Array, weights: Array, probability: float) -> Array:
    """Return the fewest points, ranked by Mahalanobis distance, that hold ``probability`` of the weight.

    Distances are from the weighted mean with the weighted covariance (its pseudo-inverse
    when singular: identical or collinear points).

    Parameters
    ----------
    points : ndarray, shape (n, 2)
        Positions, metres, n >= 1.
    weights : ndarray, shape (n,)
        Non-negative weights summing to 1.
    probability : float
        Weight to hold, in (0, 1).

    Returns
    -------
    ndarray, shape (k, 2)
        The chosen points, nearest first.

    Examples
    --------
    >>> pts = np.array([[0.0, 0.0], [1.0, 0.0], [-1.0, 0.0], [9.0, 0.0], [-9.0, 0.0]])
    >>> mahalanobis_core(pts, np.array([0.6, 0.1, 0.1, 0.1, 0.1]), 0.8).tolist()
    [[0.0, 0.0], [1.0, 0.0], [-1.0, 0.0]]
    >>> mahalanobis_core(np.ones((3, 2)), np.full(3, 1 / 3), 0.5).tolist()   # identical points
    [[1.0, 1.0], [1.0, 1.0]]
    """
    mean = weights @ points
    dx = points[:, 0] - mean[0]
    dy = points[:, 1] - mean[1]
    wx = weights * dx
    ixx, ixy, iyy = _pseudo_inverse(float(wx @ dx), float(wx @ dy), float((weights * dy) @ dy))
    distance = ixx * dx * dx + 2.0 * ixy * dx * dy + iyy * dy * dy
    order = np.argsort(distance, kind="stable")
    held = np.cumsum(weights[order])
    count = int(np.searchsorted(held, probability * held[-1] * (1.0 - 1e-12), side="left")) + 1
    return np.asarray(points[order[: min(count, len(points))]], dtype=np.float64)


def shortest_arc(headings: Array, weights: Array, probability: float) -> tuple[float, float]:
    """Return the shortest arc of the circle holding ``probability`` of the weight of ``headings``.

    Every arc that starts at a particle's heading is tried (the shortest one does), on the
    headings sorted and unrolled twice around the circle, so arcs across +-pi are found.

    Parameters
    ----------
    headings : ndarray, shape (n,)
        Headings, radians in (-pi, pi], n >= 1.
    weights : ndarray, shape (n,)
        Non-negative weights summing to 1.
    probability : float
        Weight to hold, in (0, 1).

    Returns
    -------
    center, halfwidth : float
        Centre of the arc (rad, wrapped to (-pi, pi]) and half its width (rad, <= pi).

    Examples
    --------
    >>> c, w = shortest_arc(np.array([3.1, -3.1, 0.0]), np.array([0.45, 0.45, 0.1]), 0.9)
    >>> round(c, 4), round(w, 4)                       # across the seam, not through 0
    (3.1416, 0.0416)
    >>> shortest_arc(np.array([0.5, 0.5]), np.array([0.5, 0.5]), 0.99)   # one direction
    (0.5, 0.0)
    """
    order = np.argsort(headings, kind="stable")
    sorted_headings = headings[order]
    sorted_weights = weights[order]
    n = len(sorted_headings)
    unrolled = np.concatenate([sorted_headings, sorted_headings + _TWO_PI])
    held = np.cumsum(np.concatenate([sorted_weights, sorted_weights]))
    total = float(held[n - 1])
    before = held[:n] - sorted_weights
    start = np.arange(n)
    target = before + probability * total * (1.0 - 1e-12)
    end = np.searchsorted(held, target, side="left")
    end = np.clip(end, start, start + n - 1)
    length = unrolled[end] - sorted_headings
    best = int(np.argmin(length))
    lo = float(sorted_headings[best])
    width = float(length[best])
    return wrap_angle(lo + 0.5 * width), min(0.5 * width, math.pi)


@dataclass(frozen=True, slots=True)
class ConfidenceRegion:
    """A probabilistic estimator's confidence region: a convex position polygon and a heading interval.

    Parameters
    ----------
    polygon : ConvexPolygon
        Where the robot is, counter-clockwise vertices (m); a point or a segment when the
        belief is degenerate.
    heading_center : float
        Centre of the heading interval, radians; wrapped to (-pi, pi].
    heading_halfwidth : float
        Half the interval's width, radians, in [0, pi]; pi (or more, stored as pi) is any heading.
    probability : float
        The joint probability the region stands for, in (0, 1); each factor holds
        ``sqrt(probability)`` of its marginal (see the module docstring for what that implies).

    Raises
    ------
    InputError
        For a polygon that is not a ConvexPolygon, non-finite angles, a negative
        half-width or a probability outside (0, 1).

    Examples
    --------
    >>> import math
    >>> square = ConvexPolygon([(-1, -1), (1, -1), (1, 1), (-1, 1)])
    >>> region = ConfidenceRegion(square, math.pi, 0.1, 0.99)
    >>> region.area, region.contains(0.5, 0.5, -math.pi + 0.05)    # across the +-pi seam
    (4.0, True)
    >>> region.contains(np.array([0.0, 2.0]), np.zeros(2), np.full(2, math.pi)).tolist()
    [True, False]
    >>> ConfidenceRegion(square, 0.0, -0.1, 0.99)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: heading_halfwidth: expected a non-negative number, got -0.1
    """

    polygon: ConvexPolygon
    heading_center: float
    heading_halfwidth: float
    probability: float

    def __post_init__(self) -> None:
        if not isinstance(self.polygon, ConvexPolygon):
            raise InputError(f"polygon: expected a ConvexPolygon, got {type(self.polygon).__name__}")
        center = finite_float(self.heading_center, "heading_center")
        halfwidth = finite_float(self.heading_halfwidth, "heading_halfwidth")
        if halfwidth < 0.0:
            raise InputError(f"heading_halfwidth: expected a non-negative number, got {halfwidth!r}")
        object.__setattr__(self, "heading_center", wrap_angle(center))
        object.__setattr__(self, "heading_halfwidth", min(halfwidth, math.pi))
        object.__setattr__(self, "probability", check_probability(self.probability))

    @classmethod
    def gaussian(cls, mean: ArrayLike, covariance: ArrayLike, probability: float = 0.99) -> ConfidenceRegion:
        """Return the confidence region of ``probability`` of a Gaussian pose belief.

        What :meth:`~aura_ums.baselines.ExtendedKalmanFilter.region` returns, for any filter that keeps a
        Gaussian belief (e.g. your own EKF or UKF, to compare it with
        :func:`~aura_ums.logs.compare_on_log`). Position: the ellipse of
        ``sqrt(probability)`` (chi-square, 2 degrees of freedom) of the (x, y) marginal,
        as a circumscribed 64-gon; heading: the mean +- the normal quantile of
        ``sqrt(probability)`` times its standard deviation (see the module notes).

        Parameters
        ----------
        mean : array_like, shape (3,)
            ``(x, y, heading)``: metres, metres, radians.
        covariance : array_like, shape (3, 3)
            Covariance of ``(x, y, heading)`` (m^2, m rad, rad^2): symmetric, with a
            non-negative diagonal.
        probability : float
            Joint probability, in (0, 1).

        Raises
        ------
        InputError
            For a mean or covariance of the wrong shape, non-finite values, an asymmetric
            covariance, a negative variance or a bad probability.

        Examples
        --------
        >>> region = ConfidenceRegion.gaussian([1.0, 2.0, 0.5], np.diag([0.04, 0.01, 0.0025]))
        >>> round(region.area, 3), round(region.heading_halfwidth, 4), region.contains(1.0, 2.0, 0.5)
        (0.666, 0.1403, True)
        >>> ConfidenceRegion.gaussian([0, 0, 0], np.zeros((3, 3))).area        # a known pose: a point
        0.0
        >>> ConfidenceRegion.gaussian([0, 0, 0], np.eye(2))
        Traceback (most recent call last):
        ...
        aura_ums.errors.InputError: covariance: expected a 3 x 3 array, got shape (2, 2)
        """
        centre = float_array(mean, "mean")
        if centre.shape != (3,):
            raise InputError(f"mean: expected (x, y, heading), 3 numbers, got shape {centre.shape}")
        cov = float_array(covariance, "covariance")
        if cov.shape != (3, 3):
            raise InputError(f"covariance: expected a 3 x 3 array, got shape {cov.shape}")
        if np.abs(cov - cov.T).max() > 1e-9 * max(float(np.abs(cov).max()), 1e-300):
            raise InputError(f"covariance: expected a symmetric matrix, got {cov.tolist()}")
        if (np.diag(cov) < 0.0).any():
            raise InputError(f"covariance: expected non-negative variances, got {np.diag(cov).tolist()}")
        x, y, heading = centre.tolist()
        return gaussian_region(
            x, y, heading, float(cov[0, 0]), float(cov[0, 1]), float(cov[1, 1]), float(cov[2, 2]), probability
        )

    @property
    def area(self) -> float:
        """Area of the position polygon, square metres."""
        return self.polygon.area

    @property
    def heading_width(self) -> float:
        """Width of the heading interval, radians, in [0, 2*pi]."""
        return 2.0 * self.heading_halfwidth

    @property
    def center(self) -> tuple[float, float]:
        """Area centroid (x, y) of the polygon, metres (vertex mean when degenerate)."""
        x, y = self.polygon.centroid.tolist()
        return (float(x), float(y))

    @property
    def wedge(self) -> HeadingWedge:
        """The heading interval as a :class:`~aura_ums.geometry.HeadingWedge` (full circle at pi)."""
        return HeadingWedge(self.heading_center, self.heading_halfwidth, self.heading_halfwidth)

    @overload
    def contains(self, x: float, y: float, heading: float) -> bool: ...
    @overload
    def contains(self, x: ArrayLike, y: ArrayLike, heading: ArrayLike) -> bool | NDArray[np.bool_]: ...
    def contains(self, x: ArrayLike, y: ArrayLike, heading: ArrayLike) -> bool | NDArray[np.bool_]:
        """Tell whether poses lie in the region: position in the polygon and heading in the interval.

        Parameters
        ----------
        x, y : float or array_like
            Positions, metres.
        heading : float or array_like
            Headings, radians, any value (compared modulo 2*pi).

        Returns
        -------
        bool or ndarray of bool
            A bool for scalar input, else an array of the inputs' common shape. Boundaries
            count as inside, within :data:`~aura_ums.geometry.POSITION_TOLERANCE` m and
            1e-9 rad.
        """
        xs, ys, hs = float_array(x, "x"), float_array(y, "y"), float_array(heading, "heading")
        if not (xs.shape == ys.shape == hs.shape):
            raise InputError(
                f"contains: expected x, y and heading of one shape, got {xs.shape}, {ys.shape}, {hs.shape}"
            )
        points = np.column_stack([xs.reshape(-1), ys.reshape(-1)])
        inside = self.polygon.contains(points, tolerance=POSITION_TOLERANCE)
        offset = np.abs(wrap_angle(hs.reshape(-1) - self.heading_center))
        inside &= offset <= self.heading_halfwidth + _HEADING_TOLERANCE
        if xs.ndim == 0:
            return bool(inside[0])
        return np.asarray(inside.reshape(xs.shape), dtype=np.bool_)


def gaussian_region(
    x: float, y: float, heading: float, xx: float, xy: float, yy: float, hh: float, probability: object
) -> ConfidenceRegion:
    """:meth:`ConfidenceRegion.gaussian` on checked numbers: mean (m, m, rad) and covariance entries."""
    p = check_probability(probability)
    q = marginal_probability(p)
    vertices = _ellipse_polygon((x, y), (xx, xy, yy), chi2_quantile(q, 2), _ELLIPSE_SIDES)
    try:
        polygon = ConvexPolygon(vertices)
    except InputError:  # a (nearly) singular ellipse: its hull is a segment or a point
        polygon = ConvexPolygon.from_points(vertices)
    halfwidth = normal_halfwidth(q) * math.sqrt(max(hh, 0.0))
    return ConfidenceRegion(polygon, wrap_angle(heading), min(halfwidth, math.pi), p)
