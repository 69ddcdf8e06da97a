"""``aura-ums import mrclam``, on an app built here so the test does not depend on the main app."""

from __future__ import annotations

from pathlib import Path

import pytest
import typer
from typer.testing import CliRunner

from aura_ums.cli._logs import import_app
from aura_ums.logs import load_log

runner = CliRunner()
HEADER = "# made-up MRCLAM files\n# produced by nobody\n# format\n# columns\n"
DATASET = {
    "Barcodes.dat": HEADER + "1 5\n2 14\n6 63\n7 81\n",
    "Landmark_Groundtruth.dat": HEADER + "6 0.5 -4.0 0.001 0.002\n7 1.5 2.0 0.003 0.0001\n",
    "Robot1_Measurement.dat": HEADER
    + "10.0 14 3.0 -0.25\n10.0 63 2.0 0.5\n10.5 99 1.0 0.0\n11.0 81 4.0 -0.1\n",
    "Robot1_Odometry.dat": HEADER + "9.0 0.1 0.0\n9.5 0.2 0.1\n12.0 0.0 0.0\n",
    "Robot1_Groundtruth.dat": HEADER + "8.0 0.0 0.0 3.1\n12.0 1.0 0.0 -3.1\n",
}


@pytest.fixture
def app() -> typer.Typer:
    main = typer.Typer()
    main.add_typer(import_app, name="import")
    return main


@pytest.fixture
def dataset(tmp_path: Path) -> Path:
    folder = tmp_path / "MRCLAM_Dataset3"
    folder.mkdir()
    for name, text in DATASET.items():
        (folder / name).write_text(text)
    return folder


def test_import_mrclam_writes_the_log_and_says_what(app: typer.Typer, dataset: Path, tmp_path: Path) -> None:
    out = tmp_path / "logs" / "robot1"
    result = runner.invoke(app, ["import", "mrclam", str(dataset), "--robot", "1", str(out)])
    assert result.exit_code == 0, result.output
    assert f"wrote {out}" in result.output
    assert "observations       2 (2 range_bearing)" in result.output
    assert "dropped 1 robot and 1 unknown-barcode measurements" in result.output
    assert "odometry span      9.000 .. 12.000 s (3.0 s)" in result.output
    log = load_log(out)
    assert [o.landmark_id for o in log.observations] == ["6", "7"]


def test_import_refuses_to_overwrite_unless_told(app: typer.Typer, dataset: Path, tmp_path: Path) -> None:
    out = tmp_path / "robot1"
    args = ["import", "mrclam", str(dataset), "--robot", "1", str(out)]
    assert runner.invoke(app, args).exit_code == 0
    result = runner.invoke(app, args)
    assert result.exit_code == 2
    assert f"error: OUT_DIR: expected a new or empty folder, got {out}" in result.stderr
    assert "--overwrite" in result.stderr
    assert runner.invoke(app, [*args, "--overwrite"]).exit_code == 0


def test_missing_dataset_folder_is_named(app: typer.Typer, tmp_path: Path) -> None:
    missing = tmp_path / "no-such-dataset"
    result = runner.invoke(app, ["import", "mrclam", str(missing), "--robot", "1", str(tmp_path / "out")])
    assert result.exit_code == 2
    assert f"error: {missing}: expected a UTIAS MRCLAM dataset folder, got no such folder" in result.output
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("robot", "message"),
    [
        ("2", "Robot2_Measurement.dat: expected robot 2's measurements"),
        ("9", "--robot: expected a robot number"),
    ],
)
def test_bad_robot_is_an_error(
    app: typer.Typer, dataset: Path, tmp_path: Path, robot: str, message: str
) -> None:
    result = runner.invoke(app, ["import", "mrclam", str(dataset), "--robot", robot, str(tmp_path / "out")])
    assert result.exit_code == 2
    assert "error: " in result.output
    assert message in result.output


def test_malformed_file_is_an_error_naming_file_and_line(
    app: typer.Typer, dataset: Path, tmp_path: Path
) -> None:
    (dataset / "Robot1_Odometry.dat").write_text(HEADER + "9.0 0.1\n")
    result = runner.invoke(app, ["import", "mrclam", str(dataset), "--robot", "1", str(tmp_path / "out")])
    assert result.exit_code == 2
    assert "Robot1_Odometry.dat:5: expected 3 numbers (time, v, omega), got 2" in result.output
