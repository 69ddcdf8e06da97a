"""Issue 19, "every input checked": one case for each class of bad input that slipped through.

Each case failed on the main branch before (a silent wrong result, a hang, a memory
blow-up, a traceback or an error naming an internal place) and now gives a clean
:class:`AuraUmsError` that names the file (and line or key) and states the range or the
estimate. The CLI turns these errors into exit 2 (tests/cli); here the readers are called.
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from aura_ums.camera import CameraMount, load_camera, load_opencv_calibration
from aura_ums.errors import FileFormatError, InputError
from aura_ums.logs import (
    _odometry,
    calibrate_logs,
    load_log,
    load_sensors,
    read_mrclam,
    read_rosbag,
    synthetic_log,
)
from aura_ums.logs._io import Units, groundtruth_blocks, observation_blocks
from aura_ums.logs._odometry import report_times
from aura_ums.perception._york_urban import load_york_urban
from aura_ums.sim import Scenario, check_render_consistency
from aura_ums.uncertainty import TerrainStats, TerrainTable, VerticalLineLandmark
from aura_ums.world import MeadowMap, make_grid_world
from tests.logs.test_mrclam import HEADER, TINY, tiny_dataset

REPOSITORY = Path(__file__).resolve().parents[1]
SAMPLE_LANDMARKS = REPOSITORY / "examples" / "logs" / "r1" / "landmarks.csv"
LOG = {
    "meta.toml": 'name = "tiny"\nterrain = "tile"\n[start]\nx = 0.0\ny = 0.0\nheading = 0.0\nradius = 0.5\n',
    "landmarks.csv": "id,x,y,position_uncertainty\nA,3.0,0.0,0.1\nB,0.0,4.0,0.1\n",
    "observations.csv": "time,landmark_id,bearing,range\n0.5,A,0.1,3.0\n1.0,B,1.5,4.0\n",
    "odometry.csv": "time,v,omega\n0.0,0.5,0.0\n1.0,0.5,0.1\n2.0,0.0,0.0\n",
}


def log_folder(tmp_path: Path, **changes: str | bytes) -> Path:
    folder = tmp_path / "log"
    folder.mkdir()
    for name, text in LOG.items():
        data = changes.get(name.replace(".", "_"), text)
        (folder / name).write_bytes(data if isinstance(data, bytes) else data.encode())
    return folder


def test_the_valid_log_loads(tmp_path: Path) -> None:
    assert len(load_log(log_folder(tmp_path)).landmarks) == 2


# --- absurd magnitudes: silent wrong results before, range errors now ------------------------


def test_terrain_drift_1e20_is_refused(tmp_path: Path) -> None:
    text = TerrainTable.default().to_toml()
    drift = f"drift = {TerrainTable.default()['tile'].drift!r}"
    path = tmp_path / "terrain.toml"
    path.write_text(text.replace(drift, "drift = 1e20", 1))
    with pytest.raises(
        FileFormatError, match=r"terrain\.toml: \[tile\] drift: expected a number in \[0, 10\] rad/m"
    ):
        TerrainTable.from_toml(path)
    with pytest.raises(InputError, match=r"drift: expected a number in \[0, 10\] rad/m, got 1e\+20"):
        TerrainStats(0.1, 0.0, 0.0, 1e20, 0.0, 0.0, 0.0, 0.0)


def test_start_radius_1e15_is_refused(tmp_path: Path) -> None:
    folder = log_folder(tmp_path, meta_toml=LOG["meta.toml"].replace("radius = 0.5", "radius = 1e15"))
    with pytest.raises(
        FileFormatError, match=r"meta\.toml: \[start\] radius: expected a number in \[0, 10000\] m"
    ):
        load_log(folder)


def test_start_radius_in_feet_states_the_value_in_metres(tmp_path: Path) -> None:
    meta = LOG["meta.toml"].replace("radius = 0.5", "radius = 1e5") + '[units]\nlength = "ft"\n'
    with pytest.raises(FileFormatError, match=r"radius: .* got 100000\.0 \(30480 m\)"):
        load_log(log_folder(tmp_path, meta_toml=meta))


def test_landmark_position_uncertainty_1e300_is_refused(tmp_path: Path) -> None:
    folder = log_folder(tmp_path, landmarks_csv="id,x,y,position_uncertainty\nA,3.0,0.0,1e300\nB,0,4,0\n")
    with pytest.raises(
        FileFormatError,
        match=r"landmarks\.csv:2: expected a number in \[0, 1000\] m in column 'position_uncertainty'",
    ):
        load_log(folder)
    with pytest.raises(InputError, match=r"pole\.position_uncertainty: expected a number in \[0, 1000\] m"):
        VerticalLineLandmark("pole", 0.0, 0.0, 0.0, 1.0, position_uncertainty=1e300)


def test_landmark_x_1e300_names_the_landmark_column_not_an_arena(tmp_path: Path) -> None:
    folder = log_folder(tmp_path, landmarks_csv="id,x,y\nA,1e300,0.0\nB,0.0,4.0\n")
    with pytest.raises(
        FileFormatError, match=r"landmarks\.csv:2: expected a number in \[-1e\+06, 1e\+06\] m in column 'x'"
    ):
        load_log(folder)


def test_geojson_position_uncertainty_1e300_is_refused(tmp_path: Path) -> None:
    document = make_grid_world(2, 2).to_geojson_dict()
    features = document["features"]
    assert isinstance(features, list)
    landmark = next(item for item in features if "class" in item["properties"])
    landmark["properties"]["position_uncertainty"] = 1e300
    path = tmp_path / "world.geojson"
    import json

    path.write_text(json.dumps(document))
    with pytest.raises(
        FileFormatError, match=r"world\.geojson: .*position_uncertainty: expected a number in \[0, 1000\] m"
    ):
        MeadowMap.from_geojson(path, terrain_table=TerrainTable.default())


@pytest.mark.parametrize(
    ("name", "value", "bounds"),
    [
        ("tolerance", 1e308, r"\[0, 3\.14159\] rad"),
        ("tolerance", -0.1, r"\[0, 3\.14159\] rad"),
        ("min_length", 1e300, r"\[-1e\+09, 1e\+09\]"),
    ],
)
def test_geojson_strategy_parameters_out_of_range_are_refused(
    tmp_path: Path, name: str, value: float, bounds: str
) -> None:
    # tolerance 1e308 was accepted: the detector took every line of every frame
    document = make_grid_world(2, 2).to_geojson_dict()
    features = document["features"]
    assert isinstance(features, list)
    landmark = next(item for item in features if "class" in item["properties"])
    landmark["properties"]["parameters"] = {name: value}
    path = tmp_path / "world.geojson"
    path.write_text(json.dumps(document))
    with pytest.raises(
        FileFormatError,
        match=rf"world\.geojson: .*properties\.parameters\.{name}: expected a number in {bounds}",
    ):
        MeadowMap.from_geojson(path, terrain_table=TerrainTable.default())


# --- tracebacks and hangs: v = 1e300 and a clock jump -----------------------------------------


def test_odometry_speed_1e300_names_file_and_line(tmp_path: Path) -> None:
    folder = log_folder(tmp_path, odometry_csv="time,v,omega\n0.0,0.5,0.0\n1.0,1e300,0.1\n2.0,0,0\n")
    with pytest.raises(
        FileFormatError, match=r"odometry\.csv:3: expected a number in \[-100, 100\] m/s in column 'v'"
    ):
        load_log(folder)


def test_a_clock_jump_is_refused_with_its_file_line_and_step_estimate(tmp_path: Path) -> None:
    odometry = "time,v,omega\n0.0,0.5,0.0\n1.0,0.5,0.1\n2402000.0,0.0,0.0\n"
    with pytest.raises(
        FileFormatError,
        match=r"odometry\.csv:4: expected at most 86400 s after the previous row \(line 3\), "
        r"got a clock jump of 2\.402e\+06 s \(27\.8 days; replayed, about 9607996 steps of 0\.25 s\)",
    ):
        load_log(log_folder(tmp_path, odometry_csv=odometry))


def test_a_clock_jump_in_recorded_commands_is_refused_with_its_file_and_line(tmp_path: Path) -> None:
    folder = log_folder(tmp_path)
    (folder / "odometry.csv").unlink()
    (folder / "commands.csv").write_text("time,turn,run\n0.5,0.0,0.2\n1.0,0.1,0.2\n2402000.0,0.0,0.2\n")
    with pytest.raises(
        FileFormatError,
        match=r"commands\.csv:4: expected at most 86400 s after the previous row \(line 3\), "
        r"got a clock jump of 2\.402e\+06 s \(27\.8 days\)$",
    ):
        load_log(folder)


JUMPED = (
    r"expected at most 86400 s after the previous row \(line 3\), "
    r"got a clock jump of 2\.402e\+06 s \(27\.8 days\)$"
)


def test_a_clock_jump_in_observations_is_refused_with_its_file_and_line(tmp_path: Path) -> None:
    observations = "time,landmark_id,bearing,range\n0.5,A,0.1,3.0\n1.0,B,1.5,4.0\n2402000.0,A,0.1,3.0\n"
    folder = log_folder(tmp_path, observations_csv=observations)
    with pytest.raises(FileFormatError, match=r"observations\.csv:4: " + JUMPED):
        load_log(folder)
    # Streamed block by block, a jump between two blocks gives the same message.
    with pytest.raises(FileFormatError, match=r"observations\.csv:4: " + JUMPED):
        list(observation_blocks(folder / "observations.csv", Units(), {"A", "B"}, block_bytes=48))


def test_a_clock_jump_in_ground_truth_is_refused_with_its_file_and_line(tmp_path: Path) -> None:
    folder = log_folder(tmp_path)
    (folder / "groundtruth.csv").write_text("time,x,y,heading\n0.0,0,0,0\n1.0,0,0,0\n2402000.0,0,0,0\n")
    with pytest.raises(FileFormatError, match=r"groundtruth\.csv:4: " + JUMPED):
        load_log(folder)
    with pytest.raises(FileFormatError, match=r"groundtruth\.csv:4: " + JUMPED):
        list(groundtruth_blocks(folder / "groundtruth.csv", Units(), block_bytes=40))


@pytest.mark.parametrize(
    ("name", "rows", "line"),
    [
        # Measurements are sorted on reading: the jump is found in time order (line 8 is last).
        ("Robot1_Measurement.dat", "10.0 \t 63 \t 2.0 \t 0.5\n11.0 \t 81 \t 4.0 \t -0.1\n", None),
        ("Robot1_Groundtruth.dat", "8.0 \t 0.0 \t 0.0 \t 3.1\n12.0 \t 1.0 \t 0.0 \t -3.1\n", 7),
    ],
    ids=["measurement", "groundtruth"],
)
def test_a_clock_jump_in_mrclam_files_is_refused_with_its_file_and_line(
    tmp_path: Path, name: str, rows: str, line: int | None
) -> None:
    later = "2400011.0 \t 63 \t 2.5 \t 0.2\n" if line is None else "2400012.0 \t 1.0 \t 1.0 \t 0.0\n"
    text = HEADER + (later + rows if line is None else rows + later)
    folder = tiny_dataset(tmp_path / "MRCLAM_Dataset9", **{name: text})
    where = 5 if line is None else line
    previous = 7 if line is None else 6
    with pytest.raises(
        FileFormatError,
        match=rf"{name}:{where}: expected at most 86400 s after the previous row \(line {previous}\), "
        r"got a clock jump of 2\.4e\+06 s \(27\.8 days\)$",
    ):
        read_mrclam(folder, 1)


@pytest.mark.parametrize("text", ["", HEADER], ids=["zero-bytes", "header-only"])
def test_an_empty_mrclam_measurement_file_is_a_log_without_observations_and_says_so(
    tmp_path: Path, text: str
) -> None:
    empty = read_mrclam(tiny_dataset(tmp_path / "MRCLAM_Dataset9", **{"Robot1_Measurement.dat": text}), 1)
    assert empty.observations == ()
    assert empty.odometry is not None  # replayable on odometry alone
    assert "; no measurement rows in Robot1_Measurement.dat: a log without observations;" in (
        empty.meta.source
    )
    # As an observations.csv with its header alone (a CSV without its header is refused).
    assert load_log(log_folder(tmp_path, observations_csv="time,landmark_id,bearing\n")).observations == ()


def test_a_bad_noise_table_is_refused_by_the_sensor_reader_that_ignores_it(tmp_path: Path) -> None:
    # replay reads the sensors file for its bounds only, yet a NaN anywhere in it is refused.
    log = synthetic_log(np.random.default_rng(1), duration=60.0)
    text = calibrate_logs([log]).sensors_toml()
    path = tmp_path / "terrain.sensors.toml"
    path.write_text(re.sub(r"bearing_sd = .*", "bearing_sd = nan", text))
    with pytest.raises(
        FileFormatError, match=r"sensors\.toml: \[noise\] bearing_sd: expected a finite number, got nan"
    ):
        load_sensors(path)


def test_bytes_that_are_no_bag_are_refused_naming_the_file(tmp_path: Path) -> None:
    pytest.importorskip("rosbags")
    junk = tmp_path / "junk.bag"
    # a UnicodeDecodeError traceback before
    junk.write_bytes(bytes((i * 7919 + 13) % 256 for i in range(4096)))
    with pytest.raises(
        FileFormatError, match=r"junk\.bag: expected a readable ROS bag, got UnicodeDecodeError"
    ):
        read_rosbag(junk, odom_topic="/odom", observations_topic="/obs", landmarks=SAMPLE_LANDMARKS)


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        # Each was imported "successfully", with no observation or with misread landmarks.
        ({"Barcodes.dat": HEADER}, r"Barcodes\.dat: expected at least one data row, got none"),
        ({"Landmark_Groundtruth.dat": HEADER}, r"Landmark_Groundtruth\.dat: expected at least one data row"),
        (
            {"Barcodes.dat": TINY["Barcodes.dat"] + "8 \t 63\n"},
            r"Barcodes\.dat:9: expected each barcode once, got 63",
        ),
        (
            {"Landmark_Groundtruth.dat": TINY["Landmark_Groundtruth.dat"] + "6 \t 1 \t 1 \t 0 \t 0\n"},
            r"Landmark_Groundtruth\.dat:7: expected each subject once, got 6 again",
        ),
    ],
)
def test_mrclam_files_without_rows_or_with_repeats_are_refused(
    changes: dict[str, str], message: str, tmp_path: Path
) -> None:
    with pytest.raises(FileFormatError, match=message):
        read_mrclam(tiny_dataset(tmp_path / "MRCLAM_Dataset9", **changes), 1)


def test_recorded_commands_without_rows_are_refused(tmp_path: Path) -> None:
    folder = log_folder(tmp_path)
    (folder / "odometry.csv").unlink()
    (folder / "commands.csv").write_text("time,turn,run\n")  # replayed from a start time of nan before
    with pytest.raises(FileFormatError, match=r"commands\.csv: expected at least one data row, got none"):
        load_log(folder)


def test_an_mrclam_clock_jump_is_refused_with_its_file_and_line(tmp_path: Path) -> None:
    odometry = HEADER + "9.0 0.1 0.0\n9.5 0.2 0.1\n2402009.5 0.0 0.0\n"
    with pytest.raises(
        FileFormatError, match=r"Robot1_Odometry\.dat:7: expected at most 86400 s .*27\.8 days"
    ):
        read_mrclam(tiny_dataset(tmp_path / "d", **{"Robot1_Odometry.dat": odometry}), 1)


def test_too_many_reports_are_refused_before_allocating_with_the_estimate() -> None:
    with pytest.raises(
        InputError, match=r"expected at most 2000000 reports \(about 500 MB\), got 9608000 \(about 2,402 MB"
    ):
        report_times(np.empty(0), 0.0, 2_402_000.0, 0.25)


def test_the_report_limit_counts_both_reports_of_a_piece_that_turns_while_it_runs(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(_odometry, "MAX_REPORTS", 3)
    # Two pieces of an arc pass the pieces' bound (2 <= 3) but are four reports.
    with pytest.raises(InputError, match=r"expected at most 3 reports .*, got 4 \(about 0 MB"):
        _odometry.odometry_to_commands([0.0, 2.0], [0.5, 0.0], [0.1, 0.0], max_interval=1.0)
    straight = _odometry.odometry_to_commands([0.0, 2.0], [0.5, 0.0], [0.0, 0.0], max_interval=1.0)
    assert [report.command.run for report in straight] == [0.5, 0.5]


def test_mrclam_values_out_of_range_name_the_column(tmp_path: Path) -> None:
    landmarks = TINY["Landmark_Groundtruth.dat"] + "  8 \t 1e300 \t 2.0 \t 0.003 \t 0.0001\n"
    with pytest.raises(
        FileFormatError, match=r"Landmark_Groundtruth\.dat:7: expected x a number in \[-1e\+06, 1e\+06\] m"
    ):
        read_mrclam(tiny_dataset(tmp_path / "a", **{"Landmark_Groundtruth.dat": landmarks}), 1)
    odometry = HEADER + "9.0 1e300 0.0\n12.0 0.0 0.0\n"
    with pytest.raises(
        FileFormatError, match=r"Robot1_Odometry\.dat:5: expected v a number in \[-100, 100\] m/s"
    ):
        read_mrclam(tiny_dataset(tmp_path / "b", **{"Robot1_Odometry.dat": odometry}), 1)


# --- encodings: every reader reads UTF-8 with a BOM, and refuses other bytes cleanly ------------


def test_an_excel_csv_with_a_bom_and_crlf_is_read(tmp_path: Path) -> None:
    def excel(text: str) -> bytes:
        return b"\xef\xbb\xbf" + text.replace("\n", "\r\n").encode()

    folder = log_folder(
        tmp_path,
        odometry_csv=excel(LOG["odometry.csv"]),
        landmarks_csv=excel(LOG["landmarks.csv"]),
        observations_csv=excel(LOG["observations.csv"]),
        meta_toml=excel(LOG["meta.toml"]),
    )
    log = load_log(folder)
    assert [item.id for item in log.landmarks] == ["A", "B"]
    assert log.odometry is not None
    assert log.odometry.v.tolist() == [0.5, 0.5, 0.0]


def test_mrclam_reads_a_bom_and_refuses_other_encodings_with_the_line(tmp_path: Path) -> None:
    with_bom = {name: "\ufeff" + text for name, text in TINY.items()}
    read, plain = (
        read_mrclam(tiny_dataset(tmp_path / "bom", **with_bom), 1),
        read_mrclam(tiny_dataset(tmp_path / "plain"), 1),
    )
    assert (read.landmarks, read.observations) == (plain.landmarks, plain.observations)
    assert read.odometry is not None
    assert plain.odometry is not None
    assert read.odometry.v.tolist() == plain.odometry.v.tolist()
    folder = tiny_dataset(tmp_path / "latin1")
    (folder / "Robot1_Odometry.dat").write_bytes(HEADER.replace("format", "f\xe9rmat").encode("latin-1"))
    with pytest.raises(
        FileFormatError, match=r"Robot1_Odometry\.dat:3: byte \d+: expected UTF-8 text, got the byte 0xe9"
    ):
        read_mrclam(folder, 1)


def _york_urban(folder: Path, segments: bytes) -> Path:
    import matplotlib.image

    (folder / "images").mkdir(parents=True)
    image = np.random.default_rng(19).integers(0, 255, (12, 16), dtype=np.uint8)
    matplotlib.image.imsave(folder / "images" / "P0001.png", image, cmap="gray")
    shutil.move(folder / "images" / "P0001.png", folder / "images" / "P0001.jpg")
    (folder / "segments.csv").write_bytes(segments)
    return folder


YORK_SEGMENTS = "image,x1,y1,x2,y2,vp,vertical\nP0001,1.5,2.0,10.0,2.5,1,0\nP0001,3.0,1.0,3.5,9.0,2,1\n"


def test_york_urban_reads_a_bom_and_refuses_other_encodings(tmp_path: Path) -> None:
    [image] = load_york_urban(_york_urban(tmp_path / "bom", b"\xef\xbb\xbf" + YORK_SEGMENTS.encode()))
    assert image.segments.tolist() == [[1.5, 2.0, 10.0, 2.5], [3.0, 1.0, 3.5, 9.0]]
    assert image.vertical.tolist() == [False, True]
    folder = _york_urban(tmp_path / "latin1", YORK_SEGMENTS.replace("P0001,3", "P\xe9,3").encode("latin-1"))
    with pytest.raises(
        FileFormatError, match=r"segments\.csv:3: byte \d+: expected UTF-8 text, got the byte 0xe9"
    ):
        load_york_urban(folder)
    folder = _york_urban(tmp_path / "range", YORK_SEGMENTS.replace("10.0", "1e300").encode())
    with pytest.raises(
        FileFormatError, match=r"segments\.csv:2: expected a number in \[-100000, 100000\] px in column 'x2'"
    ):
        load_york_urban(folder)


# --- counts limited from an estimate, before allocating -----------------------------------------


def scenario_file(tmp_path: Path, old: str, new: str, camera: str | None = None) -> Path:
    text = (REPOSITORY / "scenarios" / "paper_sidewalk.toml").read_text()
    assert old in text
    camera_text = (REPOSITORY / "scenarios" / "paper_camera.toml").read_text()
    (tmp_path / "paper_camera.toml").write_text(camera if camera is not None else camera_text)
    path = tmp_path / "walk.toml"
    path.write_text(text.replace(old, new))
    return path


def test_scenario_clutter_1e8_is_refused(tmp_path: Path) -> None:
    path = scenario_file(tmp_path, "clutter = 40", "clutter = 100000000")
    with pytest.raises(
        FileFormatError, match=r"walk\.toml: \[render\] clutter: expected at most 1e\+07 strips"
    ):
        Scenario.from_toml(path)
    path = scenario_file(tmp_path, "clutter = 40", "clutter = 5000000")
    with pytest.raises(
        FileFormatError,
        match=r"walk\.toml: \[render\] clutter: expected at most 600 s and 4 GB a run, got 4 frames",
    ):
        Scenario.from_toml(path)


def test_a_pole_radius_the_maps_landmarks_do_not_allow_names_the_scenario(tmp_path: Path) -> None:
    # named the landmark alone, not the file or the setting (checked when a run starts)
    scenario = Scenario.from_toml(scenario_file(tmp_path, "pole_radius = 0.1 ", "pole_radius = 100 "))
    with pytest.raises(
        InputError,
        match=r"walk\.toml: \[render\] pole_radius: telephone_pole_12: expected position_uncertainty "
        r">= the rendered pole radius 100 m, got 0\.15",
    ):
        check_render_consistency(scenario)


def test_scenario_clutter_lines_1e6_is_refused_with_the_estimate(tmp_path: Path) -> None:
    # was estimated as strips (35 us, 140 s a run) and accepted: about 13 minutes a run
    path = scenario_file(tmp_path, "clutter = 40", "clutter = 40\nclutter_lines = 1000000")
    with pytest.raises(
        FileFormatError,
        match=r"walk\.toml: \[render\] clutter_lines: expected at most 600 s and 4 GB a run, got 4 frames "
        r"of 512 x 480 px, 40 clutter strips and 1000000 lines: about 760 s",
    ):
        Scenario.from_toml(path)


@pytest.mark.parametrize(
    ("old", "new", "named"),
    [
        # A frame's million clutter lines (190 s) made even the route's 3 frames too long; the
        # refusal named frame_rate, which no value could have fixed.
        ("clutter_lines = 5", "clutter_lines = 1000000", r"\[render\] clutter_lines"),
        # 1e-300 m/s made 4.6e18 frames; the refusal named frame_rate alone.
        ("speed = 2.0", "speed = 1e-300", r"frame_rate and speed \(the frame spacing\)"),
    ],
)
def test_a_run_too_long_names_what_makes_it_so(tmp_path: Path, old: str, new: str, named: str) -> None:
    for name in ("four_terrains.geojson", "paper_camera.toml"):
        shutil.copy(REPOSITORY / "scenarios" / name, tmp_path / name)
    text = (REPOSITORY / "scenarios" / "four_terrains.toml").read_text()
    assert old in text
    (tmp_path / "four_terrains.toml").write_text(text.replace(old, new))
    with pytest.raises(
        FileFormatError,
        match=r"four_terrains\.toml: " + named + r": expected at most 600 s and 4 GB a run, got ",
    ):
        Scenario.from_toml(tmp_path / "four_terrains.toml")


@pytest.mark.parametrize(
    ("parameters", "message"),
    [
        # an unknown name is refused as the map loads, naming the feature and property
        (
            {"bogus": 1},
            r"features\[\d+\] \(id 'pole_a'\) properties\.parameters: expected names among orientation, "
            r".*, got 'bogus'",
        ),
        ({"min_length": -5}, r"pole_a\.parameters\.min_length: expected a non-negative number, got -5\.0"),
        # a Gaussian of 1e9 px asked scipy for 59.6 GiB (a MemoryError traceback)
        (
            {"smoothing": 1e9},
            r"pole_a\.parameters\.smoothing: expected a number in \[0, 100\] px, got 1000000000\.0",
        ),
    ],
)
def test_a_strategy_parameter_perception_refuses_names_the_scenarios_map(
    tmp_path: Path, parameters: dict[str, float], message: str
) -> None:
    # an unknown name is refused by the map's reader; a value out of its detector's range by
    # the scenario's check of its schemas (the ranges are perception's, above the map's layer)
    for name in ("four_terrains.toml", "paper_camera.toml"):
        shutil.copy(REPOSITORY / "scenarios" / name, tmp_path / name)
    document = json.loads((REPOSITORY / "scenarios" / "four_terrains.geojson").read_text())
    pole = next(item for item in document["features"] if item["properties"].get("id") == "pole_a")
    pole["properties"]["parameters"] = parameters
    (tmp_path / "four_terrains.geojson").write_text(json.dumps(document))
    with pytest.raises(
        FileFormatError,
        match=r"four_terrains\.toml: map: expected a meadow map file that loads, "
        r"got: (?:.*/)?four_terrains\.geojson: " + message,
    ):
        Scenario.from_toml(tmp_path / "four_terrains.toml")


@pytest.mark.parametrize(
    ("spacing", "got"),
    [
        ("1e-6", r"got 12192004 frames of 512 x 480 px"),
        # 40,640 frames: rendering alone was estimated at about 455 s and accepted; with the
        # loop's 8 ms a frame (19-25 ms a frame measured in all) it is about 780 s
        ("0.0003", r"got 40\d{3} frames of 512 x 480 px, 40 clutter strips and 0 lines: about 7\d\d s"),
    ],
)
def test_scenario_frame_spacing_is_refused_with_the_estimate(tmp_path: Path, spacing: str, got: str) -> None:
    path = scenario_file(tmp_path, "[start]\n", f"frame_spacing = {spacing}\n\n[start]\n")
    with pytest.raises(
        FileFormatError, match=r"walk\.toml: frame_spacing: expected at most 600 s and 4 GB a run, " + got
    ):
        Scenario.from_toml(path)


def test_scenario_start_radius_1e15_is_refused(tmp_path: Path) -> None:
    path = scenario_file(tmp_path, "position_radius = 0.3048", "position_radius = 1e15")
    with pytest.raises(
        FileFormatError, match=r"\[start\] position_radius: expected a number in \[0, 10000\] m"
    ):
        Scenario.from_toml(path)


def test_an_image_width_of_2e6_is_refused(tmp_path: Path) -> None:
    camera = (
        (REPOSITORY / "scenarios" / "paper_camera.toml").read_text().replace("width = 512", "width = 2000000")
    )
    path = scenario_file(tmp_path, "clutter = 40", "clutter = 40", camera=camera)
    with pytest.raises(
        FileFormatError, match=r"camera: .*\[intrinsics\] width: expected at most 20000 px, got 2000000"
    ):
        Scenario.from_toml(path)
    with pytest.raises(FileFormatError, match=r"\[intrinsics\] width: expected at most 20000 px"):
        load_camera(tmp_path / "paper_camera.toml")
    opencv = tmp_path / "calib.json"
    opencv.write_text(
        '{"image_width": 2000000, "image_height": 480, "camera_matrix": {"type_id": "opencv-matrix", '
        '"rows": 3, "cols": 3, "dt": "d", "data": [500, 0, 320, 0, 500, 240, 0, 0, 1]}, '
        '"distortion_coefficients": {"type_id": "opencv-matrix", "rows": 1, "cols": 4, "dt": "d", '
        '"data": [0, 0, 0, 0]}}'
    )
    with pytest.raises(FileFormatError, match=r"calib\.json: image_width: expected at most 20000 px"):
        load_opencv_calibration(opencv, CameraMount(1.0))


def test_a_distortion_of_1e300_is_refused_in_both_camera_formats(tmp_path: Path) -> None:
    # accepted before: every window was garbage (the replay printed n/a) with exit 0
    camera = tmp_path / "camera.toml"
    camera.write_text(
        (REPOSITORY / "examples" / "camera.toml")
        .read_text()
        .replace("# distortion = [k1, k2, p1, p2, k3]", "distortion = [1e300, 0.0, 0.0, 0.0, 0.0]")
    )
    with pytest.raises(
        FileFormatError,
        match=r"camera\.toml: \[intrinsics\] distortion\[0\]: "
        r"expected a number in \[-1000, 1000\], got 1e\+300",
    ):
        load_camera(camera)
    opencv = tmp_path / "calib.json"
    opencv.write_text(
        '{"image_width": 640, "image_height": 480, "camera_matrix": {"type_id": "opencv-matrix", '
        '"rows": 3, "cols": 3, "dt": "d", "data": [500, 0, 320, 0, 500, 240, 0, 0, 1]}, '
        '"distortion_coefficients": {"type_id": "opencv-matrix", "rows": 1, "cols": 5, "dt": "d", '
        '"data": [0.1, -0.2, 0, 0, -1e300]}}'
    )
    with pytest.raises(
        FileFormatError, match=r"calib\.json: distortion_coefficients\[4\]: expected a number in"
    ):
        load_opencv_calibration(opencv, CameraMount(1.0))


def test_a_camera_too_big_to_render_is_refused_with_the_estimate(tmp_path: Path) -> None:
    camera = (
        (REPOSITORY / "scenarios" / "paper_camera.toml")
        .read_text()
        .replace("width = 512", "width = 20000")
        .replace("height = 480", "height = 20000")
    )
    path = scenario_file(tmp_path, "clutter = 40", "clutter = 40", camera=camera)
    with pytest.raises(
        FileFormatError, match=r"walk\.toml: camera: expected at most 600 s and 4 GB a run, got .* 80 GB"
    ):
        Scenario.from_toml(path)


def test_monte_carlo_runs_are_limited_with_the_estimate() -> None:
    scenario = Scenario.from_toml(REPOSITORY / "scenarios" / "paper_sidewalk.toml")
    assert scenario.check_runs(100) == 100
    with pytest.raises(
        InputError,
        match=r"runs: expected an integer in \[1, 100000\], got 1000000000 \(about .* s and 2e\+04 GB",
    ):
        scenario.check_runs(10**9)
    with pytest.raises(InputError, match=r"runs: expected an integer in \[1, 100000\], got 0$"):
        scenario.check_runs(0)
    seconds, memory = scenario.estimate()
    assert 0.0 < seconds < 1.0
    assert math.isclose(memory, 512 * 480 * 200 + 40 * 400)


# --- found by the TOML and log fuzz passes after the first round ------------------------------


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        # the robot was simulated into the gap and stopped with "start: expected a point inside
        # a meadow for a zero-length run", naming neither the file nor the command
        (
            "{ turn_deg = 0.0, run = 6.096 },   # to 40 ft",
            "{ turn_deg = 0.0, run = 9000.0 },",
            r"walk\.toml: \[route\] commands\[2\]: expected a route inside the map's meadows, got a leg "
            r"from \(6\.096, 0\) to \(9006\.1, 0\) that leaves them",
        ),
        # 100,000 short commands are 100,001 frames: the estimate blamed the camera
        (
            "commands = [\n",
            "commands = [\n" + "{ turn_deg = 0.0, run = 0.0001 },\n" * 100_000,
            r"walk\.toml: \[route\]: expected at most 600 s and 4 GB a run, got 100004 frames",
        ),
    ],
    ids=["a-run-off-the-map", "too-many-commands"],
)
def test_a_route_is_checked_where_the_scenario_names_it(
    tmp_path: Path, old: str, new: str, message: str
) -> None:
    with pytest.raises(FileFormatError, match=message):
        Scenario.from_toml(scenario_file(tmp_path, old, new))


def test_a_waypoint_across_a_gap_between_meadows_is_refused(tmp_path: Path) -> None:
    # was simulated: the robot crossed ground no meadow covers and the run was lost
    for name in ("four_terrains.toml", "paper_camera.toml"):
        shutil.copy(REPOSITORY / "scenarios" / name, tmp_path / name)
    document = json.loads((REPOSITORY / "scenarios" / "four_terrains.geojson").read_text())
    del document["features"][1]
    (tmp_path / "four_terrains.geojson").write_text(json.dumps(document))
    with pytest.raises(
        FileFormatError,
        match=r"four_terrains\.toml: \[route\] waypoints\[\d\]: expected a route inside the map's meadows",
    ):
        Scenario.from_toml(tmp_path / "four_terrains.toml")


def test_a_maps_terrain_table_reference_is_checked_when_another_table_is_given(tmp_path: Path) -> None:
    # ignored when the caller gave a table: a broken reference loaded in silence
    document = json.loads((REPOSITORY / "scenarios" / "four_terrains.geojson").read_text())
    document["terrain_table"] = "gone.toml"
    path = tmp_path / "map.geojson"
    path.write_text(json.dumps(document))
    table = TerrainTable.default()
    with pytest.raises(FileFormatError, match=r"map\.geojson: terrain_table: expected a terrain table file"):
        MeadowMap.from_geojson(path, terrain_table=table)
    # a file that is there but no terrain table (/etc/passwd) was taken as well
    (tmp_path / "notes.toml").write_text("root:x:0:0:root:/root:/bin/bash\n")
    document["terrain_table"] = "notes.toml"
    path.write_text(json.dumps(document))
    with pytest.raises(FileFormatError, match=r"notes\.toml:1:5: expected valid TOML"):
        MeadowMap.from_geojson(path, terrain_table=table)


def test_a_camera_below_the_ground_is_refused(tmp_path: Path) -> None:
    # -5 m gave every window zero width, and containment 0, with exit 0
    text = (REPOSITORY / "scenarios" / "paper_camera.toml").read_text()
    height = re.search(r"\[mount\]\nheight = [^\n]+", text)
    assert height is not None
    path = tmp_path / "camera.toml"
    path.write_text(text.replace(height.group(0), "[mount]\nheight = -5.0"))
    with pytest.raises(
        FileFormatError, match=r"camera\.toml: \[mount\] height: expected a number in \[0, 100\] m"
    ):
        load_camera(path)
    with pytest.raises(InputError, match=r"CameraMount\.height: expected a height >= 0 m above the ground"):
        CameraMount(-5.0)
    assert CameraMount(0.0).height == 0.0


@pytest.mark.parametrize("cell", ["\uff11.5", "\u0661.5"], ids=["full-width", "arabic-indic"])
def test_digits_other_than_ascii_are_refused_in_a_log(tmp_path: Path, cell: str) -> None:
    # float() reads them as digits: a full-width 1 before "0.5" was the time 10.5
    observations = LOG["observations.csv"].replace("1.0,B", f"{cell},B")
    with pytest.raises(
        FileFormatError, match=rf"observations\.csv:3: expected a number in column 'time', got '{cell}'"
    ):
        load_log(log_folder(tmp_path, observations_csv=observations))


def test_a_broken_ground_truth_link_is_named_not_taken_for_no_ground_truth(tmp_path: Path) -> None:
    folder = log_folder(tmp_path)
    (folder / "groundtruth.csv").symlink_to(tmp_path / "gone.csv")
    with pytest.raises(
        FileFormatError, match=r"groundtruth\.csv: expected an existing CSV file, got no such file"
    ):
        load_log(folder)


@pytest.mark.parametrize("name", ["robot\\u001b[2J", "a\\u0007bell"])
def test_a_log_name_with_control_characters_is_refused(tmp_path: Path, name: str) -> None:
    # the name is printed: an escape sequence reached the terminal
    meta = f'name = "{name}"\n' + LOG["meta.toml"].split("\n", 1)[1]
    with pytest.raises(FileFormatError, match=r"meta\.toml: .*expected printable characters"):
        load_log(log_folder(tmp_path, meta_toml=meta))


def test_a_range_of_1e_300_does_not_overflow_the_calibration() -> None:
    # its relative error overflowed (numpy warnings, then FilterNoise named in the error)
    log = synthetic_log(np.random.default_rng(3), duration=60.0)
    first = log.observations[0]
    assert first.range is not None
    rest = log.observations[1:]
    tiny = calibrate_logs(
        [dataclasses.replace(log, observations=(dataclasses.replace(first, range=1e-300), *rest))]
    )
    none = calibrate_logs(
        [dataclasses.replace(log, observations=(dataclasses.replace(first, range=None), *rest))]
    )
    assert (tiny.noise, tiny.working, tiny.envelope) == (none.noise, none.working, none.envelope)


def test_a_delay_that_moves_the_start_past_the_ground_truth_is_named() -> None:
    # blamed groundtruth.csv alone: "the start lies between two rows more than 0.5 s apart"
    from aura_ums.logs import replay_log

    log = synthetic_log(np.random.default_rng(4), duration=10.0)
    late = dataclasses.replace(log, meta=dataclasses.replace(log.meta, start=None, delay_s=3600.0))
    with pytest.raises(
        InputError, match=r"or after the last row; the motion's delay_s \(3600 s, of the sensors"
    ):
        replay_log(late, TerrainTable({"floor": TerrainTable.default()["tile"]}))


def test_files_of_one_log_whose_clocks_disagree_are_refused(tmp_path: Path) -> None:
    # each file continuous, the observations 30 days after the motion: loaded, and replayed
    # as a run that never sees a landmark
    observations = LOG["observations.csv"].replace("0.5,A", "2592000.5,A").replace("1.0,B", "2592001.0,B")
    with pytest.raises(
        FileFormatError,
        match=r"log: expected the times of odometry\.csv and observations\.csv to overlap \(at most 86400 s "
        r"apart\), got 0 to 2 s and 2592000\.5 to 2592001 s",
    ):
        load_log(log_folder(tmp_path, observations_csv=observations))
