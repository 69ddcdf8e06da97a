"""A log folder read as the replay goes: its large files block by block, in bounded memory.

:func:`open_log` reads what is small (``meta.toml``, ``landmarks.csv``, ``commands.csv``)
and passes once over ``groundtruth.csv`` (checking it, and the bounding box the replay's
arena needs); :func:`~aura_ums.logs.replay_log` then reads ``observations.csv``,
``odometry.csv`` and ``groundtruth.csv`` block by block (:func:`aura_ums._files.csv_blocks`)
as its frames reach them. The windows below hold only the rows the next frames need, and
give exactly what the whole-log arrays give (the same arithmetic on the same rows, the
running sums carried across blocks in the same order).
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import os
import tempfile
import threading
import weakref
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import BinaryIO

import numpy as np
from numpy.typing import NDArray

from aura_ums._files import FileVersion, _is_row, file_version, present, read_folder, regular_file
from aura_ums._validate import gap_seconds
from aura_ums.errors import FileFormatError, InputError
from aura_ums.geometry import wrap_angle
from aura_ums.logs._io import (
    COMMANDS,
    GROUNDTRUTH,
    LANDMARKS,
    LOG_CSV_MAX_BYTES,
    META,
    OBSERVATIONS,
    ODOMETRY,
    STREAM_BLOCK_BYTES,
    ObservationColumns,
    OdometryColumns,
    TruthColumns,
    Units,
    _MetaReader,
    _read_commands,
    _read_landmarks,
    groundtruth_blocks,
    load_log,
    observation_blocks,
    odometry_blocks,
    reversed_at,
)
from aura_ums.logs._log import (
    DEFAULT_MAX_TRUTH_GAP,
    LogLandmark,
    LogMeta,
    RobotLog,
    unaligned_spans,
)
from aura_ums.logs._odometry import ReverseMotion, ReversingError, piece_commands, report_times
from aura_ums.manager import PositionReport

Array = NDArray[np.float64]


class ScratchFile:
    """A scratch file without a name, closed when the last object holding it is (copies of a stream share it).

    It is made by :func:`tempfile.TemporaryFile`: on POSIX its name is removed as it is
    created, so the system frees it when its last descriptor closes, even when the process
    is killed (``SIGKILL``) and no clean-up code runs. A named scratch file was left behind
    in the temporary folder by every killed replay.
    """

    __slots__ = ("__weakref__", "_handle", "_lock")

    def __init__(self, handle: BinaryIO) -> None:
        self._handle = handle
        self._lock = threading.Lock()
        weakref.finalize(self, handle.close)

    def read(self, offset: int, count: int) -> bytes:
        """At most ``count`` bytes from ``offset`` (each reader keeps its own place in the file)."""
        with self._lock:
            self._handle.seek(offset)
            return self._handle.read(count)


@dataclass(frozen=True, slots=True, eq=False)
class LogStream:
    """A log folder opened to be replayed block by block (:func:`open_log`), in bounded memory.

    Attributes
    ----------
    meta : LogMeta
        Name, terrain, bounds and start (``meta.toml``).
    landmarks : tuple of LogLandmark
        ``landmarks.csv``.
    path : Path
        The folder.
    units : Units
        The files' units (``meta.toml``'s ``[units]``).
    commands : tuple of PositionReport or None
        ``commands.csv`` when the log has one (read whole: recorded commands are few),
        None for an ``odometry.csv`` (read block by block).
    truth_box : tuple of float or None
        ``(x_min, y_min, x_max, y_max)`` of the ground truth, metres; None without
        ``groundtruth.csv``.
    truth_scratch : ScratchFile or None
        The ground truth as :func:`open_log` read and checked it (time, x, y, wrapped
        heading: four float64 a row), in a scratch file removed with the stream, so the
        replay does not parse ``groundtruth.csv`` twice; None: parse it again.
    versions : mapping of str to (int, int)
        Each CSV file's size and modification time when :func:`open_log` opened the log,
        by file name: a file changed since (its spans and extent checked on another
        version) is refused when the replay comes to read it.
    max_gap : float
        Seconds: the ground truth's :attr:`~aura_ums.logs.GroundTruth.max_gap`.
    block_bytes : int
        Bytes read of a CSV file at a time.

    Examples
    --------
    >>> import dataclasses
    >>> from aura_ums.logs import synthetic_log, write_log
    >>> log = synthetic_log(np.random.default_rng(0), duration=5.0)
    >>> stream = open_log(write_log(log, tempfile.mkdtemp() + "/log"), block_bytes=200)
    >>> stream.meta.name, len(stream.landmarks), len(stream.commands)   # commands.csv: read whole
    ('synthetic', 8, 50)
    >>> rows = [len(block[0]) for block in stream.observation_blocks()]   # 200 bytes at a time
    >>> len(rows) > 1, sum(rows), len(stream.load().observations)
    (True, 18, 18)
    >>> blind = open_log(write_log(dataclasses.replace(log, groundtruth=None), tempfile.mkdtemp() + "/log"))
    >>> blind.truth_box, blind.truth_scratch                             # no ground truth
    (None, None)
    """

    meta: LogMeta
    landmarks: tuple[LogLandmark, ...]
    path: Path
    units: Units
    commands: tuple[PositionReport, ...] | None
    truth_box: tuple[float, float, float, float] | None
    max_gap: float = DEFAULT_MAX_TRUTH_GAP
    block_bytes: int = STREAM_BLOCK_BYTES
    truth_scratch: ScratchFile | None = None
    versions: Mapping[str, FileVersion] = field(default_factory=dict)

    def observation_blocks(self) -> Iterator[ObservationColumns]:
        """Yield ``observations.csv``'s checked columns block by block (time, id, bearing, ...)."""
        known = {landmark.id for landmark in self.landmarks}
        return observation_blocks(
            self.path / OBSERVATIONS, self.units, known, self.block_bytes, self.versions.get(OBSERVATIONS)
        )

    def odometry_blocks(self) -> Iterator[OdometryColumns]:
        """Yield ``odometry.csv``'s checked time, v, omega block by block (at least one block)."""
        return odometry_blocks(
            self.path / ODOMETRY, self.units, self.block_bytes, self.versions.get(ODOMETRY)
        )

    def groundtruth_blocks(self) -> Iterator[TruthColumns]:
        """Yield the ground truth's checked time, x, y, heading (wrapped to (-pi, pi]) block by block."""
        if self.truth_scratch is not None:
            size, offset = 32 * max(self.block_bytes // 32, 1), 0  # four float64 a row
            while True:
                block = np.frombuffer(self.truth_scratch.read(offset, size), dtype=np.float64).reshape(-1, 4)
                if not len(block):
                    return
                offset += block.nbytes
                yield block[:, 0].copy(), block[:, 1].copy(), block[:, 2].copy(), block[:, 3].copy()
        yield from _wrapped_truth(
            groundtruth_blocks(
                self.path / GROUNDTRUTH, self.units, self.block_bytes, self.versions.get(GROUNDTRUTH)
            )
        )

    def load(self) -> RobotLog:
        """Read the whole log (:func:`~aura_ums.logs.load_log`), for what needs it all at once."""
        log = load_log(self.path)
        if log.groundtruth is not None and self.max_gap != log.groundtruth.max_gap:
            log = dataclasses.replace(log, groundtruth=log.groundtruth.with_max_gap(self.max_gap))
        return dataclasses.replace(log, meta=self.meta)


def open_log(
    folder: str | os.PathLike[str],
    *,
    max_gap: float = DEFAULT_MAX_TRUTH_GAP,
    block_bytes: int = STREAM_BLOCK_BYTES,
) -> LogStream:
    r"""Open a log folder to replay it block by block: :func:`~aura_ums.logs.load_log` in bounded memory.

    ``meta.toml`` and ``landmarks.csv`` are read and checked now, as is the whole
    ``groundtruth.csv`` (in blocks; the replay's arena needs its extent before the first
    frame). ``observations.csv`` and ``odometry.csv`` are checked as the replay reads
    them, with :func:`~aura_ums.logs.load_log`'s messages (file and line), so a fault in
    them fails the replay when it gets there (the per-step CSV is then not written).

    Parameters
    ----------
    folder : str or path-like
        A log folder (``docs/log-format.md``).
    max_gap : float
        Seconds, > 0: the ground truth's :attr:`~aura_ums.logs.GroundTruth.max_gap`.
    block_bytes : int
        Bytes read of a CSV file at a time, >= 1 (default 512 KiB) and at most 256 MiB (the
        largest log CSV file): what the replay's memory holds of each file beyond the rows it needs.

    Returns
    -------
    LogStream

    Raises
    ------
    FileFormatError
        As :func:`~aura_ums.logs.load_log` for the files read now.

    Examples
    --------
    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> _ = (folder / "meta.toml").write_text('name = "demo"\n')
    >>> _ = (folder / "landmarks.csv").write_text("id,x,y\npole,3.0,0.0\n")
    >>> _ = (folder / "observations.csv").write_text("time,landmark_id,bearing\n0.5,pole,0.1\n")
    >>> _ = (folder / "odometry.csv").write_text("time,v,omega\n0.0,0.5,0.0\n1.0,0.5,0.0\n")
    >>> stream = open_log(folder)
    >>> stream.meta.name, [block[0].tolist() for block in stream.odometry_blocks()]
    ('demo', [[0.0, 1.0]])
    >>> open_log(folder / "missing")      # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: .../missing: expected a log folder, got no such folder
    """
    base = read_folder(folder, kind="log folder")
    gap = gap_seconds(max_gap, "max_gap")
    if isinstance(block_bytes, bool) or not isinstance(block_bytes, int) or block_bytes < 1:
        raise InputError(f"block_bytes: expected an integer >= 1, got {block_bytes!r}")
    if block_bytes > LOG_CSV_MAX_BYTES:
        # A block is read into memory at once (10**12 bytes was a MemoryError, 2**63 an OverflowError).
        raise InputError(
            f"block_bytes: expected at most {LOG_CSV_MAX_BYTES} ({LOG_CSV_MAX_BYTES // 2**20} MiB, the "
            f"largest log CSV file, read at once), got {block_bytes} ({block_bytes / 2**30:.3g} GiB)"
        )
    # Before any is read: what open_log checks (spans, extent) holds for these versions only.
    versions = {name: v for name in (OBSERVATIONS, ODOMETRY, GROUNDTRUTH) if (v := file_version(base / name))}
    meta, units = _MetaReader(base / META).read(base.name)
    landmarks = _read_landmarks(base / LANDMARKS, units)
    has_odometry, has_commands = present(base / ODOMETRY), present(base / COMMANDS)
    if has_odometry == has_commands:
        got = "both" if has_odometry else "neither"
        raise FileFormatError(str(base), "", f"expected exactly one of {ODOMETRY} and {COMMANDS}, got {got}")
    commands = None if has_odometry else _read_commands(base / COMMANDS, units)
    _check_clocks(base, units, commands)
    box, scratch = None, None
    if present(base / GROUNDTRUTH):
        box, scratch = _read_truth(base / GROUNDTRUTH, units, block_bytes, versions.get(GROUNDTRUTH))
    return LogStream(meta, landmarks, base, units, commands, box, gap, block_bytes, scratch, versions)


#: Bytes read at each end of a file to find its first and last time.
_PROBE_BYTES = 65_536


def _file_span(path: Path, units: Units) -> tuple[float, float] | None:
    """Return the first and last time, s, of a log CSV file from its two ends, or None.

    Only the first and the last data row are read (a quoted cell, a short row, anything
    not plain gives None): the blocks check every row as the replay reads them.
    """
    if not regular_file(path):  # a named pipe would block the open: its reader refuses it
        return None
    try:
        with open(path, "rb") as handle:
            head = handle.read(_PROBE_BYTES)
            size = handle.seek(0, os.SEEK_END)
            handle.seek(max(0, size - _PROBE_BYTES))
            tail = handle.read(_PROBE_BYTES)
    except OSError:
        return None
    head_lines = head.decode("utf-8-sig", errors="replace").splitlines()
    if len(head) == _PROBE_BYTES:  # its last line may be cut short
        head_lines = head_lines[:-1]
    rows = [line.strip() for line in head_lines if _is_row(line)]
    last_rows = [
        line.strip() for line in tail.decode("utf-8", errors="replace").splitlines()[1:] if _is_row(line)
    ]
    if len(rows) < 2 or not last_rows:
        return None
    names = [name.strip() for name in rows[0].split(",")]
    if "time" not in names:
        return None
    column = names.index("time")
    times = []
    for row in (rows[1], last_rows[-1]):
        cells = row.split(",")
        if '"' in row or len(cells) <= column:
            return None
        try:
            value = float(cells[column]) * units.factor("time")
        except ValueError:
            return None
        if not math.isfinite(value):
            return None
        times.append(value)
    return times[0], times[1]


def _check_clocks(base: Path, units: Units, commands: tuple[PositionReport, ...] | None) -> None:
    """Refuse, as load_log does, a log whose files do not share a clock: before the replay reads them."""
    spans: list[tuple[str, float, float]] = []
    if commands:
        spans.append((COMMANDS, commands[0].time, commands[-1].time))
    for name in (() if commands is not None else (ODOMETRY,)) + (OBSERVATIONS, GROUNDTRUTH):
        span = _file_span(base / name, units)  # None for a file absent
        if span is not None:
            spans.append((name, *span))
    problem = unaligned_spans(spans)
    if problem is not None:
        raise FileFormatError(str(base), "", problem)


def _read_truth(
    path: Path, units: Units, block_bytes: int, version: FileVersion | None
) -> tuple[tuple[float, float, float, float], ScratchFile | None]:
    """Check the whole ground truth block by block: its extent, and the scratch copy of its rows."""
    low, high = np.full(2, np.inf), np.full(2, -np.inf)
    handle: BinaryIO | None = None
    with contextlib.suppress(OSError):  # no scratch file: the replay parses the file again
        handle = tempfile.TemporaryFile(prefix="aura-ums-truth-", suffix=".f8")  # noqa: SIM115
    try:
        for block in _wrapped_truth(groundtruth_blocks(path, units, block_bytes, version)):
            _, x, y, _ = block
            low = np.minimum(low, (x.min(), y.min()))
            high = np.maximum(high, (x.max(), y.max()))
            if handle is not None:
                try:
                    handle.write(np.column_stack(block).tobytes())
                except OSError:  # no room: the replay parses the file again
                    _discard(handle)
                    handle = None
    except BaseException:
        if handle is not None:
            _discard(handle)
        raise
    box = (float(low[0]), float(low[1]), float(high[0]), float(high[1]))
    if handle is None:
        return box, None
    try:
        handle.flush()
    except OSError:  # no room for the last rows: the replay parses the file again
        _discard(handle)
        return box, None
    return box, ScratchFile(handle)


def _discard(handle: BinaryIO) -> None:
    """Close a scratch file that could not be written (closing flushes, which may fail again)."""
    with contextlib.suppress(OSError):
        handle.close()


def _wrapped_truth(blocks: Iterator[TruthColumns]) -> Iterator[TruthColumns]:
    """Yield the blocks with their headings wrapped to (-pi, pi] (as GroundTruth stores them)."""
    for time, x, y, heading in blocks:
        outside = (heading <= -math.pi) | (heading > math.pi)
        if np.any(outside):
            heading = heading.copy()
            heading[outside] = wrap_angle(heading[outside])
        yield time, x, y, heading


def _read_past(
    blocks: Iterator[tuple[Array, ...]], latest: float, held: tuple[Array, ...]
) -> tuple[tuple[Array, ...], bool]:
    """Return ``held`` joined with the blocks read up to the first one past ``latest``; whether they ended.

    Columns of times first. The window is joined to the blocks once, not once per block
    (each join copied it again).
    """
    parts = [held]
    ended = True
    for block in blocks:
        parts.append(block)
        if block[0][-1] > latest:
            ended = False
            break
    if len(parts) == 1:
        return held, ended
    return tuple(np.concatenate(column) for column in zip(*parts, strict=True)), ended


class TruthWindow:
    """The ground truth at increasing times, from its rows read block by block.

    Gives exactly :meth:`GroundTruth.at` of the whole record: the same interpolation
    between the same two rows, and the heading unwrapped with the running sum of its
    corrections carried from block to block (as :func:`numpy.unwrap` sums them).
    """

    def __init__(self, blocks: Iterator[TruthColumns], max_gap: float) -> None:
        self.blocks = blocks
        self.max_gap = max_gap
        empty = np.empty(0)
        self.time, self.x, self.y, self.unwrapped = empty, empty, empty, empty
        self.last_heading = empty  # the last row's heading, as read (none before the first block)
        self.correction: float | None = None  # the running sum of the unwrapping corrections
        self.ended = False
        self._read(-math.inf)
        self.first = float(self.time[0])

    def _read(self, latest: float) -> None:
        """Read the next block, and those after it while the last row read is at or before ``latest``.

        The window is joined to the blocks read once (a join per block copied it again each time).
        """
        blocks = ((time, x, y, self._unwrapped(heading)) for time, x, y, heading in self.blocks)
        joined, self.ended = _read_past(blocks, latest, (self.time, self.x, self.y, self.unwrapped))
        self.time, self.x, self.y, self.unwrapped = joined

    def _unwrapped(self, heading: Array) -> Array:
        """Return a block's headings unwrapped, the corrections' running sum carried from the last block."""
        # numpy.unwrap's arithmetic (period 2 pi), its cumulative sum carried from block to block.
        dd = np.diff(np.concatenate((self.last_heading, heading)))
        # Its correction is 0 but where a step is pi or more (or NaN): only those steps are
        # taken modulo 2 pi (the slowest of its operations), each as numpy.unwrap takes it.
        wide = np.flatnonzero(~(abs(dd) < np.pi))
        ph_correct = np.zeros_like(dd)
        if wide.size:
            step = dd[wide]
            ddmod = np.mod(step - (-np.pi), 2 * np.pi) + (-np.pi)
            np.copyto(ddmod, np.pi, where=(ddmod == -np.pi) & (step > 0))
            ph_correct[wide] = ddmod - step
        if self.correction is None:
            sums = ph_correct.cumsum()
        else:
            sums = np.concatenate(([self.correction], ph_correct)).cumsum()[1:]
        if self.last_heading.size:
            unwrapped: Array = heading + sums
        else:  # the record's first row is its own unwrapped heading
            unwrapped = np.array(heading, copy=True)
            unwrapped[1:] = heading[1:] + sums
        if sums.size:
            self.correction = float(sums[-1])
        self.last_heading = heading[-1:].copy()  # not a view holding the whole block
        return unwrapped

    def at(self, times: Array) -> Array:
        """Return the poses (rows of x, y, heading) at ``times``: increasing, none before earlier ones."""
        query = np.asarray(times, dtype=np.float64).reshape(-1)
        if not query.size:
            return np.empty((0, 3))
        latest = float(query.max())
        if not self.ended and self.time[-1] <= latest:
            self._read(latest)
        time = self.time
        out = np.empty((len(query), 3))
        out[:, 0] = np.interp(query, time, self.x)
        out[:, 1] = np.interp(query, time, self.y)
        out[:, 2] = wrap_angle(np.interp(query, time, self.unwrapped))
        out[(query < self.first) | ((query > time[-1]) if self.ended else False)] = np.nan
        after = np.searchsorted(time, query, side="right")
        inner = (after > 0) & (after < len(time))
        gap = np.zeros(len(query), dtype=bool)
        before = after[inner] - 1
        gap[inner] = (time[before + 1] - time[before] > self.max_gap) & (query[inner] > time[before])
        out[gap] = np.nan
        # Later times are at or after ``latest``: only its row and those after it are needed.
        keep = max(int(np.searchsorted(time, latest, side="right")) - 1, 0)
        if keep:
            self.time, self.x, self.y = time[keep:], self.x[keep:], self.y[keep:]
            self.unwrapped = self.unwrapped[keep:]
        return out


class OdometryReports:
    """The position reports of an odometry record read block by block, cut at the frames as they come.

    Gives exactly :meth:`RobotLog.position_report_arrays` of the whole record over the
    same frames (:func:`~aura_ums.logs.odometry_report_arrays`): each call covers the
    frames from the previous call's last to its own, and the integrals of the rows
    dropped before are carried as the whole record's cumulative sums hold them.
    """

    def __init__(
        self,
        blocks: Iterator[OdometryColumns],
        meta: LogMeta,
        start: float,
        max_interval: float,
        reverse: ReverseMotion,
        source: Path | None = None,
    ) -> None:
        self.blocks = blocks
        self.source = source  # the odometry file, named with a refused row's line
        self.meta = meta
        self.low = start
        self.max_interval = max_interval
        self.reverse = reverse
        empty = np.empty(0)
        self.time, self.v, self.omega = empty, empty, empty
        self.row = 0  # index in the whole record of the window's first row
        self.read = 0  # rows read so far
        # The integrals (turn, forward, backward) from the record's first row to the window's.
        self.carry: tuple[float, float, float] | None = None
        self.ended = False
        self._read()

    @property
    def first_time(self) -> float:
        """The (delayed) time of the record's first row, s."""
        return float(self.time[0]) if self.row == 0 else math.nan

    def _read(self, high: float = -math.inf) -> None:
        """Read the next block, and those after it while the last row read is at or before ``high``.

        The window is joined to the blocks read once (a join per block copied it again each time).
        """
        blocks = (self._delayed(time, v, omega) for time, v, omega in self.blocks)
        joined, self.ended = _read_past(blocks, high, (self.time, self.v, self.omega))
        self.time, self.v, self.omega = joined

    def _delayed(self, time: Array, v: Array, omega: Array) -> tuple[Array, Array, Array]:
        """Return a block read, its times delayed; refuse backing up unless told what to do with it."""
        reversing = v < 0.0
        if self.reverse is ReverseMotion.ERROR and np.any(reversing):
            row = int(np.argmax(reversing))
            refused = ReversingError(self.read + row, float(v[row]))
            if self.source is None:
                raise refused
            raise reversed_at(self.source, refused)
        self.read += len(time)
        return time + self.meta.delay_s, v, omega

    def until(self, frames: Array) -> tuple[Array, Array, Array]:
        """Return the reports (times, turns, runs) after the previous call's last frame up to ``frames[-1]``.

        ``frames``: the next frame times, increasing, after the previous call's.
        """
        high = float(frames[-1])
        if not self.ended and self.time[-1] <= high:
            self._read(high)
        t, forward, angular = self.time, self.v, self.omega
        reversing = forward < 0.0
        boundaries = frames
        if np.any(reversing):
            changes = np.flatnonzero(np.diff(reversing.astype(np.int8)) != 0) + 1
            boundaries = np.concatenate((frames, t[changes]))
        times = report_times(boundaries, self.low, high, self.max_interval)
        edges = np.concatenate(([self.low], times))
        carry = self.carry
        meta = self.meta
        # The integral from the record's first row to each row, of each rate, summed once: the
        # rows dropped below carry theirs from the same sums (one window-long array at a time).
        keep = max(int(np.searchsorted(t, high, side="right")) - 1, 0)
        steps = np.diff(t)
        integrals, carried = [], []
        for index, values in enumerate((angular, np.maximum(forward, 0.0), np.maximum(-forward, 0.0))):
            at_rows = self._sums(values, steps, None if carry is None else carry[index])
            integrals.append(self._integral(values, at_rows, edges))
            carried.append(float(at_rows[keep]))
        turn = np.diff(integrals[0]) * meta.turn_scale
        ahead = np.maximum(np.diff(integrals[1]) * meta.run_scale, 0.0)
        back = np.maximum(np.diff(integrals[2]) * meta.run_scale, 0.0)
        if keep:  # drop the rows before the one holding ``high``, carrying their integrals
            self.carry = (carried[0], carried[1], carried[2])
            self.time, self.v, self.omega = t[keep:], forward[keep:], angular[keep:]
            self.row += keep
        self.low = high
        if len(times) == 0:
            return times, times, times
        return piece_commands(times, turn, ahead, back)

    def finish(self) -> None:
        """Read and check the rows after the last frame: the whole record is checked, as load_log does."""
        while not self.ended:
            self.time, self.v, self.omega = self.time[-1:], self.v[-1:], self.omega[-1:]
            self._read()

    @staticmethod
    def _sums(values: Array, steps: Array, carry: float | None) -> Array:
        """Return the integral from the record's first row to each row of the window (its time ``steps``)."""
        products = values[:-1] * steps
        if carry is None:
            return np.concatenate(([0.0], np.cumsum(products)))
        return np.cumsum(np.concatenate(([carry], products)))

    def _integral(self, values: Array, at_rows: Array, query: Array) -> Array:
        # cumulative_integral's arithmetic, on the window's rows from the carried sums (``at_rows``).
        t = self.time
        # Not ended: every query is before the window's last row, which is then not the record's.
        clipped = np.clip(query, t[0], t[-1])
        row = np.clip(np.searchsorted(t, clipped, side="right") - 1, 0, len(t) - 1)
        partial = np.where(row < len(t) - 1, values[row] * (clipped - t[row]), 0.0)
        result: Array = at_rows[row] + partial
        return result
