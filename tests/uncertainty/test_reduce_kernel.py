"""The compiled reduction kernels against the numpy reference, and their handling of bad input."""

from __future__ import annotations

import math
import tracemalloc

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numpy.typing import NDArray
from test_reduce import (
    Case,
    MakeCase,
    class_one_cases,
    class_three_cases,
    class_two_cases,
    map_inside,
    observations,
    priors,
    random_prior,
)

from aura_ums.geometry import ConvexPolygon, HeadingWedge, regular_polygon
from aura_ums.geometry._angles import TWO_PI
from aura_ums.geometry._convex import convexity_defect
from aura_ums.uncertainty import (
    BearingObservation,
    GroundLineLandmark,
    GroundLineObservation,
    PointLandmark,
    Pose,
    RangeBearingObservation,
    Reduction,
    SpatialUncertaintyMap,
    VerticalLineLandmark,
    _reduce,
)
from aura_ums.uncertainty._reduce import reduce_map, reduce_map_reference

Array = NDArray[np.float64]

KERNELS = _reduce.compiled_kernels()
compiled = pytest.mark.skipif(KERNELS is None, reason="the C reduction kernels were not built (no compiler)")

MAKERS: list[MakeCase] = [class_one_cases, class_two_cases, class_three_cases]


# --- the comparison -----------------------------------------------------------------


def wedges_agree(first: HeadingWedge, second: HeadingWedge, tolerance: float = 1e-9) -> bool:
    """Tell whether two wedges have the same centre (modulo 2 pi) and extents, to ``tolerance`` rad."""
    if first.is_full_circle and second.is_full_circle:
        return abs(math.remainder(first.center - second.center, TWO_PI)) <= tolerance
    return (
        abs(math.remainder(first.center - second.center, TWO_PI)) <= tolerance
        and abs(first.cw - second.cw) <= tolerance
        and abs(first.ccw - second.ccw) <= tolerance
    )


def compare(
    prior: SpatialUncertaintyMap, case: Case, max_vertices: int, poses: Array | None = None
) -> tuple[Reduction, Reduction]:
    """Reduce by both paths and check that they agree; return (compiled, reference).

    The verdicts and reasons must be equal and the wedges agree to 1e-9 rad. Without a vertex
    cap at work the polygons are the same up to rounding: areas agree to 1e-9 relative and
    centres to 1e-9 of the coordinates' size. With the cap at work its greedy choice may break
    rounding-level ties differently; then each result must still hold every true pose, lie
    inside the prior and have no more vertices than the uncapped polygon.
    """
    observation, landmark = case
    ours = reduce_map(prior, observation, landmark, max_vertices)
    reference = reduce_map_reference(prior, observation, landmark, max_vertices)
    assert (ours.consistent, ours.reason) == (reference.consistent, reference.reason), case
    if not ours.consistent:
        assert ours.map is prior
        assert (ours.area_after, ours.wedge_after) == (reference.area_before, prior.wedge)
        return ours, reference
    assert wedges_agree(ours.wedge_after, reference.wedge_after), (ours.wedge_after, reference.wedge_after)
    vertices = ours.map.polygon.vertices
    assert not vertices.flags.writeable
    assert convexity_defect(vertices) is None
    scale = 1.0 + float(np.abs(prior.polygon.vertices).max())
    assert ours.area_before == pytest.approx(reference.area_before, rel=1e-12, abs=1e-12 * scale**2)
    assert ours.area_after == pytest.approx(ours.map.area, rel=1e-12, abs=1e-12 * scale**2)
    uncapped = reduce_map_reference(prior, observation, landmark, 1_000_000)
    if uncapped.map.polygon.vertex_count <= max_vertices:
        assert ours.area_after == pytest.approx(reference.area_after, rel=1e-9, abs=1e-12 * scale**2)
        assert np.allclose(ours.map.center, reference.map.center, rtol=0.0, atol=1e-9 * scale)
    else:
        for result in (ours, reference):
            assert map_inside(result.map, prior)
            # The cap only ever removes vertices (it stops when none can go inside the prior).
            assert result.map.polygon.vertex_count <= uncapped.map.polygon.vertex_count
            assert result.map.contains(result.map.most_probable_pose())
    if poses is not None:
        for result in (ours, reference):
            assert np.all(result.map.contains(poses[:, 0], poses[:, 1], poses[:, 2]))
    return ours, reference


# --- agreement ----------------------------------------------------------------------


@compiled
@given(st.integers(0, 2**32 - 1), st.sampled_from([0, 1, 2]), st.sampled_from([64, 16, 5, 3]))
def test_monte_carlo_true_poses_agree(seed: int, kind: int, max_vertices: int) -> None:
    """Observations of sampled true poses: the same verdict (consistent), polygons, wedges."""
    rng = np.random.default_rng(seed)
    prior = random_prior(rng)
    poses = prior.sample_poses(4, rng)
    for pose, case in zip(poses, MAKERS[kind](rng, prior, poses), strict=True):
        ours, _ = compare(prior, case, max_vertices, pose[None, :])
        assert ours.consistent


@compiled
@given(priors(), observations(), st.sampled_from([64, 8, 3]))
def test_arbitrary_observations_agree(prior: SpatialUncertaintyMap, case: Case, max_vertices: int) -> None:
    """Observations anywhere (often inconsistent): the same verdict and, when consistent, the same map."""
    compare(prior, case, max_vertices)


@compiled
def test_many_true_poses_agree(rng: np.random.Generator) -> None:
    """A fixed Monte Carlo run: 3 x 1,500 reductions, each result holding its true pose on both paths."""
    agreed = 0
    for _ in range(100):
        prior = random_prior(rng)
        poses = prior.sample_poses(5, rng)
        for make in MAKERS:
            for pose, case in zip(poses, make(rng, prior, poses), strict=True):
                ours, _ = compare(prior, case, 64, pose[None, :])
                agreed += ours.consistent
    assert agreed == 1_500


@compiled
@pytest.mark.parametrize("shift", [0.0, 1e3, -5e5])
def test_far_from_the_origin_agrees(rng: np.random.Generator, shift: float) -> None:
    for _ in range(40):
        base = random_prior(rng)
        vertices = base.polygon.vertices + shift
        prior = SpatialUncertaintyMap.from_polygon(
            ConvexPolygon._trusted(vertices), base.center + shift, base.wedge
        )
        poses = prior.sample_poses(3, rng)
        for make in MAKERS:
            for pose, case in zip(poses, make(rng, prior, poses), strict=True):
                compare(prior, case, 64, pose[None, :])


def _degenerate_priors() -> list[SpatialUncertaintyMap]:
    wedges = [HeadingWedge(0.3, 0.0, 0.0), HeadingWedge(-2.0, 0.2, 0.1), HeadingWedge.full_circle(1.0)]
    polygons = [
        ConvexPolygon.point(1.0, 2.0),
        ConvexPolygon([(0.0, 0.0), (2.0, 1.0)]),
        ConvexPolygon([(0.0, 0.0), (1.0, 0.0), (0.5, 1e-9)]),
        regular_polygon((0.0, 0.0), 2.0, 64),
    ]
    return [
        SpatialUncertaintyMap.from_polygon(polygon, polygon.centroid, wedge)
        for polygon in polygons
        for wedge in wedges
    ]


@compiled
@pytest.mark.parametrize("prior", _degenerate_priors(), ids=lambda prior: repr(prior))
def test_points_segments_and_slivers_agree(prior: SpatialUncertaintyMap, rng: np.random.Generator) -> None:
    poses = prior.sample_poses(6, rng)
    for make in MAKERS:
        for pose, case in zip(poses, make(rng, prior, poses), strict=True):
            compare(prior, case, 64, pose[None, :])
            compare(prior, case, 3, pose[None, :])


@compiled
def test_special_observations_agree() -> None:
    prior = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 1.0, 0.1)
    pole = VerticalLineLandmark("p", 20.0, 0.0, 0.0, 6.0, "", 0.0)
    inside = VerticalLineLandmark("p", 0.1, 0.2, 0.0, 6.0, "", 0.3)
    corner = PointLandmark("c", 20.0, 0.0, 2.0, "", 0.1)
    edge = GroundLineLandmark("e", (0, 5), (9, 5), "", 0.1)
    cases: list[Case] = [
        (BearingObservation("p", 0.0, math.pi, 0.1), pole),  # behind: empty
        (BearingObservation("p", 0.0, 0.0, 4.0), pole),  # a bearing error wider than a half-turn
        (BearingObservation("p", 0.0, 0.0, 0.0, (0.3, -0.2)), pole),
        (BearingObservation("p", 0.0, 1.0, 0.1), inside),  # the landmark within the polygon
        (RangeBearingObservation("c", 0.0, 0.0, 0.1, 50.0, 60.0), corner),  # too far: empty
        (RangeBearingObservation("c", 0.0, 0.0, 0.1, 0.0, 1e9), corner),
        (RangeBearingObservation("c", 0.0, 0.0, 3.5, 19.0, 21.0, (0.5, 0.5)), corner),
        (GroundLineObservation("e", 0.0, 0.0, 0.1, math.pi / 2, 0.1), edge),  # wrong angle: empty
        (GroundLineObservation("e", 0.0, 0.0, 0.1, 0.0, 0.1), edge),  # wrong offset: empty
        (GroundLineObservation("e", 0.0, -5.0, 0.5, 0.0, 0.1, (0.4, 0.1)), edge),
        (GroundLineObservation("e", 0.0, -5.0, 0.5, 0.0, 4.0, (0.4, 0.1)), edge),
    ]
    for case in cases:
        compare(prior, case, 64)
    full = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 2.0), 0.5, math.pi)
    for case in cases:
        compare(full, case, 64)
        compare(full, case, 3)


# --- the kernels themselves ---------------------------------------------------------

_SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
_CONE_ARGS = (0.5, 0.5, 0.0, 0.01, 0.01, 0.0, 0.0, 20.0, 0.0, 0.0, 0.0, 0.001, 0.0, math.inf, 2.0)
_STRIP_ARGS = (0.5, 0.5, 0.0, 0.1, 0.1, 0.0, 0.0, 0.0, -1.0, 1.0, -1.0, 0.0, 1.5, 0.5, 0.0, 0.1)


@compiled
def test_kernels_return_the_reduction_or_a_reason() -> None:
    assert KERNELS is not None
    cone, strip = KERNELS
    found = cone(_SQUARE, *_CONE_ARGS, 16)
    assert isinstance(found, tuple)
    raw, lo, width, x, y, area_before, area_after = found
    assert np.frombuffer(raw).reshape(-1, 2).shape[1] == 2
    # The cone keeps |y| <~ 0.22: the centre moves down to its (slightly sloping) edge.
    assert width <= 0.02
    assert (x, y) == pytest.approx((0.5, 0.22), abs=0.01)
    assert area_before == 1.0
    assert area_after == pytest.approx(y, rel=0.01)
    assert isinstance(lo, float)
    behind = list(_CONE_ARGS)
    behind[10] = math.pi  # the bearing
    assert cone(_SQUARE, *behind, 16) == 0  # no position sees it there
    assert isinstance(strip(_SQUARE, *_STRIP_ARGS, 16), tuple)
    away = list(_STRIP_ARGS)
    away[12] = 9.0  # the offset
    assert strip(_SQUARE, *away, 16) == 4
    assert _reduce._REASONS[0] == "no position of the map is consistent with the observation"
    assert _reduce._REASONS[4] == "no position of the map is at the observed offset from the line"


@compiled
@pytest.mark.parametrize(
    ("vertices", "error", "message"),
    [
        (b"abcdefghabcdefgh", ValueError, r"expected a C-contiguous \(n, 2\) float64 buffer, got format 'B'"),
        (np.zeros((3, 2), dtype=np.float32), ValueError, "got format 'f' with 4-byte items"),
        (np.zeros((3, 3)), ValueError, "got 2 dimensions with 3 in the last"),
        (np.zeros((0, 2)), ValueError, "got 0 bytes"),
        (np.zeros(3), ValueError, "got 24 bytes"),
        (np.zeros((4, 4))[:, :2], ValueError, "got a non-contiguous numpy.ndarray"),
        ([[0.0, 0.0]], TypeError, "got list"),
    ],
)
def test_kernels_refuse_a_malformed_buffer(vertices: object, error: type[Exception], message: str) -> None:
    assert KERNELS is not None
    cone, strip = KERNELS
    with pytest.raises(error, match=message):
        cone(vertices, *_CONE_ARGS, 16)
    with pytest.raises(error, match=message):
        strip(vertices, *_STRIP_ARGS, 16)


@compiled
def test_kernels_refuse_bad_numbers() -> None:
    assert KERNELS is not None
    cone, strip = KERNELS
    with pytest.raises(TypeError, match="reduce_cone: expected 17 arguments, got 16"):
        cone(_SQUARE, *_CONE_ARGS)
    with pytest.raises(TypeError, match="reduce_strip: expected 18 arguments, got 2"):
        strip(_SQUARE, 16)
    with pytest.raises(TypeError, match="bearing: expected a real number, got str"):
        cone(_SQUARE, *_CONE_ARGS[:10], "north", *_CONE_ARGS[11:], 16)
    bad = list(_CONE_ARGS)
    bad[10] = math.nan
    with pytest.raises(ValueError, match="bearing: expected a finite number, got nan"):
        cone(_SQUARE, *bad, 16)
    bad[10], bad[13] = 0.0, -math.inf
    with pytest.raises(ValueError, match="range_max: expected a finite number or inf, got -inf"):
        cone(_SQUARE, *bad, 16)
    bad = list(_STRIP_ARGS)
    bad[12] = -math.inf
    with pytest.raises(ValueError, match="offset: expected a finite number, got -inf"):
        strip(_SQUARE, *bad, 16)
    bad = list(_CONE_ARGS)
    bad[14] = 0.0
    with pytest.raises(ValueError, match=r"piece: expected a positive angle, got 0\.0"):
        cone(_SQUARE, *bad, 16)
    with pytest.raises(ValueError, match="max_vertices: expected at least 3, got 2"):
        cone(_SQUARE, *_CONE_ARGS, 2)
    with pytest.raises(TypeError):
        strip(_SQUARE, *_STRIP_ARGS, 16.5)


@compiled
def test_kernels_release_the_buffer_and_free_their_memory() -> None:
    assert KERNELS is not None
    cone, strip = KERNELS
    view = memoryview(bytearray(_SQUARE.tobytes())).cast("d")
    assert isinstance(cone(view, *_CONE_ARGS, 16), tuple)
    assert isinstance(strip(view, *_STRIP_ARGS, 3), tuple)
    view.release()  # raises BufferError if a kernel kept its export
    raw = bytearray(b"x" * 16)
    with pytest.raises(ValueError, match="format 'B'"):
        cone(raw, *_CONE_ARGS, 16)
    raw.extend(b"y")  # a bytearray with exports cannot be resized
    prior = SpatialUncertaintyMap.from_polygon(
        regular_polygon((0.0, 0.0), 2.0, 40), (0.0, 0.0), HeadingWedge(0.0, 0.5, 0.5)
    )
    cases: list[Case] = [
        (BearingObservation("p", 0.0, 0.2, 0.05, (0.3, 0.1)), VerticalLineLandmark("p", 9.0, 3.0, 0.0, 1.0)),
        (
            RangeBearingObservation("c", 0.0, 0.2, 0.05, 8.0, 11.0, (0.3, 0.1)),
            PointLandmark("c", 9.0, 3.0, 1.0),
        ),
        (
            GroundLineObservation("e", 0.0, 1.0, 0.5, 0.1, 0.05, (0.3, 0.1)),
            GroundLineLandmark("e", (0, -1), (9, -1)),
        ),
        (BearingObservation("p", 0.0, 3.0, 0.05), VerticalLineLandmark("p", 9.0, 3.0, 0.0, 1.0)),  # empty
    ]

    def run() -> None:
        for observation, landmark in cases:
            prior.reduce(observation, landmark, max_vertices=6)
        with pytest.raises(ValueError, match="expected a finite"):
            cone(_SQUARE, *_CONE_ARGS[:-1], math.nan, 16)

    run()
    tracemalloc.start()
    try:
        run()
        before = tracemalloc.get_traced_memory()[0]
        for _ in range(300):
            run()
        grown = tracemalloc.get_traced_memory()[0] - before
    finally:
        tracemalloc.stop()
    assert grown < 50_000  # 1,500 calls: a leak of even one small buffer per call would show


def test_dispatch_falls_back_to_numpy(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(_reduce, "_compiled_reduce_cone", None)
    assert _reduce.compiled_kernels() is None
    prior = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 1.0, 0.1)
    reduction = prior.reduce(BearingObservation("p", 0.0, 0.0, 0.01), VerticalLineLandmark("p", 9, 0, 0, 1))
    expected = reduce_map_reference(
        prior, BearingObservation("p", 0.0, 0.0, 0.01), VerticalLineLandmark("p", 9, 0, 0, 1), 64
    )
    assert np.array_equal(reduction.map.polygon.vertices, expected.map.polygon.vertices)
