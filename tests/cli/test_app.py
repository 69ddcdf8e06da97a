from __future__ import annotations

from pathlib import Path

import pytest
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
    # typer's boxed "No such option", worded as every other refusal
    assert result.stderr.startswith("error: --colour: expected an option of aura-ums figures (see --help")
    assert result.stderr.endswith("got --colour\n")


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        # Each was a traceback from deep inside the computation before.
        (["demo", "--runs", "0"], "--runs: expected an integer in [1, 100000], got 0"),
        (
            ["demo", "--runs", "1000000000"],
            "--runs: expected an integer in [1, 100000], got 1000000000 "
            "(about 7.69e+07 s and 2e+04 GB of results)",
        ),
        (["demo", "--seed", "-1"], "--seed: expected an integer >= 0, got -1"),
        (["figures", "--seed", "-1"], "--seed: expected an integer >= 0, got -1"),
    ],
)
def test_bad_numbers_are_refused_before_any_work(arguments: list[str], message: str, tmp_path: Path) -> None:
    result = runner.invoke(app, [*arguments, "--out", str(tmp_path / "out")])
    assert result.exit_code == 2
    assert "Traceback" not in result.output
    assert result.stderr == f"error: {message}\n"
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["simulate", "s.toml", "--runs", "1.5"], "--runs: expected an integer, got '1.5'"),
        (["simulate", "s.toml", "--runs=x"], "--runs: expected an integer, got 'x'"),
        (["import", "mrclam", "d", "o", "--robot", "abc"], "--robot: expected an integer, got 'abc'"),
        # past Python's 4300-digit conversion limit: "Unable to parse input string as an integer"
        (["simulate", "s.toml", "--runs", "9" * 4400], f"--runs: expected an integer, got '{'9' * 4400}'"),
        (
            ["import", "rosbag", "b", "o", "--odom", "/o", "--observations", "/x"],
            "--landmarks: expected a value (the option is required), got none",
        ),
    ],
)
def test_typers_own_refusals_name_the_option_and_what_was_typed(argv: list[str], message: str) -> None:
    # They came boxed under a usage line: "Invalid value for '--runs': Input should be a valid
    # integer", without the value.
    result = runner.invoke(app, argv)
    assert result.exit_code == 2
    assert result.stderr == f"error: {message}\n"
