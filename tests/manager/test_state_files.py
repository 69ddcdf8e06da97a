"""Saved manager and blackboard state read through the loading layer: BOM, strict JSON, size limit."""

from __future__ import annotations

import pytest

from aura_ums.errors import FileFormatError
from aura_ums.manager import Blackboard, PositionReport, UncertaintyMapManager
from aura_ums.uncertainty import BearingObservation, Pose, SpatialUncertaintyMap, TerrainTable, TurnAndRun
from aura_ums.world import make_grid_world

WORLD = make_grid_world(2, 2)
TABLE = TerrainTable.default()


def saved_manager() -> str:
    start = SpatialUncertaintyMap.from_pose(Pose(1.0, 1.0, 0.3), 0.2, 0.05)
    manager = UncertaintyMapManager(start, WORLD, TABLE)
    board = Blackboard()
    board.post_report(PositionReport(1.0, TurnAndRun(0.1, 0.5)))
    manager.update(board, now=1.0)
    return manager.to_json()


def saved_board() -> str:
    board = Blackboard()
    board.post_report(PositionReport(1.0, TurnAndRun(0.1, 0.5)))
    board.identified.post(BearingObservation("pole", 1.0, 0.2, 0.01))
    return board.to_json()


def test_state_with_a_byte_order_mark_restores_the_same() -> None:
    text = saved_manager()
    again = UncertaintyMapManager.from_json("\ufeff" + text, WORLD, TABLE, source="saved.json")
    assert again.to_json() == text
    board = saved_board()
    assert Blackboard.from_json("\ufeff" + board).to_json() == board


@pytest.mark.parametrize("constant", ["NaN", "Infinity", "-Infinity", "1e999"])
def test_non_finite_numbers_are_refused(constant: str) -> None:
    text = saved_manager().replace('"map_time": 1.0', f'"map_time": {constant}')
    assert text != saved_manager()
    with pytest.raises(
        FileFormatError, match=r"^saved\.json: expected valid JSON, got the (non-standard )?number"
    ):
        UncertaintyMapManager.from_json(text, WORLD, TABLE, source="saved.json")


def test_repeated_keys_are_refused() -> None:
    text = saved_board().replace('"commands": [', '"commands": [], "commands": [')
    with pytest.raises(
        FileFormatError, match=r"^board\.json: expected valid JSON, got the key 'commands' twice"
    ):
        Blackboard.from_json(text, source="board.json")


def test_state_over_the_size_limit_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr("aura_ums._files.MAX_BYTES", 100)
    with pytest.raises(
        FileFormatError, match=r"^saved\.json: expected at most 100 bytes of text, got \d+ characters$"
    ):
        UncertaintyMapManager.from_json(saved_manager(), WORLD, TABLE, source="saved.json")
