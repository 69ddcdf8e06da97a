"""A log opened block by block (open_log) replays exactly as the whole log does, in bounded memory."""

from __future__ import annotations

import dataclasses
import math
import os
import re
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from aura_ums.errors import FileFormatError, InputError
from aura_ums.logs import (
    GroundTruth,
    LogMeta,
    LogStream,
    MotionCalibration,
    Odometry,
    ReplayOptions,
    ReplayResult,
    ReverseMotion,
    RobotLog,
    load_log,
    odometry_report_arrays,
    open_log,
    replay_log,
    synthetic_log,
    write_log,
)
from aura_ums.logs._stream import OdometryReports, TruthWindow
from aura_ums.uncertainty import LandmarkClass, TerrainTable
from tests.logs.log_helpers import long_odometry_log

FLOOR = TerrainTable({"floor": TerrainTable.default()["tile"]})
OPTIONS = ReplayOptions(landmark_class=LandmarkClass.POINT)


def _same(stream: ReplayResult, whole: ReplayResult) -> None:
    """Every figure but the update times (wall-clock) equal, bit for bit."""
    for name in stream.trace.__dataclass_fields__:
        if name != "update_us":
            assert np.array_equal(getattr(stream.trace, name), getattr(whole.trace, name), equal_nan=True), (
                name
            )
    ours, theirs = dict(stream.metrics()), dict(whole.metrics())
    ours.pop("median_update_us"), theirs.pop("median_update_us")
    assert ours == theirs


def _steps_without_time(path: Path) -> list[str]:
    rows = path.read_text().splitlines()
    return [",".join(cells[:6] + cells[7:]) for cells in (row.split(",") for row in rows)]


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_log(
        long_odometry_log(4000, rate=50.0, frame_every=5), tmp_path_factory.mktemp("stream") / "log"
    )


@pytest.mark.parametrize("block_bytes", [64, 1000, 1 << 20])
def test_a_streamed_replay_is_the_whole_logs_bit_for_bit(
    folder: Path, tmp_path: Path, block_bytes: int
) -> None:
    whole = replay_log(load_log(folder), FLOOR, OPTIONS, keep_maps=False, steps_csv=tmp_path / "whole.csv")
    stream = replay_log(
        open_log(folder, block_bytes=block_bytes),
        FLOOR,
        OPTIONS,
        keep_maps=False,
        steps_csv=tmp_path / "s.csv",
    )
    _same(stream, whole)
    assert _steps_without_time(tmp_path / "s.csv") == _steps_without_time(tmp_path / "whole.csv")


def test_motion_calibration_class_one_and_until_stream_as_the_whole_log(folder: Path) -> None:
    options = ReplayOptions(
        landmark_class=LandmarkClass.VERTICAL_LINE,
        motion=MotionCalibration(delay_s=0.05, run_scale=1.1, turn_scale=0.9),
        max_interval=0.07,
    )
    whole = replay_log(load_log(folder), FLOOR, options, until=50.0)
    stream = replay_log(open_log(folder, block_bytes=300), FLOOR, options, until=50.0)
    _same(stream, whole)
    assert stream.maps is not None
    assert whole.maps is not None
    assert [m.polygon.vertices.tolist() for m in stream.maps] == [
        m.polygon.vertices.tolist() for m in whole.maps
    ]


def test_reversing_odometry_a_truth_gap_and_the_frame_hook_stream_as_the_whole_log(tmp_path: Path) -> None:
    log = long_odometry_log(2500, rate=50.0, frame_every=5)
    assert log.odometry is not None
    assert log.groundtruth is not None
    odometry = log.odometry
    v = np.where((odometry.time > 10.0) & (odometry.time < 12.0), -odometry.v, odometry.v)
    truth = log.groundtruth
    kept = (truth.time < 20.0) | (truth.time > 21.0)  # a second without truth: a gap
    heading = truth.heading[kept] + np.where(truth.time[kept] > 40.0, 2 * math.pi, 0.0)  # written unwrapped
    log = dataclasses.replace(
        log,
        odometry=Odometry(odometry.time, v, odometry.omega),
        groundtruth=GroundTruth(truth.time[kept], truth.x[kept], truth.y[kept], heading),
    )
    folder = write_log(log, tmp_path / "log")
    options = ReplayOptions(landmark_class=LandmarkClass.POINT, reverse=ReverseMotion.FLIP)
    seen: dict[str, list[tuple[float, float, list[int]]]] = {"whole": [], "stream": []}

    def hook(name: str):  # type: ignore[no-untyped-def]
        return lambda time, grown, rows, focus: seen[name].append((time, grown.area, [r.line for r in rows]))

    whole = replay_log(load_log(folder), FLOOR, options, before_frame=hook("whole"))
    stream = replay_log(open_log(folder, block_bytes=200), FLOOR, options, before_frame=hook("stream"))
    _same(stream, whole)
    assert seen["stream"] == seen["whole"]
    assert np.any(whole.trace.inside < 0)  # the gap is judged as no truth
    # Refused, streamed or whole, naming the file and the first reversing row's line.
    first = int(np.argmax(v < 0.0)) + 3  # a comment line and the header before the rows
    refused = rf"odometry\.csv:{first}: expected forward velocities >= 0 in column 'v' .*, got -"
    with pytest.raises(FileFormatError, match=refused):
        replay_log(open_log(folder, block_bytes=200), FLOOR, OPTIONS)
    with pytest.raises(FileFormatError, match=refused):
        replay_log(load_log(folder), FLOOR, OPTIONS)


def test_a_commands_log_streams_as_the_whole_log(tmp_path: Path) -> None:
    log = synthetic_log(np.random.default_rng(8), duration=30.0)
    reports = log.position_reports(max_interval=0.2)
    folder = write_log(dataclasses.replace(log, odometry=None, commands=reports), tmp_path / "log")
    _same(
        replay_log(open_log(folder, block_bytes=100), FLOOR, OPTIONS),
        replay_log(load_log(folder), FLOOR, OPTIONS),
    )


def test_a_stream_cannot_save_or_resume_a_state(folder: Path) -> None:
    with pytest.raises(InputError, match=r"^log: expected a RobotLog \(load_log\) to resume or save"):
        replay_log(open_log(folder), FLOOR, OPTIONS, save_state=True)


def test_a_bad_row_far_in_a_file_fails_the_replay_with_load_logs_message(
    folder: Path, tmp_path: Path
) -> None:
    broken = tmp_path / "broken"
    broken.mkdir()
    for path in folder.iterdir():
        (broken / path.name).write_bytes(path.read_bytes())
    lines = (broken / "odometry.csv").read_text().splitlines()
    row = len(lines) - 40
    cells = lines[row].split(",")
    lines[row] = ",".join([cells[0], "nan", cells[2]])
    (broken / "odometry.csv").write_text("\n".join(lines) + "\n")
    with pytest.raises(FileFormatError) as expected:
        load_log(broken)
    with pytest.raises(FileFormatError, match=f"^{expected.value}$".replace("(", r"\(").replace(")", r"\)")):
        replay_log(open_log(broken, block_bytes=256), FLOOR, OPTIONS, steps_csv=tmp_path / "steps.csv")
    assert not (tmp_path / "steps.csv").exists()
    assert f":{row + 1}:" in str(expected.value)


@pytest.mark.parametrize("name", ["observations.csv", "odometry.csv", "groundtruth.csv"])
def test_a_file_changed_after_its_log_was_opened_is_refused_when_read(
    name: str, folder: Path, tmp_path: Path
) -> None:
    # Its spans (and the truth's extent) were checked on the version open_log saw.
    changed = tmp_path / "changed"
    changed.mkdir()
    for path in folder.iterdir():
        (changed / path.name).write_bytes(path.read_bytes())
    stream = open_log(changed)
    if name == "groundtruth.csv":  # read again by the replay only without its scratch copy
        stream = dataclasses.replace(stream, truth_scratch=None)
    text = (changed / name).read_text()
    (changed / name).write_text(text[: len(text) // 2].rsplit("\n", 1)[0] + "\n")
    with pytest.raises(FileFormatError, match=f"{name}: expected the file as it was when its log was opened"):
        replay_log(stream, FLOOR, OPTIONS)


@pytest.mark.parametrize(
    ("name", "shift"), [("observations.csv", 2 * 86_400.0), ("odometry.csv", -30 * 86_400.0)]
)
def test_files_on_other_clocks_are_refused_on_opening_as_load_log_refuses_them(
    folder: Path, tmp_path: Path, name: str, shift: float
) -> None:
    # a streamed replay read them as they came: exit 0, every sighting inconsistent (or a
    # report limit naming max_interval for a month of odometry before the first frame)
    shifted = tmp_path / "shifted"
    shifted.mkdir()
    for path in folder.iterdir():
        (shifted / path.name).write_bytes(path.read_bytes())
    lines = (shifted / name).read_text().splitlines()
    for index, line in enumerate(lines):
        if line[:1].isdigit() or line[:1] == "-":
            cells = line.split(",")
            cells[0] = repr(float(cells[0]) + shift)
            lines[index] = ",".join(cells)
    (shifted / name).write_text("\n".join(lines) + "\n")
    with pytest.raises(FileFormatError) as expected:
        load_log(shifted)
    assert "a clock offset between them" in str(expected.value)
    with pytest.raises(FileFormatError, match=f"^{re.escape(str(expected.value))}$"):
        open_log(shifted)
    assert open_log(folder).meta == load_log(folder).meta  # aligned files: no refusal


def test_open_log_refuses_a_bad_block_size(folder: Path) -> None:
    with pytest.raises(InputError, match=r"^block_bytes: expected an integer >= 1, got 0$"):
        open_log(folder, block_bytes=0)
    assert isinstance(open_log(folder), LogStream)
    assert isinstance(open_log(folder).load(), RobotLog)


def _split(values: np.ndarray, cuts: list[int]) -> list[np.ndarray]:
    return np.split(values, sorted({min(c, len(values)) for c in cuts}))


@settings(max_examples=60, deadline=None)
@given(
    st.integers(2, 60),
    st.lists(st.integers(1, 60), max_size=6),
    st.lists(st.integers(1, 30), min_size=1, max_size=6),
    st.integers(0, 2**32 - 1),
)
def test_truth_window_is_groundtruth_at(rows: int, cuts: list[int], asks: list[int], seed: int) -> None:
    rng = np.random.default_rng(seed)
    time = np.cumsum(rng.uniform(0.01, 0.4, rows))
    x, y = rng.normal(size=rows), rng.normal(size=rows)
    heading = rng.uniform(-math.pi, math.pi, rows)
    heading[rng.random(rows) < 0.1] = math.pi  # the boundary
    truth = GroundTruth(time, x, y, heading, max_gap=0.3)
    blocks = zip(*(_split(column, cuts) for column in (time, x, y, heading)), strict=True)
    window = TruthWindow(iter([b for b in blocks if len(b[0])]), 0.3)
    query = np.sort(rng.uniform(time[0] - 0.2, time[-1] + 0.2, sum(asks)))
    begin = 0
    for count in asks:
        part = query[begin : begin + count]
        begin += count
        assert np.array_equal(window.at(part), truth.at(part), equal_nan=True)


@settings(max_examples=60, deadline=None)
@given(
    st.integers(2, 60),
    st.lists(st.integers(1, 60), max_size=6),
    st.lists(st.integers(1, 8), min_size=1, max_size=6),
    st.sampled_from([0.0, 0.07]),
    st.integers(0, 2**32 - 1),
)
def test_odometry_reports_are_odometry_report_arrays(
    rows: int, cuts: list[int], chunks: list[int], delay: float, seed: int
) -> None:
    rng = np.random.default_rng(seed)
    time = np.cumsum(rng.uniform(0.01, 0.2, rows))
    v = rng.normal(0.3, 0.4, rows)
    v[rng.random(rows) < 0.1] = -0.0
    omega = rng.normal(0.0, 0.5, rows)
    start = float(time[0] + delay)
    frames = np.unique(rng.uniform(start, time[-1] + delay + 0.3, sum(chunks)))
    frames = frames[frames > start]
    if not frames.size:
        return
    meta = LogMeta("random", delay_s=delay, run_scale=1.1, turn_scale=0.9)
    expected = odometry_report_arrays(
        time, v, omega, frames, max_interval=0.1, delay_s=delay, run_scale=1.1, turn_scale=0.9,
        start=start, end=float(frames[-1]), reverse=ReverseMotion.FLIP,
    )  # fmt: skip
    blocks = zip(*(_split(column, cuts) for column in (time, v, omega)), strict=True)
    reports = OdometryReports(iter([b for b in blocks if len(b[0])]), meta, start, 0.1, ReverseMotion.FLIP)
    found: list[list[np.ndarray]] = [[], [], []]
    begin = 0
    for count in chunks:
        part = frames[begin : begin + count]
        begin += count
        if part.size:
            for column, values in zip(found, reports.until(part), strict=True):
                column.append(values)
    for column, values in zip(found, expected, strict=True):
        assert np.array_equal(np.concatenate(column), values)


_KILLED_AFTER_OPEN = """
import os, signal, sys
from aura_ums.logs import open_log
stream = open_log(sys.argv[1])
next(stream.groundtruth_blocks())
os.kill(os.getpid(), signal.SIGKILL)
"""


@pytest.mark.skipif(os.name != "posix", reason="SIGKILL and unnamed scratch files are POSIX's")
def test_a_killed_replay_leaves_no_scratch_file_behind(folder: Path, tmp_path: Path) -> None:
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    env = {**os.environ, "TMPDIR": str(scratch)}
    done = subprocess.run([sys.executable, "-c", _KILLED_AFTER_OPEN, str(folder)], env=env, check=False)
    assert done.returncode == -signal.SIGKILL
    assert sorted(path.name for path in scratch.iterdir()) == []


def test_ground_truth_readers_of_one_stream_keep_their_own_places(folder: Path) -> None:
    stream = open_log(folder, block_bytes=4096)
    first, second = stream.groundtruth_blocks(), stream.groundtruth_blocks()
    one = [next(first) for _ in range(3)]
    two = [next(second) for _ in range(2)]
    one.extend(first)
    two.extend(second)
    for blocks in (one, two):
        joined = [np.concatenate(column) for column in zip(*blocks, strict=True)]
        truth = load_log(folder).groundtruth
        assert truth is not None
        assert np.array_equal(joined[0], truth.time)
        assert np.array_equal(joined[3], truth.heading)


def test_a_files_span_is_read_from_its_two_ends_or_not_at_all(tmp_path: Path) -> None:
    from aura_ums.logs._io import Units
    from aura_ums.logs._stream import _file_span

    path = tmp_path / "odometry.csv"
    rows = "".join(f"{0.01 * k!r},0.5,0.0\n" for k in range(20_000))  # beyond both ends' probes
    path.write_text("\ufeff# odometry\ntime,v,omega\n" + rows)
    assert _file_span(path, Units()) == (0.0, 0.01 * 19_999)
    path.write_text("time,v,omega\n")  # no rows: the reader refuses it, not the probe
    assert _file_span(path, Units()) is None
    path.write_text('landmark_id,time\n"a,b",1.0\n"c",2.0\n')  # quoted: left to the blocks
    assert _file_span(path, Units()) is None
    assert _file_span(tmp_path / "missing.csv", Units()) is None


def test_a_files_span_is_not_probed_through_a_named_pipe(tmp_path: Path) -> None:
    # opening one waits for a writer: the probe must not, the file's reader refuses it
    from aura_ums.logs._io import Units
    from aura_ums.logs._stream import _file_span

    pipe = tmp_path / "observations.csv"
    os.mkfifo(pipe)
    assert _file_span(pipe, Units()) is None


@pytest.mark.parametrize("block_bytes", [10**12, 2**63])
def test_a_block_is_at_most_a_whole_log_file(tmp_path: Path, block_bytes: int) -> None:
    # a MemoryError (10**12) and an OverflowError (2**63) before
    folder = write_log(synthetic_log(np.random.default_rng(1), duration=2.0), tmp_path / "log")
    with pytest.raises(
        InputError, match=r"block_bytes: expected at most 268435456 \(256 MiB, .*got " + str(block_bytes)
    ):
        open_log(folder, block_bytes=block_bytes)


def test_a_replay_says_whether_until_left_frames(folder: Path) -> None:
    # The log's frames run to 80 s; a stream read in small blocks finds the cut as it reads.
    for open_it in (load_log, lambda path: open_log(path, block_bytes=300)):
        assert replay_log(open_it(folder), FLOOR, until=50.0).cut_short
        assert not replay_log(open_it(folder), FLOOR, until=1e6).cut_short
        assert not replay_log(open_it(folder), FLOOR).cut_short


def test_a_replay_counts_the_observations_with_bounds_of_their_own(folder: Path, tmp_path: Path) -> None:
    copy = tmp_path / "own"
    shutil.copytree(folder, copy)
    lines = (copy / "observations.csv").read_text().splitlines()
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    assert "bearing_error" not in lines[header]
    own = [*lines[:header], lines[header] + ",bearing_error"]
    # Every other row gives its own bound, the others leave it empty (the meta's applies).
    rows = [line for line in lines[header + 1 :] if not line.startswith("#")]
    own += [line + (",0.05" if index % 2 == 0 else ",") for index, line in enumerate(rows)]
    (copy / "observations.csv").write_text("\n".join(own) + "\n")
    for open_it in (load_log, lambda path: open_log(path, block_bytes=300)):
        assert replay_log(open_it(folder), FLOOR).own_bounds == 0
        replayed = replay_log(open_it(copy), FLOOR)
        assert replayed.own_bounds == sum(1 for index, _ in enumerate(rows) if index % 2 == 0)
