from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest
import shapely
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from numpy.typing import NDArray

from aura_ums import ConvexPolygon, InputError
from aura_ums.geometry import (
    clip_halfplane,
    convex_hull,
    minkowski_sum,
    outer_annular_sector,
    outer_arc,
    outer_disk,
    polygon_area,
    regular_polygon,
    simplify_outer,
)
from aura_ums.geometry._convex import ARC_STEP, FULL_DISK_SIDES, convexity_defect, remove_collinear
from aura_ums.uncertainty import Pose, SpatialUncertaintyMap

SQUARE = [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0)]

point_clouds = arrays(
    np.float64,
    st.tuples(st.integers(1, 30), st.just(2)),
    elements=st.floats(min_value=-100, max_value=100, allow_nan=False, width=32),
)


def random_polygon(rng: np.random.Generator, count: int = 12, scale: float = 5.0) -> NDArray[np.float64]:
    return convex_hull(rng.normal(0.0, scale, (count, 2)) * rng.uniform(0.1, 1.0, 2))


def assert_convex_ccw(vertices: NDArray[np.float64]) -> None:
    assert convexity_defect(vertices) is None


# --- construction and validation ---------------------------------------------------------


def test_square_basics() -> None:
    square = ConvexPolygon(SQUARE)
    assert square.area == 4.0
    assert square.vertex_count == 4
    assert square.bounds == (0.0, 0.0, 2.0, 2.0)
    assert np.allclose(square.centroid, [1.0, 1.0])
    assert not square.vertices.flags.writeable


def test_closing_vertex_of_a_geojson_ring_is_dropped() -> None:
    assert ConvexPolygon([*SQUARE, SQUARE[0]]).vertex_count == 4


def test_degenerate_point_and_segment_are_valid() -> None:
    point = ConvexPolygon([(1.0, 2.0)])
    assert point.area == 0.0
    assert point.contains([(1.0, 2.0), (1.0, 2.1)]).tolist() == [True, False]
    segment = ConvexPolygon([(0.0, 0.0), (2.0, 0.0)])
    assert segment.contains([(1.0, 0.0), (3.0, 0.0), (1.0, 0.1)]).tolist() == [True, False, False]
    assert np.allclose(segment.centroid, [1.0, 0.0])


def test_collinear_vertices_are_removed() -> None:
    polygon = ConvexPolygon([(0, 0), (1, 0), (2, 0), (2, 2), (0, 2)])
    assert polygon.vertex_count == 4


@pytest.mark.parametrize(
    ("vertices", "message"),
    [
        (list(reversed(SQUARE)), r"expected a convex counter-clockwise polygon, got clockwise order"),
        ([(0, 0), (2, 0), (1, 0.5), (2, 2), (0, 2)], r"got a reflex \(non-convex\) corner at vertex 2"),
        ([(0, 0), (float("nan"), 0), (1, 1)], r"expected finite coordinates, got \[nan, 0.0\] at row 1"),
        ([], r"expected at least 1 points, got 0"),
        ([(0, 0, 0)], r"expected an \(n, 2\) array, got shape \(1, 3\)"),
        ("abc", r"expected an \(n, 2\) array of numbers"),
    ],
)
def test_bad_polygons_are_refused(vertices: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        ConvexPolygon(vertices)  # type: ignore[arg-type]


def test_a_pentagram_is_refused() -> None:
    angles = np.arange(5) * 4 * math.pi / 5
    with pytest.raises(InputError, match=r"winds around more than once"):
        ConvexPolygon(np.column_stack([np.cos(angles), np.sin(angles)]))


def test_from_points_takes_the_hull_of_anything() -> None:
    rng = np.random.default_rng(3)
    points = rng.normal(size=(500, 2))
    polygon = ConvexPolygon.from_points(points)
    assert np.all(polygon.contains(points))
    assert math.isclose(polygon.area, shapely.MultiPoint(points).convex_hull.area, rel_tol=1e-12)


@given(point_clouds)
def test_hull_is_convex_ccw_and_contains_its_points(points: NDArray[np.float64]) -> None:
    hull = convex_hull(points)
    assert_convex_ccw(hull)
    assert np.all(ConvexPolygon._trusted(hull).contains(points, tolerance=1e-6))
    expected = shapely.MultiPoint(points).convex_hull.area
    assert math.isclose(polygon_area(hull), expected, rel_tol=1e-9, abs_tol=1e-6)


def test_far_from_the_origin_a_corner_split_by_rounding_stays_in_the_hull() -> None:
    # A kernel's polygon 3.5e4 m from the origin, its corner kept twice a few rounding steps
    # apart: both copies read as straight and went, and the hull left the corner 3 cm out.
    points = np.array(
        [
            [21026.33980523356, -34590.833031578346],
            [21027.369329209858, -34591.1959185171],
            [21028.275193785597, -34590.853624139316],
            [21028.479487750963, -34590.51653318358],
            [21028.49298117922, -34590.48865308879],
            [21028.492981179203, -34590.48865308876],
            [21026.339805233416, -34590.83303157805],
        ]
    )
    hull = convex_hull(points)
    assert_convex_ccw(hull)
    assert np.all(ConvexPolygon._trusted(hull).contains(points, tolerance=1e-9))
    assert len(hull) == 5  # each corner once


def test_hull_of_collinear_points_is_a_segment() -> None:
    assert convex_hull(np.array([[0.0, 0.0], [1.0, 1.0], [3.0, 3.0], [2.0, 2.0]])).shape == (2, 2)
    assert convex_hull(np.array([[5.0, 5.0]] * 4)).shape == (1, 2)
    many = np.column_stack([np.linspace(0, 1, 500), np.linspace(0, 2, 500)])
    assert convex_hull(many).shape == (2, 2)  # Qhull fails on these; the exact chain does not


@pytest.mark.parametrize(("radius", "count"), [(1e-10, 432), (1e-11, 150), (3e-12, 100)])
def test_hull_of_a_speck_far_from_the_origin_keeps_its_extent(radius: float, count: int) -> None:
    # A joint reduction's 432 sector results 2.7e-9 m across at (16, 1.5): every corner of
    # their hull was straight to within rounding, all went, and the hull was empty (an
    # IndexError from the manager's update, building a map on it).
    turn = np.linspace(0.0, 2.0 * np.pi, count, endpoint=False)
    speck = np.column_stack([16.0 + radius * np.cos(turn), 1.5 + radius * np.sin(turn)])
    hull = convex_hull(speck)
    assert len(hull) == 2
    assert np.hypot(*(hull[1] - hull[0])) == pytest.approx(2.0 * radius, rel=1e-3)
    assert ConvexPolygon(speck).vertices.shape == (2, 2)


# The slice vertices of a sliced map whose summary polygon left the truth 1.26e-6 m outside:
# two near-duplicate pairs (a picometre apart) on a thin sliver's ends, each corner straight
# between its own neighbours; removed at once, they cut off a real 1.9-micrometre bump.
_SLIVER = np.array(
    [
        [-1.348961310048351, 1.981656260958965],
        [-1.3489595212881924, 1.981654461482052],
        [-1.0231352548689467, 2.0212234963151907],
        [-1.0231352548650159, 2.021223496315668],
        [-1.023135254867362, 2.0212234963153834],
        [-1.042989624013734, 2.018814341404329],
        [-1.0429896240154017, 2.0188143414041266],
        [-1.331340663694983, 1.9837961628668288],
    ]
)


def test_a_long_run_of_straight_vertices_goes_in_few_passes() -> None:
    # One straight vertex of a run a pass took a pass per vertex: a saved map of a million
    # vertices on a line did not load in a minute. Every other one a pass: a few passes.
    edge = np.column_stack([np.linspace(0.0, 1.0, 200_001), np.zeros(200_001)])
    triangle = remove_collinear(np.vstack([edge, [[0.5, 1.0]]]))
    assert triangle.tolist() == [[0.0, 0.0], [1.0, 0.0], [0.5, 1.0]]


def test_hull_keeps_a_corner_between_two_straight_ones() -> None:
    hull = convex_hull(_SLIVER)
    outline = shapely.Polygon(hull)
    assert max(outline.distance(shapely.Point(*p)) for p in _SLIVER) < 1e-12
    assert np.array_equal(ConvexPolygon.from_points(_SLIVER).vertices, hull)


# --- containment --------------------------------------------------------------------------


def test_contains_matches_shapely_away_from_the_boundary() -> None:
    rng = np.random.default_rng(5)
    for _ in range(20):
        polygon = ConvexPolygon._trusted(random_polygon(rng))
        points = rng.normal(0.0, 6.0, (400, 2))
        reference = shapely.contains_xy(polygon.to_shapely(), points[:, 0], points[:, 1])
        distance = shapely.distance(shapely.Polygon(polygon.vertices).exterior, shapely.points(points))
        clear = distance > 1e-6
        assert np.array_equal(polygon.contains(points)[clear], reference[clear])


def test_boundary_and_vertices_count_as_inside() -> None:
    square = ConvexPolygon(SQUARE)
    assert np.all(square.contains([(0, 0), (1, 0), (2, 2), (0, 1.5)]))
    assert not square.contains([(2.0 + 1e-6, 1.0)])[0]


def test_distance() -> None:
    square = ConvexPolygon(SQUARE)
    assert square.distance([(1, 1), (3, 1), (3, 3)]).tolist() == pytest.approx([0.0, 1.0, math.sqrt(2)])


# --- Minkowski sum ---------------------------------------------------------------------------


@given(point_clouds, point_clouds)
def test_minkowski_sum_equals_hull_of_pairwise_sums(a: NDArray[np.float64], b: NDArray[np.float64]) -> None:
    pa, pb = convex_hull(a), convex_hull(b)
    result = minkowski_sum(pa, pb)
    assert_convex_ccw(result)
    brute = convex_hull((pa[:, None, :] + pb[None, :, :]).reshape(-1, 2))
    assert math.isclose(polygon_area(result), polygon_area(brute), rel_tol=1e-9, abs_tol=1e-6)
    assert np.all(ConvexPolygon._trusted(result).contains(brute, tolerance=1e-6))


def test_minkowski_sum_with_points_and_segments() -> None:
    square = np.array(SQUARE, dtype=float)
    shifted = minkowski_sum(square, np.array([[1.0, -1.0]]))
    assert polygon_area(shifted) == 4.0
    assert np.allclose(shifted.min(axis=0), [1.0, -1.0])
    capsule = minkowski_sum(np.array([[0.0, 0.0], [3.0, 0.0]]), np.array([[0.0, 0.0], [0.0, 1.0]]))
    assert polygon_area(capsule) == pytest.approx(3.0)
    assert minkowski_sum(np.array([[1.0, 1.0]]), np.array([[2.0, 3.0]])).tolist() == [[3.0, 4.0]]


# --- half-plane clipping -----------------------------------------------------------------------


def test_clip_matches_shapely() -> None:
    rng = np.random.default_rng(11)
    for _ in range(50):
        vertices = random_polygon(rng)
        angle = rng.uniform(-math.pi, math.pi)
        normal = np.array([math.cos(angle), math.sin(angle)])
        offset = rng.normal(0.0, 3.0)
        clipped = clip_halfplane(vertices, normal, offset)
        far = 1e4
        tangent = np.array([-normal[1], normal[0]])
        base = normal * offset
        halfplane = shapely.Polygon(
            [
                base - far * tangent,
                base + far * tangent,
                base + far * tangent - far * normal,
                base - far * tangent - far * normal,
            ]
        )
        expected = shapely.Polygon(vertices).intersection(halfplane).area
        if len(clipped) == 0:
            assert expected < 1e-9
        else:
            assert_convex_ccw(clipped)
            assert math.isclose(polygon_area(clipped), expected, rel_tol=1e-9, abs_tol=1e-9)


def test_clip_to_nothing_and_to_everything() -> None:
    square = np.array(SQUARE, dtype=float)
    assert clip_halfplane(square, np.array([0.0, 1.0]), -1.0).shape == (0, 2)
    assert clip_halfplane(square, np.array([0.0, 1.0]), 5.0) is square
    assert ConvexPolygon(SQUARE).clipped((1, 0), -3) is None


def test_clip_a_segment_and_a_point() -> None:
    segment = np.array([[0.0, 0.0], [2.0, 0.0]])
    assert clip_halfplane(segment, np.array([1.0, 0.0]), 1.0).tolist() == [[0.0, 0.0], [1.0, 0.0]]
    assert clip_halfplane(np.array([[0.0, 0.0]]), np.array([1.0, 0.0]), -1.0).shape == (0, 2)


def test_clipped_refuses_a_zero_normal() -> None:
    with pytest.raises(InputError, match=r"normal: expected a non-zero vector"):
        ConvexPolygon(SQUARE).clipped((0, 0), 1.0)


def test_intersection_of_polygons() -> None:
    a = ConvexPolygon(SQUARE)
    b = a.translated(1.0, 1.0)
    both = a.intersection(b)
    assert both is not None
    assert both.area == pytest.approx(1.0)
    assert a.intersection(a.translated(5.0, 0.0)) is None
    touching_segment = a.intersection(ConvexPolygon([(1.0, -1.0), (1.0, 3.0)]))
    assert touching_segment is not None
    assert touching_segment.area == 0.0


# --- outer polygons of arcs -------------------------------------------------------------------------


@given(
    st.floats(min_value=0.01, max_value=100.0),
    st.floats(min_value=-10.0, max_value=10.0),
    st.floats(min_value=1e-4, max_value=2 * math.pi - 1e-3),
)
def test_outer_arc_region_contains_the_arc(radius: float, start: float, width: float) -> None:
    polyline = outer_arc(radius, start, start + width)
    region = ConvexPolygon._trusted(convex_hull(np.vstack([polyline, np.zeros((1, 2))])))
    t = np.linspace(start, start + width, 2000)
    arc = radius * np.column_stack([np.cos(t), np.sin(t)])
    if width <= math.pi:
        assert np.all(region.contains(arc, tolerance=1e-9 * radius + 1e-12))
    # Every arc point lies within the polyline's reach of the origin.
    assert np.max(np.hypot(*polyline.T)) <= radius / math.cos(math.pi / 32) * (1 + 1e-12)


# Radii are either exactly zero or physically sized: subnormal radii underflow in products.
radii = st.one_of(st.just(0.0), st.floats(min_value=1e-6, max_value=50.0))


@given(
    radii,
    radii,
    st.floats(min_value=-10.0, max_value=10.0),
    st.one_of(st.just(0.0), st.floats(min_value=1e-9, max_value=7.0)),
)
def test_outer_annular_sector_contains_the_sector(a: float, b: float, start: float, width: float) -> None:
    inner, outer = min(a, b), max(a, b)
    vertices = outer_annular_sector(inner, outer, start, start + width)
    assert_convex_ccw(vertices)
    rng = np.random.default_rng(0)
    radius = rng.uniform(inner, outer, 3000)
    radius[:4] = [inner, outer, inner, outer]
    angle = rng.uniform(start, start + width, 3000)
    angle[:4] = [start, start, start + width, start + width]
    points = np.column_stack([radius * np.cos(angle), radius * np.sin(angle)])
    assert np.all(ConvexPolygon._trusted(vertices).contains(points, tolerance=1e-9 * max(outer, 1.0)))


def test_outer_disk_contains_the_disk_and_is_tight() -> None:
    disk = ConvexPolygon.disk((1.0, 2.0), 3.0, sides=16)
    t = np.linspace(0, 2 * math.pi, 1000)
    assert np.all(disk.contains(np.column_stack([1 + 3 * np.cos(t), 2 + 3 * np.sin(t)])))
    assert disk.area / (math.pi * 9) < 1.03
    assert outer_disk(np.zeros(2), 0.0).shape == (1, 2)
    with pytest.raises(InputError, match=r"radius: expected a number in \[0, 2e\+06\] m, got -1\.0"):
        ConvexPolygon.disk((0, 0), -1.0)


@pytest.mark.parametrize(
    ("build", "message"),
    [
        (
            lambda: ConvexPolygon([(0, 0), (1e300, 0), (0, 1)]),
            r"ConvexPolygon\.vertices: expected coordinates",
        ),
        (lambda: ConvexPolygon.from_points([(0, 0), (0, -2e6)]), r"points: expected coordinates .* at row 1"),
        (lambda: ConvexPolygon.point(0.0, 1e300), r"y: expected a number in \[-1e\+06, 1e\+06\] m"),
        (lambda: ConvexPolygon.disk((1e7, 0), 1.0), r"center: expected coordinates"),
        (lambda: ConvexPolygon.disk((0, 0), 1e300), r"radius: expected a number in \[0, 2e\+06\] m"),
    ],
)
def test_polygons_beyond_the_world_frame_are_refused(
    build: Callable[[], ConvexPolygon], message: str
) -> None:
    # 1e300 m was taken and its area overflowed (a RuntimeWarning, inf)
    with pytest.raises(InputError, match=message):
        build()
    assert ConvexPolygon([(-1e6, -1e6), (1e6, -1e6), (1e6, 1e6)]).area == 2e12


# --- outer simplification ---------------------------------------------------------------------------


@given(st.integers(3, 40), st.integers(0, 10_000))
def test_simplify_outer_contains_original_and_respects_the_cap(cap: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    vertices = random_polygon(rng, count=int(rng.integers(3, 200)))
    simplified = simplify_outer(vertices, cap)
    # Every cap is met: by merging edges, or else by the coarser support polygon.
    assert len(simplified) <= cap
    assert_convex_ccw(simplified)
    assert np.all(ConvexPolygon._trusted(simplified).contains(vertices, tolerance=1e-7))


def test_simplify_outer_adds_little_area_to_a_smooth_shape() -> None:
    circle = regular_polygon((0.0, 0.0), 10.0, 256)
    simplified = circle.simplified_outer(32)
    assert simplified.vertex_count <= 32
    assert simplified.area / circle.area < 1.02
    with pytest.raises(InputError, match=r"max_vertices: expected an integer in \[3, 2\*\*63 - 1\], got 2"):
        circle.simplified_outer(2)


def test_simplify_leaves_a_triangle_alone() -> None:
    triangle = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    assert np.array_equal(simplify_outer(triangle, 3), triangle)


# --- sampling and interop ----------------------------------------------------------------------------


def test_samples_are_inside_and_uniform() -> None:
    rng = np.random.default_rng(1)
    square = ConvexPolygon(SQUARE)
    samples = square.sample(40_000, rng)
    assert np.all(square.contains(samples))
    left = np.mean(samples[:, 0] < 1.0)
    assert abs(left - 0.5) < 0.01
    assert ConvexPolygon([(1.0, 1.0)]).sample(3, rng).tolist() == [[1.0, 1.0]] * 3
    on_segment = ConvexPolygon([(0.0, 0.0), (4.0, 0.0)]).sample(100, rng)
    assert np.all(on_segment[:, 1] == 0.0)
    assert np.all((on_segment[:, 0] >= 0.0) & (on_segment[:, 0] <= 4.0))


def test_shapely_round_trip_and_equality() -> None:
    square = ConvexPolygon(SQUARE)
    assert ConvexPolygon.from_shapely(square.to_shapely()).area == 4.0
    assert ConvexPolygon([(1.0, 1.0)]).to_shapely().geom_type == "Point"
    assert ConvexPolygon([(0, 0), (1, 1)]).to_shapely().geom_type == "LineString"
    assert square == ConvexPolygon(SQUARE)
    assert square != square.translated(0.1, 0.0)
    with pytest.raises(InputError, match=r"expected a non-empty shapely geometry"):
        ConvexPolygon.from_shapely(shapely.Polygon())


def test_a_sliver_whose_triangles_round_below_zero_is_still_sampled() -> None:
    # A disk of radius 2.2e-16 m a metre from the origin: its fan triangles round to signed
    # areas of both signs (found by hypothesis through union_of_maps).
    sliver = SpatialUncertaintyMap.from_pose(Pose(0.0, 1.0, 0.0), 2.220446049250313e-16, 0.0).polygon
    points = sliver.sample(50, np.random.default_rng(0))
    assert points.shape == (50, 2)
    assert np.all(sliver.contains(points, tolerance=1e-9))


def test_a_repeated_vertex_constrains_nothing_in_the_point_test() -> None:
    # The library's own kernels may repeat a vertex (60 repeated sightings did): its edge
    # of no length gave 0 / 0 = NaN, a RuntimeWarning, and every point "outside".
    from aura_ums.geometry._convex import points_in_convex

    square = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]])
    assert points_in_convex(square, np.array([[1.0, 1.0], [3.0, 1.0]]), 0.0).tolist() == [True, False]
    points = np.random.default_rng(5).uniform(-1.0, 3.0, (2000, 2))  # past the dense limit
    expected = np.all((points >= 0.0) & (points <= 2.0), axis=1)
    assert np.array_equal(points_in_convex(square, points, 0.0), expected)
    assert expected.any()
    assert not expected.all()


# Bad arguments to ConvexPolygon's methods and the polygon builders, refused by name.

UNIT = ConvexPolygon([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)])


@pytest.mark.parametrize(
    ("dx", "dy", "message"),
    [
        (math.nan, 0.0, r"dx: expected a finite number, got nan"),
        (0.0, math.inf, r"dy: expected a finite number, got inf"),
        (None, 0.0, r"dx: expected a finite number, got None"),
        ("1.0", 0.0, r"dx: expected a finite number, got '1\.0'"),
        (1e300, 0.0, r"dx: expected a shift keeping the vertices in \[-1e\+06, 1e\+06\] m, got 1e\+300"),
        (
            0.0,
            -1e6 - 0.5,
            r"dy: expected a shift keeping the vertices in \[-1e\+06, 1e\+06\] m, got -1000000\.5",
        ),
    ],
)
def test_translated_refuses_a_bad_shift(dx: object, dy: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        UNIT.translated(dx, dy)  # type: ignore[arg-type]


def test_translated_moves_to_the_edge_of_the_range_bit_for_bit() -> None:
    moved = UNIT.translated(1e6 - 1.0, -1e6)
    assert moved.vertices.tolist() == (UNIT.vertices + np.array([1e6 - 1.0, -1e6])).tolist()
    assert (
        UNIT.translated(np.float64(0.25), 1).vertices.tolist()
        == (UNIT.vertices + np.array([0.25, 1.0])).tolist()
    )


@pytest.mark.parametrize(
    ("tolerance", "message"),
    [
        (None, r"tolerance: expected a finite number, got None"),
        (math.nan, r"tolerance: expected a finite number, got nan"),
        (math.inf, r"tolerance: expected a finite number, got inf"),
        (-1e-9, r"tolerance: expected a non-negative number, got -1e-09"),
    ],
)
def test_contains_refuses_a_bad_tolerance(tolerance: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        UNIT.contains([(0.5, 0.5)], tolerance=tolerance)  # type: ignore[arg-type]


def test_contains_takes_a_zero_tolerance() -> None:
    assert UNIT.contains([(1.0, 0.5), (1.0 + 1e-12, 0.5)], tolerance=0).tolist() == [True, False]


@pytest.mark.parametrize(
    ("count", "message"),
    [
        (None, r"count: expected an integer >= 0, got None"),
        (-1, r"count: expected an integer >= 0, got -1"),
        (1.5, r"count: expected an integer >= 0, got 1\.5"),
        (math.nan, r"count: expected an integer >= 0, got nan"),
        (True, r"count: expected an integer >= 0, got True"),
        (
            10**12,
            r"count: expected at most 10,000,000 points a call \(about 10 s and 0\.7 GB.*got 1000000000000",
        ),
    ],
)
def test_sample_refuses_a_bad_count(count: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        UNIT.sample(count, np.random.default_rng(0))  # type: ignore[arg-type]


def test_sample_refuses_a_bad_rng_and_takes_zero_and_numpy_counts() -> None:
    with pytest.raises(InputError, match=r"rng: expected a numpy\.random\.Generator, got NoneType"):
        UNIT.sample(3, None)  # type: ignore[arg-type]
    assert UNIT.sample(0, np.random.default_rng(0)).shape == (0, 2)
    drawn = UNIT.sample(np.int64(5), np.random.default_rng(1))  # type: ignore[arg-type]
    assert drawn.tolist() == UNIT.sample(5, np.random.default_rng(1)).tolist()


@pytest.mark.parametrize("cap", [None, math.nan, 3.0, True, 2])
def test_simplified_outer_refuses_a_bad_cap(cap: object) -> None:
    with pytest.raises(InputError, match=r"max_vertices: expected an integer in \[3, 2\*\*63 - 1\], got"):
        UNIT.simplified_outer(cap)  # type: ignore[arg-type]


@pytest.mark.parametrize("other", [None, "x", UNIT.vertices])
def test_intersection_and_minkowski_sum_refuse_what_is_no_polygon(other: object) -> None:
    with pytest.raises(InputError, match=r"other: expected a ConvexPolygon, got (NoneType|str|ndarray)"):
        UNIT.intersection(other)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"other: expected a ConvexPolygon, got (NoneType|str|ndarray)"):
        UNIT.minkowski_sum(other)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("sides", "message"),
    [
        (None, r"sides: expected an integer >= 3, got None"),
        (math.nan, r"sides: expected an integer >= 3, got nan"),
        (3.0, r"sides: expected an integer >= 3, got 3\.0"),
        ("3", r"sides: expected an integer >= 3, got '3'"),
        (2, r"sides: expected an integer >= 3, got 2"),
        (10**12, r"sides: expected at most 1,000,000 vertices \(16 MB, 3 s\), got 1000000000000"),
    ],
)
def test_polygon_builders_refuse_a_bad_side_count(sides: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        ConvexPolygon.disk((0.0, 0.0), 1.0, sides)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=message):
        regular_polygon((0.0, 0.0), 1.0, sides)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=message):
        outer_disk(np.zeros(2), 1.0, sides)  # type: ignore[arg-type]


def test_polygon_builders_take_numpy_side_counts_bit_for_bit() -> None:
    assert outer_disk(np.zeros(2), 1.0, np.int64(7)).tolist() == outer_disk(np.zeros(2), 1.0, 7).tolist()  # type: ignore[arg-type]
    assert regular_polygon((1, 2), 3, np.int32(5)) == regular_polygon((1.0, 2.0), 3.0, 5)  # type: ignore[arg-type]
    assert ConvexPolygon.disk(np.array([1.0, 2.0]), 0.0, 5).vertices.tolist() == [[1.0, 2.0]]


@pytest.mark.parametrize(
    ("center", "message"),
    [
        ([], r"center: expected at least 1 points, got 0"),
        ({}, r"center: expected an \(n, 2\) array of numbers, got \{\}"),
        ("ab", r"center: expected an \(n, 2\) array of numbers, got 'ab'"),
        ([(0.0, 0.0), (1.0, 1.0)], r"center: expected one point \(x, y\), got shape \(2, 2\)"),
        ((math.nan, 0.0), r"center: expected finite coordinates"),
    ],
)
def test_polygon_builders_refuse_a_bad_center(center: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        regular_polygon(center, 1.0, 6)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=message):
        ConvexPolygon.disk(center, 1.0)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("radius", "phase", "message"),
    [
        (None, 0.0, r"radius: expected a finite number, got None"),
        (math.inf, 0.0, r"radius: expected a finite number, got inf"),
        (0.0, 0.0, r"radius: expected a number in \(0, 2e\+06\] m, got 0\.0"),
        (math.nan, 0.0, r"radius: expected a finite number, got nan"),
        (1.5e6, 0.0, r"radius: expected a circle around center \[0\.0, 0\.0\] inside \[-1e\+06, 1e\+06\] m"),
        (1.0, math.nan, r"phase: expected a finite number, got nan"),
        (1.0, 1e300, r"phase: expected a number in \[-1000, 1000\] rad, got 1e\+300"),
        (1.0, [1.0], r"phase: expected a finite number, got \[1\.0\]"),
    ],
)
def test_regular_polygon_names_a_bad_radius_or_phase(radius: object, phase: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        regular_polygon((0.0, 0.0), radius, 6, phase=phase)  # type: ignore[arg-type]


def test_regular_polygon_names_a_radius_too_small_to_resolve() -> None:
    with pytest.raises(
        InputError, match=r"radius: expected 6 distinct vertices around center \[100000\.0, 0\.0\]"
    ):
        regular_polygon((1e5, 0.0), 1e-14, 6)


@pytest.mark.parametrize(
    ("start", "stop", "step", "message"),
    [
        (
            0.0,
            1e300,
            ARC_STEP,
            r"stop - start: expected at most 2 pi rad, got 1e\+300 \(start 0\.0, stop 1e\+300\)",
        ),
        (-1e300, 1.0, ARC_STEP, r"stop - start: expected at most 2 pi rad, got 1e\+300"),
        (0.0, math.inf, ARC_STEP, r"stop - start: expected at most 2 pi rad, got inf"),
        (math.nan, 1.0, ARC_STEP, r"stop - start: expected at most 2 pi rad, got nan"),
        (
            0.0,
            1.0,
            1e-300,
            r"step: expected at most 1,000,000 pieces of the arc \(a vertex each: 16 MB, 3 s\)",
        ),
    ],
)
def test_outer_arc_refuses_what_would_never_return(
    start: float, stop: float, step: float, message: str
) -> None:
    with pytest.raises(InputError, match=message):
        outer_arc(1.0, start, stop, step)


def test_outer_annular_sector_refuses_a_step_that_would_never_return() -> None:
    with pytest.raises(InputError, match=r"step: expected at most 1,000,000 pieces of the arc"):
        outer_annular_sector(1.0, 2.0, 0.0, 1.0, 1e-300)
    # A sector of a turn or more is a disk, however wide (as documented).
    assert len(outer_annular_sector(1.0, 2.0, 0.0, 1e300)) == FULL_DISK_SIDES


def test_outer_arc_takes_a_turn_and_a_rounding_step_more() -> None:
    lo, width = 1.3, math.tau - 1e-15
    assert len(outer_arc(1.0, lo, lo + width)) == 34
    assert len(outer_arc(1.0, 0.0, 1.0, 1.0 / 99_999)) == 100_001
