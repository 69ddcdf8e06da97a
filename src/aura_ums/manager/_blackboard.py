"""The blackboard: position reports, the identified landmark buffer and the command buffer."""

from __future__ import annotations

import bisect
import operator
from collections import deque
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from aura_ums._validate import finite_float
from aura_ums.errors import InputError
from aura_ums.manager._buffer import IdentifiedLandmarkBuffer
from aura_ums.manager._codec import Reader, dump_document, encode_command, encode_observation
from aura_ums.uncertainty import TurnAndRun

_KIND = "aura-ums/blackboard"


@dataclass(frozen=True, slots=True)
class PositionReport:
    """What the shaft encoders report as executed since the previous report, time-stamped.

    Parameters
    ----------
    time : float
        When the motion ended, seconds.
    command : TurnAndRun
        The motion executed since the previous report (turn in radians, then run in
        metres). The uncertainty map manager grows the map by it with the terrain
        statistics of the meadows it crosses.

    Raises
    ------
    InputError
        For a non-finite time or a command that is not a :class:`TurnAndRun`.

    Examples
    --------
    >>> PositionReport(1.5, TurnAndRun(0.0, 0.4))
    PositionReport(time=1.5, command=TurnAndRun(turn=0.0, run=0.4))
    >>> PositionReport(2.0, (0.0, 0.4))
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: PositionReport.command: expected a TurnAndRun, got tuple
    """

    time: float
    command: TurnAndRun

    def __post_init__(self) -> None:
        object.__setattr__(self, "time", finite_float(self.time, "PositionReport.time"))
        if not isinstance(self.command, TurnAndRun):
            raise InputError(
                f"PositionReport.command: expected a TurnAndRun, got {type(self.command).__name__}"
            )

    @classmethod
    def _trusted(cls, time: float, turn: float, run: float) -> PositionReport:
        """``PositionReport(time, TurnAndRun(turn, run))`` of checked floats (finite, ``run >= 0``)."""
        report = object.__new__(cls)
        _set_time(report, time)
        _set_command(report, TurnAndRun._trusted(turn, run))
        return report


# The slots' own setters (frozen: the dataclass's __setattr__ refuses), for PositionReport._trusted.
_set_time: Callable[[PositionReport, float], None] = PositionReport.__dict__["time"].__set__
_set_command: Callable[[PositionReport, TurnAndRun], None] = PositionReport.__dict__["command"].__set__


# The sort key of the reports: attrgetter runs in C, cheaper than a function per comparison.
_report_time = operator.attrgetter("time")


class Blackboard:
    """The data the uncertainty subsystem's processes share (the paper's blackboard data).

    It holds three things, each filled by one side and read or emptied by the other:

    - :attr:`position_reports`: time-stamped :class:`PositionReport` s from the shaft
      encoders, appended in time order by the vehicle interface (or simulator) and read by
      the :class:`UncertaintyMapManager`, which remembers how many it has consumed. They
      are kept, so that logs and plots can replay them, until :meth:`forget_reports_before`
      lets the oldest go (a long replay's memory); their indices stay those they were
      posted with.
    - :attr:`identified`: the :class:`IdentifiedLandmarkBuffer` into which find-landmark
      schemas post observations and from which the manager drains them.
    - the command buffer: a first-in first-out queue of :class:`TurnAndRun` commands the
      pilot wants executed (:meth:`push_command`, :meth:`next_command`).

    The blackboard is mutable by design: it is the meeting point of processes that run at
    their own pace, so it must change as they post and consume. Everything it holds is an
    immutable value, and the current spatial uncertainty map is *not* here: its one writer
    is the manager. It is not thread-safe: guard it with a lock if producers and the
    manager run in different threads. :meth:`to_json` and :meth:`from_json` save and
    restore it whole, so that a restarted process loses nothing.

    Parameters
    ----------
    identified : IdentifiedLandmarkBuffer or None
        The buffer to share (e.g. the one a :class:`~aura_ums.schemas.SchemaManager`
        posts into); a new empty one when None.

    Examples
    --------
    >>> board = Blackboard()
    >>> board.post_report(PositionReport(1.0, TurnAndRun(0.1, 0.5)))
    >>> board.post_report(PositionReport(2.0, TurnAndRun(0.0, 0.5)))
    >>> [r.time for r in board.reports_until(1.5)], board.last_report_time
    ([1.0], 2.0)
    >>> board.push_command(TurnAndRun(0.0, 2.0))
    >>> board.next_command(), board.next_command()      # empty: None
    (TurnAndRun(turn=0.0, run=2.0), None)
    >>> board.post_report(PositionReport(1.5, TurnAndRun(0.0, 0.1)))
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: report.time: expected a time >= 2.0 (the last report's), got 1.5
    """

    __slots__ = ("_commands", "_identified", "_released", "_reports")

    def __init__(self, identified: IdentifiedLandmarkBuffer | None = None) -> None:
        if identified is None:
            identified = IdentifiedLandmarkBuffer()
        elif not isinstance(identified, IdentifiedLandmarkBuffer):
            raise InputError(
                f"identified: expected an IdentifiedLandmarkBuffer or None, got {type(identified).__name__}"
            )
        self._identified = identified
        self._reports: list[PositionReport] = []
        #: How many of the oldest reports were forgotten: the index of ``_reports[0]``.
        self._released = 0
        self._commands: deque[TurnAndRun] = deque()

    # --- position reports --------------------------------------------------------------

    def post_report(self, report: PositionReport) -> None:
        """Append a position report; its time must not be older than the last report's.

        Reports with equal times are kept in the order posted.

        Raises
        ------
        InputError
            For something other than a :class:`PositionReport`, or a report older than the last.
        """
        if not isinstance(report, PositionReport):
            raise InputError(f"report: expected a PositionReport, got {type(report).__name__}")
        self._check_after_last(report)
        self._reports.append(report)

    def _check_after_last(self, report: PositionReport) -> None:
        """Refuse a report older than the last one posted."""
        if self._reports and report.time < self._reports[-1].time:
            raise InputError(
                f"report.time: expected a time >= {self._reports[-1].time!r} (the last report's), "
                f"got {report.time!r}"
            )

    def _post_in_order(self, reports: list[PositionReport]) -> None:
        """:meth:`post_report` of each of ``reports``, known to be reports in time order (a replay's).

        Only the first is checked against the last report posted: one call a frame instead
        of one a report.
        """
        if not reports:
            return
        self._check_after_last(reports[0])
        self._reports += reports

    def post_reports(self, reports: Iterable[PositionReport]) -> None:
        """Append several position reports in turn (see :meth:`post_report`)."""
        for report in reports:
            self.post_report(report)

    @property
    def position_reports(self) -> tuple[PositionReport, ...]:
        """Every position report kept (posted and not forgotten), oldest first."""
        return tuple(self._reports)

    @property
    def report_count(self) -> int:
        """Number of position reports posted, forgotten ones included (the next one's index)."""
        return self._released + len(self._reports)

    @property
    def released_reports(self) -> int:
        """Number of the oldest position reports forgotten (the index of the oldest kept)."""
        return self._released

    def forget_reports_before(self, index: int) -> None:
        """Forget the position reports older than ``index``; the others keep their indices.

        A consumer that will not read them again lets them go, so that a long replay's
        memory does not grow with its log: the replay keeps the last report its manager
        consumed (which :meth:`UncertaintyMapManager.update` checks) and those after it.
        :meth:`to_json` records how many were forgotten.

        Parameters
        ----------
        index : int
            The oldest report to keep: from :attr:`released_reports` (nothing forgotten)
            to ``report_count - 1`` (the newest report is always kept).

        Raises
        ------
        InputError
            For an index outside that range.

        Examples
        --------
        >>> board = Blackboard()
        >>> board.post_reports(PositionReport(t, TurnAndRun(0.0, 0.1)) for t in (1.0, 2.0, 3.0))
        >>> board.forget_reports_before(2)
        >>> board.report_count, board.released_reports, board.report(2).time
        (3, 2, 3.0)
        >>> board.report(1)
        Traceback (most recent call last):
        ...
        aura_ums.errors.InputError: index: expected an integer in [2, 3) (older ones forgotten), got 1
        >>> Blackboard().forget_reports_before(0)          # nothing posted: nothing to forget
        """
        count = self.report_count
        newest = max(self._released, count - 1)
        if isinstance(index, bool) or not isinstance(index, int) or not self._released <= index <= newest:
            raise InputError(
                f"index: expected an integer in [{self._released}, {newest}] (the newest report "
                f"is kept), got {index!r}"
            )
        del self._reports[: index - self._released]
        self._released = index

    @property
    def last_report_time(self) -> float | None:
        """Time of the newest position report, seconds; None when there is none."""
        return self._reports[-1].time if self._reports else None

    def report(self, index: int) -> PositionReport:
        """Return the position report at ``index`` (0 is the oldest), without copying the others.

        Raises
        ------
        InputError
            For an index that is not an integer in ``[0, report_count)``.

        Examples
        --------
        >>> board = Blackboard()
        >>> board.post_report(PositionReport(1.0, TurnAndRun(0.1, 0.5)))
        >>> board.report(0).time
        1.0
        >>> board.report(1)
        Traceback (most recent call last):
        ...
        aura_ums.errors.InputError: index: expected an integer in [0, 1), got 1
        """
        count, first = self.report_count, self._released
        if isinstance(index, bool) or not isinstance(index, int) or not first <= index < count:
            forgotten = " (older ones forgotten)" if first else ""
            raise InputError(f"index: expected an integer in [{first}, {count}){forgotten}, got {index!r}")
        return self._reports[index - first]

    def reports_until(self, until: float, *, start: int = 0) -> tuple[PositionReport, ...]:
        """Return the reports from index ``start`` on whose time is ``<= until``, oldest first.

        Only those reports are copied: the map manager takes the reports it has not yet
        consumed (``start``) up to the time it updates to, at every update.

        Parameters
        ----------
        until : float
            Latest time to take, seconds (inclusive).
        start : int
            Index of the first report to consider (the number already consumed), at least
            :attr:`released_reports`.
        """
        limit = finite_float(until, "until")
        if isinstance(start, bool) or not isinstance(start, int) or start < self._released:
            at_least = (
                f"an integer >= {self._released} (older reports were forgotten)"
                if self._released
                else "a non-negative integer"
            )
            raise InputError(f"start: expected {at_least}, got {start!r}")
        reports, first = self._reports, start - self._released
        stop = bisect.bisect_right(reports, limit, lo=min(first, len(reports)), key=_report_time)
        return tuple(reports[first:stop])

    # --- command buffer ----------------------------------------------------------------

    def push_command(self, command: TurnAndRun) -> None:
        """Queue a command to execute, after those already queued."""
        if not isinstance(command, TurnAndRun):
            raise InputError(f"command: expected a TurnAndRun, got {type(command).__name__}")
        self._commands.append(command)

    def next_command(self) -> TurnAndRun | None:
        """Remove and return the oldest queued command; None when the buffer is empty."""
        return self._commands.popleft() if self._commands else None

    @property
    def pending_commands(self) -> tuple[TurnAndRun, ...]:
        """The queued commands, next first (nothing is removed)."""
        return tuple(self._commands)

    # --- identified landmarks ----------------------------------------------------------

    @property
    def identified(self) -> IdentifiedLandmarkBuffer:
        """The identified landmark buffer (shared, mutable)."""
        return self._identified

    # --- save and restore --------------------------------------------------------------

    def to_json(self) -> str:
        """Return the whole blackboard as JSON text: reports, pending observations, commands.

        Floats are written with ``repr`` precision, so :meth:`from_json` restores them
        bit for bit; observations carry their class name.

        Examples
        --------
        >>> from aura_ums.uncertainty import BearingObservation
        >>> board = Blackboard()
        >>> board.post_report(PositionReport(0.5, TurnAndRun(0.1, 0.3)))
        >>> board.identified.post(BearingObservation("pole", 0.5, 0.25, 0.01))
        >>> again = Blackboard.from_json(board.to_json())
        >>> again.position_reports == board.position_reports, again.identified.peek()
        (True, (BearingObservation(landmark_id='pole', time=0.5, bearing=0.25, bearing_error=0.01, \
sensor_offset=(0.0, 0.0)),))
        """
        body: dict[str, object] = {
            "position_reports": [
                {"time": r.time, "command": encode_command(r.command)} for r in self._reports
            ],
            "identified": [encode_observation(o) for o in self._identified.peek()],
            "commands": [encode_command(c) for c in self._commands],
        }
        if self._released:  # only then: a board that forgot nothing reads as before
            body["released_reports"] = self._released
        return dump_document(_KIND, body)

    @classmethod
    def from_json(cls, text: str, *, source: str = "<blackboard JSON>") -> Blackboard:
        """Restore a blackboard saved by :meth:`to_json`.

        Parameters
        ----------
        text : str
            The JSON text.
        source : str
            Name used in error messages (e.g. the file it was read from).

        Raises
        ------
        FileFormatError
            When the text is not such a document, naming the place and what is wrong.

        Examples
        --------
        >>> Blackboard.from_json('{"format": "aura-ums/blackboard", "version": 1}')
        Traceback (most recent call last):
        ...
        aura_ums.errors.FileFormatError: <blackboard JSON>: expected a key 'position_reports', got none
        """
        reader = Reader(source)
        data = reader.mapping(
            reader.document(text, _KIND),
            "",
            ("format", "version", "position_reports", "identified", "commands"),
            optional=("released_reports",),
        )
        board = cls()
        if "released_reports" in data:
            board._released = reader.integer(data["released_reports"], "released_reports")
        last: float | None = None
        for k, item in enumerate(reader.array(data["position_reports"], "position_reports")):
            where = f"position_reports[{k}]"
            entry = reader.mapping(item, where, ("time", "command"))
            time = reader.number(entry["time"], f"{where}.time")
            if last is not None and time < last:
                reader.fail(
                    f"{where}.time", f"expected a time >= {last!r} (the previous report's), got {time!r}"
                )
            last = time
            board._reports.append(PositionReport(time, reader.command(entry["command"], f"{where}.command")))
        for k, item in enumerate(reader.array(data["identified"], "identified")):
            board._identified.post(reader.observation(item, f"identified[{k}]"))
        for k, item in enumerate(reader.array(data["commands"], "commands")):
            board._commands.append(reader.command(item, f"commands[{k}]"))
        return board

    def __repr__(self) -> str:
        return (
            f"Blackboard({len(self._reports)} position reports"
            + (f" ({self._released} older forgotten)" if self._released else "")
            + f", {len(self._identified)} identified "
            f"observations, {len(self._commands)} queued commands)"
        )
