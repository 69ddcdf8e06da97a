"""Camera files: TOML round trip, OpenCV FileStorage YAML/JSON, and every malformed-input error."""

from __future__ import annotations

import json
import math
import re
import tempfile
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from aura_ums.camera import (
    CalibrationBounds,
    Camera,
    CameraIntrinsics,
    CameraMount,
    camera_calibration_file,
    camera_info_intrinsics,
    camera_to_toml,
    load_calibration_bounds,
    load_camera,
    load_opencv_calibration,
)
from aura_ums.errors import FileFormatError
from tests.conftest import ros_calibration_yaml

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "camera.toml"
MOUNT = CameraMount(height=1.1, forward=0.2, pan=0.1, tilt=0.05)

# ------------------------------------------------------------------------------ TOML

GOOD_TOML = """\
[intrinsics]
fx = 500.0
fy = 505.0
cx = 320.0
cy = 240.0
width = 640
height = 480
distortion = [-0.1, 0.01, 0.001, -0.002]

[mount]
height = 1.2
left = 0.1
pan_deg = 90.0
tilt = 0.1

[calibration_bounds]
fx = 3.0
tilt_deg = 1.0
"""


def write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_toml_round_trip(tmp_path: Path) -> None:
    camera = Camera(
        CameraIntrinsics(612.5, 611.25, 318.7, 241.3, 640, 480, (-0.21, 0.04, 1e-3, -2e-3, 0.003)),
        CameraMount(height=1.37, forward=0.25, left=-0.05, pan=0.3, tilt=0.12),
    )
    bounds = CalibrationBounds(fx=2.5, fy=2.0, cx=1.5, cy=1.0, pan=0.01, tilt=0.02, height=0.03)
    path = write(tmp_path, "camera.toml", camera_to_toml(camera, bounds))
    assert load_camera(path) == camera
    assert load_calibration_bounds(path) == bounds
    pinhole = Camera(CameraIntrinsics(500, 500, 320, 240, 640, 480), CameraMount(1.0))
    path = write(tmp_path, "pinhole.toml", camera_to_toml(pinhole))
    assert load_camera(path) == pinhole
    assert load_calibration_bounds(path) == CalibrationBounds()


def test_toml_units_and_defaults(tmp_path: Path) -> None:
    path = write(tmp_path, "camera.toml", GOOD_TOML)
    camera = load_camera(path)
    assert camera.intrinsics.distortion == (-0.1, 0.01, 0.001, -0.002, 0.0)  # 4 given: k3 = 0
    assert camera.mount.pan == pytest.approx(math.pi / 2)
    assert camera.mount.forward == 0.0
    bounds = load_calibration_bounds(path)
    assert bounds.tilt == pytest.approx(math.radians(1.0))
    assert (bounds.fx, bounds.cy) == (3.0, 0.0)


def test_example_camera_file_is_the_york_urban_camera() -> None:
    camera = load_camera(EXAMPLE)
    k = camera.intrinsics
    assert (k.fx, k.cx, k.cy, k.width, k.height) == (674.9, 307.55, 251.45, 640, 480)
    assert load_calibration_bounds(EXAMPLE).fx > 0.0


def edit(old: str, new: str) -> str:
    assert old in GOOD_TOML
    return GOOD_TOML.replace(old, new)


@pytest.mark.parametrize(
    ("text", "where", "match"),
    [
        ("[intrinsics\nfx = 1", "bad.toml:1:12", "expected valid TOML, got Expected ']'"),
        (
            "[mount]" + GOOD_TOML.split("[mount]")[1],
            "intrinsics",
            r"\[intrinsics\]: expected this table, got none",
        ),
        (edit("[mount]\nheight = 1.2\n", "[mount]\n"), "mount", r"\[mount\]: expected key height"),
        (edit("fx = 500.0\n", ""), "intrinsics", r"\[intrinsics\]: expected keys fx, got none"),
        (edit("cx = 320.0", "cx = 320.0\nskew = 0.0"), "skew", r"\[intrinsics\] skew: .*unknown key 'skew'"),
        (GOOD_TOML + "\n[lens]\nmodel = 1\n", "lens", r"lens: expected one of .*unknown key 'lens'"),
        (edit("width = 640", "width = 640.0"), "width", r"\[intrinsics\] width: expected an integer >= 1"),
        (edit("fy = 505.0", "fy = nan"), "fy", r"\[intrinsics\] fy: expected a finite number, got nan"),
        (edit("fy = 505.0", 'fy = "505"'), "fy", r"\[intrinsics\] fy: expected a finite number, got '505'"),
        (
            edit("fx = 500.0", "fx = -500.0"),
            "fx",
            r"\[intrinsics\] fx: expected a number in \[1, 1e\+06\] px",
        ),
        # a field of view of nearly 180 degrees squeezed every window to a nanopixel
        (
            edit("fx = 500.0", "fx = 1e-300"),
            "fx",
            r"\[intrinsics\] fx: expected a number in \[1, 1e\+06\] px, got 1e-300",
        ),
        (edit("-0.002]", "-0.002, 0.0, 0.0]"), "distortion", "expected 4, 5, 8, 12 or 14 distortion"),
        (edit("-0.002]", "-0.002, 0.0, 0.1, 0.0, 0.0]"), "distortion", "beyond k3 .* to be zero"),
        (edit("distortion = [", "distortion = 3 #"), "distortion", "distortion: expected a list of numbers"),
        (edit("tilt = 0.1", "tilt = 0.1\ntilt_deg = 5.0"), "tilt_deg", "expected tilt or tilt_deg, got both"),
        (
            edit("tilt = 0.1", "tilt_deg = 95.0"),
            "tilt",
            r"\[mount\] tilt_deg: expected a number in \(-1\.5708, 1\.5708\) rad, got 95\.0 \(1\.65806 rad\)",
        ),
        (
            edit("fx = 3.0", "fx = -3.0"),
            "fx",
            r"\[calibration_bounds\] fx: expected a number in \[0, 1e\+06\] px",
        ),
        ("intrinsics = 3\n", "intrinsics", r"\[intrinsics\]: expected a table, got 3"),
    ],
)
def test_toml_errors_name_file_and_key(tmp_path: Path, text: str, where: str, match: str) -> None:
    path = write(tmp_path, "bad.toml", text)
    with pytest.raises(FileFormatError, match=match) as caught:
        load_camera(path)
    assert caught.value.path == str(path)
    assert where in location(caught.value)


def location(error: FileFormatError) -> str:
    """The place an error names: the file, its line if any, and the key path."""
    return str(error).removesuffix(f": {error.message}")


def test_missing_files_are_named(tmp_path: Path) -> None:
    with pytest.raises(FileFormatError, match=r"nowhere\.toml: expected an existing camera TOML file"):
        load_camera(tmp_path / "nowhere.toml")
    with pytest.raises(FileFormatError, match=r"nowhere\.yml: expected an existing calibration file"):
        load_opencv_calibration(tmp_path / "nowhere.yml", MOUNT)


# -------------------------------------------------------------------- FileStorage YAML

# As cv::FileStorage writes it (OpenCV 4, the calibration sample's output).
GOOD_YAML = """\
%YAML:1.0
---
calibration_time: "Fri 21 Nov 2026 10:12:01 CET"
nframes: 20
image_width: 640
image_height: 480
board_width: 9
board_height: 6
square_size: 2.5000000000000000e-02
# flags: +fix_k3
flags: 128
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
   data: [ -1.2345678901234567e-01, 4.5000000000000001e-02,
       1.0000000000000000e-03, -2.0000000000000000e-03, 0. ]
avg_reprojection_error: 2.1345678901234567e-01
per_view_reprojection_errors: !!opencv-matrix
   rows: 2
   cols: 1
   dt: f
   data: [ 2.11e-01, 2.15e-01 ]
features:
   - { x:167, y:49, lbp:[ 1, 0, 0, 1, 0, 0, 1, 1 ] }
   - { x: 298, y: 130, lbp: [ 0, 0, 0, 1, 0, 0, 1, 1 ] }
"""


def test_opencv_yaml(tmp_path: Path) -> None:
    camera = load_opencv_calibration(write(tmp_path, "calib.yml", GOOD_YAML), MOUNT)
    k = camera.intrinsics
    assert (k.fx, k.fy, k.cx, k.cy) == (
        674.90000000000009,
        674.89999999999998,
        307.55000000000001,
        251.45000000000002,
    )
    assert (k.width, k.height) == (640, 480)
    assert k.distortion == (-0.12345678901234567, 0.045, 0.001, -0.002, 0.0)
    assert camera.mount == MOUNT


def test_opencv_yaml_tutorial_spelling_and_eight_coefficients(tmp_path: Path) -> None:
    text = (
        "%YAML:1.0\n"
        "image_Width: 640\nimage_Height: 480\n"
        "Camera_Matrix: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n"
        "  data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]\n"
        "Distortion_Coefficients: !!opencv-matrix\n  rows: 8\n  cols: 1\n  dt: d\n"
        "  data: [ 0.1, -0.01, 0., 0., 0.001, 0., 0., 0. ]\n"
    )
    camera = load_opencv_calibration(write(tmp_path, "out_camera_data.yml", text), MOUNT)
    assert camera.intrinsics.distortion == (0.1, -0.01, 0.0, 0.0, 0.001)


def yaml_edit(old: str, new: str) -> str:
    assert old in GOOD_YAML
    return GOOD_YAML.replace(old, new, 1)


@pytest.mark.parametrize(
    ("text", "where", "match"),
    [
        (GOOD_YAML.replace("%YAML:1.0\n", ""), "calib.yml:1", "expected the '%YAML:1.0' header"),
        (yaml_edit("camera_matrix:", "cam_matrix:"), "camera_matrix", "expected the key camera_matrix"),
        (yaml_edit("image_height: 480\n", ""), "image_height", "expected the key image_height"),
        (yaml_edit("image_width: 640", "image_width: 640.5"), "image_width", "expected an integer >= 1"),
        (
            yaml_edit(" 0., 0., 1. ]", " 0., 0. ]"),
            "camera_matrix.data",
            r"expected rows x cols = 9 numbers, got 8",
        ),
        (
            yaml_edit("rows: 3\n   cols: 3", "rows: 1\n   cols: 9"),
            "camera_matrix",
            "expected a 3x3 matrix, got 1x9",
        ),
        (
            yaml_edit("6.7490000000000009e+02, 0.,", "6.7490000000000009e+02, 1.,"),
            "camera_matrix",
            "zero skew",
        ),
        (yaml_edit("0., 0., 1. ]", "0., 0., 2. ]"), "camera_matrix", r"expected \[\[fx, 0, cx\]"),
        (yaml_edit("4.5000000000000001e-02", ".Nan"), "distortion_coefficients.data[1]", "expected a finite"),
        (
            yaml_edit("6.7490000000000009e+02", "-.Inf"),
            "camera_matrix.data[0]",
            "expected a finite number, got -inf",
        ),
        (
            yaml_edit("-2.0000000000000000e-03, 0. ]", "0. ]"),
            "distortion_coefficients.data",
            "rows x cols = 5",
        ),
        (
            yaml_edit("camera_matrix: !!opencv-matrix", "camera_matrix:"),
            "camera_matrix",
            "type_id opencv-matrix",
        ),
        (yaml_edit("   dt: d\n   data: [ 6", "   data: [ 6"), "camera_matrix.dt", "expected this field"),
        (yaml_edit("dt: d", "dt: 3d"), "camera_matrix.dt", "one-channel element type"),
        (yaml_edit("0., 0., 1. ]", "0., 0., 1. "), "calib.yml:16", "expected balanced brackets"),
        (yaml_edit("nframes: 20", "nframes 20"), "calib.yml:4", "expected 'key: value', got 'nframes 20'"),
        (yaml_edit("flags: 128", "   flags: 128"), "calib.yml:11", "expected indentation 0, got 3"),
        (yaml_edit("board_width: 9", "image_width: 9"), "calib.yml:7", "expected the key 'image_width' once"),
        (yaml_edit("1, 1 ] }", "1, 1 } }"), "calib.yml:31", r"expected ',' or '\]' in a list"),
        (yaml_edit("{ x:167,", "{ x 167,"), "calib.yml:31", r"expected ':' after the key 'x 167'"),
        (
            yaml_edit("rows: 5\n   cols: 1", "rows: 1\n   cols: 5")
            .replace("rows: 1\n   cols: 5", "rows: 1\n   cols: 8", 1)
            .replace("-2.0000000000000000e-03, 0. ]", "-2.0000000000000000e-03, 0., 0., 0.5, 0. ]"),
            "distortion_coefficients",
            "beyond k3",
        ),
    ],
)
def test_opencv_yaml_errors(tmp_path: Path, text: str, where: str, match: str) -> None:
    path = write(tmp_path, "calib.yml", text)
    with pytest.raises(FileFormatError, match=match) as caught:
        load_opencv_calibration(path, MOUNT)
    assert caught.value.path == str(path)
    assert where in location(caught.value)


# -------------------------------------------------------------------- FileStorage JSON


def opencv_matrix(rows: int, cols: int, data: list[float]) -> dict[str, object]:
    return {"type_id": "opencv-matrix", "rows": rows, "cols": cols, "dt": "d", "data": data}


GOOD_JSON = {
    "calibration_time": "Fri 21 Nov 2026 10:12:01 CET",
    "image_width": 640,
    "image_height": 480,
    "camera_matrix": opencv_matrix(3, 3, [674.9, 0.0, 307.55, 0.0, 674.9, 251.45, 0.0, 0.0, 1.0]),
    "distortion_coefficients": opencv_matrix(1, 5, [-0.1, 0.02, 0.0, 0.0, 0.0]),
}


def test_opencv_json(tmp_path: Path) -> None:
    path = write(tmp_path, "calib.json", json.dumps(GOOD_JSON, indent=4))
    camera = load_opencv_calibration(path, MOUNT)
    assert camera.intrinsics == CameraIntrinsics(
        674.9, 674.9, 307.55, 251.45, 640, 480, (-0.1, 0.02, 0, 0, 0)
    )


def test_opencv_json_with_bare_trailing_dots(tmp_path: Path) -> None:
    # OpenCV 3 writes reals like "1." in JSON too: accepted
    text = json.dumps(GOOD_JSON, indent=4).replace("0.0", "0.").replace("1.0]", "1.]")
    assert " 0.," in text
    camera = load_opencv_calibration(write(tmp_path, "calib.json", text), MOUNT)
    assert camera.intrinsics.fx == 674.9


@pytest.mark.parametrize(
    ("text", "where", "match"),
    [
        ('{"image_width": 640,', "calib.json:1:21", "expected valid JSON, got Expecting property name"),
        ("[1, 2]", "", "expected an object, got an array"),
        (
            '{"image_width": 640, "image_width": 640}',
            "",
            "expected valid JSON, got the key 'image_width' twice",
        ),
        (
            json.dumps({**GOOD_JSON, "image_width": -640}),
            "image_width",
            "expected an integer >= 1, got -640",
        ),
        (
            json.dumps({k: v for k, v in GOOD_JSON.items() if k != "camera_matrix"}),
            "camera_matrix",
            "no such key",
        ),
        (
            json.dumps({**GOOD_JSON, "camera_matrix": opencv_matrix(3, 3, [math.nan] * 9)}),
            "",
            "expected valid JSON, got the non-standard number NaN",
        ),
        (
            json.dumps(
                {**GOOD_JSON, "camera_matrix": {**opencv_matrix(3, 3, []), "type_id": "opencv-nd-matrix"}}
            ),
            "camera_matrix",
            "expected type_id opencv-matrix, got 'opencv-nd-matrix'",
        ),
        (
            json.dumps({**GOOD_JSON, "distortion_coefficients": opencv_matrix(2, 3, [0.0] * 6)}),
            "distortion_coefficients",
            "expected a 1xN or Nx1 matrix, got 2x3",
        ),
        (
            json.dumps({**GOOD_JSON, "distortion_coefficients": opencv_matrix(1, 3, [0.0] * 3)}),
            "distortion_coefficients",
            "expected 4, 5, 8, 12 or 14 distortion coefficients, got 3",
        ),
        (
            json.dumps({**GOOD_JSON, "camera_matrix": opencv_matrix(3, 3, ["a"] * 9)}),  # type: ignore[list-item]
            "camera_matrix.data[0]",
            "expected a finite number, got 'a'",
        ),
        (
            json.dumps({**GOOD_JSON, "cameraMatrix": GOOD_JSON["camera_matrix"]}),
            "cameraMatrix",
            "expected one camera_matrix, got camera_matrix, cameraMatrix",
        ),
        (
            json.dumps({**GOOD_JSON, "camera_matrix": opencv_matrix(3, 3, [-5.0, 0, 1, 0, 5, 1, 0, 0, 1])}),
            "camera_matrix fx",
            r"expected a number in \[1, 1e\+06\] px",
        ),
    ],
)
def test_opencv_json_errors(tmp_path: Path, text: str, where: str, match: str) -> None:
    path = write(tmp_path, "calib.json", text)
    with pytest.raises(FileFormatError, match=match) as caught:
        load_opencv_calibration(path, MOUNT)
    assert caught.value.path == str(path)
    assert where in location(caught.value)


def test_opencv_loader_refuses_other_formats(tmp_path: Path) -> None:
    path = write(tmp_path, "calib.xml", '<?xml version="1.0"?>\n<opencv_storage>\n</opencv_storage>\n')
    with pytest.raises(
        FileFormatError, match=r"calib\.xml:1: expected a FileStorage YAML \('%YAML:1.0'\) or JSON"
    ):
        load_opencv_calibration(path, MOUNT)


def test_opencv_loader_refuses_a_bad_mount(tmp_path: Path) -> None:
    path = write(tmp_path, "calib.json", json.dumps(GOOD_JSON))
    with pytest.raises(ValueError, match="mount: expected CameraMount, got float"):
        load_opencv_calibration(path, 1.0)  # type: ignore[arg-type]


def test_yaml_and_json_agree(tmp_path: Path) -> None:
    as_json = {
        **GOOD_JSON,
        "camera_matrix": opencv_matrix(3, 3, [674.9, 0.0, 307.55, 0.0, 674.9, 251.45, 0.0, 0.0, 1.0]),
        "distortion_coefficients": opencv_matrix(5, 1, [-0.1, 0.02, 0.001, -0.002, 0.0]),
    }
    yaml = (
        "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n"
        "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
        "   data: [ 674.9, 0., 307.55, 0., 674.9, 251.45, 0., 0., 1. ]\n"
        "distortion_coefficients: !!opencv-matrix\n   rows: 5\n   cols: 1\n   dt: d\n"
        "   data: [ -0.1, 0.02, 0.001, -0.002, 0. ]\n"
    )
    from_json = load_opencv_calibration(write(tmp_path, "a.json", json.dumps(as_json)), MOUNT)
    from_yaml = load_opencv_calibration(write(tmp_path, "a.yml", yaml), MOUNT)
    assert from_json == from_yaml
    np.testing.assert_array_equal(from_json.intrinsics.matrix(), from_yaml.intrinsics.matrix())


# -------------------------------------------------------------------- encodings and limits

BOM = b"\xef\xbb\xbf"


@pytest.mark.parametrize(("name", "text"), [("c.yml", GOOD_YAML), ("c.json", json.dumps(GOOD_JSON))])
def test_opencv_files_with_a_byte_order_mark_read_the_same(tmp_path: Path, name: str, text: str) -> None:
    plain = load_opencv_calibration(write(tmp_path, name, text), MOUNT)
    (tmp_path / f"bom-{name}").write_bytes(BOM + text.encode())
    assert load_opencv_calibration(tmp_path / f"bom-{name}", MOUNT) == plain


def test_toml_camera_with_a_byte_order_mark_reads_the_same(tmp_path: Path) -> None:
    (tmp_path / "bom.toml").write_bytes(BOM + GOOD_TOML.encode())
    assert load_camera(tmp_path / "bom.toml") == load_camera(write(tmp_path, "plain.toml", GOOD_TOML))
    assert load_calibration_bounds(tmp_path / "bom.toml") == load_calibration_bounds(tmp_path / "plain.toml")


@pytest.mark.parametrize("name", ["c.toml", "c.yml", "c.json"])
def test_latin1_camera_files_are_refused_naming_file_and_byte(tmp_path: Path, name: str) -> None:
    path = tmp_path / name
    path.write_bytes('{"note": "f\u00e9",'.encode("latin-1"))
    loader = load_camera if name.endswith(".toml") else (lambda p: load_opencv_calibration(p, MOUNT))
    with pytest.raises(
        FileFormatError, match=re.escape(f"{path}:1: byte 11: expected UTF-8 text, got the byte 0xe9")
    ):
        loader(path)


def test_over_size_camera_file_is_refused_stating_the_limit(tmp_path: Path) -> None:
    path = tmp_path / "huge.yml"
    with path.open("wb") as handle:
        handle.truncate(64 * 1024 * 1024 + 1)
    with pytest.raises(FileFormatError, match=r"huge\.yml: expected a calibration file of at most 64 MiB"):
        load_opencv_calibration(path, MOUNT)


def test_deeply_nested_yaml_is_a_clean_error(tmp_path: Path) -> None:
    path = write(tmp_path, "deep.yml", "%YAML:1.0\nx: " + "[" * 5000 + "]" * 5000 + "\n")
    with pytest.raises(FileFormatError, match=r"deep\.yml: expected YAML, got collections nested too deep"):
        load_opencv_calibration(path, MOUNT)


def test_a_flow_sequence_cut_after_a_comma_is_a_clean_error(tmp_path: Path) -> None:
    # Found by tests/test_files_fuzz.py: the end of the value was taken for a quote.
    path = write(tmp_path, "cut.yml", "%YAML:1.0\n]: [1,\n")
    with pytest.raises(FileFormatError, match=r"cut\.yml:2: expected a value, got ''"):
        load_opencv_calibration(path, MOUNT)


@pytest.mark.parametrize(
    ("old", "new", "where", "match"),
    [
        (
            "image_width: 640",
            "image_width: " + "9" * 5000,
            "image_width",
            "expected an integer >= 1, got inf$",
        ),
        (
            "data: [554.25,",
            "data: [" + "9" * 5000 + ",",
            "camera_matrix.data[0]",
            "expected a finite number, got inf$",
        ),
    ],
    ids=["size", "matrix"],
)
def test_an_integer_of_thousands_of_digits_is_a_clean_error(
    tmp_path: Path, old: str, new: str, where: str, match: str
) -> None:
    # Python refuses to convert integers over 4300 digits (a ValueError, which escaped).
    path = write(tmp_path, "ost.yaml", ROS_YAML.replace(old, new, 1))
    with pytest.raises(FileFormatError, match=match) as caught:
        load_opencv_calibration(path, ROS_MOUNT)
    assert where in location(caught.value)


def test_a_focal_bound_not_below_the_focal_length_is_refused_by_the_file(tmp_path: Path) -> None:
    """Named with the file when read, not at the first observation that uses it."""
    camera = Camera(CameraIntrinsics(500, 400, 320, 240, 640, 480), CameraMount(1.0))
    path = write(tmp_path, "loose.toml", camera_to_toml(camera, CalibrationBounds(fy=400.0)))
    for read in (load_camera, load_calibration_bounds):
        with pytest.raises(
            FileFormatError,
            match=r"loose\.toml: \[calibration_bounds\] fy: expected a bound below \[intrinsics\] fy "
            r"\(400\.0 px\), got 400\.0$",
        ):
            read(path)


# -------------------------------------------------------------------- ROS calibration YAML

# As ROS's camera_calibration_parsers writes it (camera_info_manager's files, the calibrator's
# ost.yaml): no '%YAML' header, matrices as plain {rows, cols, data} mappings.
ROS_YAML = ros_calibration_yaml(
    "narrow_stereo",
    "554.25, 0, 320.5, 0, 554.25, 240.5, 0, 0, 1",
    "-0.1, 0.01, 0, 0, 0",
    "554.25, 0, 320.5, 0, 0, 554.25, 240.5, 0, 0, 0, 1, 0",
)
# The same camera in aura-ums' TOML.
ROS_AS_TOML = """\
[intrinsics]
fx = 554.25
fy = 554.25
cx = 320.5
cy = 240.5
width = 640
height = 480
distortion = [-0.1, 0.01, 0.0, 0.0, 0.0]

[mount]
height = 0.3
"""
ROS_MOUNT = CameraMount(0.3)


def ros_edit(old: str, new: str) -> str:
    assert old in ROS_YAML
    return ROS_YAML.replace(old, new, 1)


def test_ros_calibration_reads_as_the_equivalent_toml(tmp_path: Path) -> None:
    camera = load_opencv_calibration(write(tmp_path, "ost.yaml", ROS_YAML), ROS_MOUNT)
    assert camera == load_camera(write(tmp_path, "cam.toml", ROS_AS_TOML))
    assert camera.intrinsics.distortion == (-0.1, 0.01, 0.0, 0.0, 0.0)


def test_ros_calibration_as_the_python_calibrator_writes_it(tmp_path: Path) -> None:
    # camera_calibration's cameracalibrator writes "%8f" numbers and padded brackets.
    text = ROS_YAML.replace(
        "data: [554.25, 0, 320.5, 0, 554.25, 240.5, 0, 0, 1]",
        "data: [ 554.250000, 0.000000, 320.500000,\n          0.000000, 554.250000, 240.500000,\n"
        "          0.000000, 0.000000, 1.000000]",
    ).replace("data: [-0.1, 0.01, 0, 0, 0]", "data: [-0.100000, 0.010000, 0.000000, 0.000000, 0.000000]")
    # Told by its content, whatever its name (a file without distortion_model is plumb_bob, as ROS reads it).
    path = write(tmp_path, "left.calibration", text.replace("distortion_model: plumb_bob\n", ""))
    assert load_opencv_calibration(path, ROS_MOUNT) == load_camera(write(tmp_path, "c.toml", ROS_AS_TOML))


def test_ros_empty_distortion_is_none(tmp_path: Path) -> None:
    # camera_calibration_parsers writes an empty D as rows 1, cols 0, data []; ROS reads it as
    # no distortion. It was refused ("cols: expected an integer >= 1, got 0").
    text = ros_edit("cols: 5\n  data: [-0.1, 0.01, 0, 0, 0]", "cols: 0\n  data: []")
    camera = load_opencv_calibration(write(tmp_path, "ost.yaml", text), ROS_MOUNT)
    assert camera.intrinsics.distortion == (0.0, 0.0, 0.0, 0.0, 0.0)
    with pytest.raises(FileFormatError, match=r"camera_matrix.cols: expected an integer >= 1, got 0$"):
        load_opencv_calibration(
            write(
                tmp_path,
                "k.yaml",
                ros_edit("rows: 3\n  cols: 3\n  data: [554", "rows: 3\n  cols: 0\n  data: [554"),
            ),
            ROS_MOUNT,
        )


def test_ros_rational_polynomial_with_zero_extra_terms(tmp_path: Path) -> None:
    text = ros_edit("distortion_model: plumb_bob", "distortion_model: rational_polynomial").replace(
        "cols: 5\n  data: [-0.1, 0.01, 0, 0, 0]", "cols: 8\n  data: [-0.1, 0.01, 0.001, 0, 0.002, 0, 0, 0]"
    )
    camera = load_opencv_calibration(write(tmp_path, "ost.yaml", text), ROS_MOUNT)
    assert camera.intrinsics.distortion == (-0.1, 0.01, 0.001, 0.0, 0.002)


@pytest.mark.parametrize(
    ("text", "where", "match"),
    [
        (
            ros_edit("distortion_model: plumb_bob", "distortion_model: equidistant")
            .replace("cols: 5", "cols: 4")
            .replace("data: [-0.1, 0.01, 0, 0, 0]", "data: [-0.1, 0.01, 0, 0]"),
            "distortion_model",
            "expected distortion_model plumb_bob or rational_polynomial, got 'equidistant'$",
        ),
        (
            ros_edit("distortion_model: plumb_bob", "distortion_model: [plumb_bob]"),
            "distortion_model",
            "expected distortion_model plumb_bob or rational_polynomial, got an array$",
        ),
        (
            ros_edit(
                "data: [1, 0, 0, 0, 1, 0, 0, 0, 1]", "data: [0.9998, 0.02, 0, -0.02, 0.9998, 0, 0, 0, 1]"
            ),
            "rectification_matrix",
            r"expected the identity \(a monocular camera: aura-ums models no rectification\), "
            r"got \[\[0\.9998",
        ),
        (
            ros_edit("rows: 3\n  cols: 3\n  data: [1, 0, 0,", "rows: 1\n  cols: 9\n  data: [1, 0, 0,"),
            "rectification_matrix",
            r"expected the identity .*, got \[\[1\.0, 0\.0",
        ),
        (
            ros_edit("distortion_model: plumb_bob", "distortion_model: rational_polynomial").replace(
                "cols: 5\n  data: [-0.1, 0.01, 0, 0, 0]", "cols: 8\n  data: [-0.1, 0.01, 0, 0, 0, 0.5, 0, 0]"
            ),
            "distortion_coefficients",
            r"expected the coefficients beyond k3 \(k4-k6, s1-s4, tau\) to be zero",
        ),
        (
            ros_edit(
                "cols: 5\n  data: [-0.1, 0.01, 0, 0, 0]", "cols: 8\n  data: [-0.1, 0.01, 0, 0, 0, 0, 0, 0]"
            ),
            "distortion_coefficients",
            r"expected 4 or 5 \(k1, k2, p1, p2\[, k3\]\) coefficients \(or none: no distortion\) for "
            r"distortion_model plumb_bob, got 8$",
        ),
        (
            ros_edit("distortion_model: plumb_bob", "distortion_model: rational_polynomial"),
            "distortion_coefficients",
            r"expected 8 \(k1, k2, p1, p2, k3, k4, k5, k6\) coefficients \(or none: no distortion\) for "
            r"distortion_model rational_polynomial, got 5$",
        ),
        (
            ros_edit("camera_matrix:", "K:"),
            "camera_matrix",
            "expected the key camera_matrix, got no such key",
        ),
        (
            ros_edit("image_height: 480\n", ""),
            "image_height",
            "expected the key image_height, got no such key",
        ),
        (ros_edit("image_width: 640", "image_width: 0"), "image_width", "expected an integer >= 1, got 0"),
        (
            ros_edit("  cols: 3\n  data: [554", "  data: [554"),
            "camera_matrix.cols",
            "expected this field of a matrix",
        ),
        (
            ros_edit("554.25, 0, 320.5, 0, 554.25", "554.25, 3, 320.5, 0, 554.25"),
            "camera_matrix",
            "zero skew",
        ),
        (
            ros_edit("554.25, 0, 320.5, 0, 554.25", "0.5, 0, 320.5, 0, 554.25"),
            "camera_matrix fx",
            "expected a number in",
        ),
        (
            ros_edit("data: [-0.1, 0.01, 0, 0, 0]", "data: [-0.1, .nan, 0, 0, 0]"),
            "distortion_coefficients.data[1]",
            "finite",
        ),
        (
            ros_edit("camera_matrix:\n", "camera_matrix: 3\n").replace(
                "  rows: 3\n  cols: 3\n  data: [554.25, 0, 320.5, 0, 554.25, 240.5, 0, 0, 1]\n", "", 1
            ),
            "camera_matrix",
            "expected a matrix mapping, got 3$",
        ),
        (
            ros_edit("image_width: 640", "image_width 640"),
            "ost.yaml:1",
            "expected 'key: value', got 'image_width 640'",
        ),
    ],
)
def test_ros_calibration_errors(tmp_path: Path, text: str, where: str, match: str) -> None:
    path = write(tmp_path, "ost.yaml", text)
    with pytest.raises(FileFormatError, match=match) as caught:
        load_opencv_calibration(path, ROS_MOUNT)
    assert caught.value.path == str(path)
    assert where in location(caught.value)


def test_a_header_less_yaml_of_neither_kind_is_refused(tmp_path: Path) -> None:
    path = write(tmp_path, "notes.yaml", "# a calibration?\nfocal: 500\n")
    with pytest.raises(
        FileFormatError,
        match=r"notes\.yaml:1: expected the '%YAML:1\.0' header of an OpenCV FileStorage file, or a ROS "
        r"calibration \(camera_matrix: rows, cols, data\), got '# a calibration\?'$",
    ):
        load_opencv_calibration(path, ROS_MOUNT)


@given(
    focal=st.floats(100.0, 2000.0),
    aspect=st.floats(0.9, 1.1),
    centre=st.tuples(st.floats(-50.0, 50.0), st.floats(-50.0, 50.0)),
    size=st.tuples(st.integers(1, 4000), st.integers(1, 4000)),
    distortion=st.tuples(
        st.floats(-0.3, 0.3),
        st.floats(-0.1, 0.1),
        st.floats(-0.01, 0.01),
        st.floats(-0.01, 0.01),
        st.floats(-0.05, 0.05),
    ),
    rational=st.booleans(),
)
@settings(max_examples=40, deadline=None)
def test_any_ros_calibration_reads_as_its_toml(
    focal: float,
    aspect: float,
    centre: tuple[float, float],
    size: tuple[int, int],
    distortion: tuple[float, ...],
    rational: bool,
) -> None:
    """Whatever the numbers (written with repr, as exactly as the TOML), both files read the same camera."""
    width, height = size
    fx, fy, cx, cy = focal, focal * aspect, width / 2 + centre[0], height / 2 + centre[1]
    coefficients = [*distortion, 0.0, 0.0, 0.0] if rational else list(distortion)
    numbers = ", ".join(repr(c) for c in coefficients)
    ros = (
        f"image_width: {width}\nimage_height: {height}\ncamera_name: cam\n"
        f"camera_matrix:\n  rows: 3\n  cols: 3\n  data: [{fx!r}, 0, {cx!r}, 0, {fy!r}, {cy!r}, 0, 0, 1]\n"
        f"distortion_model: {'rational_polynomial' if rational else 'plumb_bob'}\n"
        f"distortion_coefficients:\n  rows: 1\n  cols: {len(coefficients)}\n  data: [{numbers}]\n"
    )
    toml = (
        f"[intrinsics]\nfx = {fx!r}\nfy = {fy!r}\ncx = {cx!r}\ncy = {cy!r}\n"
        f"width = {width}\nheight = {height}\n"
        f"distortion = [{', '.join(repr(c) for c in distortion)}]\n[mount]\nheight = 0.3\n"
    )
    with tempfile.TemporaryDirectory() as folder:
        ost = write(Path(folder), "ost.yaml", ros)
        named = write(
            Path(folder), "named.toml", '[intrinsics]\ncalibration = "ost.yaml"\n[mount]\nheight = 0.3\n'
        )
        expected = load_camera(write(Path(folder), "cam.toml", toml))
        assert load_opencv_calibration(ost, ROS_MOUNT) == expected
        assert load_camera(named) == expected


# ------------------------------------------------------- a camera TOML naming a calibration

NAMING_TOML = """\
[intrinsics]
calibration = "calibrations/ost.yaml"   # relative to this file

[mount]
height = 0.3

[calibration_bounds]
fx = 3.0
"""


def test_a_camera_toml_may_name_its_calibration(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "robot" / "calibrations").mkdir(parents=True)
    write(tmp_path / "robot" / "calibrations", "ost.yaml", ROS_YAML)
    toml = write(tmp_path / "robot", "camera.toml", NAMING_TOML)
    monkeypatch.chdir(tmp_path)  # the calibration is found beside the TOML, not in the current folder
    relative = Path("robot") / "camera.toml"
    assert load_camera(relative) == load_camera(write(tmp_path, "same.toml", ROS_AS_TOML))
    assert load_calibration_bounds(relative) == CalibrationBounds(fx=3.0)
    assert camera_calibration_file(relative) == Path("robot") / "calibrations" / "ost.yaml"
    assert camera_calibration_file(toml) == tmp_path / "robot" / "calibrations" / "ost.yaml"
    assert camera_calibration_file(tmp_path / "same.toml") is None
    # An OpenCV FileStorage calibration, named by an absolute path, reads the same way.
    opencv = write(tmp_path, "calib.yml", GOOD_YAML)
    text = NAMING_TOML.replace('"calibrations/ost.yaml"', json.dumps(str(opencv)))
    assert (
        load_camera(write(tmp_path, "opencv.toml", text)).intrinsics
        == load_opencv_calibration(opencv, MOUNT).intrinsics
    )


def test_calibration_and_numbers_together_are_refused(tmp_path: Path) -> None:
    write(tmp_path, "ost.yaml", ROS_YAML)
    text = NAMING_TOML.replace('"calibrations/ost.yaml"', '"ost.yaml"\nfx = 554.25\ncy = 240.5')
    with pytest.raises(
        FileFormatError, match=r"cam\.toml: \[intrinsics\] fx: expected calibration or fx, cy, got both$"
    ):
        load_camera(write(tmp_path, "cam.toml", text))


def test_a_missing_calibration_file_is_refused_naming_both_files(tmp_path: Path) -> None:
    toml = write(tmp_path, "cam.toml", NAMING_TOML)
    missing = tmp_path / "calibrations" / "ost.yaml"
    for read in (load_camera, load_calibration_bounds, camera_calibration_file):
        with pytest.raises(
            FileFormatError,
            match=re.escape(
                f"{toml}: [intrinsics] calibration: expected an OpenCV or ROS calibration file that reads, "
                f"got: {missing}: expected an existing calibration file, got no such file"
            ),
        ):
            read(toml)


@pytest.mark.parametrize(
    ("calibration", "match"),
    [
        ("3", r"cam\.toml: \[intrinsics\] calibration: expected a non-empty string, got 3$"),
        ('""', r"cam\.toml: \[intrinsics\] calibration: expected a non-empty string, got ''$"),
        (
            '"ost.yaml"',
            r"cam\.toml: \[intrinsics\] calibration: expected an OpenCV or ROS calibration file that reads, "
            r"got: .*ost\.yaml: distortion_model: expected distortion_model plumb_bob or "
            r"rational_polynomial, got 'equidistant'$",
        ),
    ],
)
def test_a_bad_calibration_entry_is_named_with_its_file(tmp_path: Path, calibration: str, match: str) -> None:
    write(tmp_path, "ost.yaml", ros_edit("distortion_model: plumb_bob", "distortion_model: equidistant"))
    text = NAMING_TOML.replace('"calibrations/ost.yaml"', calibration)
    with pytest.raises(FileFormatError, match=match):
        load_camera(write(tmp_path, "cam.toml", text))


# ------------------------------------------------------- a CameraInfo message (ROS 1 or 2)


def camera_info(**fields: object) -> SimpleNamespace:
    """A sensor_msgs/CameraInfo as rosbags deserializes it (ROS 2 field names; arrays as numpy)."""
    values: dict[str, object] = {
        "width": 640,
        "height": 480,
        "distortion_model": "plumb_bob",
        "d": np.array([-0.1, 0.01, 0.0, 0.0, 0.0]),
        "k": np.array([554.25, 0.0, 320.5, 0.0, 554.25, 240.5, 0.0, 0.0, 1.0]),
        "r": np.eye(3).ravel(),
        "binning_x": 0,
        "binning_y": 0,
        "roi": SimpleNamespace(x_offset=0, y_offset=0, width=0, height=0),
    }
    return SimpleNamespace(**{**values, **fields})


def test_a_camera_info_reads_as_the_ros_calibration_file(tmp_path: Path) -> None:
    expected = load_opencv_calibration(write(tmp_path, "ost.yaml", ROS_YAML), ROS_MOUNT).intrinsics
    assert camera_info_intrinsics(camera_info(), "run.bag", "topic /info, message 0") == expected
    ros1 = camera_info()  # ROS 1's upper-case D, K, R
    for name in ("d", "k", "r"):
        setattr(ros1, name.upper(), getattr(ros1, name))
        delattr(ros1, name)
    assert camera_info_intrinsics(ros1, "run.bag", "topic /info, message 0") == expected
    full = camera_info(roi=SimpleNamespace(x_offset=0, y_offset=0, width=640, height=480), binning_x=1)
    assert camera_info_intrinsics(full, "run.bag", "topic /info, message 0") == expected


@pytest.mark.parametrize(
    ("fields", "match"),
    [
        (
            {"k": np.zeros(8)},
            r"run\.bag: topic /info, message 0, k: expected 9 numbers \(a 3x3 matrix\), got 8$",
        ),
        ({"r": "identity"}, r"message 0, r: expected an array of numbers, got 'identity'$"),
        ({"d": [0.1, "x", 0, 0, 0]}, r"message 0, d\[1\]: expected a finite number, got 'x'$"),
        ({"distortion_model": ""}, r"message 0, distortion_model: expected distortion_model plumb_bob or "),
        ({"height": 480.5}, r"message 0, height: expected an integer >= 1, got 480\.5$"),
        ({"binning_y": 4}, r"message 0, binning_y: expected 0 or 1 \(an unbinned image\), got 4$"),
    ],
)
def test_a_camera_info_is_checked_as_a_calibration_file(fields: dict[str, object], match: str) -> None:
    with pytest.raises(FileFormatError, match=match):
        camera_info_intrinsics(camera_info(**fields), "run.bag", "topic /info, message 0")


def test_a_camera_info_without_a_field_is_refused() -> None:
    message = camera_info()
    del message.k
    with pytest.raises(
        FileFormatError,
        match=r"run\.bag: topic /info, message 0: expected a CameraInfo with the field k, got none$",
    ):
        camera_info_intrinsics(message, "run.bag", "topic /info, message 0")
