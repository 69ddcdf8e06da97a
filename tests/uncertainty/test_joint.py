"""The joint reduction: observations of one instant, the heading wedge split into sectors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.typing import NDArray

from aura_ums.errors import InputError
from aura_ums.geometry import ConvexPolygon, HeadingWedge
from aura_ums.uncertainty import (
    BearingObservation,
    Landmark,
    Observation,
    PointLandmark,
    Pose,
    RangeBearingObservation,
    SpatialUncertaintyMap,
    VerticalLineLandmark,
    reduce_jointly,
)
from aura_ums.uncertainty._joint import JOINT_INCONSISTENT
from tests.uncertainty.test_reduce import map_inside, wedge_inside

Array = NDArray[np.float64]
Sighting = tuple[Observation, Landmark]
TWO_PI = 2.0 * math.pi


def wide_prior(rng: np.random.Generator) -> SpatialUncertaintyMap:
    """A random polygon with a wide wedge (often the full circle, often across the seam)."""
    center = rng.uniform(-5.0, 5.0, 2)
    points = center + rng.normal(size=(int(rng.integers(3, 30)), 2)) * rng.uniform(0.5, 8.0, 2)
    polygon = ConvexPolygon.from_points(points)
    kind = int(rng.integers(0, 3))
    if kind == 0:
        wedge = HeadingWedge.full_circle(float(rng.uniform(-math.pi, math.pi)))
    elif kind == 1:
        wedge = HeadingWedge(math.pi - float(rng.uniform(-0.2, 0.2)), *rng.uniform(0.2, 2.5, 2).tolist())
    else:
        wedge = HeadingWedge(float(rng.uniform(-math.pi, math.pi)), *rng.uniform(0.1, 3.0, 2).tolist())
    return SpatialUncertaintyMap.from_polygon(polygon, polygon.centroid, wedge)


def bounded(rng: np.random.Generator, bound: float) -> float:
    """An error anywhere in [-bound, bound]; a third of the time exactly at an end."""
    if rng.uniform() < 1.0 / 3.0:
        return bound * float(rng.choice([-1.0, 1.0]))
    return float(rng.uniform(-bound, bound))


def sightings_of(
    rng: np.random.Generator, prior: SpatialUncertaintyMap, pose: Pose, count: int
) -> list[Sighting]:
    """Class I and II observations of ``count`` landmarks, from ``pose``, errors within their bounds."""
    found: list[Sighting] = []
    for k in range(count):
        if rng.uniform() < 0.2:  # inside the polygon
            x, y = prior.polygon.sample(1, rng)[0].tolist()
        else:
            angle, reach = rng.uniform(0.0, TWO_PI), rng.uniform(1.0, 30.0)
            x, y = (prior.center + reach * np.array([math.cos(angle), math.sin(angle)])).tolist()
        uncertainty = 0.0 if rng.uniform() < 0.5 else float(rng.uniform(0.0, 0.3))
        tx, ty = np.array([x, y]) + uncertainty * math.sqrt(rng.uniform()) * np.array(
            [math.cos(a := rng.uniform(0.0, TWO_PI)), math.sin(a)]
        )
        bound = float(rng.uniform(0.0, 0.1))
        bearing = math.atan2(ty - pose.y, tx - pose.x) - pose.heading + bounded(rng, bound)
        name = f"lm{k}"
        if rng.uniform() < 0.5:
            found.append(
                (
                    BearingObservation(name, 0.0, bearing, bound),
                    VerticalLineLandmark(name, x, y, 0.0, 5.0, "", uncertainty),
                )
            )
        else:
            span = float(rng.uniform(0.0, 1.0))
            distance = math.hypot(tx - pose.x, ty - pose.y) + bounded(rng, span)
            found.append(
                (
                    RangeBearingObservation(
                        name, 0.0, bearing, bound, max(0.0, distance - span), distance + span
                    ),
                    PointLandmark(name, x, y, 2.0, "", uncertainty),
                )
            )
    return found


def poles_at(*points: tuple[float, float]) -> list[VerticalLineLandmark]:
    return [VerticalLineLandmark(f"pole{k}", x, y, 0.0, 5.0) for k, (x, y) in enumerate(points)]


def in_turn(prior: SpatialUncertaintyMap, sightings: list[Sighting]) -> SpatialUncertaintyMap:
    current = prior
    for observation, landmark in sightings:
        current = current.reduce(observation, landmark).map
    return current


def test_every_true_pose_is_kept_and_the_joint_map_bites(rng: np.random.Generator) -> None:
    kept = total = tighter = 0
    for _ in range(120):
        prior = wide_prior(rng)
        sector = math.radians(float(rng.uniform(5.0, 30.0)))
        for values in prior.sample_poses(12, rng):
            pose = Pose(*values.tolist())
            sightings = sightings_of(rng, prior, pose, int(rng.integers(2, 4)))
            joint = reduce_jointly(prior, sightings, sector=sector)
            total += 1
            kept += joint.consistent and bool(joint.map.contains(pose))
            assert map_inside(joint.map, prior), (prior, sightings)
            # Never looser than one by one, beyond the hull's and the sectors' slack.
            tighter += joint.area_after < 0.9 * in_turn(prior, sightings).area
    assert total >= 1400
    assert kept == total
    assert tighter > total // 3


def test_one_sector_is_the_reduction_in_turn() -> None:
    prior = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.3), 2.0, math.radians(4.0))  # 8 degrees wide
    a = VerticalLineLandmark("a", 10.0, 3.0, 0.0, 5.0)
    b = PointLandmark("b", -2.0, 9.0, 2.0)
    sightings: list[Sighting] = [
        (BearingObservation("a", 0.0, math.atan2(3.0, 10.0) - 0.3, 0.02), a),
        (RangeBearingObservation("b", 0.0, math.atan2(9.0, -2.0) - 0.3, 0.02, 9.0, 9.5), b),
    ]
    joint = reduce_jointly(prior, sightings, sector=math.radians(10.0))
    expected = in_turn(prior, sightings)
    assert joint.map.polygon.vertices.tobytes() == expected.polygon.vertices.tobytes()
    assert (joint.map.wedge.center, joint.map.wedge.cw, joint.map.wedge.ccw) == (
        expected.wedge.center,
        expected.wedge.cw,
        expected.wedge.ccw,
    )
    assert joint.area_before == prior.area


def test_full_circle_across_the_seam_keeps_the_truth_and_closes_the_wedge() -> None:
    truth = Pose(1.0, -2.0, -math.pi + 0.005)  # just across the seam
    prior = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 12.0, math.pi)
    poles = [
        VerticalLineLandmark(n, x, y, 0.0, 5.0)
        for n, (x, y) in zip("abc", [(9, 1), (-3, 8), (-6, -7)], strict=True)
    ]
    sightings: list[Sighting] = [
        (BearingObservation(p.id, 0.0, math.atan2(p.y - truth.y, p.x - truth.x) - truth.heading, 0.01), p)
        for p in poles
    ]
    joint = reduce_jointly(prior, sightings)
    assert joint.consistent
    assert joint.map.contains(truth)
    assert joint.map.wedge.width < 0.2
    assert abs(math.remainder(joint.map.wedge.center - math.pi, TWO_PI)) < 0.1  # around the seam
    assert joint.map.contains(Pose(truth.x, truth.y, truth.heading + TWO_PI))  # the same heading
    assert joint.area_after < 0.02 * prior.area
    assert in_turn(prior, sightings).wedge.is_full_circle  # one by one: nothing learnt about heading


def test_a_partial_wedge_stays_inside_the_prior_wedge() -> None:
    # 300 degrees wide; the truth near one end: the result must not wrap through the 60 missing.
    prior = SpatialUncertaintyMap.from_polygon(
        ConvexPolygon.disk((0.0, 0.0), 3.0),
        (0.0, 0.0),
        HeadingWedge(0.0, math.radians(150), math.radians(150)),
    )
    truth = Pose(0.5, 0.5, math.radians(145.0))
    poles = [
        VerticalLineLandmark(n, x, y, 0.0, 5.0) for n, (x, y) in zip("ab", [(8, 2), (-1, 9)], strict=True)
    ]
    sightings: list[Sighting] = [
        (BearingObservation(p.id, 0.0, math.atan2(p.y - truth.y, p.x - truth.x) - truth.heading, 0.05), p)
        for p in poles
    ]
    joint = reduce_jointly(prior, sightings)
    assert joint.map.contains(truth)
    assert wedge_inside(joint.map.wedge, prior.wedge)


def test_landmark_inside_the_polygon_and_an_empty_intersection() -> None:
    prior = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 10.0, math.pi)
    truth = Pose(2.0, 1.0, -0.5)
    near = VerticalLineLandmark("near", 0.5, 0.5, 0.0, 5.0, position_uncertainty=0.2)  # in the polygon
    far = VerticalLineLandmark("far", 20.0, 0.0, 0.0, 5.0)
    sightings: list[Sighting] = [
        (BearingObservation(p.id, 0.0, math.atan2(p.y - truth.y, p.x - truth.x) - truth.heading, 0.02), p)
        for p in (near, far)
    ]
    joint = reduce_jointly(prior, sightings)
    assert joint.consistent
    assert joint.map.contains(truth)
    # The far pole straight ahead and to the left at once, without error: no heading agrees.
    ahead: list[Sighting] = [
        (BearingObservation("far", 0.0, 0.0, 0.0), far),
        (BearingObservation("far", 0.0, math.pi / 2, 0.0), far),
    ]
    empty = reduce_jointly(prior, ahead)
    assert not empty.consistent
    assert empty.map is prior
    assert empty.reason == JOINT_INCONSISTENT
    assert empty.area_after == empty.area_before == prior.area


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(math.radians(3.0), TWO_PI))
def test_joint_map_lies_inside_the_prior_with_its_centre(seed: int, sector: float) -> None:
    rng = np.random.default_rng(seed)
    prior = wide_prior(rng)
    x, y = rng.uniform(-10.0, 10.0, 2).tolist()
    pose = Pose(x, y, float(rng.uniform(-math.pi, math.pi)))  # anywhere: the map may not hold it
    joint = reduce_jointly(prior, sightings_of(rng, prior, pose, int(rng.integers(1, 4))), sector=sector)
    assert map_inside(joint.map, prior)
    assert joint.map.polygon.contains(joint.map.center[None, :], tolerance=1e-6)[0]
    assert joint.area_after <= joint.area_before * (1.0 + 1e-9) + 1e-12
    assert joint.map.polygon.vertex_count <= max(64, prior.polygon.vertex_count)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(3, 8), st.floats(math.radians(1.0), math.radians(6.0)))
def test_the_joint_hull_is_capped_and_keeps_every_true_pose(seed: int, cap: int, sector: float) -> None:
    # Many narrow sectors and several observations: the sectors' hull runs past a small cap.
    rng = np.random.default_rng(seed)
    prior = wide_prior(rng)
    sightings_count = int(rng.integers(2, 6))
    for values in prior.sample_poses(4, rng):
        pose = Pose(*values.tolist())
        sightings = sightings_of(rng, prior, pose, sightings_count)
        joint = reduce_jointly(prior, sightings, sector=sector, max_vertices=cap)
        assert joint.consistent
        assert joint.map.contains(pose), (prior, sightings, cap)
        assert joint.map.polygon.vertex_count <= max(cap, prior.polygon.vertex_count)
        assert map_inside(joint.map, prior)


def test_the_cap_test_drives_the_joint_hull_past_the_cap() -> None:
    # The property above bites only if the uncapped joint polygon is often past the cap.
    rng = np.random.default_rng(17)
    past = 0
    for _ in range(40):
        prior = wide_prior(rng)
        cap = int(rng.integers(3, 9))
        pose = Pose(*prior.sample_poses(1, rng)[0].tolist())
        sightings = sightings_of(rng, prior, pose, int(rng.integers(2, 6)))
        uncapped = reduce_jointly(prior, sightings, sector=math.radians(3.0), max_vertices=10**6)
        past += uncapped.map.polygon.vertex_count > max(cap, prior.polygon.vertex_count)
    assert past >= 10


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"prior": "map"}, "prior: expected a SpatialUncertaintyMap, got str"),
        ({"sightings": []}, "sightings: expected at least one"),
        ({"sightings": "ab"}, r"sightings: expected a sequence of \(observation, landmark\) pairs, got str"),
        ({"sightings": [(1, 2, 3)]}, r"sightings\[0\]: expected an \(observation, landmark\) pair"),
        ({"sector": 0.0}, r"sector: expected radians in \(0, 2 pi\], got 0.0"),
        ({"sector": 7.0}, r"sector: expected radians in \(0, 2 pi\], got 7.0"),
        ({"sector": math.nan}, "sector: expected a finite number"),
        ({"max_vertices": 2}, r"max_vertices: expected an integer in \[3, 2\*\*63 - 1\], got 2"),
        # an OverflowError from the kernel before
        ({"max_vertices": 2**63}, r"max_vertices: expected an integer in \[3, 2\*\*63 - 1\], got 92233"),
        (
            {"sector": 1e-300},
            r"sector: expected at least 0\.00174533 rad \(0\.1 degree, at most 3600 sectors; .*"
            r"got 1e-300 \(6\.28e\+300 sectors of a full circle\)",
        ),
    ],
)
def test_bad_arguments_are_named(kwargs: dict[str, object], match: str) -> None:
    pole = VerticalLineLandmark("a", 5.0, 0.0, 0.0, 5.0)
    arguments: dict[str, object] = {
        "prior": SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 1.0, math.pi),
        "sightings": [(BearingObservation("a", 0.0, 0.0, 0.01), pole)],
        "sector": math.radians(10.0),
        "max_vertices": 64,
    }
    arguments.update(kwargs)
    prior, sightings = arguments.pop("prior"), arguments.pop("sightings")
    with pytest.raises(InputError, match=match):
        reduce_jointly(prior, sightings, **arguments)  # type: ignore[arg-type]


def test_a_pair_of_mismatched_classes_is_refused() -> None:
    prior = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 1.0, math.pi)
    corner = PointLandmark("a", 5.0, 0.0, 2.0)
    with pytest.raises(InputError, match="for a RangeBearingObservation, got VerticalLineLandmark"):
        reduce_jointly(prior, [(RangeBearingObservation("a", 0.0, 0.0, 0.01, 4.0, 6.0), _line(corner))] * 2)
    # A bearing may name a point: the bearing to the vertical line through it.
    joint = reduce_jointly(prior, [(BearingObservation("a", 0.0, 0.0, 0.01), corner)] * 2)
    assert joint.map.wedge.width < 0.5 * prior.wedge.width
    assert joint.map.contains(Pose(0.0, 0.0, 0.0))


def _line(corner: PointLandmark) -> VerticalLineLandmark:
    return VerticalLineLandmark(corner.id, corner.x, corner.y, 0.0, corner.z)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(math.radians(3.0), TWO_PI), st.booleans())
def test_the_managers_joint_reduction_is_reduce_jointly_without_the_areas(
    seed: int, sector: float, sliced: bool
) -> None:
    # The manager reads no area: its entry gives reduce_jointly's map, bit for bit, or its reason.
    rng = np.random.default_rng(seed)
    prior = wide_prior(rng)
    if sliced:
        prior = prior.with_slices(math.radians(4.0))
    x, y = rng.uniform(-10.0, 10.0, 2).tolist()
    pose = Pose(x, y, float(rng.uniform(-math.pi, math.pi)))
    sightings = sightings_of(rng, prior, pose, int(rng.integers(1, 4)))
    public = reduce_jointly(prior, sightings, sector=sector, max_vertices=16)
    found = prior._reduce_jointly(sightings, sector, 16)
    if isinstance(found, str):
        assert not public.consistent
        assert found == public.reason
        return
    assert public.consistent
    assert found.polygon.vertices.tobytes() == public.map.polygon.vertices.tobytes()
    assert found.center.tobytes() == public.map.center.tobytes()
    assert found.wedge == public.map.wedge
    assert found.is_sliced == sliced
    assert public.area_after == found.area


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(math.radians(3.0), math.radians(30.0)))
def test_sectors_reduced_without_held_centres_give_the_same_map(seed: int, sector: float) -> None:
    # Only the sector the joint map takes its centre from is reduced with held centres (again):
    # the result must be the one every sector reduced with held centres gives, bit for bit.
    # Holding a centre seldom moves it (a noisy edge a hair off): here it always moves, to
    # the vertices' mean, so that a centre taken from the wrong sector reduction shows.
    from aura_ums.uncertainty import _joint, _reduce

    rng = np.random.default_rng(seed)
    prior = wide_prior(rng)
    pose = Pose(*prior.sample_poses(1, rng)[0].tolist())
    sightings = sightings_of(rng, prior, pose, int(rng.integers(2, 4)))
    always_held = _joint._in_turn

    def held_everywhere(
        current: SpatialUncertaintyMap, pairs: list[Sighting], cap: int, *, held: bool = True
    ) -> SpatialUncertaintyMap | str:
        return always_held(current, pairs, cap)

    def to_the_mean(vertices: Array, x: float, y: float) -> tuple[float, float]:
        mean_x, mean_y = vertices.mean(axis=0).tolist()
        return mean_x, mean_y

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(_reduce, "held_centre", to_the_mean)
        found = _joint.joint_reduced(prior, sightings, sector, 12)
        patch.setattr(_joint, "_in_turn", held_everywhere)
        reference = _joint.joint_reduced(prior, sightings, sector, 12)
    assert not isinstance(found, str)
    assert not isinstance(reference, str)
    assert found.polygon.vertices.tobytes() == reference.polygon.vertices.tobytes()
    assert found.center.tobytes() == reference.center.tobytes()
    assert found.wedge == reference.wedge
    assert found.contains(pose)
