"""The blackboard: position reports in time order, the command buffer, and JSON save/restore."""

from __future__ import annotations

import dataclasses
import json
import math

import pytest

from aura_ums.errors import FileFormatError, InputError
from aura_ums.manager import Blackboard, IdentifiedLandmarkBuffer, PositionReport
from aura_ums.uncertainty import (
    BearingObservation,
    GroundLineObservation,
    RangeBearingObservation,
    TurnAndRun,
)


def report(time: float, turn: float = 0.0, run: float = 1.0) -> PositionReport:
    return PositionReport(time, TurnAndRun(turn, run))


# --- position reports ------------------------------------------------------------------


def test_position_report_is_a_checked_frozen_value() -> None:
    value = report(1.0, 0.5, 2.0)
    assert value.command == TurnAndRun(0.5, 2.0)
    assert isinstance(PositionReport(2, TurnAndRun(0.0, 1.0)).time, float)
    with pytest.raises(dataclasses.FrozenInstanceError, match="cannot assign"):
        value.time = 3.0  # type: ignore[misc]
    with pytest.raises(InputError, match=r"PositionReport\.time: expected a finite number, got nan"):
        PositionReport(math.nan, TurnAndRun(0.0, 1.0))
    with pytest.raises(InputError, match=r"PositionReport\.command: expected a TurnAndRun, got tuple"):
        PositionReport(1.0, (0.0, 1.0))  # type: ignore[arg-type]


def test_reports_are_appended_in_time_order_and_older_ones_refused() -> None:
    board = Blackboard()
    assert board.last_report_time is None
    assert board.report_count == 0
    board.post_reports([report(1.0), report(2.0), report(2.0, run=0.5)])  # equal times are fine
    assert [r.time for r in board.position_reports] == [1.0, 2.0, 2.0]
    assert board.position_reports[-1].command.run == 0.5
    assert board.last_report_time == 2.0
    with pytest.raises(
        InputError, match=r"report\.time: expected a time >= 2\.0 \(the last report's\), got 1\.5"
    ):
        board.post_report(report(1.5))
    assert board.report_count == 3  # the refused report was not added
    with pytest.raises(InputError, match="report: expected a PositionReport, got TurnAndRun"):
        board.post_report(TurnAndRun(0.0, 1.0))  # type: ignore[arg-type]


def test_reports_in_order_are_posted_in_one_call_and_an_older_first_one_refused() -> None:
    board, one_by_one = Blackboard(), Blackboard()
    reports = [report(1.0), report(2.0), report(2.0, run=0.5)]
    board._post_in_order(reports[:1])
    board._post_in_order([])
    board._post_in_order(reports[1:])
    one_by_one.post_reports(reports)
    assert board.position_reports == one_by_one.position_reports
    with pytest.raises(
        InputError, match=r"report\.time: expected a time >= 2\.0 \(the last report's\), got 1\.5"
    ):
        board._post_in_order([report(1.5), report(3.0)])
    assert board.report_count == 3  # neither was added


def test_reports_until_takes_from_start_up_to_until_inclusive() -> None:
    board = Blackboard()
    board.post_reports(report(t) for t in (1.0, 2.0, 3.0, 4.0))
    assert [r.time for r in board.reports_until(2.0)] == [1.0, 2.0]
    assert [r.time for r in board.reports_until(3.5, start=1)] == [2.0, 3.0]
    assert board.reports_until(0.5) == ()
    assert board.reports_until(3.0, start=3) == ()  # start is past until
    assert board.reports_until(10.0, start=9) == ()  # start is past the end
    with pytest.raises(InputError, match="start: expected a non-negative integer, got -1"):
        board.reports_until(1.0, start=-1)
    with pytest.raises(InputError, match="until: expected a finite number, got inf"):
        board.reports_until(math.inf)


def test_report_reads_one_report_by_index() -> None:
    board = Blackboard()
    board.post_reports(report(t) for t in (1.0, 2.0, 3.0))
    assert [board.report(k).time for k in range(3)] == [1.0, 2.0, 3.0]
    assert board.report(1) is board.position_reports[1]
    for bad in (3, -1, True, 1.0):
        with pytest.raises(InputError, match=rf"index: expected an integer in \[0, 3\), got {bad!r}"):
            board.report(bad)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"index: expected an integer in \[0, 0\), got 0"):
        Blackboard().report(0)


# --- command buffer and identified buffer ------------------------------------------------


def test_command_buffer_is_first_in_first_out() -> None:
    board = Blackboard()
    assert board.next_command() is None
    commands = [TurnAndRun(0.1, 1.0), TurnAndRun(-0.2, 0.0), TurnAndRun(0.0, 3.0)]
    for command in commands:
        board.push_command(command)
    assert board.pending_commands == tuple(commands)
    assert board.next_command() == commands[0]
    assert board.pending_commands == tuple(commands[1:])
    assert [board.next_command(), board.next_command(), board.next_command()] == [*commands[1:], None]
    with pytest.raises(InputError, match="command: expected a TurnAndRun, got PositionReport"):
        board.push_command(report(1.0))  # type: ignore[arg-type]


def test_identified_buffer_can_be_shared() -> None:
    shared = IdentifiedLandmarkBuffer()
    board = Blackboard(shared)
    assert board.identified is shared
    shared.post(BearingObservation("pole", 1.0, 0.0, 0.01))
    assert len(board.identified) == 1
    assert len(Blackboard().identified) == 0
    with pytest.raises(
        InputError, match="identified: expected an IdentifiedLandmarkBuffer or None, got list"
    ):
        Blackboard([])  # type: ignore[arg-type]


def test_repr_counts_what_is_held() -> None:
    board = Blackboard()
    board.post_report(report(1.0))
    board.push_command(TurnAndRun(0.0, 1.0))
    assert repr(board) == "Blackboard(1 position reports, 0 identified observations, 1 queued commands)"


# --- save and restore --------------------------------------------------------------------


def full_board() -> Blackboard:
    board = Blackboard()
    awkward = [0.1 + 0.2, math.pi / 3, 1e-300, -2.5e-17, 123.456789012345]
    for k, value in enumerate(awkward):
        board.post_report(PositionReport(10.0 * k + value, TurnAndRun(value, abs(value))))
    board.identified.post(BearingObservation("pole", 3.0, 0.1 + 0.2, 0.01, (0.3, -0.1)))
    board.identified.post(RangeBearingObservation("corner", 2.0, -math.pi / 7, 0.02, 4.25, 5.5))
    board.identified.post(GroundLineObservation("edge", 3.0, 1.0 / 3.0, 0.05, -0.2, 0.01, (0.1, 0.0)))
    board.identified.post(BearingObservation("pole", 2.0, 0.7, 0.01))  # ties keep posting order
    board.push_command(TurnAndRun(math.e, 1.0 / 7.0))
    board.push_command(TurnAndRun(0.0, 0.0))
    return board


def test_round_trip_is_exact() -> None:
    board = full_board()
    text = board.to_json()
    again = Blackboard.from_json(text)
    assert again.position_reports == board.position_reports  # float equality: bit-exact here
    assert again.identified.peek() == board.identified.peek()
    assert [type(o) for o in again.identified.peek()] == [type(o) for o in board.identified.peek()]
    assert again.pending_commands == board.pending_commands
    assert again.to_json() == text
    assert json.loads(text)["format"] == "aura-ums/blackboard"


def test_empty_round_trip() -> None:
    again = Blackboard.from_json(Blackboard().to_json())
    assert again.report_count == 0
    assert not again.identified
    assert again.next_command() is None


def edited(change: str, value: object) -> str:
    data = json.loads(full_board().to_json())
    target = data
    *path, last = change.split("/")
    for key in path:
        target = target[int(key)] if isinstance(target, list) else target[key]
    if value is KeyError:
        del target[last]
    elif isinstance(target, list):
        target[int(last)] = value
    else:
        target[last] = value
    return json.dumps(data)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("{", r"<blackboard JSON>:1:2: expected valid JSON"),
        ("[]", r"<blackboard JSON>: expected an object, got an array"),
        (edited("format", "aura-ums/other"), r"format: expected 'aura-ums/blackboard', got 'aura-ums/other'"),
        (edited("version", 7), r"version: expected 1, got 7"),
        (edited("commands", KeyError), r"expected a key 'commands', got none"),
        (edited("extra", 1), r"expected only the keys .*, got 'extra'"),
        (edited("position_reports", {}), r"position_reports: expected an array, got an object"),
        (
            edited("position_reports/1/time", "soon"),
            r"position_reports\[1\]\.time: expected a finite number, got 'soon'",
        ),
        (
            edited("position_reports/1/time", True),
            r"position_reports\[1\]\.time: expected a finite number, got true",
        ),
        (edited("position_reports/3/time", 0.5), r"position_reports\[3\]\.time: expected a time >= 20\.0 "),
        (
            edited("position_reports/0/command/run", -1.0),
            r"position_reports\[0\]\.command: .*expected a number in \[0, 10000\] m, got -1.0",
        ),
        (edited("position_reports/0/command/spin", 1.0), r"position_reports\[0\]\.command: expected only"),
        (edited("identified/0/class", "Sonar"), r"identified\[0\]\.class: expected one of \['BearingObs"),
        (edited("identified/0/range_max", 1.0), r"identified\[0\]: range_max: expected >= range_min"),
        (
            edited("identified/3/sensor_offset", [1.0]),
            r"identified\[3\]\.sensor_offset: expected \[forward, left\]",
        ),
        (
            edited("identified/2/landmark_id", 5),
            r"identified\[2\]\.landmark_id: expected a string, got 5",
        ),
        (edited("identified/1/range_min", 1.0), r"identified\[1\]: expected only the keys"),
        (edited("commands/1", None), r"commands\[1\]: expected an object, got null"),
        (
            full_board().to_json().replace("0.01", "NaN", 1),
            r"expected valid JSON, got the non-standard number NaN",
        ),
    ],
)
def test_malformed_json_names_what_is_wrong(text: str, message: str) -> None:
    with pytest.raises(FileFormatError, match=message):
        Blackboard.from_json(text)


def test_source_names_the_file_and_non_text_is_refused() -> None:
    with pytest.raises(FileFormatError, match=r"^board\.json: expected JSON text \(str\), got bytes$"):
        Blackboard.from_json(b"{}", source="board.json")  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"board\.json: version: expected 1, got nothing"):
        Blackboard.from_json('{"format": "aura-ums/blackboard"}', source="board.json")


# --- forgetting consumed reports -----------------------------------------------------------


def test_forgotten_reports_keep_the_indices_of_the_rest() -> None:
    board = Blackboard()
    board.post_reports(report(float(t)) for t in range(6))
    board.forget_reports_before(4)
    assert (board.report_count, board.released_reports) == (6, 4)
    assert [r.time for r in board.position_reports] == [4.0, 5.0]
    assert board.report(4).time == 4.0
    assert [r.time for r in board.reports_until(10.0, start=5)] == [5.0]
    board.forget_reports_before(4)  # again: nothing more
    board.post_report(report(6.0))
    assert board.report(6).time == 6.0
    assert board.report_count == 7
    with pytest.raises(
        InputError, match=r"index: expected an integer in \[4, 7\) \(older ones forgotten\), got 3"
    ):
        board.report(3)
    with pytest.raises(
        InputError, match=r"start: expected an integer >= 4 \(older reports were forgotten\), got 2"
    ):
        board.reports_until(10.0, start=2)
    with pytest.raises(InputError, match=r"report\.time: expected a time >= 6\.0"):
        board.post_report(report(5.5))  # the time order holds across what was forgotten


@pytest.mark.parametrize("index", [3, 7, -1, 1.0, True])
def test_forgetting_the_newest_report_or_a_forgotten_one_is_refused(index: object) -> None:
    board = Blackboard()
    board.post_reports(report(float(t)) for t in range(7))
    board.forget_reports_before(4)
    with pytest.raises(
        InputError, match=r"index: expected an integer in \[4, 6\] \(the newest report is kept\)"
    ):
        board.forget_reports_before(index)  # type: ignore[arg-type]


def test_a_board_that_forgot_round_trips_and_one_that_did_not_reads_as_before() -> None:
    board = Blackboard()
    board.post_reports(report(float(t), 0.1 * t) for t in range(5))
    untouched = json.loads(board.to_json())
    assert "released_reports" not in untouched
    board.forget_reports_before(3)
    again = Blackboard.from_json(board.to_json())
    assert (again.report_count, again.released_reports) == (5, 3)
    assert again.position_reports == board.position_reports
    assert again.to_json() == board.to_json()
    assert "older forgotten" in repr(again)
    with pytest.raises(FileFormatError, match=r"released_reports"):
        Blackboard.from_json(board.to_json().replace('"released_reports": 3', '"released_reports": -1'))
