"""ConfidenceRegion, the ellipse polygon, the particle core and the shortest heading arc."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numpy.typing import NDArray

from aura_ums.baselines import ConfidenceRegion, ExtendedKalmanFilter, chi2_quantile, ellipse_polygon
from aura_ums.baselines._region import convex_hull_polygon, mahalanobis_core, shortest_arc
from aura_ums.errors import InputError
from aura_ums.geometry import ConvexPolygon
from aura_ums.uncertainty import Pose, TerrainTable, TurnAndRun

SQUARE = ConvexPolygon([(-1, -1), (1, -1), (1, 1), (-1, 1)])


def test_contains_wraps_around_pi() -> None:
    region = ConfidenceRegion(SQUARE, math.pi, 0.1, 0.99)
    assert region.contains(0.0, 0.0, -math.pi + 0.09) is True
    assert region.contains(0.0, 0.0, math.pi - 0.09) is True
    assert region.contains(0.0, 0.0, 3 * math.pi + 0.05) is True  # any representative of the angle
    assert region.contains(0.0, 0.0, math.pi - 0.11) is False
    assert region.contains(0.0, 0.0, 0.0) is False
    assert region.contains(1.5, 0.0, math.pi) is False  # heading fine, position outside
    headings = np.array([[math.pi, -math.pi + 0.05], [0.0, math.pi - 0.2]])
    inside = region.contains(np.zeros((2, 2)), np.zeros((2, 2)), headings)
    assert isinstance(inside, np.ndarray)
    assert inside.shape == (2, 2)
    assert inside.tolist() == [[True, True], [False, False]]


@pytest.mark.parametrize(("beyond", "inside"), [(0.5e-9, True), (2e-9, False)])
def test_a_heading_just_past_the_edge_counts_as_a_wedge_counts_it(beyond: float, inside: bool) -> None:
    # The region writes the wedge's angular tolerance again (it may not import geometry's
    # private constant): here the two are held equal.
    region = ConfidenceRegion(SQUARE, 0.0, 0.1, 0.99)
    for heading in (0.1 + beyond, -0.1 - beyond):
        assert region.contains(0.0, 0.0, heading) is inside
        assert region.wedge.contains(heading) is inside


def test_centre_is_wrapped_and_wide_interval_is_the_full_circle() -> None:
    region = ConfidenceRegion(SQUARE, -math.pi, 5.0, 0.5)
    assert region.heading_center == math.pi
    assert region.heading_halfwidth == math.pi
    assert region.heading_width == 2 * math.pi
    assert region.wedge.is_full_circle
    assert np.all(region.contains(np.zeros(7), np.zeros(7), np.linspace(-math.pi, math.pi, 7)))


def test_degenerate_polygon_region() -> None:
    region = ConfidenceRegion(ConvexPolygon.point(2.0, 3.0), 0.0, 0.0, 0.9)
    assert region.area == 0.0
    assert region.center == (2.0, 3.0)
    assert region.contains(2.0, 3.0, 0.0) is True
    assert region.contains(2.0, 3.0 + 1e-6, 0.0) is False
    assert region.contains(2.0, 3.0, 1e-6) is False


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"polygon": [(0, 0)]}, "polygon: expected a ConvexPolygon"),
        ({"heading_center": math.nan}, "heading_center: expected a finite number"),
        ({"heading_halfwidth": -0.1}, "heading_halfwidth: expected a non-negative number"),
        ({"probability": 1.0}, r"probability: expected a probability in \(0, 1\)"),
        ({"probability": 0.0}, r"probability: expected a probability in \(0, 1\)"),
    ],
)
def test_bad_region_arguments(kwargs: dict[str, object], match: str) -> None:
    args: dict[str, object] = {
        "polygon": SQUARE,
        "heading_center": 0.0,
        "heading_halfwidth": 0.1,
        "probability": 0.99,
    }
    args.update(kwargs)
    with pytest.raises(InputError, match=match):
        ConfidenceRegion(**args)  # type: ignore[arg-type]


def test_contains_rejects_mismatched_shapes() -> None:
    region = ConfidenceRegion(SQUARE, 0.0, 0.1, 0.99)
    with pytest.raises(InputError, match="contains: expected x, y and heading of one shape"):
        region.contains(np.zeros(2), np.zeros(3), np.zeros(2))


def test_chi2_quantiles_match_scipy() -> None:
    from scipy.stats import chi2

    for p in (0.5, 0.9, 0.99, 0.999):
        assert chi2_quantile(p, 1) == pytest.approx(chi2.ppf(p, 1), rel=1e-9)
        assert chi2_quantile(p, 2) == pytest.approx(chi2.ppf(p, 2), rel=1e-9)


def test_ellipse_polygon_circumscribes_the_ellipse() -> None:
    covariance = (2.0, 0.8, 0.5)
    scale = 9.21
    vertices = ellipse_polygon((3.0, -1.0), covariance, scale)
    polygon = ConvexPolygon(vertices)  # validates: convex and counter-clockwise
    assert polygon.vertex_count == 64
    matrix = np.array([[2.0, 0.8], [0.8, 0.5]])
    root = np.linalg.cholesky(matrix * scale)
    t = np.linspace(0.0, 2 * math.pi, 2000)
    boundary = np.array([3.0, -1.0]) + (root @ np.vstack([np.cos(t), np.sin(t)])).T
    assert np.all(polygon.contains(boundary))
    ellipse_area = math.pi * scale * math.sqrt(np.linalg.det(matrix))
    assert 1.0 < polygon.area / ellipse_area < 1.0 + 2.5e-3


def test_ellipse_polygon_of_a_rank_one_covariance_at_the_rounding_edge() -> None:
    # cxy**2 a rounding above cxx * cyy (a covariance computed as an outer product): taken.
    cxx, cyy = 0.1, 0.3
    cxy = math.sqrt(cxx * cyy) * (1.0 + 1e-12)
    assert ellipse_polygon((0.0, 0.0), (cxx, cxy, cyy), 9.0, sides=8).shape == (8, 2)


@pytest.mark.parametrize(
    ("arguments", "match"),
    [
        (((0.0, 0.0), (1.0, 0.0, 1.0), 3.0, 0), r"sides: expected an integer in \[3, 1000000\] \(16 bytes"),
        (((0.0, 0.0), (1.0, 0.0, 1.0), 3.0, 1.5), r"sides: expected an integer in \[3, 1000000\].*got 1.5"),
        (((0.0, 0.0), (1.0, 0.0, 1.0), 3.0, True), r"sides: expected an integer in \[3, 1000000\].*got True"),
        (((0.0, 0.0), (1.0, 0.0, 1.0), 3.0, 10**12), r"sides: .*: 16 MB\), got 1000000000000"),
        (((math.nan, 0.0), (1.0, 0.0, 1.0), 3.0), r"center\[0\]: expected a finite number, got nan"),
        (((0.0, 2e6), (1.0, 0.0, 1.0), 3.0), r"center\[1\]: expected a number in \[-1e\+06, 1e\+06\] m"),
        ((None, (1.0, 0.0, 1.0), 3.0), r"center: expected \(x, y\) in metres, got NoneType"),
        (((0.0,), (1.0, 0.0, 1.0), 3.0), r"center: expected \(x, y\) in metres, got \(0.0,\)"),
        (((0.0, 0.0), (math.nan, 0.0, 1.0), 3.0), r"covariance\[0\]: expected a finite number, got nan"),
        (((0.0, 0.0), (1.0, 0.0), 3.0), r"covariance: expected \(cxx, cxy, cyy\) in m\^2, got \(1.0, 0.0\)"),
        (((0.0, 0.0), (-1.0, 0.0, 1.0), 3.0), r"covariance\[0\]: expected a number in \[0, 1e\+12\] m\^2"),
        (((0.0, 0.0), (1.0, 0.0, 1e300), 3.0), r"covariance\[2\]: expected a number in \[0, 1e\+12\] m\^2"),
        (((0.0, 0.0), (1.0, 5.0, 1.0), 3.0), r"covariance: expected a positive semi-definite \(cxx, cxy"),
        (((0.0, 0.0), (1.0, 0.0, 1.0), -1.0), r"scale: expected a number in \(0, 10000\], got -1.0"),
        (((0.0, 0.0), (1.0, 0.0, 1.0), 1e300), r"scale: expected a number in \(0, 10000\], got 1e\+300"),
    ],
)
def test_ellipse_polygon_refuses_what_is_no_ellipse(arguments: tuple[object, ...], match: str) -> None:
    with pytest.raises(InputError, match=match):
        ellipse_polygon(*arguments)  # type: ignore[arg-type]


def test_chi2_quantile_takes_one_or_two_degrees_of_freedom() -> None:
    with pytest.raises(InputError, match="dof: expected 1 or 2, got True"):
        chi2_quantile(0.99, True)


def _ekf_with_covariance(correlated: bool) -> ExtendedKalmanFilter:
    ekf = ExtendedKalmanFilter(
        Pose(1.0, -2.0, 3.0), position_sd=0.3, heading_sd=0.05, bearing_sd=0.01, range_sd=0.1
    )
    if correlated:  # a long run correlates the lateral position with the heading
        ekf.predict(TurnAndRun(0.3, 15.0), TerrainTable.default()["grass"])
    return ekf


@pytest.mark.parametrize("correlated", [False, True])
def test_ekf_region_is_calibrated_on_gaussian_draws(correlated: bool) -> None:
    """Containment of Gaussian draws: ~p uncorrelated, >= p correlated (Gaussian correlation inequality)."""
    ekf = _ekf_with_covariance(correlated)
    mean, covariance = ekf.mean, ekf.covariance
    rng = np.random.default_rng(7)
    n = 200_000
    draws = rng.multivariate_normal([mean.x, mean.y, mean.heading], covariance, n)
    p = 0.99
    region = ekf.region(p)
    rate = float(np.mean(region.contains(draws[:, 0], draws[:, 1], draws[:, 2])))
    tolerance = 4.0 * math.sqrt(p * (1 - p) / n)
    if correlated:
        assert abs(covariance[0, 2]) > 0.1 * math.sqrt(covariance[0, 0] * covariance[2, 2])
        assert rate >= p - tolerance
    else:
        assert rate == pytest.approx(p, abs=tolerance)
    # Each factor holds sqrt(p) of its marginal.
    q = math.sqrt(p)
    in_position = float(np.mean(region.polygon.contains(draws[:, :2])))
    offset = np.abs(np.remainder(draws[:, 2] - region.heading_center + math.pi, 2 * math.pi) - math.pi)
    in_heading = float(np.mean(offset <= region.heading_halfwidth))
    assert in_position == pytest.approx(q, abs=4.0 * math.sqrt(q * (1 - q) / n))
    assert in_heading == pytest.approx(q, abs=4.0 * math.sqrt(q * (1 - q) / n))


def test_shortest_arc_across_the_seam_and_degenerate() -> None:
    headings = np.array([math.pi - 0.05, -math.pi + 0.05, 0.0])
    center, halfwidth = shortest_arc(headings, np.array([0.45, 0.45, 0.1]), 0.9)
    assert abs(math.remainder(center - math.pi, 2 * math.pi)) < 1e-12
    assert halfwidth == pytest.approx(0.05)
    assert shortest_arc(np.full(5, -1.0), np.full(5, 0.2), 0.99) == (-1.0, 0.0)
    assert shortest_arc(np.array([2.0]), np.array([1.0]), 0.5) == (2.0, 0.0)


def test_shortest_arc_of_uniform_circle() -> None:
    headings = np.linspace(-math.pi, math.pi, 360, endpoint=False)
    _, halfwidth = shortest_arc(headings, np.full(360, 1 / 360), 0.5)
    assert halfwidth == pytest.approx(math.pi / 2, abs=2 * math.pi / 360)


def _brute_force_arc(headings: NDArray[np.float64], weights: NDArray[np.float64], p: float) -> float:
    best = 2 * math.pi
    for start in headings:
        offsets = np.remainder(headings - start, 2 * math.pi)
        order = np.argsort(offsets)
        held = np.cumsum(weights[order])
        k = int(np.searchsorted(held, p * (1 - 1e-12)))
        best = min(best, float(offsets[order][min(k, len(held) - 1)]))
    return best


@given(
    st.lists(st.floats(-math.pi, math.pi), min_size=1, max_size=12),
    st.integers(0, 2**32 - 1),
    st.floats(0.05, 0.999),
)
def test_shortest_arc_holds_the_weight_and_is_shortest(headings: list[float], seed: int, p: float) -> None:
    h = np.array(headings)
    weights = np.random.default_rng(seed).uniform(0.1, 1.0, len(h))
    weights /= weights.sum()
    center, halfwidth = shortest_arc(h, weights, p)
    offset = np.abs(np.remainder(h - center + math.pi, 2 * math.pi) - math.pi)
    assert float(weights[offset <= halfwidth + 1e-9].sum()) >= p * (1 - 1e-9)
    assert 2 * halfwidth == pytest.approx(_brute_force_arc(h, weights, p), abs=1e-9)


@given(st.integers(1, 40), st.integers(0, 2**32 - 1), st.floats(0.05, 0.999), st.booleans())
def test_mahalanobis_core_holds_the_weight(n: int, seed: int, p: float, collinear: bool) -> None:
    rng = np.random.default_rng(seed)
    points = rng.normal(size=(n, 2)) * [3.0, 0.5]
    if collinear:
        points[:, 1] = 2.0 * points[:, 0]
    weights = rng.uniform(0.0, 1.0, n) + 1e-3
    weights /= weights.sum()
    core = mahalanobis_core(points, weights, p)
    hull = ConvexPolygon.from_points(core)
    assert float(weights[hull.contains(points, tolerance=1e-9)].sum()) >= p * (1 - 1e-9)
    # The fewest: without its last (farthest) point the core holds less than p.
    rows = [int(np.flatnonzero(np.all(points == row, axis=1))[0]) for row in core]
    assert len(set(rows)) == len(rows)
    assert float(weights[rows[:-1]].sum()) < p


@given(st.integers(1, 300), st.integers(0, 2**32 - 1), st.sampled_from(["cloud", "collinear", "repeated"]))
def test_prefiltered_hull_is_the_hull(n: int, seed: int, kind: str) -> None:
    rng = np.random.default_rng(seed)
    points = rng.normal(size=(n, 2)) * [5.0, 0.1] + [100.0, -40.0]
    if kind == "collinear":
        points[:, 1] = -0.5 * points[:, 0]
    elif kind == "repeated":
        points = points[rng.integers(0, min(n, 3), n)]
    hull = convex_hull_polygon(points)
    reference = ConvexPolygon.from_points(points)
    assert hull.vertex_count == reference.vertex_count
    assert hull.area == pytest.approx(reference.area, rel=1e-12, abs=1e-12)
    assert np.all(hull.contains(points, tolerance=1e-9))


@pytest.mark.parametrize("correlated", [False, True])
def test_gaussian_region_is_the_ekf_region(correlated: bool) -> None:
    ekf = _ekf_with_covariance(correlated)
    mean = ekf.mean
    for p in (0.5, 0.99):
        ours = ConfidenceRegion.gaussian([mean.x, mean.y, mean.heading], ekf.covariance, p)
        theirs = ekf.region(p)
        assert ours.polygon.vertices.tobytes() == theirs.polygon.vertices.tobytes()
        assert (ours.heading_center, ours.heading_halfwidth, ours.probability) == (
            theirs.heading_center,
            theirs.heading_halfwidth,
            theirs.probability,
        )


def test_gaussian_region_edge_cases() -> None:
    point = ConfidenceRegion.gaussian((2.0, -1.0, 4.0), np.zeros((3, 3)))
    assert point.area == 0.0
    assert point.heading_halfwidth == 0.0
    assert point.heading_center == pytest.approx(4.0 - 2 * math.pi)  # wrapped
    assert point.contains(2.0, -1.0, 4.0) is True
    assert point.contains(2.0, -0.99, 4.0) is False
    # Known along x, unknown along y: a segment; a huge heading variance: the full circle.
    segment = ConfidenceRegion.gaussian((0.0, 0.0, 0.0), np.diag([0.0, 1.0, 100.0]))
    assert segment.area == 0.0
    assert segment.contains(0.0, 3.0, math.pi) is True
    assert segment.contains(0.1, 0.0, 0.0) is False
    assert segment.heading_width == 2 * math.pi


@pytest.mark.parametrize(
    ("mean", "covariance", "probability", "match"),
    [
        ((0, 0), np.eye(3), 0.99, r"mean: expected \(x, y, heading\), 3 numbers, got shape \(2,\)"),
        ((0, 0, 0), np.eye(2), 0.99, r"covariance: expected a 3 x 3 array, got shape \(2, 2\)"),
        ((0, 0, math.nan), np.eye(3), 0.99, "mean: expected finite numbers"),
        ((0, 0, 0), np.full((3, 3), math.inf), 0.99, "covariance: expected finite numbers"),
        ((0, 0, 0), [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]], 0.99, "covariance: expected a symmetric matrix"),
        ((0, 0, 0), np.diag([1.0, -1.0, 1.0]), 0.99, "covariance: expected non-negative variances"),
        ((0, 0, 0), np.eye(3), 1.0, "probability"),
        ("here", np.eye(3), 0.99, "mean: expected numbers, got 'here'"),
    ],
)
def test_gaussian_region_rejects_bad_input(
    mean: object, covariance: object, probability: float, match: str
) -> None:
    with pytest.raises(InputError, match=match):
        ConfidenceRegion.gaussian(mean, covariance, probability)  # type: ignore[arg-type]
