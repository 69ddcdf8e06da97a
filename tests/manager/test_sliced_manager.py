"""The manager with heading-sliced maps: the setting decides its form; saving keeps the slices."""

from __future__ import annotations

import json
import math
from typing import Any

import pytest

from aura_ums.errors import FileFormatError
from aura_ums.manager import ManagerSettings, UncertaintyMapManager
from aura_ums.uncertainty import Pose, SpatialUncertaintyMap
from aura_ums.uncertainty._slices import DEFAULT_MAX_SLICES
from tests.manager.test_map_manager import (
    POLE_NORTH,
    START,
    STRIDE,
    TABLE,
    WORLD,
    assert_same_map,
    bearing_of,
    board_with,
    manager_for,
    start_map,
)

WIDTH = math.radians(2.0)


def sliced_manager(**settings: Any) -> UncertaintyMapManager:
    return manager_for(slice_width=WIDTH, max_slices=30, **settings)


def test_the_setting_decides_the_map_form() -> None:
    assert sliced_manager().map.is_sliced
    assert sliced_manager().map.max_slices == 30
    assert not manager_for().map.is_sliced
    # A sliced map handed to a product-map manager is taken back to its summary.
    assert not manager_for(start_map().with_slices(WIDTH)).map.is_sliced
    manager = sliced_manager()
    manager.relocalize(SpatialUncertaintyMap.from_pose(START, 1.0, 0.5))
    assert manager.map.is_sliced


def test_a_sliced_manager_keeps_the_truth_and_is_no_looser() -> None:
    truth = Pose(START.x + 3 * STRIDE.run * 0.975, START.y, START.heading)
    observations = (bearing_of(truth, POLE_NORTH, 3.0),)
    reports = [(1.0, STRIDE), (2.0, STRIDE), (3.0, STRIDE)]
    sliced, product = sliced_manager(robust=True), manager_for(robust=True)
    for manager in (sliced, product):
        step = manager.update(board_with(*reports, observations=observations), now=3.0)
        assert step.outcomes[0].accepted
    # The envelope, the fallback, stays a product map.
    assert sliced.map.is_sliced
    assert sliced.envelope_map is not None
    assert not sliced.envelope_map.is_sliced
    assert sliced.map.area <= product.map.area * 1.01


def test_save_and_resume_keeps_the_slices_bit_for_bit() -> None:
    manager = sliced_manager(robust=True)
    manager.update(board_with((1.0, STRIDE), (2.0, STRIDE)), now=2.0)
    again = UncertaintyMapManager.from_json(manager.to_json(), WORLD, TABLE)
    assert again.map.is_sliced
    assert_same_map(again.map, manager.map)
    assert [(s.lo, s.width, s.polygon.vertices.tobytes()) for s in again.map.slices] == [
        (s.lo, s.width, s.polygon.vertices.tobytes()) for s in manager.map.slices
    ]
    assert again.to_json() == manager.to_json()
    # And both go on alike.
    later = board_with((1.0, STRIDE), (2.0, STRIDE), (3.0, STRIDE))
    for m in (manager, again):
        m.update(later, now=3.0)
    assert again.to_json() == manager.to_json()


def test_a_corrupt_slice_is_refused_naming_its_place() -> None:
    manager = sliced_manager()
    data = json.loads(manager.to_json())
    data["map"]["slices"]["pieces"][0]["lo"] = -1.0
    with pytest.raises(FileFormatError, match=r"map\.slices: .*expected lo in \[0, 2 pi\)"):
        UncertaintyMapManager.from_json(json.dumps(data), WORLD, TABLE)
    data = json.loads(manager.to_json())
    data["map"]["slices"]["pieces"] = []
    with pytest.raises(FileFormatError, match=r"map\.slices: slices: expected 1 to 30 heading slices, got 0"):
        UncertaintyMapManager.from_json(json.dumps(data), WORLD, TABLE)
    data = json.loads(manager.to_json())
    del data["map"]["slices"]["max_slices"]
    with pytest.raises(FileFormatError, match="expected a key 'max_slices'"):
        UncertaintyMapManager.from_json(json.dumps(data), WORLD, TABLE)


def test_settings_of_slices_are_checked() -> None:
    assert ManagerSettings().max_slices == DEFAULT_MAX_SLICES
    assert ManagerSettings().slice_width is None  # the paper's product map unless asked
    with pytest.raises(ValueError, match=r"slice_width: expected a number in \(0, 2 pi\] or none"):
        ManagerSettings(slice_width=0.0)
    with pytest.raises(ValueError, match="max_slices: expected an integer >= 1"):
        ManagerSettings(max_slices=0)
