"""The log folder format: ``meta.toml`` and CSV files (see ``docs/log-format.md``).

Reading validates every file once and fails with a :class:`FileFormatError` that names
the file and the line (or the TOML key). Writing uses SI units and ``repr`` floats, so a
written log reads back equal.
"""

from __future__ import annotations

import contextlib
import copy
import csv
import io
import json
import math
import os
import shutil
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, NoReturn, TypeVar

import numpy as np
from numpy.typing import NDArray

from aura_ums import _native
from aura_ums._files import (
    CsvFallbackError,
    CsvFloats,
    CsvTable,
    Fields,
    FileVersion,
    atomic_path,
    csv_blocks,
    describe,
    key_path,
    load_toml,
    make_folders,
    parse_csv,
    present,
    read_csv_floats,
    read_folder,
    read_text,
    remove_made,
    scratch_path,
)
from aura_ums._validate import (
    ANGLE,
    ANGLE_ERROR,
    ANGULAR_SPEED,
    COORDINATE,
    DELAY,
    HEIGHT,
    LENGTH,
    ODOMETRY_SCALE,
    POSITION_UNCERTAINTY,
    ROW_GAP,
    SENSOR_OFFSET,
    SPEED,
    START_RADIUS,
    TIME,
    Range,
)
from aura_ums.errors import FileFormatError, InputError
from aura_ums.logs._log import (
    GroundTruth,
    LogLandmark,
    LogMeta,
    LogObservation,
    Odometry,
    RobotLog,
    printable,
)
from aura_ums.logs._odometry import DEFAULT_MAX_INTERVAL, NO_REVERSE, ReversingError
from aura_ums.manager import PositionReport
from aura_ums.uncertainty import Pose, TurnAndRun

META = "meta.toml"
ODOMETRY = "odometry.csv"
COMMANDS = "commands.csv"
OBSERVATIONS = "observations.csv"
LANDMARKS = "landmarks.csv"
GROUNDTRUTH = "groundtruth.csv"
#: Every file of a log folder, in the order they are described.
LOG_FILES = (META, ODOMETRY, COMMANDS, OBSERVATIONS, LANDMARKS, GROUNDTRUTH)

#: Factors from each unit a ``[units]`` table may name to SI.
LENGTH_UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001, "ft": 0.3048}
ANGLE_UNITS = {"rad": 1.0, "deg": math.pi / 180.0}
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}

# The unit of every number in the files: "length", "angle", "time", a ratio of two, or "" (none).
_ODOMETRY_COLUMNS = {"time": "time", "v": "length/time", "omega": "angle/time"}
_COMMAND_COLUMNS = {"time": "time", "turn": "angle", "run": "length"}
_OBSERVATION_COLUMNS = {
    "time": "time",
    "landmark_id": "text",
    "bearing": "angle",
    "range": "length",
    "bearing_error": "angle",
    "range_error": "length",
}
_LANDMARK_COLUMNS = {
    "id": "text",
    "x": "length",
    "y": "length",
    "position_uncertainty": "length",
    "z_bottom": "length",
    "z_top": "length",
    "symbol": "text",
}
_GROUNDTRUTH_COLUMNS = {"time": "time", "x": "length", "y": "length", "heading": "angle"}
#: The physical range of every numeric column (in SI, after the units), by column name:
#: a name means the same in every file. docs/log-format.md lists them.
COLUMN_RANGES: dict[str, Range] = {
    "time": TIME,
    "v": SPEED,
    "omega": ANGULAR_SPEED,
    "turn": ANGLE,
    "run": LENGTH,
    "bearing": ANGLE,
    "range": LENGTH,
    "bearing_error": ANGLE_ERROR,
    "range_error": LENGTH,
    "x": COORDINATE,
    "y": COORDINATE,
    "heading": ANGLE,
    "position_uncertainty": POSITION_UNCERTAINTY,
    "z_bottom": HEIGHT,
    "z_top": HEIGHT,
}

# meta.toml: table -> key -> (LogMeta field, unit, physical range in SI). The top-level table is "".
_META_KEYS: dict[str, dict[str, tuple[str, str, Range | None]]] = {
    "": {
        "name": ("name", "text", None),
        "terrain": ("terrain", "text", None),
        "source": ("source", "text", None),
    },
    "sensor": {
        "bearing_error": ("bearing_error", "angle", ANGLE_ERROR),
        "range_error": ("range_error", "length", LENGTH),
        "range_error_fraction": ("range_error_fraction", "", Range(0.0, 1.0, high_open=True)),
        "forward": ("sensor_forward", "length", SENSOR_OFFSET),
        "left": ("sensor_left", "length", SENSOR_OFFSET),
    },
    "motion": {
        "delay_s": ("delay_s", "", DELAY),
        "run_scale": ("run_scale", "", ODOMETRY_SCALE),
        "turn_scale": ("turn_scale", "", ODOMETRY_SCALE),
    },
    "start": {
        "x": ("start.x", "length", COORDINATE),
        "y": ("start.y", "length", COORDINATE),
        "heading": ("start.heading", "angle", ANGLE),
        "radius": ("start_radius", "length", START_RADIUS),
        "heading_halfwidth": ("start_heading_halfwidth", "angle", Range(0.0, ANGLE.high, "rad")),
    },
    "landmarks": {
        "z_bottom": ("landmark_z_bottom", "length", HEIGHT),
        "z_top": ("landmark_z_top", "length", HEIGHT),
    },
}
_TABLES = ("units", *(table for table in _META_KEYS if table))
_FIELD_PLACES = {
    target: (f"[{table}] {key}" if table else key)
    for table, keys in _META_KEYS.items()
    for key, (target, _, _) in keys.items()
}
_FIELD_PLACES["start"] = "[start]"

#: Largest CSV file of a log, bytes (256 MiB), above :data:`aura_ums._files.MAX_BYTES`: a log
#: may hold up to :data:`aura_ums._files.MAX_ROWS` (2,000,000) rows, and a ground-truth row
#: written with ``repr`` floats (as :func:`write_log` writes) takes up to ~80 bytes.
LOG_CSV_MAX_BYTES = 256 * 1024 * 1024

#: Bytes a streamed replay reads of a log's CSV file at a time (:func:`aura_ums.logs.open_log`):
#: its rows, parsed, cost a few times that while they are in use, whatever the log's length.
STREAM_BLOCK_BYTES = 512 * 1024

#: Most data rows of a log's CSV file read block by block (:func:`aura_ums.logs.open_log`):
#: above :data:`aura_ums._files.MAX_ROWS`, which bounds what a whole file costs in memory.
#: (A file the blocks cannot read is read whole, under that bound.)
STREAM_MAX_ROWS = 100_000_000

#: Line of the first data row in the CSV files :func:`write_log` writes (a comment, then the header).
FIRST_ROW_LINE = 3


@dataclass(frozen=True, slots=True)
class Units:
    """Factors from a log's file units to SI.

    Parameters
    ----------
    length, angle, time : float
        Metres per length unit, radians per angle unit, seconds per time unit.
    """

    length: float = 1.0
    angle: float = 1.0
    time: float = 1.0

    def factor(self, unit: str) -> float:
        """Return the factor of a unit expression: "", "length", "angle/time", ..."""
        if unit in ("", "text"):
            return 1.0
        numerator, _, denominator = unit.partition("/")
        value: float = getattr(self, numerator)
        return value / getattr(self, denominator) if denominator else value


# --- reading -----------------------------------------------------------------------------------


class _CsvFile:
    """One CSV file: its path for messages, its columns and their line numbers.

    A file of numbers only is read block by block and parsed column-wise
    (:func:`read_csv_floats`: no Python object per cell, never the whole text in memory);
    any other file, or one that the fast path cannot read exactly, cell by cell
    (:func:`read_text`, :func:`parse_csv`).
    """

    def __init__(
        self,
        path: Path,
        columns: Mapping[str, str],
        required: Sequence[str],
        block: CsvFloats | CsvTable | None = None,
    ) -> None:
        self.source = str(path)
        self.units = columns
        self.cells: dict[str, list[str]] = {}
        self.values: dict[str, NDArray[np.float64]] | None = None
        self.fast: CsvFloats | None = None
        if isinstance(block, CsvFloats):
            self.fast = block
        elif block is None and all(unit != "text" for unit in columns.values()):
            self.fast = read_csv_floats(
                path,
                columns=tuple(columns),
                required=required,
                max_bytes=LOG_CSV_MAX_BYTES,
                parse_rows=_native.parse_float_rows,
            )
        if self.fast is not None:
            self.lines: NDArray[np.int64] | tuple[int, ...] = self.fast.lines
            self.header = self.fast.header
            self.values = {name: self.fast.values[:, index] for index, name in enumerate(self.fast.header)}
        else:
            if block is None:
                text = read_text(path, kind="CSV", max_bytes=LOG_CSV_MAX_BYTES)
                block = parse_csv(
                    text, self.source, columns=tuple(columns), required=required, max_bytes=LOG_CSV_MAX_BYTES
                )
            assert isinstance(block, CsvTable)
            self.lines = block.lines
            self.header = block.header
            self.cells = block.columns()

    @classmethod
    def blocks(
        cls,
        path: Path,
        columns: Mapping[str, str],
        required: Sequence[str],
        block_bytes: int,
        version: FileVersion | None = None,
    ) -> Iterator[_CsvFile]:
        """Yield the file's rows block by block (:func:`csv_blocks`), each block a table of its own.

        A file the blocks cannot read exactly is read whole (its message, when it is
        malformed, is that of the whole file), and only its rows after those already
        yielded are yielded.
        """
        numeric = all(unit != "text" for unit in columns.values())
        done = 0  # the last line yielded
        try:
            for block in csv_blocks(
                path,
                columns=tuple(columns),
                required=required,
                numeric=numeric,
                max_rows=STREAM_MAX_ROWS,
                max_bytes=LOG_CSV_MAX_BYTES,
                block_bytes=block_bytes,
                parse_rows=_native.parse_float_rows,
                version=version,
            ):
                table = cls(path, columns, required, block)
                if len(table):
                    done = int(table.lines[-1])
                yield table
        except CsvFallbackError:
            whole = cls(path, columns, required, _text_table(path, columns, required))
            yield whole.after(done)

    def after(self, line: int) -> _CsvFile:
        """Return this table's rows after line ``line`` (all of them for 0)."""
        first = int(np.searchsorted(np.asarray(self.lines, dtype=np.int64), line, side="right"))
        table = copy.copy(self)
        table.lines = self.lines[first:]
        assert self.fast is None  # the whole file read cell by cell
        table.cells = {name: cells[first:] for name, cells in self.cells.items()}
        return table

    def __len__(self) -> int:
        return len(self.lines)

    def cell(self, column: str, row: int) -> str:
        """Return one cell's stripped text (row index from 0)."""
        return self.fast.cell(row, column) if self.fast is not None else self.cells[column][row]

    def fail(self, where: str, message: str) -> NoReturn:
        raise FileFormatError(self.source, where, message)

    def fail_at(self, row: int, message: str) -> NoReturn:
        raise FileFormatError(self.source, "", message, line=int(self.lines[row]))

    def numbers(self, column: str, units: Units, *, optional: bool = False) -> NDArray[np.float64]:
        """Return a column as finite floats in SI; with ``optional``, NaN where absent or empty."""
        factor = units.factor(self.units[column])
        if column not in self.header:
            return np.full(len(self), np.nan)
        if self.values is not None:
            # The fast path read every cell as a number: none is empty.
            values = self.values[column]
            bad = ~np.isfinite(values)
            if np.any(bad):
                row = int(np.argmax(bad))
                cell = describe(self.cell(column, row))
                self.fail_at(row, f"expected a finite number in column {column!r}, got {cell}")
            # No copy in SI already (x * 1.0 is x): a long log's columns are large.
            result: NDArray[np.float64] = values if factor == 1.0 else values * factor
        else:
            cells = self.cells[column]
            # float() reads "0_03" as 3.0 (Python's digit grouping) and full-width or Arabic-Indic
            # digits as digits: no CSV writer means either.
            # Looked for in all the cells at once first (the usual case: none), then row by row.
            joined = "".join(cells)
            grouped = None
            if "_" in joined or not joined.isascii():
                grouped = next(row for row, cell in enumerate(cells) if "_" in cell or not cell.isascii())
            if grouped is not None:
                got = describe(cells[grouped])
                self.fail_at(grouped, f"expected a number in column {column!r}, got {got}")
            try:
                if optional and "" in cells:
                    values = np.array([float(cell) if cell else math.nan for cell in cells])
                else:  # every cell read (an empty one refused by float, as below)
                    values = np.array(list(map(float, cells)))
            except ValueError:
                for row, cell in enumerate(cells):
                    try:
                        float(cell)
                    except ValueError:
                        self.fail_at(row, f"expected a number in column {column!r}, got {describe(cell)}")
                raise  # pragma: no cover - the loop above finds the cell
            values = values.reshape(-1)
            bad = ~np.isfinite(values)
            if optional:
                bad &= np.array([cell != "" for cell in cells], dtype=bool)
            if np.any(bad):
                row = int(np.argmax(bad))
                self.fail_at(
                    row, f"expected a finite number in column {column!r}, got {describe(cells[row])}"
                )
            result = values * factor
        bounds = COLUMN_RANGES[column]
        outside = ~(np.isnan(result) | _within(result, bounds))
        if np.any(outside):
            row = int(np.argmax(outside))
            in_si = "" if factor == 1.0 else f" ({float(result[row]):g} {bounds.unit})"
            cell = describe(self.cell(column, row))
            self.fail_at(row, f"expected {bounds.text()} in column {column!r}, got {cell}{in_si}")
        return result

    def texts(self, column: str) -> list[str]:
        """Return a column of non-empty strings."""
        cells = self.cells[column]
        if "" in cells:  # the first empty one named
            self.fail_at(cells.index(""), f"expected a non-empty {column} in column {column!r}, got ''")
        return cells

    def at_least(self, column: str, values: NDArray[np.float64], *, positive: bool = False) -> None:
        """Check a column (NaN for not given) is >= 0, or > 0 with ``positive``."""
        bad = values <= 0.0 if positive else values < 0.0
        if np.any(bad):
            row = int(np.argmax(bad))
            expected = f"a positive {column}" if positive else f"a {column} >= 0"
            self.fail_at(row, f"expected {expected}, got {describe(self.cell(column, row))}")

    def times(self, units: Units, *, strict: bool) -> NDArray[np.float64]:
        """Return the ``time`` column in seconds, checked increasing (strictly or not)."""
        time = self.numbers("time", units)
        steps = np.diff(time)
        bad = steps <= 0.0 if strict else steps < 0.0
        if np.any(bad):
            row = int(np.argmax(bad)) + 1
            order = "strictly increasing" if strict else "non-decreasing"
            self.fail_at(
                row,
                f"expected {order} times, got {describe(self.cell('time', row))} after "
                f"{describe(self.cell('time', row - 1))} (line {int(self.lines[row - 1])})",
            )
        return time

    def no_clock_jump(self, time: NDArray[np.float64], *, held: bool = True) -> None:
        """Refuse a clock jump between two rows (:func:`clock_jump`), naming the later row's line."""
        jump = clock_jump(time, np.asarray(self.lines, dtype=np.int64), held=held)
        if jump is not None:
            self.fail_at(jump[0], jump[1])

    def need_rows(self) -> None:
        if not len(self.lines):
            self.fail("", "expected at least one data row, got none")


def plural(count: int, word: str) -> str:
    """Return ``"1 word"`` or ``"n words"`` (an importer's notes)."""
    return f"{count} {word}{'' if count == 1 else 's'}"


def clock_jump(time: NDArray[np.float64], lines: NDArray[np.int64], *, held: bool) -> tuple[int, str] | None:
    """Find the first gap between two rows longer than :data:`~aura_ums._validate.ROW_GAP` allows.

    The one rule for every file of rows in time (``odometry.csv``, ``commands.csv``,
    ``observations.csv``, ``groundtruth.csv`` and MRCLAM's ``.dat`` files). An odometry
    row's velocities hold until the next row (``held``), and a replay cuts the motion at
    least every :data:`~aura_ums.logs._odometry.DEFAULT_MAX_INTERVAL` seconds: a gap of
    days is a clock jump, and would become millions of steps. A recorded command, an
    observation or a ground-truth pose is one instant, but a day between two of them is
    the same clock jump, which would put every later row out of step with the others.
    Real logs stay far below the limit (MRCLAM's longest gaps: about 3 minutes without
    a measurement, 1.4 s of odometry, 0.33 s of ground truth).

    Parameters
    ----------
    time : ndarray of float
        The rows' times, seconds, in file order (a gap backwards is not a jump).
    lines : ndarray of int
        Each row's line in its file, for the message.
    held : bool
        Whether a row holds until the next (the message then estimates the replay's steps).

    Returns
    -------
    tuple of (int, str) or None
        The index of the row after the jump and the message, or None without a jump.

    Examples
    --------
    >>> lines = np.array([2, 3, 4])
    >>> clock_jump(np.array([0.0, 1.0, 90_000.0]), lines, held=False)
    (2, 'expected at most 86400 s after the previous row (line 3), got a clock jump of 89999 s (1.0 days)')
    >>> clock_jump(np.array([0.0, 86_400.0, 1.0]), lines, held=True) is None  # a day exactly; a step back
    True
    """
    gaps = np.diff(time)
    jumps = gaps > ROW_GAP.high
    if not np.any(jumps):
        return None
    row = int(np.argmax(jumps)) + 1
    gap = float(gaps[row - 1])
    replayed = (
        f"; replayed, about {math.ceil(gap / DEFAULT_MAX_INTERVAL)} steps of {DEFAULT_MAX_INTERVAL:g} s"
        if held
        else ""
    )
    return row, (
        f"expected at most {ROW_GAP.high:g} s after the previous row (line {int(lines[row - 1])}), "
        f"got a clock jump of {gap:g} s ({gap / 86_400.0:.1f} days{replayed})"
    )


def _text_table(path: Path, columns: Mapping[str, str], required: Sequence[str]) -> CsvTable:
    """Read a CSV file of a log whole and cell by cell (the reader whose messages name the line)."""
    text = read_text(path, kind="CSV", max_bytes=LOG_CSV_MAX_BYTES)
    return parse_csv(text, str(path), columns=tuple(columns), required=required, max_bytes=LOG_CSV_MAX_BYTES)


def _within(values: NDArray[np.float64], bounds: Range) -> NDArray[np.bool_]:
    above = values > bounds.low if bounds.low_open else values >= bounds.low
    below = values < bounds.high if bounds.high_open else values <= bounds.high
    result: NDArray[np.bool_] = above & below
    return result


def _given(values: NDArray[np.float64]) -> list[float | None]:
    absent = np.isnan(values)
    if not absent.any():
        return values.tolist()  # type: ignore[no-any-return]
    if absent.all():  # a column the file does not have
        return [None] * len(values)
    return [None if math.isnan(value) else value for value in values.tolist()]


class _MetaReader:
    def __init__(self, path: Path) -> None:
        self.source = str(path)
        self.fields = Fields(self.source)
        self.document = load_toml(path, kind="log metadata TOML")

    def fail(self, where: str, message: str) -> NoReturn:
        raise FileFormatError(self.source, where, message)

    def units(self) -> Units:
        table = self.fields.table(self.document.get("units", {}), "[units]")
        choices = {"length": LENGTH_UNITS, "angle": ANGLE_UNITS, "time": TIME_UNITS}
        self.fields.keys(table, tuple(choices), "[units]")
        factors: dict[str, float] = {}
        for key, value in table.items():
            if not isinstance(value, str) or value not in choices[key]:
                allowed = ", ".join(map(repr, choices[key]))
                self.fail(f"[units] {key}", f"expected one of {allowed}, got {self.fields.describe(value)}")
            factors[key] = choices[key][value]
        return Units(**factors)

    def read(self, default_name: str) -> tuple[LogMeta, Units]:
        units = self.units()
        values: dict[str, object] = {}
        for key, value in self.document.items():
            if key in _TABLES:
                table = self.fields.table(value, f"[{key}]")
                if key != "units":
                    for inner, item in table.items():
                        self.value(key, inner, item, units, values)
            elif key in _META_KEYS[""]:
                self.value("", key, value, units, values)
            else:
                self.fields.keys({key: value}, [*_META_KEYS[""], *(f"[{table}]" for table in _TABLES)])
        pose = {
            axis: values.pop(f"start.{axis}") for axis in ("x", "y", "heading") if f"start.{axis}" in values
        }
        if pose and len(pose) != 3:
            given = " and ".join(pose)
            self.fail("[start]", f"expected x, y and heading together (or none of them), got only {given}")
        if pose:
            values["start"] = Pose(pose["x"], pose["y"], pose["heading"])  # type: ignore[arg-type]
        values.setdefault("name", printable(default_name))  # a folder name may hold a line break
        try:
            meta = LogMeta(**values)  # type: ignore[arg-type]
        except InputError as exc:
            name, _, message = str(exc).partition(": ")
            field = name.removeprefix("LogMeta.")
            self.fail(_FIELD_PLACES.get(field, field), message)
        return meta, units

    def value(self, table: str, key: str, value: object, units: Units, values: dict[str, object]) -> None:
        keys = _META_KEYS[table]
        self.fields.keys({key: value}, tuple(keys), f"[{table}]" if table else "")
        where = key_path(f"[{table}]" if table else "", key)
        target, unit, bounds = keys[key]
        if bounds is None:
            values[target] = self.fields.string(value, where)
            return
        values[target] = self.fields.ranged(value, where, bounds, scale=units.factor(unit))


def load_log(folder: str | os.PathLike[str]) -> RobotLog:
    r"""Read a log folder (see ``docs/log-format.md``), validating every file.

    Parameters
    ----------
    folder : str or path-like
        The folder holding ``meta.toml``, ``observations.csv``, ``landmarks.csv``, exactly
        one of ``odometry.csv`` and ``commands.csv``, and optionally ``groundtruth.csv``.

    Returns
    -------
    RobotLog
        The log in SI units, its ``path`` set to ``folder``.

    Raises
    ------
    FileFormatError
        Naming the file and the line (or TOML key) and saying what was expected and what
        was found: missing files or columns, unknown columns or keys, cells that are not
        finite numbers, unsorted times, unknown or duplicate landmark ids, negative runs,
        both odometry and commands, values out of range.

    Examples
    --------
    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> _ = (folder / "meta.toml").write_text('name = "demo"\n[units]\nangle = "deg"\n')
    >>> _ = (folder / "landmarks.csv").write_text("id,x,y\npole,3.0,0.0\n")
    >>> _ = (folder / "observations.csv").write_text("time,landmark_id,bearing\n0.5,pole,90\n")
    >>> _ = (folder / "commands.csv").write_text("time,turn,run\n1.0,0.0,0.5\n")
    >>> log = load_log(folder)
    >>> log.observations[0].bearing == math.pi / 2, log.commands[0].command.run
    (True, 0.5)
    >>> _ = (folder / "observations.csv").write_text("time,landmark_id,bearing\n0.5,post,90\n")
    >>> load_log(folder)      # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: .../observations.csv:2: expected a landmark id ..., got 'post'
    """
    base = read_folder(folder, kind="log folder")
    meta, units = _MetaReader(base / META).read(base.name)
    landmarks = _read_landmarks(base / LANDMARKS, units)
    observations = _read_observations(base / OBSERVATIONS, units, {item.id for item in landmarks})
    has_odometry, has_commands = present(base / ODOMETRY), present(base / COMMANDS)
    if has_odometry == has_commands:
        got = "both" if has_odometry else "neither"
        raise FileFormatError(str(base), "", f"expected exactly one of {ODOMETRY} and {COMMANDS}, got {got}")
    odometry = _read_odometry(base / ODOMETRY, units) if has_odometry else None
    commands = None if has_odometry else _read_commands(base / COMMANDS, units)
    groundtruth = _read_groundtruth(base / GROUNDTRUTH, units) if present(base / GROUNDTRUTH) else None
    log = RobotLog(meta, landmarks, observations, odometry, commands, groundtruth, base)
    motion = ODOMETRY if has_odometry else COMMANDS
    problem = log.unaligned_clocks(
        {"motion": motion, "observations": OBSERVATIONS, "ground truth": GROUNDTRUTH}
    )
    if problem is not None:
        raise FileFormatError(str(base), "", problem)
    return log


def _read_landmarks(path: Path, units: Units) -> tuple[LogLandmark, ...]:
    table = _CsvFile(path, _LANDMARK_COLUMNS, ("id", "x", "y"))
    ids = table.texts("id")
    first: dict[str, int] = {}
    for row, ident in enumerate(ids):
        if ident in first:
            earlier = table.lines[first[ident]]
            table.fail_at(row, f"expected a unique id, got {describe(ident)} again (first at line {earlier})")
        first[ident] = row
    x, y = table.numbers("x", units), table.numbers("y", units)
    uncertainty = table.numbers("position_uncertainty", units, optional=True)
    table.at_least("position_uncertainty", uncertainty)
    bottom = table.numbers("z_bottom", units, optional=True)
    top = table.numbers("z_top", units, optional=True)
    upside_down = top < bottom
    if np.any(upside_down):
        row = int(np.argmax(upside_down))
        bottom_cell, top_cell = table.cells["z_bottom"][row], table.cells["z_top"][row]
        table.fail_at(row, f"expected z_top >= z_bottom ({bottom_cell}), got {describe(top_cell)}")
    symbols = table.cells.get("symbol", [""] * len(table))
    result = []
    for row, (ident, u, zb, zt) in enumerate(
        zip(ids, _given(uncertainty), _given(bottom), _given(top), strict=True)
    ):
        try:
            result.append(
                LogLandmark(ident, float(x[row]), float(y[row]), u or 0.0, zb, zt, symbols[row] or "landmark")
            )
        except InputError as exc:
            table.fail_at(row, str(exc).partition(": ")[2])
    return tuple(result)


#: The columns of a block of ``observations.csv``: time (s), landmark id, bearing (rad),
#: range (m; NaN when not given), bearing_error (rad; NaN), range_error (m; NaN), file line.
ObservationColumns = tuple[
    NDArray[np.float64], list[str], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64],
    NDArray[np.float64], NDArray[np.int64],
]  # fmt: skip


def _observation_columns(table: _CsvFile, units: Units, known: set[str]) -> ObservationColumns:
    """Check and convert the rows of one table (a whole file or a block) of ``observations.csv``."""
    times = table.times(units, strict=False)
    table.no_clock_jump(times, held=False)
    ids = table.texts("landmark_id")
    if not known.issuperset(ids):  # the first row of an unknown one named
        for row, ident in enumerate(ids):
            if ident not in known:
                table.fail_at(row, f"expected a landmark id listed in {LANDMARKS}, got {describe(ident)}")
    bearing = table.numbers("bearing", units)
    measured = table.numbers("range", units, optional=True)
    bearing_error = table.numbers("bearing_error", units, optional=True)
    range_error = table.numbers("range_error", units, optional=True)
    table.at_least("range", measured)
    table.at_least("bearing_error", bearing_error, positive=True)
    table.at_least("range_error", range_error)
    lines = np.asarray(table.lines, dtype=np.int64)
    return times, ids, bearing, measured, bearing_error, range_error, lines


def _read_observations(path: Path, units: Units, known: set[str]) -> tuple[LogObservation, ...]:
    table = _CsvFile(path, _OBSERVATION_COLUMNS, ("time", "landmark_id", "bearing"))
    times, ids, bearing, measured, bearing_error, range_error, lines = _observation_columns(
        table, units, known
    )
    # Every column was checked above, as LogObservation checks each value.
    return tuple(
        LogObservation._checked(*values)
        for values in zip(
            times.tolist(),
            ids,
            bearing.tolist(),
            _given(measured),
            _given(bearing_error),
            _given(range_error),
            lines.tolist(),
            strict=True,
        )
    )


def observation_blocks(
    path: Path,
    units: Units,
    known: set[str],
    block_bytes: int = STREAM_BLOCK_BYTES,
    version: FileVersion | None = None,
) -> Iterator[ObservationColumns]:
    """Yield the checked columns of ``observations.csv`` block by block (:meth:`_CsvFile.blocks`).

    Each block is checked as :func:`load_log` checks the whole file, and its times
    against the previous block's (in order, without a clock jump); when a check fails,
    the whole file is read again, so the message is exactly :func:`load_log`'s (naming
    the fault it finds first).
    """

    def whole() -> None:
        _read_observations(path, units, known)

    tables = _CsvFile.blocks(
        path, _OBSERVATION_COLUMNS, ("time", "landmark_id", "bearing"), block_bytes, version
    )
    yield from _checked_blocks(
        tables, lambda table: _observation_columns(table, units, known), whole, strict=False, need_rows=False
    )


#: A block's checked columns, its times first (observations, odometry, ground truth).
ColumnsT = TypeVar("ColumnsT", bound=tuple[Any, ...])


def _checked_blocks(
    tables: Iterator[_CsvFile],
    columns_of: Callable[[_CsvFile], ColumnsT],
    whole: Callable[[], object],
    *,
    strict: bool,
    need_rows: bool,
) -> Iterator[ColumnsT]:
    """Yield each block's checked columns (time first), checked across blocks as the whole file is.

    Across two blocks, as within one: times in order (``strict``: increasing) and no clock
    jump (:func:`clock_jump`'s limit); ``need_rows``: at least one row. A failing check
    fails as ``whole`` (the whole file's reader) fails, with its message.
    """
    previous = math.nan
    for table in tables:
        with _as_whole(whole):
            columns = columns_of(table)
        time = columns[0]
        if time.size:
            if not math.isnan(previous):
                gap = float(time[0]) - previous
                if gap < 0.0 or (strict and gap == 0.0) or gap > ROW_GAP.high:
                    _whole_fails(whole)
            previous = float(time[-1])
            yield columns
    if need_rows and math.isnan(previous):
        _whole_fails(whole)  # no rows


@contextlib.contextmanager
def _as_whole(whole: Callable[[], object]) -> Iterator[None]:
    """Fail as the whole file's reader fails when a block's check fails."""
    try:
        yield
    except FileFormatError:
        _whole_fails(whole)


def _whole_fails(whole: Callable[[], object]) -> NoReturn:
    whole()  # raises the whole file's message
    raise AssertionError("a block failed a check the whole file passes")  # pragma: no cover


def _read_odometry(path: Path, units: Units) -> Odometry:
    table = _CsvFile(path, _ODOMETRY_COLUMNS, ("time", "v", "omega"))
    table.need_rows()
    return Odometry(*_odometry_columns(table, units))


OdometryColumns = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]


def _odometry_columns(table: _CsvFile, units: Units) -> OdometryColumns:
    time = table.times(units, strict=True)
    table.no_clock_jump(time)
    return time, table.numbers("v", units), table.numbers("omega", units)


def reversed_at(path: Path, refused: ReversingError) -> FileFormatError:
    """Return the refusal of a negative forward velocity naming its file and line.

    The replay knows the row's index in the record, not its line: the file's data lines
    are read again (on this error path only) to find it.
    """
    line = int(np.asarray(_CsvFile(path, _ODOMETRY_COLUMNS, ("time", "v", "omega")).lines)[refused.row])
    return FileFormatError(
        str(path),
        "",
        f"expected forward velocities >= 0 in column 'v' ({NO_REVERSE}), got {refused.value!r}",
        line=line,
    )


def odometry_blocks(
    path: Path, units: Units, block_bytes: int = STREAM_BLOCK_BYTES, version: FileVersion | None = None
) -> Iterator[OdometryColumns]:
    """Yield the checked time (s), v (m/s) and omega (rad/s) of ``odometry.csv`` block by block.

    Checked as :func:`load_log` checks the whole file (times strictly increasing and
    without clock jumps across blocks too); a failing check fails with the whole file's
    message. At least one block is yielded.
    """

    def whole() -> None:
        _read_odometry(path, units)

    tables = _CsvFile.blocks(path, _ODOMETRY_COLUMNS, ("time", "v", "omega"), block_bytes, version)
    yield from _checked_blocks(
        tables, lambda table: _odometry_columns(table, units), whole, strict=True, need_rows=True
    )


def _read_commands(path: Path, units: Units) -> tuple[PositionReport, ...]:
    table = _CsvFile(path, _COMMAND_COLUMNS, ("time", "turn", "run"))
    table.need_rows()  # as odometry.csv: without a motion the replay had no start time (nan)
    times = table.times(units, strict=True)
    table.no_clock_jump(times, held=False)
    turn, run = table.numbers("turn", units), table.numbers("run", units)
    table.at_least("run", run)
    return tuple(
        PositionReport(when, TurnAndRun(angle, distance))
        for when, angle, distance in zip(times.tolist(), turn.tolist(), run.tolist(), strict=True)
    )


def _read_groundtruth(path: Path, units: Units) -> GroundTruth:
    table = _CsvFile(path, _GROUNDTRUTH_COLUMNS, ("time", "x", "y", "heading"))
    table.need_rows()
    return GroundTruth(*_groundtruth_columns(table, units))


TruthColumns = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]


def _groundtruth_columns(table: _CsvFile, units: Units) -> TruthColumns:
    time = table.times(units, strict=True)
    table.no_clock_jump(time, held=False)
    return time, table.numbers("x", units), table.numbers("y", units), table.numbers("heading", units)


def groundtruth_blocks(
    path: Path, units: Units, block_bytes: int = STREAM_BLOCK_BYTES, version: FileVersion | None = None
) -> Iterator[TruthColumns]:
    """Yield the checked time (s), x, y (m) and heading (rad) of ``groundtruth.csv`` block by block.

    Checked as :func:`load_log` checks the whole file (times strictly increasing and
    without clock jumps across blocks too); a failing check fails with the whole file's
    message. At least one block is yielded.
    """

    def whole() -> None:
        _read_groundtruth(path, units)

    tables = _CsvFile.blocks(path, _GROUNDTRUTH_COLUMNS, ("time", "x", "y", "heading"), block_bytes, version)
    yield from _checked_blocks(
        tables, lambda table: _groundtruth_columns(table, units), whole, strict=True, need_rows=True
    )


# --- writing -----------------------------------------------------------------------------------


def _toml_string(text: str) -> str:
    return json.dumps(text, ensure_ascii=False).replace("\x7f", "\\u007f")


def _meta_toml(meta: LogMeta) -> str:
    lines = [
        "# aura-ums log metadata (docs/log-format.md)",
        f"name = {_toml_string(meta.name)}",
        f"terrain = {_toml_string(meta.terrain)}",
        f"source = {_toml_string(meta.source)}",
        "",
        "[units]",
        'length = "m"',
        'angle = "rad"',
        'time = "s"',
        "",
        "[sensor]",
        f"bearing_error = {meta.bearing_error!r}",
        f"range_error = {meta.range_error!r}",
        f"range_error_fraction = {meta.range_error_fraction!r}",
        f"forward = {meta.sensor_forward!r}",
        f"left = {meta.sensor_left!r}",
        "",
        "[motion]",
        f"delay_s = {meta.delay_s!r}",
        f"run_scale = {meta.run_scale!r}",
        f"turn_scale = {meta.turn_scale!r}",
        "",
        "[start]",
    ]
    if meta.start is not None:
        lines += [f"x = {meta.start.x!r}", f"y = {meta.start.y!r}", f"heading = {meta.start.heading!r}"]
    lines += [
        f"radius = {meta.start_radius!r}",
        f"heading_halfwidth = {meta.start_heading_halfwidth!r}",
        "",
        "[landmarks]",
        f"z_bottom = {meta.landmark_z_bottom!r}",
        f"z_top = {meta.landmark_z_top!r}",
        "",
    ]
    return "\n".join(lines)


def _cell(value: object) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(value)
    return str(value)


def _csv_text(title: str, header: Sequence[str], rows: Iterator[Sequence[object]]) -> str:
    buffer = io.StringIO()
    buffer.write(f"# {title}\n")
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    for row in rows:
        writer.writerow([_cell(value) for value in row])
    lines = buffer.getvalue().split("\n")
    for index in range(2, len(lines)):
        if lines[index].startswith("#"):  # an id starting with '#' is not a comment: quote it
            first, comma, rest = lines[index].partition(",")
            lines[index] = f'"{first}"{comma}{rest}'
    return "\n".join(lines)


def _floats(array: np.ndarray) -> list[float]:
    return [float(value) for value in array]


def log_files_in(folder: str | os.PathLike[str]) -> tuple[str, ...]:
    """Return the names of the log files that ``folder`` holds, in the format's order.

    Parameters
    ----------
    folder : str or path-like
        Any path; a missing folder (or a file) holds no log files.

    Returns
    -------
    tuple of str
        Among ``meta.toml``, ``odometry.csv``, ``commands.csv``, ``observations.csv``,
        ``landmarks.csv`` and ``groundtruth.csv``, those present; empty when none is.
        :func:`write_log` refuses such a folder unless told to overwrite.

    Examples
    --------
    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> log_files_in(folder), log_files_in(folder / "missing")
    ((), ())
    >>> _ = (folder / "landmarks.csv").write_text(""), (folder / "meta.toml").write_text("")
    >>> log_files_in(folder)
    ('meta.toml', 'landmarks.csv')
    """
    base = Path(folder)
    return tuple(name for name in LOG_FILES if present(base / name))


def write_log(
    log: RobotLog,
    folder: str | os.PathLike[str],
    *,
    overwrite: bool = False,
    progress: Callable[[int, int], None] | None = None,
) -> Path:
    """Write ``log`` as a log folder (SI units, ``repr`` floats) that :func:`load_log` reads back equal.

    Nothing partial is ever left under a final name. A new (or empty) folder is written
    whole under a hidden scratch name beside it and renamed onto ``folder`` at the end,
    so an error, a ``KeyboardInterrupt`` or a killed process leaves no log folder at all
    (at most the hidden scratch folder). Into a folder that already holds files, every
    file is first written under a scratch name, then each is renamed onto its final name:
    each file is the old one or the whole new one.

    Parameters
    ----------
    log : RobotLog
        The log to write.
    folder : str or path-like
        Created if needed (with its parents).
    overwrite : bool
        Replace the log files of a folder that already has some. The log files this log
        does not have (e.g. ``groundtruth.csv``) are then removed. Other files are left alone.
    progress : callable or None
        Called as ``progress(done, total)`` after each file written (``total`` files).

    Returns
    -------
    Path
        The folder.

    Raises
    ------
    InputError
        When the folder already holds log files and ``overwrite`` is False, or ``folder``
        is not a folder, or has no name of its own (``.``, ``..``, ``/``).
    FileFormatError
        When a file cannot be written.

    Examples
    --------
    >>> import tempfile
    >>> log = RobotLog(LogMeta("demo"), (), (), commands=(PositionReport(1.0, TurnAndRun(0.1, 0.5)),))
    >>> folder = write_log(log, Path(tempfile.mkdtemp()) / "demo")
    >>> sorted(path.name for path in folder.iterdir())
    ['commands.csv', 'landmarks.csv', 'meta.toml', 'observations.csv']
    >>> load_log(folder).commands == log.commands
    True
    >>> write_log(log, folder)        # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: folder: expected a folder without a log, got .../demo holding ...
    """
    if not isinstance(log, RobotLog):
        raise InputError(f"log: expected a RobotLog, got {type(log).__name__}")
    base = Path(folder)
    if base.is_symlink():
        # Into the folder it leads to (made when missing): the scratch folder is renamed onto
        # a folder, and a rename onto the link would fail after all the work.
        base = Path(os.path.realpath(base))
    if base.name in ("", ".."):
        # The log is written under a scratch name beside the folder, then renamed onto it.
        raise InputError(f"folder: expected a path ending in the log folder's name, got {str(folder)!r}")
    if base.exists() and not base.is_dir():
        raise InputError(f"folder: expected a folder, got the file {base}")
    existing = log_files_in(base)
    if existing and not overwrite:
        raise InputError(
            f"folder: expected a folder without a log, got {base} holding {', '.join(existing)} "
            "(pass overwrite=True)"
        )
    files: dict[str, str] = {META: _meta_toml(log.meta)}
    files[LANDMARKS] = _landmarks_csv(log.landmarks)
    files[OBSERVATIONS] = _observations_csv(log.observations)
    if log.odometry is not None:
        odometry = log.odometry
        files[ODOMETRY] = _csv_text(
            "odometry: time [s], v [m/s], omega [rad/s]; each row holds until the next",
            ("time", "v", "omega"),
            zip(_floats(odometry.time), _floats(odometry.v), _floats(odometry.omega), strict=True),
        )
    else:
        assert log.commands is not None
        files[COMMANDS] = _csv_text(
            "commands: time [s] when the motion ended, turn [rad], run [m]",
            ("time", "turn", "run"),
            ((report.time, report.command.turn, report.command.run) for report in log.commands),
        )
    if log.groundtruth is not None:
        truth = log.groundtruth
        files[GROUNDTRUTH] = _csv_text(
            "ground truth: time [s], x [m], y [m], heading [rad]",
            ("time", "x", "y", "heading"),
            zip(_floats(truth.time), _floats(truth.x), _floats(truth.y), _floats(truth.heading), strict=True),
        )
    if progress is not None and not callable(progress):
        raise InputError(f"progress: expected a callable or None, got {type(progress).__name__}")
    try:
        if base.is_dir() and any(base.iterdir()):
            _write_into(base, files, existing, progress)
        else:
            _write_fresh(base, files, progress)
    except OSError as exc:
        reason = exc.strerror or exc
        raise FileFormatError(str(base), "", f"expected a writable folder, got {reason}") from exc
    return base


def _write_fresh(base: Path, files: Mapping[str, str], progress: Callable[[int, int], None] | None) -> None:
    """Write a whole new folder under a scratch name, then rename it onto ``base`` (absent or empty)."""
    made = make_folders(base.parent)
    scratch = scratch_path(base)
    try:
        scratch.mkdir()
        for done, (name, text) in enumerate(files.items(), start=1):
            (scratch / name).write_text(text, encoding="utf-8")
            if progress is not None:
                progress(done, len(files))
        # rename(2) replaces an empty folder in one step, and refuses a non-empty one
        os.replace(scratch, base)
    except BaseException:
        shutil.rmtree(scratch, ignore_errors=True)
        remove_made(made)  # no empty folders left where the log was to go
        raise


def _write_into(
    base: Path,
    files: Mapping[str, str],
    existing: Sequence[str],
    progress: Callable[[int, int], None] | None,
) -> None:
    """Replace the log files of a folder holding other files too: every file whole, or the old one."""
    with contextlib.ExitStack() as stack:
        for done, (name, text) in enumerate(files.items(), start=1):
            scratch = stack.enter_context(atomic_path(base / name))
            scratch.write_text(text, encoding="utf-8")
            if progress is not None:
                progress(done, len(files))
        # leaving the stack renames each scratch file onto its name, all text already on disk
    for name in existing:
        if name not in files:
            (base / name).unlink()


def _landmarks_csv(landmarks: Sequence[LogLandmark]) -> str:
    heights = any(item.z_bottom is not None or item.z_top is not None for item in landmarks)
    header = ["id", "x", "y", "position_uncertainty", *(("z_bottom", "z_top") if heights else ()), "symbol"]

    def rows() -> Iterator[list[object]]:
        for item in landmarks:
            cells: list[object] = [item.id, item.x, item.y, item.position_uncertainty]
            if heights:
                cells += [item.z_bottom, item.z_top]
            yield [*cells, item.symbol]

    return _csv_text("landmarks: id, x [m], y [m], position_uncertainty [m], heights [m]", header, rows())


def _observations_csv(observations: Sequence[LogObservation]) -> str:
    optional = [
        name
        for name in ("range", "bearing_error", "range_error")
        if any(getattr(item, name) is not None for item in observations)
    ]
    header = ["time", "landmark_id", "bearing", *optional]
    rows = (
        [item.time, item.landmark_id, item.bearing, *(getattr(item, n) for n in optional)]
        for item in observations
    )
    return _csv_text(
        "observations: time [s], landmark_id, bearing [rad], range [m], bearing_error [rad], range_error [m]",
        header,
        rows,
    )


def renumbered(observations: Sequence[LogObservation]) -> tuple[LogObservation, ...]:
    """Return the observations with the ``line`` numbers :func:`write_log` gives them."""
    return tuple(replace(item, line=FIRST_ROW_LINE + index) for index, item in enumerate(observations))
