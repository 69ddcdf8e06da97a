"""The loading layer: size limit, UTF-8 with or without BOM, TOML, strict JSON, CSV, typed fields."""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums import _files
from aura_ums._files import (
    MAX_BYTES,
    MAX_ROWS,
    Fields,
    atomic_path,
    decode,
    describe,
    key_path,
    load_csv,
    load_json,
    load_toml,
    make_folders,
    parse_csv,
    parse_json,
    parse_toml,
    read_bytes,
    read_folder,
    read_text,
)
from aura_ums.errors import AuraUmsError, FileFormatError, InputError

BOM = b"\xef\xbb\xbf"


def write(path: Path, data: bytes) -> Path:
    path.write_bytes(data)
    return path


def assert_worded(error: FileFormatError, source: str) -> None:
    """The one shape: the file named first, then "expected ..., got ..."."""
    text = str(error)
    assert text.startswith(source)
    assert re.search(r"expected .*, got ", error.message), text
    assert isinstance(error, InputError)
    assert isinstance(error, ValueError)


# --- limits ------------------------------------------------------------------------------------


def test_limits_are_the_stated_ones() -> None:
    assert MAX_BYTES == 64 * 1024 * 1024
    assert MAX_ROWS == 2_000_000


def test_a_file_at_the_limit_is_read_and_one_byte_more_is_refused(tmp_path: Path) -> None:
    path = write(tmp_path / "f.toml", b"x" * 100)
    assert read_bytes(path, kind="TOML", max_bytes=100) == b"x" * 100
    with pytest.raises(
        FileFormatError, match=r"f\.toml: expected a TOML file of at most 99 bytes, got a larger"
    ):
        read_bytes(path, kind="TOML", max_bytes=99)


def test_the_default_limit_is_stated_in_mebibytes(tmp_path: Path) -> None:
    path = tmp_path / "huge.json"
    with path.open("wb") as handle:
        handle.truncate(MAX_BYTES + 1)  # sparse: no disk used
    with pytest.raises(
        FileFormatError, match=r"huge\.json: expected a JSON file of at most 64 MiB \(67108864 bytes\)"
    ):
        load_json(path)


def test_text_in_memory_has_the_same_limit() -> None:
    with pytest.raises(FileFormatError, match=r"^mem: expected at most 8 bytes of text, got 9 characters$"):
        parse_json("[1,2,3,4]", "mem", max_bytes=8)


def test_missing_folder_and_unreadable_paths(tmp_path: Path) -> None:
    with pytest.raises(FileFormatError, match=r"nope\.csv: expected an existing CSV file, got no such file"):
        read_bytes(tmp_path / "nope.csv", kind="CSV")
    with pytest.raises(FileFormatError, match=r": expected a CSV file, got a folder$"):
        read_bytes(tmp_path, kind="CSV")
    with pytest.raises(FileFormatError, match=r"expected the path of a CSV file, got an invalid path"):
        read_bytes(str(tmp_path / "a\0b"), kind="CSV")


# --- text ----------------------------------------------------------------------------------------


def test_utf8_with_and_without_bom_decode_the_same() -> None:
    text = 'name = "Caf\u00e9 \u2013 \u65e5\u672c"\n'
    assert decode(text.encode(), "a") == decode(BOM + text.encode(), "a") == text


def test_only_a_leading_bom_is_removed() -> None:
    assert decode(BOM + b"a" + BOM, "f") == "a\ufeff"


def test_latin1_is_refused_naming_file_line_and_byte_offset(tmp_path: Path) -> None:
    path = write(tmp_path / "latin.toml", "a = 1\nname = 'M\u00fcller'\n".encode("latin-1"))
    with pytest.raises(FileFormatError) as caught:
        read_text(path, kind="TOML")
    assert str(caught.value) == f"{path}:2: byte 15: expected UTF-8 text, got the byte 0xfc"
    assert (caught.value.line, caught.value.where) == (2, "byte 15")


def test_utf16_is_named_as_such(tmp_path: Path) -> None:
    path = write(tmp_path / "excel.csv", "time,v\n".encode("utf-16"))
    with pytest.raises(
        FileFormatError, match=r"excel\.csv:1: byte 0: expected UTF-8 text, got a UTF-16 or UTF-32"
    ):
        read_text(path, kind="CSV")


@given(st.binary(max_size=200))
def test_any_bytes_decode_or_fail_cleanly(data: bytes) -> None:
    try:
        expected = data.decode("utf-8")
    except UnicodeDecodeError:
        with pytest.raises(FileFormatError, match=r"^f:\d+: byte \d+: expected UTF-8 text, got "):
            decode(data, "f")
    else:
        assert decode(data, "f") == expected.removeprefix("\ufeff")


# --- TOML and JSON ---------------------------------------------------------------------------


def test_toml_with_bom_and_errors_at_line_and_column(tmp_path: Path) -> None:
    path = write(tmp_path / "t.toml", BOM + b"[a]\nb = 1\n")
    assert load_toml(path) == {"a": {"b": 1}}
    with pytest.raises(FileFormatError, match=r"t\.toml:2:5: expected valid TOML, got Invalid value"):
        parse_toml("[a]\nb = \n", str(path))
    with pytest.raises(FileFormatError, match=r"^t:1:7: expected valid TOML, got Unclosed array$"):
        parse_toml("a = [1", "t")


def test_toml_nesting_and_huge_integers_are_clean_errors() -> None:
    with pytest.raises(
        FileFormatError, match=r"^t: expected valid TOML, got arrays or tables nested too deep$"
    ):
        parse_toml("a = " + "[" * 100_000, "t")
    with pytest.raises(
        FileFormatError, match=r"^t: expected valid TOML, got Exceeds the limit \(4300 digits\)"
    ):
        parse_toml("a = " + "9" * 5000, "t")


def test_json_with_bom(tmp_path: Path) -> None:
    path = write(tmp_path / "j.json", BOM + b'{"a": [1, 2.5, null, true]}')
    assert load_json(path) == {"a": [1, 2.5, None, True]}


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('{"a": NaN}', r"^j: expected valid JSON, got the non-standard number NaN$"),
        ('{"a": -Infinity}', r"^j: expected valid JSON, got the non-standard number -Infinity$"),
        ('{"a": 1e309}', r"^j: expected valid JSON, got the number '1e309', beyond the largest float$"),
        ('{"a": 1, "a": 2}', r"^j: expected valid JSON, got the key 'a' twice in one object$"),
        ('{"a": 1,}', r"^j:1:9: expected valid JSON, got Expecting property name"),
        ("[" * 100_000, r"^j: expected valid JSON, got arrays or objects nested too deep$"),
        ("9" * 5000, r"^j: expected valid JSON, got Exceeds the limit \(4300 digits\)"),
        ("", r"^j:1:1: expected valid JSON, got Expecting value$"),
    ],
)
def test_strict_json_refuses(text: str, message: str) -> None:
    with pytest.raises(FileFormatError, match=message) as caught:
        parse_json(text, "j")
    assert_worded(caught.value, "j")


# --- CSV -----------------------------------------------------------------------------------------

COLUMNS = ("time", "v", "omega")


def test_csv_header_rows_and_line_numbers() -> None:
    text = "# odometry\n\ntime, v ,omega\n0,1,2\n  # a comment\n1, 2 ,3\n"
    table = parse_csv(text, "o.csv", columns=COLUMNS, required=("time",))
    assert table.header == COLUMNS
    assert table.header_line == 3
    assert table.rows == (("0", "1", "2"), ("1", "2", "3"))
    assert table.lines == (4, 6)
    assert table.columns() == {"time": ["0", "1"], "v": ["1", "2"], "omega": ["2", "3"]}
    assert len(table) == 2


def test_a_quoted_cell_may_follow_spaces_after_the_comma() -> None:
    # "Spaces around cells are ignored" did not hold for a quoted cell: `, "sign, red"` was
    # read as two cells, `"sign` and `red"`, and the row refused as one cell too many.
    table = parse_csv('id, symbol\n pole ,  "sign, red"\n', "l.csv", columns=("id", "symbol"))
    assert table.rows == (("pole", "sign, red"),)


def test_csv_with_an_excel_bom_reads_like_without(tmp_path: Path) -> None:
    plain = write(tmp_path / "plain.csv", b"time,v,omega\n0,1,2\n")
    excel = write(tmp_path / "excel.csv", BOM + b"time,v,omega\r\n0,1,2\r\n")
    assert load_csv(plain, columns=COLUMNS).rows == load_csv(excel, columns=COLUMNS).rows
    assert load_csv(excel, columns=COLUMNS).header == COLUMNS


def test_a_bom_left_inside_the_text_is_stripped_from_the_column_name() -> None:
    assert parse_csv("# c\n\ufefftime,v\n", "f", columns=COLUMNS).header == ("time", "v")


def test_csv_row_limit() -> None:
    text = "time,v,omega\n" + "0,1,2\n" * 5
    assert len(parse_csv(text, "o.csv", columns=COLUMNS, max_rows=5)) == 5
    with pytest.raises(FileFormatError, match=r"^o\.csv:6: expected at most 4 data rows, got more$"):
        parse_csv(text, "o.csv", columns=COLUMNS, max_rows=4)


def test_the_default_row_limit_is_read_when_called(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(_files, "MAX_ROWS", 1)
    with pytest.raises(FileFormatError, match=r"^o:3: expected at most 1 data rows, got more$"):
        parse_csv("time\n0\n1\n", "o", columns=COLUMNS)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", r"^o: expected a header row naming the columns time, got none$"),
        ("# only a comment\n", r"^o: expected a header row naming the columns time, got none$"),
        ("time,speed\n", r"^o:1: expected columns from time, v, omega, got unknown column 'speed'$"),
        ("time,v,v\n", r"^o:1: expected each column once, got 'v' twice$"),
        ("v\n", r"^o:1: expected a column 'time', got columns v$"),
        ("time,v\n0,1\n0,1,2\n", r"^o:3: expected 2 cells, got 3$"),
        ('time,v\n"0,1\n2,3\n', r"^o:3: expected CSV, got unexpected end of data$"),
        ('time,v\n"0\n1",2\n', r"^o: expected one row per line, got a quoted cell spanning lines$"),
        ('time,v\n"0"x,1\n', r"^o:2: expected CSV, got ',' expected after"),
    ],
)
def test_malformed_csv(text: str, message: str) -> None:
    with pytest.raises(FileFormatError, match=message) as caught:
        parse_csv(text, "o", columns=COLUMNS, required=("time",))
    assert_worded(caught.value, "o")


# --- typed fields ----------------------------------------------------------------------------


def test_key_paths() -> None:
    assert key_path("", "map") == "map"
    assert key_path("[start]", "x") == "[start] x"
    assert key_path("[my terrain]", "drift") == "[my terrain] drift"
    assert key_path("[route] commands[2]", "run") == "[route] commands[2].run"
    assert key_path("map.wedge", "cw") == "map.wedge.cw"


def test_descriptions_are_short_and_never_print_containers() -> None:
    assert describe(None) == "nothing"
    assert describe(None, "json") == "null"
    assert describe(False) == "false"
    assert describe({"a": [1] * 10_000}) == "a table"
    assert describe({}, "json") == "an object"
    assert describe([[[]]]) == "an array"
    assert describe(float("nan")) == "nan"
    assert describe(2**300) == "a huge integer"
    assert len(describe("x" * 10_000)) == 60


FIELDS = Fields("f.toml")


@pytest.mark.parametrize(
    ("table", "kind", "expected"),
    [({"k": 2}, float, 2.0), ({"k": 2}, int, 2), ({"k": "s"}, str, "s"), ({"k": True}, bool, True)],
)
def test_field_returns_checked_values(table: dict[str, object], kind: type, expected: object) -> None:
    value: object = FIELDS.field(table, "k", kind, "[t]")
    assert value == expected
    assert type(value) is kind


def test_field_default_when_absent() -> None:
    assert FIELDS.field({}, "k", float, "[t]", 1.5) == 1.5
    assert FIELDS.field({}, "k", list, "", [1]) == [1]


@pytest.mark.parametrize(
    ("table", "kind", "message"),
    [
        ({}, float, r"^f\.toml: \[t\] k: expected a finite number, got nothing$"),
        ({"k": "1"}, float, r"^f\.toml: \[t\] k: expected a finite number, got '1'$"),
        ({"k": True}, float, r"^f\.toml: \[t\] k: expected a finite number, got true$"),
        ({"k": float("inf")}, float, r"^f\.toml: \[t\] k: expected a finite number, got inf$"),
        ({"k": 10**400}, float, r"^f\.toml: \[t\] k: expected a finite number, got a huge integer$"),
        ({"k": 1.0}, int, r"^f\.toml: \[t\] k: expected an integer, got 1\.0$"),
        ({"k": 1}, str, r"^f\.toml: \[t\] k: expected a string, got 1$"),
        ({"k": 1}, bool, r"^f\.toml: \[t\] k: expected true or false, got 1$"),
        ({"k": []}, dict, r"^f\.toml: \[t\] k: expected a table, got an array$"),
        ({"k": {}}, list, r"^f\.toml: \[t\] k: expected an array, got a table$"),
    ],
)
def test_field_refusals_share_one_wording(table: dict[str, object], kind: type, message: str) -> None:
    with pytest.raises(FileFormatError, match=message) as caught:
        FIELDS.field(table, "k", kind, "[t]")
    assert_worded(caught.value, "f.toml")


def test_ranges_keys_and_json_vocabulary() -> None:
    with pytest.raises(FileFormatError, match=r"^f\.toml: x: expected a positive number, got 0$"):
        FIELDS.positive(0, "x")
    with pytest.raises(FileFormatError, match=r"^f\.toml: x: expected a non-negative number, got -1\.5$"):
        FIELDS.nonnegative(-1.5, "x")
    with pytest.raises(FileFormatError, match=r"^f\.toml: x: expected an integer >= 1, got 0$"):
        FIELDS.integer(0, "x", minimum=1)
    with pytest.raises(FileFormatError, match=r"^f\.toml: x: expected a non-empty string, got ''$"):
        FIELDS.string("", "x", nonempty=True)
    with pytest.raises(FileFormatError, match=r"^f\.toml: \[a\] c: expected one of b, got unknown key 'c'$"):
        FIELDS.keys({"b": 1, "c": 2}, ("b",), "[a]")
    with pytest.raises(FileFormatError, match=r"^s\.json: map: expected an object, got null$"):
        Fields("s.json", "json").table(None, "map")
    with pytest.raises(FileFormatError, match=r"^f\.toml:7: here: expected it, got that$"):
        FIELDS.fail("here", "expected it, got that", line=7)


def test_every_error_is_an_aura_ums_value_error() -> None:
    assert issubclass(FileFormatError, AuraUmsError)
    assert issubclass(FileFormatError, ValueError)


def test_a_named_pipe_is_refused_not_waited_on(tmp_path: Path) -> None:
    # open() of a FIFO waits for a writer: `replay --terrain FIFO` hung until killed.
    pipe = tmp_path / "terrain.toml"
    os.mkfifo(pipe)
    with pytest.raises(
        FileFormatError, match=r"terrain\.toml: expected a TOML file, got a named pipe or socket"
    ):
        read_bytes(pipe, kind="TOML")


def test_a_folder_is_read_only_when_it_is_a_folder_this_process_may_enter(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    assert read_folder(tmp_path, kind="log folder") == tmp_path
    file = tmp_path / "meta.toml"
    file.write_text("")
    with pytest.raises(FileFormatError, match=r"meta\.toml: expected a log folder, got a file$"):
        read_folder(file, kind="log folder")
    with pytest.raises(FileFormatError, match=r"/gone: expected a dataset folder, got no such folder$"):
        read_folder(tmp_path / "gone", kind="dataset folder")
    with pytest.raises(FileFormatError, match=r"expected the path of a log folder, got an invalid path$"):
        read_folder(str(tmp_path / "a\0b"), kind="log folder")
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o600)  # listable by its owner, not enterable
    if os.geteuid() == 0:  # root enters anything: the system's answer for a user, given here
        monkeypatch.setattr(os, "access", lambda path, mode: Path(path) != locked)
    with pytest.raises(
        FileFormatError, match=r"locked: expected a readable log folder, got Permission denied$"
    ):
        read_folder(locked, kind="log folder")
    locked.chmod(0o755)


def test_a_failed_atomic_write_removes_the_folders_it_made_and_keeps_the_others(tmp_path: Path) -> None:
    kept = tmp_path / "kept"
    kept.mkdir()

    def write_part(target: Path) -> None:
        with atomic_path(target) as scratch:
            scratch.write_text("part")
            raise OSError(28, "No space left on device")

    for target in (tmp_path / "new" / "deeper" / "a.json", kept / "a.json"):
        with pytest.raises(OSError, match="No space left"):
            write_part(target)
    assert [path.name for path in tmp_path.iterdir()] == ["kept"]
    assert list(kept.iterdir()) == []


def test_make_folders_undoes_what_it_made_when_it_fails(tmp_path: Path) -> None:
    # The parents are made first; then the last name is refused (too long for the file system).
    with pytest.raises(OSError, match="File name too long"):
        make_folders(tmp_path / "a" / "b" / ("x" * 300))
    assert list(tmp_path.iterdir()) == []
    (tmp_path / "file").write_text("")
    for below in (tmp_path / "file", tmp_path / "file" / "below"):
        with pytest.raises(NotADirectoryError, match="Not a directory"):
            make_folders(below)
    assert [path.name for path in tmp_path.iterdir()] == ["file"]


@pytest.mark.parametrize(("separator", "name"), [("\t", "tabs"), (";", "semicolons"), ("|", "vertical bars")])
def test_a_csv_separated_otherwise_is_named_so_not_as_an_unknown_column(separator: str, name: str) -> None:
    text = f"# odometry\ntime{separator}v{separator}omega\n0.0{separator}1.0{separator}0.0\n"
    with pytest.raises(
        FileFormatError,
        match=rf"^odometry\.csv:2: expected comma-separated values, got a header separated by {name}$",
    ):
        _files.parse_csv(text, "odometry.csv", columns=("time", "v", "omega"))
    # A header cell that only looks so (not every part a known column) stays an unknown column.
    with pytest.raises(FileFormatError, match=r"got unknown column 'time;speed'"):
        _files.parse_csv("time;speed,v\n", "odometry.csv", columns=("time", "v", "omega"))
