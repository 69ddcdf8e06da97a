"""Landmarks found where another mapped landmark may appear: withheld, and counted in the metrics."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from aura_ums.schemas import SchemaManager, StepReport
from aura_ums.sim import Scenario, run_scenario, summarize_runs

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


def _pole(name: str, x: float, y: float) -> dict[str, object]:
    return {
        "type": "Feature",
        "geometry": {"type": "Point", "coordinates": [x, y]},
        "properties": {
            "kind": "landmark", "id": name, "class": "I", "symbol": "pole", "position_uncertainty": 0.05,
            "strategy": "line_finder", "activation_range": 25.0, "recognition_threshold": 300.0,
            "z_bottom": 0.0, "z_top": 4.0,
        },
    }  # fmt: skip


@pytest.fixture(scope="module")
def clustered(tmp_path_factory: pytest.TempPathFactory) -> Scenario:
    """Five poles 0.2-0.3 m apart beside a 30 m route: each found pole may be any of them."""
    folder = tmp_path_factory.mktemp("cluster")
    names = [f"c{i}" for i in range(5)]
    field = {
        "type": "Feature",
        "geometry": {"type": "Polygon", "coordinates": [[[-5, -5], [40, -5], [40, 5], [-5, 5], [-5, -5]]]},
        "properties": {"kind": "meadow", "id": "field", "terrain": "concrete", "landmarks": names},
    }
    poles = [_pole(name, 12.0 + 0.3 * i, 2.5 + 0.2 * i) for i, name in enumerate(names)]
    (folder / "map.geojson").write_text(
        json.dumps({"type": "FeatureCollection", "features": [field, *poles]})
    )
    (folder / "cluster.toml").write_text(
        'name = "cluster"\nmap = "map.geojson"\nterrain = "default"\n'
        f"camera = {json.dumps(str(SCENARIOS / 'paper_camera.toml'))}\n"
        f"landmarks = {json.dumps(names)}\nframe_spacing = 2.0\n"
        "[start]\nx = 0.0\ny = 0.0\nheading_deg = 0.0\nposition_radius = 0.3\nheading_halfwidth_deg = 3.0\n"
        "[route]\ngoal = [30.0, 0.0]\n[render]\npole_radius = 0.05\n"
    )
    return Scenario.from_toml(folder / "cluster.toml")


def test_withheld_identifications_are_counted(clustered: Scenario, monkeypatch: pytest.MonkeyPatch) -> None:
    # 52 withheld in five runs, and the metrics said only: detection rate 0.82, 0 accepted.
    withheld: list[str] = []
    step = SchemaManager.step

    def counted(self: SchemaManager, *args: object, **kwargs: object) -> StepReport:
        report = step(self, *args, **kwargs)  # type: ignore[arg-type]
        withheld.extend(report.ambiguous)
        return report

    monkeypatch.setattr(SchemaManager, "step", counted)
    results = [run_scenario(clustered, rng) for rng in np.random.default_rng(2).spawn(3)]
    metrics = summarize_runs(results)
    assert metrics["ambiguous_identifications"] == len(withheld) > 0
    assert metrics["accepted_observations"] == 0
    assert sum(record.ambiguous for result in results for record in result.records) == len(withheld)
