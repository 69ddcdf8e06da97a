"""The compiled reductions against their numpy reference, on maps (the kernels' own input: tests/_native)."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TypeVar

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numpy.typing import NDArray

from aura_ums import _native
from aura_ums._native import _reduce as native_reduce
from aura_ums.geometry import ConvexPolygon, HeadingWedge, regular_polygon
from aura_ums.geometry._angles import TWO_PI
from aura_ums.geometry._convex import convexity_defect
from aura_ums.uncertainty import (
    BearingObservation,
    GroundLineLandmark,
    GroundLineObservation,
    Landmark,
    Observation,
    PointLandmark,
    Pose,
    RangeBearingObservation,
    Reduction,
    SpatialUncertaintyMap,
    VerticalLineLandmark,
)
from aura_ums.uncertainty._reduce import reduce_map
from tests.uncertainty.test_reduce import (
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

Array = NDArray[np.float64]
T = TypeVar("T")

compiled = pytest.mark.skipif(
    not _native.NATIVE, reason="the C kernels are not in use (not built, or AURA_UMS_NATIVE=0)"
)


def on_reference(call: Callable[..., T], *args: object) -> T:
    """Return ``call(*args)`` run on the numpy reference (the one switch turned off for it)."""
    saved = _native.reduce_cone, _native.reduce_strip
    _native.reduce_cone = native_reduce.reduce_cone_reference
    _native.reduce_strip = native_reduce.reduce_strip_reference
    try:
        return call(*args)
    finally:
        _native.reduce_cone, _native.reduce_strip = saved


def reduce_map_reference(
    prior: SpatialUncertaintyMap, observation: Observation, landmark: Landmark, max_vertices: int
) -> Reduction:
    return on_reference(reduce_map, prior, observation, landmark, max_vertices)


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


def test_the_reference_kernel_reduces_maps_alike(monkeypatch: pytest.MonkeyPatch) -> None:
    prior = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 1.0, 0.1)
    case = (BearingObservation("p", 0.0, 0.0, 0.01), VerticalLineLandmark("p", 9, 0, 0, 1))
    expected = reduce_map_reference(prior, *case, 64)
    monkeypatch.setattr(_native, "reduce_cone", native_reduce.reduce_cone_reference)
    reduction = prior.reduce(*case)
    assert np.array_equal(reduction.map.polygon.vertices, expected.map.polygon.vertices)
