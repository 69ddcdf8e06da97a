"""Long logs: a replay keeps a few numbers per step, streams its per-step CSV, and judges as before."""

from __future__ import annotations

import dataclasses
import gc
import math
import tracemalloc
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums.errors import FileFormatError, InputError
from aura_ums.logs import (
    ReplayOptions,
    ReplayResult,
    ReplayTrace,
    RobotLog,
    open_log,
    replay_log,
    synthetic_log,
    write_log,
)
from aura_ums.uncertainty import LandmarkClass, TerrainTable, TurnAndRun
from tests.logs.log_helpers import long_odometry_log

FLOOR = TerrainTable({"floor": TerrainTable.default()["tile"]})
OPTIONS = ReplayOptions(landmark_class=LandmarkClass.POINT)


@pytest.fixture(scope="module")
def long_log() -> RobotLog:
    return long_odometry_log(100_000)  # 1,000 s of 100 Hz odometry, a frame a second


def _retained_bytes(log: RobotLog, *, keep_maps: bool) -> tuple[int, ReplayResult]:
    """Bytes the replay's result still holds once it returns (tracemalloc), and the result."""
    # A short replay first: modules imported on first use (numpy.unique imports numpy.ma)
    # would otherwise count as held, whenever no earlier test in the process imported them.
    replay_log(long_odometry_log(2_000), FLOOR, OPTIONS, keep_maps=False)
    tracemalloc.start()
    try:
        # A full collection empties the interpreter's free lists (tuples, floats), which
        # keep what the replay dropped and are not the result's.
        gc.collect()
        before = tracemalloc.get_traced_memory()[0]
        result = replay_log(log, FLOOR, OPTIONS, keep_maps=keep_maps)
        gc.collect()
        after = tracemalloc.get_traced_memory()[0]
    finally:
        tracemalloc.stop()
    return after - before, result


def test_a_long_log_replays_keeping_a_few_numbers_per_step_unless_maps_are_asked(
    long_log: RobotLog,
) -> None:
    lean_bytes, lean = _retained_bytes(long_log, keep_maps=False)
    full_bytes, full = _retained_bytes(long_log, keep_maps=True)
    steps = len(lean.trace)
    assert steps > 500
    assert lean.maps is None
    assert full.maps is not None
    assert len(full.maps) == steps
    # The trace's columns (~100 bytes a step); a map per step costs ten times that and more.
    assert lean_bytes / steps < 300
    assert full_bytes / steps > 1_000
    assert lean.metrics().to_dict() | {"median_update_us": 0} == full.metrics().to_dict() | {
        "median_update_us": 0
    }
    with pytest.raises(InputError, match=r"ReplayResult\.steps: expected a replay that kept its maps"):
        _ = lean.steps


def test_the_trace_holds_what_the_steps_hold(long_log: RobotLog) -> None:
    result = replay_log(long_log, FLOOR, OPTIONS)
    rebuilt = ReplayTrace.of_steps(result.steps)
    for name in ReplayTrace.__slots__:
        assert np.array_equal(getattr(rebuilt, name), getattr(result.trace, name), equal_nan=True), name
    assert result.containment_rate == np.mean([s.inside for s in result.steps if s.inside is not None])


def _csv_as_before(result: ReplayResult) -> str:
    """The per-step CSV as the CLI wrote it from the steps before it was streamed."""
    lines = ["time,inside,area_m2,wedge_width_rad,accepted,rejected,update_us,state,relocalized"]
    for s in result.steps:
        inside = "" if s.inside is None else str(int(s.inside))
        lines.append(
            f"{s.time!r},{inside},{s.map.area!r},{s.map.wedge.width!r},{s.accepted},{s.rejected},"
            f"{s.update_us:.3f},{s.state.value},{int(s.relocalized)}"
        )
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("seed", [1, 2])
def test_the_streamed_csv_equals_the_one_written_from_the_steps(tmp_path: Path, seed: int) -> None:
    # Longer than one block of judged steps, with truth missing at the end.
    log = synthetic_log(np.random.default_rng(seed), duration=400.0, frame_every=1)
    target = tmp_path / "out" / "steps.csv"
    result = replay_log(log, FLOOR, OPTIONS, steps_csv=target)
    assert len(result.trace) > 2048
    assert target.read_text(encoding="utf-8") == _csv_as_before(result)
    assert [path.name for path in target.parent.iterdir()] == ["steps.csv"]  # no scratch left


def test_a_replay_that_fails_leaves_the_old_csv_and_no_scratch(tmp_path: Path) -> None:
    target = tmp_path / "steps.csv"
    target.write_text("old\n", encoding="utf-8")
    log = synthetic_log(np.random.default_rng(3), duration=10.0)
    onto_a_folder = tmp_path / "folder"
    onto_a_folder.mkdir()
    (onto_a_folder / "keep").write_text("", encoding="utf-8")
    with pytest.raises(FileFormatError, match=r"folder: expected a writable file, got"):
        replay_log(log, FLOOR, OPTIONS, steps_csv=onto_a_folder)
    with pytest.raises(InputError, match=r"keep_maps: expected True or False, got 1"):
        replay_log(log, FLOOR, OPTIONS, keep_maps=1, steps_csv=target)  # type: ignore[arg-type]
    assert target.read_text(encoding="utf-8") == "old\n"
    assert sorted(path.name for path in tmp_path.iterdir()) == ["folder", "steps.csv"]
    assert [path.name for path in onto_a_folder.iterdir()] == ["keep"]


@pytest.mark.parametrize("where", ["write", "close"])
def test_a_full_disk_leaves_no_csv_no_scratch_and_no_folder_made_for_it(
    where: str, tmp_path: Path, full_disk: Callable[[str, str], None]
) -> None:
    # Found on a 64 KiB tmpfs: the flush on close failed and the scratch file stayed behind.
    full_disk("steps.csv", where)
    target = tmp_path / "new" / "deeper" / "steps.csv"
    log = synthetic_log(np.random.default_rng(3), duration=10.0)
    if where == "write":  # the write's own error, as the system raised it
        with pytest.raises(OSError, match="No space left on device"):
            replay_log(log, FLOOR, OPTIONS, steps_csv=target)
    else:
        with pytest.raises(FileFormatError, match=r"steps.csv: expected a writable file, got No space left"):
            replay_log(log, FLOOR, OPTIONS, steps_csv=target)
    assert list(tmp_path.iterdir()) == []


def test_a_ctrl_c_while_the_csv_is_opened_leaves_no_scratch(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A SIGHUP sent the moment the scratch CSV appeared (tests/cli/test_interrupts.py) once
    # left it behind: a stop raised inside the CSV's __enter__ skipped its __exit__.
    opened = Path.open

    def stop_once_made(path: Path, mode: str = "r", *args: object, **kwargs: object) -> object:
        stream = opened(path, mode, *args, **kwargs)  # type: ignore[call-overload]
        if "steps.csv" in path.name and "x" in mode:
            stream.close()
            raise KeyboardInterrupt
        return stream

    monkeypatch.setattr(Path, "open", stop_once_made)
    log = synthetic_log(np.random.default_rng(3), duration=10.0)
    with pytest.raises(KeyboardInterrupt, match=r"^$") as stopped:
        replay_log(log, FLOOR, OPTIONS, steps_csv=tmp_path / "new" / "steps.csv")
    # While the interrupt is still held (the command line says what was written, then exits
    # without waiting for the collector), not only once its frames are collected.
    assert stopped.value.__traceback__ is not None
    assert list(tmp_path.iterdir()) == []


def test_the_batched_truth_check_judges_a_sliced_map_by_its_slices() -> None:
    from aura_ums.logs._replay import _contains
    from aura_ums.uncertainty import Pose, SpatialUncertaintyMap

    sliced = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.5, 0.3).with_slices(math.radians(4.0))
    grown = sliced.grow(TurnAndRun(0.0, 3.0), TerrainTable.default()["tile"])
    # In the hull of the slices and the summary wedge, but not in the slice of its heading:
    # the far end of the run at the wedge's edge, where only the straight-ahead slice reaches.
    x, y, heading = 3.0, 0.0, grown.wedge.center + 0.95 * grown.wedge.ccw
    assert grown.polygon.contains(np.array([[x, y]]))[0]
    assert grown.wedge.contains(heading)
    assert not grown.contains(x, y, heading)
    poses = np.array([[x, y, heading]] * 2)
    assert _contains([grown, grown.without_slices()], poses).tolist() == [0, 1]


@given(
    st.lists(st.integers(1, 40), min_size=1, max_size=12),
    st.floats(-8.0, 3.0),
    st.floats(-1e4, 1e4),
    st.floats(-18.0, 0.0),
    st.integers(0, 2**32 - 1),
)
def test_the_judges_batched_areas_are_polygon_area_bit_for_bit(
    counts: list[int], log_scale: float, offset: float, log_squash: float, seed: int
) -> None:
    """Polygons of every vertex count (BLAS's unrolled dot from 16 on), far from the origin, thin."""
    from aura_ums.geometry import polygon_area
    from aura_ums.logs._replay import _areas, _Rings

    rng = np.random.default_rng(seed)
    polygons = []
    for count in counts:
        angles = np.sort(rng.uniform(0.0, 2.0 * math.pi, count))
        ring = np.column_stack((np.cos(angles), np.sin(angles) * 10.0**log_squash)) * 10.0**log_scale
        polygons.append(ring + np.array([offset, -offset]))
    expected = np.array([polygon_area(vertices) for vertices in polygons])
    assert _areas(polygons).view(np.int64).tolist() == expected.view(np.int64).tolist()
    # Each group gathered from the polygons' rows, as a flush shares them.
    assert _areas(polygons, _Rings(polygons)).view(np.int64).tolist() == expected.view(np.int64).tolist()


@given(
    st.integers(3, 16),
    st.floats(-8.0, 3.0),
    st.floats(-1e4, 1e4),
    st.floats(-1e4, 1e4),
    st.floats(-18.0, 0.0),
    st.integers(0, 2**32 - 1),
)
def test_the_envelope_gate_calls_an_area_positive_only_when_polygon_area_does(
    count: int, log_scale: float, x: float, y: float, log_squash: float, seed: int
) -> None:
    """The judge's batched area sign never admits a polygon polygon_area calls flat or worse."""
    from aura_ums.geometry import polygon_area
    from aura_ums.logs._replay import _Rings, _surely_positive

    rng = np.random.default_rng(seed)
    angles = np.sort(rng.uniform(0.0, 2.0 * math.pi, count))
    vertices = np.column_stack((np.cos(angles), np.sin(angles) * 10.0**log_squash)) * 10.0**log_scale
    origin = np.array([x, y])
    vertices += origin
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]) + origin
    line = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]) + origin
    gate = _surely_positive([vertices, square, line])
    assert (
        _surely_positive([vertices, square, line], _Rings([vertices, square, line])).tolist() == gate.tolist()
    )
    if gate[0] == 1.0:
        assert polygon_area(vertices) > 0.0
    assert gate[1:].tolist() == [1.0, 0.0]


def test_the_batched_truth_check_takes_a_repeated_vertex_as_no_edge() -> None:
    # 0 / 0 on the repeated vertex's edge: a RuntimeWarning and the truth judged outside
    from aura_ums.geometry import ConvexPolygon, HeadingWedge
    from aura_ums.logs._replay import _contains, _Rings
    from aura_ums.uncertainty import SpatialUncertaintyMap

    square = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]])
    polygon = ConvexPolygon._trusted(square)
    repeated = SpatialUncertaintyMap._trusted(polygon, np.array([1.0, 1.0]), HeadingWedge(0.0, 0.5, 0.5))
    poses = np.array([[1.0, 1.0, 0.0], [2.5, 1.0, 0.0], [1.0, 1.0, 1.0]])
    assert _contains([repeated] * 3, poses).tolist() == [1, 0, 0]
    # The shared rows of a flush give the same (all batched, and some not: a segment).
    segment = SpatialUncertaintyMap._trusted(
        ConvexPolygon._trusted(square[:2]), np.array([1.0, 0.0]), HeadingWedge(0.0, 0.5, 0.5)
    )
    for maps in ([repeated] * 3, [repeated, segment, repeated]):
        vertices = [m.polygon.vertices for m in maps]
        assert _contains(maps, poses, rings=_Rings(vertices)).tolist() == _contains(maps, poses).tolist()


def test_observations_at_or_before_the_start_are_counted_not_lost_silently(tmp_path: Path) -> None:
    # Dropped without a word: 806 of 807 accepted, none rejected, none excluded (helper-63).
    log = synthetic_log(np.random.default_rng(3), duration=10.0)
    first = log.observations[0]
    early = [dataclasses.replace(first, time=when) for when in (-2.0, -1.0, 0.0)]
    log = dataclasses.replace(log, observations=(*early, *log.observations))
    whole = replay_log(log, FLOOR, OPTIONS, keep_maps=False)
    streamed = replay_log(open_log(write_log(log, tmp_path / "log")), FLOOR, OPTIONS, keep_maps=False)
    assert whole.start_time == 0.0
    assert whole.early_observations == streamed.early_observations == 3
    assert whole.metrics()["observations_before_start"] == 3
    plain = replay_log(
        synthetic_log(np.random.default_rng(3), duration=10.0), FLOOR, OPTIONS, keep_maps=False
    )
    assert plain.early_observations == 0
    assert whole.trace.area_m2.tobytes() == plain.trace.area_m2.tobytes()
