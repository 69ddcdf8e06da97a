"""Tests of heading-sliced maps: the same guarantees as the product map's, slice by slice."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums._native import narrowed, summary_wedge
from aura_ums.errors import InputError
from aura_ums.geometry import ConvexPolygon, HeadingWedge
from aura_ums.geometry._angles import TWO_PI
from aura_ums.uncertainty import (
    BearingObservation,
    GroundLineLandmark,
    GroundLineObservation,
    PointLandmark,
    Pose,
    RangeBearingObservation,
    SpatialUncertaintyMap,
    TerrainStats,
    TerrainTable,
    TurnAndRun,
    VerticalLineLandmark,
    cell_count,
    reduce_jointly,
)
from aura_ums.uncertainty._slices import SliceSet, distributed, split_product
from tests.uncertainty.test_reduce import (
    MakeCase,
    class_one_cases,
    class_three_cases,
    class_two_cases,
    map_inside,
    random_prior,
)

WIDTHS = [math.radians(1.0), math.radians(2.0), math.radians(5.0), 1.0]


def random_terrain(rng: np.random.Generator) -> TerrainStats:
    table = TerrainTable.default()
    return table[str(rng.choice(sorted(table)))]


def random_command(rng: np.random.Generator) -> TurnAndRun:
    turn = 0.0 if rng.uniform() < 0.3 else float(rng.uniform(-2.0, 2.0))
    run = 0.0 if rng.uniform() < 0.1 else float(rng.uniform(0.0, 6.0))
    return TurnAndRun(turn, run)


def coupled_prior(rng: np.random.Generator) -> SpatialUncertaintyMap:
    """A random sliced map, grown once now and then so that its slices differ."""
    width = WIDTHS[int(rng.integers(len(WIDTHS)))]
    sliced = random_prior(rng).with_slices(width, max_slices=int(rng.integers(1, 60)))
    if rng.uniform() < 0.5:
        sliced = sliced.grow(random_command(rng), random_terrain(rng))
    return sliced


def inside_prior(
    reduced: SpatialUncertaintyMap, prior: SpatialUncertaintyMap, rng: np.random.Generator
) -> bool:
    """Tell whether sampled poses of ``reduced`` (and its summary) lie in ``prior``."""
    poses = reduced.sample_poses(200, rng)
    return bool(np.all(prior.contains(poses[:, 0], poses[:, 1], poses[:, 2]))) and map_inside(reduced, prior)


# --- one pose at a time ----------------------------------------------------------------


def boundary_poses(
    subject: SpatialUncertaintyMap, rng: np.random.Generator
) -> list[tuple[float, float, float]]:
    """Poses on and a hair either side of the map's edges, vertices and heading ends."""
    poses = [(float(x), float(y), float(h)) for x, y, h in subject.sample_poses(20, rng).tolist()]
    for piece in subject.slices:
        vertices = piece.polygon.vertices
        ends = [piece.lo, piece.lo + piece.width, piece.lo + 0.5 * piece.width]
        for index in rng.integers(0, len(vertices), 4).tolist():
            a, b = vertices[index], vertices[(index + 1) % len(vertices)]
            point = a + rng.uniform() * (b - a) if rng.uniform() < 0.7 else a
            for nudge in (0.0, 1e-9, -1e-9, 1e-7, float(rng.normal(0.0, 1e-3))):
                heading = ends[int(rng.integers(3))] + float(rng.choice([0.0, 1e-9, -1e-9, 1e-6, TWO_PI]))
                poses.append((float(point[0] + nudge), float(point[1] - nudge), heading))
    return poses


@given(st.integers(0, 2**32 - 1))
def test_one_pose_at_a_time_gives_what_arrays_give(seed: int) -> None:
    """The float path of ``contains`` (a Pose, or three floats) answers as the array path does."""
    rng = np.random.default_rng(seed)
    subject = coupled_prior(rng) if rng.uniform() < 0.6 else random_prior(rng)
    poses = boundary_poses(subject, rng)
    xs, ys, headings = (np.array(column) for column in zip(*poses, strict=True))
    expected = np.asarray(subject.contains(xs, ys, headings)).tolist()
    assert [subject.contains(x, y, heading) for x, y, heading in poses] == expected
    wrapped = [Pose(x, y, heading) for x, y, heading in poses[:10]]
    as_arrays = subject.contains(xs[:10], ys[:10], np.array([pose.heading for pose in wrapped]))
    assert [subject.contains(pose) for pose in wrapped] == np.asarray(as_arrays).tolist()


# --- building ------------------------------------------------------------------------


def test_a_product_map_cut_into_slices_is_the_same_pose_set(rng: np.random.Generator) -> None:
    for _ in range(60):
        product = random_prior(rng)
        sliced = product.with_slices(WIDTHS[int(rng.integers(len(WIDTHS)))], max_slices=400)
        assert sliced.area == pytest.approx(product.area)
        assert sliced.wedge.width == pytest.approx(product.wedge.width, abs=1e-9)
        low, high = product.polygon.vertices.min(axis=0) - 1.0, product.polygon.vertices.max(axis=0) + 1.0
        xy = rng.uniform(low, high, (400, 2))
        headings = rng.uniform(-math.pi, math.pi, 400)
        # Away from the boundaries, where the tolerances decide.
        ours = np.asarray(sliced.contains(xy[:, 0], xy[:, 1], headings))
        assert np.mean(ours == np.asarray(product.contains(xy[:, 0], xy[:, 1], headings))) > 0.99
        poses = product.sample_poses(300, rng)
        assert np.all(sliced.contains(poses[:, 0], poses[:, 1], poses[:, 2]))


def test_slices_lie_on_the_grid_and_the_summary_holds_them() -> None:
    start = SpatialUncertaintyMap.from_pose(Pose(1.0, 2.0, math.pi), 0.3, 0.1).with_slices(math.radians(2))
    step = math.radians(2)
    for piece in start.slices:
        cell = math.floor(piece.lo / step + 1e-9)
        assert piece.lo >= cell * step - 1e-12
        assert piece.lo + piece.width <= (cell + 1) * step + 1e-12
        assert 0.0 <= piece.lo < TWO_PI
    assert start.wedge.center == pytest.approx(math.pi)
    assert start.wedge.width == pytest.approx(0.2)
    assert start.without_slices().wedge.width == pytest.approx(0.2)
    assert not start.without_slices().is_sliced


def test_with_slices_refuses_bad_arguments() -> None:
    start = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.3, 0.1)
    with pytest.raises(InputError, match=r"slice_width: expected radians in \(0, 2 pi\]"):
        start.with_slices(0.0)
    with pytest.raises(InputError, match="max_slices: expected"):
        start.with_slices(0.1, max_slices=0)


def test_with_slices_keeps_a_map_already_on_that_grid() -> None:
    sliced = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.3, 0.1).with_slices(0.05, 10)
    assert sliced.with_slices(0.05, 10) is sliced
    assert sliced.with_slices(0.1, 10).slice_width == pytest.approx(TWO_PI / 63)
    assert sliced.max_slices == 10
    assert sliced.slice_width == pytest.approx(TWO_PI / 126)


def test_summary_wedge_leaves_out_the_widest_gap() -> None:
    wedge = HeadingWedge._trusted(*summary_wedge([0.1, 3.5, 5.0], [0.2, 3.6, 5.1], 0.15))
    # Widest gap: 0.2 .. 3.5 (the wrap 5.1 .. 0.1 is narrower); the wedge runs from 3.5 round to 0.2.
    assert wedge.width == pytest.approx(TWO_PI - 3.3)
    assert wedge.contains(0.15)
    assert wedge.contains(3.55)
    assert wedge.contains(6.0)
    assert not wedge.contains(1.5)
    every = [k * 0.5 for k in range(13)]
    assert HeadingWedge._trusted(*summary_wedge(every, [k + 0.5 for k in every], 1.0)).is_full_circle


def pieces_of(
    polygons: list[np.ndarray],
    starts: list[float],
    stops: list[float],
    cells: int,
    max_vertices: int,
    cap: int,
) -> tuple[SliceSet, HeadingWedge]:
    """Distribute pieces, each its own source, with the summary centred on the first piece's start."""
    points = np.concatenate(polygons)
    counts = np.array([len(p) for p in polygons], dtype=np.int64)
    sources = np.arange(len(polygons), dtype=np.int64)
    return distributed(
        points,
        counts,
        np.array(starts),
        np.array(stops),
        sources,
        cells,
        max_vertices,
        cap,
        starts[0] % TWO_PI,
    )


def test_distribute_gives_a_piece_to_every_cell_it_meets() -> None:
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    other = square + 5.0
    cells = 4  # quarter turns
    found, _ = pieces_of([square, other], [-0.1, 0.1], [0.2, 1.7], cells, 16, 48)
    assert [round(lo, 3) for lo in found.lo.tolist()] == [0.0, 1.571, 6.183]
    # Cell 0 holds both pieces: their hull; cell 1 only the second; cell 3 only the first.
    polygons = found.polygons()
    assert ConvexPolygon(polygons[0]).area == pytest.approx(11.0)
    assert np.array_equal(polygons[1], other)
    assert np.array_equal(polygons[2], square)
    assert found.hi[2] == pytest.approx(TWO_PI)
    assert len(pieces_of([square], [0.0], [7.0], cells, 16, 48)[0].lo) == cells


def test_capped_merges_neighbours_into_an_outer_bound(rng: np.random.Generator) -> None:
    polygons = [rng.normal(size=(1, 2)) + np.array([[k, 0.0]]) for k in range(20)]
    starts = [k * 0.1 for k in range(20)]
    few, _ = pieces_of(polygons, starts, [start + 0.05 for start in starts], 63, 8, 6)
    assert len(few.lo) <= 6
    held = few.polygons()
    for polygon, start in zip(polygons, starts, strict=True):
        holder = [k for k in range(len(few.lo)) if few.lo[k] <= start and start + 0.05 <= few.hi[k]]
        assert len(holder) == 1
        assert ConvexPolygon(held[holder[0]]).contains(polygon).all()
        assert len(held[holder[0]]) <= 8


@given(st.floats(-20.0, 20.0), st.floats(0.0, 0.5), st.floats(0.0, 6.0), st.floats(0.001, 3.0))
def test_narrowed_keeps_the_arc_inside_the_slice(
    arc_lo: float, arc_width: float, lo: float, span: float
) -> None:
    hi = lo + span
    new_lo, new_hi = narrowed(arc_lo, arc_width, lo, hi)
    assert lo - 1e-12 <= new_lo <= new_hi <= hi + 1e-12
    # Every heading of the slice that is in the arc stays.
    for where in np.linspace(0.0, 1.0, 11):
        heading = lo + where * span
        in_arc = (heading - arc_lo) % TWO_PI <= arc_width
        if in_arc and span <= math.pi:
            assert new_lo - 1e-9 <= heading <= new_hi + 1e-9


# --- growth --------------------------------------------------------------------------


@pytest.mark.parametrize("batched", [False, True], ids=["one by one", "batched"])
def test_growth_keeps_every_true_pose(rng: np.random.Generator, batched: bool) -> None:
    kept = total = 0
    for _ in range(40):
        current = coupled_prior(rng)
        terrain = random_terrain(rng)
        poses = current.sample_poses(60, rng)
        commands = [random_command(rng) for _ in range(int(rng.integers(1, 4)))]
        for command in commands:
            poses = terrain.sample_motions(poses, command, rng, truncate=3.0)
        if batched:
            current = current._grow_many(commands, terrain, 3.0)
        else:
            for command in commands:
                current = current.grow(command, terrain)
        assert current.is_sliced
        assert len(current.slices) <= (current.max_slices or 0)
        assert all(len(piece.polygon.vertices) <= 64 for piece in current.slices)
        assert current.polygon.contains(current.center[None, :])[0]
        assert current.wedge.contains(current.wedge.center)
        kept += int(np.sum(current.contains(poses[:, 0], poses[:, 1], poses[:, 2])))
        total += len(poses)
    assert kept == total


def test_growth_is_tighter_than_the_product_map_after_a_turning_run() -> None:
    start = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.2, math.radians(20))
    terrain = TerrainTable.default()["concrete"]
    product, sliced = start, start.with_slices(math.radians(2))
    for command in [TurnAndRun(0.0, 5.0), TurnAndRun(0.5, 5.0)]:
        product, sliced = product.grow(command, terrain), sliced.grow(command, terrain)
    # A wide wedge swept over every position: the product map is much larger.
    assert sliced.area < 0.8 * product.area


# --- reductions ----------------------------------------------------------------------


@pytest.mark.parametrize(
    "make_cases", [class_one_cases, class_two_cases, class_three_cases], ids=["I", "II", "III"]
)
def test_reduction_keeps_every_true_pose_and_stays_inside(
    rng: np.random.Generator, make_cases: MakeCase
) -> None:
    kept = total = shrunk = 0
    for _ in range(50):
        prior = coupled_prior(rng)
        poses = prior.sample_poses(12, rng)
        for pose, (observation, landmark) in zip(poses, make_cases(rng, prior, poses), strict=True):
            reduction = prior.reduce(observation, landmark)
            assert reduction.consistent
            kept += bool(reduction.map.contains(Pose(*pose.tolist())))
            total += 1
            assert reduction.map.is_sliced
            assert inside_prior(reduction.map, prior, rng), (prior, observation, landmark)
            assert reduction.map.contains(reduction.map.most_probable_pose())
            shrunk += reduction.area_after < reduction.area_before or len(reduction.map.slices) < len(
                prior.slices
            )
    assert kept == total
    assert shrunk > total // 3


def test_empty_slices_drop_out() -> None:
    prior = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.5, math.radians(30))
    sliced = prior.with_slices(math.radians(2))
    edge = GroundLineLandmark("edge", (-10.0, -2.0), (10.0, -2.0))
    # The line seen at -20 degrees (+-1): only headings near +20 degrees agree.
    seen = sliced.reduce(
        GroundLineObservation("edge", 0.0, 2.0, 0.6, math.radians(-20), math.radians(1)), edge
    )
    assert seen.consistent
    assert len(seen.map.slices) < len(sliced.slices)
    assert seen.map.wedge.width <= math.radians(2.0) + 1e-6
    assert seen.map.contains(Pose(0.0, 0.0, math.radians(20)))
    assert not seen.map.contains(Pose(0.0, 0.0, 0.0))


def test_every_slice_empty_is_inconsistent() -> None:
    sliced = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.5, math.radians(30)).with_slices()
    pole = VerticalLineLandmark("pole", 10.0, 0.0, 0.0, 4.0)
    behind = sliced.reduce(BearingObservation("pole", 0.0, math.pi, 0.01), pole)
    assert not behind.consistent
    assert behind.map is sliced
    assert behind.reason == "no position of the map is consistent with the observation"


def test_a_bearing_from_a_slice_is_a_narrow_cone() -> None:
    # Heading open +-30 degrees, position 3 m wide: the product cone is 60 degrees wide,
    # the slices' cones 2 degrees each, and a range cuts each to a small arc piece.
    start = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 3.0, math.radians(30))
    corner = PointLandmark("corner", 10.0, 0.0, 1.0)
    seen = RangeBearingObservation("corner", 0.0, 0.0, math.radians(1), 9.5, 10.5)
    product = start.reduce(seen, corner)
    sliced = start.with_slices(math.radians(2)).reduce(seen, corner)
    assert sliced.map.contains(Pose(0.0, 0.0, 0.0))
    assert product.map.contains(Pose(0.0, 0.0, 0.0))
    assert sliced.area_after <= product.area_after + 1e-9
    # The sliced map knows that looking left means standing to the right of the line of sight.
    left = math.radians(10)
    assert not sliced.map.contains(Pose(0.0, 2.0, left))
    assert sliced.map.contains(Pose(10.0 - 9.8 * math.cos(left), -9.8 * math.sin(left), left))


def test_joint_reduction_of_a_sliced_map_is_slice_by_slice() -> None:
    truth = Pose(3.0, 4.0, 1.0)
    lost = SpatialUncertaintyMap.from_pose(Pose(5.0, 5.0, 0.0), 15.0, math.pi).with_slices(math.radians(2))
    poles = [
        VerticalLineLandmark("a", 12.0, 4.0, 0.0, 5.0),
        VerticalLineLandmark("b", 3.0, 14.0, 0.0, 5.0),
        VerticalLineLandmark("c", -4.0, 2.0, 0.0, 5.0),
    ]
    sightings = [
        (BearingObservation(p.id, 0.0, math.atan2(p.y - truth.y, p.x - truth.x) - truth.heading, 0.02), p)
        for p in poles
    ]
    joint = reduce_jointly(lost, sightings)
    assert joint.consistent
    assert joint.map.is_sliced
    assert joint.map.contains(truth)
    assert joint.area_after < 0.05 * joint.area_before
    assert joint.map.wedge.width < 0.3
    ahead = [(BearingObservation(p.id, 0.0, 0.0, 0.02), p) for p in poles]
    assert not reduce_jointly(lost, ahead).consistent


def test_split_product_of_a_full_circle_covers_every_cell() -> None:
    slices, wedge = split_product(np.zeros((1, 2)), 1.0, TWO_PI, 12, 48, 1.0)
    assert len(slices.lo) == 12
    assert slices.lo[0] == 0.0
    assert slices.hi[-1] == pytest.approx(TWO_PI)
    assert wedge.is_full_circle


def test_sliced_map_repr_and_product_slices() -> None:
    start = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.3, 0.1)
    assert "slices=" in repr(start.with_slices())
    (only,) = start.slices
    assert only.width == pytest.approx(0.2)
    assert only.polygon is start.polygon
    assert isinstance(only.wedge, HeadingWedge)
    assert start.slice_width is None
    assert start.max_slices is None


def test_a_distribution_over_its_cell_budget_merges_neighbours_into_an_outer_bound(
    monkeypatch: pytest.MonkeyPatch, rng: np.random.Generator
) -> None:
    """Every slice grown over a wide interval covers many cells: past the budget, neighbours merge first.

    0.1 degree cells over +-1.5 rad took 23 s for one growth before; at 1 degree with a small
    budget here, the merged map must hold every sampled true motion, and not much looser.
    """
    import aura_ums.uncertainty._slices as slices_module

    terrain = TerrainStats(0.0, 0.0, 0.0, 0.1, 0.0, 0.0, 0.0, 0.0)  # drift: +-1 rad over 10 m
    start = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 1.0, math.pi).with_slices(
        math.radians(1.0), 360
    )
    command = TurnAndRun(0.0, 10.0)
    exact = start.grow(command, terrain)
    monkeypatch.setattr(slices_module, "CELL_ROW_BUDGET", 4_000)
    within = slices_module._within_budget
    pieces: list[tuple[int, int]] = []

    def spy(*args: Any) -> Any:
        found = within(*args)
        pieces.append((len(args[1]), len(found[1])))
        return found

    monkeypatch.setattr(slices_module, "_within_budget", spy)
    merged = start.grow(command, terrain)
    assert any(after < before for before, after in pieces)  # the budget did bite
    assert len(merged.slices) <= len(exact.slices)
    # Both are outer bounds (each cell's hull is capped at 64 vertices, outwards), not nested.
    assert merged.area <= 1.5 * exact.area
    truths = terrain.sample_motions(start.sample_poses(4000, rng), command, rng, truncate=3.0)
    assert np.all(merged.contains(truths[:, 0], truths[:, 1], truths[:, 2]))


@pytest.mark.parametrize(
    ("width", "match"),
    [
        (math.nan, "slice_width: expected a finite number, got nan"),
        (math.inf, "slice_width: expected a finite number, got inf"),
        (None, "slice_width: expected a finite number, got None"),
    ],
)
def test_cell_count_refuses_what_is_not_a_width(width: object, match: str) -> None:
    with pytest.raises(InputError, match=match):
        cell_count(width)  # type: ignore[arg-type]


def test_with_slices_caps_the_slice_cap() -> None:
    start = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.1, 0.01)
    with pytest.raises(
        InputError, match=r"max_slices: expected at most 100000 slices .*, got 9223372036854775808"
    ):
        start.with_slices(0.035, 2**63)
    assert len(start.with_slices(0.035, 100_000).slices) == len(start.with_slices(0.035).slices)
