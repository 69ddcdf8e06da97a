"""The loading layer: every file aura-ums reads goes through here, and fails one way.

Each reader (terrain tables, cameras, scenarios, sensor calibrations, log folders and
their ``meta.toml``, saved manager state, meadow maps) reads its file with these steps:

1. bytes, at most :data:`MAX_BYTES` (64 MiB) per file;
2. UTF-8 text, with or without a byte-order mark (Excel writes one); other bytes are
   refused naming the line and the byte offset;
3. parsed as TOML (:mod:`tomllib`), strict JSON (no ``NaN``/``Infinity``, no key twice)
   or CSV (a header row naming the columns, then at most :data:`MAX_ROWS` data rows;
   blank lines and ``#`` comments skipped; every row keeps its 1-based line number);
4. typed values pulled from the parsed tables with :class:`Fields`.

Every failure is a :class:`~aura_ums.errors.FileFormatError` whose message reads
``file:line: expected ..., got ...`` or ``file: key path: expected ..., got ...``; the
wording of the common cases (a number, an integer, a string, a table, an unknown key)
is made here once. Nothing here evaluates what it reads: no pickle, no eval.

Writing goes the other way once too: :func:`atomic_path` gives a scratch name beside
the target and moves it over the target in one ``os.replace``, so a reader (or a
command killed half-way) sees the old file or the whole new one, never a part.
"""

from __future__ import annotations

import contextlib
import csv
import errno
import io
import json
import math
import os
import re
import secrets
import stat
import tomllib
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Literal, NoReturn, TypeAlias, TypeVar, cast

import numpy as np
from numpy.typing import NDArray

from aura_ums._validate import Range
from aura_ums.errors import FileFormatError, InputError

__all__ = [
    "MAX_BYTES",
    "MAX_ROWS",
    "NAME_MAX",
    "SCRATCH_SUFFIX",
    "CsvFallbackError",
    "CsvFloats",
    "CsvTable",
    "Fields",
    "RowsParser",
    "atomic_path",
    "csv_blocks",
    "decode",
    "describe",
    "is_scratch",
    "key_path",
    "load_csv",
    "load_json",
    "load_toml",
    "parse_csv",
    "parse_csv_floats",
    "parse_float_rows",
    "parse_json",
    "parse_toml",
    "place_new",
    "read_bytes",
    "read_csv_floats",
    "read_folder",
    "read_text",
    "scratch_path",
    "write_text_atomic",
]

#: Largest file read, bytes (64 MiB): far above any aura-ums file, far below memory trouble.
MAX_BYTES = 64 * 1024 * 1024
#: Most data rows of a CSV file (two million: hours of 100 Hz odometry).
MAX_ROWS = 2_000_000
#: Bytes :func:`read_csv_floats` reads at a time: what a large CSV file costs in memory beyond its values.
CSV_BLOCK_BYTES = 4 * 1024 * 1024

Syntax = Literal["toml", "json"]
T = TypeVar("T")

_BOM = "\ufeff"
_OTHER_BOMS = (b"\xff\xfe", b"\xfe\xff")  # UTF-16 and UTF-32 start with one of these
_DESCRIBED_LENGTH = 60
_TOML_POSITION = re.compile(r"^(?P<message>.*) \(at line (?P<line>\d+), column (?P<column>\d+)\)$", re.DOTALL)


def _size(limit: int) -> str:
    mebibytes, rest = divmod(limit, 1024 * 1024)
    return f"{mebibytes} MiB ({limit} bytes)" if mebibytes and not rest else f"{limit} bytes"


def _first_clause(exc: Exception) -> str:
    return str(exc).split(";", 1)[0]


def _limit(value: int | None, default: int) -> int:
    return default if value is None else value


# --- bytes and text ------------------------------------------------------------------------


def read_bytes(path: str | os.PathLike[str], *, kind: str, max_bytes: int | None = None) -> bytes:
    r"""Return the bytes of a file of at most ``max_bytes`` (default :data:`MAX_BYTES`).

    Parameters
    ----------
    path : str or path-like
        The file.
    kind : str
        What the file is, for messages (``"TOML"``, ``"scenario"``, ...).
    max_bytes : int, optional
        Largest size accepted, bytes.

    Returns
    -------
    bytes
        The whole file.

    Raises
    ------
    FileFormatError
        For a missing, unreadable or larger file; the message states the limit.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "a.toml"
    >>> _ = path.write_bytes(b"x = 1\n")
    >>> read_bytes(path, kind="TOML")
    b'x = 1\n'
    >>> read_bytes(path, kind="TOML", max_bytes=4)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: .../a.toml: expected a TOML file of at most 4 bytes, got a larger one
    """
    limit = _limit(max_bytes, MAX_BYTES)
    as_path(path, "path", f"a {kind} file's path (str or path-like)")
    source = str(path)
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):
        mode = 0  # the open below says why
    if stat.S_ISFIFO(mode) or stat.S_ISSOCK(mode):
        # Opening one waits for a writer: the command hung, silent, until killed.
        raise FileFormatError(source, "", f"expected a {kind} file, got a named pipe or socket")
    try:
        with open(path, "rb") as handle:
            # One byte more than the limit tells a larger file without reading all of it.
            data = handle.read(limit + 1)
    except FileNotFoundError:
        raise FileFormatError(source, "", f"expected an existing {kind} file, got no such file") from None
    except IsADirectoryError:
        raise FileFormatError(source, "", f"expected a {kind} file, got a folder") from None
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise FileFormatError(source, "", f"expected a readable {kind} file, got {reason}") from None
    except ValueError:  # a NUL in the path
        raise FileFormatError(
            source, "", f"expected the path of a {kind} file, got an invalid path"
        ) from None
    if len(data) > limit:
        raise FileFormatError(
            source, "", f"expected a {kind} file of at most {_size(limit)}, got a larger one"
        )
    return data


def present(path: str | os.PathLike[str]) -> bool:
    """Whether an optional file is there: a link that leads nowhere (or round in a loop) is.

    ``Path.exists`` calls such a link absent, so a log whose ``groundtruth.csv`` was a
    broken link replayed without ground truth in silence; present, its reader names it.

    Examples
    --------
    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> (folder / "link").symlink_to(folder / "gone")
    >>> present(folder / "link"), (folder / "link").exists(), present(folder / "other")
    (True, False, False)
    """
    return os.path.lexists(path)


def path_mode(path: str | os.PathLike[str]) -> int:
    r"""Return the ``st_mode`` of what ``path`` leads to, 0 where it leads nowhere.

    ``Path.is_file`` and ``Path.is_dir`` raise for a name too long or a NUL in it (they
    were tracebacks); such a path names nothing, so it reads as absent here, and the
    reader that then opens it says why.

    Examples
    --------
    >>> import stat, tempfile
    >>> stat.S_ISDIR(path_mode(tempfile.gettempdir())), path_mode("x" * 300), path_mode("a\0b")
    (True, 0, 0)
    """
    try:
        return os.stat(path).st_mode
    except (OSError, ValueError):
        return 0


def regular_file(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` leads to a regular file: never raising, never opening it (``path_mode``)."""
    return stat.S_ISREG(path_mode(path))


def as_path(value: object, name: str, what: str = "a path (str or os.PathLike)") -> Path:
    """Return ``value`` as a Path, refusing anything but a str or path-like object (``name``: ``what``).

    Examples
    --------
    >>> as_path("runs/log", "folder").as_posix()
    'runs/log'
    >>> as_path(None, "folder")
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: folder: expected a path (str or os.PathLike), got NoneType
    """
    if not isinstance(value, (str, os.PathLike)):
        raise InputError(f"{name}: expected {what}, got {type(value).__name__}")
    return Path(value)


def read_folder(path: str | os.PathLike[str], *, kind: str, name: str = "folder") -> Path:
    """Return ``path`` as a folder whose files can be read, or refuse it naming why.

    The one check of every folder a reader takes (a log, a dataset): a path that is
    missing, a file, or a folder this process may not list or enter is refused here,
    rather than as "unreadable" on the first file read inside it.

    Raises
    ------
    FileFormatError
        Naming the path: "expected a <kind>, got no such folder", "... got a file" or
        "expected a readable <kind>, got Permission denied".

    Examples
    --------
    >>> import tempfile
    >>> read_folder(tempfile.gettempdir(), kind="log folder").is_dir()
    True
    >>> read_folder("/nowhere", kind="log folder")
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: /nowhere: expected a log folder, got no such folder
    """
    folder = as_path(path, name)
    try:
        mode = os.stat(folder).st_mode
    except (FileNotFoundError, NotADirectoryError):
        raise FileFormatError(str(folder), "", f"expected a {kind}, got no such folder") from None
    except OSError as exc:  # a name too long, a loop of links: Path.is_dir raised them
        reason = exc.strerror or type(exc).__name__
        raise FileFormatError(str(folder), "", f"expected a {kind}, got {reason}") from None
    except ValueError:  # a NUL in the path
        raise FileFormatError(
            str(folder), "", f"expected the path of a {kind}, got an invalid path"
        ) from None
    if not stat.S_ISDIR(mode):
        raise FileFormatError(str(folder), "", f"expected a {kind}, got a file")
    # Listing needs read permission, opening a file inside needs execute (search).
    if not os.access(folder, os.R_OK | os.X_OK):
        raise FileFormatError(str(folder), "", f"expected a readable {kind}, got {os.strerror(errno.EACCES)}")
    return folder


def decode(data: bytes, source: str) -> str:
    r"""Return ``data`` decoded as UTF-8, without its byte-order mark if it has one.

    Parameters
    ----------
    data : bytes
        The file's bytes.
    source : str
        The file, for messages.

    Returns
    -------
    str
        The text.

    Raises
    ------
    FileFormatError
        Naming the line and the byte offset of the first byte that is not UTF-8.

    Examples
    --------
    >>> decode(b"\xef\xbb\xbftime,v\n", "odometry.csv")
    'time,v\n'
    >>> decode(b"name = 'caf\xe9'\n", "meta.toml")
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: meta.toml:1: byte 11: expected UTF-8 text, got the byte 0xe9
    """
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        offset = exc.start
        if offset < 2 and data.startswith(_OTHER_BOMS):
            found = "a UTF-16 or UTF-32 byte-order mark"
        else:
            found = f"the byte 0x{data[offset]:02x}"
        line = data.count(b"\n", 0, offset) + 1
        raise FileFormatError(
            source, f"byte {offset}", f"expected UTF-8 text, got {found}", line=line
        ) from None
    return text.removeprefix(_BOM)


def read_text(path: str | os.PathLike[str], *, kind: str, max_bytes: int | None = None) -> str:
    """Return a file's text: :func:`read_bytes` then :func:`decode`."""
    return decode(read_bytes(path, kind=kind, max_bytes=max_bytes), str(path))


def _text(text: str, source: str, max_bytes: int | None) -> str:
    """Text given in memory: the same size limit (in characters) and BOM rule as files."""
    limit = _limit(max_bytes, MAX_BYTES)
    if len(text) > limit:
        raise FileFormatError(
            source, "", f"expected at most {_size(limit)} of text, got {len(text)} characters"
        )
    return text.removeprefix(_BOM)


# --- TOML and JSON -------------------------------------------------------------------------


def parse_toml(text: str, source: str, *, max_bytes: int | None = None) -> dict[str, object]:
    r"""Parse TOML text; a syntax error names the line and column.

    Examples
    --------
    >>> parse_toml("\ufeff[mount]\nheight = 1.2\n", "cam.toml")
    {'mount': {'height': 1.2}}
    >>> parse_toml("[mount]\nheight = \n", "cam.toml")
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: cam.toml:2:10: expected valid TOML, got Invalid value
    """
    body = _text(text, source, max_bytes)
    try:
        return tomllib.loads(body)
    except tomllib.TOMLDecodeError as exc:
        text_of_error = str(exc)
        match = _TOML_POSITION.match(text_of_error)
        if match is not None:
            message, line, column = match["message"], int(match["line"]), int(match["column"])
        else:  # "... (at end of document)": the place after the last character
            message = text_of_error.removesuffix(" (at end of document)")
            line, column = body.count("\n") + 1, len(body) - body.rfind("\n")
        raise FileFormatError(
            source, "", f"expected valid TOML, got {message}", line=line, column=column
        ) from None
    except RecursionError:
        raise FileFormatError(
            source, "", "expected valid TOML, got arrays or tables nested too deep"
        ) from None
    except ValueError as exc:  # an integer of more digits than Python converts
        raise FileFormatError(source, "", f"expected valid TOML, got {_first_clause(exc)}") from None


def _no_constants(name: str) -> NoReturn:
    raise _RefusedError(f"the non-standard number {name}")


def _finite_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise _RefusedError(f"the number {describe(text)}, beyond the largest float")
    return value


def _no_repeats(pairs: list[tuple[str, object]]) -> dict[str, object]:
    result = dict(pairs)
    if len(result) != len(pairs):
        seen: set[str] = set()
        for key, _ in pairs:
            if key in seen:
                raise _RefusedError(f"the key {describe(key)} twice in one object")
            seen.add(key)
    return result


class _RefusedError(Exception):
    """What strict JSON refuses although :mod:`json` would read it; turned into a FileFormatError."""


def parse_json(text: str, source: str, *, max_bytes: int | None = None) -> object:
    r"""Parse strict JSON text: no ``NaN``/``Infinity`` constants, no key twice in an object.

    Examples
    --------
    >>> parse_json('\ufeff{"x": [1, 2.5]}', "state.json")
    {'x': [1, 2.5]}
    >>> parse_json('{"x": NaN}', "state.json")
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: state.json: expected valid JSON, got the non-standard number NaN
    """
    body = _text(text, source, max_bytes)
    try:
        return cast(
            object,
            json.loads(
                body, parse_constant=_no_constants, parse_float=_finite_float, object_pairs_hook=_no_repeats
            ),
        )
    except json.JSONDecodeError as exc:
        raise FileFormatError(
            source, "", f"expected valid JSON, got {exc.msg}", line=exc.lineno, column=exc.colno
        ) from None
    except _RefusedError as exc:
        raise FileFormatError(source, "", f"expected valid JSON, got {exc}") from None
    except RecursionError:
        raise FileFormatError(
            source, "", "expected valid JSON, got arrays or objects nested too deep"
        ) from None
    except ValueError as exc:  # an integer of more digits than Python converts
        raise FileFormatError(source, "", f"expected valid JSON, got {_first_clause(exc)}") from None


def load_toml(
    path: str | os.PathLike[str], *, kind: str = "TOML", max_bytes: int | None = None
) -> dict[str, object]:
    """Read and parse a TOML file (:func:`read_text`, :func:`parse_toml`)."""
    return parse_toml(read_text(path, kind=kind, max_bytes=max_bytes), str(path), max_bytes=max_bytes)


def load_json(path: str | os.PathLike[str], *, kind: str = "JSON", max_bytes: int | None = None) -> object:
    """Read and parse a strict JSON file (:func:`read_text`, :func:`parse_json`)."""
    return parse_json(read_text(path, kind=kind, max_bytes=max_bytes), str(path), max_bytes=max_bytes)


# --- CSV -----------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class CsvTable:
    """A parsed CSV file: the header, the rows of stripped cells and their line numbers.

    Parameters
    ----------
    source : str
        The file, for messages.
    header : tuple of str
        The column names, stripped (of spaces and of a byte-order mark).
    header_line : int
        1-based line of the header.
    rows : tuple of tuple of str
        The data rows, each with one stripped cell per column.
    lines : tuple of int
        1-based line of each row.
    """

    source: str
    header: tuple[str, ...]
    header_line: int
    rows: tuple[tuple[str, ...], ...]
    lines: tuple[int, ...]

    def __len__(self) -> int:
        return len(self.rows)

    def columns(self) -> dict[str, list[str]]:
        """Return the cells column by column, keyed by column name."""
        transposed = list(zip(*self.rows, strict=True)) if self.rows else [() for _ in self.header]
        return {name: list(cells) for name, cells in zip(self.header, transposed, strict=True)}


#: Separators of CSV-like files that are not commas, by name: told apart from an unknown column.
_OTHER_SEPARATORS = {"\t": "tabs", ";": "semicolons", "|": "vertical bars"}


def _other_separator(cell: str, columns: Sequence[str]) -> str | None:
    """Name the separator that splits a header cell into known columns (a file not comma-separated)."""
    for separator, name in _OTHER_SEPARATORS.items():
        parts = [part.strip() for part in cell.split(separator)]
        if len(parts) > 1 and all(part in columns for part in parts):
            return name
    return None


def parse_csv(
    text: str,
    source: str,
    *,
    columns: Sequence[str],
    required: Sequence[str] = (),
    max_rows: int | None = None,
    max_bytes: int | None = None,
) -> CsvTable:
    r"""Parse CSV text: a header naming known columns, then rows of as many cells.

    Blank lines and lines starting with ``#`` are skipped; a quoted cell may not span lines.

    Parameters
    ----------
    text : str
        The CSV text.
    source : str
        The file, for messages.
    columns : sequence of str
        The column names allowed in the header.
    required : sequence of str
        The columns the header must have.
    max_rows : int, optional
        Most data rows accepted (default :data:`MAX_ROWS`).
    max_bytes : int, optional
        Longest text accepted, characters (default :data:`MAX_BYTES`).

    Returns
    -------
    CsvTable
        The header and the rows, with their line numbers.

    Raises
    ------
    FileFormatError
        Naming the line: no header, an unknown, repeated or missing column, a row with
        the wrong number of cells, too many rows, malformed CSV.

    Examples
    --------
    >>> table = parse_csv("\ufefftime, v\n# a comment\n0.5, 1.0\n", "odometry.csv", columns=("time", "v"))
    >>> table.header, table.rows, table.lines
    (('time', 'v'), (('0.5', '1.0'),), (3,))
    >>> parse_csv("time,v\n1,2\n3,4\n", "odometry.csv", columns=("time", "v"), max_rows=1)
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: odometry.csv:3: expected at most 1 data rows, got more
    """
    body = _text(text, source, max_bytes)
    most = _limit(max_rows, MAX_ROWS)
    numbers: list[int] = []
    lines: list[str] = []
    for number, line in enumerate(body.splitlines(), start=1):
        if _is_row(line):
            if len(lines) > most:
                raise FileFormatError(source, "", f"expected at most {most} data rows, got more", line=number)
            numbers.append(number)
            lines.append(line)
    wanted = ", ".join(required or columns)
    if not lines:
        raise FileFormatError(source, "", f"expected a header row naming the columns {wanted}, got none")
    # A space before a quote would make the quote part of the cell: `a, "b, c"` is two cells.
    reader = csv.reader(lines, strict=True, skipinitialspace=True)
    try:
        parsed = list(reader)
    except csv.Error as exc:
        line_number = numbers[min(reader.line_num, len(numbers)) - 1]
        raise FileFormatError(source, "", f"expected CSV, got {exc}", line=line_number) from None
    if len(parsed) != len(lines):
        raise FileFormatError(source, "", "expected one row per line, got a quoted cell spanning lines")
    header = tuple(name.strip().removeprefix(_BOM).strip() for name in parsed[0])
    for index, name in enumerate(header):
        if name not in columns:
            separator = _other_separator(name, columns)
            if separator is not None:
                raise FileFormatError(
                    source,
                    "",
                    f"expected comma-separated values, got a header separated by {separator}",
                    line=numbers[0],
                )
            raise FileFormatError(
                source,
                "",
                f"expected columns from {', '.join(columns)}, got unknown column {describe(name)}",
                line=numbers[0],
            )
        if name in header[:index]:
            raise FileFormatError(
                source, "", f"expected each column once, got {describe(name)} twice", line=numbers[0]
            )
    for name in required:
        if name not in header:
            raise FileFormatError(
                source, "", f"expected a column {name!r}, got columns {', '.join(header)}", line=numbers[0]
            )
    data = parsed[1:]
    if any(width != len(header) for width in set(map(len, data))):  # the first such row named
        for number, cells in zip(numbers[1:], data, strict=True):
            if len(cells) != len(header):
                raise FileFormatError(
                    source, "", f"expected {len(header)} cells, got {len(cells)}", line=number
                )
    rows = tuple([tuple(map(str.strip, cells)) for cells in data])
    return CsvTable(source, header, numbers[0], rows, tuple(numbers[1:]))


def load_csv(
    path: str | os.PathLike[str],
    *,
    columns: Sequence[str],
    required: Sequence[str] = (),
    max_rows: int | None = None,
    max_bytes: int | None = None,
) -> CsvTable:
    """Read and parse a CSV file (:func:`read_text`, :func:`parse_csv`)."""
    text = read_text(path, kind="CSV", max_bytes=max_bytes)
    return parse_csv(
        text, str(path), columns=columns, required=required, max_rows=max_rows, max_bytes=max_bytes
    )


@dataclass(frozen=True, slots=True, eq=False)
class CsvFloats:
    """A CSV file of numbers, parsed column-wise: what :func:`parse_csv_floats` returns.

    Parameters
    ----------
    source : str
        The file, for messages.
    header : tuple of str
        The column names, as :func:`parse_csv` gives them.
    header_line : int
        1-based line of the header.
    values : ndarray, shape (rows, len(header))
        Every cell as a float (``float(cell)``).
    lines : ndarray of int64, shape (rows,)
        1-based line of each row.
    text : str or None
        The text parsed (to quote a cell in a message: :meth:`cell`); None when it was read
        from the file ``source`` block by block (:func:`read_csv_floats`), which
        :meth:`cell` then reads again.
    """

    source: str
    header: tuple[str, ...]
    header_line: int
    values: NDArray[np.float64]
    lines: NDArray[np.int64]
    text: str | None

    def __len__(self) -> int:
        return len(self.lines)

    def cell(self, row: int, column: str) -> str:
        """Return the stripped text of one cell (row index from 0), as :func:`parse_csv` gives it."""
        text = self.text if self.text is not None else read_text(self.source, kind="CSV")
        line = text.removeprefix(_BOM).splitlines()[int(self.lines[row]) - 1]
        return line.split(",")[self.header.index(column)].strip()


_TAB, _LF, _CR, _SPACE, _HASH = 9, 10, 13, 32, 35
# Bytes the fast path leaves to parse_csv: control characters (line breaks that
# str.splitlines knows and "\n" does not, whitespace that str.strip removes) and quotes.
_FORBIDDEN = np.zeros(256, dtype=bool)
_FORBIDDEN[:32] = True
_FORBIDDEN[[_TAB, _LF, _CR]] = False
_FORBIDDEN[ord('"')] = True
_ALLOWED = bytes(np.flatnonzero(~_FORBIDDEN).astype(np.uint8).tolist())
# More lines starting with spaces than this: each is looked at alone, so parse_csv reads the file.
_MOST_INDENTED = 10_000


#: Reads the data rows of a numeric CSV block: ``(data, rows, columns)`` to a
#: ``(rows, columns)`` array, or None when it cannot (see :func:`parse_float_rows`).
RowsParser: TypeAlias = Callable[[bytes, int, int], NDArray[np.float64] | None]

#: What tells two versions of one file apart: its size, bytes, and modification time, ns.
FileVersion: TypeAlias = tuple[int, int]


def parse_csv_floats(
    text: str | bytes,
    source: str,
    *,
    columns: Sequence[str],
    required: Sequence[str] = (),
    max_rows: int | None = None,
    max_bytes: int | None = None,
    parse_rows: RowsParser | None = None,
) -> CsvFloats | None:
    r"""Parse a CSV file of numbers only, without a Python object per cell; None when it cannot.

    The fast path of :func:`parse_csv` for large numeric files (odometry, ground truth):
    the lines are classified (data, blank, ``#`` comment) with numpy and the data rows
    parsed by :func:`numpy.loadtxt`. It returns exactly what :func:`parse_csv` followed by
    ``float()`` of every cell gives, or None whenever it could differ or fail: non-ASCII
    text, quotes, control characters, a ``#`` inside a row, a bad header, an empty or
    non-numeric cell, a row of the wrong length, more than ``max_rows`` rows. The caller
    then parses the text with :func:`parse_csv`, whose message names the line at fault.

    Parameters
    ----------
    text : str or bytes
        The CSV text, or its bytes when they are ASCII (a block of a file: not decoded and
        encoded again; the result then keeps no text, and :meth:`CsvFloats.cell` reads the file).
    source : str
        The file, for messages.
    columns, required, max_rows, max_bytes
        As for :func:`parse_csv`.
    parse_rows : callable or None
        Reads the data rows (:data:`RowsParser`); None: :func:`parse_float_rows`.

    Returns
    -------
    CsvFloats or None
        The header, the values and the line of each row; None to parse with :func:`parse_csv`.

    Raises
    ------
    FileFormatError
        For a text longer than ``max_bytes`` (as :func:`parse_csv`).

    Examples
    --------
    >>> table = parse_csv_floats("# odometry\ntime,v\n0.5, 1.0\n\n1.5,2e-1\n", "o.csv", columns=("time", "v"))
    >>> table.header, table.values.tolist(), table.lines.tolist(), table.cell(1, "v")
    (('time', 'v'), [[0.5, 1.0], [1.5, 0.2]], [3, 5], '2e-1')
    >>> parse_csv_floats("time,v\n0.5,\n", "o.csv", columns=("time", "v")) is None   # an empty cell
    True
    """
    most = _limit(max_rows, MAX_ROWS)
    body: str | None
    if isinstance(text, bytes):
        if len(text) > _limit(max_bytes, MAX_BYTES) or not text.isascii():
            return None  # parse_csv says what is wrong
        body, encoded = None, text
    else:
        body = _text(text, source, max_bytes)
        if not body.isascii():
            return None
        encoded = body.encode("ascii")
    # What is left once the allowed bytes are deleted: a tenth of the time of a lookup per byte.
    if encoded.translate(None, _ALLOWED):
        return None
    raw = np.frombuffer(encoded, dtype=np.uint8)
    returns = np.flatnonzero(raw == _CR) if b"\r" in encoded else np.empty(0, dtype=np.intp)
    if returns.size:
        # "\r\n" ends a line for str.splitlines as "\n" does; a lone "\r" too, which "\n" does not.
        if returns[-1] + 1 >= raw.size or np.any(raw[returns + 1] != _LF):
            return None
        raw = raw[raw != _CR]
    breaks = np.flatnonzero(raw == _LF)
    starts = np.concatenate(([0], breaks + 1))
    ends = np.concatenate((breaks, [raw.size]))
    # The first byte of each line that is not a space or a tab; _LF for a blank line.
    lead = np.full(starts.size, _LF, dtype=np.uint8)
    filled = starts < ends
    lead[filled] = raw[starts[filled]]
    indented = np.flatnonzero((lead == _SPACE) | (lead == _TAB))
    if indented.size > _MOST_INDENTED:
        return None
    for line in indented.tolist():
        piece = raw[starts[line] : ends[line]]
        visible = np.flatnonzero((piece != _SPACE) & (piece != _TAB))
        lead[line] = piece[visible[0]] if visible.size else _LF
    comment = lead == _HASH
    data = (lead != _LF) & ~comment
    # Counted only when there is one ("in" finds a byte many times faster than count counts them).
    if b"#" in encoded and encoded.count(b"#") != np.count_nonzero(comment):
        return None  # a "#" inside a row: parse_csv says what it makes of it
    numbers = np.flatnonzero(data)
    rows = numbers.size - 1
    if rows < 0 or rows > most:
        return None
    head = int(numbers[0])
    try:
        header = parse_csv(
            raw[starts[head] : ends[head]].tobytes().decode("ascii"),
            source,
            columns=columns,
            required=required,
        ).header
    except FileFormatError:
        return None
    lines = (numbers[1:] + 1).astype(np.int64)
    if rows == 0:
        return CsvFloats(source, header, head + 1, np.empty((0, len(header))), lines, body)
    first_row = int(numbers[1])
    if rows == starts.size - first_row or (rows == starts.size - first_row - 1 and lead[-1] == _LF):
        rows_bytes = raw[starts[first_row] :]  # the rows run to the end: no copy of each
    else:
        data[head] = False
        rows_bytes = raw[np.repeat(data, np.diff(np.concatenate((starts, [raw.size]))))]
    values = (parse_rows or parse_float_rows)(rows_bytes.tobytes(), rows, len(header))
    if values is None:
        return None
    return CsvFloats(source, header, head + 1, values, lines, body)


def parse_float_rows(data: bytes, rows: int, columns: int) -> NDArray[np.float64] | None:
    r"""Return ``rows`` lines of ``columns`` comma-separated numbers as an array, or None.

    The reader of :func:`parse_csv_floats` by default, :func:`numpy.loadtxt`; and the
    reference of the compiled one the log readers pass (``aura_ums._native.parse_float_rows``).

    Parameters
    ----------
    data : bytes
        ASCII lines ending in ``"\n"`` (the last one may not), each a data row: no header,
        comment, blank line, quote or ``"\r"``.
    rows, columns : int
        The shape expected, ``rows >= 0``, ``columns >= 1``.

    Returns
    -------
    ndarray of shape (rows, columns), or None
        Each cell's number (as ``float(cell)``); None when a cell is not a number or the
        shape differs.

    Examples
    --------
    >>> parse_float_rows(b"0.5, 1\n-2e-1,3.\n", 2, 2).tolist()
    [[0.5, 1.0], [-0.2, 3.0]]
    >>> parse_float_rows(b"0.5,\n", 1, 2) is None   # an empty cell
    True
    """
    if rows == 0 or not data:  # loadtxt would warn of no data
        return np.empty((0, columns)) if rows == 0 and not data else None
    try:
        # From bytes: numpy reads them in blocks (a str would be copied as 4 bytes a character).
        values = np.loadtxt(
            io.BytesIO(data), delimiter=",", comments=None, quotechar=None, dtype=np.float64, ndmin=2
        )
    except ValueError:
        return None
    return values if values.shape == (rows, columns) else None


def _is_row(line: str) -> bool:
    """Whether a line of CSV text is a row (the header or data): not blank, not a ``#`` comment."""
    stripped = line.strip()
    return bool(stripped) and not stripped.startswith("#")


def _regular_file(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` is a regular file: opening a named pipe would wait for a writer.

    The fast readers then leave the file to :func:`read_bytes`, whose message names it.
    """
    try:
        return stat.S_ISREG(os.stat(path).st_mode)
    except (OSError, ValueError):
        return False


class CsvFallbackError(Exception):
    """Raised by :func:`csv_blocks` for a file it cannot read block by block exactly.

    The caller then reads the whole file (:func:`read_text`, :func:`parse_csv`), whose
    messages name what is wrong, or which reads what the blocks could not.
    """


# Line breaks str.splitlines knows besides "\n" (and "\r\n"): a block holding one would
# number its lines otherwise than parse_csv does.
_OTHER_BREAKS = re.compile("\r(?!\n)|[\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029]")


def csv_blocks(
    path: str | os.PathLike[str],
    *,
    columns: Sequence[str],
    required: Sequence[str] = (),
    numeric: bool,
    max_rows: int | None = None,
    max_bytes: int | None = None,
    block_bytes: int = CSV_BLOCK_BYTES,
    parse_rows: RowsParser | None = None,
    version: FileVersion | None = None,
) -> Iterator[CsvFloats | CsvTable]:
    r"""Read a CSV file ``block_bytes`` at a time and yield each block's rows as they are read.

    Each block is cut after its last line break and parsed below the file's header, so
    the rows, the header and the line numbers (of the file) are exactly those
    :func:`parse_csv` gives for the whole text; the text of a large file is never in
    memory whole, and the rows of one block are dropped once the caller moves on.
    ``numeric`` files are parsed by :func:`parse_csv_floats` (every cell a float),
    others by :func:`parse_csv` (stripped cells). Nothing is yielded for a file without
    data rows (the header only).

    Parameters
    ----------
    path : str or path-like
        The file.
    columns, required, max_rows, max_bytes
        As for :func:`parse_csv`.
    numeric : bool
        Yield :class:`CsvFloats` (every cell a number) rather than :class:`CsvTable`.
    block_bytes : int
        Bytes read at a time, >= 1.
    parse_rows : callable or None
        Reads each block's data rows (:data:`RowsParser`); None: :func:`parse_float_rows`.
    version : FileVersion or None
        The file as it was seen before (:func:`file_version`, when its log was opened):
        a file changed since is refused as soon as it is opened. Either way a file that
        changes while it is read is refused when its end is reached.

    Yields
    ------
    CsvFloats or CsvTable
        One block's rows; ``lines`` are lines of the file, ``text`` (of a
        :class:`CsvFloats`) is None.

    Raises
    ------
    CsvFallbackError
        Whenever a block cannot be read exactly so (a missing, unreadable or too large
        file, text that is not UTF-8 (ASCII when ``numeric``), a line break other than
        ``"\n"``, a bad header, a cell ``parse_csv_floats`` refuses, too many rows), possibly
        after blocks were yielded: the caller reads the whole file instead.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "o.csv"
    >>> _ = path.write_bytes(b"# odometry\ntime,v\n0.5, 1.0\n\n1.5,2e-1\n2.5,3\n")
    >>> [b.lines.tolist() for b in csv_blocks(path, columns=("time", "v"), numeric=True, block_bytes=8)]
    [[], [3], [5], [6]]
    >>> _ = path.write_bytes(b"time,v\n")
    >>> [len(b) for b in csv_blocks(path, columns=("time", "v"), numeric=True)]   # the header alone
    [0]
    >>> _ = path.write_bytes(b"time,v\n0.5,\n")
    >>> list(csv_blocks(path, columns=("time", "v"), numeric=True))   # an empty cell: parse_csv says more
    Traceback (most recent call last):
    ...
    aura_ums._files.CsvFallbackError
    """
    source = str(path)
    limit = _limit(max_bytes, MAX_BYTES)
    most = _limit(max_rows, MAX_ROWS)
    if not _regular_file(path):
        raise CsvFallbackError
    try:
        handle = open(path, "rb")  # noqa: SIM115 - closed below, on every path
    except (OSError, ValueError):
        raise CsvFallbackError from None
    with handle:
        try:
            opened = os.fstat(handle.fileno())
        except OSError:
            raise CsvFallbackError from None
        # The version every later look must find: the one the log was opened on, else this one.
        expected = _version_of(opened) if version is None else version
        if version is not None:
            _unchanged(opened, expected, source, _SINCE_OPENED)
        if opened.st_size > limit:
            raise CsvFallbackError
        header_text: str | None = None
        rows = 0
        lines_before = 0  # lines of the file before the block
        carry = b""
        first = True
        while True:
            try:
                chunk = handle.read(block_bytes)
            except OSError:
                raise CsvFallbackError from None
            if not chunk:
                with contextlib.suppress(OSError):  # nothing to compare: the reading stands
                    now = os.fstat(handle.fileno())
                    _unchanged(now, expected, source, _WHILE_READ)
            data = carry + chunk
            if chunk:
                cut = data.rfind(b"\n") + 1
                if cut == 0:  # no line break yet: read on
                    carry = data
                    continue
                block, carry = data[:cut], data[cut:]
            else:
                block, carry = data, b""
            if first:
                block = block.removeprefix(_BOM.encode("utf-8"))
                first = False
            if numeric and not block.isascii():
                raise CsvFallbackError
            # A numeric block is parsed as its bytes (ASCII): decoded only to find the header.
            text = "" if numeric and header_text is not None else _decoded(block)
            if not numeric and _OTHER_BREAKS.search(text):
                raise CsvFallbackError
            found: CsvFloats | CsvTable | None
            if header_text is None:
                if chunk and not any(_is_row(line) for line in text.splitlines()):
                    carry = block + carry  # comments and blank lines only: the header is further on
                    continue
                found = _parse_block(text, source, columns, required, numeric, most, limit, parse_rows)
                if found is None:
                    raise CsvFallbackError
                header_text = text.splitlines()[found.header_line - 1]
                lines = found.lines
                head = True
            else:
                # The header again before the block: the block's rows read as they would below it.
                found = _parse_block(
                    header_text.encode("ascii") + b"\n" + block if numeric else f"{header_text}\n{text}",
                    source,
                    columns,
                    required,
                    numeric,
                    most - rows,
                    limit,
                    parse_rows,
                )
                if found is None or found.header_line != 1:
                    raise CsvFallbackError
                lines = np.asarray(found.lines, dtype=np.int64) - 1 + lines_before
                head = False
            rows += len(found)
            # numpy counts the line breaks a few times faster than bytes.count.
            lines_before += int(np.count_nonzero(np.frombuffer(block, dtype=np.uint8) == _LF))
            if len(found) or head:
                lines = np.asarray(lines, dtype=np.int64)
                if isinstance(found, CsvFloats):
                    yield CsvFloats(source, found.header, found.header_line, found.values, lines, None)
                else:
                    yield CsvTable(source, found.header, found.header_line, found.rows, tuple(lines.tolist()))
            if not chunk:
                return


def file_version(path: str | os.PathLike[str]) -> FileVersion | None:
    """Return the file's :data:`FileVersion` now, or None when it cannot be looked at."""
    try:
        return _version_of(os.stat(path))
    except OSError:
        return None


def _version_of(status: os.stat_result) -> FileVersion:
    return status.st_size, status.st_mtime_ns


#: How a change is told (compared with, when, what to do): after the log was opened, or during the reading.
_SINCE_OPENED = ("when its log was opened", "since", "open the log again")
_WHILE_READ = ("when it was opened", "while it was read", "read it again once nothing writes to it")


def _unchanged(now: os.stat_result, expected: FileVersion, source: str, told: tuple[str, str, str]) -> None:
    """Refuse a file whose size or modification time is no longer ``expected``.

    Read block by block, a file cut short (or written on) meanwhile would give rows from
    two versions of it, its last one perhaps cut mid-number, and no error: a replay went on
    without the odometry's end and lost the truth with exit 0. Not a fallback: reading the
    whole file again would read the changed one.
    """
    if _version_of(now) != expected:
        raise FileFormatError(
            source,
            "",
            f"expected the file as it was {told[0]} ({expected[0]} bytes), got one changed {told[1]} "
            f"({now.st_size} bytes now); {told[2]}",
        )


def _decoded(block: bytes) -> str:
    try:
        return block.decode("utf-8")
    except UnicodeDecodeError:
        raise CsvFallbackError from None


def _parse_block(
    text: str | bytes,
    source: str,
    columns: Sequence[str],
    required: Sequence[str],
    numeric: bool,
    most: int,
    limit: int,
    parse_rows: RowsParser | None,
) -> CsvFloats | CsvTable | None:
    """One block of :func:`csv_blocks`: its rows, or None when it cannot be read exactly."""
    if numeric:
        return parse_csv_floats(
            text, source, columns=columns, required=required, max_rows=most, max_bytes=limit,
            parse_rows=parse_rows,
        )  # fmt: skip
    if isinstance(text, bytes):  # only numeric blocks come as bytes: not met
        text = text.decode("utf-8")
    try:
        return parse_csv(text, source, columns=columns, required=required, max_rows=most, max_bytes=limit)
    except FileFormatError:
        return None


def read_csv_floats(
    path: str | os.PathLike[str],
    *,
    columns: Sequence[str],
    required: Sequence[str] = (),
    max_rows: int | None = None,
    max_bytes: int | None = None,
    block_bytes: int = CSV_BLOCK_BYTES,
    parse_rows: RowsParser | None = None,
) -> CsvFloats | None:
    r"""Read a CSV file of numbers only block by block (:func:`csv_blocks`); None when it cannot.

    The file is read ``block_bytes`` at a time, each block cut after its last line break,
    so the text of a large file is never in memory whole: only the values and the line
    numbers grow with it. The result is exactly what :func:`parse_csv` and ``float()`` of
    every cell give; None whenever :func:`csv_blocks` cannot read it (at least whenever
    :func:`parse_csv_floats` of the whole text would give None), and for a file that is
    missing, unreadable, larger than ``max_bytes`` or not ASCII: the caller then reads it
    with :func:`read_text` and :func:`parse_csv`, whose messages say what is wrong. The
    result holds no text (:meth:`CsvFloats.cell` reads the file again, for a message).

    Parameters
    ----------
    path : str or path-like
        The file.
    columns, required, max_rows, max_bytes
        As for :func:`parse_csv`.
    block_bytes : int
        Bytes read at a time, >= 1.
    parse_rows : callable or None
        Reads each block's data rows (:data:`RowsParser`); None: :func:`parse_float_rows`.

    Returns
    -------
    CsvFloats or None
        The header, the values and the line of each row; None to read it with :func:`parse_csv`.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "o.csv"
    >>> _ = path.write_bytes(b"\xef\xbb\xbf# odometry\ntime,v\n0.5, 1.0\n\n1.5,2e-1\n2.5,3\n")
    >>> table = read_csv_floats(path, columns=("time", "v"), block_bytes=8)
    >>> table.header, table.values.tolist(), table.lines.tolist(), table.cell(1, "v")
    (('time', 'v'), [[0.5, 1.0], [1.5, 0.2], [2.5, 3.0]], [3, 5, 6], '2e-1')
    >>> _ = path.write_bytes(b"time,v\n0.5,\n")
    >>> read_csv_floats(path, columns=("time", "v")) is None   # an empty cell: parse_csv says more
    True
    """
    if not _regular_file(path):
        return None
    try:
        with open(path, "rb") as handle:
            # Rows are at most the line breaks plus one: the values are written in place, never
            # held twice (as blocks and as their concatenation).
            capacity = 1 + sum(piece.count(b"\n") for piece in iter(lambda: handle.read(block_bytes), b""))
    except (OSError, ValueError):
        return None
    values: NDArray[np.float64] | None = None
    lines = np.empty(capacity, dtype=np.int64)
    header: CsvFloats | None = None
    rows = 0
    try:
        for block in csv_blocks(
            path,
            columns=columns,
            required=required,
            numeric=True,
            max_rows=max_rows,
            max_bytes=max_bytes,
            block_bytes=block_bytes,
            parse_rows=parse_rows,
        ):
            assert isinstance(block, CsvFloats)
            if header is None:
                header = block
                values = np.empty((capacity, len(block.header)))
            assert values is not None
            if rows + len(block) > capacity:  # the file grew since its line breaks were counted
                return None
            values[rows : rows + len(block)] = block.values
            lines[rows : rows + len(block)] = block.lines
            rows += len(block)
    except CsvFallbackError:
        return None
    # The header's block comes first, or CsvFallbackError.
    assert header is not None
    assert values is not None
    return CsvFloats(str(path), header.header, header.header_line, values[:rows], lines[:rows], None)


# --- typed values --------------------------------------------------------------------------


def describe(value: object, syntax: Syntax = "toml") -> str:
    """Name a parsed value in a message: scalars by their (shortened) repr, containers by kind.

    Containers are never printed: a message stays short, whatever the file holds.

    Examples
    --------
    >>> describe("much"), describe(True), describe([1, 2]), describe({}, "json"), describe(None, "json")
    ("'much'", 'true', 'an array', 'an object', 'null')
    >>> describe("x" * 100)
    "'xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx..."
    """
    if value is None:
        return "null" if syntax == "json" else "nothing"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, Mapping):
        return "an object" if syntax == "json" else "a table"
    if isinstance(value, list):
        return "an array"
    if isinstance(value, (str, int, float)):
        text = repr(value) if not isinstance(value, int) or value.bit_length() < 200 else "a huge integer"
    else:  # TOML dates and times
        text = f"a {type(value).__name__} {value}"
    return text if len(text) <= _DESCRIBED_LENGTH else text[: _DESCRIBED_LENGTH - 3] + "..."


def key_path(where: str, key: str) -> str:
    """Return the place of ``key`` inside the table at ``where``.

    A TOML table header is followed by a space, any other place by a dot.

    Examples
    --------
    >>> key_path("[start]", "x"), key_path("[route] commands[0]", "run"), key_path("", "map")
    ('[start] x', '[route] commands[0].run', 'map')
    """
    if not where:
        return key
    if where.startswith("[") and where.endswith("]") and "]" not in where[:-1]:
        return f"{where} {key}"
    return f"{where}.{key}"


@dataclass(frozen=True, slots=True)
class Fields:
    """Typed values pulled from a parsed document; every failure names the file and the place.

    Parameters
    ----------
    source : str
        The file (or a description such as ``"<manager JSON>"``), for messages.
    syntax : {"toml", "json"}
        How containers and null are named in messages ("a table" or "an object").

    Examples
    --------
    >>> fields = Fields("terrain.toml")
    >>> fields.field({"drift": 0.01}, "drift", float, "[grass]")
    0.01
    >>> fields.field({"drift": "much"}, "drift", float, "[grass]")
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: terrain.toml: [grass] drift: expected a finite number, got 'much'
    >>> fields.field({}, "drift", float, "[grass]")
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: terrain.toml: [grass] drift: expected a finite number, got nothing
    """

    source: str
    syntax: Syntax = "toml"

    def error(self, where: str, message: str, *, line: int | None = None) -> FileFormatError:
        """Return the error for ``where`` (raise it)."""
        return FileFormatError(self.source, where, message, line=line)

    def fail(self, where: str, message: str, *, line: int | None = None) -> NoReturn:
        """Raise the error for ``where``."""
        raise self.error(where, message, line=line)

    def describe(self, value: object) -> str:
        """Name ``value`` in a message (see :func:`describe`)."""
        return describe(value, self.syntax)

    def table(self, value: object, where: str) -> dict[str, object]:
        """Return ``value`` as a table (a JSON object)."""
        if not isinstance(value, dict):
            self.fail(where, f"expected {self.describe({})}, got {self.describe(value)}")
        return cast(dict[str, object], value)

    def array(self, value: object, where: str) -> list[object]:
        """Return ``value`` as an array."""
        if not isinstance(value, list):
            self.fail(where, f"expected an array, got {self.describe(value)}")
        return cast(list[object], value)

    def number(self, value: object, where: str) -> float:
        """Return ``value`` as a finite float (an integer or a float, not a boolean)."""
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            try:
                result = float(value)
            except OverflowError:  # an integer beyond the largest float
                result = math.inf
            if math.isfinite(result):
                return result
        self.fail(where, f"expected a finite number, got {self.describe(value)}")

    def positive(self, value: object, where: str) -> float:
        """Return ``value`` as a finite float > 0."""
        result = self.number(value, where)
        if result <= 0.0:
            self.fail(where, f"expected a positive number, got {self.describe(value)}")
        return result

    def nonnegative(self, value: object, where: str) -> float:
        """Return ``value`` as a finite float >= 0."""
        result = self.number(value, where)
        if result < 0.0:
            self.fail(where, f"expected a non-negative number, got {self.describe(value)}")
        return result

    def ranged(self, value: object, where: str, bounds: Range, *, scale: float = 1.0) -> float:
        """Return ``value`` times ``scale`` (a unit's factor to SI) checked in ``bounds``.

        The message quotes the value as written (not scaled).

        Examples
        --------
        >>> from aura_ums._validate import START_RADIUS
        >>> Fields("meta.toml").ranged(2e4, "radius", START_RADIUS)
        Traceback (most recent call last):
        ...
        aura_ums.errors.FileFormatError: meta.toml: radius: expected a number in [0, 10000] m, got 20000.0
        """
        result = self.number(value, where) * scale
        if not bounds.contains(result):
            in_si = "" if scale == 1.0 else f" ({result:g} {bounds.unit})"
            self.fail(where, f"expected {bounds.text()}, got {self.describe(value)}{in_si}")
        return result

    def integer(self, value: object, where: str, minimum: int | None = None) -> int:
        """Return ``value`` as an integer (not a boolean), >= ``minimum`` when given."""
        expected = "an integer" if minimum is None else f"an integer >= {minimum}"
        if isinstance(value, bool) or not isinstance(value, int) or (minimum is not None and value < minimum):
            self.fail(where, f"expected {expected}, got {self.describe(value)}")
        return value

    def string(self, value: object, where: str, *, nonempty: bool = False) -> str:
        """Return ``value`` as a string, non-empty with ``nonempty``."""
        if not isinstance(value, str) or (nonempty and not value):
            self.fail(
                where, f"expected {'a non-empty' if nonempty else 'a'} string, got {self.describe(value)}"
            )
        return value

    def boolean(self, value: object, where: str) -> bool:
        """Return ``value`` as a boolean."""
        if not isinstance(value, bool):
            self.fail(where, f"expected true or false, got {self.describe(value)}")
        return value

    def keys(
        self, table: Mapping[str, object], allowed: Sequence[str], where: str = "", *, noun: str = "key"
    ) -> None:
        """Refuse any key of ``table`` not in ``allowed``, naming the allowed ones."""
        for key in table:
            if key not in allowed:
                self.fail(
                    key_path(where, key),
                    f"expected one of {', '.join(allowed)}, got unknown {noun} {describe(key)}",
                )

    def field(
        self, table: Mapping[str, object], key: str, kind: type[T], where: str = "", default: T | None = None
    ) -> T:
        """Return ``table[key]`` checked as ``kind``, or ``default`` when absent (None: required).

        ``kind`` is one of ``float`` (a finite number; integers accepted), ``int``,
        ``str``, ``bool``, ``dict`` (a table) and ``list`` (an array).
        """
        place = key_path(where, key)
        if key not in table:
            if default is not None:
                return default
            expected = self.describe({}) if kind is dict else _EXPECTED[kind]
            self.fail(place, f"expected {expected}, got nothing")
        value = table[key]
        if kind is float:
            return cast(T, self.number(value, place))
        if kind is int:
            return cast(T, self.integer(value, place))
        if kind is str:
            return cast(T, self.string(value, place))
        if kind is bool:
            return cast(T, self.boolean(value, place))
        if kind is dict:
            return cast(T, self.table(value, place))
        if kind is list:
            return cast(T, self.array(value, place))
        raise TypeError(f"kind: expected float, int, str, bool, dict or list, got {kind!r}")


_EXPECTED: dict[type, str] = {
    float: "a finite number",
    int: "an integer",
    str: "a string",
    bool: "true or false",
    list: "an array",
}


#: Ending of the scratch names beside a target being written (``.<name>.<random>.tmp``).
SCRATCH_SUFFIX = ".tmp"
#: The longest file name, bytes, on the file systems we write to (Linux, macOS, Windows).
NAME_MAX = 255


def scratch_path(target: Path) -> Path:
    """Return a fresh hidden name beside ``target``: ``.<name>.<16 hex digits>.tmp``.

    In the target's folder, so that :func:`os.replace` onto the target is one rename on
    one file system.

    Examples
    --------
    >>> name = scratch_path(Path("out/metrics.json"))
    >>> name.parent.as_posix(), name.name.startswith(".metrics.json."), name.suffix
    ('out', True, '.tmp')
    >>> len(scratch_path(Path("a" * 300 + ".json")).name)   # a name too long for a scratch name: cut
    255
    """
    # The two dots and the random part add 18 bytes, the suffix 4: a long target name is cut
    # (at a whole character) so that the scratch name stays within a file name's 255 bytes.
    kept = os.fsencode(target.name)[: NAME_MAX - 18 - len(SCRATCH_SUFFIX)].decode("utf-8", "ignore")
    return target.with_name(f".{kept}.{secrets.token_hex(8)}{SCRATCH_SUFFIX}")


def is_scratch(path: Path) -> bool:
    """Whether ``path`` is named as :func:`scratch_path` names: a write's scratch file or folder.

    One found where no command runs was left by a process killed outright (``SIGKILL``):
    never an output, and safe to delete.

    Examples
    --------
    >>> is_scratch(scratch_path(Path("out/r.mcap"))), is_scratch(Path("out/r.mcap"))
    (True, False)
    >>> is_scratch(Path(".r.mcap.tmp")), is_scratch(Path(".r.mcap.0123456789abcdef.tmp"))
    (False, True)
    """
    return _SCRATCH_NAME.fullmatch(path.name) is not None


#: The names :func:`scratch_path` gives.
_SCRATCH_NAME = re.compile(r"\..*\.[0-9a-f]{16}" + re.escape(SCRATCH_SUFFIX), re.DOTALL)


@contextmanager
def atomic_path(target: str | os.PathLike[str], *, replace: bool = True) -> Iterator[Path]:
    """Yield a scratch path beside ``target`` to write; when the block ends, it replaces ``target``.

    The folder of ``target`` is created when missing. When the block raises (a
    ``KeyboardInterrupt`` too) the scratch file is removed and ``target`` is left as it
    was. A process killed outright (``SIGKILL``) leaves at most the hidden scratch file:
    never a partial file under the target's name. Without ``replace``, a ``target`` that
    exists when the block ends (made by someone else meanwhile) is kept and
    :class:`FileExistsError` raised: the check and the rename are one step (a hard link).

    Examples
    --------
    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> with atomic_path(folder / "a.txt") as scratch:
    ...     _ = scratch.write_text("whole")
    >>> (folder / "a.txt").read_text(), len(list(folder.iterdir()))
    ('whole', 1)
    >>> with atomic_path(folder / "a.txt") as scratch:          # a failure leaves the old file
    ...     _ = scratch.write_text("part")
    ...     raise OSError("disk full")
    Traceback (most recent call last):
    ...
    OSError: disk full
    >>> (folder / "a.txt").read_text(), len(list(folder.iterdir()))
    ('whole', 1)
    >>> with atomic_path(folder / "a.txt", replace=False) as scratch:   # it exists: kept
    ...     _ = scratch.write_text("new")
    Traceback (most recent call last):
    ...
    FileExistsError: ...
    >>> (folder / "a.txt").read_text(), len(list(folder.iterdir()))
    ('whole', 1)

    A ``target`` that is the scratch path of an enclosing ``atomic_path`` (a writer that
    writes atomically itself, given the scratch file of a caller that does too) is yielded
    as it is: the enclosing one moves it whole onto its own target, or removes it.

    >>> with atomic_path(folder / "b.txt") as outer, atomic_path(outer) as inner:
    ...     _ = inner.write_text("once")
    >>> inner == outer, (folder / "b.txt").read_text()
    (True, 'once')
    """
    final = Path(target)
    if final in _scratch_in_use:
        # A second scratch file beside the first wrote everything twice, and a kill left
        # a scratch of a scratch behind (.r.mcap.<hex>.tmp.<hex>.tmp).
        yield final
        return
    made = make_folders(final.parent)
    scratch = scratch_path(final)
    _scratch_in_use.add(scratch)
    try:
        yield scratch
        if replace:
            os.replace(scratch, final)
        else:
            place_new(scratch, final)
    except BaseException:
        scratch.unlink(missing_ok=True)
        remove_made(made)
        raise
    finally:
        _scratch_in_use.discard(scratch)


# The scratch paths atomic_path has yielded and not yet moved or removed (see there).
_scratch_in_use: set[Path] = set()


def make_folders(folder: Path) -> list[Path]:
    """Create ``folder`` and its missing parents; return the ones this call created, innermost first.

    For an output that may yet fail: :func:`remove_made` takes them away again, so that a
    failed write (a full disk, a Ctrl-C) leaves no empty folder where its output was to go.
    When the creation itself fails, the folders it did create are removed before the
    error is raised.

    Examples
    --------
    >>> import tempfile
    >>> base = Path(tempfile.mkdtemp())
    >>> made = make_folders(base / "a" / "b")
    >>> [path.relative_to(base).as_posix() for path in made]
    ['a/b', 'a']
    >>> make_folders(base / "a")          # there already: nothing made
    []
    >>> remove_made(made)
    >>> list(base.iterdir())
    []
    """
    if os.path.lexists(folder) and not folder.is_dir():
        # mkdir would say "File exists", which reads as if the folder were there.
        raise NotADirectoryError(errno.ENOTDIR, os.strerror(errno.ENOTDIR), str(folder))
    missing: list[Path] = []
    at = folder
    while not os.path.lexists(at) and at.parent != at:
        missing.append(at)
        at = at.parent
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except BaseException:
        remove_made(missing)
        raise
    return missing


def remove_made(folders: Sequence[Path]) -> None:
    """Remove the folders :func:`make_folders` created, innermost first, those still empty."""
    for folder in folders:
        # Not empty (another process wrote there meanwhile), or gone: it stays as it is.
        with contextlib.suppress(OSError):
            folder.rmdir()


def place_new(scratch: Path, final: Path) -> None:
    """Move the file ``scratch`` to ``final``, which must not exist (:class:`FileExistsError` if it does).

    A hard link refuses an existing name in the same step as it makes the new one; on a
    file system without hard links, the check comes just before the rename.

    Examples
    --------
    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> _ = (folder / "a").write_text("a")
    >>> place_new(folder / "a", folder / "b")
    >>> sorted(path.name for path in folder.iterdir())
    ['b']
    """
    try:
        os.link(scratch, final)
    except FileExistsError:
        raise FileExistsError(errno.EEXIST, os.strerror(errno.EEXIST), str(final)) from None
    except OSError as exc:
        if exc.errno not in (errno.EPERM, errno.EOPNOTSUPP, errno.EXDEV, errno.EMLINK):
            raise
        if os.path.lexists(final):
            raise FileExistsError(errno.EEXIST, os.strerror(errno.EEXIST), str(final)) from None
        os.replace(scratch, final)
        return
    scratch.unlink()


def write_text_atomic(target: str | os.PathLike[str], text: str, *, replace: bool = True) -> Path:
    """Write ``text`` (UTF-8) to ``target`` through :func:`atomic_path` and return the path.

    Without ``replace``, an existing ``target`` is kept and :class:`FileExistsError` raised.

    Examples
    --------
    >>> import tempfile
    >>> path = write_text_atomic(Path(tempfile.mkdtemp()) / "new" / "b.csv", "x,1")
    >>> path.read_text(), len(list(path.parent.iterdir()))
    ('x,1', 1)
    """
    final = Path(target)
    # "x": a fresh file that honours the umask (tempfile.mkstemp's 0600 would stay on the result)
    with (
        atomic_path(final, replace=replace) as scratch,
        scratch.open("x", encoding="utf-8", newline="") as stream,
    ):
        stream.write(text)
    return final
