"""``--workers``, ``--scheduler``: simulate, replay and calibrate as campaigns equal the serial commands."""

from __future__ import annotations

import dataclasses
import json
import socket
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

from aura_ums import Metrics
from aura_ums.cli import app
from aura_ums.logs import synthetic_log, write_log
from aura_ums.uncertainty import TerrainTable

runner = CliRunner()
SCENARIO = str(Path(__file__).resolve().parents[2] / "scenarios" / "paper_sidewalk.toml")
# Measured times: never equal between two runs.
TIMING = {"median_frame_ms", "median_update_us"}


def strict_json(text: str) -> Any:
    def refuse(constant: str) -> None:
        raise ValueError(f"not JSON: {constant}")

    return json.loads(text, parse_constant=refuse)


def untimed(figures: dict[str, Any]) -> dict[str, Any]:
    return {k: v for k, v in figures.items() if k not in TIMING}


@pytest.fixture(scope="module")
def log_folders(tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    root = tmp_path_factory.mktemp("logs")
    return [
        write_log(synthetic_log(np.random.default_rng(seed), duration=20.0), root / f"r{seed}")
        for seed in (4, 5)
    ]


@pytest.fixture
def floor_terrain(tmp_path: Path) -> Path:
    """A terrain table naming the synthetic logs' terrain, ``floor``."""
    terrain = tmp_path / "terrain.toml"
    terrain.write_text(TerrainTable({"floor": TerrainTable.default()["tile"]}).to_toml())
    return terrain


def test_simulate_on_two_workers_writes_the_serial_metrics(tmp_path: Path) -> None:
    pytest.importorskip("distributed", reason="the dask extra is not installed")
    written = {}
    for workers in ("1", "2"):
        out = tmp_path / f"w{workers}.json"
        args = ["simulate", SCENARIO, "--runs", "4", "--seed", "3", "--workers", workers]
        result = runner.invoke(app, [*args, "--metrics-json", str(out)])
        assert result.exit_code == 0, result.output
        written[workers] = strict_json(out.read_text())
    assert set(written["2"]) == {key.name for key in Metrics.table() if "simulate" in key.written_by}
    assert written["2"]["runs_retried"] == 0
    assert untimed(written["2"]) == untimed(written["1"])


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--workers", "0"], r"--workers: expected an integer in [1, 256], got 0"),
        (["--retries", "-1"], r"--retries: expected an integer in [0, 100], got -1"),
        (["--run-timeout", "0"], r"--run-timeout: expected a finite number of seconds > 0 or None, got 0.0"),
        (["--workers", "2", "--scheduler", "tcp://127.0.0.1:1"], "--workers: expected 1 with a scheduler"),
        # Refused before distributed is asked: its Client left a thread that kept the command alive.
        (
            ["--scheduler", "nonsense"],
            "--scheduler: expected a Dask scheduler address [tcp:// or tls://]HOST:PORT",
        ),
        (["--scheduler", "tcp://host:99999"], "--scheduler: expected a Dask scheduler address"),
    ],
)
def test_bad_campaign_options_are_clean_errors(options: list[str], message: str) -> None:
    result = runner.invoke(app, ["simulate", SCENARIO, "--runs", "1", *options])
    assert result.exit_code == 2
    assert message in result.output
    assert "Traceback" not in result.output


def test_a_scheduler_address_nothing_listens_at_is_refused_at_once() -> None:
    """Not after distributed's 30 s of retries: the port is probed first."""
    with socket.socket() as probe:  # a port just free: nothing listens at it
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    address = f"tcp://127.0.0.1:{port}"
    result = runner.invoke(app, ["simulate", SCENARIO, "--runs", "1", "--scheduler", address])
    assert result.exit_code == 2
    assert result.stderr.startswith(
        f"error: --scheduler: expected a Dask scheduler at '{address}', got ConnectionRefusedError"
    )


def test_without_the_extra_workers_name_it_and_one_worker_runs(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "distributed", None)
    result = runner.invoke(app, ["simulate", SCENARIO, "--runs", "1", "--workers", "2"])
    assert result.exit_code == 2
    assert "install aura-ums[dask]" in result.output
    assert "Traceback" not in result.output
    assert runner.invoke(app, ["simulate", SCENARIO, "--runs", "1"]).exit_code == 0


def test_replay_of_several_logs_lists_each_as_its_own_replay(log_folders: list[Path], tmp_path: Path) -> None:
    terrain = tmp_path / "terrain.toml"
    calibrated = runner.invoke(app, ["calibrate", *map(str, log_folders), "--out", str(terrain)])
    assert calibrated.exit_code == 0, calibrated.output
    out = tmp_path / "all.json"
    both = runner.invoke(
        app, ["replay", *map(str, log_folders), "--terrain", str(terrain), "--metrics-json", str(out)]
    )
    assert both.exit_code == 0, both.output
    together = strict_json(out.read_text())
    assert set(together) == {key.name for key in Metrics.table() if "replay (several logs)" in key.written_by}
    assert together["runs_retried"] == 0
    for folder, entry in zip(log_folders, together["replays"], strict=True):
        alone = tmp_path / f"{folder.name}.json"
        result = runner.invoke(
            app, ["replay", str(folder), "--terrain", str(terrain), "--metrics-json", str(alone)]
        )
        assert result.exit_code == 0, result.output
        assert untimed(entry) == untimed(strict_json(alone.read_text()))


def test_replay_of_several_logs_names_the_terrain_file_and_the_log_without_its_terrain(
    log_folders: list[Path], tmp_path: Path
) -> None:
    terrain = tmp_path / "other.toml"
    terrain.write_text(TerrainTable.default().to_toml())  # no 'floor', the logs' terrain
    result = runner.invoke(app, ["replay", *map(str, log_folders), "--terrain", str(terrain), "-q"])
    assert result.exit_code == 2
    # was "table: expected a terrain 'floor' (the log's), got none of that name"
    assert result.stderr == (
        f"error: {terrain}: expected the terrain 'floor' of the log in {log_folders[0]} (its meta.toml), "
        "got 'tile', 'concrete', 'grass', 'gravel'\n"
    )


@pytest.mark.parametrize(
    ("until", "message"),
    [
        ("-1", "--until: expected a time at or after the replay's start (0.0 s), got -1.0"),
        (
            "0.01",
            "{log}: --until: expected a frame (an observation time) between the replay's start (0 s) "
            "and 0.01 s, got none",
        ),
    ],
    ids=["before-start", "before-first-frame"],
)
def test_replay_of_several_logs_names_until_as_the_option(
    log_folders: list[Path], floor_terrain: Path, until: str, message: str
) -> None:
    # was "until: expected ..." and "LOG: until: expected ...": the library's argument, not the option
    args = ["replay", *map(str, log_folders), "--terrain", str(floor_terrain), "-q", "--until", until]
    result = runner.invoke(app, args)
    assert result.exit_code == 2
    assert result.stderr == f"error: {message.format(log=log_folders[0])}\n"


def test_replay_of_several_logs_refuses_the_outputs_of_one(log_folders: list[Path], tmp_path: Path) -> None:
    args = ["replay", *map(str, log_folders), "--terrain", str(tmp_path / "t.toml")]
    result = runner.invoke(app, [*args, "--steps-csv", str(tmp_path / "s.csv")])
    assert result.exit_code == 2
    assert "--steps-csv: expected one LOG_DIR, got 2" in result.output


@pytest.mark.parametrize("mode", ["full_frame", "focus_first"])
def test_simulate_perception_runs_the_campaign_in_that_mode(tmp_path: Path, mode: str) -> None:
    from aura_ums.campaign import simulate_campaign
    from aura_ums.manager import MapProfile
    from aura_ums.sim import PerceptionMode, Scenario, summarize_runs

    corridor = Path(SCENARIO).with_name("indoor_corridor.toml")
    out = tmp_path / "m.json"
    args = ["simulate", str(corridor), "--runs", "2", "--seed", "5", "--profile", "relaxed", "--quiet"]
    result = runner.invoke(app, [*args, "--perception", mode, "--metrics-json", str(out)])
    assert result.exit_code == 0, result.output
    written = strict_json(out.read_text())
    assert written["perception"] == mode
    # The same as the library's campaign in that mode, and not the windows' campaign.
    loaded = Scenario.from_toml(corridor)
    relaxed = dataclasses.replace(loaded, settings=MapProfile.RELAXED.settings(loaded.settings))
    figures = {
        chosen: json.loads(
            summarize_runs(simulate_campaign(relaxed, 2, 5, perception=chosen).values).to_json()
        )
        for chosen in (PerceptionMode(mode), PerceptionMode.WINDOWS)
    }
    assert all(written[key] == value for key, value in untimed(figures[PerceptionMode(mode)]).items())
    # Focus-first finds what the windows find here (tests/campaign checks its windows).
    if mode == "full_frame":
        assert untimed(figures[PerceptionMode(mode)]) != untimed(figures[PerceptionMode.WINDOWS])


def test_simulate_refuses_an_unknown_perception() -> None:
    result = runner.invoke(app, ["simulate", SCENARIO, "--runs", "1", "--perception", "everywhere"])
    assert result.exit_code == 2
    assert "--perception" in result.output
    assert "everywhere" in result.output


def test_a_log_lost_to_the_run_timeout_is_named_with_the_option(
    log_folders: list[Path], floor_terrain: Path
) -> None:
    # "run 0: ... (last: no result within 1e-09 s)" named neither the log nor --run-timeout
    pytest.importorskip("distributed", reason="the dask extra is not installed")
    terrain = floor_terrain
    options = ["--terrain", str(terrain), "-q", "--workers", "2", "--retries", "0", "--run-timeout", "1e-9"]
    result = runner.invoke(app, ["replay", *map(str, log_folders), *options])
    assert result.exit_code == 2
    assert result.stderr.startswith("error: run ")
    assert f" ({log_folders[0]}): " in result.stderr or f" ({log_folders[1]}): " in result.stderr
    assert result.stderr.endswith(
        ": expected it to finish within 0 retries, got it lost 1 times "
        "(last: no result within --run-timeout 1e-09 s)\n"
    )


def test_a_missing_log_among_many_on_workers_gives_the_clean_message_alone(
    log_folders: list[Path], tmp_path: Path, floor_terrain: Path
) -> None:
    # the workers logged "Compute Failed" and the task's traceback before the clean message
    pytest.importorskip("distributed", reason="the dask extra is not installed")
    import subprocess

    terrain = floor_terrain
    missing = tmp_path / "r3"
    aura = Path(sys.executable).with_name("aura-ums")
    command: list[str | Path] = [
        aura,
        "replay",
        log_folders[0],
        missing,
        "--terrain",
        terrain,
        "-q",
        "--workers",
        "2",
    ]
    done = subprocess.run(command, capture_output=True, text=True, check=False, timeout=120)
    assert done.returncode == 2
    assert done.stderr == f"error: {missing}: expected a log folder, got no such folder\n"
    assert done.stdout == ""
