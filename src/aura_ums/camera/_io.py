"""Camera files: aura-ums' TOML, OpenCV ``cv::FileStorage`` calibrations, ROS calibrations.

Neither OpenCV, ROS nor a YAML library is needed: the FileStorage YAML subset (a
``%YAML:1.0`` header, block mappings and sequences, flow ``[...]``/``{...}`` collections
over several lines, ``!!opencv-matrix`` tags, quoted and plain scalars, comments) is
parsed here, and so are ROS's calibration files (camera_calibration_parsers' YAML, which
camera_info_manager and the ROS calibrator write: the same subset without the header).
Every error is a :class:`~aura_ums.errors.FileFormatError` naming the file and the place.

The TOML camera file::

    [intrinsics]              # pixels; (0, 0) is the centre of the top-left pixel
    fx = 674.9
    fy = 674.9
    cx = 307.55
    cy = 251.45
    width = 640
    height = 480
    distortion = [-0.1, 0.01, 0.0, 0.0, 0.0]   # optional: k1, k2, p1, p2[, k3]

    [mount]                   # metres; pan/tilt in radians, or pan_deg/tilt_deg in degrees
    height = 1.2
    forward = 0.0             # optional, default 0
    left = 0.0                # optional, default 0
    pan_deg = 0.0             # optional, default 0
    tilt_deg = 5.0            # optional, default 0

    [calibration_bounds]      # optional: half-widths, see CalibrationBounds
    fx = 3.0
    pan_deg = 0.5

``[intrinsics]`` may instead name a calibration file, OpenCV's or ROS's (read by
:func:`load_opencv_calibration`), for the numbers above; the mount, which no calibration
holds, stays in the TOML::

    [intrinsics]
    calibration = "ost.yaml"  # relative to this file's folder; no fx... beside it
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from aura_ums._files import Fields, describe, load_toml, parse_json, read_text
from aura_ums._validate import ANGLE, DISTORTION, FOCAL_LENGTH, IMAGE_SIDE, PIXEL, SENSOR_OFFSET, Range
from aura_ums.camera._model import Camera, CameraIntrinsics, CameraMount, opencv_distortion
from aura_ums.camera._observe import CalibrationBounds
from aura_ums.errors import FileFormatError, InputError

Array = NDArray[np.float64]

#: Distortion vector lengths OpenCV writes (k1, k2, p1, p2[, k3[, k4, k5, k6[, s1..s4[, tx, ty]]]]).

_INTRINSIC_KEYS = ("fx", "fy", "cx", "cy", "width", "height", "distortion")
_ANGLES = ("pan", "tilt")
#: Where a camera sits on the robot, metres from the robot's reference point: a sensor's
#: offset (``CameraMount`` checks the same range).
MOUNT_OFFSET = SENSOR_OFFSET
#: The physical range of every number of a camera file, by table and key (docs/formats.md
#: lists them); the bounds of ``[calibration_bounds]`` are bounds on errors, >= 0.
KEY_RANGES: dict[str, dict[str, Range]] = {
    "intrinsics": {
        "fx": FOCAL_LENGTH,
        "fy": FOCAL_LENGTH,
        "cx": PIXEL,
        "cy": PIXEL,
        "width": IMAGE_SIDE,
        "height": IMAGE_SIDE,
        "distortion": DISTORTION,  # each coefficient (OpenCV files too)
    },
    "mount": {
        "height": Range(0.0, MOUNT_OFFSET.high, "m"),  # above the ground
        "forward": MOUNT_OFFSET,
        "left": MOUNT_OFFSET,
        "pan": ANGLE,
        # CameraMount's own limit: at +-pi/2 the optical axis is vertical, the horizon out of view.
        "tilt": Range(-math.pi / 2, math.pi / 2, "rad", low_open=True, high_open=True),
    },
    "calibration_bounds": {
        "fx": Range(0.0, FOCAL_LENGTH.high, "px"),
        "fy": Range(0.0, FOCAL_LENGTH.high, "px"),
        "cx": Range(0.0, PIXEL.high, "px"),
        "cy": Range(0.0, PIXEL.high, "px"),
        "height": Range(0.0, MOUNT_OFFSET.high, "m"),
        "pan": Range(0.0, ANGLE.high, "rad"),
        "tilt": Range(0.0, ANGLE.high, "rad"),
    },
}


# ------------------------------------------------------------------------------ shared


def _number(value: object, source: str, where: str) -> float:
    return Fields(source).number(value, where)


def _integer(value: object, source: str, where: str) -> int:
    return Fields(source).integer(value, where, minimum=1)


def _ranged(value: object, source: str, where: str, bounds: Range) -> float:
    return Fields(source).ranged(value, where, bounds)


def _side(value: object, source: str, where: str) -> int:
    """Return an image's width or height: an integer in :data:`~aura_ums._validate.IMAGE_SIDE`."""
    result = _integer(value, source, where)
    if result > IMAGE_SIDE.high:
        raise FileFormatError(source, where, f"expected at most {IMAGE_SIDE.high:g} px, got {result}")
    return result


def _distortion(values: Array, source: str, where: str) -> tuple[float, float, float, float, float]:
    """OpenCV's distortion vector as (k1, k2, p1, p2, k3) (:func:`opencv_distortion`), the file named."""
    try:
        return opencv_distortion(values, where)
    except InputError as exc:
        located, _, message = str(exc).partition(": ")
        raise FileFormatError(source, located, message) from None


def _reraise(source: str, where: str, exc: InputError) -> FileFormatError:
    field, _, message = str(exc).partition(": ")
    key = field.rsplit(".", 1)[-1]
    return FileFormatError(source, f"{where} {key}".strip(), message or str(exc))


# ------------------------------------------------------------------------------ TOML


def _table(document: Mapping[str, object], name: str, source: str, *, required: bool) -> dict[str, object]:
    if name not in document:
        if required:
            raise FileFormatError(source, f"[{name}]", "expected this table, got none")
        return {}
    return Fields(source).table(document[name], f"[{name}]")


def _angle(
    table: Mapping[str, object], name: str, source: str, where: str, bounds: Range = ANGLE
) -> float | None:
    radians, degrees = table.get(name), table.get(f"{name}_deg")
    if radians is not None and degrees is not None:
        raise FileFormatError(source, f"{where} {name}_deg", f"expected {name} or {name}_deg, got both")
    if degrees is not None:
        return Fields(source).ranged(degrees, f"{where} {name}_deg", bounds, scale=math.pi / 180.0)
    if radians is not None:
        return _ranged(radians, source, f"{where} {name}", bounds)
    return None


def _check_keys(table: Mapping[str, object], allowed: tuple[str, ...], source: str, where: str) -> None:
    Fields(source).keys(table, allowed, where)


def _calibrated(table: Mapping[str, object], path: str | Path, source: str) -> tuple[CameraIntrinsics, Path]:
    """Return the intrinsics of the calibration file ``[intrinsics] calibration`` names, and its path."""
    given = [key for key in _INTRINSIC_KEYS if key in table]
    if given:
        # Two sources of the same numbers: which one the user meant is not ours to guess.
        raise FileFormatError(
            source, f"[intrinsics] {given[0]}", f"expected calibration or {', '.join(given)}, got both"
        )
    name = Fields(source).string(table["calibration"], "[intrinsics] calibration", nonempty=True)
    file = Path(name)
    if not file.is_absolute():
        file = Path(path).parent / file  # relative to the camera file, wherever it is run from
    try:
        return _read_calibration(file), file
    except FileFormatError as exc:
        raise FileFormatError(
            source,
            "[intrinsics] calibration",
            f"expected an OpenCV or ROS calibration file that reads, got: {exc}",
        ) from None


def _parse_toml(path: str | Path) -> tuple[Camera, CalibrationBounds, Path | None]:
    source = str(path)
    document = load_toml(path, kind="camera TOML")
    _check_keys(document, ("intrinsics", "mount", "calibration_bounds"), source, "")

    table = _table(document, "intrinsics", source, required=True)
    _check_keys(table, (*_INTRINSIC_KEYS, "calibration"), source, "[intrinsics]")
    if "calibration" in table:
        intrinsics, calibration = _calibrated(table, path, source)
    else:
        intrinsics, calibration = _listed(table, source), None
    mount, bounds = _mount_and_bounds(document, source, intrinsics)
    return Camera(intrinsics, mount), bounds, calibration


def _listed(table: Mapping[str, object], source: str) -> CameraIntrinsics:
    """Return the intrinsics given in ``[intrinsics]`` itself."""
    missing = [key for key in _INTRINSIC_KEYS[:6] if key not in table]
    if missing:
        raise FileFormatError(
            source, "[intrinsics]", f"expected keys {', '.join(missing)}, got none for them"
        )
    fx, fy, cx, cy = (
        _ranged(table[key], source, f"[intrinsics] {key}", KEY_RANGES["intrinsics"][key])
        for key in ("fx", "fy", "cx", "cy")
    )
    width, height = (_side(table[key], source, f"[intrinsics] {key}") for key in ("width", "height"))
    distortion = None
    if "distortion" in table:
        raw = table["distortion"]
        if not isinstance(raw, list):
            raise FileFormatError(
                source, "[intrinsics] distortion", f"expected a list of numbers, got {describe(raw)}"
            )
        numbers = [_number(v, source, f"[intrinsics] distortion[{i}]") for i, v in enumerate(raw)]
        distortion = _distortion(np.array(numbers, dtype=np.float64), source, "[intrinsics] distortion")
    try:
        return CameraIntrinsics(fx, fy, cx, cy, width, height, distortion)
    except InputError as exc:
        raise _reraise(source, "[intrinsics]", exc) from None


def _mount_and_bounds(
    document: Mapping[str, object], source: str, intrinsics: CameraIntrinsics
) -> tuple[CameraMount, CalibrationBounds]:
    table = _table(document, "mount", source, required=True)
    _check_keys(table, ("height", "forward", "left", "pan", "pan_deg", "tilt", "tilt_deg"), source, "[mount]")
    if "height" not in table:
        raise FileFormatError(source, "[mount]", "expected key height, got none for it")
    mount_values = _lengths_and_angles(
        table, ("height", "forward", "left"), source, "[mount]", KEY_RANGES["mount"]
    )
    try:
        mount = CameraMount(**mount_values)
    except InputError as exc:
        raise _reraise(source, "[mount]", exc) from None

    table = _table(document, "calibration_bounds", source, required=False)
    _check_keys(
        table,
        ("fx", "fy", "cx", "cy", "pan", "pan_deg", "tilt", "tilt_deg", "height"),
        source,
        "[calibration_bounds]",
    )
    bound_values = _lengths_and_angles(
        table,
        ("fx", "fy", "cx", "cy", "height"),
        source,
        "[calibration_bounds]",
        KEY_RANGES["calibration_bounds"],
    )
    try:
        bounds = CalibrationBounds(**bound_values)
    except InputError as exc:
        raise _reraise(source, "[calibration_bounds]", exc) from None
    for key, focal in (("fx", intrinsics.fx), ("fy", intrinsics.fy)):
        # A focal length that may be zero or negative bounds nothing: refused here, not at first use.
        if getattr(bounds, key) >= focal:
            raise FileFormatError(
                source,
                f"[calibration_bounds] {key}",
                f"expected a bound below [intrinsics] {key} ({focal!r} px), got {getattr(bounds, key)!r}",
            )
    return mount, bounds


def _lengths_and_angles(
    table: Mapping[str, object],
    keys: tuple[str, ...],
    source: str,
    where: str,
    ranges: Mapping[str, Range],
) -> dict[str, float]:
    """Read the numbers ``keys`` and the angles (pan, tilt; radians or ``*_deg``), in ``ranges``."""
    values = {key: _ranged(table[key], source, f"{where} {key}", ranges[key]) for key in keys if key in table}
    for name in _ANGLES:
        angle = _angle(table, name, source, where, ranges[name])
        if angle is not None:
            values[name] = angle
    return values


def load_camera(path: str | Path) -> Camera:
    r"""Read a camera (intrinsics and mount) from a TOML file.

    The format is in this module's documentation: ``[intrinsics]`` (fx, fy, cx, cy in
    pixels; width, height integers; optional ``distortion`` list of 4 or 5 OpenCV
    coefficients, or 8/12/14 whose extra terms are zero), or instead ``calibration``, the
    path of an OpenCV or ROS calibration file (:func:`load_opencv_calibration`) relative
    to the TOML file's folder; ``[mount]`` (height, forward, left in metres;
    ``pan``/``tilt`` in radians or ``pan_deg``/``tilt_deg`` in degrees) and the optional
    ``[calibration_bounds]`` (read by :func:`load_calibration_bounds`).

    Parameters
    ----------
    path : str or Path
        The TOML file.

    Returns
    -------
    Camera
        The camera it describes.

    Raises
    ------
    FileFormatError
        Naming the file and the table/key: missing or unreadable file, malformed TOML,
        missing or unknown keys, wrong types, non-finite or out-of-range values; both
        ``calibration`` and numbers in ``[intrinsics]``; and, naming both files, a
        calibration file that is missing or does not read.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "cam.toml").write_text(
    ...     "[intrinsics]\nfx = 500\nfy = 500\ncx = 320\ncy = 240\nwidth = 640\nheight = 480\n"
    ...     "[mount]\nheight = 1.0\ntilt_deg = 10\n"
    ... )
    >>> round(load_camera(folder / "cam.toml").mount.tilt, 6)
    0.174533
    >>> _ = (folder / "bad.toml").write_text("[intrinsics]\nfx = 500\n")
    >>> load_camera(folder / "bad.toml")
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: ...bad.toml: [intrinsics]: expected keys fy, cx, cy, width, height, ...
    """
    return _parse_toml(path)[0]


def load_calibration_bounds(path: str | Path) -> CalibrationBounds:
    r"""Read the ``[calibration_bounds]`` table of a TOML camera file (all zero when absent).

    Keys: ``fx``, ``fy``, ``cx``, ``cy`` (pixels), ``pan``/``tilt`` (radians) or
    ``pan_deg``/``tilt_deg`` (degrees), ``height`` (metres); each optional, default 0.
    The whole file is validated as by :func:`load_camera`.

    Parameters
    ----------
    path : str or Path
        The TOML file.

    Returns
    -------
    CalibrationBounds
        The bounds on the calibration.

    Raises
    ------
    FileFormatError
        As :func:`load_camera`.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> text = camera_to_toml(Camera(CameraIntrinsics(500, 500, 320, 240, 640, 480), CameraMount(1.0)))
    >>> _ = (folder / "cam.toml").write_text(text + "[calibration_bounds]\nfx = 3.0\npan_deg = 0.5\n")
    >>> bounds = load_calibration_bounds(folder / "cam.toml")
    >>> bounds.fx, round(bounds.pan, 6), bounds.tilt   # degrees read as radians; absent keys are 0
    (3.0, 0.008727, 0.0)
    >>> _ = (folder / "plain.toml").write_text(text)
    >>> load_calibration_bounds(folder / "plain.toml") == CalibrationBounds()   # no table: all zero
    True
    >>> _ = (folder / "bad.toml").write_text(text + "[calibration_bounds]\nfx = -1.0\n")
    >>> load_calibration_bounds(folder / "bad.toml")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: ...bad.toml: [calibration_bounds] fx: expected a number in ..., got -1.0
    """
    return _parse_toml(path)[1]


def camera_calibration_file(path: str | Path) -> Path | None:
    r"""Return the calibration file a camera TOML file names (``[intrinsics] calibration``).

    Resolved against the TOML file's folder when relative. For a command's list of the
    files it reads, which a camera file naming a calibration extends by one. The whole
    file is validated as by :func:`load_camera`, the calibration file read too.

    Parameters
    ----------
    path : str or Path
        The TOML file.

    Returns
    -------
    Path or None
        The calibration file; None when ``[intrinsics]`` gives the numbers itself.

    Raises
    ------
    FileFormatError
        As :func:`load_camera`.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "ost.yaml").write_text(   # a ROS calibration
    ...     "image_width: 640\nimage_height: 480\n"
    ...     "camera_matrix:\n  rows: 3\n  cols: 3\n  data: [500, 0, 320, 0, 500, 240, 0, 0, 1]\n"
    ...     "distortion_model: plumb_bob\n"
    ...     "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [0, 0, 0, 0, 0]\n")
    >>> _ = (folder / "cam.toml").write_text(
    ...     '[intrinsics]\ncalibration = "ost.yaml"\n[mount]\nheight = 1.0\n')
    >>> camera_calibration_file(folder / "cam.toml") == folder / "ost.yaml"
    True
    >>> load_camera(folder / "cam.toml").intrinsics.fx
    500.0
    >>> _ = (folder / "plain.toml").write_text(camera_to_toml(load_camera(folder / "cam.toml")))
    >>> camera_calibration_file(folder / "plain.toml") is None   # the numbers are in the file
    True
    """
    return _parse_toml(path)[2]


def camera_to_toml(camera: Camera, bounds: CalibrationBounds | None = None) -> str:
    """Return TOML text that :func:`load_camera` and :func:`load_calibration_bounds` read back exactly.

    Parameters
    ----------
    camera : Camera
        The camera to write.
    bounds : CalibrationBounds, optional
        Written as ``[calibration_bounds]`` when given.

    Returns
    -------
    str
        The TOML document (angles in radians).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> camera = Camera(CameraIntrinsics(500, 500, 320, 240, 640, 480), CameraMount(1.0, tilt=0.1))
    >>> text = camera_to_toml(camera, CalibrationBounds(fx=3.0))
    >>> print(text.split("[mount]")[1].split("[calibration_bounds]")[0].strip())
    height = 1.0
    forward = 0.0
    left = 0.0
    pan = 0.0
    tilt = 0.1
    >>> file = pathlib.Path(tempfile.mkdtemp()) / "cam.toml"
    >>> _ = file.write_text(text)
    >>> load_camera(file) == camera, load_calibration_bounds(file).fx   # read back exactly
    (True, 3.0)
    >>> camera_to_toml(camera.mount)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: camera: expected Camera, got CameraMount
    """
    if not isinstance(camera, Camera):
        raise InputError(f"camera: expected Camera, got {type(camera).__name__}")
    k, m = camera.intrinsics, camera.mount
    lines = ["[intrinsics]"]
    lines += [f"{name} = {getattr(k, name)!r}" for name in ("fx", "fy", "cx", "cy", "width", "height")]
    if k.distortion is not None:
        lines.append(f"distortion = [{', '.join(repr(c) for c in k.distortion)}]")
    lines += ["", "[mount]"]
    lines += [f"{name} = {getattr(m, name)!r}" for name in ("height", "forward", "left", "pan", "tilt")]
    if bounds is not None:
        if not isinstance(bounds, CalibrationBounds):
            raise InputError(f"bounds: expected CalibrationBounds, got {type(bounds).__name__}")
        lines += ["", "[calibration_bounds]"]
        lines += [f"{name} = {getattr(bounds, name)!r}" for name in CalibrationBounds.field_names()]
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------- FileStorage YAML subset


class _Matrix(dict[str, object]):
    """A mapping tagged ``!!opencv-matrix`` in YAML."""


_INT = re.compile(r"[-+]?(0|[1-9][0-9]*)")
_FLOAT = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")
_SPECIAL = {".inf": math.inf, "+.inf": math.inf, "-.inf": -math.inf, ".nan": math.nan}


def _scalar(text: str) -> object:
    """Convert a plain YAML scalar to int, float (OpenCV writes ``1.``, ``.Inf``, ``.Nan``) or string."""
    if _INT.fullmatch(text):
        try:
            return int(text)
        except ValueError:  # past Python's 4300-digit limit: a float, inf as "1e400" reads
            return float(text)
    if _FLOAT.fullmatch(text):
        return float(text)
    return _SPECIAL.get(text.lower(), text)


class _Flow:
    """Recursive-descent reader of one flow value (``[...]``, ``{...}``, quoted or plain scalar)."""

    def __init__(self, text: str, fail: Callable[[str], FileFormatError]) -> None:
        self.text, self.pos, self.fail = text, 0, fail

    def _skip(self) -> None:
        while self.pos < len(self.text) and self.text[self.pos].isspace():
            self.pos += 1

    def _peek(self) -> str:
        self._skip()
        return self.text[self.pos] if self.pos < len(self.text) else ""

    def value(self, stops: str) -> object:
        char = self._peek()
        if char == "[":
            return self._sequence()
        if char == "{":
            return self._mapping()
        if char and char in "\"'":  # "" (the end) is in every string
            return self._quoted()
        start = self.pos
        while self.pos < len(self.text) and self.text[self.pos] not in stops:
            self.pos += 1
        plain = self.text[start : self.pos].strip()
        if not plain:
            raise self.fail(f"expected a value, got {describe(self.text[start : start + 20])}")
        return _scalar(plain)

    def _quoted(self) -> str:
        quote = self.text[self.pos]
        self.pos += 1
        out: list[str] = []
        while self.pos < len(self.text):
            char = self.text[self.pos]
            self.pos += 1
            if char == quote:
                if quote == "'" and self.text[self.pos : self.pos + 1] == "'":
                    out.append("'")
                    self.pos += 1
                    continue
                return "".join(out)
            if char == "\\" and quote == '"' and self.pos < len(self.text):
                escaped = self.text[self.pos]
                self.pos += 1
                out.append({"n": "\n", "t": "\t", '"': '"', "\\": "\\"}.get(escaped, escaped))
                continue
            out.append(char)
        raise self.fail(f"expected a closing {quote}, got the end of the value")

    def _sequence(self) -> list[object]:
        self.pos += 1
        items: list[object] = []
        if self._peek() == "]":
            self.pos += 1
            return items
        while True:
            items.append(self.value(",]"))
            char = self._peek()
            self.pos += 1
            if char == "]":
                return items
            if char != ",":
                raise self.fail(f"expected ',' or ']' in a list, got {char or 'the end of the value'!r}")

    def _mapping(self) -> dict[str, object]:
        self.pos += 1
        items: dict[str, object] = {}
        if self._peek() == "}":
            self.pos += 1
            return items
        while True:
            key = self._quoted() if self._peek() in ('"', "'") else str(self.value(":,}"))
            if self._peek() != ":":
                raise self.fail(f"expected ':' after the key {key!r}, got {self._peek() or 'the end'!r}")
            self.pos += 1
            items[key] = self.value(",}")
            char = self._peek()
            self.pos += 1
            if char == "}":
                return items
            if char != ",":
                raise self.fail(f"expected ',' or '}}' in a mapping, got {char or 'the end of the value'!r}")

    def finish(self) -> None:
        if self._peek():
            raise self.fail(f"expected the end of the value, got {describe(self.text[self.pos :])}")


def _strip_comment(line: str) -> str:
    quote = ""
    for i, char in enumerate(line):
        if quote:
            if char == quote:
                quote = ""
        elif char in "\"'":
            quote = char
        elif char == "#" and (i == 0 or line[i - 1].isspace()):
            return line[:i].rstrip()
    return line.rstrip()


def _balance(text: str, depth: int = 0, quote: str = "") -> tuple[int, str]:
    """Bracket depth and open quote after ``text``, from those before it (so lines add up)."""
    for char in text:
        if quote:
            if char == quote:
                quote = ""
        elif char in "\"'":
            quote = char
        elif char in "[{":
            depth += 1
        elif char in "]}":
            depth -= 1
    return depth, quote


class _YamlReader:
    """Block structure of a FileStorage YAML document: (line number, indent, text) items."""

    def __init__(self, text: str, source: str, *, header: bool = True) -> None:
        self.source = source
        raw = text.splitlines()
        i = 0
        if header:  # FileStorage's own files; a ROS calibration has none
            first = next((i for i, line in enumerate(raw) if line.strip()), None)
            if first is None or not re.match(r"%YAML[: ]1\.\d", raw[first].strip()):
                raise _no_header(source, raw, first)
            i = first + 1
        self.lines: list[tuple[int, int, str]] = []
        while i < len(raw):
            number, content = i + 1, _strip_comment(raw[i])
            i += 1
            if not content.strip() or content.strip() in ("---", "..."):
                continue
            if "\t" in content[: len(content) - len(content.lstrip())]:
                raise FileFormatError(source, "", "expected spaces for indentation, got a tab", line=number)
            depth, quote = _balance(content)
            parts = [content]
            while depth > 0 and i < len(raw):  # a flow collection over several lines
                parts.append(" " + _strip_comment(raw[i]).strip())
                depth, quote = _balance(parts[-1], depth, quote)
                i += 1
            content = "".join(parts)
            if depth != 0:
                raise FileFormatError(
                    source, "", "expected balanced brackets, got unbalanced ones", line=number
                )
            self.lines.append((number, len(content) - len(content.lstrip()), content.strip()))
        self.pos = 0

    def fail(self, number: int, message: str) -> FileFormatError:
        return FileFormatError(self.source, "", message, line=number)

    def flow(self, text: str, number: int) -> object:
        reader = _Flow(text, lambda message: self.fail(number, message))
        if text[0] in "[{\"'":
            value = reader.value("")
            reader.finish()
            return value
        return _scalar(text)

    def block(self, indent: int) -> object:
        text = self.lines[self.pos][2]
        if text == "-" or text.startswith("- "):
            return self._sequence(indent)
        return self._mapping(indent)

    def _nested(self, indent: int, number: int) -> object:
        if self.pos < len(self.lines):
            _, next_indent, text = self.lines[self.pos]
            is_item = text == "-" or text.startswith("- ")
            if next_indent > indent or (next_indent == indent and is_item and indent >= 0):
                return self.block(next_indent)
        return None

    def _sequence(self, indent: int) -> list[object]:
        items: list[object] = []
        while self.pos < len(self.lines):
            number, current, text = self.lines[self.pos]
            if current != indent or not (text == "-" or text.startswith("- ")):
                break
            self.pos += 1
            rest = text[1:].strip()
            items.append(self.flow(rest, number) if rest else self._nested(indent, number))
        return items

    def _mapping(self, indent: int) -> dict[str, object]:
        items: dict[str, object] = {}
        while self.pos < len(self.lines):
            number, current, text = self.lines[self.pos]
            if current < indent:
                break
            if current > indent:
                raise self.fail(number, f"expected indentation {indent}, got {current}")
            if text == "-" or text.startswith("- "):
                break
            match = re.match(r"""("[^"]*"|'[^']*'|[^:\s][^:]*?)\s*:(\s+|$)""", text)
            if match is None:
                raise self.fail(number, f"expected 'key: value', got {describe(text)}")
            key = match.group(1).strip("\"'")
            rest = text[match.end() :].strip()
            self.pos += 1
            tag = ""
            if rest.startswith("!!"):
                tag, _, rest = rest.partition(" ")
                rest = rest.strip()
            value = self.flow(rest, number) if rest else self._nested(indent, number)
            if tag == "!!opencv-matrix":
                if not isinstance(value, dict):
                    raise self.fail(
                        number, f"expected a mapping under !!opencv-matrix, got {describe(value)}"
                    )
                value = _Matrix(value, type_id="opencv-matrix")
            if key in items:
                raise self.fail(number, f"expected the key {describe(key)} once, got it twice")
            items[key] = value
        return items


def _no_header(source: str, raw: list[str], first: int | None) -> FileFormatError:
    found = describe(raw[first].strip()) if first is not None else "an empty file"
    return FileFormatError(
        source,
        "",
        f"expected the '%YAML:1.0' header of an OpenCV FileStorage file, or a ROS calibration "
        f"(camera_matrix: rows, cols, data), got {found}",
        line=1 if first is None else first + 1,
    )


def _parse_yaml(text: str, source: str, *, header: bool = True) -> dict[str, object]:
    reader = _YamlReader(text, source, header=header)
    if not reader.lines:
        return {}
    try:
        document = reader.block(reader.lines[0][1])
    except RecursionError:
        raise FileFormatError(source, "", "expected YAML, got collections nested too deep") from None
    if reader.pos < len(reader.lines):
        number, _, found = reader.lines[reader.pos]
        raise reader.fail(number, f"expected a top-level 'key: value', got {describe(found)}")
    if not isinstance(document, dict):
        raise FileFormatError(source, "", f"expected a top-level mapping, got {type(document).__name__}")
    return document


def _parse_json(text: str, source: str) -> dict[str, object]:
    try:
        document = parse_json(text, source)
    except FileFormatError as first:
        # OpenCV before 4.x writes reals such as ``1.`` that strict JSON refuses: try once more
        tolerant = re.sub(r"(?<=\d)\.(?=\s*[,\]}\s])", ".0", text)
        if tolerant == text:
            raise
        try:
            document = parse_json(tolerant, source)
        except FileFormatError:
            raise first from None
    return Fields(source, "json").table(document, "")


# --------------------------------------------------------------- FileStorage contents


def _normalized(name: str) -> str:
    return name.replace("_", "").lower()


#: Spelling in messages, and accepted spellings (lower case, no underscores), of each key.
_NAMES = {
    "camera_matrix": ("cameramatrix", "k"),
    "distortion_coefficients": ("distortioncoefficients", "distcoeffs", "distortion", "d"),
    "image_width": ("imagewidth",),
    "image_height": ("imageheight",),
}


def _find(document: Mapping[str, object], label: str, source: str) -> tuple[str, object]:
    names = _NAMES[label]
    found = [(key, value) for key, value in document.items() if _normalized(key) in names]
    if not found:
        raise FileFormatError(source, label, f"expected the key {label}, got no such key")
    if len(found) > 1:
        keys = ", ".join(key for key, _ in found)
        raise FileFormatError(source, found[1][0], f"expected one {label}, got {keys}")
    return found[0]


def _matrix(value: object, source: str, key: str, *, opencv: bool = True, empty: bool = False) -> Array:
    """Return a matrix mapping's ``data`` as rows x cols.

    With ``opencv`` FileStorage's ``opencv-matrix`` (``type_id`` and ``dt`` too), else ROS's
    mapping (rows, cols and data alone). With ``empty``, ``cols`` may be 0 (ROS writes an
    empty distortion vector as ``rows: 1, cols: 0, data: []``).
    """
    kind = "an opencv-matrix" if opencv else "a matrix"
    if not isinstance(value, dict):
        raise FileFormatError(source, key, f"expected {kind} mapping, got {describe(value)}")
    if opencv and value.get("type_id") != "opencv-matrix":
        raise FileFormatError(
            source, key, f"expected type_id opencv-matrix, got {describe(value.get('type_id'))}"
        )
    for field in ("rows", "cols", "dt", "data") if opencv else ("rows", "cols", "data"):
        if field not in value:
            raise FileFormatError(source, f"{key}.{field}", f"expected this field of {kind}, got none")
    rows = _integer(value["rows"], source, f"{key}.rows")
    cols = Fields(source).integer(value["cols"], f"{key}.cols", minimum=0 if empty else 1)
    if opencv:
        dt = value["dt"]
        if not isinstance(dt, str) or not re.fullmatch(r"[ucswifd]", dt):
            raise FileFormatError(
                source, f"{key}.dt", f"expected a one-channel element type (d, f, i...), got {describe(dt)}"
            )
    data = value["data"]
    if not isinstance(data, list):
        raise FileFormatError(source, f"{key}.data", f"expected a list of numbers, got {describe(data)}")
    if len(data) != rows * cols:
        raise FileFormatError(
            source, f"{key}.data", f"expected rows x cols = {rows * cols} numbers, got {len(data)}"
        )
    numbers = [_number(v, source, f"{key}.data[{i}]") for i, v in enumerate(data)]
    return np.array(numbers, dtype=np.float64).reshape(rows, cols)


def _camera_matrix(k: Array, source: str, key: str) -> Array:
    """Check a camera matrix's shape and form: ``[[fx, 0, cx], [0, fy, cy], [0, 0, 1]]``."""
    if k.shape != (3, 3):
        raise FileFormatError(source, key, f"expected a 3x3 matrix, got {k.shape[0]}x{k.shape[1]}")
    if k[1, 0] != 0.0 or k[2, 0] != 0.0 or k[2, 1] != 0.0 or k[2, 2] != 1.0:
        raise FileFormatError(
            source, key, f"expected [[fx, 0, cx], [0, fy, cy], [0, 0, 1]], got {k.tolist()}"
        )
    if k[0, 1] != 0.0:
        raise FileFormatError(source, key, f"expected zero skew (element [0][1]), got {k[0, 1]}")
    return k


def _vector(d: Array, source: str, key: str) -> Array:
    """Return a distortion matrix's coefficients: it must be one row or one column."""
    if 1 not in d.shape:
        raise FileFormatError(source, key, f"expected a 1xN or Nx1 matrix, got {d.shape[0]}x{d.shape[1]}")
    return d.ravel()


def _intrinsics(
    k: Array,
    key: str,
    distortion: tuple[float, float, float, float, float],
    size: tuple[int, int],
    source: str,
) -> CameraIntrinsics:
    """Return the intrinsics of a checked camera matrix (:func:`_camera_matrix`), in :data:`KEY_RANGES`."""
    for name, (row, col) in (("fx", (0, 0)), ("fy", (1, 1)), ("cx", (0, 2)), ("cy", (1, 2))):
        bounds = KEY_RANGES["intrinsics"][name]
        if not bounds.contains(float(k[row, col])):
            raise FileFormatError(
                source, f"{key} {name}", f"expected {bounds.text()}, got {float(k[row, col])!r}"
            )
    try:
        return CameraIntrinsics(k[0, 0], k[1, 1], k[0, 2], k[1, 2], size[0], size[1], distortion)
    except InputError as exc:
        raise _reraise(source, key, exc) from None


def _intrinsics_from_filestorage(document: Mapping[str, object], source: str) -> CameraIntrinsics:
    key, value = _find(document, "camera_matrix", source)
    k = _camera_matrix(_matrix(value, source, key), source, key)
    dkey, dvalue = _find(document, "distortion_coefficients", source)
    distortion = _distortion(_vector(_matrix(dvalue, source, dkey), source, dkey), source, dkey)
    wkey, width = _find(document, "image_width", source)
    hkey, height = _find(document, "image_height", source)
    size = (_side(width, source, wkey), _side(height, source, hkey))
    return _intrinsics(k, key, distortion, size, source)


# ----------------------------------------------------------------- ROS calibration YAML

#: The distortion models of ROS's ``sensor_msgs/CameraInfo`` that aura-ums models, each with
#: the numbers of coefficients it takes (plumb_bob is OpenCV's k1, k2, p1, p2, k3;
#: rational_polynomial adds k4-k6, which :func:`opencv_distortion` requires to be zero).
_ROS_MODELS: dict[str, tuple[tuple[int, ...], str]] = {
    "plumb_bob": ((4, 5), "4 or 5 (k1, k2, p1, p2[, k3])"),
    "rational_polynomial": ((8,), "8 (k1, k2, p1, p2, k3, k4, k5, k6)"),
}
#: Keys only a ROS calibration has (camera_calibration_parsers writes them all).
_ROS_ONLY = ("camera_name", "distortion_model", "rectification_matrix", "projection_matrix")
_ROS_SIZE = ("image_width", "image_height")
#: The first line of a header-less YAML document: ``key:``.
_KEY_LINE = re.compile(r"[A-Za-z_][\w-]*\s*:(\s|$)")


def _is_ros(document: Mapping[str, object]) -> bool:
    """Whether a header-less YAML document is a ROS calibration: no ``!!opencv-matrix``, ROS's keys."""
    if any(isinstance(value, _Matrix) for value in document.values()):
        return False  # a FileStorage file that lost its header
    return any(key in document for key in ("camera_matrix", *_ROS_ONLY))


def _ros_key(document: Mapping[str, object], key: str, source: str) -> object:
    # ROS's reader matches its keys exactly (FileStorage's spellings are not ROS's).
    if key not in document:
        raise FileFormatError(source, key, f"expected the key {key}, got no such key")
    return document[key]


def _intrinsics_from_ros(document: Mapping[str, object], source: str) -> CameraIntrinsics:
    """Return the intrinsics of a ROS calibration (camera_calibration_parsers' YAML: CameraInfo's fields)."""
    k = _matrix(_ros_key(document, "camera_matrix", source), source, "camera_matrix", opencv=False)
    # ROS's own reader takes a file without distortion_model (older ones) as plumb_bob.
    model = document.get("distortion_model", "plumb_bob")
    dkey = "distortion_coefficients"
    d = _vector(
        _matrix(_ros_key(document, dkey, source), source, dkey, opencv=False, empty=True), source, dkey
    )
    rkey = "rectification_matrix"
    # Absent: none, as ROS's writer takes a missing one for the identity.
    r = _matrix(document[rkey], source, rkey, opencv=False) if rkey in document else None
    width, height = (_ros_key(document, name, source) for name in _ROS_SIZE)
    return _ros_intrinsics(k, model, d, r, (width, height), source, _ROS_FILE_NAMES)


#: How the messages of a ROS calibration file name its parts: by their keys.
_ROS_FILE_NAMES = {
    "k": "camera_matrix",
    "model": "distortion_model",
    "d": "distortion_coefficients",
    "r": "rectification_matrix",
    "width": "image_width",
    "height": "image_height",
}


def _ros_model(model: object, source: str, where: str) -> str:
    """Return a ``distortion_model`` aura-ums models (:data:`_ROS_MODELS`), or refuse it."""
    if not isinstance(model, str) or model not in _ROS_MODELS:
        raise FileFormatError(
            source, where, f"expected distortion_model {' or '.join(_ROS_MODELS)}, got {describe(model)}"
        )
    return model


def _ros_intrinsics(
    k: Array,
    model: object,
    d: Array,
    r: Array | None,
    size: tuple[object, object],
    source: str,
    names: Mapping[str, str],
) -> CameraIntrinsics:
    """Return the intrinsics of a ROS calibration's parts (a file's, a CameraInfo message's).

    ``names`` says how messages name each part (:data:`_ROS_FILE_NAMES`' keys).
    """
    _camera_matrix(k, source, names["k"])
    model = _ros_model(model, source, names["model"])
    counts, expected = _ROS_MODELS[model]
    if d.size and d.size not in counts:
        raise FileFormatError(
            source,
            names["d"],
            f"expected {expected} coefficients (or none: no distortion) for distortion_model {model}, "
            f"got {d.size}",
        )
    # ROS (image_geometry) takes an empty distortion vector for no distortion, as a driver of a
    # rectified or simulated camera publishes it and camera_calibration_parsers writes it.
    distortion = _distortion(d, source, names["d"]) if d.size else (0.0, 0.0, 0.0, 0.0, 0.0)
    # A stereo pair's rectification turns the camera: its pixels are no longer those of K and D
    # on the raw image, which is what aura-ums models. A monocular calibration writes the identity.
    if r is not None and (r.shape != (3, 3) or not np.array_equal(r, np.eye(3))):
        raise FileFormatError(
            source,
            names["r"],
            f"expected the identity (a monocular camera: aura-ums models no rectification), got {r.tolist()}",
        )
    width, height = (
        _side(value, source, names[name]) for value, name in zip(size, ("width", "height"), strict=True)
    )
    return _intrinsics(k, names["k"], distortion, (width, height), source)


def camera_info_intrinsics(message: object, source: str, where: str) -> CameraIntrinsics:
    """Return the intrinsics of a ROS ``sensor_msgs/CameraInfo`` message, checked as a ROS calibration file.

    Reads ``width``, ``height``, ``distortion_model``, ``d``, ``k`` and ``r`` (ROS 1's
    ``D``, ``K``, ``R`` too) as :func:`load_opencv_calibration` reads a ROS calibration
    file's keys: the same models, the same identity rectification. The image must be the
    full, unbinned one the calibration describes (``binning_x``, ``binning_y`` 0 or 1; an
    empty or full ``roi``). For readers of ROS messages (:func:`aura_ums.logs.read_camera_info`).

    Parameters
    ----------
    message : object
        The message, as deserialized (any object with those attributes).
    source : str
        Where it was read (a bag), for messages.
    where : str
        The message's place in it (a topic and index), for messages.

    Returns
    -------
    CameraIntrinsics
        The calibrated intrinsics.

    Raises
    ------
    FileFormatError
        Naming ``source``, ``where`` and the field, as for a calibration file.

    Examples
    --------
    >>> from types import SimpleNamespace as Message
    >>> info = Message(width=640, height=480, distortion_model="plumb_bob", d=[-0.1, 0.01, 0, 0, 0],
    ...                k=[554.25, 0, 320.5, 0, 554.25, 240.5, 0, 0, 1], r=[1, 0, 0, 0, 1, 0, 0, 0, 1])
    >>> camera_info_intrinsics(info, "run.bag", "topic /camera_info, message 0").fx
    554.25
    >>> info.k = [0.0] * 9    # an uncalibrated camera's
    >>> camera_info_intrinsics(info, "run.bag", "topic /camera_info, message 0")
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: run.bag: topic /camera_info, message 0, k: expected [[fx, 0, cx], ...
    """
    fields = Fields(source)

    def field(name: str) -> object:
        for spelling in (name, name.upper()):  # ROS 2's d, k, r; ROS 1's D, K, R
            if hasattr(message, spelling):
                return getattr(message, spelling)
        raise FileFormatError(source, where, f"expected a CameraInfo with the field {name}, got none")

    def numbers(name: str) -> Array:
        values = field(name)
        # rosbags gives arrays as numpy arrays (a float64[9] of ROS 2, a float64[] of either).
        if isinstance(values, np.ndarray):
            values = values.tolist()
        if not isinstance(values, (list, tuple)):
            raise FileFormatError(
                source, f"{where}, {name}", f"expected an array of numbers, got {describe(values)}"
            )
        items = [fields.number(value, f"{where}, {name}[{i}]") for i, value in enumerate(values)]
        return np.array(items, dtype=np.float64)

    k = numbers("k")
    if k.size != 9:
        raise FileFormatError(source, f"{where}, k", f"expected 9 numbers (a 3x3 matrix), got {k.size}")
    r = numbers("r")
    if r.size != 9:
        raise FileFormatError(source, f"{where}, r", f"expected 9 numbers (a 3x3 matrix), got {r.size}")
    for name in ("binning_x", "binning_y"):
        binning = getattr(message, name, 0)
        if binning not in (0, 1):
            raise FileFormatError(
                source, f"{where}, {name}", f"expected 0 or 1 (an unbinned image), got {describe(binning)}"
            )
    size = (field("width"), field("height"))
    _full_image(getattr(message, "roi", None), size, source, f"{where}, roi")
    names = {
        key: f"{where}, {name}"
        for key, name in (
            ("k", "k"),
            ("model", "distortion_model"),
            ("d", "d"),
            ("r", "r"),
            ("width", "width"),
            ("height", "height"),
        )
    }
    return _ros_intrinsics(
        k.reshape(3, 3), field("distortion_model"), numbers("d"), r.reshape(3, 3), size, source, names
    )


def _full_image(roi: object, size: tuple[object, object], source: str, where: str) -> None:
    """Refuse a region of interest other than none (all zero) or the whole image: K is the full image's."""
    if roi is None:
        return
    offset = (getattr(roi, "x_offset", 0), getattr(roi, "y_offset", 0))
    extent = (getattr(roi, "width", 0), getattr(roi, "height", 0))
    if offset == (0, 0) and (extent == (0, 0) or extent == size):
        return
    raise FileFormatError(
        source,
        where,
        f"expected no region of interest (the full image the calibration describes), got x_offset "
        f"{offset[0]!r}, y_offset {offset[1]!r}, width {extent[0]!r}, height {extent[1]!r}",
    )


def _read_calibration(path: str | Path) -> CameraIntrinsics:
    """Return the intrinsics of an OpenCV (YAML, JSON) or ROS calibration file, told by its content."""
    source = str(path)
    text = read_text(path, kind="calibration")
    start, suffix = text.lstrip(), Path(path).suffix.lower()
    if start.startswith("%YAML"):
        return _intrinsics_from_filestorage(_parse_yaml(text, source), source)
    if start.startswith("{") or suffix == ".json":
        return _intrinsics_from_filestorage(_parse_json(text, source), source)
    raw = text.splitlines()
    first = next((i for i, line in enumerate(raw) if line.strip()), None)
    content = next((line for line in raw if line.strip() and not line.lstrip().startswith("#")), "")
    if suffix in (".yml", ".yaml") or _KEY_LINE.match(content):
        document = _parse_yaml(text, source, header=False)
        if not _is_ros(document):
            raise _no_header(source, raw, first)
        return _intrinsics_from_ros(document, source)
    found = describe(start.splitlines()[0][:40]) if start else "an empty file"
    raise FileFormatError(
        source,
        "",
        f"expected a FileStorage YAML ('%YAML:1.0') or JSON ('{{') file, or a ROS calibration YAML, "
        f"got {found}",
        line=1,
    )


def load_opencv_calibration(path: str | Path, mount: CameraMount) -> Camera:
    r"""Read an OpenCV or ROS camera calibration and put it on a mount.

    An OpenCV ``cv::FileStorage`` calibration (YAML or JSON): ``camera_matrix`` (an
    ``opencv-matrix``: rows, cols, dt, data; zero skew), ``distortion_coefficients`` (4 or
    5 coefficients, or 8/12/14 whose terms beyond k3 are zero), ``image_width`` and
    ``image_height``. Key names are matched ignoring case and underscores, and OpenCV's
    other spellings are accepted (``cameraMatrix``, ``Camera_Matrix``, ``distCoeffs``,
    ``Distortion_Coefficients``); other keys are ignored.

    A ROS calibration (camera_calibration_parsers' YAML: a camera_info_manager file, the
    calibrator's ``ost.yaml``): the same four keys, exactly so spelled, with matrices as
    plain ``{rows, cols, data}`` mappings; ``distortion_model`` ``plumb_bob`` (4 or 5
    coefficients, OpenCV's k1, k2, p1, p2, k3; the model taken when the key is absent, as
    ROS does) or ``rational_polynomial`` (8, whose k4-k6 are zero); any other model
    (``equidistant``...) is refused. ``rectification_matrix``, when given, must be the
    identity (a monocular calibration's): a stereo camera's rectified pixels are not
    those of the raw image this camera model describes. ``projection_matrix`` (the
    rectified image's) and ``camera_name`` are ignored.

    The format is told by the content: a ``%YAML`` header (FileStorage), a JSON object
    (FileStorage), or YAML without a header holding ROS's keys and no ``!!opencv-matrix``.

    Parameters
    ----------
    path : str or Path
        The calibration file.
    mount : CameraMount
        Where the camera sits on the robot (a calibration file does not say).

    Returns
    -------
    Camera
        The calibrated camera.

    Raises
    ------
    FileFormatError
        Naming the file and the line or key: missing file, malformed YAML/JSON, missing
        keys, wrong matrix shapes, non-finite values, unsupported distortion terms or
        models, a rectification.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> file = pathlib.Path(tempfile.mkdtemp()) / "calib.json"
    >>> _ = file.write_text('{"image_width": 640, "image_height": 480, '
    ...     '"camera_matrix": {"type_id": "opencv-matrix", "rows": 3, "cols": 3, "dt": "d", '
    ...     '"data": [674.9, 0.0, 307.55, 0.0, 674.9, 251.45, 0.0, 0.0, 1.0]}, '
    ...     '"distortion_coefficients": {"type_id": "opencv-matrix", "rows": 1, "cols": 4, "dt": "d", '
    ...     '"data": [0.0, 0.0, 0.0, 0.0]}}')
    >>> load_opencv_calibration(file, CameraMount(1.0)).intrinsics.distortion  # 4 given: k3 = 0
    (0.0, 0.0, 0.0, 0.0, 0.0)
    >>> ros = file.with_name("ost.yaml")   # as ROS's camera_calibration_parsers write it
    >>> _ = ros.write_text("image_width: 640\nimage_height: 480\ncamera_name: narrow_stereo\n"
    ...     "camera_matrix:\n  rows: 3\n  cols: 3\n  data: [554.25, 0, 320.5, 0, 554.25, 240.5, 0, 0, 1]\n"
    ...     "distortion_model: plumb_bob\n"
    ...     "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [-0.1, 0.01, 0, 0, 0]\n")
    >>> load_opencv_calibration(ros, CameraMount(1.0)).intrinsics.fx
    554.25
    >>> _ = ros.write_text(ros.read_text().replace("plumb_bob", "equidistant"))
    >>> load_opencv_calibration(ros, CameraMount(1.0))
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: ...ost.yaml: distortion_model: expected ..., got 'equidistant'
    >>> load_opencv_calibration(file.with_name("missing.yml"), CameraMount(1.0))
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: ...missing.yml: expected an existing calibration file, got no such file
    """
    if not isinstance(mount, CameraMount):
        raise InputError(f"mount: expected CameraMount, got {type(mount).__name__}")
    return Camera(_read_calibration(path), mount)
