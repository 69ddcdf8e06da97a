"""Outputs never touch inputs, collide, or silently replace a file; names from data stay in their folder.

Each case is one failure class of issue 19: the command must exit 2 before it computes,
say why on stderr (naming the option and both paths), print nothing on stdout, show no
traceback, and leave every input byte-identical.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import os
import shutil
import stat
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import typer
from typer.main import get_command
from typer.testing import CliRunner, Result

from aura_ums.cli import app
from aura_ums.cli._outputs import safe_name
from aura_ums.logs import synthetic_log, write_log
from aura_ums.uncertainty import TerrainTable
from tests.logs.log_helpers import long_odometry_log

runner = CliRunner()
REPOSITORY = Path(__file__).resolve().parents[2]
EXAMPLES = REPOSITORY / "examples"
SCENARIO = REPOSITORY / "scenarios" / "paper_sidewalk.toml"


def invoke(*arguments: str | Path) -> Result:
    return runner.invoke(app, [str(a) for a in arguments])


def digest(folder: Path) -> dict[str, str]:
    """Every file under ``folder`` with its SHA-256: inputs must stay byte-identical."""
    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def refused(result: Result, *words: str) -> None:
    """A clean refusal: exit 2, the message on stderr only, no traceback."""
    assert result.exit_code == 2, result.output
    assert result.stdout == ""
    assert result.stderr.startswith("error: ")
    assert "Traceback" not in result.output
    for word in words:
        assert word in result.stderr, result.stderr


@pytest.fixture(scope="module")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> Path:
    base = tmp_path_factory.mktemp("inputs")
    write_log(synthetic_log(np.random.default_rng(4), duration=20.0), base / "log")
    (base / "terrain.toml").write_text(TerrainTable({"floor": TerrainTable.default()["tile"]}).to_toml())
    return base


@pytest.fixture
def untouched(inputs: Path) -> object:
    before = digest(inputs)
    yield
    assert digest(inputs) == before


def test_replay_refuses_to_write_into_its_log_folder(inputs: Path, untouched: object) -> None:
    log = inputs / "log"
    target = log / "observations.csv"
    result = invoke("replay", log, "--terrain", inputs / "terrain.toml", "--steps-csv", target, "--overwrite")
    refused(result, "--steps-csv", str(target), str(log), "LOG_DIR")


def test_calibrate_refuses_to_write_onto_its_meta_toml(inputs: Path, untouched: object) -> None:
    log = inputs / "log"
    result = invoke("calibrate", log, "--out", log / "meta.toml", "--overwrite")
    refused(result, "--out", str(log / "meta.toml"), "LOG_DIRS")


def test_an_input_file_is_refused_as_output(inputs: Path, untouched: object) -> None:
    terrain = inputs / "terrain.toml"
    result = invoke("replay", inputs / "log", "--terrain", terrain, "--metrics-json", terrain, "--overwrite")
    refused(result, "--metrics-json", "--terrain", str(terrain))


def test_symlinks_are_resolved_before_comparing(inputs: Path, tmp_path: Path, untouched: object) -> None:
    link = tmp_path / "innocent.toml"
    link.symlink_to(inputs / "log" / "meta.toml")
    folder_link = tmp_path / "elsewhere"
    folder_link.symlink_to(inputs / "log", target_is_directory=True)
    refused(invoke("calibrate", inputs / "log", "--out", link, "--overwrite"), str(link), "LOG_DIRS")
    out = folder_link / "steps.csv"
    result = invoke("replay", inputs / "log", "--terrain", inputs / "terrain.toml", "--steps-csv", out)
    refused(result, "--steps-csv", str(out))


def test_a_hard_link_to_an_input_is_refused_as_output(
    inputs: Path, tmp_path: Path, untouched: object
) -> None:
    # written atomically the input survived, but the name given was the input's other name
    link = tmp_path / "hard.json"
    os.link(inputs / "terrain.toml", link)
    result = invoke(
        "replay", inputs / "log", "--terrain", inputs / "terrain.toml", "--metrics-json", link, "--overwrite"
    )
    refused(result, "--metrics-json", "a hard link to the input --terrain", str(link.name))


def test_a_hard_link_to_a_file_of_the_input_folder_is_refused_as_output(
    inputs: Path, tmp_path: Path, untouched: object
) -> None:
    link = tmp_path / "hard.csv"
    os.link(inputs / "log" / "observations.csv", link)
    result = invoke(
        "replay", inputs / "log", "--terrain", inputs / "terrain.toml", "--steps-csv", link, "--overwrite"
    )
    refused(result, "--steps-csv", "a hard link to a file of the input LOG_DIR", str(link.name))
    assert os.stat(link).st_nlink == 2


def test_two_outputs_may_not_share_a_path(inputs: Path, tmp_path: Path, untouched: object) -> None:
    same = tmp_path / "same.toml"
    refused(
        invoke("calibrate", inputs / "log", "--out", same, "--sensors-out", same),
        "--sensors-out",
        "--out",
        str(same),
    )
    both = tmp_path / "both.out"
    common = ("replay", inputs / "log", "--terrain", inputs / "terrain.toml")
    refused(invoke(*common, "--metrics-json", both, "--steps-csv", both), "--steps-csv", "--metrics-json")
    assert not same.exists()
    assert not both.exists()
    # One output file as the folder of another: refused before either is written.
    refused(
        invoke(*common, "--metrics-json", both, "--steps-csv", both / "steps.csv"),
        "--steps-csv",
        "--metrics-json",
    )
    assert not both.exists()


def test_an_existing_output_is_replaced_only_with_overwrite(inputs: Path, tmp_path: Path) -> None:
    out = tmp_path / "metrics.json"
    out.write_text("old")
    common = ("replay", inputs / "log", "--terrain", inputs / "terrain.toml", "--metrics-json", out)
    refused(invoke(*common), "--metrics-json", str(out), "--overwrite")
    assert out.read_text() == "old"
    result = invoke(*common, "--overwrite")
    assert result.exit_code == 0, result.output
    assert out.read_text().startswith("{")
    assert f"wrote {out}" in result.stderr
    assert "containment_rate" in result.stdout
    assert [p.name for p in tmp_path.iterdir()] == ["metrics.json"]  # no scratch file left


def test_a_pipe_or_device_is_never_replaced_by_an_output(inputs: Path, tmp_path: Path) -> None:
    # The atomic write renames a scratch file onto its target: a FIFO (or, as root, /dev/null)
    # would become a regular file. It is refused, with --overwrite too.
    pipe = tmp_path / "pipe"
    os.mkfifo(pipe)
    common = ("replay", inputs / "log", "--terrain", inputs / "terrain.toml", "--metrics-json", pipe)
    refused(invoke(*common, "--overwrite"), "--metrics-json", str(pipe), "expected a regular file")
    assert stat.S_ISFIFO(pipe.lstat().st_mode)


def test_the_commands_own_stdout_is_refused_as_an_output(inputs: Path, tmp_path: Path) -> None:
    # --metrics-json /dev/stdout on a pipe: "expected a writable place, got /proc/<pid>/fd";
    # redirected to a file, the rename would have replaced the printed results
    import subprocess
    import sys

    aura = Path(sys.executable).with_name("aura-ums")
    command: list[str | Path] = [
        aura, "replay", inputs / "log", "--terrain", inputs / "terrain.toml", "-q", "--metrics-json"
    ]  # fmt: skip
    piped = subprocess.run([*command, "/dev/stdout"], capture_output=True, text=True, check=False)
    assert piped.returncode == 2
    assert piped.stderr == (
        "error: --metrics-json: expected a file apart from the command's own stdout, got /dev/stdout "
        "(results are printed on stdout, errors on stderr, anyway)\n"
    )
    printed = tmp_path / "printed.txt"
    with printed.open("w") as out:
        done = subprocess.run(
            [*command, printed, "--overwrite"], stdout=out, stderr=subprocess.PIPE, check=False
        )
    assert done.returncode == 2
    assert b"expected a file apart from the command's own stdout, got " in done.stderr
    assert printed.read_text() == ""


def test_an_unwritable_output_is_refused_before_the_computation(
    inputs: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import aura_ums.sim

    def never(*_: object, **__: object) -> None:
        raise AssertionError("the computation started")

    monkeypatch.setattr(aura_ums.sim, "run_scenario", never)
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    result = invoke("simulate", SCENARIO, "--runs", "3", "--metrics-json", blocker / "m.json")
    refused(result, "--metrics-json", str(blocker))


def test_an_output_folder_may_not_hold_an_input(inputs: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    landmarks = out / "landmarks.csv"
    landmarks.write_text((inputs / "log" / "landmarks.csv").read_text())
    bag = tmp_path / "walk.bag"
    bag.write_bytes(b"not read: refused before")
    topics = ("--odom", "/o", "--observations", "/s")
    result = invoke("import", "rosbag", bag, out, *topics, "--landmarks", landmarks, "--overwrite")
    refused(result, "OUT_DIR", "--landmarks", str(landmarks))


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("../x", "x"),
        ("/abs/x", "abs_x"),
        ("../../etc/passwd", "etc_passwd"),
        ("a b:c*?\u00e9", "a_b_c_e"),
        ("..", "log"),
    ],
)
def test_names_from_data_are_sanitized(name: str, expected: str) -> None:
    assert safe_name(name) == expected


@pytest.mark.parametrize("name", ["../../escaped", "/abs/escaped", "we?ird:*na\u00efme"])
def test_replay_plot_stays_in_its_folder(name: str, inputs: Path, tmp_path: Path) -> None:
    log = synthetic_log(np.random.default_rng(4), duration=8.0)
    import dataclasses

    crafted = dataclasses.replace(log, meta=dataclasses.replace(log.meta, name=name))
    folder = write_log(crafted, tmp_path / "data" / "crafted")
    plots = tmp_path / "data" / "plots" / "inner"
    result = invoke("replay", folder, "--terrain", inputs / "terrain.toml", "--plot", plots, "--quiet")
    assert result.exit_code == 0, result.output
    written = sorted(p for p in tmp_path.rglob("*.png"))
    assert written == [plots / f"{safe_name(name)}_replay.png"]
    assert [p.name for p in plots.iterdir()] == [f"{safe_name(name)}_replay.png"]


@pytest.mark.parametrize(
    "arguments",
    [["figures", "--out", "/", "--overwrite"], ["demo", "--out", "///", "--runs", "1", "--overwrite"]],
    ids=["figures", "demo"],
)
def test_the_root_is_refused_as_an_output_folder(arguments: list[str]) -> None:
    # An output folder is staged beside it: the root has no place beside it (a ValueError escaped).
    refused(invoke(*arguments), "error: --out: expected a folder other than the file system's root, got /\n")


def test_replay_refuses_the_root_as_its_plot_folder_writing_nothing(
    inputs: Path, tmp_path: Path, untouched: object
) -> None:
    metrics = tmp_path / "m.json"
    args = ("replay", inputs / "log", "--terrain", inputs / "terrain.toml", "--metrics-json", metrics)
    result = invoke(*args, "--plot", "/", "--quiet")
    refused(result, "error: --plot: expected a folder other than the file system's root, got /\n")
    assert not metrics.exists()


def test_every_command_that_writes_takes_the_same_overwrite() -> None:
    root = get_command(app)
    assert isinstance(root, typer.core.TyperGroup)
    commands = dict(root.commands)
    imports = commands.pop("import")
    assert isinstance(imports, typer.core.TyperGroup)
    commands.update({f"import {name}": command for name, command in imports.commands.items()})
    helps = {}
    for name, command in commands.items():
        options = {option: param for param in command.params for option in getattr(param, "opts", ())}
        assert "--overwrite" in options, name
        helps[name] = getattr(options["--overwrite"], "help", None)
    assert set(commands) == {
        "figures",
        "demo",
        "simulate",
        "calibrate",
        "replay",
        "compare",
        "import mrclam",
        "import rosbag",
        "import camera-info",
    }
    assert len(set(helps.values())) == 1, helps


def test_errors_go_to_stderr_and_results_to_stdout(inputs: Path, tmp_path: Path) -> None:
    missing = tmp_path / "no-such-log"
    refused(invoke("replay", missing, "--terrain", inputs / "terrain.toml"), str(missing))
    bad = tmp_path / "latin1.toml"
    bad.write_bytes("[floor]\nname = 'caf\u00e9'\n".encode("latin-1"))
    refused(invoke("replay", inputs / "log", "--terrain", bad), str(bad))
    result = invoke("replay", inputs / "log", "--terrain", inputs / "terrain.toml")
    assert result.exit_code == 0, result.output
    assert result.stderr == ""
    assert "containment_rate" in result.stdout


def test_an_output_through_a_symlink_replaces_the_file_it_leads_to(inputs: Path, tmp_path: Path) -> None:
    real = tmp_path / "real.json"
    real.write_text("old")
    link = tmp_path / "link.json"
    link.symlink_to(real)
    common = ("replay", inputs / "log", "--terrain", inputs / "terrain.toml", "--metrics-json", link)
    refused(invoke(*common), str(link), "exists")
    result = invoke(*common, "--overwrite")
    assert result.exit_code == 0, result.output
    assert link.is_symlink()
    assert real.read_text().startswith("{")


# --- a folder the user may not write into --------------------------------------------------------

#: Where each command's computation starts: none may be reached when an output is unwritable.
COMPUTATIONS = [
    ("aura_ums.logs", "replay_log"),
    ("aura_ums.logs", "replay_windows"),
    ("aura_ums.logs", "calibrate_logs"),
    ("aura_ums.logs", "compare_on_log"),
    ("aura_ums.logs", "read_mrclam"),
    ("aura_ums.logs", "read_rosbag"),
    ("aura_ums.campaign", "run_campaign"),
    ("aura_ums.campaign", "simulate_campaign"),
    ("aura_ums.plot", "write_experiment_report"),
    ("aura_ums.plot", "draw_all_figures"),
]


@pytest.fixture
def locked(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """A folder this process may not create files in, and nothing may start computing.

    By its mode when the tests run as a user; as root, who may write anywhere, by the
    system's own refusal (EACCES) of every file opened for writing in it.
    """
    import importlib

    folder = tmp_path / "locked"
    folder.mkdir()

    def never(*_: object, **__: object) -> None:
        raise AssertionError("the computation started")

    for module, name in COMPUTATIONS:
        monkeypatch.setattr(importlib.import_module(module), name, never)
    if os.geteuid() != 0:
        folder.chmod(0o555)
        yield folder
        folder.chmod(0o755)
        return
    opened = Path.open

    def refusing(path: Path, mode: str = "r", *args: Any, **kwargs: Any) -> Any:
        if folder in path.parents and any(flag in mode for flag in "wxa+"):
            raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(path))
        return opened(path, mode, *args, **kwargs)

    monkeypatch.setattr(Path, "open", refusing)
    yield folder


@pytest.mark.parametrize(
    ("arguments", "option"),
    [
        (
            ("replay", "{log}", "--terrain", "{terrain}", "--metrics-json", "{locked}/m.json"),
            "--metrics-json",
        ),
        (("replay", "{log}", "--terrain", "{terrain}", "--steps-csv", "{locked}/s.csv"), "--steps-csv"),
        (("replay", "{log}", "--terrain", "{terrain}", "--plot", "{locked}/plots"), "--plot"),
        (("replay", "{log}", "--terrain", "{terrain}", "--mcap", "{locked}/r.mcap"), "--mcap"),
        (("replay", "{log}", "--terrain", "{terrain}", "--save-state", "{locked}/s.json"), "--save-state"),
        (
            (
                "replay",
                "{log}",
                "--terrain",
                "{terrain}",
                "--camera",
                "{camera}",
                "--windows-csv",
                "{locked}/w.csv",
            ),
            "--windows-csv",
        ),
        (
            ("replay", "{log}", "{log}", "--terrain", "{terrain}", "--metrics-json", "{locked}/m.json"),
            "--metrics-json",
        ),
        (("calibrate", "{log}", "--out", "{locked}/t.toml"), "--out"),
        (
            ("calibrate", "{log}", "--out", "{free}/t.toml", "--sensors-out", "{locked}/s.toml"),
            "--sensors-out",
        ),
        (
            ("compare", "{log}", "--terrain", "{terrain}", "--metrics-json", "{locked}/c.json"),
            "--metrics-json",
        ),
        (("simulate", "{scenario}", "--runs", "1", "--metrics-json", "{locked}/m.json"), "--metrics-json"),
        (("demo", "--out", "{locked}/report", "--runs", "1"), "--out"),
        (("figures", "--out", "{locked}/figures"), "--out"),
        (("import", "mrclam", "{log}", "{locked}/new", "--robot", "1"), "OUT_DIR"),
        (
            (
                *("import", "rosbag", "{log}", "{locked}/new", "--odom", "/odom", "--observations", "/seen"),
                *("--landmarks", "{log}/landmarks.csv"),
            ),
            "OUT_DIR",
        ),
    ],
    ids=[
        *(f"replay {o}" for o in ("--metrics-json", "--steps-csv", "--plot", "--mcap", "--save-state")),
        "replay --windows-csv",
        "replay of two logs",
        "calibrate --out",
        "calibrate --sensors-out",
        "compare",
        "simulate",
        "demo",
        "figures",
        "import mrclam",
        "import rosbag",
    ],
)
def test_an_output_in_a_folder_without_write_permission_is_refused_before_the_computation(
    arguments: tuple[str, ...], option: str, inputs: Path, locked: Path, tmp_path: Path, untouched: object
) -> None:
    # was an OSError traceback, and only after the whole computation (issue 19)
    places = {
        "log": inputs / "log",
        "terrain": inputs / "terrain.toml",
        "camera": EXAMPLES / "virtual_camera_60deg.toml",
        "scenario": SCENARIO,
        "locked": locked,
        "free": tmp_path,
    }
    result = invoke(*(argument.format(**places) for argument in arguments))
    refused(result, f"{option}: expected a writable place, got {locked}: Permission denied")
    assert list(locked.iterdir()) == []


# --- an input the user may not read --------------------------------------------------------------


@pytest.fixture
def deny(monkeypatch: pytest.MonkeyPatch) -> Callable[[Path], None]:
    """Make a file unreadable to this process: by its mode as a user; as root, by EACCES on open."""
    import aura_ums._files

    denied: list[Path] = []

    def refusing(path: Any, *args: Any, **kwargs: Any) -> Any:
        if Path(path) in denied:
            raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(path))
        return open(path, *args, **kwargs)

    access = os.access

    def no_access(path: Any, mode: int, *args: Any, **kwargs: Any) -> bool:
        return Path(path) not in denied and access(path, mode, *args, **kwargs)

    if os.geteuid() == 0:
        # every reader opens its file, and checks its folder, in aura_ums._files
        monkeypatch.setattr(aura_ums._files, "open", refusing, raising=False)
        monkeypatch.setattr(os, "access", no_access)

    def deny_path(path: Path) -> None:
        denied.append(path)
        path.chmod(0)

    return deny_path


def read_log(command: str, log: Path, inputs: Path, out: Path) -> Result:
    """Run a command that reads a log folder (replay, calibrate, compare), writing ``out``."""
    if command == "calibrate":
        return invoke(command, log, "--out", out)
    return invoke(command, log, "--terrain", inputs / "terrain.toml", "--metrics-json", out)


@pytest.mark.parametrize(
    "name", ["meta.toml", "commands.csv", "observations.csv", "groundtruth.csv", "landmarks.csv"]
)
@pytest.mark.parametrize("command", ["replay", "calibrate", "compare"])
def test_an_unreadable_log_file_is_named_with_the_reason(
    command: str, name: str, inputs: Path, tmp_path: Path, deny: Callable[[Path], None]
) -> None:
    log = tmp_path / "log"
    shutil.copytree(inputs / "log", log)
    deny(log / name)
    out = tmp_path / "out.json"
    result = read_log(command, log, inputs, out)
    refused(result, f"error: {log / name}: expected a readable ")
    assert result.stderr.endswith(f" file, got {os.strerror(errno.EACCES)}\n")
    assert not out.exists()


@pytest.mark.parametrize("command", ["replay", "calibrate", "compare"])
def test_an_unreadable_log_folder_is_named_not_its_first_file(
    command: str, inputs: Path, tmp_path: Path, deny: Callable[[Path], None]
) -> None:
    # was "LOG/meta.toml: expected a readable ... file", for a folder the user may not enter
    log = tmp_path / "log"
    shutil.copytree(inputs / "log", log)
    deny(log)
    out = tmp_path / "out.json"
    result = read_log(command, log, inputs, out)
    log.chmod(0o755)
    refused(result)
    assert result.stderr == f"error: {log}: expected a readable log folder, got {os.strerror(errno.EACCES)}\n"
    assert not out.exists()


def test_an_unreadable_dataset_folder_is_named(tmp_path: Path, deny: Callable[[Path], None]) -> None:
    dataset = tmp_path / "MRCLAM_Dataset1"
    dataset.mkdir()
    deny(dataset)
    result = invoke("import", "mrclam", dataset, tmp_path / "new", "--robot", "1")
    dataset.chmod(0o755)
    refused(result)
    what = "a readable UTIAS MRCLAM dataset folder"
    assert result.stderr == f"error: {dataset}: expected {what}, got {os.strerror(errno.EACCES)}\n"
    assert not (tmp_path / "new").exists()


@pytest.mark.parametrize(
    ("arguments", "source"),
    [
        (("replay", "{log}", "--terrain", "{file}"), "{terrain}"),
        (("replay", "{log}", "--terrain", "{terrain}", "--sensors", "{file}"), "{terrain}"),
        (("replay", "{log}", "--terrain", "{terrain}", "--camera", "{file}"), "{examples}/camera.toml"),
        (("replay", "{log}", "--terrain", "{terrain}", "--resume", "{file}"), "{terrain}"),
        (("compare", "{log}", "--terrain", "{file}"), "{terrain}"),
        (("simulate", "{file}", "--runs", "1"), "{scenario}"),
    ],
)
def test_an_unreadable_input_file_is_named_by_our_reader_not_the_parser(
    arguments: tuple[str, ...], source: str, inputs: Path, tmp_path: Path, deny: Callable[[Path], None]
) -> None:
    # The parser's own check answered in its boxed usage format ("Invalid value for
    # '--terrain': path 'ut.toml' is not readable."); our readers give the one-line error.
    given = Path(source.format(terrain=inputs / "terrain.toml", examples=EXAMPLES, scenario=SCENARIO))
    file = tmp_path / ("input" + given.suffix)
    shutil.copyfile(given, file)
    deny(file)
    values = {"log": inputs / "log", "terrain": inputs / "terrain.toml", "file": file}
    out = tmp_path / "out.json"
    result = invoke(*(a.format(**values) for a in arguments), "--metrics-json", out)
    file.chmod(0o644)
    refused(result, str(file), os.strerror(errno.EACCES))
    assert "Invalid value" not in result.output
    assert result.stderr.count("\n") == 1
    assert not out.exists()


def _commands(group: typer.Typer) -> Iterator[Callable[..., Any]]:
    for command in group.registered_commands:
        assert command.callback is not None
        yield command.callback
    for sub in group.registered_groups:
        assert sub.typer_instance is not None
        yield from _commands(sub.typer_instance)


def test_no_path_is_checked_by_the_parser_before_our_readers() -> None:
    # Every path is read (or written) by aura-ums itself, which names it with the reason.
    import typing

    from typer.models import ArgumentInfo, OptionInfo

    checked = []
    for callback in _commands(app):
        for name, hint in typing.get_type_hints(callback, include_extras=True).items():
            if typing.get_origin(hint) is not typing.Annotated or "Path" not in str(hint.__origin__):
                continue
            info = next(m for m in hint.__metadata__ if isinstance(m, (OptionInfo, ArgumentInfo)))
            checked.append(name)
            assert info.parser is not None or info.readable is False, f"{callback.__name__}: {name}"
    assert len(checked) >= 20


def test_the_sensors_file_read_by_default_is_an_input(inputs: Path, tmp_path: Path) -> None:
    """replay and compare read TERRAIN.sensors.toml without --sensors: never an output."""
    terrain = tmp_path / "terrain.toml"
    shutil.copy(inputs / "terrain.toml", terrain)
    calibrated = invoke("calibrate", inputs / "log", "--out", terrain, "--overwrite", "--quiet")
    assert calibrated.exit_code == 0, calibrated.output
    sensors = tmp_path / "terrain.sensors.toml"
    before = sensors.read_bytes()
    for command in ("replay", "compare"):
        result = invoke(
            command, inputs / "log", "--terrain", terrain, "--metrics-json", sensors, "--overwrite"
        )
        refused(result, "--metrics-json", "--sensors (by default, beside --terrain)", str(sensors))
    assert sensors.read_bytes() == before


@pytest.mark.parametrize(("key", "name"), [("camera", "paper_camera.toml"), ("map", "four_terrains.geojson")])
def test_the_files_a_scenario_names_are_inputs(key: str, name: str, tmp_path: Path) -> None:
    for file in ("four_terrains.toml", "four_terrains.geojson", "paper_camera.toml"):
        shutil.copy(SCENARIO.with_name(file), tmp_path / file)
    named = tmp_path / name
    before = named.read_bytes()
    for option in ("--metrics-json", "--mcap"):
        scenario = tmp_path / "four_terrains.toml"
        result = invoke("simulate", scenario, "--runs", "1", option, named, "--overwrite")
        refused(result, option, f"SCENARIO's {key}", str(named))
    assert named.read_bytes() == before


def test_a_name_too_long_for_the_file_system_is_refused_before_the_computation(
    inputs: Path, tmp_path: Path
) -> None:
    common = ("replay", inputs / "log", "--terrain", inputs / "terrain.toml", "--quiet")
    too_long = tmp_path / ("m" * 256 + ".json")
    result = invoke(*common, "--metrics-json", tmp_path / "ok.json", "--steps-csv", too_long)
    refused(result, "--steps-csv", "261 bytes")
    assert list(tmp_path.iterdir()) == []
    # A name that fits, but not with the 22 bytes of its scratch name's dots and suffix.
    longest = tmp_path / ("m" * 250 + ".csv")
    result = invoke(*common, "--steps-csv", longest)
    assert result.exit_code == 0, result.output
    assert [p.name for p in tmp_path.iterdir()] == [longest.name]
    assert longest.read_text().startswith("time,")


@pytest.mark.parametrize("kind", ["text", "placed", "staged"])
def test_an_output_that_appears_during_the_run_is_kept_without_overwrite(kind: str, tmp_path: Path) -> None:
    """The existence check before the work and the final rename are both no-clobber."""
    from aura_ums.cli import _outputs

    out = tmp_path / ("figures" if kind == "staged" else "out.txt")
    target = _outputs.Target("--out", out, folder=kind == "staged")
    precious = (out / "a.txt") if kind == "staged" else out
    for overwrite in (False, True):
        shutil.rmtree(tmp_path)
        tmp_path.mkdir()
        _outputs.check_outputs([target], [], overwrite=overwrite)
        precious.parent.mkdir(exist_ok=True)
        precious.write_text("precious")  # made by someone else while the command computes
        with pytest.raises(typer.Exit) if not overwrite else _nothing():
            if kind == "text":
                _outputs.write_text(target, "new")
            elif kind == "placed":
                with _outputs.placed(target) as scratch:
                    scratch.write_text("new")
            else:
                with _outputs.staged(target) as stage:
                    (stage / "a.txt").write_text("new")
        assert precious.read_text() == ("new" if overwrite else "precious")
        leftovers = [p.name for p in precious.parent.iterdir() if p.name.startswith(".")]
        assert leftovers == []


@contextlib.contextmanager
def _nothing() -> Iterator[None]:
    yield


def test_import_into_a_symlinked_out_dir_writes_where_it_leads(tmp_path: Path) -> None:
    real = tmp_path / "real"
    real.mkdir()
    link = tmp_path / "link"
    link.symlink_to(real, target_is_directory=True)
    written = write_log(synthetic_log(np.random.default_rng(5), duration=5.0), link)
    assert written == real
    assert link.is_symlink()
    assert (real / "meta.toml").is_file()
    dangling = tmp_path / "dangling"
    dangling.symlink_to(tmp_path / "missing", target_is_directory=True)
    write_log(synthetic_log(np.random.default_rng(5), duration=5.0), dangling)
    assert (tmp_path / "missing" / "meta.toml").is_file()


@pytest.mark.parametrize(
    "name", ["meta.toml", "landmarks.csv", "observations.csv", "odometry.csv", "groundtruth.csv"]
)
@pytest.mark.parametrize("command", ["replay", "calibrate"])
def test_a_log_file_that_is_a_named_pipe_is_refused_not_waited_on(
    name: str, command: str, tmp_path: Path
) -> None:
    """The streamed readers open the big files block by block: a pipe would block the open."""
    log = tmp_path / "log"
    write_log(long_odometry_log(600), log)
    (log / name).unlink()
    os.mkfifo(log / name)
    terrain = tmp_path / "terrain.toml"
    terrain.write_text(TerrainTable({"floor": TerrainTable.default()["tile"]}).to_toml())
    if command == "replay":
        result = invoke("replay", log, "--terrain", terrain, "--quiet")
    else:
        result = invoke("calibrate", log, "--out", tmp_path / "out.toml", "--quiet")
    refused(result, str(log / name), "named pipe")


def test_input_names_too_long_for_the_file_system_are_refused_cleanly(inputs: Path, tmp_path: Path) -> None:
    # Path.is_dir and Path.is_file raised OSError for them: a traceback, exit 1
    long = "q" * 256
    too_long = os.strerror(errno.ENAMETOOLONG)
    terrain = inputs / "terrain.toml"
    refused(invoke("replay", tmp_path / long, "--terrain", terrain), f"expected a log folder, got {too_long}")
    refused(invoke("replay", inputs / "log", "--terrain", tmp_path / f"{long}.toml"), too_long)
    refused(invoke("simulate", tmp_path / f"{long}.toml"), "expected a scenario TOML file, got no such file")
    bag = ("import", "rosbag", "--odom", "/odom", "--observations", "/seen")
    landmarks = inputs / "log" / "landmarks.csv"
    refused(
        invoke(*bag, "--landmarks", landmarks, tmp_path / long, tmp_path / "out"),
        "got no such file or folder",
    )
    refused(
        invoke(*bag, "--landmarks", tmp_path / long, inputs / "log", tmp_path / "out"), "got no such file"
    )


# --- a full disk: the system refuses a write part-way through -----------------------------
# Found on a 64 KiB tmpfs: a traceback from the MCAP writer, an empty folder left under the
# name of --plot, and the per-step CSV's scratch file left beside its target.


def failed_late(result: Result, *words: str) -> None:
    """An output that failed after the results were printed: exit 2, the error on stderr, no traceback."""
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    assert "error: " in result.stderr
    for word in words:
        assert word in result.stderr, result.stderr


@pytest.mark.parametrize("where", ["write", "close"])
def test_a_full_disk_under_the_steps_csv_is_a_clean_error_leaving_nothing(
    where: str, inputs: Path, tmp_path: Path, full_disk: Callable[[str, str], None]
) -> None:
    full_disk("steps.csv", where)
    target = tmp_path / "out" / "steps.csv"
    result = invoke("replay", inputs / "log", "--terrain", inputs / "terrain.toml", "--steps-csv", target)
    refused(result, f"--steps-csv: expected a writable place, got {target}: No space left on device")
    assert list(tmp_path.iterdir()) == []


def test_a_full_disk_under_the_plot_leaves_no_folder_under_its_name(
    inputs: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import aura_ums.plot

    def full(*_: object) -> None:  # what matplotlib's savefig raises on a full disk
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(aura_ums.plot, "draw_replay", full)
    kept = tmp_path / "kept"
    kept.mkdir()
    for folder in (tmp_path / "new" / "plots", kept):
        result = invoke("replay", inputs / "log", "--terrain", inputs / "terrain.toml", "--plot", folder)
        failed_late(result, f"--plot: expected a writable place, got {folder}: No space left on device")
    # The folders made for the figure are gone; the one that was there stays, empty as it was.
    assert [path.name for path in tmp_path.iterdir()] == ["kept"]
    assert list(kept.iterdir()) == []


def test_a_full_disk_under_the_mcap_is_a_clean_error_leaving_the_old_file(
    inputs: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import foxglove

    opened = foxglove.open_mcap
    # The SDK's own words when its write or its closing flush fails (foxglove-sdk 0.30.3).
    failure = "FoxgloveError: MCAP error: I/O error from writing, or reading a compression stream"

    class FullDisk:
        def __init__(self, *args: Any, **kwargs: Any) -> None:
            self._writer = opened(*args, **kwargs)

        def __getattr__(self, name: str) -> Any:
            return getattr(self._writer, name)

        def __enter__(self) -> FullDisk:
            return self

        def __exit__(self, *_: object) -> None:
            self._writer.close()
            raise RuntimeError(failure)

    monkeypatch.setattr(foxglove, "open_mcap", FullDisk)
    target = tmp_path / "replay.mcap"
    target.write_bytes(b"the old file")
    arguments = ("--terrain", inputs / "terrain.toml", "--mcap", target, "--overwrite")
    result = invoke("replay", inputs / "log", *arguments)
    failed_late(result, f"--mcap: expected a writable place, got {target}: {failure}")
    assert target.read_bytes() == b"the old file"
    assert [path.name for path in tmp_path.iterdir()] == ["replay.mcap"]


@pytest.mark.skipif(
    not Path("/dev/full").exists(), reason="needs /dev/full (Linux), a device that is always full"
)
@pytest.mark.parametrize("arguments", [["--version"], ["replay", "LOG", "--terrain", "TERRAIN", "--quiet"]])
def test_a_stdout_that_takes_nothing_is_a_clean_error(arguments: list[str], inputs: Path) -> None:
    # The results printed onto a full device raised OSError: a traceback, exit 1.
    import subprocess
    import sys

    names = {"LOG": str(inputs / "log"), "TERRAIN": str(inputs / "terrain.toml")}
    with open("/dev/full", "w") as full:
        done = subprocess.run(
            [
                sys.executable,
                "-c",
                "from aura_ums.cli import main; main()",
                *(names.get(a, a) for a in arguments),
            ],
            stdout=full,
            stderr=subprocess.PIPE,
            text=True,
            check=False,
            timeout=120,
        )
    assert done.returncode == 2, done.stderr
    assert (
        done.stderr == "error: stdout: expected a place to print the results, got No space left on device\n"
    )


def test_memory_refused_by_the_system_is_a_clean_error() -> None:
    # Under a tight `ulimit -v` a replay of an MRCLAM log raised MemoryError: a traceback, exit 1.
    import subprocess
    import sys

    script = (
        "import aura_ums.cli._app as cli\n"
        "def exhausted():\n"
        "    held = [bytearray(10**6) for _ in range(20)]  # what the frames keep until they are left\n"
        "    raise MemoryError\n"
        "cli.app = exhausted\n"
        "cli.main()\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=False, timeout=60
    )
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith(
        "error: memory: expected what this command needs, got a refusal from the system"
    )
    assert "ulimit -v" in done.stderr
    assert "Traceback" not in done.stderr


def test_an_output_that_is_a_looping_link_is_refused_before_the_computation(
    inputs: Path, tmp_path: Path
) -> None:
    # It passed the checks, then the final rename refused it "as appeared while this command ran".
    loop = tmp_path / "loop.json"
    loop.symlink_to(loop.name)
    given = ("replay", inputs / "log", "--terrain", inputs / "terrain.toml", "--metrics-json", loop)
    refused(invoke(*given), f"--metrics-json: expected a new file, got {loop}, a symbolic link that loops")
    assert loop.is_symlink()
    assert invoke(*given, "--overwrite").exit_code == 0
    assert not loop.is_symlink()
    assert loop.read_text().startswith("{")


def test_a_deleted_current_folder_is_said_not_a_traceback(inputs: Path, tmp_path: Path) -> None:
    # os.getcwd() raised FileNotFoundError from the first relative path resolved.
    import subprocess
    import sys

    gone = tmp_path / "gone"
    gone.mkdir()
    script = "import os; os.rmdir(os.getcwd()); from aura_ums.cli import main; main()"
    given = [
        "replay",
        str(inputs / "log"),
        "--terrain",
        str(inputs / "terrain.toml"),
        "--metrics-json",
        "m.json",
    ]
    done = subprocess.run(
        [sys.executable, "-c", script, *given],
        cwd=gone,
        capture_output=True,
        text=True,
        check=False,
        timeout=120,
    )
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr
    assert done.stderr.startswith(
        "warning: relative paths cannot be found: a current folder that was deleted"
    )
    assert "error: m.json: expected a path from an existing current folder" in done.stderr


def test_the_write_probe_is_removed_when_a_stop_lands_while_it_exists(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A Ctrl-C (or SIGTERM) between making the probe file and removing it left it behind."""
    from aura_ums.cli import _outputs

    opened = Path.open

    def open_then_stop(self: Path, *args: Any, **kwargs: Any) -> Any:
        handle = opened(self, *args, **kwargs)
        handle.close()
        raise KeyboardInterrupt  # the signal, as the handler raises it, right after the file exists

    monkeypatch.setattr(Path, "open", open_then_stop)
    with pytest.raises(KeyboardInterrupt, match=r"^$"):
        _outputs._writable(_outputs.Target("--metrics-json", tmp_path / "m.json"), tmp_path / "m.json")
    monkeypatch.undo()
    assert list(tmp_path.iterdir()) == []


def test_a_folder_holding_only_a_killed_commands_scratch_files_is_refused_saying_so(tmp_path: Path) -> None:
    # A SIGKILL leaves a hidden scratch file (.NAME.<16 hex digits>.tmp): not an output, but
    # the folder is not empty either; "holds files" sent the user looking for outputs.
    from tests.cli.test_logs_cli import DATASET

    dataset = tmp_path / "dataset"
    dataset.mkdir()
    for name, text in DATASET.items():
        (dataset / name).write_text(text)
    out = tmp_path / "robot1"
    out.mkdir()
    (out / ".meta.toml.0123456789abcdef.tmp").write_text("a part")
    arguments = ("import", "mrclam", dataset, out, "--robot", "1")
    refused(
        invoke(*arguments),
        f"OUT_DIR: expected a new or empty folder, got {out}, which holds only the scratch files of "
        "unfinished writes (.meta.toml.0123456789abcdef.tmp: a killed command's leftovers can be deleted; "
        "or pass --overwrite)",
    )
    (out / "notes.txt").write_text("mine")
    refused(invoke(*arguments), f"got {out}, which holds files (pass --overwrite")
    assert sorted(path.name for path in out.iterdir()) == [".meta.toml.0123456789abcdef.tmp", "notes.txt"]


# The camera of scenarios/paper_camera.toml as a ROS calibration (camera_calibration_parsers' YAML).
PAPER_OST = """\
image_width: 512
image_height: 480
camera_name: paper
camera_matrix:
  rows: 3
  cols: 3
  data: [549, 0, 255.5, 0, 549, 239.5, 0, 0, 1]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [0, 0, 0, 0, 0]
"""
NAMING_CAMERA = '[intrinsics]\ncalibration = "ost.yaml"\n[mount]\nheight = 1.2\ntilt_deg = 3.0\n'


def test_the_calibration_a_camera_file_names_is_an_input(inputs: Path, tmp_path: Path) -> None:
    """replay --camera, and simulate of a scenario whose camera names one, never write onto it."""
    for file in ("four_terrains.toml", "four_terrains.geojson"):
        shutil.copy(SCENARIO.with_name(file), tmp_path / file)
    (tmp_path / "paper_camera.toml").write_text(NAMING_CAMERA)
    calibration = tmp_path / "ost.yaml"
    calibration.write_text(PAPER_OST)
    before = calibration.read_bytes()
    for option in ("--metrics-json", "--mcap"):
        result = invoke(
            "simulate", tmp_path / "four_terrains.toml", "--runs", "1", option, calibration, "--overwrite"
        )
        refused(result, option, "SCENARIO's camera's calibration", str(calibration))
    common = (
        "replay",
        inputs / "log",
        "--terrain",
        inputs / "terrain.toml",
        "--camera",
        tmp_path / "paper_camera.toml",
    )
    for logs in ((), (EXAMPLES / "logs" / "r1",)):  # one log, and several (each replayed on its own)
        for option in ("--metrics-json", "--steps-csv"):
            if logs and option == "--steps-csv":
                continue  # one log's output only
            result = invoke(*common, *logs, option, calibration, "--overwrite", "--quiet")
            refused(result, option, "the input --camera's [intrinsics] calibration", str(calibration))
    assert calibration.read_bytes() == before
