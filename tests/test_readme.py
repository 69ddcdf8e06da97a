from __future__ import annotations

import json
import os
import re
import shlex
import shutil
from pathlib import Path
from typing import Any

import pytest
import typer
from typer.testing import CliRunner

from aura_ums.cli import app
from aura_ums.logs import load_log

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_library_examples_run(monkeypatch: pytest.MonkeyPatch) -> None:
    text = README.read_text(encoding="utf-8")
    match = re.search(r"## Library in 15 lines\n\n```python\n(.*?)```", text, re.S)
    assert match is not None, "README lost its library example"
    code = match.group(1)
    assert len(code.strip().splitlines()) <= 15
    namespace: dict[str, object] = {"print": lambda *args: None}
    exec(compile(code, str(README), "exec"), namespace)
    assert "m" in namespace
    # The landmark example continues from the first, with paths relative to the repository.
    landmarks = re.search(r"## Recognizing landmarks.*?```python\n(.*?)```", text, re.S)
    assert landmarks is not None, "README lost its landmark example"
    monkeypatch.chdir(README.parent)
    exec(compile(landmarks.group(1), str(README), "exec"), namespace)
    assert namespace["window"] is not None
    reduction = namespace["reduction"]
    assert reduction.consistent  # type: ignore[attr-defined]
    assert reduction.area_after <= reduction.area_before  # type: ignore[attr-defined]


def test_readme_gives_the_two_command_quick_start() -> None:
    text = README.read_text(encoding="utf-8")
    assert "make demo" in text
    assert "make test" in text


# -- every command of the README runs, as printed, in a clone with nothing beside it ---------

REPOSITORY = README.parent
#: Commands the README shows that take too long for a unit test: their options parse and
#: their input files exist here; what else checks them.
SLOW = {
    "demo": "tests/cli/test_app.py writes the whole report",
    "simulate": "run here with --runs 2 in place of the README's 500",
}


def readme_commands() -> list[list[str]]:
    """The commands of the README's ``sh`` blocks, as words (continuations joined, comments cut)."""
    commands = []
    for block in re.findall(r"```sh\n(.*?)```", README.read_text(encoding="utf-8"), re.S):
        for line in block.replace("\\\n", " ").splitlines():
            words = shlex.split(line, comments=True)
            if words:
                commands.append(words)
    return commands


def parsed(args: list[str]) -> Any:
    """The context of ``aura-ums ARGS``: its options and arguments parsed and checked, nothing run."""
    command: Any = typer.main.get_command(app)
    prog = "aura-ums"
    while hasattr(command, "commands"):  # a group: descend to the subcommand
        assert args[0] in command.commands, f"aura-ums has no command {args[0]!r}"
        prog, command, args = f"{prog} {args[0]}", command.commands[args[0]], args[1:]
    return command.make_context(prog, list(args))


def test_every_readme_command_is_make_or_aura_ums() -> None:
    commands = readme_commands()
    assert {words[0] for words in commands} == {"make", "aura-ums"}
    makefile = (REPOSITORY / "Makefile").read_text(encoding="utf-8")
    for words in commands:
        if words[0] == "make":
            for target in words[1:]:
                assert re.search(rf"^{re.escape(target)}:", makefile, re.M), f"no make target {target!r}"
    names = {words[1] for words in commands if words[0] == "aura-ums"}
    assert {"calibrate", "replay", "compare", "demo", "simulate"} <= names


@pytest.fixture
def clone(tmp_path: Path) -> Path:
    """A folder holding what a clone has that the commands read, and nothing beside it."""
    for folder in ("examples", "scenarios"):
        shutil.copytree(REPOSITORY / folder, tmp_path / folder)
    return tmp_path


def test_readme_commands_run_as_printed_on_the_shipped_sample(
    clone: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(clone)
    runner = CliRunner()
    ran = []
    for words in readme_commands():
        if words[0] != "aura-ums":
            continue
        args = words[1:]
        context = parsed(args)
        for value in context.params.values():  # every input path the command names is here
            if isinstance(value, Path) and value.suffix == ".toml" and "--out" not in args:
                assert value.exists(), (words, value)
        if args[0] == "demo":
            continue
        if args[0] == "simulate":
            args[args.index("--runs") + 1] = "2"
        result = runner.invoke(app, args)
        assert result.exit_code == 0, (words, result.output)
        ran.append(args[0])
    assert ran == ["figures", "simulate", "calibrate", "replay", "compare", "replay"]
    assert sorted(p.name for p in (clone / "cal").iterdir()) == ["terrain.sensors.toml", "terrain.toml"]
    metrics = json.loads((clone / "r2.json").read_text(encoding="utf-8"))
    assert metrics["containment_rate"] == 1.0  # the synthetic sample's errors are within its bounds
    assert list((clone / "out").glob("*.png"))
    assert json.loads((clone / "m.json").read_text(encoding="utf-8"))["runs_completed"] == 2
    # the sliced, relaxed replay through the virtual camera: a window row per observation and method
    assert (clone / "r2-windows.csv").read_text(encoding="utf-8").count("\n") > 3
    assert list((clone / "figures").glob("figure3*.png"))


def test_the_sample_logs_are_what_examples_readme_says(tmp_path: Path) -> None:
    # examples/README.md gives the code that made them: it makes them again, byte for byte.
    text = (REPOSITORY / "examples" / "README.md").read_text(encoding="utf-8")
    code = re.search(r"```python\n(.*?)```", text, re.S)
    assert code is not None, "examples/README.md lost the code that makes the sample logs"
    (tmp_path / "examples").mkdir()
    cwd = Path.cwd()
    try:
        os.chdir(tmp_path)
        exec(compile(code.group(1), "examples/README.md", "exec"), {})
    finally:
        os.chdir(cwd)
    shipped = REPOSITORY / "examples" / "logs"
    for robot in ("r1", "r2"):
        names = sorted(p.name for p in (shipped / robot).iterdir())
        assert names == sorted(p.name for p in (tmp_path / "examples" / "logs" / robot).iterdir())
        for name in names:
            made = (tmp_path / "examples" / "logs" / robot / name).read_bytes()
            assert made == (shipped / robot / name).read_bytes(), f"{robot}/{name} differs"
        assert load_log(shipped / robot).meta.source.startswith("synthetic: ")
    size = sum(p.stat().st_size for p in (REPOSITORY / "examples").rglob("*") if p.is_file())
    assert size <= 1_000_000


def test_the_parse_check_refuses_what_would_not_run(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(typer.Exit, match=r"^$"):  # the refusal is said on stderr; the exit holds no text
        parsed(["replay", "examples/logs/r2", "--colour", "red"])
    assert "error: --colour: expected an option of aura-ums replay" in capsys.readouterr().err
    with pytest.raises(AssertionError, match="no command 'replayy'"):
        parsed(["replayy"])
