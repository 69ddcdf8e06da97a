from __future__ import annotations

import dataclasses

import pytest

from aura_ums import InputError
from aura_ums.world import (
    LandmarkRecord,
    MeadowMap,
    ShortTermMemory,
    make_grid_world,
    plan_route,
    sample_world,
)


@pytest.fixture
def grid() -> MeadowMap:
    return make_grid_world(5, 8, cell=5.0)


def test_leg_instantiates_traversed_meadows_in_order(grid: MeadowMap) -> None:
    stm = ShortTermMemory.for_leg(grid, (7.5, 12.5), (27.5, 12.5), nearby=0.0)
    assert stm.traversed == ("cell_2_1", "cell_2_2", "cell_2_3", "cell_2_4", "cell_2_5")
    assert stm.meadow_ids[: len(stm.traversed)] == stm.traversed
    assert stm.leg == ((7.5, 12.5), (27.5, 12.5))
    # Reversed, the order along the leg reverses.
    back = ShortTermMemory.for_leg(grid, (27.5, 12.5), (7.5, 12.5), nearby=0.0)
    assert back.traversed == stm.traversed[::-1]


def test_adjacent_and_nearby_meadows_are_instantiated_too(grid: MeadowMap) -> None:
    adjacent = ShortTermMemory.for_leg(grid, (7.5, 12.5), (27.5, 12.5), nearby=0.0)
    rows = {int(ident.split("_")[1]) for ident in adjacent.meadow_ids}
    cols = {int(ident.split("_")[2]) for ident in adjacent.meadow_ids}
    assert (rows, cols) == ({1, 2, 3}, {0, 1, 2, 3, 4, 5, 6})
    assert len(adjacent.meadows) == 3 * 7 - 4  # diagonal corners only touch at a point
    assert adjacent.meadow_ids[:5] == adjacent.traversed
    # Nearby ones join by distance to the leg: the diagonal corners at 2.5 * sqrt(2) m.
    near = ShortTermMemory.for_leg(grid, (7.5, 12.5), (27.5, 12.5), nearby=3.6)
    assert set(near.meadow_ids) - set(adjacent.meadow_ids) == {"cell_1_0", "cell_3_0", "cell_1_6", "cell_3_6"}
    far = ShortTermMemory.for_leg(grid, (7.5, 12.5), (27.5, 12.5), nearby=8.0)
    assert set(near.meadow_ids) < set(far.meadow_ids)
    assert "cell_0_3" in far.meadow_ids
    assert "cell_0_7" not in far.meadow_ids
    # Nearby meadows come in order of distance: the corners (3.5 m) before row 0 (7.5 m).
    assert far.meadow_ids.index("cell_1_0") < far.meadow_ids.index("cell_0_3")


def test_adjacent_meadows_join_however_far_from_the_leg() -> None:
    world = make_grid_world(1, 3, cell=50.0)
    stm = ShortTermMemory.for_leg(world, (10.0, 25.0), (12.0, 25.0), nearby=1.0)
    assert stm.traversed == ("cell_0_0",)
    assert stm.meadow_ids == ("cell_0_0", "cell_0_1")


def test_landmarks_are_those_visible_from_instantiated_meadows(grid: MeadowMap) -> None:
    stm = ShortTermMemory.for_leg(grid, (7.5, 12.5), (27.5, 12.5), nearby=0.0)
    expected: list[str] = []
    for meadow in stm.meadows:
        expected.extend(i for i in meadow.landmark_ids if i not in expected)
    assert stm.landmark_ids == tuple(expected)
    assert len(set(stm.landmark_ids)) == len(stm.landmark_ids)
    assert all(isinstance(r, LandmarkRecord) for r in stm.landmarks)
    # Poles seen only from far meadows are not candidates.
    assert "pole_0_8" not in stm.landmark_ids
    assert "pole_4_8" in grid.meadow("cell_3_7").landmark_ids
    assert "cell_3_7" not in stm.meadow_ids
    assert "pole_4_8" not in stm.landmark_ids


def test_zero_length_leg_and_legs_off_the_map(grid: MeadowMap) -> None:
    turn = ShortTermMemory.for_leg(grid, (12.5, 12.5), (12.5, 12.5), nearby=0.0)
    assert turn.traversed == ("cell_2_2",)
    corner = ShortTermMemory.for_leg(grid, (10.0, 10.0), (10.0, 10.0), nearby=0.0)
    assert corner.traversed == ("cell_1_1", "cell_1_2", "cell_2_1", "cell_2_2")
    away = ShortTermMemory.for_leg(grid, (100, 100), (120, 100), nearby=5.0)
    assert (away.meadows, away.landmarks, away.traversed) == ((), (), ())
    edge = ShortTermMemory.for_leg(grid, (-3.0, 2.5), (-1.0, 2.5), nearby=1.0)
    assert edge.traversed == ()
    assert edge.meadow_ids == ("cell_0_0",)


def test_corridor_leg_sees_doors_walls_and_the_lobby() -> None:
    world = sample_world("indoor_corridor")
    stm = ShortTermMemory.for_leg(world, (1.0, 1.2), (29.0, 1.2), nearby=1.5)
    assert stm.traversed == ("corridor_west", "corridor_middle", "corridor_east")
    assert {"door_101", "door_102", "door_103", "lobby", "room_101", "room_102", "room_103"} <= set(
        stm.meadow_ids
    )
    assert {"corridor_north_wall_base", "door_101_west_edge", "exit_sign_corner"} <= set(stm.landmark_ids)
    (start, end), *_ = plan_route(world, (1.0, 1.2), (29.0, 1.2)).legs
    first = ShortTermMemory.for_leg(world, start, end, nearby=0.5)
    assert first.traversed == ("corridor_west",)
    assert first.meadow_ids == ("corridor_west", "corridor_middle", "door_101")
    assert "exit_sign_corner" not in first.landmark_ids  # seen only from the corridor's far end


def test_stm_is_a_frozen_value(grid: MeadowMap) -> None:
    stm = ShortTermMemory.for_leg(grid, (1, 1), (9, 1))
    assert stm == ShortTermMemory.for_leg(grid, (1, 1), (9, 1))
    assert hash(stm) == hash(ShortTermMemory.for_leg(grid, (1, 1), (9, 1)))
    with pytest.raises(dataclasses.FrozenInstanceError, match="cannot assign"):
        stm.nearby = 3.0  # type: ignore[misc]


def test_stm_validates_its_arguments(grid: MeadowMap) -> None:
    with pytest.raises(InputError, match=r"nearby: expected a non-negative number, got -1\.0"):
        ShortTermMemory.for_leg(grid, (1, 1), (9, 1), nearby=-1.0)
    with pytest.raises(InputError, match=r"end: expected an \(n, 2\) array, got shape \(3,\)"):
        ShortTermMemory.for_leg(grid, (1, 1), (9, 1, 2))
    with pytest.raises(InputError, match="meadow_map: expected a MeadowMap, got dict"):
        ShortTermMemory.for_leg({}, (1, 1), (9, 1))  # type: ignore[arg-type]
    with pytest.raises(InputError, match="traversed: expected ids of the instantiated meadows, got 'x'"):
        ShortTermMemory(((0, 0), (1, 0)), (), ("x",), (), 1.0)
    with pytest.raises(InputError, match=r"meadows\[0\]: expected a Meadow, got str"):
        ShortTermMemory(((0, 0), (1, 0)), ("m",), (), (), 1.0)  # type: ignore[arg-type]
