"""The lens distortion's range over a convex region: every value inside the bounds."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.typing import NDArray

from aura_ums.camera import Camera, CameraIntrinsics, CameraMount, distort, fold_radius
from aura_ums.expecter import Expecter
from aura_ums.expecter._distortion import distorted_range
from aura_ums.geometry import ConvexPolygon, HeadingWedge
from aura_ums.uncertainty import PointLandmark, SpatialUncertaintyMap

Array = NDArray[np.float64]
Coefficients = tuple[float, float, float, float, float]

#: A strong lens whose radial image r (1 + k1 r^2 + k2 r^4 + k3 r^6) peaks at r = 0.818.
FOLDING: Coefficients = (2.7752199057918254, -2.5335874851127196, 0.0, 0.0, -0.4291520079374034)


def sampled(points: Array, coefficients: Coefficients, rng: np.random.Generator, count: int) -> Array:
    """Distorted (x_d, y_d) of random convex combinations of the points, and the points themselves.

    Only those the camera images: within the lens's fold (beyond it, no ray reaches a pixel).
    """
    weights = rng.dirichlet(np.full(len(points), 0.3), count)
    inside = np.vstack([points, weights @ points])
    inside = inside[np.hypot(inside[:, 0], inside[:, 1]) <= fold_radius(coefficients)]
    x, y = distort(inside[:, 0], inside[:, 1], coefficients)
    return np.column_stack([x, y])


def bounds(points: Array, coefficients: Coefficients, tolerance: float) -> tuple[Array, Array]:
    """:func:`distorted_range`, for a region the camera images some of."""
    found = distorted_range(points, coefficients, tolerance)
    assert found is not None
    return found


def test_a_critical_point_on_a_cells_edge_is_not_missed(rng: np.random.Generator) -> None:
    """The radial peak lies on y = 0, an edge of the cells the test for critical points splits.

    There d x_d / d y is <= 0 on one cell and >= 0 on the other, both reaching 0 at y = 0,
    where d x_d / d x vanishes too. Counting a sign that reaches 0 as constant proved "no
    critical point", the maximum was taken on the boundary only, 1.2670 against 1.3039
    attained, and the Expecter's window missed a true camera's pixel.
    """
    square = np.array([[0.65, -0.32], [1.0, -0.32], [1.0, 0.32], [0.65, 0.32]])
    lower, upper = bounds(square, FOLDING, 1e-5)
    values = sampled(square, FOLDING, rng, 200_000)
    assert values[:, 0].max() > 1.3  # the peak is inside
    assert np.all(values >= lower - 1e-12)
    assert np.all(values <= upper + 1e-12)


coefficient = st.floats(-3.0, 3.0)


@settings(max_examples=150, deadline=None)
@given(
    centre=st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)),
    half=st.tuples(st.floats(0.01, 0.5), st.floats(0.01, 0.5)),
    k=st.tuples(coefficient, coefficient, st.floats(-0.05, 0.05), st.floats(-0.05, 0.05), coefficient),
    seed=st.integers(0, 2**32 - 1),
)
def test_every_distorted_point_of_a_region_lies_within_the_range(
    centre: tuple[float, float], half: tuple[float, float], k: Coefficients, seed: int
) -> None:
    (cx, cy), (hx, hy) = centre, half
    box = np.array([[cx - hx, cy - hy], [cx + hx, cy - hy], [cx + hx, cy + hy], [cx - hx, cy + hy]])
    found = distorted_range(box, k, 1e-6)
    if found is None:  # every point beyond the fold: none imaged
        assert not len(sampled(box, k, np.random.default_rng(seed), 4000))
        return
    lower, upper = found
    values = sampled(box, k, np.random.default_rng(seed), 4000)
    slack = 1e-9 * (1.0 + np.abs(values))
    assert np.all(values >= lower - slack)
    assert np.all(values <= upper + slack)


def test_the_range_is_taken_over_the_rays_within_the_fold(rng: np.random.Generator) -> None:
    """Beyond the fold (r = 0.818 here) the polynomial falls back: those pixels are no ray's.

    A region from r = 0.5 to 1.6 reaches x_d = -1.2 beyond the fold, where no ray is imaged;
    within it x_d stays above 0.5. The bounds hold every imaged point and leave the rest out.
    A region wholly beyond the fold is not imaged at all.
    """
    region = np.array([[0.5, -0.1], [1.6, -0.1], [1.6, 0.1], [0.5, 0.1]])
    x, _ = distort(region[:, 0], region[:, 1], FOLDING)
    assert x.min() < -1.0  # the corners beyond the fold
    lower, upper = bounds(region, FOLDING, 1e-6)
    values = sampled(region, FOLDING, rng, 100_000)
    assert np.all(values >= lower - 1e-12)
    assert np.all(values <= upper + 1e-12)
    assert lower[0] > 0.4  # not the fold-back's -1.2
    beyond = np.array([[1.0, -0.1], [1.6, -0.1], [1.6, 0.1], [1.0, 0.1]])
    assert distorted_range(beyond, FOLDING, 1e-6) is None
    assert distorted_range(np.array([[0.9, 0.0], [1.2, 0.0]]), FOLDING, 1e-6) is None  # a segment
    assert distorted_range(np.array([[0.5, 0.0], [1.2, 0.0]]), FOLDING, 1e-6) is not None


def test_a_long_lens_window_holds_a_landmark_partly_behind_the_camera() -> None:
    # helper-62: with the wedge turning the landmark behind the camera, the normalized points
    # hold cut-plane crossings some 1e12 across, and the hull's merge of nearly straight
    # vertices (relative to that extent) dropped the extreme ones: the window missed true
    # projections by up to 56 px (fx 50000), 22 px (fx 20000) and 0.1 px (fx 1000).
    def largest_miss(fx: float, distance: float, radius: float, rise: float) -> float:
        lens = CameraIntrinsics(fx, fx, 320.0, 240.0, 640, 480, distortion=(-0.05, 0.0, 0.0, 0.0, 0.0))
        camera = Camera(lens, CameraMount(height=1.0))
        the_map = SpatialUncertaintyMap(ConvexPolygon([(0.0, 0.0)]), (0.0, 0.0), HeadingWedge(0.0, 0.0, 1.7))
        landmark = PointLandmark("corner", distance, 0.0, 1.0 + distance * rise, position_uncertainty=radius)
        window = Expecter(camera).bounds(the_map, landmark)
        assert window is not None
        headings = np.linspace(0.0, 1.7, 341)
        around = np.linspace(-math.pi, math.pi, 96, endpoint=False)
        points = np.column_stack(
            [distance + radius * np.cos(around), radius * np.sin(around), np.full(len(around), landmark.z)]
        )
        poses = np.column_stack([np.zeros(len(headings)), np.zeros(len(headings)), headings])
        pixels = camera.project(poses, points).reshape(-1, 2)
        pixels = pixels[np.isfinite(pixels).all(axis=1)]
        assert len(pixels)
        return float(
            max(
                window.u_min - pixels[:, 0].min(),
                pixels[:, 0].max() - window.u_max,
                window.v_min - pixels[:, 1].min(),
                pixels[:, 1].max() - window.v_max,
                0.0,
            )
        )

    assert largest_miss(50000.0, 1000.0, 5.0, 0.002) <= 1e-6
    assert largest_miss(20000.0, 1000.0, 5.0, 0.01) <= 1e-6
    assert largest_miss(1000.0, 1000.0, 0.5, 0.01) <= 1e-6
