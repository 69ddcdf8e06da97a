"""A numeric CSV file read block by block gives what its whole text parsed at once gives."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from aura_ums._files import CsvFloats, csv_blocks, parse_csv, parse_csv_floats, read_csv_floats, read_text
from aura_ums.errors import FileFormatError

COLUMNS = ("time", "v", "omega")

_NUMBERS = st.one_of(
    st.floats(-1e6, 1e6).map(repr),
    st.integers(-1000, 1000).map(str),
    st.sampled_from(["1e-3", "2E+2", ".5", "5.", "-0.0", "+1", "nan", "inf", "1_0", "0x10", "", "a"]),
)
_LINES = st.one_of(
    st.lists(_NUMBERS, min_size=3, max_size=3).map(",".join),
    st.lists(_NUMBERS, min_size=2, max_size=4).map(", ".join),
    st.sampled_from(["", "  ", "# a comment", "  # indented comment", '"1",2,3', "1,2,3 # note", "\t1,2,3"]),
)


@st.composite
def _files(draw: st.DrawFn) -> bytes:
    before = draw(st.lists(st.sampled_from(["# odometry", "", "  "]), max_size=3))
    header = draw(st.sampled_from(["time,v,omega", " time , v ,omega", "time,v", "time,speed,omega"]))
    rows = draw(st.lists(_LINES, max_size=30))
    newline = draw(st.sampled_from(["\n", "\r\n"]))
    text = newline.join([*before, header, *rows]) + draw(st.sampled_from(["", newline]))
    bom = draw(st.sampled_from([b"", b"\xef\xbb\xbf"]))
    return bom + text.encode("ascii")


def _cell_by_cell(path: Path) -> tuple[tuple[str, ...], int, list[int], np.ndarray] | None:
    """The slow reader's header, header line, row lines and ``float()`` of every cell; None if it fails."""
    try:
        table = parse_csv(read_text(path, kind="CSV"), str(path), columns=COLUMNS)
        values = np.array([[float(cell) for cell in row] for row in table.rows], dtype=np.float64)
    except (FileFormatError, ValueError):
        return None
    return (
        table.header,
        table.header_line,
        list(table.lines),
        values.reshape(len(table.rows), len(table.header)),
    )


@settings(max_examples=300, deadline=None)
@given(_files(), st.integers(1, 64))
def test_blocks_of_any_size_read_what_the_cells_read_one_by_one_give(data: bytes, block_bytes: int) -> None:
    with tempfile.TemporaryDirectory() as scratch:
        path = Path(scratch) / "odometry.csv"
        path.write_bytes(data)
        whole = parse_csv_floats(read_text(path, kind="CSV"), str(path), columns=COLUMNS)
        found = read_csv_floats(path, columns=COLUMNS, block_bytes=block_bytes)
        # Never less able than the whole text parsed at once; exactly the cells when able.
        assert found is not None or whole is None
        if found is None:
            return
        truth = _cell_by_cell(path)
        assert truth is not None
        header, header_line, lines, values = truth
        assert found.header == header
        assert found.header_line == header_line
        assert found.lines.tolist() == lines
        assert np.array_equal(found.values, values, equal_nan=True)
        assert found.text is None
        if whole is not None:
            for row in range(len(found)):
                for column in found.header:
                    assert found.cell(row, column) == whole.cell(row, column)


def test_a_long_file_is_read_in_many_blocks(tmp_path: Path) -> None:
    rng = np.random.default_rng(7)
    values = rng.uniform(-10.0, 10.0, size=(5_000, 3))
    lines = ["# odometry", "time,v,omega", *(",".join(map(repr, row)) for row in values.tolist())]
    path = tmp_path / "odometry.csv"
    path.write_text("\n".join(lines) + "\n", encoding="ascii")
    found = read_csv_floats(path, columns=COLUMNS, block_bytes=1024)
    assert found is not None
    assert np.array_equal(found.values, values)
    assert found.lines.tolist() == list(range(3, 5_003))


def test_files_it_cannot_read_go_to_the_reader_whose_message_names_them(tmp_path: Path) -> None:
    missing = tmp_path / "missing.csv"
    assert read_csv_floats(missing, columns=COLUMNS) is None
    latin = tmp_path / "latin.csv"
    latin.write_bytes(b"time,v,omega\n1,2,3\n# caf\xe9\n")
    assert read_csv_floats(latin, columns=COLUMNS) is None
    with pytest.raises(
        FileFormatError, match=r"latin\.csv:3: byte 24: expected UTF-8 text, got the byte 0xe9"
    ):
        read_text(latin, kind="CSV")
    large = tmp_path / "large.csv"
    large.write_bytes(b"time,v,omega\n1,2,3\n")
    assert read_csv_floats(large, columns=COLUMNS, max_bytes=10) is None
    rows = tmp_path / "rows.csv"
    rows.write_bytes(b"time,v,omega\n1,2,3\n4,5,6\n7,8,9\n")
    assert read_csv_floats(rows, columns=COLUMNS, max_rows=2, block_bytes=16) is None
    assert read_csv_floats(rows, columns=COLUMNS, max_rows=3, block_bytes=16) is not None


@pytest.mark.parametrize("change", ["cut short", "written on"])
def test_a_file_that_changes_while_it_is_read_is_refused_not_read_twice(change: str, tmp_path: Path) -> None:
    # A replay whose odometry.csv was cut short under it went on without the rest, exit 0.
    path = tmp_path / "odometry.csv"
    path.write_text("time,v,omega\n" + "".join(f"{i},0.5,0.01\n" for i in range(2000)))
    size = path.stat().st_size
    blocks = csv_blocks(path, columns=COLUMNS, numeric=True, block_bytes=4096)
    first = next(blocks)
    assert isinstance(first, CsvFloats)
    assert first.values[0].tolist() == [0.0, 0.5, 0.01]
    with path.open("r+b") as stream:
        if change == "cut short":
            stream.truncate(size // 2 + 3)  # mid-row, as a cut file ends
        else:
            stream.seek(0, 2)
            stream.write(b"2000,0.5,0.01\n")
    with pytest.raises(FileFormatError, match=r"odometry.csv: expected the file as it was when it was open"):
        list(blocks)
