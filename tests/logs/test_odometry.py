"""Odometry to turn-and-run position reports: integrals, cut times, intervals and edge cases."""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from aura_ums.errors import InputError
from aura_ums.logs import ReverseMotion, odometry_to_commands
from aura_ums.manager import PositionReport


def held_integral(time: list[float], values: list[float], low: float, high: float) -> float:
    """Integral over [low, high] of the zero-order-hold signal, summed row by row."""
    total = 0.0
    for i in range(len(time) - 1):
        start, stop = max(time[i], low), min(time[i + 1], high)
        if stop > start:
            total += values[i] * (stop - start)
    return total


def compose(reports: tuple[PositionReport, ...]) -> tuple[float, float, float]:
    """The pose reached from (0, 0, 0) by executing the reports' turn-then-run commands exactly."""
    x = y = heading = 0.0
    for report in reports:
        heading += report.command.turn
        x += report.command.run * math.cos(heading)
        y += report.command.run * math.sin(heading)
    return x, y, heading


def pieces_of(reports: tuple[PositionReport, ...]) -> list[tuple[float, float, float]]:
    """(time, turn, run) of each piece: the reports of one time summed."""
    pieces: list[tuple[float, float, float]] = []
    for report in reports:
        if pieces and pieces[-1][0] == report.time:
            time, turn, run = pieces[-1]
            pieces[-1] = (time, turn + report.command.turn, run + report.command.run)
        else:
            pieces.append((report.time, report.command.turn, report.command.run))
    return pieces


@st.composite
def odometry_cases(draw: st.DrawFn) -> dict[str, Any]:
    first = draw(st.floats(-100.0, 100.0))
    steps = draw(st.lists(st.floats(0.01, 1.0), min_size=0, max_size=15))
    time = (first + np.concatenate(([0.0], np.cumsum(steps)))).tolist()
    n = len(time)
    delay = draw(st.sampled_from([0.0, 0.2]))
    low, high = time[0] + delay, time[-1] + delay
    cuts = draw(st.lists(st.floats(low - 1.0, high + 1.0), max_size=8))
    start = draw(st.none() | st.floats(low - 0.5, high))
    end = draw(st.none() | st.floats(high - 0.5, high + 0.5))
    if start is not None and end is not None and end < start:
        start, end = end, start
    return {
        "time": time,
        "v": draw(st.lists(st.floats(0.0, 2.0), min_size=n, max_size=n)),
        "omega": draw(st.lists(st.floats(-1.0, 1.0), min_size=n, max_size=n)),
        "cuts": cuts,
        "max_interval": draw(st.floats(0.1, 2.0) | st.just(math.inf)),
        "delay_s": delay,
        "run_scale": draw(st.floats(0.5, 2.0)),
        "turn_scale": draw(st.floats(0.5, 2.0)),
        "start": start,
        "end": end,
    }


@settings(max_examples=40)
@given(odometry_cases())
def test_reports_integrate_the_motion_and_respect_cuts_and_intervals(case: dict[str, Any]) -> None:
    reports = odometry_to_commands(
        case["time"],
        case["v"],
        case["omega"],
        case["cuts"],
        max_interval=case["max_interval"],
        delay_s=case["delay_s"],
        run_scale=case["run_scale"],
        turn_scale=case["turn_scale"],
        start=case["start"],
        end=case["end"],
    )
    shifted = [t + case["delay_s"] for t in case["time"]]
    start, end = case["start"], case["end"]
    if start is None:
        start = shifted[0] if end is None else min(shifted[0], end)
    if end is None:
        end = max(shifted[-1], start)
    if end == start:
        assert reports == ()
        return
    pieces = pieces_of(reports)
    times = [time for time, _, _ in pieces]
    assert times[-1] == end
    assert all(b > a for a, b in zip([start, *times], times, strict=False))
    for cut in case["cuts"]:
        if start < cut <= end:
            assert cut in times
    edges = [start, *times]
    gaps = np.diff(edges)
    assert np.all(gaps <= case["max_interval"] * (1 + 1e-9) + 1e-12)
    for low, high, (_, piece_turn, piece_run) in zip(edges[:-1], edges[1:], pieces, strict=True):
        run = case["run_scale"] * held_integral(shifted, case["v"], low, high)
        turn = case["turn_scale"] * held_integral(shifted, case["omega"], low, high)
        assert piece_run == pytest.approx(run, rel=1e-9, abs=1e-9)
        assert piece_turn == pytest.approx(turn, rel=1e-9, abs=1e-9)
    for report in reports:
        assert report.command.run >= 0.0
    for first, second in itertools.pairwise(reports):
        if first.time == second.time:  # a piece that turns while it runs: half, the run, half
            assert second.command.run == 0.0 < first.command.run
            assert first.command.turn == second.command.turn != 0.0
    total_run = case["run_scale"] * held_integral(shifted, case["v"], start, end)
    assert sum(r.command.run for r in reports) == pytest.approx(total_run, rel=1e-9, abs=1e-9)


@pytest.mark.parametrize("max_interval", [1.0, 0.1, 0.01])
def test_constant_curvature_matches_the_arc(max_interval: float) -> None:
    v, omega, duration = 0.5, 0.2, 10.0
    reports = odometry_to_commands([0.0, duration], [v, 0.0], [omega, 0.0], max_interval=max_interval)
    pieces = math.ceil(duration / max_interval - 1e-9)
    assert len(reports) == 2 * pieces  # every piece turns while it runs: half, the run, half
    for ahead, after in zip(reports[::2], reports[1::2], strict=True):
        assert ahead.time == after.time
        assert ahead.command.turn == after.command.turn
        assert after.command.run == 0.0
        # the piece turns and runs in the ratio of the radius v / omega
        assert ahead.command.run == pytest.approx(2.0 * ahead.command.turn * v / omega)
    x, y, heading = compose(reports)
    radius, angle = v / omega, omega * duration
    assert heading == pytest.approx(angle)
    # Half the turn first puts each piece's run along the arc's chord; only its length, the
    # arc's, is longer than the chord, by about run * turn**2 / 24: second order in the turn.
    error = math.hypot(x - radius * math.sin(angle), y - radius * (1 - math.cos(angle)))
    turn = omega * min(max_interval, duration)
    assert error <= v * duration * turn**2 / 12.0 + 1e-12
    # Turning first, the whole turn, was first order: off by half the piece's turn.
    whole = [(r.command.turn, r.command.run) for r in reports]
    first_x = first_y = first_heading = 0.0
    for (turn_a, run_a), (turn_b, _) in zip(whole[::2], whole[1::2], strict=True):
        first_heading += turn_a + turn_b
        first_x += run_a * math.cos(first_heading)
        first_y += run_a * math.sin(first_heading)
    turned_first = math.hypot(first_x - radius * math.sin(angle), first_y - radius * (1 - math.cos(angle)))
    assert turned_first >= 0.1 * v * duration * omega * max_interval > 2.0 * error


def test_delay_shifts_the_reports() -> None:
    time, v, omega = [0.0, 0.3, 1.0], [0.5, 1.0, 0.0], [0.1, -0.2, 0.0]
    delayed = odometry_to_commands(time, v, omega, [0.5], delay_s=0.25)
    shifted = odometry_to_commands([t + 0.25 for t in time], v, omega, [0.5])
    assert delayed == shifted
    assert delayed[0].time > 0.25


def test_motion_outside_the_record_is_zero() -> None:
    reports = odometry_to_commands([0.0, 1.0], [1.0, 5.0], [0.0, 9.0], start=-0.5, end=2.0, max_interval=0.5)
    assert [r.time for r in reports] == [0.0, 0.5, 1.0, 1.5, 2.0]
    assert [r.command.run for r in reports] == [0.0, 0.5, 0.5, 0.0, 0.0]  # the last row only ends the record


def test_a_turn_too_small_to_halve_stays_one_command() -> None:
    # Half of 5e-324 rad is 0.0: split, the piece's halves would not sum to its turn (hypothesis).
    (tiny,) = odometry_to_commands([0.0, 1.0], [0.5, 0.0], [5e-324, 0.0], max_interval=2.0)
    assert (tiny.time, tiny.command.turn, tiny.command.run) == (1.0, 5e-324, 0.5)
    halves = odometry_to_commands([0.0, 1.0], [0.5, 0.0], [1e-323, 0.0], max_interval=2.0)
    assert [(r.command.turn, r.command.run) for r in halves] == [(5e-324, 0.5), (5e-324, 0.0)]


def test_degenerate_spans_give_nothing() -> None:
    assert odometry_to_commands([3.0], [1.0], [1.0], [3.0, 4.0]) == ()
    assert odometry_to_commands([0.0, 1.0], [1.0, 0.0], [0.0, 0.0], start=0.5, end=0.5) == ()
    # One bound given beyond the other's default: an empty span, not an error.
    assert odometry_to_commands([0.0, 1.0], [1.0, 0.0], [0.0, 0.0], end=-1.0) == ()
    assert odometry_to_commands([0.0, 1.0], [1.0, 0.0], [0.0, 0.0], start=2.0) == ()


def test_cut_times_outside_or_at_the_start_are_ignored() -> None:
    reports = odometry_to_commands(
        [0.0, 1.0], [1.0, 0.0], [0.0, 0.0], [-1.0, 0.0, 0.5, 0.5, 7.0], max_interval=math.inf
    )
    assert [r.time for r in reports] == [0.5, 1.0]


def test_reversing_is_refused_by_default() -> None:
    with pytest.raises(InputError, match=r"v: expected forward velocities >= 0 .*got -0\.2 at row 1"):
        odometry_to_commands([0.0, 1.0, 2.0], [0.5, -0.2, 0.0], [0.0, 0.0, 0.0])


def test_flip_reports_reversing_as_turn_round_run_turn_back() -> None:
    time, v, omega = [0.0, 1.0, 2.0, 3.0], [1.0, -1.0, 0.5, 0.0], [0.0, 0.2, 0.0, 0.0]
    reports = odometry_to_commands(time, v, omega, max_interval=math.inf, reverse=ReverseMotion.FLIP)
    assert [r.time for r in reports] == [1.0, 2.0, 2.0, 3.0]  # cut where v changes sign; one flip pair
    assert reports[1].command.turn == pytest.approx(0.1 + math.pi)
    assert reports[2].command.turn == pytest.approx(0.1 - math.pi)
    assert reports[2].command.run == 0.0
    x, y, heading = compose(reports)
    # Forward 1, then back 1 along the chord of the reversing arc (its middle heading, 0.1),
    # then forward 0.5 at the heading it ended with, 0.2.
    assert heading == pytest.approx(0.2)
    assert x == pytest.approx(1.0 - math.cos(0.1) + 0.5 * math.cos(0.2))
    assert y == pytest.approx(-math.sin(0.1) + 0.5 * math.sin(0.2))
    assert sum(r.command.run for r in reports) == pytest.approx(2.5)


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"time": [0.0, 1.0], "v": [1.0]}, r"time, v, omega: expected equal lengths, got 2, 1, 2"),
        ({"time": [], "v": [], "omega": []}, r"time: expected at least one row, got none"),
        ({"time": [1.0, 1.0]}, r"time: expected strictly increasing times, got 1\.0 after 1\.0"),
        ({"v": [1.0, math.nan]}, r"v: expected finite numbers"),
        ({"cut_times": [math.inf]}, r"cut_times: expected finite numbers"),
        ({"max_interval": 0.0}, r"max_interval: expected a positive number of seconds \(or inf\), got 0\.0"),
        ({"max_interval": math.nan}, r"max_interval: expected a positive number"),
        ({"delay_s": -1.0}, r"delay_s: expected a non-negative number, got -1\.0"),
        ({"run_scale": 0.0}, r"run_scale: expected a positive number, got 0\.0"),
        ({"turn_scale": math.inf}, r"turn_scale: expected a finite number"),
        ({"start": 1.0, "end": 0.0}, r"end: expected a time >= start \(1\.0\), got 0\.0"),
        ({"reverse": "flip"}, r"reverse: expected a ReverseMotion, got 'flip'"),
        (
            {"max_interval": 1e-6, "end": 100.0},
            r"max_interval: expected at most 2000000 reports \(about 500 MB\), "
            r"got 100000000 \(about 25,000 MB",
        ),
    ],
)
def test_bad_arguments(kwargs: dict[str, Any], pattern: str) -> None:
    values: dict[str, Any] = {"time": [0.0, 1.0], "v": [1.0, 0.0], "omega": [0.0, 0.0]}
    values.update(kwargs)
    with pytest.raises(InputError, match=pattern):
        odometry_to_commands(**values)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (
            {"run_scale": 1e6},
            r"run_scale: expected runs of at most 10000 m a report .*got 20000 m \(run_scale 1000000\.0\)",
        ),
        (
            {"turn_scale": 1e6},
            r"turn_scale: expected turns of at most 1000 rad a report .*\(turn_scale 1000000\.0\)",
        ),
    ],
)
def test_a_scale_past_the_commands_range_is_named(kwargs: dict[str, Any], match: str) -> None:
    # named TurnAndRun.run (or turn) before
    with pytest.raises(InputError, match=match):
        odometry_to_commands([0.0, 0.1, 0.2], [0.1] * 3, [0.1] * 3, **kwargs)
