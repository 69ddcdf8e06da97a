"""The commands' shared helpers: one-line errors and warnings."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from aura_ums.cli import _common, app

runner = CliRunner()


@pytest.mark.parametrize("name", ["lo\ng", "lo\rg", "lo\x1b[2Jg", "lo\u2028g"], ids=["lf", "cr", "esc", "ls"])
def test_an_error_naming_a_path_with_control_characters_is_one_line(tmp_path: Path, name: str) -> None:
    terrain = tmp_path / "terrain.toml"
    terrain.write_text("")
    result = runner.invoke(app, ["replay", str(tmp_path / name), "--terrain", str(terrain)])
    assert result.exit_code == 2
    escaped = repr(name)[1:-1]
    assert result.stderr == f"error: {tmp_path / escaped}: expected a log folder, got no such folder\n"


def test_a_warning_is_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    _common.warn("a\nb")
    assert capsys.readouterr().err == "warning: a\\nb\n"
    assert _common.one_line("tab\there") == "tab\\there"
