"""``--version``, help as written, progress bars on stderr, and ``replay --save-state/--resume``."""

from __future__ import annotations

import dataclasses
import io
import itertools
import json
import os
import shutil
import subprocess
import sys
from importlib.metadata import version
from pathlib import Path

import numpy as np
import pytest
from rich.console import Console
from typer.testing import CliRunner, Result

import aura_ums.cli._common as common
from aura_ums.cli import app
from aura_ums.logs import synthetic_log, write_log
from aura_ums.uncertainty import TerrainTable
from tests.conftest import SHARED_DATA

runner = CliRunner()
SCENARIO = Path(__file__).resolve().parents[2] / "scenarios" / "paper_sidewalk.toml"
MRCLAM6 = SHARED_DATA / "mrclam6"
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SAMPLE = EXAMPLES / "logs" / "r1"


def floor_terrain(path: Path) -> Path:
    """Write the built-in tile statistics as the terrain 'floor' (the sample logs') to ``path``."""
    path.write_text(TerrainTable({"floor": TerrainTable.default()["tile"]}).to_toml())
    return path


@pytest.fixture(scope="module")
def sample_replay(tmp_path_factory: pytest.TempPathFactory) -> list[str]:
    """``aura-ums replay`` of the sample log r1 on the floor terrain, quiet."""
    terrain = floor_terrain(tmp_path_factory.mktemp("floor") / "terrain.toml")
    return ["replay", str(SAMPLE), "-q", "--terrain", str(terrain)]


def invoke(*arguments: object) -> Result:
    result = runner.invoke(app, [str(a) for a in arguments])
    assert result.exit_code == 0, result.output
    return result


def test_version_is_the_installed_one() -> None:
    result = invoke("--version")
    assert result.stdout == f"aura-ums {version('aura-ums')}\n"


@pytest.mark.parametrize(
    "arguments", [["replay", "--help"], ["replay", "SAMPLE", "-q", "--terrain", "TERRAIN"]]
)
def test_a_stream_that_cannot_encode_every_character_gets_them_escaped(
    arguments: list[str], tmp_path: Path
) -> None:
    # The help's ellipsis raised UnicodeEncodeError on an ASCII stdout: a traceback, exit 1.
    terrain = floor_terrain(tmp_path / "terrain.toml")
    given = [str(SAMPLE) if a == "SAMPLE" else str(terrain) if a == "TERRAIN" else a for a in arguments]
    script = "from aura_ums.cli import main; main()"
    done = subprocess.run(
        [sys.executable, "-c", script, *given],
        capture_output=True,
        env={**os.environ, "PYTHONIOENCODING": "ascii", "COLUMNS": "80"},
        check=False,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr.decode("ascii", "replace")
    assert b"Traceback" not in done.stderr
    assert done.stdout
    assert done.stdout.isascii()


def test_a_misspelt_matplotlib_backend_in_the_environment_does_not_stop_a_figure(tmp_path: Path) -> None:
    # MPLBACKEND=nonexistent made `import matplotlib` raise: a ValueError traceback from --plot.
    terrain = floor_terrain(tmp_path / "terrain.toml")
    arguments = ["replay", str(SAMPLE), "-q", "--terrain", str(terrain), "--plot", str(tmp_path / "plots")]
    done = subprocess.run(
        [sys.executable, "-c", "from aura_ums.cli import main; main()", *arguments],
        capture_output=True,
        text=True,
        env={**os.environ, "MPLBACKEND": "nonexistent"},
        check=False,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert [path.suffix for path in (tmp_path / "plots").iterdir()] == [".png"]


@pytest.mark.parametrize("command", ["simulate", "replay", "compare", "calibrate", "import mrclam", "demo"])
def test_help_shows_flags_and_brackets_as_written(command: str) -> None:
    result = runner.invoke(app, [*command.split(), "--help"], env={"COLUMNS": "200"})
    assert result.exit_code == 0, result.output
    assert "<bool>" not in result.stdout
    assert "--overwrite" in result.stdout
    # Positional arguments named as click names them and typed as the options are.
    assert "Path]" not in result.stdout
    assert "<Path>" not in result.stdout
    assert "{log_dir" not in result.stdout
    assert "{dataset_dir}" not in result.stdout
    if command in ("replay", "calibrate"):
        assert "{LOG_DIRS}..." in result.stdout
        assert "<path>..." in result.stdout
    if command == "simulate":
        assert "aura-ums[foxglove]" in result.stdout
        assert "[manager]" in result.stdout
        assert "--prune" in result.stdout
        assert "--no-prune" in result.stdout


HELPED = ["", "figures", "demo", "simulate", "replay", "compare", "calibrate"]
HELPED += ["import", "import mrclam", "import rosbag"]


@pytest.mark.parametrize("command", HELPED)
def test_help_paragraphs_wrap_to_the_terminal_without_ragged_lines(command: str) -> None:
    result = runner.invoke(app, [*command.split(), "--help"], env={"COLUMNS": "80"})
    assert result.exit_code == 0, result.output
    # The description: the lines above the first box, each indented by one space.
    description = result.stdout.split("\u256d", 1)[0].splitlines()
    width = 80 - 2
    for line, following in itertools.pairwise(description):
        if line.strip() and following.strip() and not line.lstrip().startswith("Usage:"):
            # Greedy wrapping: the next line's first word would not have fit on this one.
            assert len(line.strip()) + 1 + len(following.split()[0]) > width, (line, following)


def test_progress_is_drawn_on_a_terminal_and_not_with_quiet(monkeypatch: pytest.MonkeyPatch) -> None:
    screen = io.StringIO()
    monkeypatch.setattr(common, "err_console", Console(file=screen, force_terminal=True, width=100))
    result = invoke("simulate", SCENARIO, "--runs", "3")
    assert "runs" in screen.getvalue()
    assert "3/3" in screen.getvalue()
    assert "3/3" not in result.stdout + result.stderr
    screen.truncate(0)
    screen.seek(0)
    invoke("simulate", SCENARIO, "--runs", "3", "--quiet")
    assert screen.getvalue() == ""


def test_no_progress_when_stderr_is_not_a_terminal() -> None:
    result = invoke("simulate", SCENARIO, "--runs", "2")
    assert result.stderr == ""


@pytest.fixture(scope="module")
def walk(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    base = tmp_path_factory.mktemp("walk")
    folder = write_log(synthetic_log(np.random.default_rng(6), duration=40.0), base / "log")
    return folder, floor_terrain(base / "terrain.toml")


def resumed_alike(folder: Path, terrain: Path, tmp: Path, first: float, last: float, *extra: str) -> None:
    """Replay to ``last`` in one go, and to ``first`` then resumed to ``last``: the same final state."""
    common_args = ("replay", folder, "--terrain", terrain, "--quiet", *extra)
    whole_out = ("--save-state", tmp / "whole.json", "--steps-csv", tmp / "whole.csv")
    invoke(*common_args, "--until", last, *whole_out)
    invoke(*common_args, "--until", first, "--save-state", tmp / "half.json")
    rest = invoke(
        *common_args,
        "--resume",
        tmp / "half.json",
        "--until",
        last,
        "--save-state",
        tmp / "rest.json",
        "--steps-csv",
        tmp / "rest.csv",
    )
    whole = json.loads((tmp / "whole.json").read_text())
    again = json.loads((tmp / "rest.json").read_text())
    half = json.loads((tmp / "half.json").read_text())
    assert 0 < half["frames_done"] < whole["frames_done"]
    assert again == whole  # the map, the envelope, the counters and the blackboard, bit for bit
    whole_rows = (tmp / "whole.csv").read_text().splitlines()
    rest_rows = (tmp / "rest.csv").read_text().splitlines()
    assert len(rest_rows) - 1 == whole["frames_done"] - half["frames_done"]
    # the same maps step by step after the resume (the update timing column aside)
    trimmed = [",".join(row.split(",")[:6]) for row in whole_rows[-(len(rest_rows) - 1) :]]
    assert [",".join(row.split(",")[:6]) for row in rest_rows[1:]] == trimmed
    assert "steps" in rest.stdout


def test_a_resumed_replay_ends_with_the_same_map(walk: tuple[Path, Path], tmp_path: Path) -> None:
    folder, terrain = walk
    resumed_alike(folder, terrain, tmp_path, 15.0, 40.0)


def test_a_resumed_sliced_relaxed_replay_ends_with_the_same_map(
    walk: tuple[Path, Path], tmp_path: Path
) -> None:
    # The configuration the README recommends where the truth must stay inside.
    folder, terrain = walk
    options = ("--slice-width", "2deg", "--relaxed-q", "1", "--relaxed-window", "5", "--classes", "II")
    resumed_alike(folder, terrain, tmp_path, 15.0, 40.0, *options)
    saved = json.loads((tmp_path / "rest.json").read_text())
    assert saved["manager"]["settings"]["relaxed_window"] == 5


def test_a_resumed_replay_refuses_options_other_than_its_saved_settings(
    walk: tuple[Path, Path], tmp_path: Path
) -> None:
    folder, terrain = walk
    state = tmp_path / "s.json"
    common_args = ("replay", folder, "--terrain", terrain, "--classes", "II", "--quiet")
    invoke(*common_args, "--profile", "relaxed", "--until", "15", "--save-state", state)
    # Left out, or given as saved: the saved settings run, and the metrics report them.
    for same in ((), ("--profile", "relaxed"), ("--relaxed-window", "5", "--robust")):
        result = invoke(*common_args, "--resume", state, *same)
        assert "relaxed_q                    1" in result.stdout
        assert "relaxed_window               5" in result.stdout
    refused = {
        ("--relaxed-q", "0"): "--relaxed-q: expected relaxed_q 1, as --resume's state was saved with",
        # The first setting the profile asks otherwise (in the fields' order) is named.
        (
            "--profile",
            "sliced",
        ): "--profile sliced: expected max_slices 180, as --resume's state was saved with",
        ("--gate-only",): "--robust/--gate-only: expected robust true, as --resume's state was saved with",
    }
    for other, message in refused.items():
        result = runner.invoke(app, [str(a) for a in (*common_args, "--resume", state, *other)])
        assert result.exit_code == 2, other
        assert message in result.stderr
        assert "Traceback" not in result.output


def test_a_state_from_another_log_is_refused(walk: tuple[Path, Path], tmp_path: Path) -> None:
    folder, terrain = walk
    invoke("replay", folder, "--terrain", terrain, "--until", "10", "--save-state", tmp_path / "s.json")
    other = write_log(synthetic_log(np.random.default_rng(9), duration=40.0), tmp_path / "other")
    result = runner.invoke(
        app, ["replay", str(other), "--terrain", str(terrain), "--resume", str(tmp_path / "s.json")]
    )
    assert result.exit_code == 2
    assert "resume: expected a state saved from a replay of log" in result.stderr
    broken = tmp_path / "broken.json"
    broken.write_text('{"format": "aura_ums.ReplayState", "version": 2, "log": "x"}')
    result = runner.invoke(app, ["replay", str(folder), "--terrain", str(terrain), "--resume", str(broken)])
    assert result.exit_code == 2
    assert str(broken) in result.stderr
    assert "Traceback" not in result.output


def test_until_before_the_resumed_state_is_refused_naming_both(
    walk: tuple[Path, Path], tmp_path: Path
) -> None:
    # It was accepted: nothing after the state was replayed, and the empty result exited 0.
    folder, terrain = walk
    state = tmp_path / "s.json"
    invoke("replay", folder, "--terrain", terrain, "--until", "20", "--save-state", state)
    last = json.loads(state.read_text())["last_time"]
    result = runner.invoke(
        app, ["replay", str(folder), "--terrain", str(terrain), "--resume", str(state), "--until", "10"]
    )
    assert result.exit_code == 2
    assert result.stderr == (
        f"error: --until: expected a time at or after the state in {state}'s last frame ({last!r} s), "
        "got 10.0\n"
    )
    resumed = runner.invoke(
        app, ["replay", str(folder), "--terrain", str(terrain), "--resume", str(state), "--until", str(last)]
    )
    # At the state's own last frame: nothing left. It exited 0 with every figure n/a; it is
    # refused as any replay of no frame is (a state saved again is an answer).
    assert resumed.exit_code == 2
    assert resumed.stderr == (
        f"error: --resume: expected a state with frames left after it, got {state}, saved at {last:g} s "
        f"(--until {last:g}): nothing is left to replay\n"
    )


def test_a_bad_resume_names_the_option_and_file_and_until_must_be_finite(
    walk: tuple[Path, Path], tmp_path: Path
) -> None:
    folder, terrain = walk
    state = tmp_path / "s.json"
    invoke("replay", folder, "--terrain", terrain, "--until", "10", "--save-state", state)
    other = write_log(synthetic_log(np.random.default_rng(9), duration=40.0), tmp_path / "other")
    result = runner.invoke(app, ["replay", str(other), "--terrain", str(terrain), "--resume", str(state)])
    assert result.exit_code == 2
    assert f"error: {state}: --resume: expected a state saved from a replay of log" in result.stderr
    saved = json.loads(state.read_text())
    saved["manager"]["map"]["vertices"] = []
    state.write_text(json.dumps(saved))
    result = runner.invoke(app, ["replay", str(folder), "--terrain", str(terrain), "--resume", str(state)])
    assert result.exit_code == 2
    assert f"error: {state}: --resume: map.vertices: expected at least one vertex, got none" in result.stderr
    result = runner.invoke(app, ["replay", str(folder), "--terrain", str(terrain), "--until", "nan"])
    assert result.exit_code == 2
    assert "error: --until: expected a finite number of seconds, got nan" in result.stderr


@pytest.mark.skipif(
    not (MRCLAM6 / "Robot1_Measurement.dat").is_file(),
    reason=f"UTIAS MRCLAM Dataset 6 not found at {MRCLAM6} (shared data is not part of the repository)",
)
def test_a_resumed_mrclam6_replay_ends_with_the_same_map(tmp_path: Path) -> None:
    log = tmp_path / "log"
    invoke("import", "mrclam", MRCLAM6, log, "--robot", "1", "--quiet")
    invoke("calibrate", log, "--out", tmp_path / "terrain.toml")
    first = float((log / "observations.csv").read_text().splitlines()[2].split(",")[0])
    sensors = ("--sensors", str(tmp_path / "terrain.sensors.toml"), "--classes", "II")
    resumed_alike(log, tmp_path / "terrain.toml", tmp_path, first + 60.0, first + 150.0, *sensors)


def test_an_option_that_would_have_no_effect_is_refused(walk: tuple[Path, Path], tmp_path: Path) -> None:
    folder, terrain = walk
    replay = ("replay", folder, "--terrain", terrain, "--quiet")
    cases = {
        (*replay, "--window-margin", "5"): "--window-margin: expected --camera too, got no camera",
        (*replay, "--live-port", "9000"): "--live-port: expected --live too, got no --live",
        (*replay, "--retries", "0"): "--retries: expected --workers above 1 or --scheduler too, got neither",
        ("simulate", SCENARIO, "--runs", "1", "--live-rate", "2"): "--live-rate: expected --live too",
        (
            "simulate",
            SCENARIO,
            "--runs",
            "1",
            "--run-timeout",
            "5",
        ): "--run-timeout: expected --workers above 1",
        (
            "calibrate",
            folder,
            "--out",
            tmp_path / "never.toml",
            "--retries",
            "2",
        ): "--retries: expected --workers",
    }
    for arguments, message in cases.items():
        result = runner.invoke(app, [str(a) for a in arguments])
        assert result.exit_code == 2, arguments
        assert message in result.stderr
        assert "Traceback" not in result.output
    assert not (tmp_path / "never.toml").exists()
    # The same options with what they need, or left out, run.
    assert "containment_rate" in invoke(*replay).stdout


def test_until_before_the_start_and_a_run_timeout_of_none(tmp_path: Path, sample_replay: list[str]) -> None:
    replay = sample_replay
    # --until -1 replayed no frame and exited 0 with figures of none
    result = runner.invoke(app, [*replay, "--until", "-1"])
    assert result.exit_code == 2
    assert result.stderr.startswith("error: --until: expected a time at or after the replay's start (")
    # "default none" in the help, and 'none' was refused by typer
    result = runner.invoke(app, [*replay, "--run-timeout", "none"])
    assert result.stderr.startswith("error: --run-timeout: expected --workers above 1 or --scheduler too")
    bad = runner.invoke(app, [*replay, "--run-timeout", "soon"])
    assert bad.exit_code == 2
    assert bad.stderr == "error: --run-timeout: expected a positive number of seconds or none, got 'soon'\n"


def test_a_resumed_state_whose_parts_disagree_names_the_file(
    tmp_path: Path, sample_replay: list[str]
) -> None:
    # "blackboard: expected the one this manager reads, ..." named no file
    replay = sample_replay
    state = tmp_path / "state.json"
    invoke(*replay, "--until", "20", "--save-state", state)
    document = json.loads(state.read_text())
    document["manager"]["map_time"] = 1e9
    edited = tmp_path / "edited.json"
    edited.write_text(json.dumps(document))
    result = runner.invoke(app, [*replay, "--resume", str(edited)])
    assert result.exit_code == 2
    assert result.stderr.startswith(
        f"error: {edited}: --resume: blackboard: expected the one this manager reads"
    )


def test_a_replay_of_no_frame_is_refused_and_leaves_no_output(tmp_path: Path) -> None:
    # a ground truth 10,000 s after the motion (the clocks check allows a day): 0 steps,
    # every figure n/a, exit 0; and --until before the first frame did the same
    sample = SAMPLE
    late = tmp_path / "late"
    shutil.copytree(sample, late)
    truth = late / "groundtruth.csv"
    lines = truth.read_text().splitlines()
    shifted = [
        f"{float(time) + 10000.0!r},{rest}" for time, rest in (line.split(",", 1) for line in lines[2:])
    ]
    truth.write_text("\n".join([*lines[:2], *shifted]) + "\n")
    terrain = floor_terrain(tmp_path / "terrain.toml")
    steps = tmp_path / "steps.csv"
    result = runner.invoke(
        app, ["replay", str(late), "-q", "--terrain", str(terrain), "--steps-csv", str(steps)]
    )
    assert result.exit_code == 2
    assert result.stdout == ""
    assert result.stderr.startswith(
        f"error: {late}: log 'sample-r1': expected a frame (an observation time) after the replay's start, "
        "10000 s, got none"
    )
    assert not steps.exists()
    assert sorted(path.name for path in tmp_path.iterdir()) == ["late", "terrain.toml"]
    # among many logs, the folder is named
    many = runner.invoke(app, ["replay", str(sample), str(late), "-q", "--terrain", str(terrain)])
    assert many.exit_code == 2
    assert many.stderr.startswith(f"error: {late}: log 'sample-r1': expected a frame")
    early = runner.invoke(app, ["replay", str(sample), "-q", "--terrain", str(terrain), "--until", "0.05"])
    assert early.exit_code == 2
    assert early.stderr == (
        "error: --until: expected a frame (an observation time) between the replay's start (0 s) and 0.05 s, "
        "got none\n"
    )


def test_a_camera_that_sees_no_observation_is_warned_about(tmp_path: Path, sample_replay: list[str]) -> None:
    # a camera turned backwards reported 0 window observations and n/a, on stdout alone
    root = EXAMPLES
    camera = tmp_path / "back.toml"
    text = (root / "virtual_camera_60deg.toml").read_text()
    camera.write_text(text.replace("pan_deg = 0.0 ", "pan_deg = 180.0", 1))
    replay = [*sample_replay, "--until", "10"]
    result = invoke(*replay, "--camera", camera)
    assert "window_observations            0\n" in result.stdout
    assert result.stderr.startswith(
        f"warning: --camera: expected some of the 33 observations to fall in the image of {camera}, got none"
    )
    seen = invoke(*replay, "--camera", root / "virtual_camera_60deg.toml")
    assert "warning" not in seen.stderr


@pytest.mark.parametrize("whole", [False, True], ids=["streamed", "loaded"])
def test_ground_truth_too_sparse_to_score_any_frame_is_warned_about(tmp_path: Path, whole: bool) -> None:
    # ground truth once a second, off the frames' times: every frame unscored, n/a, nothing said
    sparse = tmp_path / "sparse"
    shutil.copytree(SAMPLE, sparse)
    truth = sparse / "groundtruth.csv"
    lines = truth.read_text().splitlines()
    rows = [line.split(",", 1) for line in lines[2:]]
    kept = [f"{float(time) + 0.013!r},{rest}" for time, rest in rows if float(time) == round(float(time))]
    truth.write_text("\n".join([*lines[:2], *kept]) + "\n")
    replay = ["replay", sparse, "-q", "--terrain", floor_terrain(tmp_path / "terrain.toml")]
    if whole:  # a figure needs the whole log loaded, not streamed
        replay += ["--plot", tmp_path / "plot"]
    result = invoke(*replay)
    assert "steps_with_truth             0\n" in result.stdout
    assert "containment_rate             n/a\n" in result.stdout
    assert result.stderr.startswith(
        f"warning: {sparse}: expected some frames between ground-truth rows at most --max-truth-gap 0.5 s "
        "apart, got none of the 178 frames"
    )
    assert "is recorded more sparsely, pass a larger --max-truth-gap\n" in result.stderr
    scored = invoke(*replay, "--max-truth-gap", "1.5", "--overwrite")
    assert "steps_with_truth             178\n" in scored.stdout
    assert "warning" not in scored.stderr


def test_resuming_a_state_saved_at_the_end_is_refused(tmp_path: Path, sample_replay: list[str]) -> None:
    # 0 steps and every figure n/a, exit 0: a resumed replay with nothing left
    replay = sample_replay
    end = tmp_path / "end.json"
    invoke(*replay, "--save-state", end)
    result = runner.invoke(app, [*replay, "--resume", str(end)])
    assert result.exit_code == 2
    assert result.stderr.endswith(
        f"error: --resume: expected a state with frames left after it, got {end}, saved at 60 s: "
        "nothing is left to replay\n"
    )
    # saving the state again is an answer: the same state
    again = tmp_path / "again.json"
    invoke(*replay, "--resume", end, "--save-state", again)
    assert again.exists()


def test_a_state_saved_before_any_frame_is_not_exported_and_nothing_is_written(
    walk: tuple[Path, Path], tmp_path: Path
) -> None:
    # --save-state takes a replay of no frame (the start map, resumable); --mcap cannot: it
    # refused only after the state, the steps CSV and the figure were written.
    folder, terrain = walk
    out = tmp_path / "out"
    out.mkdir()
    early = ["replay", str(folder), "--terrain", str(terrain), "-q", "--until", "-5"]
    outputs = ["--steps-csv", str(out / "s.csv"), "--plot", str(out), "--mcap", str(out / "r.mcap")]
    result = runner.invoke(app, [*early, "--save-state", str(out / "s.json"), *outputs])
    assert result.exit_code == 2
    assert result.stderr == (
        "error: --mcap: expected a replay of at least one frame to export, got none "
        "(--until -5 comes before the first frame)\n"
    )
    assert list(out.iterdir()) == []
    invoke(*early, "--save-state", out / "s.json")  # without --mcap: the start map, saved
    assert sorted(path.name for path in out.iterdir()) == ["s.json"]


def test_the_camera_files_calibration_bounds_widen_the_windows(
    tmp_path: Path, sample_replay: list[str]
) -> None:
    """replay --camera reads the file's [calibration_bounds]: windows for every camera within them."""
    exact = EXAMPLES / "virtual_camera_60deg.toml"
    loose = tmp_path / "loose.toml"
    loose.write_text(exact.read_text() + "\n[calibration_bounds]\ncx = 4.0\npan_deg = 0.5\ntilt_deg = 0.5\n")
    widths = []
    for index, camera in enumerate((exact, loose)):
        metrics = tmp_path / f"m{index}.json"
        invoke(*sample_replay, "--until", "10", "--camera", camera, "--metrics-json", metrics)
        widths.append(json.loads(metrics.read_text())["median_window_width_frac"])
    assert widths[1] > widths[0]


def test_a_resume_with_other_inputs_is_refused_naming_the_option(
    walk: tuple[Path, Path], tmp_path: Path
) -> None:
    # --sigmas was refused, but --classes and --terrain were taken: a mix of two replays.
    folder, terrain = walk
    state = tmp_path / "half.json"
    invoke(
        "replay", folder, "--terrain", terrain, "--classes", "II", "--until", 20, "--save-state", state, "-q"
    )
    grass = tmp_path / "grass.toml"
    grass.write_text(TerrainTable({"floor": TerrainTable.default()["grass"]}).to_toml())
    cases = [
        (
            ("--terrain", terrain, "--classes", "I"),
            "--classes: expected landmark_class 'II', as the state in ",
        ),
        (("--terrain", grass, "--classes", "II"), "--terrain: expected the terrain table the state in "),
    ]
    for options, said in cases:
        result = runner.invoke(app, [str(a) for a in ("replay", folder, *options, "--resume", state, "-q")])
        assert result.exit_code == 2, result.output
        assert said in result.stderr
        assert f"{state} (--resume)" in result.stderr
        assert "Traceback" not in result.output
    invoke("replay", folder, "--terrain", terrain, "--classes", "II", "--resume", state, "-q")


def test_log_times_in_replay_messages_keep_their_digits(tmp_path: Path) -> None:
    # A log on Unix time (a ROS bag's stamps): the --until warning read "1.7e+09 s is after the
    # last frame of ... (1.7e+09 s)", and the resume refusal "saved at 1.7e+09 s".
    log = synthetic_log(np.random.default_rng(6), duration=10.0)
    shift = 1_700_000_000.0
    assert log.groundtruth is not None
    unix = dataclasses.replace(
        log,
        observations=tuple(dataclasses.replace(o, time=o.time + shift) for o in log.observations),
        commands=tuple(dataclasses.replace(c, time=c.time + shift) for c in log.commands or ()),
        groundtruth=dataclasses.replace(log.groundtruth, time=log.groundtruth.time + shift),
    )
    folder = write_log(unix, tmp_path / "log")
    terrain = floor_terrain(tmp_path / "terrain.toml")
    last = max(o.time for o in unix.observations)
    state = tmp_path / "end.json"
    args = ("replay", folder, "--terrain", terrain, "--quiet")
    after = invoke(*args, "--until", "1700000300", "--save-state", state)
    assert f"--until: 1700000300 s is after the last frame of {folder} ({last!r} s)" in after.stderr
    assert "e+09" not in after.stderr
    result = runner.invoke(app, [str(a) for a in (*args, "--resume", state)])
    assert result.exit_code == 2, result.output
    assert f"saved at {last!r} s: nothing is left to replay" in result.stderr
    assert "e+09" not in result.stderr
    # Stopping at the last frame itself is no mistake: it was warned of as "after" it.
    assert "--until:" not in invoke(*args, "--until", repr(last)).stderr


def test_a_state_is_not_saved_from_a_replay_growing_from_anchors(
    walk: tuple[Path, Path], tmp_path: Path
) -> None:
    # Its anchors are not in the state: resumed, the maps differed by up to 29% in area.
    folder, terrain = walk
    state = tmp_path / "s.json"
    args = ["replay", str(folder), "--terrain", str(terrain), "--anchor-growth", "--until", "20"]
    result = runner.invoke(app, [*args, "--save-state", str(state), "-q"])
    assert result.exit_code == 2, result.output
    assert "--save-state: expected a replay without --anchor-growth" in result.stderr
    assert not state.exists()


def test_an_until_after_the_last_frame_is_said(walk: tuple[Path, Path]) -> None:
    # A log kept in milliseconds: --until 30000 meant 30 s, and replayed all 40 s without a word.
    folder, terrain = walk
    after = invoke("replay", folder, "--terrain", terrain, "--quiet", "--until", "30000")
    assert "--until: 30000 s is after the last frame of" in after.stderr
    assert "every frame was replayed (--until is in seconds" in after.stderr
    for cut in (("--until", "20"), ()):
        assert "--until:" not in invoke("replay", folder, "--terrain", terrain, "--quiet", *cut).stderr


def test_observations_with_their_own_bounds_over_a_calibration_are_said(tmp_path: Path) -> None:
    # A bag's point.z became every row's bearing_error, which silently won over the calibrated
    # bounds (helper-72: containment 0.975 with rows tighter than the true noise).
    log = synthetic_log(np.random.default_rng(6), duration=20.0)
    folder = write_log(log, tmp_path / "log")
    terrain = tmp_path / "cal" / "terrain.toml"
    invoke("calibrate", folder, "--out", terrain, "--quiet")
    lines = (folder / "observations.csv").read_text().splitlines()
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    own = [*lines[:header], lines[header] + ",bearing_error"]
    own += [line if line.startswith("#") else line + ",0.05" for line in lines[header + 1 :]]
    (folder / "observations.csv").write_text("\n".join(own) + "\n")
    said = invoke("replay", folder, "--terrain", terrain, "--quiet")
    assert "of the observations replayed carry their own bearing_error or range_error" in said.stderr
    assert "take precedence over the calibrated bounds of" in said.stderr
    # Without a sensors file the row's bound is the only one given: nothing to say.
    (tmp_path / "cal" / "terrain.sensors.toml").unlink()
    assert "their own bearing_error" not in invoke("replay", folder, "--terrain", terrain, "--quiet").stderr
