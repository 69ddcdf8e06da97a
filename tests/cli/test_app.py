from __future__ import annotations

from pathlib import Path

from typer.testing import CliRunner

from aura_ums.cli import app

runner = CliRunner()


def test_help_lists_the_commands() -> None:
    result = runner.invoke(app, ["--help"])
    assert result.exit_code == 0
    assert "figures" in result.output
    assert "demo" in result.output


def test_figures_command_writes_three_files(tmp_path: Path) -> None:
    result = runner.invoke(app, ["figures", "--out", str(tmp_path), "--seed", "2"])
    assert result.exit_code == 0, result.output
    assert sorted(path.name for path in tmp_path.glob("figure[567]*.png")) == [
        "figure5_point_transform.png",
        "figure6_heading_wedge.png",
        "figure7_map_transform.png",
    ]


def test_demo_writes_the_report(tmp_path: Path) -> None:
    # Five Monte Carlo runs, not the default forty: the report, not its statistics, is tested here.
    result = runner.invoke(app, ["demo", "--out", str(tmp_path), "--runs", "5"])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "summary.md").read_text().startswith("# aura-ums report")


def test_unknown_option_is_a_usage_error() -> None:
    result = runner.invoke(app, ["figures", "--colour", "red"])
    assert result.exit_code == 2
    assert "No such option" in result.output
