"""The log folder format: round trips, units, and every kind of bad log."""

from __future__ import annotations

import itertools
import math
import re
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from aura_ums._files import MAX_BYTES
from aura_ums._validate import ANGLE_ERROR, ANGULAR_SPEED, COORDINATE, DELAY, ROW_GAP, SPEED, TIME, Range
from aura_ums.errors import FileFormatError, InputError
from aura_ums.logs import (
    LogLandmark,
    LogMeta,
    LogObservation,
    ObservationKind,
    Odometry,
    RobotLog,
    load_log,
    write_log,
)
from aura_ums.logs import _io as log_io
from aura_ums.manager import PositionReport
from aura_ums.uncertainty import FOOT, TurnAndRun
from tests.logs.log_helpers import VALID_FILES, assert_same_log, small_log, write_files

# --- round trips ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("commands", "groundtruth", "start"),
    [(False, True, True), (True, False, False), (True, True, False), (False, False, True)],
)
def test_write_then_load_gives_the_same_log(
    tmp_path: Path, commands: bool, groundtruth: bool, start: bool
) -> None:
    log = small_log(commands=commands, groundtruth=groundtruth, start=start)
    folder = write_log(log, tmp_path / "log")
    loaded = load_log(folder)
    assert_same_log(loaded, log)
    assert loaded.path == folder
    assert (folder / "groundtruth.csv").exists() == groundtruth
    # Written observations are numbered by their line in observations.csv.
    lines = (folder / "observations.csv").read_text().splitlines()
    for observation in loaded.observations:
        assert lines[observation.line - 1].startswith(repr(observation.time) + ",")


def within(bounds: Range) -> st.SearchStrategy[float]:
    """Any float in a reader's physical range (the values a written log may hold)."""
    return st.floats(
        min_value=bounds.low,
        max_value=bounds.high,
        exclude_min=bounds.low_open,
        exclude_max=bounds.high_open,
        allow_nan=False,
        allow_subnormal=bounds.low <= 0.0,
    )


positive = st.floats(min_value=1e-300, max_value=1e3, allow_nan=False)


@st.composite
def random_logs(draw: st.DrawFn) -> RobotLog:
    ids = draw(
        st.lists(
            st.text(min_size=1, max_size=5).filter(lambda text: text.isprintable() and text == text.strip()),
            min_size=1,
            max_size=4,
            unique=True,
        )
    )
    landmarks = tuple(
        LogLandmark(ident, draw(within(COORDINATE)), draw(within(COORDINATE)), draw(positive))
        for ident in ids
    )
    # Observations at most a day apart too (half a day: rounding the sums keeps them within).
    steps = draw(st.lists(st.floats(0.0, ROW_GAP.high / 2.0), min_size=0, max_size=5))
    first = draw(st.floats(TIME.low, TIME.high - 6.0 * ROW_GAP.high))
    times = list(itertools.accumulate(steps, initial=first))[: draw(st.integers(0, 6))]
    observations = tuple(
        LogObservation(
            time,
            draw(st.sampled_from(ids)),
            draw(st.floats(-math.pi, math.pi, exclude_min=True)),
            range=draw(st.none() | positive),
            bearing_error=draw(st.none() | within(ANGLE_ERROR)),
        )
        for time in times
    )
    # Rows at most a day apart: a longer gap is a clock jump (refused on reading). A gap of
    # exactly a day, added to a time and subtracted back, can come out a rounding step longer.
    gaps = draw(st.lists(st.floats(1e-3, ROW_GAP.high - 1.0), min_size=0, max_size=5))
    # The files share a clock: the motion starts within half a day of the first observation.
    start = first + draw(st.floats(0.0, ROW_GAP.high / 2.0)) if times else draw(st.floats(-1e9, 1e9))
    motion = list(itertools.accumulate(gaps, initial=start))
    odometry = Odometry(
        motion, [draw(within(SPEED)) for _ in motion], [draw(within(ANGULAR_SPEED)) for _ in motion]
    )
    name = draw(st.text(max_size=12).filter(str.isprintable))
    meta = LogMeta(name, bearing_error=draw(within(ANGLE_ERROR)), delay_s=draw(within(DELAY)))
    return RobotLog(meta, landmarks, observations, odometry=odometry)


@settings(max_examples=25)
@given(random_logs())
def test_round_trip_is_exact_for_random_logs(log: RobotLog) -> None:
    with tempfile.TemporaryDirectory() as scratch:
        assert_same_log(load_log(write_log(log, Path(scratch) / "log")), log)


def test_write_log_refuses_an_existing_log_unless_told(tmp_path: Path) -> None:
    folder = write_log(small_log(groundtruth=True), tmp_path / "log")
    with pytest.raises(InputError, match=r"expected a folder without a log, got .*holding meta\.toml"):
        write_log(small_log(commands=True, groundtruth=False), folder)
    write_log(small_log(commands=True, groundtruth=False), folder, overwrite=True)
    loaded = load_log(folder)  # the old odometry and ground truth are gone: no "both" error
    assert loaded.commands is not None
    assert loaded.groundtruth is None


@pytest.mark.parametrize("name", [".", "", "..", "/"])
def test_write_log_refuses_a_folder_without_a_name_of_its_own(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, name: str
) -> None:
    # "." raised ValueError from pathlib (no name to put the scratch folder beside): the
    # log is written under a scratch name and renamed onto its folder, which needs a name.
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError, match=r"folder: expected a path ending in the log folder's name, got"):
        write_log(small_log(), name)
    assert list(tmp_path.iterdir()) == []


def test_write_log_refuses_a_file_as_folder(tmp_path: Path) -> None:
    (tmp_path / "file").write_text("x")
    with pytest.raises(InputError, match="folder: expected a folder, got the file"):
        write_log(small_log(), tmp_path / "file")


def test_comments_blank_lines_and_spaces_are_ignored(tmp_path: Path) -> None:
    files = dict(VALID_FILES)
    files["odometry.csv"] = (
        "# header comment\n time , v , omega \n\n  # indented comment\n0.0, 0.5 ,0.0\n2.0,0,0\n"
    )
    log = load_log(write_files(tmp_path, files))
    assert log.odometry is not None
    np.testing.assert_array_equal(log.odometry.v, [0.5, 0.0])
    assert [o.kind for o in log.observations] == [
        ObservationKind.RANGE_BEARING,
        ObservationKind.BEARING,
        ObservationKind.RANGE_BEARING,
    ]
    assert log.meta.name == "tiny"
    assert log.meta.bearing_error == 0.02


def test_name_defaults_to_the_folder_name(tmp_path: Path) -> None:
    files = dict(VALID_FILES, **{"meta.toml": 'terrain = "grass"\n'})
    assert load_log(write_files(tmp_path / "run-7", files)).meta.name == "run-7"


# --- units -------------------------------------------------------------------------------------


def test_units_convert_every_value_to_si(tmp_path: Path) -> None:
    files = {
        "meta.toml": (
            'name = "units"\n[units]\nlength = "cm"\nangle = "deg"\ntime = "ms"\n'
            "[sensor]\nbearing_error = 2\nrange_error = 5\nrange_error_fraction = 0.1\n"
            "[motion]\ndelay_s = 0.5\n"
            "[start]\nx = 100\ny = -50\nheading = 180\nradius = 20\nheading_halfwidth = 3\n"
            "[landmarks]\nz_bottom = 10\nz_top = 250\n"
        ),
        "landmarks.csv": "id,x,y,position_uncertainty,z_bottom,z_top\nA,150,-20,2,,300\n",
        "observations.csv": "time,landmark_id,bearing,range,bearing_error,range_error\n1500,A,-90,250,1,4\n",
        "odometry.csv": "time,v,omega\n1000,0.05,0.09\n3000,0,0\n",
        "groundtruth.csv": "time,x,y,heading\n1000,10,20,45\n",
    }
    log = load_log(write_files(tmp_path, files))
    degree = math.pi / 180.0
    meta = log.meta
    assert meta.bearing_error == pytest.approx(2 * degree)
    assert (meta.range_error, meta.range_error_fraction) == pytest.approx((0.05, 0.1))
    assert meta.delay_s == 0.5  # the key's name says seconds: [units] time does not apply
    assert meta.start is not None
    np.testing.assert_allclose(meta.start.as_array(), [1.0, -0.5, math.pi])
    assert (meta.start_radius, meta.start_heading_halfwidth) == pytest.approx((0.2, 3 * degree))
    assert (meta.landmark_z_bottom, meta.landmark_z_top) == pytest.approx((0.1, 2.5))
    landmark = log.landmark("A")
    assert (landmark.x, landmark.y, landmark.position_uncertainty) == pytest.approx((1.5, -0.2, 0.02))
    assert landmark.z_bottom is None
    assert landmark.z_top == pytest.approx(3.0)
    observation = log.observations[0]
    assert observation.time == pytest.approx(1.5)
    assert (observation.bearing, observation.range) == pytest.approx((-math.pi / 2, 2.5))
    assert (observation.bearing_error, observation.range_error) == pytest.approx((degree, 0.04))
    assert log.odometry is not None
    np.testing.assert_allclose(log.odometry.time, [1.0, 3.0])
    np.testing.assert_allclose(log.odometry.v, [0.5, 0.0])  # 0.05 cm/ms = 0.5 m/s
    np.testing.assert_allclose(log.odometry.omega, [90 * degree, 0.0])  # 0.09 deg/ms
    assert log.groundtruth is not None
    np.testing.assert_allclose(log.groundtruth.at(1.0), [[0.1, 0.2, math.pi / 4]])


def test_feet_and_nanoseconds(tmp_path: Path) -> None:
    files = dict(VALID_FILES)
    files["meta.toml"] = '[units]\nlength = "ft"\ntime = "ns"\n'
    files["commands.csv"] = "time,turn,run\n1000000000,0.5,30\n"
    del files["odometry.csv"]
    log = load_log(write_files(tmp_path, files))
    assert log.commands == (PositionReport(1.0, TurnAndRun(0.5, 30 * FOOT)),)
    assert log.landmark("A").x == pytest.approx(3 * FOOT)


# --- bad logs ----------------------------------------------------------------------------------

BAD_CSV_CASES = [
    # (file, new text or None to remove, pattern after the file name)
    ("observations.csv", None, "observations.csv: expected an existing CSV file, got no such file"),
    ("landmarks.csv", None, "landmarks.csv: expected an existing CSV file, got no such file"),
    ("meta.toml", None, "meta.toml: expected an existing log metadata TOML file, got no such file"),
    ("observations.csv", "# only a comment\n", "observations.csv: expected a header row naming the columns"),
    ("observations.csv", "time,landmark_id\n", "observations.csv:1: expected a column 'bearing', got"),
    (
        "odometry.csv",
        "time,v,omega,speed\n",
        "odometry.csv:1: expected columns from .*unknown column 'speed'",
    ),
    ("odometry.csv", "time,v,v,omega\n", "odometry.csv:1: expected each column once, got 'v' twice"),
    ("odometry.csv", "time,v,omega\n", "odometry.csv: expected at least one data row, got none"),
    (
        "odometry.csv",
        "time,v,omega\n0,1,0\n# c\n1,abc,0\n",
        "odometry.csv:4: expected a number in column 'v', got 'abc'",
    ),
    (
        "odometry.csv",
        "time,v,omega\n0,1,0\n1,0_5,0\n",  # float() would read 5.0 (Python's digit grouping)
        "odometry.csv:3: expected a number in column 'v', got '0_5'",
    ),
    (
        "odometry.csv",
        "time,v,omega\n0,1,nan\n",
        "odometry.csv:2: expected a finite number in column 'omega', got 'nan'",
    ),
    (
        "odometry.csv",
        "time,v,omega\n0,1,0\n1,-inf,0\n",
        "odometry.csv:3: expected a finite number in column 'v', got '-inf'",
    ),
    (
        "odometry.csv",
        "time,v,omega\n0,1,\n",
        "odometry.csv:2: expected a number in column 'omega', got ''",
    ),
    ("odometry.csv", "time,v,omega\n0,1,0,7\n", "odometry.csv:2: expected 3 cells, got 4"),
    (
        "odometry.csv",
        "time,v,omega\n0,1,0\n2,1,0\n1,1,0\n",
        r"odometry.csv:4: expected strictly increasing times, got '1' after '2' \(line 3\)",
    ),
    (
        "odometry.csv",
        "time,v,omega\n0,1,0\n0,1,0\n",
        "odometry.csv:3: expected strictly increasing times, got '0' after '0'",
    ),
    (
        "groundtruth.csv",
        "time,x,y,heading\n1,0,0,0\n0.5,0,0,0\n",
        "groundtruth.csv:3: expected strictly increasing times",
    ),
    ("groundtruth.csv", "time,x,y\n1,0,0\n", "groundtruth.csv:1: expected a column 'heading'"),
    (
        "observations.csv",
        "time,landmark_id,bearing\n1.0,A,0\n0.5,A,0\n",
        "observations.csv:3: expected non-decreasing times, got '0.5' after '1.0'",
    ),
    (
        "observations.csv",
        "time,landmark_id,bearing\n" + "0,A,0\n" * 15 + "1,99,0\n",
        "observations.csv:17: expected a landmark id listed in landmarks.csv, got '99'",
    ),
    (
        "observations.csv",
        "time,landmark_id,bearing\n0,,0\n",
        "observations.csv:2: expected a non-empty landmark_id",
    ),
    (
        "observations.csv",
        "time,landmark_id,bearing,range\n0,A,0,-1\n",
        r"observations.csv:2: expected a number in \[0, 10000\] m in column 'range', got '-1'",
    ),
    (
        "observations.csv",
        "time,landmark_id,bearing,bearing_error\n0,A,0,0\n",
        r"observations.csv:2: expected a number in \[1e-06, 1000\] rad in column 'bearing_error', got '0'",
    ),
    (
        "observations.csv",
        "time,landmark_id,bearing,range_error\n0,A,0,-0.1\n",
        r"observations.csv:2: expected a number in \[0, 10000\] m in column 'range_error'",
    ),
    (
        "landmarks.csv",
        "id,x,y\nA,0,0\nB,1,1\nA,2,2\n",
        r"landmarks.csv:4: expected a unique id, got 'A' again \(first at line 2\)",
    ),
    (
        "landmarks.csv",
        "id,x,y,position_uncertainty\nA,0,0,-1\n",
        r"landmarks.csv:2: expected a number in \[0, 1000\] m in column 'position_uncertainty'",
    ),
    (
        "landmarks.csv",
        "id,x,y,z_bottom,z_top\nA,0,0,2,1\n",
        "landmarks.csv:2: expected z_top >= z_bottom",
    ),
    ("landmarks.csv", "id,x\nA,0\n", "landmarks.csv:1: expected a column 'y'"),
    ("landmarks.csv", 'id,x,y\n"A\nB",0,0\n', "landmarks.csv: expected one row per line"),
]


@pytest.mark.parametrize(("name", "text", "pattern"), BAD_CSV_CASES)
def test_bad_csv_files_are_named_with_their_line(
    tmp_path: Path, name: str, text: str | None, pattern: str
) -> None:
    files: dict[str, str | None] = dict(VALID_FILES)
    files[name] = text
    write_files(tmp_path, files)
    with pytest.raises(FileFormatError, match=re.escape(str(tmp_path)) + "/" + pattern):
        load_log(tmp_path)


def test_negative_run_in_commands(tmp_path: Path) -> None:
    files: dict[str, str | None] = dict(VALID_FILES, **{"odometry.csv": None})
    files["commands.csv"] = "time,turn,run\n1,0.1,0.5\n2,0.0,-0.5\n"
    with pytest.raises(
        FileFormatError,
        match=r"commands\.csv:3: expected a number in \[0, 10000\] m in column 'run', got '-0\.5'",
    ):
        load_log(write_files(tmp_path, files))


def test_commands_times_must_increase(tmp_path: Path) -> None:
    files: dict[str, str | None] = dict(VALID_FILES, **{"odometry.csv": None})
    files["commands.csv"] = "time,turn,run\n1,0.1,0.5\n1,0.0,0.5\n"
    with pytest.raises(FileFormatError, match=r"commands\.csv:3: expected strictly increasing times"):
        load_log(write_files(tmp_path, files))


def test_both_odometry_and_commands(tmp_path: Path) -> None:
    files = dict(VALID_FILES, **{"commands.csv": "time,turn,run\n1,0,0\n"})
    with pytest.raises(
        FileFormatError, match=r"expected exactly one of odometry\.csv and commands\.csv, got both"
    ):
        load_log(write_files(tmp_path, files))


def test_neither_odometry_nor_commands(tmp_path: Path) -> None:
    files: dict[str, str | None] = dict(VALID_FILES, **{"odometry.csv": None})
    with pytest.raises(
        FileFormatError, match=re.escape(str(tmp_path)) + ": expected exactly one .*got neither"
    ):
        load_log(write_files(tmp_path, files))


def test_missing_folder(tmp_path: Path) -> None:
    with pytest.raises(FileFormatError, match=r"/nowhere: expected a log folder, got no such folder"):
        load_log(tmp_path / "nowhere")


BAD_META_CASES = [
    ('name = "x"\ncolour = "red"\n', r"meta\.toml: colour: expected one of name, terrain, source, \[units\]"),
    (
        "[sensor]\nbearing_eror = 0.1\n",
        r"meta\.toml: \[sensor\] bearing_eror: expected one of bearing_error",
    ),
    ("[sensors]\nbearing_error = 0.1\n", r"meta\.toml: sensors: expected one of .*got unknown key 'sensors'"),
    (
        '[sensor]\nbearing_error = "big"\n',
        r"meta\.toml: \[sensor\] bearing_error: expected a finite number, got 'big'",
    ),
    (
        "[sensor]\nbearing_error = true\n",
        r"meta\.toml: \[sensor\] bearing_error: expected a finite number, got true",
    ),
    (
        "[sensor]\nbearing_error = nan\n",
        r"meta\.toml: \[sensor\] bearing_error: expected a finite number, got nan",
    ),
    (
        "[sensor]\nbearing_error = 0\n",
        r"meta\.toml: \[sensor\] bearing_error: expected a number in \[1e-06, 1000\] rad, got 0",
    ),
    (
        "[sensor]\nrange_error = -0.1\n",
        r"meta\.toml: \[sensor\] range_error: expected a number in \[0, 10000\] m",
    ),
    (
        "[motion]\nrun_scale = -1\n",
        r"meta\.toml: \[motion\] run_scale: expected a number in \[0\.001, 1000\], got -1",
    ),
    ("[motion]\ndelay_s = -0.5\n", r"meta\.toml: \[motion\] delay_s: expected a number in \[0, 3600\] s"),
    (
        "[start]\nx = 1\ny = 2\n",
        r"meta\.toml: \[start\]: expected x, y and heading together .*got only x and y",
    ),
    ("[start]\nradius = -1\n", r"meta\.toml: \[start\] radius: expected a number in \[0, 10000\] m"),
    (
        "[landmarks]\nz_bottom = 2\nz_top = 1\n",
        r"meta\.toml: \[landmarks\] z_top: expected >= landmark_z_bottom",
    ),
    ('terrain = ""\n', r"meta\.toml: terrain: expected a non-empty string"),
    ("terrain = 3\n", r"meta\.toml: terrain: expected a string, got 3"),
    (
        '[units]\nlength = "inch"\n',
        r"meta\.toml: \[units\] length: expected one of 'm', 'cm', 'mm', 'ft', got 'inch'",
    ),
    ('[units]\nmass = "kg"\n', r"meta\.toml: \[units\] mass: expected one of length, angle, time"),
    ('units = "m"\n', r"meta\.toml: \[units\]: expected a table, got 'm'"),
    ("sensor = 3\n", r"meta\.toml: \[sensor\]: expected a table, got 3"),
    ('name = "x\n', r"meta\.toml:1:10: expected valid TOML, got Illegal character"),
]


@pytest.mark.parametrize(("text", "pattern"), BAD_META_CASES)
def test_bad_meta_toml(tmp_path: Path, text: str, pattern: str) -> None:
    write_files(tmp_path, dict(VALID_FILES, **{"meta.toml": text}))
    with pytest.raises(FileFormatError, match=pattern):
        load_log(tmp_path)


# --- encodings and limits (the loading layer) ---------------------------------------------------


def test_every_file_with_an_excel_byte_order_mark_reads_the_same(tmp_path: Path) -> None:
    plain = load_log(write_files(tmp_path / "plain", VALID_FILES))
    folder = write_files(tmp_path / "bom", {name: "\ufeff" + text for name, text in VALID_FILES.items()})
    with_bom = load_log(folder)
    assert_same_log(with_bom, plain, lines=True)
    assert with_bom.meta == plain.meta


def test_an_excel_csv_with_crlf_and_bom_reads_the_same(tmp_path: Path) -> None:
    plain = load_log(write_files(tmp_path / "plain", VALID_FILES))
    folder = write_files(tmp_path / "excel", VALID_FILES)
    for name in ("landmarks.csv", "observations.csv", "odometry.csv"):
        (folder / name).write_bytes(b"\xef\xbb\xbf" + VALID_FILES[name].replace("\n", "\r\n").encode())
    assert_same_log(load_log(folder), plain, lines=True)


@pytest.mark.parametrize("name", ["meta.toml", "landmarks.csv", "observations.csv", "odometry.csv"])
def test_latin1_files_are_refused_naming_file_and_byte(tmp_path: Path, name: str) -> None:
    folder = write_files(tmp_path, VALID_FILES)
    (folder / name).write_bytes(("# r\u00e9sum\u00e9\n" + VALID_FILES[name]).encode("latin-1"))
    with pytest.raises(
        FileFormatError, match=re.escape(f"{folder / name}:1: byte 3: expected UTF-8 text, got the byte 0xe9")
    ):
        load_log(folder)


def test_too_many_rows_are_refused_at_the_first_one_over(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    folder = write_files(tmp_path, VALID_FILES)
    monkeypatch.setattr("aura_ums._files.MAX_ROWS", 2)
    with pytest.raises(FileFormatError, match=r"observations\.csv:4: expected at most 2 data rows, got more"):
        load_log(folder)


def test_a_file_over_the_size_limit_is_refused_stating_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # The real limit (256 MiB) would make the test read 256 MiB; a small one shows the same path.
    monkeypatch.setattr(log_io, "LOG_CSV_MAX_BYTES", 2 * 1024 * 1024)
    folder = write_files(tmp_path, VALID_FILES)
    with (folder / "odometry.csv").open("ab") as handle:
        handle.truncate(2 * 1024 * 1024 + 1)
    with pytest.raises(FileFormatError, match=r"odometry\.csv: expected a CSV file of at most 2 MiB \("):
        load_log(folder)


def test_a_log_csv_may_exceed_the_general_file_limit() -> None:
    # 2,000,000 rows of repr floats do not fit in 64 MiB.
    assert log_io.LOG_CSV_MAX_BYTES >= 2_000_000 * 80 > MAX_BYTES


@settings(max_examples=25, deadline=None)
@given(
    st.lists(
        st.tuples(st.floats(0.0, 1.0), st.floats(-2.0, 2.0), st.floats(-1.0, 1.0)), min_size=1, max_size=20
    ),
    st.sampled_from(["\n", "\r\n"]),
)
def test_numbers_read_column_wise_equal_those_read_cell_by_cell(
    rows: list[tuple[float, float, float]], newline: str
) -> None:
    # A quoted cell sends the file through the cell-by-cell reader, which must agree.
    times = np.cumsum([1.0 + step for step, _, _ in rows]).tolist()
    plain = [
        "# odometry",
        "time,v,omega",
        *(f"{t!r}, {v!r},{w!r}" for t, (_, v, w) in zip(times, rows, strict=True)),
    ]
    quoted = [
        "# odometry",
        "time,v,omega",
        *(f'"{t!r}",{v!r},{w!r}' for t, (_, v, w) in zip(times, rows, strict=True)),
    ]
    read = []
    for lines in (plain, quoted):
        with tempfile.TemporaryDirectory() as scratch:
            files = dict(VALID_FILES, **{"odometry.csv": newline.join(lines) + newline})
            read.append(load_log(write_files(Path(scratch), files)).odometry)
    fast, slow = read
    assert fast is not None
    assert slow is not None
    for name in ("time", "v", "omega"):
        assert np.array_equal(getattr(fast, name), getattr(slow, name))
