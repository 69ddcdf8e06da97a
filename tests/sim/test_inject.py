"""Injected misidentifications in the closed loop: read from the scenario, counted, reproducible."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from aura_ums.errors import FileFormatError, InputError
from aura_ums.sim import Scenario, run_scenario, summarize_runs

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


@pytest.fixture(scope="module")
def paper() -> Scenario:
    return Scenario.from_toml(SCENARIOS / "paper_sidewalk.toml")


def test_a_zero_rate_draws_nothing_and_changes_nothing(paper: Scenario) -> None:
    plain = run_scenario(paper, np.random.default_rng(5))
    zero = run_scenario(dataclasses.replace(paper, inject_wrong_rate=0.0), np.random.default_rng(5))
    assert plain.final_map.polygon.vertices.tobytes() == zero.final_map.polygon.vertices.tobytes()
    assert all(record.injected == 0 and record.excluded == 0 for record in plain.records)


def test_every_identification_made_wrong_is_counted_and_the_relaxed_manager_excludes_them(
    paper: Scenario,
) -> None:
    settings = dataclasses.replace(paper.settings, relaxed_q=1, relaxed_window=4)
    always = dataclasses.replace(paper, inject_wrong_rate=1.0, settings=settings)
    results = [run_scenario(always, rng) for rng in np.random.default_rng(2).spawn(3)]
    metrics = summarize_runs(results)
    found = sum(len(record.posted) for result in results for record in result.records)
    assert metrics["injected_observations"] == found > 0
    # Swapped for another landmark of the map: each is excluded, or rejected by the gate.
    excluded = metrics["excluded_observations"]
    assert isinstance(excluded, int)
    assert excluded > 0
    again = [run_scenario(always, rng) for rng in np.random.default_rng(2).spawn(3)]
    assert summarize_runs(again)["excluded_observations"] == excluded


def test_the_rate_is_read_from_the_scenario_and_checked(paper: Scenario, tmp_path: Path) -> None:
    text = (SCENARIOS / "paper_sidewalk.toml").read_text(encoding="utf-8")
    camera = (SCENARIOS / "paper_camera.toml").read_text(encoding="utf-8")
    (tmp_path / "paper_camera.toml").write_text(camera, encoding="utf-8")
    good = tmp_path / "good.toml"
    good.write_text("inject_wrong_rate = 0.25\n" + text, encoding="utf-8")
    assert Scenario.from_toml(good).inject_wrong_rate == 0.25
    bad = tmp_path / "bad.toml"
    bad.write_text("inject_wrong_rate = 1.5\n" + text, encoding="utf-8")
    with pytest.raises(FileFormatError, match=r"inject_wrong_rate: expected a number in \[0, 1\], got 1.5"):
        Scenario.from_toml(bad)
    with pytest.raises(
        InputError, match=r"Scenario.inject_wrong_rate: expected a number in \[0, 1\], got -0.1"
    ):
        dataclasses.replace(paper, inject_wrong_rate=-0.1)
