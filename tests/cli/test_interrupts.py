"""A Ctrl-C leaves the old file or none, exits 130 and says what was (not) written.

The interrupt is raised deterministically from inside the work (a monkeypatched step),
where a user's Ctrl-C would land.
"""

from __future__ import annotations

import contextlib
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import aura_ums.logs
from aura_ums.cli import app
from aura_ums.logs import synthetic_log, write_log
from aura_ums.uncertainty import TerrainTable

runner = CliRunner()


@pytest.fixture(scope="module")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> Path:
    base = tmp_path_factory.mktemp("inputs")
    write_log(synthetic_log(np.random.default_rng(5), duration=20.0), base / "log")
    (base / "terrain.toml").write_text(TerrainTable({"floor": TerrainTable.default()["tile"]}).to_toml())
    return base


def interrupted(result: object) -> str:
    exit_code = getattr(result, "exit_code", None)
    stderr = str(getattr(result, "stderr", ""))
    assert exit_code == 130, getattr(result, "output", "")
    assert "Traceback" not in stderr
    return stderr


def test_ctrl_c_during_the_replay_writes_nothing(
    inputs: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def stop(*_: object, **__: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(aura_ums.logs, "replay_log", stop)
    out = tmp_path / "out"
    out.mkdir()
    (out / "metrics.json").write_text("old")
    result = runner.invoke(
        app,
        [
            "replay",
            str(inputs / "log"),
            "--terrain",
            str(inputs / "terrain.toml"),
            "--metrics-json",
            str(out / "metrics.json"),
            "--steps-csv",
            str(out / "steps.csv"),
            "--overwrite",
        ],
    )
    assert "interrupted: nothing was written" in interrupted(result)
    assert sorted(p.name for p in out.iterdir()) == ["metrics.json"]
    assert (out / "metrics.json").read_text() == "old"


def test_ctrl_c_during_the_mcap_export_leaves_no_partial_file(
    inputs: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from foxglove import channels

    original = channels.SceneUpdateChannel.log
    calls = []

    def log(self: object, *args: object, **kwargs: object) -> None:
        calls.append(1)
        if len(calls) == 25:  # half-way through the steps
            raise KeyboardInterrupt
        original(self, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(channels.SceneUpdateChannel, "log", log)
    metrics = tmp_path / "metrics.json"
    mcap = tmp_path / "replay.mcap"
    mcap.write_bytes(b"the old file")
    arguments = [str(inputs / "log"), "--terrain", str(inputs / "terrain.toml"), "--overwrite"]
    result = runner.invoke(app, ["replay", *arguments, "--metrics-json", str(metrics), "--mcap", str(mcap)])
    message = interrupted(result)
    assert f"interrupted: only {metrics} written whole; nothing else was written" in message
    assert mcap.read_bytes() == b"the old file"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["metrics.json", "replay.mcap"]


def test_ctrl_c_during_import_leaves_no_log_folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from tests.cli.test_logs_cli import DATASET

    dataset = tmp_path / "dataset"
    dataset.mkdir()
    for name, text in DATASET.items():
        (dataset / name).write_text(text)
    original = Path.write_text

    def write_text(self: Path, *args: object, **kwargs: object) -> int:
        if self.name == "observations.csv":
            raise KeyboardInterrupt
        return original(self, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(Path, "write_text", write_text)
    out = tmp_path / "robot1"
    result = runner.invoke(app, ["import", "mrclam", str(dataset), str(out), "--robot", "1"])
    assert "interrupted: nothing was written" in interrupted(result)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dataset"]


# A Ctrl-C at two moments before any command runs, made deterministic: while the command
# line's code is imported (numpy and the kernels load then), and while typer reads the
# arguments (typer answers it with a bare exit code 130 of its own).
_INTERRUPTED_BEFORE_THE_COMMAND = {
    "loading": """
import sys

class Interrupt:
    @staticmethod
    def find_spec(name, path=None, target=None):
        if name == "aura_ums.cli._app":
            raise KeyboardInterrupt
        return None

sys.meta_path.insert(0, Interrupt)
""",
    "reading the arguments": """
import typer.core

def interrupted(*args, **kwargs):
    raise KeyboardInterrupt

typer.core.TyperGroup.make_context = interrupted
""",
}


@pytest.mark.parametrize("moment", sorted(_INTERRUPTED_BEFORE_THE_COMMAND))
def test_ctrl_c_before_the_command_runs_exits_130_and_says_so(moment: str) -> None:
    script = _INTERRUPTED_BEFORE_THE_COMMAND[moment] + (
        "import sys\nsys.argv = ['aura-ums', '--version']\nfrom aura_ums.cli import main\nmain()\n"
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=False)
    assert done.returncode == 130, done.stderr
    assert done.stderr == "error: interrupted: nothing was written\n"
    assert done.stdout == ""


def test_a_real_ctrl_c_early_in_a_command_exits_130_without_a_traceback(tmp_path: Path) -> None:
    """Sent 1 s in: while the libraries load, or once the command runs; either way a clean 130.

    (Not sooner: a signal during the interpreter's own start, before any of our code runs,
    ends it with 130 too, but says nothing.)
    """
    cli = Path(sys.executable).with_name("aura-ums")
    out = tmp_path / "metrics.json"
    scenario = Path(__file__).resolve().parents[2] / "scenarios" / "paper_sidewalk.toml"
    command = [str(cli), "simulate", str(scenario), "--runs", "50", "--metrics-json", str(out)]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(1.0)
    process.send_signal(signal.SIGINT)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 130, stderr
    assert "Traceback" not in stderr
    assert "interrupted: nothing was written" in stderr
    assert not out.exists()
    assert list(tmp_path.iterdir()) == []


def test_the_console_script_loads_nothing_heavy_before_its_ctrl_c_handler() -> None:
    """A Ctrl-C is a traceback until ``main`` runs: ``from aura_ums.cli import main`` stays light.

    (The interpreter's own start is out of reach; typing, re and enum would add milliseconds.)
    """
    listed = "import sys{}\nsys.stdout.write(' '.join(sorted(sys.modules)))"
    modules = [
        set(
            subprocess.run(
                [sys.executable, "-c", listed.format(extra)], capture_output=True, text=True, check=True
            ).stdout.split()
        )
        for extra in ("", "\nfrom aura_ums.cli import main")
    ]
    loaded = modules[1] - modules[0]
    assert "aura_ums.cli" in loaded
    assert loaded & {"typing", "re", "enum", "contextlib", "collections", "signal", "numpy"} == set()


# A Ctrl-C once the command is over (its outputs written whole): while Python joins threads
# and runs its exit functions, and after them, while it tears the modules down. Either way the
# command's own exit status, not death by the signal (which a caller reads as a crash).
_INTERRUPTED_AFTER_THE_COMMAND = {
    "shutting down": (
        "try:\n    main()\nfinally:\n    os.kill(os.getpid(), signal.STOP)\n    time.sleep(5)\n"
    ),
    "tearing down": (
        "class Late:\n    def __del__(self):\n        os.kill(os.getpid(), signal.STOP)\n"
        "late = Late()\nmain()\n"
    ),
}


# A SIGTERM in the teardown ended the process by the signal (helper-64): Python had put its
# default action back, as it does for every signal it handles, and only SIGINT was ignored.
@pytest.mark.parametrize("stop", ["SIGINT", "SIGTERM", "SIGHUP"])
@pytest.mark.parametrize("moment", sorted(_INTERRUPTED_AFTER_THE_COMMAND))
def test_a_ctrl_c_after_the_command_keeps_its_exit_status(moment: str, stop: str) -> None:
    script = (
        "import os, signal, sys, time\nsys.argv = ['aura-ums', '--version']\n"
        "from aura_ums.cli import main\n"
        + _INTERRUPTED_AFTER_THE_COMMAND[moment].replace("signal.STOP", f"signal.{stop}")
    )
    command = [sys.executable, "-c", script]
    done = subprocess.run(command, capture_output=True, text=True, check=False, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("aura-ums ")
    assert "Traceback" not in done.stderr


@pytest.mark.parametrize("stop", ["SIGTERM", "SIGHUP"])
def test_a_request_to_stop_is_met_as_a_ctrl_c_with_its_own_exit_code(
    stop: str, inputs: Path, tmp_path: Path
) -> None:
    # SIGTERM (kill, timeout, a cancelled CI job) ended the process by the signal, said
    # nothing and left the per-step CSV's scratch file behind.
    from tests.logs.log_helpers import long_odometry_log

    log = write_log(long_odometry_log(300_000), tmp_path / "long")
    out = tmp_path / "out"
    out.mkdir()
    cli = Path(sys.executable).with_name("aura-ums")
    command = [str(cli), "replay", str(log), "--terrain", str(inputs / "terrain.toml"), "--quiet"]
    command += ["--steps-csv", str(out / "steps.csv"), "--metrics-json", str(out / "metrics.json")]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    waited = time.monotonic()
    while not any(out.iterdir()) and process.poll() is None and time.monotonic() - waited < 60:
        time.sleep(0.01)  # until the replay writes its scratch CSV: well inside the command
    process.send_signal(getattr(signal, stop))
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 128 + getattr(signal, stop), stderr
    assert "Traceback" not in stderr
    assert f"error: terminated ({stop}): nothing was written" in stderr
    assert list(out.iterdir()) == []


@pytest.mark.parametrize("stop", ["SIGTERM", "SIGHUP"])
def test_a_request_to_stop_while_the_arguments_are_read_keeps_its_exit_code(stop: str) -> None:
    # Typer turns any KeyboardInterrupt it meets while it reads the arguments (a Terminated
    # included) into a Ctrl-C's status: a SIGTERM there exited 130, "interrupted".
    script = (
        "import os, signal, sys, time\nimport typer.core\n"
        "def parse_args(self, ctx, args):\n"
        f"    os.kill(os.getpid(), signal.{stop})\n    time.sleep(5)\n"
        "typer.core.TyperCommand.parse_args = parse_args\n"
        "sys.argv = ['aura-ums', 'replay', 'log', '--terrain', 't.toml']\n"
        "from aura_ums.cli import main\nmain()\n"
    )
    command = [sys.executable, "-c", script]
    done = subprocess.run(command, capture_output=True, text=True, check=False, timeout=60)
    assert done.returncode == 128 + getattr(signal, stop), done.stderr
    assert done.stderr == f"error: terminated ({stop}): nothing was written\n"


def _group(leader: int) -> dict[int, str]:
    """Return the processes of ``leader``'s process group, each with its command line (Linux's /proc)."""
    found = {}
    for entry in Path("/proc").iterdir():
        try:
            # the fields after the command's name, which is in parentheses and may hold spaces
            fields = (entry / "stat").read_text().rpartition(")")[2].split()
            # a zombie is gone, only not yet reaped by whoever inherited it
            if entry.name.isdigit() and int(fields[2]) == leader and fields[0] != "Z":
                found[int(entry.name)] = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode()
        except (OSError, IndexError, ValueError):  # gone meanwhile, or no process
            continue
    return found


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs Linux's /proc")
@pytest.mark.parametrize("stop", ["SIGINT", "SIGTERM", "SIGHUP"])
def test_a_stop_while_local_dask_workers_start_leaves_no_traceback_and_no_worker(
    stop: str, tmp_path: Path
) -> None:
    """Sent to the whole process group, as a terminal's Ctrl-C is, the moment a worker process starts.

    The workers printed their KeyboardInterrupt tracebacks while they imported, and the
    half-started cluster Dask's ("Nanny failed to start", an AssertionError at exit).
    """
    pytest.importorskip("distributed", reason="the dask extra is not installed")
    cli = Path(sys.executable).with_name("aura-ums")
    out = tmp_path / "out"
    out.mkdir()
    scenario = Path(__file__).resolve().parents[2] / "scenarios" / "paper_sidewalk.toml"
    command = [str(cli), "simulate", str(scenario), "--runs", "20", "--workers", "2"]
    command += ["--metrics-json", str(out / "metrics.json")]
    process = subprocess.Popen(
        command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True
    )
    try:
        waited = time.monotonic()
        while process.poll() is None and time.monotonic() - waited < 60:
            if any("spawn_main" in line for line in _group(process.pid).values()):
                break  # a worker process is starting: the cluster is half-started
            time.sleep(0.005)
        os.killpg(process.pid, getattr(signal, stop))
        _, stderr = process.communicate(timeout=60)
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGKILL)  # whatever is left, for the next tests
    assert process.returncode == 128 + getattr(signal, stop), stderr
    said = "interrupted" if stop == "SIGINT" else f"terminated ({stop})"
    assert stderr == f"error: {said}: nothing was written\n"
    assert list(out.iterdir()) == []
    waited = time.monotonic()
    while _group(process.pid) and time.monotonic() - waited < 10:
        time.sleep(0.05)  # the workers the cluster stopped may take a moment to be gone
    assert _group(process.pid) == {}


# A SIGKILL half-way through an output a library writer streams to disk itself: after the
# 25th scene of the MCAP file, or the first rows of the per-step CSV.
_KILLED_WHILE_WRITING = {
    "--mcap": (
        "from foxglove import channels\n"
        "original = channels.SceneUpdateChannel.log\n"
        "calls = []\n"
        "def log(self, *args, **kwargs):\n"
        "    calls.append(1)\n"
        "    if len(calls) == 25:\n"
        "        os.kill(os.getpid(), signal.SIGKILL)\n"
        "    original(self, *args, **kwargs)\n"
        "channels.SceneUpdateChannel.log = log\n"
    ),
    "--steps-csv": (
        "from aura_ums.logs import _replay\n"
        "original = _replay._StepsCsv.write\n"
        "def write(self, trace):\n"
        "    original(self, trace)\n"
        "    self.stream.flush()\n"
        "    os.kill(os.getpid(), signal.SIGKILL)\n"
        "_replay._StepsCsv.write = write\n"
    ),
}


@pytest.mark.parametrize("option", sorted(_KILLED_WHILE_WRITING))
def test_a_kill_while_an_output_is_written_leaves_one_scratch_file_and_the_old_output(
    option: str, inputs: Path, tmp_path: Path
) -> None:
    # The MCAP writer and the per-step CSV wrote a scratch file of the command's scratch file:
    # twice the writing, and a kill left .replay.mcap.<hex>.tmp.<hex>.tmp behind.
    if option == "--mcap":
        pytest.importorskip("foxglove", reason="the foxglove extra is not installed")
    out = tmp_path / "out"
    out.mkdir()
    name = "replay.mcap" if option == "--mcap" else "steps.csv"
    (out / name).write_text("the old file")
    arguments = ["replay", str(inputs / "log"), "--terrain", str(inputs / "terrain.toml")]
    arguments += [option, str(out / name), "--overwrite", "--quiet"]
    script = (
        "import os, signal, sys\n"
        + _KILLED_WHILE_WRITING[option]
        + f"sys.argv = ['aura-ums', *{arguments!r}]\nfrom aura_ums.cli import main\nmain()\n"
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert done.returncode == -signal.SIGKILL, done.stderr
    left = sorted(path.name for path in out.iterdir() if path.name != name)
    assert len(left) == 1, left
    assert (out / name).read_text() == "the old file"
    scratch = out / left[0]
    assert re.fullmatch(rf"\.{re.escape(name)}\.[0-9a-f]{{16}}\.tmp", scratch.name), scratch.name
    assert scratch.stat().st_size > 0  # killed while writing it, not before
    # Run again, the scratch file is no output: the output is written whole, the scratch
    # file left to the user (another run might still be writing it).
    again = runner.invoke(app, arguments)
    assert again.exit_code == 0, again.output
    assert sorted(path.name for path in out.iterdir()) == [scratch.name, name]
    assert (out / name).read_bytes() != b"the old file"
