"""union_of_maps: an outer bound of the union of maps, its primary's centre and heading kept."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums.errors import InputError
from aura_ums.geometry import ConvexPolygon, HeadingWedge
from aura_ums.uncertainty import Pose, SpatialUncertaintyMap, union_of_maps, union_of_wedges

maps = st.builds(
    lambda x, y, heading, radius, half: SpatialUncertaintyMap.from_pose(Pose(x, y, heading), radius, half),
    st.floats(-50.0, 50.0),
    st.floats(-50.0, 50.0),
    st.floats(-math.pi, math.pi),
    st.floats(0.0, 5.0),
    st.floats(0.0, 3.5),
)


@given(st.lists(maps, min_size=1, max_size=6), st.integers(0, 2**32 - 1), st.integers(3, 64))
def test_every_pose_of_every_map_is_inside_the_union(
    parts: list[SpatialUncertaintyMap], seed: int, cap: int
) -> None:
    rng = np.random.default_rng(seed)
    union = union_of_maps(parts, max_vertices=cap)
    assert union.polygon.vertex_count <= max(cap, parts[0].polygon.vertex_count)
    for part in parts:
        poses = np.vstack([part.sample_poses(50, rng), np.column_stack([part.polygon.vertices, np.zeros(
            part.polygon.vertex_count
        ) + part.wedge.center])])  # fmt: skip
        assert np.all(union.polygon.contains(poses[:, :2], tolerance=1e-9))
        assert np.all(union.wedge.contains(poses[:, 2]))
        for end in (part.wedge.center - part.wedge.cw, part.wedge.center + part.wedge.ccw):
            assert union.wedge.contains(end)
    assert union.most_probable_pose() == parts[0].most_probable_pose()


@given(maps, maps)
def test_the_union_is_idempotent_and_not_much_larger_than_the_hull(
    first: SpatialUncertaintyMap, second: SpatialUncertaintyMap
) -> None:
    union = union_of_maps([first, second])
    again = union_of_maps([union, union])
    hull = ConvexPolygon.from_points(np.vstack([first.polygon.vertices, second.polygon.vertices]))
    # The lines are pushed out by 4e-6 of the coordinates' size: a band along the perimeter.
    scale = max(1.0, float(np.abs(union.polygon.vertices).max()))
    sides = np.roll(union.polygon.vertices, -1, axis=0) - union.polygon.vertices
    perimeter = float(np.hypot(sides[:, 0], sides[:, 1]).sum())
    band = 1.2 * perimeter * 4e-6 * scale + 4 * (4e-6 * scale) ** 2
    # Fixed directions: taking the union twice adds the margin's band only.
    assert again.area <= union.area + band
    # A bulge over each hull edge: a triangle of at most length^2 tan(pi / 64) / 4 (64 directions).
    edges = np.roll(hull.vertices, -1, axis=0) - hull.vertices
    bulges = float(np.sum(edges**2)) * math.tan(math.pi / 64) / 4
    assert union.area <= hull.area + bulges + band


def test_the_shortest_arc_holds_every_wedge_across_the_seam() -> None:
    wedges = [HeadingWedge(3.0, 0.1, 0.1), HeadingWedge(-3.0, 0.1, 0.1), HeadingWedge(math.pi, 0.0, 0.0)]
    union = union_of_wedges(wedges, 3.0)
    assert union.width == pytest.approx(2 * math.pi - 6.0 + 0.2)
    assert union.center == 3.0
    # Three wedges spread round the circle: the shortest arc skips the largest gap.
    spread = [HeadingWedge(0.0, 0.1, 0.1), HeadingWedge(2.0, 0.1, 0.1), HeadingWedge(-2.0, 0.1, 0.1)]
    assert union_of_wedges(spread, 0.0).width == pytest.approx(4.2)


def test_bad_arguments_are_refused() -> None:
    one = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 1.0, 0.1)
    with pytest.raises(InputError, match=r"maps\[1\]: expected a SpatialUncertaintyMap, got str"):
        union_of_maps([one, "map"])  # type: ignore[list-item]
    with pytest.raises(InputError, match=r"max_vertices: expected an integer >= 3, got 2"):
        union_of_maps([one], max_vertices=2)


def test_the_union_of_sliced_maps_keeps_their_slices_and_every_pose() -> None:
    rng = np.random.default_rng(7)
    east = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.3), 0.5, 0.2).with_slices(math.radians(4.0))
    west = SpatialUncertaintyMap.from_pose(Pose(3.0, 1.0, 1.2), 0.4, 0.1)
    union = union_of_maps([east, west])
    assert union.is_sliced
    for member in (east, west):
        for x, y, heading in member.sample_poses(300, rng).tolist():
            assert union.contains(x, y, heading)
    # Sliced, the union keeps position and heading coupled: a pose with east's position and
    # west's heading lies in the product hull but not in the union.
    assert union.polygon.contains(np.array([[0.0, 0.0]]))[0]
    assert not union.contains(0.0, 0.0, 1.2)
    assert union.area <= union_of_maps([east.without_slices(), west]).area + 1e-9


def test_union_of_maps_caps_the_vertex_cap() -> None:
    start = SpatialUncertaintyMap.from_pose(Pose(2.5, 2.5, 0.0), 0.1, 0.01)
    other = SpatialUncertaintyMap.from_pose(Pose(3.0, 2.5, 0.0), 0.1, 0.01)
    with pytest.raises(
        InputError, match=r"max_vertices: expected at most 100000 .*got 1000000000000 \(about 1e\+05 GB\)"
    ):
        union_of_maps([start, other], max_vertices=10**12)
    with pytest.raises(InputError, match="max_vertices: expected at most 100000"):
        union_of_maps([start, other], max_vertices=2**63)


@pytest.mark.parametrize(
    ("wedges", "center", "match"),
    [
        ([], 0.0, "wedges: expected at least one HeadingWedge, got none"),
        (None, 0.0, "wedges: expected a sequence of HeadingWedge, got NoneType"),
        ([None], 0.0, r"wedges\[0\]: expected a HeadingWedge, got NoneType"),
        ([HeadingWedge(0.0, 0.1, 0.1)], None, "center: expected a finite number, got None"),
        ([HeadingWedge(0.0, 0.1, 0.1)], math.inf, "center: expected a finite number, got inf"),
    ],
)
def test_union_of_wedges_refuses_bad_arguments(wedges: object, center: object, match: str) -> None:
    with pytest.raises(InputError, match=match):
        union_of_wedges(wedges, center)  # type: ignore[arg-type]
