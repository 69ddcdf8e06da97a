"""``replay --live`` and ``simulate --live``: the real command streams to a client that watches it."""

from __future__ import annotations

import json
import queue
import re
import socket
import subprocess
import sys
import threading
import time
from collections import Counter
from pathlib import Path

import pytest
from typer.testing import CliRunner

from aura_ums.cli import app
from aura_ums.uncertainty import TerrainTable
from tests.export.live_client import LiveClient, Received

ROOT = Path(__file__).resolve().parents[2]
SAMPLE = ROOT / "examples" / "logs" / "r1"
CAMERA = ROOT / "examples" / "virtual_camera_60deg.toml"
WAIT = 60.0  # seconds the test waits for the command at most (a loaded machine is slow)
runner = CliRunner()


@pytest.fixture(scope="module")
def terrain(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("terrain") / "floor.toml"
    path.write_text(TerrainTable({"floor": TerrainTable.default()["tile"]}).to_toml())
    return path


def _watch(arguments: list[str]) -> tuple[subprocess.CompletedProcess[str], list[Received]]:
    """Run the command with ``--live --live-port 0``, watch it with a client to the end; return what came."""
    command = [str(Path(sys.executable).with_name("aura-ums")), *arguments, "--live", "--live-port", "0"]
    lines: queue.Queue[str] = queue.Queue()
    errors: list[str] = []
    messages: list[Received] = []
    with subprocess.Popen(
        command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT
    ) as process:
        assert process.stdout is not None
        assert process.stderr is not None
        stderr = process.stderr

        def read_stderr() -> None:
            for line in stderr:
                errors.append(line)
                lines.put(line)

        reader = threading.Thread(target=read_stderr, daemon=True)
        reader.start()
        try:
            _watch_until_streamed(lines, errors, messages)
            # the client has left: the command stops its server and ends (its few results fit the pipe)
            process.wait(timeout=WAIT)
            stdout = process.stdout.read()
        finally:
            if process.poll() is None:
                process.kill()
        reader.join(WAIT)
    return subprocess.CompletedProcess(command, process.returncode, stdout, "".join(errors)), messages


def _watch_until_streamed(lines: queue.Queue[str], errors: list[str], messages: list[Received]) -> None:
    """Connect to the URL the command prints, subscribe to everything, read until all it streamed came."""
    url = ""
    while not url:
        found = re.search(r"live: serving on (ws://127\.0\.0\.1:\d+);", lines.get(timeout=WAIT))
        url = found.group(1) if found else ""
    with LiveClient(url) as client:
        client.subscribe(set(client.advertised({"/map/polygon", "/metrics"})))
        deadline = time.monotonic() + WAIT
        while time.monotonic() < deadline:
            client.pump(0.2)
            messages += client.take()
            done = [re.search(r"live: streamed (\d+) ", line) for line in errors]
            streamed = next((int(m.group(1)) for m in done if m), -1)
            if 0 < streamed <= sum(1 for m in messages if m.topic == "/metrics"):
                return
    raise AssertionError(f"the command did not stream to the end within {WAIT} s: {''.join(errors)}")


def test_replay_live_streams_maps_and_windows_then_writes_its_results(terrain: Path, tmp_path: Path) -> None:
    metrics_json = tmp_path / "m.json"
    arguments = ["replay", str(SAMPLE), "--terrain", str(terrain), "--classes", "II", "--camera", str(CAMERA)]
    # 20 s of the log: fewer messages than the server queues for a client, however slow the client
    live = ["--until", "20", "--live-rate", "0"]
    done, messages = _watch([*arguments, *live, "--metrics-json", str(metrics_json), "-q"])
    assert done.returncode == 0, done.stderr
    steps = json.loads(metrics_json.read_text())["steps"]
    assert f"live: streamed {steps} steps" in done.stderr
    assert "live: server stopped" in done.stderr
    counts = Counter(m.topic for m in messages)
    for topic in ("/map/polygon", "/map/wedge", "/map/center", "/truth", "/metrics", "/camera/annotations"):
        assert counts[topic] == steps, topic
    windows = [p for m in messages if m.topic == "/camera/annotations" for p in m.data.get("points", [])]
    assert sum(1 for p in windows if p["type"] == 2) > steps  # LINE_LOOP rectangles: the windows
    assert counts["/landmarks"] >= 1
    assert "containment_rate" in done.stdout


def test_simulate_live_streams_each_run(tmp_path: Path) -> None:
    scenario = ROOT / "scenarios" / "paper_sidewalk.toml"
    # --live-wait long enough for the client: the run streams as without it
    done, messages = _watch(
        ["simulate", str(scenario), "--runs", "2", "--live-rate", "0", "-q", "--live-wait", "60"]
    )
    assert done.returncode == 0, done.stderr
    metrics = [m.data for m in messages if m.topic == "/metrics"]
    assert {m["run"] for m in metrics} == {1, 2}
    assert sum(1 for m in messages if m.topic == "/camera/image") == len(metrics)
    frames = re.search(r"frames\s+(\d+)", done.stdout)
    assert frames is not None
    assert int(frames.group(1)) == len(metrics)


def test_no_client_within_live_wait_exits_2_having_computed_nothing(terrain: Path, tmp_path: Path) -> None:
    # --live waited for Foxglove with no limit: a scripted run without a client hung. In a
    # process of its own: the server's import of foxglove stays out of this one
    # (test_missing_extra_names_it hides the package from it).
    metrics = tmp_path / "m.json"
    options = ["--terrain", str(terrain), "-q", "--live", "--live-port", "0", "--metrics-json", str(metrics)]
    aura = str(Path(sys.executable).with_name("aura-ums"))
    result = subprocess.run(
        [aura, "replay", str(SAMPLE), *options, "--live-wait", "0.2"],
        capture_output=True,
        text=True,
        timeout=WAIT,
        check=False,
    )
    assert result.returncode == 2
    assert re.search(
        r"error: --live-wait: expected a Foxglove client at ws://127\.0\.0\.1:\d+ within 0\.2 s, got none\n$",
        result.stderr,
    )
    assert "(waiting for up to 0.2 s for it to subscribe; Ctrl-C to stop)" in result.stderr
    assert list(tmp_path.iterdir()) == []
    alone = runner.invoke(app, ["replay", str(SAMPLE), "--terrain", str(terrain), "--live-wait", "5"])
    assert alone.exit_code == 2
    assert alone.stderr == "error: --live-wait: expected --live too, got no --live\n"
    bad = runner.invoke(app, ["replay", str(SAMPLE), *options, "--live-wait", "soon"])
    assert bad.stderr == "error: --live-wait: expected a finite number of seconds >= 0 or none, got 'soon'\n"


def test_a_port_in_use_names_the_option(terrain: Path) -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        result = runner.invoke(
            app, ["replay", str(SAMPLE), "--terrain", str(terrain), "--live", "--live-port", str(port)]
        )
    assert result.exit_code == 2
    assert (
        f"error: --live-port: expected a free port on 127.0.0.1, got {port}, which is in use" in result.stderr
    )


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [
        (
            "--live-rate",
            "-1",
            "error: --live-rate: expected a finite number >= 0 (0: as fast as computed), got -1.0",
        ),
        ("--live-port", "70000", "error: --live-port: expected an integer from 0 to 65535, got 70000"),
    ],
)
def test_bad_live_options_name_the_option(option: str, value: str, message: str) -> None:
    scenario = ROOT / "scenarios" / "paper_sidewalk.toml"
    result = runner.invoke(app, ["simulate", str(scenario), "--runs", "1", "--live", option, value])
    assert result.exit_code == 2
    assert message in result.stderr


def test_missing_extra_names_it(terrain: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    for name in [m for m in sys.modules if m == "foxglove" or m.startswith("foxglove.")]:
        monkeypatch.setitem(sys.modules, name, None)
    result = runner.invoke(app, ["replay", str(SAMPLE), "--terrain", str(terrain), "--live"])
    assert result.exit_code == 2
    assert "error: --live: the live view needs the optional package 'foxglove-sdk'" in result.stderr
    assert "install aura-ums[foxglove]" in result.stderr
    # without --live nothing changes
    assert runner.invoke(app, ["replay", str(SAMPLE), "--terrain", str(terrain)]).exit_code == 0


def test_a_resumed_live_replay_streams_the_slices_of_its_saved_settings(
    terrain: Path, tmp_path: Path
) -> None:
    state = tmp_path / "s.json"
    arguments = ["replay", str(SAMPLE), "--terrain", str(terrain), "--classes", "II"]
    saved = runner.invoke(
        app, [*arguments, "--slice-width", "2deg", "--until", "10", "--save-state", str(state)]
    )
    assert saved.exit_code == 0, saved.output
    # Resumed without --slice-width: the saved (sliced) settings run, and the view shows their slices.
    done, messages = _watch([*arguments, "--resume", str(state), "--until", "20", "--live-rate", "0", "-q"])
    assert done.returncode == 0, done.stderr
    counts = Counter(m.topic for m in messages)
    assert counts["/map/slices"] == counts["/metrics"] > 0
