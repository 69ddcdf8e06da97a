"""Recorded velocities to turn-and-run position reports: integration under a zero-order hold."""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import ANGLE, LENGTH, Choice, finite_float, float_array
from aura_ums.errors import InputError
from aura_ums.manager import PositionReport
from aura_ums.uncertainty import TurnAndRun

#: Longest time, seconds, one position report covers by default (a replay's step).
DEFAULT_MAX_INTERVAL = 0.25
#: Memory one position report takes (its PositionReport, TurnAndRun, floats and slot), bytes.
REPORT_BYTES = 250
#: Most reports from one call, from a memory budget of 500 MB (2 million: 139 hours of
#: motion at the default interval); more is a mistake (a clock jump, an interval far too small).
MAX_REPORTS = 500_000_000 // REPORT_BYTES


#: Why a negative forward velocity is refused, and what to pass instead (every such message).
NO_REVERSE = (
    "the turn-and-run model has no reverse; pass --reverse flip to aura-ums, or reverse=ReverseMotion.FLIP"
)


class ReversingError(InputError):
    """A negative forward velocity refused (``ReverseMotion.ERROR``), with its row's index.

    ``row`` counts the record's rows from 0, so that a reader of the record's file can
    name the row's line (:func:`~aura_ums.logs._io.reversed_at`).
    """

    def __init__(self, row: int, value: float) -> None:
        super().__init__(f"v: expected forward velocities >= 0 ({NO_REVERSE}), got {value!r} at row {row}")
        self.row = row
        self.value = value


class ReverseMotion(Choice):
    """What :func:`odometry_to_commands` does with negative forward velocities.

    The turn-and-run model has no reverse gear.

    - ``ERROR``: refuse, naming the first negative row (the default).
    - ``FLIP``: cut the motion where the sign of ``v`` changes; report a reversing piece
      that turns by ``t`` and backs up by ``d`` as ``TurnAndRun(t / 2 + pi, d)`` followed, at
      the same time, by ``TurnAndRun(t / 2 - pi, 0)``: turn round, run forward, turn back,
      with half the piece's turn before the run and half after, as every piece that turns
      while it runs. The end pose is the same, and growth through the two half turns is
      sound, if wide.

    Examples
    --------
    >>> ReverseMotion("flip")
    <ReverseMotion.FLIP: 'flip'>
    """

    ERROR = "error"
    FLIP = "flip"


def cumulative_integral(
    time: NDArray[np.float64], values: NDArray[np.float64], query: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Integrate a zero-order-hold signal from ``time[0]`` to each query time.

    Parameters
    ----------
    time : ndarray, shape (n,)
        Row times, seconds, strictly increasing, n >= 1.
    values : ndarray, shape (n,)
        Row ``i`` holds on ``[time[i], time[i + 1])``; the last row only ends the record.
    query : ndarray, shape (k,)
        Seconds, any order.

    Returns
    -------
    ndarray, shape (k,)
        The integral of the signal from ``time[0]`` to each query time (value unit times
        seconds); 0 before ``time[0]``, constant after ``time[-1]``.

    Examples
    --------
    >>> time, values = np.array([0.0, 1.0, 3.0]), np.array([2.0, 1.0, 5.0])
    >>> cumulative_integral(time, values, np.array([-1.0, 0.5, 2.0, 9.0]))
    array([0., 1., 3., 4.])
    """
    steps = values[:-1] * np.diff(time)
    at_rows = np.concatenate(([0.0], np.cumsum(steps)))
    clipped = np.clip(query, time[0], time[-1])
    row = np.clip(np.searchsorted(time, clipped, side="right") - 1, 0, len(time) - 1)
    partial = np.where(row < len(time) - 1, values[row] * (clipped - time[row]), 0.0)
    result: NDArray[np.float64] = at_rows[row] + partial
    return result


def report_times(
    boundaries: NDArray[np.float64], start: float, end: float, max_interval: float
) -> NDArray[np.float64]:
    """Return the end times of the reports, cut at the boundaries and at most ``max_interval`` apart.

    The times are the boundaries in ``(start, end]``, ``end``, and more evenly spaced
    between them wherever two are more than ``max_interval`` apart.

    Parameters
    ----------
    boundaries : ndarray, shape (k,)
        Seconds at which a report must end, any order; those outside ``(start, end]`` are ignored.
    start, end : float
        Seconds, ``start <= end``.
    max_interval : float
        Seconds, > 0 (inf: no subdivision).

    Returns
    -------
    ndarray, shape (m,)
        Strictly increasing seconds in ``(start, end]``, ending with ``end``; empty when
        ``start == end``.

    Examples
    --------
    >>> report_times(np.array([0.3, 5.0]), 0.0, 1.0, 0.4).round(6).tolist()
    [0.3, 0.65, 1.0]
    """
    if end <= start:
        return np.empty(0)
    inside = boundaries[(boundaries > start) & (boundaries < end)]
    anchors = np.unique(np.concatenate(([start], inside, [end])))
    if not math.isfinite(max_interval):
        return anchors[1:]
    gaps = np.diff(anchors)
    pieces = np.maximum(np.ceil(gaps / max_interval), 1.0)
    total = float(pieces.sum())
    if total > MAX_REPORTS:
        raise _too_many_reports(total, max_interval, end - start)
    counts = pieces.astype(np.int64)
    gap_index = np.repeat(np.arange(len(gaps)), counts)
    step = np.arange(len(gap_index)) - np.repeat(np.cumsum(counts) - counts, counts) + 1
    times = anchors[gap_index] + gaps[gap_index] * (step / counts[gap_index])
    times[np.cumsum(counts) - 1] = anchors[1:]  # the anchors themselves, exactly
    keep = np.concatenate((np.diff(times) > 0.0, [True]))
    result: NDArray[np.float64] = times[keep]
    return result


def odometry_report_arrays(
    time: ArrayLike,
    v: ArrayLike,
    omega: ArrayLike,
    cut_times: ArrayLike = (),
    *,
    max_interval: float = 0.25,
    delay_s: float = 0.0,
    run_scale: float = 1.0,
    turn_scale: float = 1.0,
    start: float | None = None,
    end: float | None = None,
    reverse: ReverseMotion = ReverseMotion.ERROR,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Return the reports of :func:`odometry_to_commands` as arrays: no Python object per report.

    Parameters and errors are those of :func:`odometry_to_commands`.

    Returns
    -------
    times, turns, runs : ndarray, shape (m,)
        Seconds, radians and metres (>= 0) of each report, in order; the two reports of
        a piece that turns while it runs (or backs up) have the same time.

    Examples
    --------
    >>> times, turns, runs = odometry_report_arrays([0.0, 2.0], [0.5, 0.0], [0.1, 0.0], max_interval=1.0)
    >>> times.tolist(), runs.tolist()     # each piece turns while it runs: two reports
    ([1.0, 1.0, 2.0, 2.0], [0.5, 0.0, 0.5, 0.0])
    >>> odometry_report_arrays([0.0, 2.0], [0.5, 0.0], [0.0, 0.0], max_interval=1.0)[0].tolist()
    [1.0, 2.0]
    >>> odometry_report_arrays([0.0, 1.0], [1.0, 0.0], [0.0, 0.0], max_interval=0.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: max_interval: expected a positive number of seconds (or inf), got 0.0
    """
    t = float_array(time, "time").reshape(-1)
    forward = float_array(v, "v").reshape(-1)
    angular = float_array(omega, "omega").reshape(-1)
    if not len(t) == len(forward) == len(angular):
        raise InputError(
            f"time, v, omega: expected equal lengths, got {len(t)}, {len(forward)}, {len(angular)}"
        )
    if len(t) == 0:
        raise InputError("time: expected at least one row, got none")
    steps = np.diff(t)
    if np.any(steps <= 0.0):
        row = int(np.argmax(steps <= 0.0)) + 1
        raise InputError(
            f"time: expected strictly increasing times, got {float(t[row])!r} after {float(t[row - 1])!r}"
        )
    cuts = float_array(cut_times, "cut_times").reshape(-1)
    if not isinstance(reverse, ReverseMotion):
        raise InputError(f"reverse: expected a ReverseMotion, got {reverse!r}")
    if isinstance(max_interval, bool) or not isinstance(max_interval, (int, float)) or not max_interval > 0:
        raise InputError(
            f"max_interval: expected a positive number of seconds (or inf), got {max_interval!r}"
        )
    delay = finite_float(delay_s, "delay_s")
    if delay < 0.0:
        raise InputError(f"delay_s: expected a non-negative number, got {delay!r}")
    for name, scale in (("run_scale", run_scale), ("turn_scale", turn_scale)):
        if finite_float(scale, name) <= 0.0:
            raise InputError(f"{name}: expected a positive number, got {scale!r}")
    reversing = forward < 0.0
    if reverse is ReverseMotion.ERROR and np.any(reversing):
        row = int(np.argmax(reversing))
        raise ReversingError(row, float(forward[row]))

    t = t + delay
    low = None if start is None else finite_float(start, "start")
    high = None if end is None else finite_float(end, "end")
    # A default never conflicts with a given bound: the span is then empty.
    if low is None:
        low = float(t[0]) if high is None else min(float(t[0]), high)
    if high is None:
        high = max(float(t[-1]), low)
    if high < low:
        raise InputError(f"end: expected a time >= start ({low!r}), got {high!r}")
    boundaries = cuts
    if np.any(reversing):
        changes = np.flatnonzero(np.diff(reversing.astype(np.int8)) != 0) + 1
        boundaries = np.concatenate((cuts, t[changes]))
    times = report_times(boundaries, low, high, float(max_interval))
    if len(times) == 0:
        empty = np.empty(0)
        return empty, empty, empty
    edges = np.concatenate(([low], times))
    turn = np.diff(cumulative_integral(t, angular, edges)) * turn_scale
    ahead = np.maximum(np.diff(cumulative_integral(t, np.maximum(forward, 0.0), edges)) * run_scale, 0.0)
    back = np.maximum(np.diff(cumulative_integral(t, np.maximum(-forward, 0.0), edges)) * run_scale, 0.0)
    out_times, out_turns, out_runs = piece_commands(times, turn, ahead, back)
    _check_report_ranges(out_turns, out_runs, run_scale, turn_scale)
    return out_times, out_turns, out_runs


def _check_report_ranges(
    turns: NDArray[np.float64], runs: NDArray[np.float64], run_scale: float, turn_scale: float
) -> None:
    """Refuse reports a TurnAndRun would refuse, naming the scale: not ``TurnAndRun.run`` deep inside."""
    longest = float(runs.max())
    if longest > LENGTH.high:
        raise InputError(
            f"run_scale: expected runs of at most {LENGTH.high:g} m a report (run_scale times the "
            f"odometry's distance over at most max_interval), got {longest:g} m (run_scale {run_scale!r})"
        )
    widest = float(np.abs(turns).max())
    if widest > ANGLE.high:
        raise InputError(
            f"turn_scale: expected turns of at most {ANGLE.high:g} rad a report (turn_scale times the "
            f"odometry's turn over at most max_interval), got {widest:g} rad (turn_scale {turn_scale!r})"
        )


def piece_commands(
    times: NDArray[np.float64],
    turn: NDArray[np.float64],
    ahead: NDArray[np.float64],
    back: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Return report times, turns and runs with every piece that turns while it runs made two commands.

    ``times``, ``turn`` (rad), ``ahead`` and ``back`` (m, >= 0) are per piece; the log is
    cut at every sign change, so a piece never runs both ways. A piece that turns while it
    runs moves along its chord, which points along its middle heading: it becomes half its
    turn and its run, then, at the same time, the other half of its turn and no run. A turn
    first and the run after it would end the piece off to the side by about half the run
    times the turn, a systematic error no terrain statistic bounds. A piece backing up
    becomes half its turn and a turn round, a run of ``back``, then the other half of its
    turn and a turn back, with no run. A piece that only turns or only runs stays one command.

    Examples
    --------
    >>> times, turns, runs = piece_commands(
    ...     np.array([1.0, 2.0, 3.0]), np.array([0.2, 0.0, 0.4]), np.array([0.5, 0.5, 0.0]), np.zeros(3)
    ... )
    >>> times.tolist(), turns.tolist(), runs.tolist()
    ([1.0, 1.0, 2.0, 3.0], [0.1, 0.1, 0.0, 0.4], [0.5, 0.0, 0.5, 0.0])
    """
    flipped = back > 0.0
    # A turn too small to halve (a subnormal: half of 5e-324 is 0) stays one command, as no turn.
    split = flipped | ((ahead > 0.0) & (turn / 2.0 != 0.0))
    if not np.any(split):
        return times, turn, ahead
    count = np.where(split, 2, 1)
    first = np.cumsum(count) - count
    out_times = np.repeat(times, count)
    out_turns = np.repeat(turn, count)
    out_runs = np.repeat(ahead, count)
    half = turn[split] / 2.0
    out_turns[first[split]] = half
    out_turns[first[split] + 1] = half
    out_runs[first[split] + 1] = 0.0
    out_turns[first[flipped]] += math.pi
    out_runs[first[flipped]] = back[flipped]
    out_turns[first[flipped] + 1] -= math.pi
    return out_times, out_turns, out_runs


def _megabytes(reports: float) -> str:
    return f"{reports * REPORT_BYTES / 1e6:,.0f} MB"


def _too_many_reports(total: float, max_interval: float, span: float) -> InputError:
    return InputError(
        f"max_interval: expected at most {MAX_REPORTS} reports (about {_megabytes(MAX_REPORTS)}), "
        f"got {total:.0f} (about {_megabytes(total)}; max_interval {max_interval!r} s over {span!r} s)"
    )


def odometry_to_commands(
    time: ArrayLike,
    v: ArrayLike,
    omega: ArrayLike,
    cut_times: ArrayLike = (),
    *,
    max_interval: float = DEFAULT_MAX_INTERVAL,
    delay_s: float = 0.0,
    run_scale: float = 1.0,
    turn_scale: float = 1.0,
    start: float | None = None,
    end: float | None = None,
    reverse: ReverseMotion = ReverseMotion.ERROR,
) -> tuple[PositionReport, ...]:
    """Integrate recorded velocities into turn-and-run position reports.

    Row ``i`` holds from ``time[i]`` until ``time[i + 1]`` (zero-order hold); the last row
    only ends the record, and there is no motion outside it. Every time is first delayed by
    ``delay_s``. The motion from ``start`` to ``end`` is cut at each of ``cut_times`` in
    ``(start, end]``, at ``end``, and evenly in between wherever two cuts are more than
    ``max_interval`` apart. The piece ending at each cut ``T``, of turn ``t = turn_scale *
    integral(omega)`` and run ``r = run_scale * integral(|v|)``, becomes
    ``PositionReport(T, TurnAndRun(t, r))`` when it only turns or only runs, and otherwise
    ``PositionReport(T, TurnAndRun(t / 2, r))`` then ``PositionReport(T, TurnAndRun(t / 2,
    0))``: a piece that turns while it runs moves along its chord, which points along its
    middle heading. :func:`odometry_report_arrays` gives the same reports as three arrays.

    Parameters
    ----------
    time : array_like, shape (n,)
        Seconds, strictly increasing, n >= 1.
    v : array_like, shape (n,)
        Forward velocity, m/s.
    omega : array_like, shape (n,)
        Angular velocity, rad/s, counter-clockwise positive.
    cut_times : array_like, shape (k,)
        Seconds (after the delay, like ``start`` and ``end``) at which a report must end.
    max_interval : float
        Longest time, seconds, a report may cover; > 0, ``math.inf`` for none.
    delay_s : float
        Seconds, >= 0: the motion recorded at ``t`` happens at ``t + delay_s``.
    run_scale, turn_scale : float
        Factors, > 0, applied to the integrated run and turn.
    start, end : float or None
        Seconds, ``start <= end``; default the first and the last delayed row time (but
        never past the other bound when only one is given: the span is then empty).
    reverse : ReverseMotion
        ``ERROR`` (default) refuses negative ``v``; ``FLIP`` reports reversing pieces as a
        turn round, a forward run and a turn back (two reports with the same time).

    Returns
    -------
    tuple of PositionReport
        Runs >= 0; times increasing, strictly but for the pairs of one piece; empty when
        ``start == end``. The runs sum to ``run_scale`` times the integral of ``|v|`` and
        the turns to ``turn_scale`` times the integral of ``omega`` (plus 0 net for flips).

    Raises
    ------
    InputError
        For non-finite or mismatched arrays, unsorted times, bad scales, ``end < start``,
        or negative ``v`` with ``ReverseMotion.ERROR``.

    Examples
    --------
    >>> reports = odometry_to_commands([0.0, 2.0], [0.5, 0.0], [0.1, 0.0], [0.5], max_interval=1.0)
    >>> for r in reports:      # each piece turns while it runs: half its turn, its run, the other half
    ...     print(r.time, round(r.command.turn, 4), r.command.run)
    0.5 0.025 0.25
    0.5 0.025 0.0
    1.25 0.0375 0.375
    1.25 0.0375 0.0
    2.0 0.0375 0.375
    2.0 0.0375 0.0
    >>> odometry_to_commands([0.0, 1.0], [1.0, 1.0], [0.0, 0.0], start=1.0)   # nothing to cover
    ()
    """
    times, turns, runs = odometry_report_arrays(
        time,
        v,
        omega,
        cut_times,
        max_interval=max_interval,
        delay_s=delay_s,
        run_scale=run_scale,
        turn_scale=turn_scale,
        start=start,
        end=end,
        reverse=reverse,
    )
    # report_times bounds the pieces; a piece that turns while it runs is two reports, and
    # each report here is a Python object, so the bound is checked again on the reports.
    if len(times) > MAX_REPORTS:
        raise _too_many_reports(len(times), max_interval, float(times[-1] - times[0]))
    return tuple(reports_of(times, turns, runs))


def reports_of(
    times: NDArray[np.float64], turns: NDArray[np.float64], runs: NDArray[np.float64]
) -> Iterator[PositionReport]:
    """Yield the position reports of :func:`odometry_report_arrays`' arrays, one at a time.

    Examples
    --------
    >>> list(reports_of(np.array([0.5]), np.array([0.1]), np.array([0.2])))
    [PositionReport(time=0.5, command=TurnAndRun(turn=0.1, run=0.2))]
    >>> list(reports_of(np.empty(0), np.empty(0), np.empty(0)))
    []
    """
    for when, turn, run in zip(times.tolist(), turns.tolist(), runs.tolist(), strict=True):
        yield PositionReport(when, TurnAndRun(turn, run))
