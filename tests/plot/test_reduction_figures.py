from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from aura_ums.errors import InputError
from aura_ums.plot import draw_all_figures, draw_path_figure, run_down_path


def test_path_run_keeps_the_truth_and_beats_the_disk_model() -> None:
    # The paper's Figure 3: seeing the path edge keeps the polygon thin across the path,
    # while a disk around the centre that encloses it keeps growing.
    for seed in range(5):
        steps = run_down_path(np.random.default_rng(seed), steps=8)
        assert all(step.uncertainty_map.contains(step.truth) for step in steps)
        ratios = [step.uncertainty_map.area / step.disk_area for step in steps]
        assert max(ratios[2:]) < 0.5
        assert steps[-1].disk_area > steps[0].disk_area
        ys = steps[-1].uncertainty_map.polygon.vertices[:, 1]
        assert np.ptp(ys) < 0.5  # across the path: held by the edge observations


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"steps": 10**12}, r"steps: expected at most 10000 steps \(about 0.3 ms and 1 kB a step: 3 s\)"),
        ({"step_length": 1e300}, r"step_length: expected a number in \(0, 10000\] m, got 1e\+300"),
        ({"step_length": 0.0}, r"step_length: expected a number in \(0, 10000\] m, got 0.0"),
        (
            {"steps": 1000, "step_length": 1e4},
            r"steps, step_length: expected a path of at most 1e\+06 m \(the coordinate range\), got 1000 ",
        ),
    ],
)
def test_a_path_run_is_bounded(arguments: dict[str, float], message: str) -> None:
    with pytest.raises(InputError, match=message):
        run_down_path(np.random.default_rng(0), **arguments)  # type: ignore[arg-type]


def test_figure3_is_written(tmp_path: Path) -> None:
    path = draw_path_figure(tmp_path, np.random.default_rng(0))
    assert path.name == "figure3_disk_vs_polygon.png"
    assert path.read_bytes()[:4] == b"\x89PNG"


def test_all_figures(tmp_path: Path) -> None:
    names = sorted(path.name for path in draw_all_figures(tmp_path, seed=1))
    assert names == [
        "figure3_disk_vs_polygon.png",
        "figure4_top_view.png",
        "figure4_windows.png",
        "figure5_point_transform.png",
        "figure6_heading_wedge.png",
        "figure7_map_transform.png",
    ]
