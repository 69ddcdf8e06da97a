"""benchmarks/bench_real_logs.py: its core on a tiny synthetic log, so that the script cannot rot."""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np
import pytest

import bench_real_logs as bench
from aura_ums.camera import load_camera
from aura_ums.errors import AuraUmsError, InputError
from aura_ums.logs import Calibration, calibrate_logs, synthetic_log
from aura_ums.manager import ManagerSettings
from aura_ums.uncertainty import LandmarkClass

ROOT = Path(__file__).resolve().parents[2]
PARTICLES = 100


@pytest.fixture(scope="module")
def calibration() -> Calibration:
    return calibrate_logs([synthetic_log(np.random.default_rng(1), duration=60.0)])


@pytest.fixture(scope="module")
def runs(calibration: Calibration) -> list[bench.Run]:
    camera = load_camera(ROOT / "examples" / "virtual_camera_60deg.toml")
    log = synthetic_log(np.random.default_rng(2), duration=20.0)
    maps = bench.map_settings({}, {}, {})
    return [
        bench.measure(log, calibration, camera, landmark_class, maps, particles=PARTICLES, seed=0)
        for landmark_class in (LandmarkClass.VERTICAL_LINE, LandmarkClass.POINT)
    ]


def test_every_method_has_a_row_with_the_tables_figures(runs: list[bench.Run]) -> None:
    for run in runs:
        methods = [row["method"] for row in run.rows]
        assert set(bench.table_methods(PARTICLES)) <= set(methods)
        assert {"EKF", bench.DISK_MODEL} <= set(methods)
        for method in (bench.SLICED, bench.PRODUCT, bench.FILTERPY):
            row = run.row(method)
            for key, _, _ in bench.COLUMNS:
                assert not math.isnan(row.number(key)), (run.log, method, key)


def test_both_maps_keep_the_truth_and_its_projection_on_a_sound_log(runs: list[bench.Run]) -> None:
    # The synthetic log's noise lies inside its bounds: containment below 1 is a bug.
    for run in runs:
        for method in (bench.SLICED, bench.PRODUCT):
            assert run.row(method)["containment_rate"] == 1.0, (run.log, method)
            assert run.row(method)["window_truth_containment"] == 1.0, (run.log, method)


def test_the_figure_series_are_the_judged_windows(runs: list[bench.Run]) -> None:
    run = runs[1]
    assert [series.method for series in run.series] == [bench.PRODUCT, bench.SLICED, bench.EKF_BOX]
    for series in run.series:
        assert series.time.size == series.width_frac.size > 0
        assert series.time[0] == 0.0
        assert np.all(np.diff(series.time) >= 0.0)
    widths = {series.method: float(np.median(series.width_frac)) for series in run.series}
    assert widths[bench.SLICED] == run.row(bench.SLICED)["median_window_width_frac"]


def test_the_tables_give_a_range_per_class_and_method_and_a_row_per_log(runs: list[bench.Run]) -> None:
    methods = bench.table_methods(PARTICLES)
    summary = bench.summary_table(runs, methods).splitlines()
    assert len(summary) == 2 + 2 * len(methods)
    assert summary[2].startswith("| I | sliced map | 1.000 |")
    assert summary[-1].startswith(f"| II | {bench.particle_label(PARTICLES)} |")
    assert summary[-1].count("n/a") == 2  # a particle filter has no window
    per_log = bench.log_table(runs, methods).splitlines()
    assert len(per_log) == 2 + len(runs) * len(methods)


def test_the_json_holds_every_run_with_metrics_keys(runs: list[bench.Run], calibration: Calibration) -> None:
    maps = bench.map_settings({}, {}, {})
    doc = bench.document(
        runs, maps, calibration, calibrated_on="synthetic", camera=Path("camera.toml"), particles=PARTICLES,
        seed=0, command="bench",
    )  # fmt: skip
    again = json.loads(json.dumps(doc))
    assert [run["landmark_class"] for run in again["runs"]] == ["I", "II"]
    assert again["settings"][bench.PRODUCT]["slice_width"] is None
    assert again["runs"][1]["methods"][0]["method"] == bench.PRODUCT


def test_the_figure_is_drawn(runs: list[bench.Run], tmp_path: Path) -> None:
    path = tmp_path / "figure" / "windows.png"
    bench.draw(runs[1], path)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_settings_come_from_the_defaults_then_the_options() -> None:
    maps = bench.map_settings({"max_vertices": 32}, {}, {"relaxed_q": 1})
    assert maps[bench.PRODUCT].slice_width is None
    assert maps[bench.SLICED].slice_width == (ManagerSettings().slice_width or bench.BEST_SLICE_WIDTH)
    assert maps[bench.PRODUCT].max_vertices == maps[bench.SLICED].max_vertices == 32
    assert (maps[bench.PRODUCT].relaxed_q, maps[bench.SLICED].relaxed_q) == (0, 1)
    with pytest.raises(InputError, match="expected a field of ManagerSettings"):
        bench.map_settings({"slices": 3}, {}, {})


@pytest.mark.parametrize(
    ("text", "expected"),
    [("relaxed_q=1", ("relaxed_q", 1)), ("slice_width=None", ("slice_width", None)),
     ("robust=false", ("robust", False)), ("sigmas = 2.5", ("sigmas", 2.5)),
     ("slice_width=2deg", ("slice_width", math.radians(2.0))), ("joint_sector=0.1", ("joint_sector", 0.1))],
)  # fmt: skip
def test_a_setting_option_is_parsed(text: str, expected: tuple[str, object]) -> None:
    assert bench.setting(text) == expected


@pytest.mark.parametrize(
    ("text", "message"),
    [("sigmas", "expected KEY=VALUE"), ("sigmas=big", "a number"), ("relaxed_q=2deg", "a number")],
)
def test_a_bad_setting_option_is_refused(text: str, message: str) -> None:
    with pytest.raises(argparse.ArgumentTypeError, match=message):
        bench.setting(text)


def test_the_docs_blocks_are_replaced_between_their_markers() -> None:
    text = "a\n<!-- b -->\nold\n<!-- /b -->\nc\n"
    assert bench.replace_block(text, "b", "new\n") == "a\n<!-- b -->\nnew\n<!-- /b -->\nc\n"
    with pytest.raises(AuraUmsError, match="expected the markers <!-- d -->"):
        bench.replace_block(text, "d", "new\n")


def test_the_readme_and_the_docs_page_have_the_markers() -> None:
    for path in (bench.README, bench.DOCS_PAGE):
        text = path.read_text(encoding="utf-8")
        assert "<!-- bench_real_logs -->" in text, path
        assert "<!-- /bench_real_logs -->" in text, path
    assert "<!-- bench_real_logs per log -->" in bench.DOCS_PAGE.read_text(encoding="utf-8")


def test_without_the_data_the_script_says_so_and_stops(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert bench.main(["--data", str(tmp_path), "--quiet"]) == 0
    assert "development data not found" in capsys.readouterr().out


def test_development_logs_are_found_by_their_files(tmp_path: Path) -> None:
    for dataset, robots in (("set_a", (1, 2)), ("set_b", (3,)), ("notes", ())):
        (tmp_path / dataset).mkdir()
        if robots:
            (tmp_path / dataset / "Barcodes.dat").write_text("", encoding="utf-8")
        for robot in robots:
            (tmp_path / dataset / f"Robot{robot}_Odometry.dat").write_text("", encoding="utf-8")
    assert bench.development_logs(tmp_path) == [("set_a", 1), ("set_a", 2), ("set_b", 3)]


def test_the_tables_come_back_the_same_from_the_json(runs: list[bench.Run], calibration: Calibration) -> None:
    doc = bench.document(
        runs, bench.map_settings({}, {}, {}), calibration, calibrated_on="synthetic:1",
        camera=Path("camera.toml"), particles=PARTICLES, seed=0, command="bench --write-docs",
    )  # fmt: skip
    again = bench.runs_of(json.loads(json.dumps(doc)))
    methods = bench.table_methods(PARTICLES)
    assert bench.summary_table(again, methods) == bench.summary_table(runs, methods)
    assert bench.log_table(again, methods) == bench.log_table(runs, methods)
    said = bench.provenance(doc)
    assert said.startswith("Calibrated on synthetic robot 1, replayed on 1 other robots")
    assert "`bench --write-docs`" in said


def test_write_docs_fills_the_blocks_of_the_readme_and_the_page(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    readme, page = tmp_path / "README.md", tmp_path / "real-logs.md"
    readme.write_text("# r\n<!-- bench_real_logs -->\nold\n<!-- /bench_real_logs -->\n", encoding="utf-8")
    page.write_text(
        "<!-- bench_real_logs -->\n<!-- /bench_real_logs -->\n"
        "<!-- bench_real_logs per log -->\nold\n<!-- /bench_real_logs per log -->\n",
        encoding="utf-8",
    )
    monkeypatch.setattr(bench, "README", readme)
    monkeypatch.setattr(bench, "DOCS_PAGE", page)
    settings = {name: s.to_dict() for name, s in bench.map_settings({}, {}, {"relaxed_q": 1}).items()}
    bench.write_docs("SUMMARY\n", "PER LOG\n", "MEASURED", settings)
    assert readme.read_text(encoding="utf-8") == (
        "# r\n<!-- bench_real_logs -->\nSUMMARY\n\nMEASURED\n<!-- /bench_real_logs -->\n"
    )
    text = page.read_text(encoding="utf-8")
    assert "- product map: `slice_width=none`\n" in text
    assert (
        "- sliced map: `slice_width=0.06981`, `relaxed_q=1`\n" in text or "sliced map: `slice_width=" in text
    )
    assert "<!-- bench_real_logs per log -->\nPER LOG\n<!-- /bench_real_logs per log -->" in text
