"""Reader of the UTIAS Multi-Robot Cooperative Localization and Mapping (MRCLAM) dataset.

K. Y. K. Leung, Y. Halpern, T. D. Barfoot, H. H. T. Liu, "The UTIAS Multi-Robot
Cooperative Localization and Mapping Dataset", IJRR 30(8), 2011. Each dataset folder
holds whitespace-separated ``.dat`` files with ``#`` header lines: ``Barcodes.dat``
(subject, barcode), ``Landmark_Groundtruth.dat`` (subject, x, y, x sd, y sd) and, per
robot N, ``RobotN_Odometry.dat`` (time, v, omega), ``RobotN_Measurement.dat`` (time,
barcode, range, bearing) and ``RobotN_Groundtruth.dat`` (time, x, y, heading); SI units.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import replace
from pathlib import Path
from typing import NoReturn

import numpy as np
from numpy.typing import NDArray

from aura_ums._files import MAX_ROWS, present, read_folder, read_text
from aura_ums._validate import (
    ANGLE,
    ANGULAR_SPEED,
    COORDINATE,
    LENGTH,
    SPEED,
    TIME,
    Range,
)
from aura_ums.errors import FileFormatError, InputError
from aura_ums.logs._io import clock_jump, plural, renumbered, write_log
from aura_ums.logs._log import (
    GroundTruth,
    LogLandmark,
    LogMeta,
    LogObservation,
    Odometry,
    RobotLog,
    printable,
)

#: Subjects 1-5 are the robots; 6-20 the landmarks.
ROBOT_SUBJECTS = range(1, 6)
CITATION = "Leung et al., IJRR 2011"
LANDMARK_SYMBOL = "cylinder"
#: Subjects and barcodes are small whole numbers.
_NUMBER = Range(0, 1e6)
_WHOLE = frozenset({"subject", "barcode"})
#: The physical range of each column of the ``.dat`` files (docs/formats.md lists them).
COLUMN_RANGES: dict[str, Range] = {
    "subject": _NUMBER,
    "barcode": _NUMBER,
    "time": TIME,
    "v": SPEED,
    "omega": ANGULAR_SPEED,
    "x": COORDINATE,
    "y": COORDINATE,
    # a landmark's position_uncertainty is 3 sd: at most 900 m, within POSITION_UNCERTAINTY
    "x_sd": Range(0.0, 300.0, "m"),
    "y_sd": Range(0.0, 300.0, "m"),
    "range": LENGTH,
    "bearing": ANGLE,
    "heading": ANGLE,
}


_LINE_BREAK = re.compile(r"\r\n|\r|\n")


class _DatFile:
    """A whitespace-separated ``.dat`` file of numbers, rows kept with their line numbers."""

    def __init__(self, path: Path, columns: tuple[str, ...]) -> None:
        self.source = str(path)
        if not present(path):  # a folder or a pipe: read_text names what it is
            self.fail("", f"expected an MRCLAM data file ({', '.join(columns)}), got no such file")
        # The same reader as every other file: size limit, UTF-8 with an optional BOM.
        text = read_text(path, kind="MRCLAM data")
        lines: list[int] = []
        rows: list[list[float]] = []
        # Lines end at a newline as an editor counts them: splitlines() also broke at form
        # feeds, U+2028 and NEL, and every later line number was off.
        for number, line in enumerate(_LINE_BREAK.split(text), start=1):
            cells = line.split()
            if not cells or cells[0].startswith("#"):
                continue
            if len(rows) >= MAX_ROWS:
                self.fail_at(number, f"expected at most {MAX_ROWS} data rows, got more")
            if len(cells) != len(columns):
                self.fail_at(
                    number,
                    f"expected {len(columns)} numbers ({', '.join(columns)}), got {len(cells)}",
                )
            try:
                if any("_" in cell or not cell.isascii() for cell in cells):
                    raise ValueError(line)  # float() reads 0_1 as 1 and full-width digits as digits
                values = [float(cell) for cell in cells]
            except ValueError:
                self.fail_at(number, f"expected numbers ({', '.join(columns)}), got {_shown(line)}")
            if not all(math.isfinite(value) for value in values):
                self.fail_at(number, f"expected finite numbers, got {_shown(line)}")
            for name, cell, value in zip(columns, cells, values, strict=True):
                bounds = COLUMN_RANGES[name]
                if not bounds.contains(value):
                    self.fail_at(number, f"expected {name} {bounds.text()}, got {_shown(cell)}")
                if name in _WHOLE and value != int(value):  # 14.9 would be read as barcode 14
                    self.fail_at(number, f"expected a whole number as {name}, got {_shown(cell)}")
            lines.append(number)
            rows.append(values)
        self.lines = np.array(lines, dtype=np.int64)
        self.data: NDArray[np.float64] = np.array(rows, dtype=np.float64).reshape(-1, len(columns))

    def fail(self, where: str, message: str) -> NoReturn:
        raise FileFormatError(self.source, where, message)

    def fail_at(self, line: int, message: str) -> NoReturn:
        raise FileFormatError(self.source, "", message, line=line)

    def need_rows(self) -> None:
        """Refuse a file without data rows."""
        if len(self.data) == 0:
            self.fail("", "expected at least one data row, got none")

    def once(self, column: int, what: str) -> None:
        """Refuse a value of ``column`` that a row repeats, at the line of its second row."""
        values = self.data[:, column]
        _, first = np.unique(values, return_index=True)
        if len(first) < len(values):
            repeat = int(np.setdiff1d(np.arange(len(values)), first)[0])
            again = int(values[repeat])
            self.fail_at(int(self.lines[repeat]), f"expected each {what} once, got {again} again")

    def increasing(self) -> tuple[NDArray[np.float64], int]:
        """Rows with strictly increasing times: an exact repeat of a time keeps the last row.

        Returns the rows and how many repeats were dropped; a time going back is an error.
        """
        self.need_rows()
        time = self.data[:, 0]
        steps = np.diff(time)
        if np.any(steps < 0.0):
            row = int(np.argmax(steps < 0.0)) + 1
            self.fail_at(
                int(self.lines[row]),
                f"expected non-decreasing times, got {float(time[row])!r} after {float(time[row - 1])!r}",
            )
        keep = np.concatenate((steps > 0.0, [True]))
        return self.data[keep], int(np.count_nonzero(~keep))

    def no_clock_jump(self, *, held: bool, order: NDArray[np.intp] | None = None) -> None:
        """Refuse a clock jump between two rows (:func:`~aura_ums.logs._io.clock_jump`).

        ``order`` sorts the rows by time first (measurements are sorted on reading).
        """
        rows = slice(None) if order is None else order
        jump = clock_jump(self.data[rows, 0], self.lines[rows], held=held)
        if jump is not None:
            self.fail_at(int(self.lines[rows][jump[0]]), jump[1])


def _shown(text: str) -> str:
    """Quote a cell or line in a message, shortened."""
    stripped = text.strip()
    return repr(stripped if len(stripped) <= 60 else stripped[:57] + "...")


def _dataset_label(folder: Path) -> str:
    match = re.search(r"(\d+)$", folder.name)
    return f"UTIAS MRCLAM Dataset{match.group(1)}" if match else f"UTIAS MRCLAM dataset {folder.name!r}"


def read_mrclam(dataset_dir: str | os.PathLike[str], robot: int) -> RobotLog:
    """Read one robot's run from a UTIAS MRCLAM dataset folder (any of its datasets).

    Measurements of barcodes that belong to robots (subjects 1-5) or to no subject are
    dropped, and so are landmark subjects missing from ``Landmark_Groundtruth.dat``; the
    counts are in ``meta.source``. Landmark ids are the subject numbers as strings ("6"
    to "20"); their ``position_uncertainty`` is 3 times the larger of the x and y
    standard deviations. Exact repeats of an odometry (or ground-truth) time keep the last
    row, and are counted in ``meta.source`` too. Measurements outside the ground truth's
    time span are kept; a ``RobotN_Measurement.dat`` without data rows (empty, or ``#``
    lines alone) gives a log without observations, as an ``observations.csv`` with its
    header alone does, and says so in ``meta.source``. The meta has terrain ``"floor"``
    and :class:`LogMeta`'s default bounds (placeholders for calibration). Each
    observation's ``line`` is its line in ``RobotN_Measurement.dat``.

    Parameters
    ----------
    dataset_dir : str or path-like
        The folder with ``Barcodes.dat``, ``Landmark_Groundtruth.dat`` and ``RobotN_*.dat``.
    robot : int
        Robot number, 1 to 5.

    Returns
    -------
    RobotLog
        Range-and-bearing observations, odometry (the recorded commanded velocities) and
        ground truth, in SI units; ``path`` is None.

    Raises
    ------
    InputError
        For a robot number outside 1-5.
    FileFormatError
        For a missing folder or file (naming it) or a malformed line (naming file and line).

    Examples
    --------
    >>> read_mrclam("/no/such/folder", 1)
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: /no/such/folder: expected a UTIAS MRCLAM dataset folder, got no such ...
    """
    if (
        isinstance(robot, bool)
        or not isinstance(robot, (int, np.integer))
        or int(robot) not in ROBOT_SUBJECTS
    ):
        raise InputError(f"robot: expected a robot number from 1 to 5, got {robot!r}")
    robot = int(robot)
    folder = read_folder(dataset_dir, kind="UTIAS MRCLAM dataset folder", name="dataset_dir")
    prefix = f"Robot{robot}_"
    if not present(folder / f"{prefix}Measurement.dat"):
        found = sorted({path.name.split("_")[0] for path in folder.glob("Robot*_*.dat")})
        raise FileFormatError(
            str(folder / f"{prefix}Measurement.dat"),
            "",
            f"expected robot {robot}'s measurements, got no such file "
            f"(robots in this folder: {', '.join(found) or 'none'})",
        )

    barcodes = _DatFile(folder / "Barcodes.dat", ("subject", "barcode"))
    # Without rows, or with a barcode twice, every measurement would be dropped or misread
    # in silence: the import would succeed with no observation or the wrong landmark.
    barcodes.need_rows()
    barcodes.once(1, "barcode")
    barcodes.once(0, "subject")  # two barcodes of one subject: a typing slip, or two landmarks made one
    subject_of = {int(barcode): int(subject) for subject, barcode in barcodes.data}
    landmark_file = _DatFile(folder / "Landmark_Groundtruth.dat", ("subject", "x", "y", "x_sd", "y_sd"))
    landmark_file.need_rows()
    landmark_file.once(0, "subject")
    landmarks: list[LogLandmark] = []
    for number, (subject, x, y, x_sd, y_sd) in zip(
        landmark_file.lines.tolist(), landmark_file.data.tolist(), strict=True
    ):
        try:
            landmarks.append(
                LogLandmark(str(int(subject)), x, y, 3.0 * max(abs(x_sd), abs(y_sd)), symbol=LANDMARK_SYMBOL)
            )
        except InputError as exc:
            landmark_file.fail_at(number, str(exc).partition(": ")[2])
    known = {landmark.id for landmark in landmarks}

    measurements = _DatFile(folder / f"{prefix}Measurement.dat", ("time", "barcode", "range", "bearing"))
    # Real gaps (the robot sees no barcode for minutes) stay far below the limit.
    measurements.no_clock_jump(held=False, order=np.argsort(measurements.data[:, 0], kind="stable"))
    observations: list[LogObservation] = []
    robots = unknown = 0
    for number, (time, barcode, distance, bearing) in zip(
        measurements.lines.tolist(), measurements.data.tolist(), strict=True
    ):
        subject = subject_of.get(int(barcode))
        if subject in ROBOT_SUBJECTS:
            robots += 1
        elif subject is None or str(subject) not in known:
            unknown += 1
        elif distance < 0.0:
            measurements.fail_at(number, f"expected a range >= 0, got {distance!r}")
        else:
            observations.append(LogObservation(time, str(subject), bearing, range=distance, line=int(number)))
    if unknown and not observations:
        # Every landmark measurement dropped: a log that would replay on odometry alone, in silence.
        measurements.fail(
            "",
            f"expected measurements of the landmarks of Landmark_Groundtruth.dat (by Barcodes.dat), "
            f"got none: {unknown} of unknown barcodes, {robots} of robots",
        )
    observations.sort(key=lambda item: item.time)  # stable: frames keep their order

    odometry_file = _DatFile(folder / f"{prefix}Odometry.dat", ("time", "v", "omega"))
    odometry_file.no_clock_jump(held=True)
    odometry_rows, odometry_repeats = odometry_file.increasing()
    truth_file = _DatFile(folder / f"{prefix}Groundtruth.dat", ("time", "x", "y", "heading"))
    truth_file.no_clock_jump(held=False)
    truth_rows, truth_repeats = truth_file.increasing()

    notes = [f"dropped {robots} robot and {unknown} unknown-barcode measurements"]
    earlier = int(np.count_nonzero(np.diff(measurements.data[:, 0]) < 0.0)) if len(measurements.data) else 0
    if earlier:
        # Sorted by time above: said, so that a reader of the log knows its file was not in order.
        notes.append(
            f"sorted {prefix}Measurement.dat by time ({plural(earlier, 'row')} earlier than the one above)"
        )
    if not len(measurements.data):
        # As an observations.csv with its header alone: a log without observations is one
        # to replay on odometry alone, so it is kept, but said (a truncated download?).
        notes.append(f"no measurement rows in {prefix}Measurement.dat: a log without observations")
    if odometry_repeats:
        notes.append(f"dropped {plural(odometry_repeats, 'repeated odometry time')} (kept the last row)")
    if truth_repeats:
        notes.append(f"dropped {plural(truth_repeats, 'repeated ground-truth time')} (kept the last row)")
    source = f"{_dataset_label(folder)} robot {robot} ({CITATION}); {'; '.join(notes)}"
    name = printable(f"{folder.name}-robot{robot}").strip()
    meta = LogMeta(name=name, terrain="floor", source=printable(source))
    log = RobotLog(
        meta,
        tuple(landmarks),
        tuple(observations),
        odometry=Odometry(odometry_rows[:, 0], odometry_rows[:, 1], odometry_rows[:, 2]),
        groundtruth=GroundTruth(truth_rows[:, 0], truth_rows[:, 1], truth_rows[:, 2], truth_rows[:, 3]),
    )
    names = {"motion": "Odometry", "observations": "Measurement", "ground truth": "Groundtruth"}
    problem = log.unaligned_clocks({key: f"{prefix}{name}.dat" for key, name in names.items()})
    if problem is not None:
        raise FileFormatError(str(folder), "", problem)
    return log


def import_mrclam(
    dataset_dir: str | os.PathLike[str],
    robot: int,
    out_dir: str | os.PathLike[str],
    *,
    overwrite: bool = False,
) -> RobotLog:
    """Read one robot's run with :func:`read_mrclam` and write it as a log folder.

    Parameters
    ----------
    dataset_dir : str or path-like
        The MRCLAM dataset folder.
    robot : int
        Robot number, 1 to 5.
    out_dir : str or path-like
        The log folder to write (see :func:`write_log`).
    overwrite : bool
        Replace an existing log in ``out_dir``.

    Returns
    -------
    RobotLog
        The log as :func:`load_log` would read it back: ``path`` is ``out_dir`` and each
        observation's ``line`` is its line in the written ``observations.csv``.

    Raises
    ------
    InputError, FileFormatError
        As :func:`read_mrclam` and :func:`write_log`.

    Examples
    --------
    >>> import_mrclam("/no/such/folder", 1, "/tmp/never-written")   # nothing is written
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: /no/such/folder: expected a UTIAS MRCLAM dataset folder, got no such ...
    """
    log = read_mrclam(dataset_dir, robot)
    folder = write_log(log, out_dir, overwrite=overwrite)
    return replace(log, observations=renumbered(log.observations), path=folder)
