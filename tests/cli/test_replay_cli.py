"""``aura-ums calibrate``, ``replay`` and ``compare`` on a synthetic log written to a folder."""

from __future__ import annotations

import json
import math
import shutil
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner, Result

from aura_ums import ManagerSettings, Metrics
from aura_ums.cli import app
from aura_ums.logs import ReverseMotion, load_noise, synthetic_log, write_log
from aura_ums.uncertainty import TerrainTable
from tests.conftest import ros_calibration_yaml
from tests.logs.log_helpers import VALID_FILES, long_odometry_log, write_files

runner = CliRunner()


def strict_json(text: str) -> Any:
    def refuse(constant: str) -> None:
        raise ValueError(f"not JSON: {constant}")

    return json.loads(text, parse_constant=refuse)


def written_by(output: str) -> list[str]:
    return [key.name for key in Metrics.table() if output in key.written_by]


@pytest.fixture(scope="module")
def log_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    log = synthetic_log(np.random.default_rng(4), duration=20.0)
    return write_log(log, tmp_path_factory.mktemp("log") / "r1")


def test_calibrate_replay_and_compare(log_folder: Path, tmp_path: Path) -> None:
    terrain = tmp_path / "cal" / "terrain.toml"
    result = runner.invoke(app, ["calibrate", str(log_folder), "--out", str(terrain)])
    assert result.exit_code == 0, result.output
    sensors = terrain.with_suffix(".sensors.toml")
    assert terrain.is_file()
    assert sensors.is_file()
    common = [str(log_folder), "--terrain", str(terrain), "--sensors", str(sensors)]

    metrics: dict[str, dict[str, object]] = {}
    runs: tuple[tuple[str, list[str]], ...] = (
        ("joint", []),
        ("one by one", ["--one-by-one"]),
        ("gate only", ["--gate-only"]),
        ("coarse", ["--max-vertices", "8"]),
    )
    for label, extra in runs:
        out = tmp_path / f"{label}.json"
        steps = tmp_path / f"{label}.csv"
        result = runner.invoke(
            app,
            [
                "replay",
                *common,
                "--classes",
                "I",
                *extra,
                "--metrics-json",
                str(out),
                "--steps-csv",
                str(steps),
            ],
        )
        assert result.exit_code == 0, result.output
        assert "containment_rate" in result.output
        metrics[label] = strict_json(out.read_text())
        assert set(metrics[label]) == set(written_by("replay"))
        assert steps.read_text().splitlines()[0].split(",") == written_by("replay --steps-csv")
    assert metrics["joint"]["joint_above_rad"] == pytest.approx(math.pi / 2)
    assert metrics["one by one"]["joint_above_rad"] is None
    assert (metrics["joint"]["robust"], metrics["gate only"]["robust"]) == (True, False)
    default = ManagerSettings().max_vertices
    assert (metrics["joint"]["max_vertices"], metrics["coarse"]["max_vertices"]) == (default, 8)
    # A coarser polygon: looser on this log.
    coarse, fine = metrics["coarse"]["median_area_m2"], metrics["joint"]["median_area_m2"]
    assert isinstance(coarse, float)
    assert isinstance(fine, float)
    assert coarse >= fine
    for figures in metrics.values():
        assert figures["containment_rate"] == 1.0
        assert isinstance(figures["median_update_us"], float)

    table = tmp_path / "compare.json"
    result = runner.invoke(app, ["compare", *common, "--particles", "50", "--metrics-json", str(table)])
    assert result.exit_code == 0, result.output
    rows = strict_json(table.read_text())
    assert set(rows) == set(written_by("compare"))
    assert [row["method"] for row in rows["methods"]] == ["aura-ums", "EKF", "PF (50)", "codac"]
    for row in rows["methods"]:
        assert set(row) == set(written_by("compare (per method)"))
    assert rows["methods"][3]["containment_rate"] == 1.0


def test_compare_without_codac_leaves_its_row_out_with_a_note(
    log_folder: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    terrain = tmp_path / "terrain.toml"
    assert runner.invoke(app, ["calibrate", str(log_folder), "--out", str(terrain)]).exit_code == 0
    monkeypatch.setitem(sys.modules, "codac", None)  # an import of codac now fails
    table = tmp_path / "compare.json"
    result = runner.invoke(
        app,
        [
            "compare",
            str(log_folder),
            "--terrain",
            str(terrain),
            "--particles",
            "20",
            "--metrics-json",
            str(table),
        ],
    )
    assert result.exit_code == 0, result.output
    assert "note: no codac row: Codac is not installed (pip install aura-ums[codac])" in result.output
    assert [row["method"] for row in strict_json(table.read_text())["methods"]] == [
        "aura-ums",
        "EKF",
        "PF (20)",
    ]


def test_replay_names_a_missing_terrain_file(log_folder: Path, tmp_path: Path) -> None:
    missing = tmp_path / "nowhere.toml"
    result = runner.invoke(app, ["replay", str(log_folder), "--terrain", str(missing)])
    assert result.exit_code != 0
    assert "nowhere.toml" in result.output


@pytest.mark.parametrize("command", ["replay", "compare"])
def test_a_vertex_cap_below_three_is_refused_by_name(command: str, log_folder: Path, tmp_path: Path) -> None:
    terrain = tmp_path / "terrain.toml"
    terrain.write_text("")
    result = runner.invoke(app, [command, str(log_folder), "--terrain", str(terrain), "--max-vertices", "2"])
    assert result.exit_code != 0
    assert "--max-vertices: expected an integer >= 3, got 2" in result.output


@pytest.mark.parametrize("command", ["replay", "compare"])
def test_the_landmark_classes_are_a_choice(command: str, log_folder: Path, tmp_path: Path) -> None:
    terrain = tmp_path / "terrain.toml"
    terrain.write_text("")
    result = runner.invoke(app, [command, str(log_folder), "--terrain", str(terrain), "--classes", "III"])
    assert result.exit_code == 2
    assert result.stderr == "error: --classes: expected one of I, II, got 'III'\n"


VIRTUAL_CAMERA = Path(__file__).resolve().parents[2] / "examples" / "virtual_camera_60deg.toml"
FLOOR_TOML = TerrainTable({"floor": TerrainTable.default()["tile"]}).to_toml()


def test_replay_with_a_camera_writes_the_window_figures_and_rows(log_folder: Path, tmp_path: Path) -> None:
    terrain = tmp_path / "terrain.toml"
    terrain.write_text(FLOOR_TOML)
    out, rows = tmp_path / "m.json", tmp_path / "out" / "windows.csv"
    base = [str(log_folder), "--terrain", str(terrain), "--classes", "II"]
    result = runner.invoke(
        app,
        [
            "replay",
            *base,
            "--camera",
            str(VIRTUAL_CAMERA),
            "--metrics-json",
            str(out),
            "--windows-csv",
            str(rows),
        ],
    )
    assert result.exit_code == 0, result.output
    assert "window_containment" in result.output
    assert f"wrote {rows}" in result.output
    metrics = strict_json(out.read_text())
    assert set(metrics) == set(written_by("replay")) | set(written_by("replay --camera"))
    assert [row["method"] for row in metrics["window_baselines"]] == ["EKF 3-sigma box", "disk model"]
    for row in metrics["window_baselines"]:
        assert set(row) == set(written_by("replay --camera (per baseline)"))
    assert metrics["window_margin_px"] == 0.0
    assert 0.0 < metrics["median_window_width_frac"] <= 1.0
    header, *lines = rows.read_text().splitlines()
    assert set(header.split(",")) == set(written_by("replay --windows-csv"))
    # One row per observation and method: ours, the focus map's, the EKF box's, the disk's.
    assert len(lines) == 4 * sum(1 for line in lines if ",aura-ums," in line)
    assert sum(1 for line in lines if ",aura-ums focus," in line) == len(lines) // 4
    # Without --camera the replay is the same and writes no window keys.
    plain_out = tmp_path / "plain.json"
    result = runner.invoke(app, ["replay", *base, "--metrics-json", str(plain_out)])
    assert result.exit_code == 0, result.output
    plain = strict_json(plain_out.read_text())
    assert set(plain) == set(written_by("replay"))
    for key in ("containment_rate", "median_area_m2", "accepted_observations", "relocalizations"):
        assert plain[key] == metrics[key]
    # A margin widens every window.
    wide_out = tmp_path / "wide.json"
    extra = ["--camera", str(VIRTUAL_CAMERA), "--window-margin", "20", "--metrics-json", str(wide_out)]
    result = runner.invoke(app, ["replay", *base, *extra])
    assert result.exit_code == 0, result.output
    wide = strict_json(wide_out.read_text())
    assert wide["window_margin_px"] == 20.0
    assert wide["median_window_width_frac"] > metrics["median_window_width_frac"]


def test_windows_csv_needs_a_camera_and_a_bad_camera_is_named(log_folder: Path, tmp_path: Path) -> None:
    terrain = tmp_path / "terrain.toml"
    terrain.write_text("")
    rows = tmp_path / "windows.csv"
    result = runner.invoke(
        app, ["replay", str(log_folder), "--terrain", str(terrain), "--windows-csv", str(rows)]
    )
    assert result.exit_code == 2
    assert "--windows-csv: expected --camera too, got no camera" in result.output
    assert not rows.exists()
    camera = tmp_path / "camera.toml"
    camera.write_text("[intrinsics]\nfx = 500.0\n")
    floor = tmp_path / "floor.toml"
    floor.write_text(FLOOR_TOML)
    result = runner.invoke(app, ["replay", str(log_folder), "--terrain", str(floor), "--camera", str(camera)])
    assert result.exit_code == 2
    assert "camera.toml" in result.output
    assert "Traceback" not in result.output
    result = runner.invoke(
        app,
        [
            "replay",
            str(log_folder),
            "--terrain",
            str(floor),
            "--camera",
            str(VIRTUAL_CAMERA),
            "--window-margin",
            "-1",
        ],
    )
    assert result.exit_code == 2
    assert "--window-margin: expected a finite number of pixels >= 0, got -1.0" in result.output
    camera_args = ["--camera", str(VIRTUAL_CAMERA), "--window-margin", "1e308"]
    result = runner.invoke(app, ["replay", str(log_folder), "--terrain", str(floor), *camera_args])
    assert result.exit_code == 2
    assert "--window-margin: expected at most 20000 pixels (an image's longest side), got 1e+308" in (
        result.stderr
    )


SAMPLE = VIRTUAL_CAMERA.parent / "logs" / "r1"
# examples/virtual_camera_60deg.toml's intrinsics, with a little barrel distortion, as ROS's
# camera_calibration_parsers writes a calibration.
VIRTUAL_OST = ros_calibration_yaml(
    "virtual",
    "554.2562584220407, 0, 319.5, 0, 554.2562584220407, 239.5, 0, 0, 1",
    "-0.05, 0.002, 0, 0, 0",
    "554.2562584220407, 0, 319.5, 0, 0, 554.2562584220407, 239.5, 0, 0, 0, 1, 0",
)


def test_replay_with_a_camera_naming_a_ros_calibration_scores_as_its_toml(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    terrain = tmp_path / "terrain.toml"
    terrain.write_text(FLOOR_TOML)
    given = VIRTUAL_CAMERA.read_text(encoding="utf-8")
    inline = tmp_path / "inline.toml"
    inline.write_text(given.replace("height = 480\n", "height = 480\ndistortion = [-0.05, 0.002, 0, 0, 0]\n"))
    (tmp_path / "robot" / "calibration").mkdir(parents=True)
    (tmp_path / "robot" / "calibration" / "ost.yaml").write_text(VIRTUAL_OST)
    mount = given[given.index("[mount]") :]
    (tmp_path / "robot" / "camera.toml").write_text(
        '[intrinsics]\ncalibration = "calibration/ost.yaml"   # beside this file\n\n' + mount
    )
    (tmp_path / "elsewhere").mkdir()
    monkeypatch.chdir(tmp_path / "elsewhere")  # the calibration is found beside the TOML
    metrics = {}
    for name, camera in (("inline", inline), ("named", Path("..") / "robot" / "camera.toml")):
        out = tmp_path / f"{name}.json"
        result = runner.invoke(
            app,
            ["replay", str(SAMPLE), "--terrain", str(terrain), "--camera", str(camera), "-q",
             "--metrics-json", str(out)],
        )  # fmt: skip
        assert result.exit_code == 0, result.output
        metrics[name] = strict_json(out.read_text())
        metrics[name].pop("median_update_us")  # a timing
    assert metrics["named"] == metrics["inline"]
    assert metrics["named"]["window_observations"] > 100


def test_replay_refuses_a_camera_whose_calibration_is_missing_or_doubled(tmp_path: Path) -> None:
    terrain = tmp_path / "terrain.toml"
    terrain.write_text(FLOOR_TOML)
    camera = tmp_path / "camera.toml"
    camera.write_text('[intrinsics]\ncalibration = "ost.yaml"\n[mount]\nheight = 0.3\n')
    out = tmp_path / "m.json"
    arguments = ["replay", str(SAMPLE), "--terrain", str(terrain), "--camera", str(camera), "-q"]
    result = runner.invoke(app, [*arguments, "--metrics-json", str(out)])
    assert result.exit_code == 2
    assert result.stderr == (
        f"error: {camera}: [intrinsics] calibration: expected an OpenCV or ROS calibration file that reads, "
        f"got: {tmp_path / 'ost.yaml'}: expected an existing calibration file, got no such file\n"
    )
    (tmp_path / "ost.yaml").write_text(VIRTUAL_OST)
    camera.write_text('[intrinsics]\ncalibration = "ost.yaml"\nfx = 554.0\n[mount]\nheight = 0.3\n')
    result = runner.invoke(app, arguments)
    assert result.exit_code == 2
    assert result.stderr == f"error: {camera}: [intrinsics] fx: expected calibration or fx, got both\n"
    assert not out.exists()


def test_replay_reads_the_sensors_file_calibrate_wrote_beside_the_terrain(
    log_folder: Path, tmp_path: Path
) -> None:
    terrain = tmp_path / "cal" / "terrain.toml"
    assert runner.invoke(app, ["calibrate", str(log_folder), "--out", str(terrain)]).exit_code == 0
    sensors = terrain.with_suffix(".sensors.toml")
    given, beside = tmp_path / "given.json", tmp_path / "beside.json"
    args = [str(log_folder), "--terrain", str(terrain), "--classes", "II"]
    result = runner.invoke(app, ["replay", *args, "--sensors", str(sensors), "--metrics-json", str(given)])
    assert result.exit_code == 0, result.output
    assert "written by calibrate" not in result.output
    result = runner.invoke(app, ["replay", *args, "--metrics-json", str(beside)])
    assert result.exit_code == 0, result.output
    assert f"sensors: {sensors}" in " ".join(result.output.split())
    drop = {"median_update_us"}
    first, second = strict_json(given.read_text()), strict_json(beside.read_text())
    assert {k: v for k, v in first.items() if k not in drop} == {
        k: v for k, v in second.items() if k not in drop
    }


def test_compare_takes_the_filters_noise_from_the_calibration_never_the_log(
    log_folder: Path, tmp_path: Path
) -> None:
    terrain = tmp_path / "terrain.toml"
    terrain.write_text(TerrainTable({"floor": TerrainTable.default()["tile"]}).to_toml())
    args = ["compare", str(log_folder), "--terrain", str(terrain), "--particles", "20"]
    result = runner.invoke(app, args)
    assert result.exit_code == 2
    assert "expected the filters' noise from a sensors file" in " ".join(result.output.split())
    calibrated = tmp_path / "cal.toml"
    assert runner.invoke(app, ["calibrate", str(log_folder), "--out", str(calibrated)]).exit_code == 0
    table = tmp_path / "compare.json"
    sensors = calibrated.with_suffix(".sensors.toml")
    result = runner.invoke(app, [*args, "--sensors", str(sensors), "--metrics-json", str(table)])
    assert result.exit_code == 0, result.output
    noise = load_noise(sensors)
    assert noise is not None
    written = strict_json(table.read_text())
    assert (written["bearing_sd_rad"], written["range_sd_fraction"]) == (
        noise.bearing_sd,
        noise.range_sd_fraction,
    )
    # nor from the log itself when named as a calibration log (here through a symlink)
    again = tmp_path / "again"
    again.symlink_to(log_folder)
    itself = runner.invoke(app, [*args, "--noise-from", str(again)])
    assert itself.exit_code == 2
    assert itself.stderr.startswith(
        f"error: --noise-from: expected calibration logs other than LOG_DIR, got {again}, which is LOG_DIR"
    )
    # nor twice from one calibration log: pooled, its errors would count twice
    other = tmp_path / "other"
    shutil.copytree(log_folder, other)
    twice = runner.invoke(app, [*args, "--noise-from", str(other), "--noise-from", f"{other}/"])
    assert twice.exit_code == 2
    assert (
        twice.stderr
        == f"error: --noise-from: expected distinct log folders, got {other} and {other}, one folder\n"
    )


def test_reversing_is_replayable_from_the_command_line(tmp_path: Path) -> None:
    files = dict(VALID_FILES, **{"odometry.csv": "time,v,omega\n0.0,0.5,0.0\n0.75,-0.25,0.1\n2.0,0.0,0.0\n"})
    folder = write_files(tmp_path / "reversing", files)
    terrain = tmp_path / "terrain.toml"
    terrain.write_text(TerrainTable.default().to_toml())
    args = ["replay", str(folder), "--terrain", str(terrain)]
    refused = runner.invoke(app, args)
    assert refused.exit_code == 2
    assert "--reverse flip" in " ".join(refused.output.split())
    flipped = runner.invoke(app, [*args, "--reverse", "flip"])
    assert flipped.exit_code == 0, flipped.output
    assert {choice.value for choice in ReverseMotion} == {"error", "flip"}
    wrong = runner.invoke(app, [*args, "--reverse", "backwards"])
    assert wrong.exit_code == 2


def test_frames_in_a_ground_truth_gap_are_not_scored(tmp_path: Path) -> None:
    # The ground truth has rows at 0 s and 2 s only: frames at 0.5 s and 1 s lie in a gap.
    folder = write_files(tmp_path / "gap", VALID_FILES)
    terrain = tmp_path / "terrain.toml"
    terrain.write_text(TerrainTable.default().to_toml())
    figures = {}
    for label, extra in (("default", []), ("no limit", ["--max-truth-gap", "inf"])):
        out = tmp_path / f"{label}.json"
        result = runner.invoke(
            app, ["replay", str(folder), "--terrain", str(terrain), *extra, "--metrics-json", str(out)]
        )
        assert result.exit_code == 0, result.output
        figures[label] = strict_json(out.read_text())
    assert (figures["default"]["steps_with_truth"], figures["default"]["containment_rate"]) == (0, None)
    assert figures["no limit"]["steps_with_truth"] == 2


@pytest.mark.parametrize("command", ["replay", "compare"])
def test_a_start_in_a_ground_truth_gap_is_refused_naming_the_file(
    command: str, log_folder: Path, tmp_path: Path
) -> None:
    # No [start] pose in meta.toml: the start comes from the truth, whose first two rows
    # (-1 s and 0.1 s) are further apart than the 0.5 s interpolated across.
    folder = tmp_path / "log"
    shutil.copytree(log_folder, folder)
    truth = folder / "groundtruth.csv"
    lines = truth.read_text().splitlines(keepends=True)
    first = next(index for index, line in enumerate(lines) if line[:1].isdigit())
    lines[first] = "-1" + lines[first][lines[first].index(",") :]
    truth.write_text("".join(lines))
    terrain = tmp_path / "cal" / "terrain.toml"
    assert runner.invoke(app, ["calibrate", str(log_folder), "--out", str(terrain)]).exit_code == 0
    result = runner.invoke(app, [command, str(folder), "--terrain", str(terrain)])
    assert result.exit_code == 2
    assert "Traceback" not in result.stderr
    assert "error" not in result.stdout
    assert (
        "groundtruth.csv: expected a ground-truth pose at the replay's start, 0 s (meta.toml gives no "
        "[start] pose), got none: the start lies between two rows more than 0.5 s apart" in result.stderr
    )


@pytest.mark.parametrize("command", ["replay", "compare"])
def test_a_terrain_file_without_the_logs_terrain_is_named(
    command: str, log_folder: Path, tmp_path: Path
) -> None:
    terrain = tmp_path / "cal" / "terrain.toml"
    assert runner.invoke(app, ["calibrate", str(log_folder), "--out", str(terrain)]).exit_code == 0
    grass = tmp_path / "grass.toml"
    grass.write_text(TerrainTable({"grass": TerrainTable.default()["grass"]}).to_toml())
    sensors = terrain.with_suffix(".sensors.toml")
    result = runner.invoke(
        app, [command, str(log_folder), "--terrain", str(grass), "--sensors", str(sensors)]
    )
    assert result.exit_code == 2
    assert result.stderr == (
        f"error: --terrain {grass}: expected the terrain 'floor' of the log in {log_folder} (its meta.toml), "
        "got 'grass'\n"
    )


def test_a_log_too_short_to_calibrate_from_is_named(log_folder: Path, tmp_path: Path) -> None:
    folder = tmp_path / "short"
    shutil.copytree(log_folder, folder)
    commands = folder / "commands.csv"
    commands.write_text("".join(commands.read_text().splitlines(keepends=True)[:3]))  # one row
    result = runner.invoke(app, ["calibrate", str(folder), "--out", str(tmp_path / "t.toml")])
    assert result.exit_code == 2
    assert f"error: LOG_DIRS ({folder}): calibrating from their contents: " in result.stderr
    assert (
        "default horizons: expected a horizon of which the logs hold at least 10 windows of motion, "
        "got 1 s (0 windows in their " in result.stderr
    )
    # the files whose times overlap too little are named with their spans
    assert f"{folder}: commands.csv 0.1 to 0.1 s, groundtruth.csv " in result.stderr
    assert not (tmp_path / "t.toml").exists()
    # a --horizon too long for the logs is named as the option (it named neither)
    longer = runner.invoke(
        app, ["calibrate", str(log_folder), "--out", str(tmp_path / "t.toml"), "--horizon", "1000"]
    )
    assert longer.exit_code == 2
    assert longer.stderr.startswith(
        "error: --horizon: expected a horizon of which the logs hold at least 10 windows of motion, "
        "got 1000 s (0 windows in their "
    )


def test_a_calibration_no_sighting_agrees_with_is_warned_about(log_folder: Path, tmp_path: Path) -> None:
    # every bearing wrong: bearing_error 3.11 rad written without a word, a map nothing shrinks
    folder = tmp_path / "wrong"
    shutil.copytree(log_folder, folder)
    observations = folder / "observations.csv"
    lines = observations.read_text().splitlines()
    header = [line for line in lines if line.startswith(("#", "time,"))]
    rows = [line.split(",") for line in lines[len(header) :]]
    rng = np.random.default_rng(3)
    for row in rows:
        row[2] = repr(float(rng.uniform(-3.1, 3.1)))
    observations.write_text("\n".join([*header, *(",".join(row) for row in rows)]) + "\n")
    result = runner.invoke(app, ["calibrate", str(folder), "--out", str(tmp_path / "t.toml"), "-q"])
    assert result.exit_code == 0, result.output
    assert (
        "warning: working bearing bound: expected the observations to agree with the ground truth within "
        in (result.stderr)
    )
    clean = runner.invoke(app, ["calibrate", str(log_folder), "--out", str(tmp_path / "c.toml"), "-q"])
    assert clean.exit_code == 0
    assert "warning" not in clean.stderr


def test_compare_shows_figures_without_truth_as_n_a_never_nan(log_folder: Path, tmp_path: Path) -> None:
    terrain = tmp_path / "cal" / "terrain.toml"
    assert runner.invoke(app, ["calibrate", str(log_folder), "--out", str(terrain)]).exit_code == 0
    folder = tmp_path / "one-truth-row"
    shutil.copytree(log_folder, folder)
    truth = folder / "groundtruth.csv"
    truth.write_text("".join(truth.read_text().splitlines(keepends=True)[:3]))  # nothing to score
    out = tmp_path / "compare.json"
    arguments = [
        "compare",
        str(folder),
        "--terrain",
        str(terrain),
        "--particles",
        "20",
        "--metrics-json",
        str(out),
    ]
    result = runner.invoke(app, arguments)
    assert result.exit_code == 0, result.output
    assert "nan" not in result.stdout
    assert "n/a" in result.stdout
    assert strict_json(out.read_text())["methods"][0]["containment_rate"] is None


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [
        ("--quantile", "nan", "--quantile: expected a finite number, got nan"),
        ("--quantile", "1.5", r"--quantile: expected a number in (0.5, 1), got 1.5"),
        ("--horizon", "0", "--horizon: expected seconds, each >= move (0.5), got [0.0]"),
        ("--horizon", "1e308", "--horizon: expected seconds, each <= 86400 (a day), got [1e+308]"),
        # A move of 1 ns cut 20 s of log into 2e10 moves: a MemoryError traceback before.
        ("--move", "1e-9", "--move: expected at most 2000000 moves over the logs' "),
        # 1e6 moves, but the check of the bounds grows a map over each second's next 20 s of them:
        # 0.01 s moves and a 600 s horizon on a 13-minute log grew for hours before.
        ("--move", "2e-5", "--move: expected at most 10,000,000 growths in the check of the bounds"),
        # was named --horizon, which the user never gave
        ("--move", "1e308", "--move: expected seconds <= 86400 (a day, the longest horizon), got 1e+308"),
        ("--move", "5", "--move: expected seconds <= the shortest horizon (1 s of the defaults 1, 2, 5"),
    ],
)
def test_calibrate_names_its_options_out_of_range(
    option: str, value: str, message: str, log_folder: Path, tmp_path: Path
) -> None:
    out = tmp_path / "t.toml"
    result = runner.invoke(app, ["calibrate", str(log_folder), "--out", str(out), option, value])
    assert result.exit_code == 2
    assert "Traceback" not in result.output
    assert f"error: {message}" in result.stderr
    assert not out.exists()


def _compare(folder: Path, tmp_path: Path, *options: str) -> Result:
    """Run ``compare`` on ``folder`` with the floor terrain table and ``options``."""
    terrain = tmp_path / "terrain.toml"
    terrain.write_text(FLOOR_TOML)
    return runner.invoke(app, ["compare", str(folder), "--terrain", str(terrain), *options])


def test_compare_names_a_log_folder_without_ground_truth(log_folder: Path, tmp_path: Path) -> None:
    bare = tmp_path / "bare"
    shutil.copytree(log_folder, bare)
    (bare / "groundtruth.csv").unlink()
    result = _compare(bare, tmp_path)
    assert result.exit_code == 2
    assert (
        f"error: LOG_DIR: expected a log folder with groundtruth.csv to compare against, got {bare}"
        in result.stderr
    )


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [
        ("--particles", "1000000000", "--particles: expected an integer in [1, 1000000], got 1000000000"),
        ("--seed", "-1", "--seed: expected an integer >= 0, got -1"),
    ],
)
def test_compare_refuses_bad_particle_filter_options_by_name(
    option: str, value: str, message: str, log_folder: Path, tmp_path: Path
) -> None:
    result = _compare(log_folder, tmp_path, option, value)
    assert result.exit_code == 2
    assert "Traceback" not in result.output
    assert result.stderr == f"error: {message}\n"


@pytest.mark.parametrize("command", ["replay", "compare", "calibrate"])
def test_a_bad_max_truth_gap_is_named_as_the_option(command: str, log_folder: Path, tmp_path: Path) -> None:
    terrain = tmp_path / "terrain.toml"
    terrain.write_text(FLOOR_TOML)
    where = ["--out", str(tmp_path / "t.toml")] if command == "calibrate" else ["--terrain", str(terrain)]
    result = runner.invoke(app, [command, str(log_folder), *where, "--max-truth-gap", "nan"])
    assert result.exit_code == 2
    # was "GroundTruth.max_gap: ..." or "max_gap: ...", the library's names
    assert (
        result.stderr == "error: --max-truth-gap: expected a positive number of seconds (or inf), got nan\n"
    )


def test_calibrate_names_the_log_folder_without_ground_truth(log_folder: Path, tmp_path: Path) -> None:
    # It said "calibrating from their contents: logs: expected logs with ground truth, got
    # 'synthetic' without": the library's argument and the log's name, not the folder.
    bare = tmp_path / "bare"
    shutil.copytree(log_folder, bare)
    (bare / "groundtruth.csv").unlink()
    result = runner.invoke(app, ["calibrate", str(log_folder), str(bare), "--out", str(tmp_path / "t.toml")])
    assert result.exit_code == 2
    assert result.stderr == (
        "error: LOG_DIRS: expected log folders with ground truth (the calibration fits the motion and "
        f"sensor bounds against it), got {bare} without a groundtruth.csv\n"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bare"]


def test_calibrate_refuses_an_empty_out_path(log_folder: Path) -> None:
    result = runner.invoke(app, ["calibrate", str(log_folder), "--out", ""])
    assert result.exit_code == 2
    assert "Traceback" not in result.output  # a ValueError of Path.with_suffix before
    assert result.stderr == "error: --out: expected a file name, got an empty path ''\n"


@pytest.mark.parametrize(
    ("argv", "name"),
    [
        (["replay", "", "--terrain", "t.toml"], "LOG_DIR"),
        (["compare", "", "--terrain", "t.toml"], "LOG_DIR"),
        (["calibrate", "", "--out", "t.toml"], "LOG_DIRS"),
    ],
    ids=["replay", "compare", "calibrate"],
)
def test_an_empty_log_argument_is_named(argv: list[str], name: str) -> None:
    # '' was Path("."), the current folder: "meta.toml: expected an existing log metadata ..."
    result = runner.invoke(app, argv)
    assert result.exit_code == 2
    assert result.stderr == f"error: {name}: expected a log folder, got an empty path ''\n"


_NAMED = "OUT_DIR: expected a path ending in the new log folder's name, got"
_TOPICS = ["--odom", "/odom", "--observations", "/obs"]
_EMPTY = "got an empty path ''"
_TERRAIN = "--terrain: expected a terrain table TOML file, got"


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["import", "mrclam", "", "o", "--robot", "1"], f"DATASET_DIR: expected a dataset folder, {_EMPTY}"),
        (["import", "mrclam", "data", "", "--robot", "1"], f"{_NAMED} an empty path ''"),
        (["import", "mrclam", "data", ".", "--robot", "1"], f"{_NAMED} '.'"),
        (["import", "mrclam", "data", "logs/..", "--robot", "1"], f"{_NAMED} 'logs/..'"),
        (["import", "rosbag", "", "out", *_TOPICS], "BAG: expected a ROS bag, got an empty path ''"),
        (["import", "rosbag", "bag", ".", *_TOPICS], f"{_NAMED} '.'"),
        (["replay", "log", "--terrain", "t.toml", "--plot", ""], f"--plot: expected a folder, {_EMPTY}"),
        (["figures", "--out", ""], "--out: expected a folder, got an empty path ''"),
        (["demo", "--out", ""], "--out: expected a folder, got an empty path ''"),
        (["replay", "log", "--terrain", ""], f"--terrain: expected a terrain table TOML file, {_EMPTY}"),
        (["replay", "log", "--terrain", "."], f"{_TERRAIN} '.', which names a folder"),
        (["compare", "log", "--terrain", "/"], f"{_TERRAIN} '/', which names a folder"),
        (["replay", "log", "--terrain", "cal/"], f"{_TERRAIN} 'cal/', which names a folder"),
    ],
    ids=["import-dataset", "import-out-empty", "import-out-dot", "import-out-dotdot", "rosbag-bag",
         "rosbag-out-dot", "replay-plot", "figures-out", "demo-out", "replay-terrain-empty",
         "replay-terrain-dot", "compare-terrain-root", "replay-terrain-folder"],
)  # fmt: skip
def test_an_empty_or_nameless_path_is_refused_naming_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, argv: list[str], message: str
) -> None:
    # '' was the current folder: `--plot ''` wrote its figure there, and `import ... .` in an
    # empty folder raised ValueError from pathlib (no name to put the scratch folder beside),
    # as did `--terrain .` (no name to put its sensors file's beside).
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, argv)
    assert result.exit_code == 2
    assert result.stderr == f"error: {message}\n"
    assert list(tmp_path.iterdir()) == []


_SCENARIO = str(Path(__file__).resolve().parents[2] / "scenarios" / "paper_sidewalk.toml")
_REPLAY = ["replay", "log", "--terrain", "t.toml"]


@pytest.mark.parametrize(
    ("argv", "option", "example"),
    [
        (["simulate", _SCENARIO, "--runs", "1", "--metrics-json"], "--metrics-json", "metrics.json"),
        (["simulate", _SCENARIO, "--runs", "1", "--mcap"], "--mcap", "run.mcap"),
        (["calibrate", "log", "--out"], "--out", "terrain.toml"),
        (["calibrate", "log", "--out", "t.toml", "--sensors-out"], "--sensors-out", "terrain.sensors.toml"),
        ([*_REPLAY, "--metrics-json"], "--metrics-json", "metrics.json"),
        ([*_REPLAY, "--steps-csv"], "--steps-csv", "steps.csv"),
        ([*_REPLAY, "--mcap"], "--mcap", "run.mcap"),
        ([*_REPLAY, "--save-state"], "--save-state", "state.json"),
        ([*_REPLAY, "--windows-csv"], "--windows-csv", "windows.csv"),
        (["compare", "log", "--terrain", "t.toml", "--metrics-json"], "--metrics-json", "metrics.json"),
    ],
    ids=["simulate-json", "simulate-mcap", "calibrate-out", "calibrate-sensors-out", "replay-json",
         "replay-steps", "replay-mcap", "replay-state", "replay-windows", "compare-json"],
)  # fmt: skip
def test_a_file_output_given_as_a_folder_is_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, argv: list[str], option: str, example: str
) -> None:
    # `--metrics-json out/` lost its slash as a Path: the metrics went to a file named `out`.
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, [*argv, "out/"])
    assert result.exit_code == 2
    assert result.stderr == (
        f"error: {option}: expected a file name, got 'out/', which names a folder "
        f"(give the file's name in it, e.g. out/{example})\n"
    )
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "how",
    [
        ["replay"],
        ["replay", "--plot", "plot"],
        ["replay", "--camera", "camera"],
        ["compare", "--particles", "50", "--noise-from", "sample"],
    ],
    ids=["streamed", "whole (--plot)", "windows (--camera)", "compare"],
)
def test_a_negative_odometry_speed_is_refused_naming_the_file_and_line(
    tmp_path: Path, how: list[str]
) -> None:
    folder = write_log(long_odometry_log(200, rate=50.0, frame_every=5), tmp_path / "log")
    lines = (folder / "odometry.csv").read_text().splitlines()
    row = next(number for number, text in enumerate(lines) if text[:1].isdigit()) + 2  # a later data row
    cells = lines[row].split(",")
    lines[row] = ",".join([cells[0], "-1", *cells[2:]])
    (folder / "odometry.csv").write_text("\n".join(lines) + "\n")
    terrain = tmp_path / "terrain.toml"
    terrain.write_text(
        TerrainTable({"tile": TerrainTable.default()["tile"]}).to_toml().replace("tile", "floor")
    )
    sample = VIRTUAL_CAMERA.parent / "logs" / "r1"
    places = {"plot": str(tmp_path / "plot"), "camera": str(VIRTUAL_CAMERA), "sample": str(sample)}
    command, *options = (places.get(word, word) for word in how)
    result = runner.invoke(app, [command, str(folder), "--terrain", str(terrain), "-q", *options])
    assert result.exit_code == 2
    # was "v: expected forward velocities >= 0 (...), got -1.0 at row 2": an argument's name
    # (compare and replay --camera said so until 29 November)
    assert result.stderr.startswith(
        f"error: {folder / 'odometry.csv'}:{row + 1}: expected forward velocities >= 0 in column 'v' "
    )
    assert result.stderr.endswith("--reverse flip to aura-ums, or reverse=ReverseMotion.FLIP), got -1.0\n")


def test_a_calibration_whose_envelope_or_odometry_replay_will_struggle_with_is_warned_about(
    tmp_path: Path,
) -> None:
    # one sighting off by 3 rad (a misread landmark) made the envelope bearing bound 3.7 rad,
    # and a log's negative speeds calibrated in silence that replay then refused
    folder = write_log(long_odometry_log(6000, frame_every=20), tmp_path / "odo")
    observations = folder / "observations.csv"
    lines = observations.read_text().splitlines()
    first = next(index for index, line in enumerate(lines) if line[:1].isdigit() or line[:1] == "-")
    row = lines[first].split(",")
    row[2] = repr(float(row[2]) + 3.0)
    lines[first] = ",".join(row)
    observations.write_text("\n".join(lines) + "\n")
    odometry = folder / "odometry.csv"
    lines = odometry.read_text().splitlines()
    at = next(index for index, line in enumerate(lines) if line[:1].isdigit()) + 5
    row = lines[at].split(",")
    row[1] = "-0.002"
    lines[at] = ",".join(row)
    odometry.write_text("\n".join(lines) + "\n")
    result = runner.invoke(app, ["calibrate", str(folder), "--out", str(tmp_path / "t.toml"), "-q"])
    assert result.exit_code == 0, result.output
    assert "warning: envelope bearing bound: expected less than pi rad, got +-" in result.stderr
    assert f"warning: {folder}: 1 odometry rows with a negative forward speed (down to -0.002 m/s)" in (
        result.stderr
    )
    replayed = runner.invoke(app, ["replay", str(folder), "--terrain", str(tmp_path / "t.toml"), "-q"])
    assert replayed.exit_code == 2
    assert "pass --reverse flip" in replayed.stderr


def test_calibrate_refuses_one_log_folder_given_twice(log_folder: Path, tmp_path: Path) -> None:
    link = tmp_path / "again"
    link.symlink_to(log_folder)
    result = runner.invoke(app, ["calibrate", str(log_folder), str(link), "--out", str(tmp_path / "t.toml")])
    assert result.exit_code == 2
    assert result.stderr == (
        f"error: LOG_DIRS: expected distinct log folders, got {log_folder} and {link}, one folder\n"
    )
    assert not (tmp_path / "t.toml").exists()


def test_replay_refuses_the_growth_its_terrain_statistics_were_not_fitted_for(
    log_folder: Path, tmp_path: Path
) -> None:
    # From an anchor, statistics fitted move by move kept the truth in under 1% of the frames.
    for name, extra in (("move", []), ("anchor", ["--anchor"])):
        fitted = runner.invoke(
            app, ["calibrate", str(log_folder), "--out", str(tmp_path / f"{name}.toml"), *extra]
        )
        assert fitted.exit_code == 0, fitted.output
    replay = ["replay", str(log_folder), "-q", "--terrain"]
    wrong = runner.invoke(app, [*replay, str(tmp_path / "move.toml"), "--anchor-growth"])
    assert wrong.exit_code == 2
    assert (
        f"error: --anchor-growth: expected the growth the terrain statistics were fitted for, got "
        f"{tmp_path / 'move.sensors.toml'} saying they were fitted move by move" in wrong.stderr
    )
    missing = runner.invoke(app, [*replay, str(tmp_path / "anchor.toml")])
    assert missing.exit_code == 2
    assert "saying they were fitted from an anchor (calibrate --anchor): replay with it" in missing.stderr
    assert runner.invoke(app, [*replay, str(tmp_path / "anchor.toml"), "--anchor-growth"]).exit_code == 0
    # No sensors file to say: replayed, with a warning.
    table = tmp_path / "table" / "terrain.toml"
    table.parent.mkdir()
    table.write_text((tmp_path / "anchor.toml").read_text())
    unsaid = runner.invoke(app, [*replay, str(table), "--anchor-growth"])
    assert unsaid.exit_code == 0, unsaid.output
    assert "warning: --anchor-growth: the terrain statistics must be fitted for growth from an anchor" in (
        " ".join(unsaid.stderr.split())
    )
