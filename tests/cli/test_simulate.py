"""``aura-ums simulate``: Monte Carlo metrics as JSON, clean errors."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from typer.testing import CliRunner

from aura_ums import Metrics
from aura_ums.cli import app

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
KEYS = (
    "containment_rate",
    "median_area_m2",
    "median_wedge_width_rad",
    "landmark_detection_rate",
    "inconsistent_observations",
    "median_frame_ms",
)


def strict_json(text: str) -> Any:
    def refuse(constant: str) -> None:
        raise ValueError(f"not JSON: {constant}")

    return json.loads(text, parse_constant=refuse)


def test_simulate_writes_the_metrics(tmp_path: Path) -> None:
    out = tmp_path / "m.json"
    args = ["simulate", str(SCENARIOS / "paper_sidewalk.toml"), "--runs", "3", "--seed", "1"]
    result = CliRunner().invoke(app, [*args, "--metrics-json", str(out)])
    assert result.exit_code == 0, result.output
    metrics = strict_json(out.read_text())
    for key in KEYS:
        assert key in metrics
    # Exactly the keys the metrics table gives simulate, each printed on its own line.
    assert set(metrics) == {key.name for key in Metrics.table() if "simulate" in key.written_by}
    for key in metrics:
        assert f"\n{key} " in "\n" + result.output
    assert metrics["runs"] == 3
    assert metrics["prune"] is True
    again = tmp_path / "n.json"
    result = CliRunner().invoke(app, [*args, "--no-prune", "--metrics-json", str(again)])
    assert result.exit_code == 0, result.output
    assert strict_json(again.read_text())["accepted_observations"] == 0


def test_simulate_bad_input_is_a_clean_error(tmp_path: Path) -> None:
    result = CliRunner().invoke(app, ["simulate", str(tmp_path / "none.toml")])
    assert result.exit_code == 2
    assert "no such file" in result.output
    assert "Traceback" not in result.output
    bad = tmp_path / "bad.toml"
    bad.write_text('map = "sample:moon"\n')
    result = CliRunner().invoke(app, ["simulate", str(bad), "--runs", "1"])
    assert result.exit_code == 2
    assert "moon" in result.output
    assert "Traceback" not in result.output
    result = CliRunner().invoke(app, ["simulate", str(SCENARIOS / "paper_sidewalk.toml"), "--runs", "0"])
    assert result.exit_code == 2
    assert "--runs" in result.output


def test_simulate_refuses_too_many_runs_before_allocating() -> None:
    result = CliRunner().invoke(
        app, ["simulate", str(SCENARIOS / "paper_sidewalk.toml"), "--runs", "1000000000"]
    )
    assert result.exit_code == 2
    assert "--runs: expected an integer in [1, 100000], got 1000000000 (about" in result.output
    assert "Traceback" not in result.output
