"""``after_frame``: a run hands each frame and its image on as it computes them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from aura_ums.errors import InputError
from aura_ums.sim import FrameRecord, Scenario, run_scenario

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


def test_each_frame_is_handed_on_with_its_image() -> None:
    scenario = Scenario.from_toml(SCENARIOS / "paper_sidewalk.toml")
    seen: list[tuple[FrameRecord, np.ndarray]] = []
    result = run_scenario(
        scenario, np.random.default_rng(4), keep_images=True, after_frame=lambda r, i: seen.append((r, i))
    )
    assert [record for record, _ in seen] == list(result.records)
    for (_, image), kept in zip(seen, result.images, strict=True):
        assert image is kept
        assert not image.flags.writeable
    # the hook changes nothing: the same seed without it gives the same run
    again = run_scenario(scenario, np.random.default_rng(4))
    assert [r.map_after.area for r in again.records] == [r.map_after.area for r in result.records]


def test_a_resumed_run_hands_on_only_its_own_frames() -> None:
    scenario = Scenario.from_toml(SCENARIOS / "paper_sidewalk.toml")
    half = run_scenario(scenario, np.random.default_rng(4), stop_after=2)
    seen: list[int] = []
    rest = run_scenario(
        scenario,
        np.random.default_rng(0),
        resume_from=half.saved,
        after_frame=lambda r, _: seen.append(r.index),
    )
    assert seen == [r.index for r in rest.records[2:]]


def test_a_hook_that_is_not_callable_is_refused() -> None:
    scenario = Scenario.from_toml(SCENARIOS / "paper_sidewalk.toml")
    with pytest.raises(InputError, match=r"after_frame: expected a callable or None, got int"):
        run_scenario(scenario, np.random.default_rng(0), after_frame=1)  # type: ignore[arg-type]
