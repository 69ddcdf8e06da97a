"""Fuzz every file reader: random bytes and mutations of a valid file fail only with our errors.

Each reader gets random bytes and a valid file of its format mutated (bytes replaced,
tokens of TOML/JSON/CSV/YAML/.dat inserted, slices deleted or repeated, the tail cut).
The guarantee: the reader returns, or raises an :class:`AuraUmsError` that is a
``ValueError`` naming the file and reading "expected ..., got ..."; never anything else
(no ``KeyError``, ``TypeError``, ``RecursionError``, ``UnicodeDecodeError``...), and
never a hang: each case runs under a time limit (:data:`CASE_SECONDS`, SIGALRM).

The readers: terrain tables, cameras (TOML, also naming a calibration file; OpenCV YAML and
JSON; ROS calibration YAML), scenarios, sensor
calibrations, a log folder's ``meta.toml`` and CSV files (odometry, commands,
observations, landmarks, ground truth), saved manager and blackboard state, GeoJSON meadow
maps, the MRCLAM ``.dat`` files, York Urban's ``segments.csv``, and the files
``aura-ums calibrate`` writes (its terrain table and sensor calibration).

CI runs the loaded hypothesis profile (100 cases a reader, derandomized); more cases:
``AURA_HYPOTHESIS_PROFILE=thorough`` (1000 a reader) or ``AURA_FUZZ_EXAMPLES=N``; the
per-case limit: ``AURA_FUZZ_CASE_SECONDS``. Counts per reader:
``pytest tests/test_files_fuzz.py --hypothesis-show-statistics``.
"""

from __future__ import annotations

import collections
import json
import math
import os
import shutil
import signal
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from types import FrameType

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from aura_ums.camera import CameraMount, load_calibration_bounds, load_camera, load_opencv_calibration
from aura_ums.errors import AuraUmsError
from aura_ums.logs import calibrate_logs, load_log, load_sensors, read_mrclam, synthetic_log
from aura_ums.manager import Blackboard, PositionReport, UncertaintyMapManager
from aura_ums.perception._york_urban import load_york_urban
from aura_ums.sim import Scenario
from aura_ums.uncertainty import BearingObservation, Pose, SpatialUncertaintyMap, TerrainTable, TurnAndRun
from aura_ums.world import MeadowMap, make_grid_world
from tests.conftest import ros_calibration_yaml

REPOSITORY = Path(__file__).resolve().parents[1]
CAMERA_TOML = (REPOSITORY / "scenarios" / "paper_camera.toml").read_bytes()
SCENARIO = (
    (REPOSITORY / "scenarios" / "paper_sidewalk.toml")
    .read_bytes()
    .replace(b"paper_camera.toml", b"cam.toml")
    .replace(b"clutter = 40", b"clutter = 2")
)
TERRAIN = TerrainTable.default().to_toml().encode()
SENSORS = b"""format = "aura-ums/sensor-calibration"

[motion]
delay_s = 0.1
run_scale = 1.02
turn_scale = 0.98

[working]
bearing_error = 0.02
range_error = 0.1
range_fraction_low = 0.05
range_fraction_high = 0.1

[envelope]
bearing_error = 0.05
range_error = 0.3
range_fraction_low = 0.1
range_fraction_high = 0.2
"""
OPENCV_YAML = b"""%YAML:1.0
---
image_width: 640
image_height: 480
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 6.7490000000000009e+02, 0., 3.0755000000000001e+02, 0.,
       6.7489999999999998e+02, 2.5145000000000002e+02, 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 5
   cols: 1
   dt: d
   data: [ -1.2e-01, 4.5e-02, 1.0e-03, -2.0e-03, 0. ]
features:
   - { x:167, y:49, lbp:[ 1, 0, 0, 1 ] }
"""
OPENCV_JSON = json.dumps(
    {
        "image_width": 640,
        "image_height": 480,
        "camera_matrix": {
            "type_id": "opencv-matrix",
            "rows": 3,
            "cols": 3,
            "dt": "d",
            "data": [674.9, 0.0, 307.5, 0.0, 674.9, 251.4, 0.0, 0.0, 1.0],
        },
        "distortion_coefficients": {
            "type_id": "opencv-matrix",
            "rows": 1,
            "cols": 4,
            "dt": "d",
            "data": [0.1, 0.0, 0.0, 0.0],
        },
    },
    indent=1,
).encode()
ROS_YAML = ros_calibration_yaml(
    "narrow_stereo",
    "674.9, 0, 307.5, 0, 674.9, 251.4, 0, 0, 1",
    "-0.12, 0.045, 0.001, -0.002, 0",
    "674.9, 0, 307.5, 0, 0, 674.9, 251.4, 0, 0, 0, 1, 0",
).encode()
#: A camera TOML whose intrinsics are a ROS calibration file beside it (``ost.yaml``).
CALIBRATED_CAMERA_TOML = b'[intrinsics]\ncalibration = "ost.yaml"\n\n[mount]\nheight = 1.2\ntilt_deg = 5.0\n'
LOG_FILES: dict[str, bytes] = {
    "meta.toml": (
        b'name = "tiny"\nterrain = "tile"\n\n[units]\nangle = "deg"\n\n[sensor]\nbearing_error = 2.0\n'
        b"\n[start]\nx = 0.0\ny = 0.0\nheading = 0.0\nradius = 0.5\n"
    ),
    "landmarks.csv": (
        b"id,x,y,position_uncertainty,z_bottom,z_top,symbol\n"
        b"# two poles\nA,3.0,0.0,0.1,0,2,pole\nB,0.0,4.0,,,,\n"
    ),
    "observations.csv": (
        b"time,landmark_id,bearing,range,bearing_error,range_error\n"
        b"0.5,A,5.7,3.0,,\n0.5,B,86,,1,\n1.0,A,11,2.5,,0.1\n"
    ),
    "odometry.csv": b"time,v,omega\n0.0,0.5,0.0\n1.0,0.5,5.7\n2.0,0.0,0.0\n",
    "groundtruth.csv": b"time,x,y,heading\n0.0,0.0,0.0,0.0\n2.0,1.0,0.0,5.7\n",
}
MRCLAM_HEADER = b"# UTIAS MRCLAM Dataset (made up)\n# columns\n"
MRCLAM_FILES: dict[str, bytes] = {
    "Barcodes.dat": MRCLAM_HEADER + b"  1 \t 5\n  6 \t 63\n  7 \t 81\n",
    "Landmark_Groundtruth.dat": MRCLAM_HEADER
    + b"  6 \t 0.5 \t -4.0 \t 0.001 \t 0.002\n  7 \t 1.5 \t 2.0 \t 0.003 \t 0.0001\n",
    "Robot1_Measurement.dat": MRCLAM_HEADER
    + b"10.0 \t 63 \t 2.0 \t 0.5\n10.5 \t 99 \t 1.0 \t 0.0\n11.0 \t 81 \t 4.0 \t -0.1\n",
    "Robot1_Odometry.dat": MRCLAM_HEADER + b"9.0 \t 0.1 \t 0.0\n9.5 \t 0.2 \t 0.1\n12.0 \t 0.0 \t 0.0\n",
    "Robot1_Groundtruth.dat": MRCLAM_HEADER + b"8.0 \t 0.0 \t 0.0 \t 3.1\n12.0 \t 1.0 \t 0.0 \t -3.1\n",
}
YORK_SEGMENTS = b"image,x1,y1,x2,y2,vp,vertical\nP0001,1.5,2.0,10.0,2.5,1,0\nP0001,3.0,1.0,3.5,9.0,2,1\n"
COMMANDS_CSV = b"time,turn,run\n1.0,0.1,0.5\n2.0,0.0,0.5\n"
#: What `aura-ums calibrate` writes: a terrain table and a sensor calibration.
CALIBRATION = calibrate_logs([synthetic_log(np.random.default_rng(19), duration=60.0)])
CALIBRATED_TERRAIN = CALIBRATION.terrain_table().to_toml().encode()
CALIBRATED_SENSORS = CALIBRATION.sensors_toml().encode()
WORLD = make_grid_world(2, 2)
TABLE = TerrainTable.default()
MOUNT = CameraMount(1.0)

#: Pieces of the formats read here, inserted by the mutations.
TOKENS = (
    b"\x00", b"\xff", b"\xc3", b"\xef\xbb\xbf", b"\n", b"\r\n", b"\t", b" ", b'"', b"'", b"\\",
    b"[", b"]", b"{", b"}", b",", b"=", b":", b"#", b"-", b".", b"- ", b"!!opencv-matrix",
    b"nan", b"inf", b"-inf", b"NaN", b"Infinity", b".Nan", b"1e999", b"-1", b"0", b"1.5", b"true",
    b"null", b"[[[[[[[[[[[[", b"{{{{{{{{", b"9" * 40, b"0x" + b"f" * 80, b"1979-05-27",
    b'"\\ud800"', b"\xc3\xa9", b"[x]\n", b"[[x]]\n", b"a = 1\n", b'"a": 1, ', b"x,y\n",
    b"1e300", b"-1e300", b"1e15", b"1e-6", b"100000000", b"2000000", b" \t ", b"\t", b"4.9e-324",
)  # fmt: skip


def _splice(draw: st.DrawFn, data: bytearray) -> None:
    at = draw(st.integers(0, len(data)))
    end = draw(st.integers(at, min(len(data), at + 40)))
    operation = draw(st.sampled_from(["replace", "insert", "delete", "repeat", "cut"]))
    if operation == "replace" and data:
        data[min(at, len(data) - 1)] = draw(st.integers(0, 255))
    elif operation == "insert":
        data[at:at] = draw(st.sampled_from(TOKENS))
    elif operation == "delete":
        del data[at:end]
    elif operation == "repeat":
        data[at:at] = data[at:end] * draw(st.integers(1, 3))
    else:
        del data[at:]


@st.composite
def mutated(draw: st.DrawFn, valid: bytes) -> bytes:
    """A valid file with 1 to 8 random edits."""
    data = bytearray(valid)
    for _ in range(draw(st.integers(1, 8))):
        _splice(draw, data)
    return bytes(data)


def contents(valid: bytes) -> st.SearchStrategy[bytes]:
    """Random bytes, or the valid file mutated (more often: it reaches deeper)."""
    return st.one_of(st.binary(max_size=400), mutated(valid), mutated(valid), mutated(valid))


#: Longest a reader may take on one case, seconds: a case that takes longer is a hang.
CASE_SECONDS = float(os.environ.get("AURA_FUZZ_CASE_SECONDS", "20"))


class HangError(Exception):
    """A reader took longer than :data:`CASE_SECONDS` on one case."""


def _hang(signum: int, frame: FrameType | None) -> None:
    raise HangError(f"expected a reader to finish within {CASE_SECONDS} s, got a hang")


def outcome(read: Callable[[], object], seconds: float = CASE_SECONDS) -> AuraUmsError | None:
    """Run a reader: None if it returns, our error if it raises one (anything else propagates).

    The reader runs under an alarm of ``seconds``: a hang fails the case.
    """
    previous = signal.signal(signal.SIGALRM, _hang)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        read()
    except AuraUmsError as error:
        return error
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, previous)
    return None


#: Cases run per reader (the test's name), read or refused: written as JSON to the file
#: ``AURA_FUZZ_COUNTS`` names, when set, at the end of the module.
COUNTS: collections.Counter[tuple[str, str]] = collections.Counter()


@pytest.fixture(scope="module", autouse=True)
def _write_counts() -> Iterator[None]:
    yield
    target = os.environ.get("AURA_FUZZ_COUNTS")
    if target:
        table: dict[str, dict[str, int]] = {}
        for (reader, result), count in sorted(COUNTS.items()):
            table.setdefault(reader, {})[result] = count
        Path(target).write_text(json.dumps(table, indent=1), encoding="utf-8")


def assert_clean(error: AuraUmsError | None, name: str) -> None:
    """An error from a file is a ValueError that names the file and says what it expected and got."""
    reader = os.environ.get("PYTEST_CURRENT_TEST", "?").split("::")[-1].split(" ")[0]
    COUNTS[(reader, "read" if error is None else "refused")] += 1
    if error is None:
        return
    text = str(error)
    assert isinstance(error, ValueError), text
    assert name in text, text
    assert "expected" in text, text
    assert "got" in text, text


def test_the_valid_files_load(tmp_path: Path) -> None:
    """The files mutated below are valid: the mutations start from a file every check passes."""
    files = {
        "terrain.toml": TERRAIN,
        "cam.toml": CAMERA_TOML,
        "calib.yml": OPENCV_YAML,
        "calib.json": OPENCV_JSON,
        "ost.yaml": ROS_YAML,
        "named.toml": CALIBRATED_CAMERA_TOML,
        "walk.toml": SCENARIO,
        "sensors.toml": SENSORS,
        "world.geojson": _geojson_text(),
    }
    for name, data in files.items():
        (tmp_path / name).write_bytes(data)
    assert TerrainTable.from_toml(tmp_path / "terrain.toml") == TABLE
    assert load_camera(tmp_path / "cam.toml").intrinsics.width > 0
    assert load_opencv_calibration(tmp_path / "calib.yml", MOUNT).intrinsics.distortion is not None
    assert load_opencv_calibration(tmp_path / "calib.json", MOUNT).intrinsics.fx == 674.9
    ros = load_opencv_calibration(tmp_path / "ost.yaml", MOUNT).intrinsics
    assert ros.fx == 674.9
    assert ros.distortion == (-0.12, 0.045, 0.001, -0.002, 0.0)
    assert load_camera(tmp_path / "named.toml").intrinsics == ros
    assert len(Scenario.from_toml(tmp_path / "walk.toml").commands) == 3
    assert load_sensors(tmp_path / "sensors.toml")[0].delay_s == 0.1
    assert MeadowMap.from_geojson(tmp_path / "world.geojson", terrain_table=TABLE) == WORLD
    assert len(load_log(_log_folder(tmp_path, "", b"")).observations) == 3
    assert (
        UncertaintyMapManager.from_json(_manager_json().decode(), WORLD, TABLE).to_json().encode()
        == _manager_json()
    )
    assert Blackboard.from_json(_board_json().decode()).to_json().encode() == _board_json()
    assert len(read_mrclam(_mrclam_folder(tmp_path, "", b""), 1).observations) == 2
    [image] = load_york_urban(_york_urban_folder(tmp_path, YORK_SEGMENTS))
    assert image.segments.shape == (2, 4)
    (tmp_path / "calibrated.toml").write_bytes(CALIBRATED_TERRAIN)
    assert TerrainTable.from_toml(tmp_path / "calibrated.toml") == CALIBRATION.terrain_table()
    (tmp_path / "calibrated_sensors.toml").write_bytes(CALIBRATED_SENSORS)
    assert load_sensors(tmp_path / "calibrated_sensors.toml")[0] == CALIBRATION.motion
    folder = _log_folder(tmp_path, "odometry.csv", b"")
    (folder / "odometry.csv").unlink()
    (folder / "commands.csv").write_bytes(COMMANDS_CSV)
    assert len(load_log(folder).commands or ()) == 2


_EXAMPLES = os.environ.get("AURA_FUZZ_EXAMPLES")
FUZZ = settings(
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
    max_examples=int(_EXAMPLES) if _EXAMPLES else settings().max_examples,
)


@FUZZ
@given(data=contents(TERRAIN))
def test_terrain_toml(tmp_path: Path, data: bytes) -> None:
    path = tmp_path / "terrain.toml"
    path.write_bytes(data)
    assert_clean(outcome(lambda: TerrainTable.from_toml(path)), "terrain.toml")


@FUZZ
@given(data=contents(CAMERA_TOML))
def test_camera_toml(tmp_path: Path, data: bytes) -> None:
    path = tmp_path / "cam.toml"
    path.write_bytes(data)
    assert_clean(outcome(lambda: load_camera(path)), "cam.toml")
    assert_clean(outcome(lambda: load_calibration_bounds(path)), "cam.toml")


@FUZZ
@given(data=contents(OPENCV_YAML))
def test_opencv_yaml(tmp_path: Path, data: bytes) -> None:
    path = tmp_path / "calib.yml"
    path.write_bytes(data)
    assert_clean(outcome(lambda: load_opencv_calibration(path, MOUNT)), "calib.yml")


@FUZZ
@given(data=contents(OPENCV_JSON))
def test_opencv_json(tmp_path: Path, data: bytes) -> None:
    path = tmp_path / "calib.json"
    path.write_bytes(data)
    assert_clean(outcome(lambda: load_opencv_calibration(path, MOUNT)), "calib.json")


@FUZZ
@given(data=contents(ROS_YAML))
def test_ros_calibration_yaml(tmp_path: Path, data: bytes) -> None:
    path = tmp_path / "ost.yaml"
    path.write_bytes(data)
    assert_clean(outcome(lambda: load_opencv_calibration(path, MOUNT)), "ost.yaml")


@FUZZ
@given(toml=contents(CALIBRATED_CAMERA_TOML), calibration=contents(ROS_YAML))
def test_camera_toml_naming_a_calibration(tmp_path: Path, toml: bytes, calibration: bytes) -> None:
    # Either file may be the bad one: the error names the camera file (and the calibration's).
    (tmp_path / "ost.yaml").write_bytes(calibration)
    path = tmp_path / "named.toml"
    path.write_bytes(toml)
    assert_clean(outcome(lambda: load_camera(path)), "named.toml")


@FUZZ
@given(data=contents(SCENARIO))
def test_scenario_toml(tmp_path: Path, data: bytes) -> None:
    (tmp_path / "cam.toml").write_bytes(CAMERA_TOML)
    path = tmp_path / "walk.toml"
    path.write_bytes(data)
    assert_clean(outcome(lambda: Scenario.from_toml(path)), "walk.toml")


@FUZZ
@given(data=contents(SENSORS))
def test_sensors_toml(tmp_path: Path, data: bytes) -> None:
    path = tmp_path / "sensors.toml"
    path.write_bytes(data)
    assert_clean(outcome(lambda: load_sensors(path)), "sensors.toml")


def _log_folder(tmp_path: Path, name: str, data: bytes) -> Path:
    folder = tmp_path / "log"
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir()
    for file, valid in LOG_FILES.items():
        (folder / file).write_bytes(data if file == name else valid)
    return folder


@FUZZ
@given(data=contents(LOG_FILES["meta.toml"]))
def test_log_meta_toml(tmp_path: Path, data: bytes) -> None:
    folder = _log_folder(tmp_path, "meta.toml", data)
    assert_clean(outcome(lambda: load_log(folder)), str(folder))


@FUZZ
@given(name=st.sampled_from(sorted(set(LOG_FILES) - {"meta.toml"})), seed=st.data())
def test_log_csv(tmp_path: Path, name: str, seed: st.DataObject) -> None:
    data = seed.draw(contents(LOG_FILES[name]))
    folder = _log_folder(tmp_path, name, data)
    assert_clean(outcome(lambda: load_log(folder)), str(folder))


def _geojson_text() -> bytes:
    return json.dumps(WORLD.to_geojson_dict(), indent=1).encode()


@FUZZ
@given(data=contents(_geojson_text()))
def test_geojson(tmp_path: Path, data: bytes) -> None:
    path = tmp_path / "world.geojson"
    path.write_bytes(data)
    assert_clean(outcome(lambda: MeadowMap.from_geojson(path, terrain_table=TABLE)), "world.geojson")


def _manager_json() -> bytes:
    start = SpatialUncertaintyMap.from_pose(Pose(1.0, 1.0, 0.3), 0.2, 0.05)
    manager = UncertaintyMapManager(start, WORLD, TABLE)
    board = Blackboard()
    board.post_report(PositionReport(1.0, TurnAndRun(0.1, 0.5)))
    manager.update(board, now=1.0)
    return manager.to_json().encode()


def _board_json() -> bytes:
    board = Blackboard()
    board.post_report(PositionReport(1.0, TurnAndRun(0.1, 0.5)))
    board.identified.post(BearingObservation("pole", 1.0, math.pi / 3, 0.01, (0.1, 0.0)))
    board.push_command(TurnAndRun(0.2, 1.0))
    return board.to_json().encode()


@FUZZ
@given(data=contents(_manager_json()))
def test_manager_state_json(data: bytes) -> None:
    text = data.decode("utf-8", errors="replace")
    read = lambda: UncertaintyMapManager.from_json(text, WORLD, TABLE, source="state.json")  # noqa: E731
    assert_clean(outcome(read), "state.json")


@FUZZ
@given(data=contents(_board_json()))
def test_blackboard_state_json(data: bytes) -> None:
    text = data.decode("utf-8", errors="replace")
    assert_clean(outcome(lambda: Blackboard.from_json(text, source="board.json")), "board.json")


@FUZZ
@given(data=contents(COMMANDS_CSV))
def test_log_commands_csv(tmp_path: Path, data: bytes) -> None:
    folder = _log_folder(tmp_path, "odometry.csv", b"")
    (folder / "odometry.csv").unlink()
    (folder / "commands.csv").write_bytes(data)
    assert_clean(outcome(lambda: load_log(folder)), str(folder))


def _mrclam_folder(tmp_path: Path, name: str, data: bytes) -> Path:
    folder = tmp_path / "mrclam"
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir()
    for file, valid in MRCLAM_FILES.items():
        (folder / file).write_bytes(data if file == name else valid)
    return folder


@FUZZ
@given(name=st.sampled_from(sorted(MRCLAM_FILES)), seed=st.data())
def test_mrclam_dat(tmp_path: Path, name: str, seed: st.DataObject) -> None:
    data = seed.draw(contents(MRCLAM_FILES[name]))
    folder = _mrclam_folder(tmp_path, name, data)
    assert_clean(outcome(lambda: read_mrclam(folder, 1)), str(folder))


def _york_urban_folder(tmp_path: Path, data: bytes) -> Path:
    folder = tmp_path / "york_urban"
    image = folder / "images" / "P0001.jpg"
    if not image.exists():
        import matplotlib.image

        image.parent.mkdir(parents=True)
        pixels = np.random.default_rng(19).integers(0, 255, (12, 16), dtype=np.uint8)
        matplotlib.image.imsave(image.with_suffix(".png"), pixels, cmap="gray")
        image.with_suffix(".png").rename(image)
    (folder / "segments.csv").write_bytes(data)
    return folder


@FUZZ
@given(data=contents(YORK_SEGMENTS))
def test_york_urban_segments_csv(tmp_path: Path, data: bytes) -> None:
    folder = _york_urban_folder(tmp_path, data)
    assert_clean(outcome(lambda: load_york_urban(folder)), "segments.csv")


@FUZZ
@given(data=contents(CALIBRATED_TERRAIN))
def test_calibrated_terrain_toml(tmp_path: Path, data: bytes) -> None:
    path = tmp_path / "calibrated.toml"
    path.write_bytes(data)
    assert_clean(outcome(lambda: TerrainTable.from_toml(path)), "calibrated.toml")


@FUZZ
@given(data=contents(CALIBRATED_SENSORS))
def test_calibrated_sensors_toml(tmp_path: Path, data: bytes) -> None:
    path = tmp_path / "calibrated_sensors.toml"
    path.write_bytes(data)
    assert_clean(outcome(lambda: load_sensors(path)), "calibrated_sensors.toml")


def test_a_hang_fails_the_case() -> None:
    """The time limit works: a reader that does not return within it fails with HangError."""

    def forever() -> None:
        while True:
            time.sleep(0.01)

    with pytest.raises(HangError, match=r"expected a reader to finish within .* s, got a hang"):
        outcome(forever, seconds=0.2)
