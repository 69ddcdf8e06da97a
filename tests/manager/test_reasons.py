"""RejectReason: one member for every reason the manager rejects an observation."""

from __future__ import annotations

import ast
import json
from pathlib import Path

import pytest

import aura_ums
from aura_ums.errors import InputError, UnknownLandmarkError, UnknownTerrainError
from aura_ums.manager import Blackboard, RejectReason, UncertaintyMapManager
from aura_ums.uncertainty import (
    BearingObservation,
    Pose,
    SpatialUncertaintyMap,
    TerrainTable,
)
from aura_ums.uncertainty._joint import JOINT_INCONSISTENT
from aura_ums.world import sample_world

SOURCE = Path(aura_ums.__file__).parent


def reduction_reasons() -> set[str]:
    """Every text the reductions give for an empty intersection ("no ... of the map ...")."""
    found: set[str] = set()
    for folder in ("uncertainty", "_native"):
        for path in sorted((SOURCE / folder).glob("*.py")):
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, ast.Constant) and isinstance(node.value, str):
                    text = node.value
                    if text.startswith("no ") and " of the map " in text:
                        found.add(text)
    # A joint reduction that no heading agrees with is retaken one by one by the manager.
    found.discard(JOINT_INCONSISTENT)
    return found


def test_every_reason_a_reduction_gives_is_a_reject_reason() -> None:
    reasons = reduction_reasons()
    assert len(reasons) >= 5
    assert reasons <= {reason.value for reason in RejectReason}
    assert {reason.value for reason in RejectReason if reason.inconsistent} == reasons


def test_reasons_are_their_texts_wherever_a_string_is_expected() -> None:
    assert isinstance(RejectReason.STALE, str)
    assert f"{RejectReason.UNKNOWN_LANDMARK}" == "unknown landmark id"
    assert (
        json.dumps({RejectReason.CLASS_MISMATCH: 1})
        == '{"observation class differs from the landmark\'s": 1}'
    )
    with pytest.raises(InputError, match=r"^RejectReason: expected one of .*, got 'stale'$"):
        RejectReason("stale")


def test_an_unknown_landmark_has_its_own_error_and_its_own_reason() -> None:
    world = sample_world("paper_sidewalk")
    with pytest.raises(
        UnknownLandmarkError, match="landmark: expected the id of a landmark of this map"
    ) as info:
        world.landmark("lamppost_999")
    assert isinstance(info.value, KeyError)
    assert isinstance(info.value, InputError)
    assert not isinstance(info.value, UnknownTerrainError)
    start = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.3, 0.05)
    manager = UncertaintyMapManager(start, world, TerrainTable.default())
    board = Blackboard()
    board.identified.post(BearingObservation("lamppost_999", 0.0, 0.0, 0.01))
    (outcome,) = manager.update(board, now=0.0).outcomes
    assert outcome.reason is RejectReason.UNKNOWN_LANDMARK
    assert not outcome.reason.inconsistent
