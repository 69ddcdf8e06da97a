"""MCAP export: channels, schemas, counts and message contents read back with the ``mcap`` reader."""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from aura_ums.errors import FileFormatError, InputError, MissingDependencyError
from aura_ums.export import mcap_channels, write_replay_mcap, write_simulation_mcap
from aura_ums.geometry import ImageWindow
from aura_ums.manager import ManagerState
from aura_ums.sim import RunResult, Scenario, run_scenario
from aura_ums.uncertainty import Pose, SpatialUncertaintyMap, TurnAndRun
from tests.export.export_helpers import Message, decode, descriptors, points_xy, read_messages

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"

#: The documented channels of a simulation export (docs/interop.md).
SIMULATION_CHANNELS = {
    "/meadows": "foxglove.SceneUpdate",
    "/landmarks": "foxglove.SceneUpdate",
    "/map/polygon": "foxglove.SceneUpdate",
    "/map/grown": "foxglove.SceneUpdate",
    "/map/wedge": "foxglove.SceneUpdate",
    "/map/center": "foxglove.SceneUpdate",
    "/truth": "foxglove.SceneUpdate",
    "/camera/image": "foxglove.RawImage",
    "/camera/annotations": "foxglove.ImageAnnotations",
    "/metrics": "aura_ums.SimulationMetrics",
}
PER_FRAME = [t for t in SIMULATION_CHANNELS if t not in ("/meadows", "/landmarks")]
LINE_LOOP_3D = 1  # foxglove.LinePrimitive.Type.LINE_LOOP
LINE_LOOP_2D, LINE_LIST_2D = 2, 4  # foxglove.PointsAnnotation.Type


@dataclasses.dataclass(frozen=True)
class Sim:
    scenario: Scenario
    result: RunResult
    path: Path
    messages: dict[str, list[Message]]


@pytest.fixture(scope="module")
def sim(tmp_path_factory: pytest.TempPathFactory) -> Sim:
    scenario = Scenario.from_toml(SCENARIOS / "paper_sidewalk.toml")
    result = run_scenario(scenario, np.random.default_rng(3), keep_images=True)
    path = write_simulation_mcap(tmp_path_factory.mktemp("export") / "sub" / "run.mcap", scenario, result)
    return Sim(scenario, result, path, read_messages(path))


def heading_of(pose: dict[str, Any]) -> float:
    q = pose.get("orientation", {})
    z, w = q.get("z", 0.0), q.get("w", 0.0)
    return math.atan2(2.0 * w * z, w * w - z * z)


def only_entity(message: Message) -> dict[str, Any]:
    entities = message.data["entities"]
    assert len(entities) == 1
    entity: dict[str, Any] = entities[0]
    return entity


# --- simulation ---------------------------------------------------------------------------


def test_every_channel_has_its_schema_and_encoding(sim: Sim) -> None:
    assert mcap_channels(sim.path) == SIMULATION_CHANNELS
    assert set(sim.messages) == set(SIMULATION_CHANNELS)
    for topic, messages in sim.messages.items():
        for message in messages:
            assert message.schema_name == SIMULATION_CHANNELS[topic]
            if topic == "/metrics":
                assert (message.schema_encoding, message.message_encoding) == ("jsonschema", "json")
            else:
                assert (message.schema_encoding, message.message_encoding) == ("protobuf", "protobuf")


def test_message_counts_and_log_times_follow_the_frames(sim: Sim) -> None:
    records = sim.result.records
    assert len(records) >= 2
    times = [round(r.time * 1e9) for r in records]
    for topic in PER_FRAME:
        assert [m.log_time for m in sim.messages[topic]] == times, topic
    for topic in ("/meadows", "/landmarks"):
        assert [m.log_time for m in sim.messages[topic]] == [times[0]]
    # message timestamps equal log times (the Image panel pairs images and annotations by them)
    for image, notes in zip(sim.messages["/camera/image"], sim.messages["/camera/annotations"], strict=True):
        stamp = image.data.get("timestamp", {})
        assert stamp.get("seconds", 0) * 10**9 + stamp.get("nanos", 0) == image.log_time
        for rectangle in notes.data.get("points", []):
            assert rectangle.get("timestamp", {}) == stamp


def test_polygons_are_the_maps_vertices(sim: Sim) -> None:
    for record, after, before in zip(
        sim.result.records, sim.messages["/map/polygon"], sim.messages["/map/grown"], strict=True
    ):
        for message, the_map, ident in (
            (after, record.map_after, "polygon"),
            (before, record.map_before, "grown"),
        ):
            entity = only_entity(message)
            assert (entity["id"], entity["frame_id"]) == (ident, "world")
            (line,) = entity["lines"]
            assert line["type"] == LINE_LOOP_3D
            np.testing.assert_allclose(points_xy(line), the_map.polygon.vertices, atol=1e-12)


def test_wedge_fan_spans_the_wedge_from_the_centre(sim: Sim) -> None:
    for record, message in zip(sim.result.records, sim.messages["/map/wedge"], strict=True):
        wedge, center = record.map_after.wedge, record.map_after.center
        (line,) = only_entity(message)["lines"]
        assert line["type"] == LINE_LOOP_3D
        fan = np.array(points_xy(line))
        np.testing.assert_allclose(fan[0], center, atol=1e-12)
        rays = fan[1:] - center
        angles = np.arctan2(rays[:, 1], rays[:, 0])
        assert math.isclose(
            math.remainder(angles[0] - (wedge.center - wedge.cw), math.tau), 0.0, abs_tol=1e-9
        )
        assert math.isclose(
            math.remainder(angles[-1] - (wedge.center + wedge.ccw), math.tau), 0.0, abs_tol=1e-9
        )
        # the rays reach beyond the polygon
        far = np.max(np.hypot(*(record.map_after.polygon.vertices - center).T))
        assert np.all(np.hypot(*rays.T) > far)


def test_center_and_truth_arrows_sit_at_their_poses(sim: Sim) -> None:
    for record, center, truth in zip(
        sim.result.records, sim.messages["/map/center"], sim.messages["/truth"], strict=True
    ):
        for message, x, y, heading in (
            (center, *record.map_after.center, record.map_after.wedge.center),
            (truth, record.true_pose.x, record.true_pose.y, record.true_pose.heading),
        ):
            (arrow,) = only_entity(message)["arrows"]
            position = arrow["pose"]["position"]
            assert math.isclose(position.get("x", 0.0), x, abs_tol=1e-12)
            assert math.isclose(position.get("y", 0.0), y, abs_tol=1e-12)
            assert math.isclose(
                math.remainder(heading_of(arrow["pose"]) - heading, math.tau), 0.0, abs_tol=1e-9
            )


def test_meadows_and_landmarks_are_drawn_once(sim: Sim) -> None:
    world = sim.scenario.meadow_map
    (meadows,) = sim.messages["/meadows"]
    entities = {e["id"]: e for e in meadows.data["entities"]}
    assert set(entities) == {m.id for m in world.meadows}
    for meadow in world.meadows:
        entity = entities[meadow.id]
        (fill,) = entity["triangles"]
        triangles = np.array(points_xy(fill)).reshape(-1, 3, 2)
        assert len(triangles) == meadow.polygon.vertex_count - 2
        # the fan of triangles covers the meadow exactly
        ab, ac = triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0]
        area = 0.5 * np.abs(ab[:, 0] * ac[:, 1] - ab[:, 1] * ac[:, 0]).sum()
        assert math.isclose(area, meadow.polygon.area, rel_tol=1e-9)
        assert {"key": "terrain", "value": meadow.terrain} in entity["metadata"]
    (landmarks,) = sim.messages["/landmarks"]
    drawn = {e["id"]: e for e in landmarks.data["entities"]}
    assert set(drawn) == {r.id for r in world.landmarks}
    for record in world.landmarks:
        kind = {"I": "cylinders", "II": "spheres", "III": "lines"}[record.landmark_class.value]
        assert kind in drawn[record.id], record.id
        used = "yes" if record.id in sim.scenario.landmark_ids else "no"
        assert {"key": "used", "value": used} in drawn[record.id]["metadata"]


def test_annotations_hold_one_rectangle_per_window(sim: Sim) -> None:
    width, height = sim.scenario.camera.intrinsics.width, sim.scenario.camera.intrinsics.height
    assert sum(len(r.windows) for r in sim.result.records) > 0
    for record, message in zip(sim.result.records, sim.messages["/camera/annotations"], strict=True):
        rectangles = [p for p in message.data.get("points", []) if p["type"] == LINE_LOOP_2D]
        assert len(rectangles) == len(record.windows)
        labels = [t["text"] for t in message.data.get("texts", [])]
        assert labels == [landmark_id for landmark_id, _ in record.windows]
        for rectangle, (landmark_id, window) in zip(rectangles, record.windows, strict=True):
            corners = np.array(points_xy(rectangle))
            # Foxglove's origin is the top-left pixel's corner; ours its centre
            u = np.clip([window.u_min, window.u_max], -0.5, width - 0.5) + 0.5
            v = np.clip([window.v_min, window.v_max], -0.5, height - 0.5) + 0.5
            np.testing.assert_allclose(corners.min(axis=0), [u[0], v[0]], atol=1e-9)
            np.testing.assert_allclose(corners.max(axis=0), [u[1], v[1]], atol=1e-9)
            found = "yes" if landmark_id in record.found else "no"
            assert {"key": "found", "value": found} in rectangle["metadata"]
            assert {"key": "landmark_id", "value": landmark_id} in rectangle["metadata"]


def test_images_are_the_frames(sim: Sim) -> None:
    for image, message in zip(sim.result.images, sim.messages["/camera/image"], strict=True):
        data = message.data
        assert (data["height"], data["width"], data["step"]) == (
            image.shape[0],
            image.shape[1],
            image.shape[1],
        )
        assert (data["encoding"], data["frame_id"]) == ("mono8", "camera")
        assert data["data"] == image.tobytes()


def test_metrics_are_the_records(sim: Sim) -> None:
    for record, message in zip(sim.result.records, sim.messages["/metrics"], strict=True):
        m = message.data
        assert m["frame"] == record.index
        assert m["area_m2"] == record.area
        assert m["area_before_m2"] == record.area_before
        assert m["wedge_width_rad"] == record.wedge_width
        assert m["inside"] == int(record.inside)
        assert (m["accepted"], m["rejected"]) == (record.accepted, len(record.rejected))
        assert (m["windows"], m["found"]) == (len(record.windows), len(record.found))
        assert m["lost"] == int(record.state is ManagerState.LOST)


def test_without_images(sim: Sim, tmp_path: Path) -> None:
    path = write_simulation_mcap(tmp_path / "blind.mcap", sim.scenario, sim.result, camera_topic_images=False)
    expected = {k: v for k, v in SIMULATION_CHANNELS.items() if k != "/camera/image"}
    assert mcap_channels(path) == expected
    blind = dataclasses.replace(sim.result, images=())
    with pytest.raises(InputError, match=r"result\.images: expected the frames' images .*keep_images=True"):
        write_simulation_mcap(tmp_path / "x.mcap", sim.scenario, blind)
    # after a resume, the images are those of the last frames
    tail = dataclasses.replace(sim.result, images=sim.result.images[-1:])
    messages = read_messages(write_simulation_mcap(tmp_path / "tail.mcap", sim.scenario, tail))
    assert [m.log_time for m in messages["/camera/image"]] == [messages["/metrics"][-1].log_time]


def test_detections_are_drawn_as_segments(sim: Sim) -> None:
    from foxglove import messages as fm

    from aura_ums.export._messages import frame_annotations

    record = SimpleNamespace(
        windows=(("pole", ImageWindow(10.0, 20.0, 50.0, 40.0)),),
        found=(),
        detections=(("pole", (12.0, 21.0, 13.0, 39.0)), ("pole", (30.0, 22.0, 31.0, 38.5))),
    )
    encoded = frame_annotations(fm.Timestamp(1, 0), record, 640, 480).encode()  # type: ignore[arg-type]
    data = decode(descriptors(fm.ImageAnnotations.get_schema().data), "foxglove.ImageAnnotations", encoded)
    loop, segments = data["points"]
    assert loop["type"] == LINE_LOOP_2D
    assert {"key": "found", "value": "no"} in loop["metadata"]
    assert segments["type"] == LINE_LIST_2D
    assert points_xy(segments) == [(12.5, 21.5), (13.5, 39.5), (30.5, 22.5), (31.5, 39.0)]


def test_bad_arguments_and_paths(sim: Sim, tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"scenario: expected a Scenario, got str"):
        write_simulation_mcap(tmp_path / "a.mcap", "paper", sim.result)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"result: expected a RunResult"):
        write_simulation_mcap(tmp_path / "a.mcap", sim.scenario, None)  # type: ignore[arg-type]
    blocker = tmp_path / "file"
    blocker.write_text("")
    with pytest.raises(FileFormatError, match=r"file.*expected a writable file"):
        write_simulation_mcap(blocker / "run.mcap", sim.scenario, sim.result)
    with pytest.raises(FileFormatError, match=r"none\.mcap: expected an MCAP file, got no such file"):
        mcap_channels(tmp_path / "none.mcap")
    truncated = tmp_path / "truncated.mcap"
    truncated.write_bytes(sim.path.read_bytes()[:1000])
    with pytest.raises(FileFormatError, match=r"truncated\.mcap: expected an MCAP file"):
        mcap_channels(truncated)


def test_a_file_without_summary_is_scanned(sim: Sim, tmp_path: Path) -> None:
    from mcap.writer import Writer

    path = tmp_path / "plain.mcap"
    with path.open("wb") as stream:
        writer = Writer(stream, use_summary_offsets=False)
        writer.start()
        schema = writer.register_schema("demo.Thing", "jsonschema", b"{}")
        writer.register_channel("/a", "json", schema)
        writer.register_channel("/b", "json", 0)
        writer.finish()  # type: ignore[no-untyped-call]
    assert mcap_channels(path) == {"/a": "demo.Thing", "/b": ""}


# --- replay -------------------------------------------------------------------------------


@dataclasses.dataclass(frozen=True, slots=True)
class FakeLandmark:
    id: str
    x: float
    y: float
    position_uncertainty: float
    z_bottom: float
    z_top: float
    symbol: str


@dataclasses.dataclass(frozen=True, slots=True)
class FakeMeta:
    name: str


@dataclasses.dataclass(frozen=True, slots=True)
class FakeLog:
    meta: FakeMeta
    landmarks: tuple[FakeLandmark, ...]


@dataclasses.dataclass(frozen=True, slots=True)
class FakeStep:
    time: float
    map: SpatialUncertaintyMap
    truth: Pose | None
    inside: bool | None
    accepted: int
    rejected: int
    update_us: float
    state: ManagerState


@dataclasses.dataclass(frozen=True, slots=True)
class FakeReplay:
    log: FakeLog
    steps: tuple[FakeStep, ...]


def fake_replay(*, truth: bool) -> FakeReplay:
    rng = np.random.default_rng(5)
    the_map = SpatialUncertaintyMap.from_pose(Pose(1.0, 2.0, 0.3), 0.2, 0.05)
    from aura_ums.uncertainty import TerrainTable

    concrete = TerrainTable.default()["concrete"]
    steps = []
    for i in range(5):
        time = 100.0 + 0.25 * i
        pose = Pose(1.0 + 0.5 * i, 2.0, 0.3) if truth and i != 2 else None
        inside = None if pose is None else bool(rng.integers(2))
        state = ManagerState.LOST if i == 4 else ManagerState.NOMINAL
        steps.append(FakeStep(time, the_map, pose, inside, i % 2, i // 3, 10.0 + i, state))
        the_map = the_map.grow(TurnAndRun(0.1, 0.5), concrete)
    landmarks = (
        FakeLandmark("pole", 5.0, 1.0, 0.1, 0.0, 4.0, "lamppost"),
        FakeLandmark("mark", 2.0, -1.0, 0.2, math.nan, math.nan, "marker"),
    )
    return FakeReplay(FakeLog(FakeMeta("fake"), landmarks), tuple(steps))


def test_replay_channels_counts_and_contents(tmp_path: Path) -> None:
    replay = fake_replay(truth=True)
    path = write_replay_mcap(tmp_path / "replay.mcap", replay)
    assert mcap_channels(path) == {
        "/landmarks": "foxglove.SceneUpdate",
        "/map/polygon": "foxglove.SceneUpdate",
        "/map/wedge": "foxglove.SceneUpdate",
        "/map/center": "foxglove.SceneUpdate",
        "/truth": "foxglove.SceneUpdate",
        "/metrics": "aura_ums.ReplayMetrics",
    }
    messages = read_messages(path)
    times = [round(s.time * 1e9) for s in replay.steps]
    for topic in ("/map/polygon", "/map/wedge", "/map/center", "/truth", "/metrics"):
        assert [m.log_time for m in messages[topic]] == times, topic
    for step, message in zip(replay.steps, messages["/map/polygon"], strict=True):
        (line,) = only_entity(message)["lines"]
        np.testing.assert_allclose(points_xy(line), step.map.polygon.vertices, atol=1e-12)
    # a step without ground truth deletes the arrow instead of leaving a stale one
    for step, message in zip(replay.steps, messages["/truth"], strict=True):
        if step.truth is None:
            assert message.data["deletions"][0]["id"] == "truth"
            assert "entities" not in message.data
        else:
            (arrow,) = only_entity(message)["arrows"]
            assert math.isclose(arrow["pose"]["position"]["x"], step.truth.x)
    for step, message in zip(replay.steps, messages["/metrics"], strict=True):
        m = message.data
        assert m["inside"] == (None if step.inside is None else int(step.inside))
        assert (m["accepted"], m["rejected"], m["update_us"]) == (
            step.accepted,
            step.rejected,
            step.update_us,
        )
        assert m["area_m2"] == step.map.area
        assert m["lost"] == int(step.state is ManagerState.LOST)
    (landmarks,) = messages["/landmarks"]
    drawn = {e["id"]: e for e in landmarks.data["entities"]}
    (pole,) = drawn["pole"]["cylinders"]
    assert math.isclose(pole["size"]["z"], 4.0)
    assert math.isclose(pole["pose"]["position"]["z"], 2.0)
    assert "spheres" in drawn["mark"]  # no heights: a sphere on the ground


def test_replay_without_truth_has_no_truth_channel(tmp_path: Path) -> None:
    path = write_replay_mcap(tmp_path / "replay.mcap", fake_replay(truth=False))
    assert "/truth" not in mcap_channels(path)
    assert all(m.data["inside"] is None for m in read_messages(path)["/metrics"])


def test_replay_bad_input(tmp_path: Path) -> None:
    replay = fake_replay(truth=False)
    early = dataclasses.replace(replay.steps[0], time=-1.0)
    with pytest.raises(InputError, match=r"replay\.steps\[0\]\.time: expected a time >= 0 s"):
        write_replay_mcap(tmp_path / "r.mcap", dataclasses.replace(replay, steps=(early,)))
    with pytest.raises(InputError, match=r"replay: expected a ReplayResult \(with \.log\), got int"):
        write_replay_mcap(tmp_path / "r.mcap", 3)  # type: ignore[arg-type]


# --- missing optional dependency ----------------------------------------------------------


def test_missing_foxglove_is_a_clear_error(sim: Sim, monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    for name in [m for m in sys.modules if m == "foxglove" or m.startswith("foxglove.")]:
        monkeypatch.setitem(sys.modules, name, None)
    with pytest.raises(MissingDependencyError, match=r"'foxglove-sdk'.*install aura-ums\[foxglove\]"):
        write_simulation_mcap(tmp_path / "a.mcap", sim.scenario, sim.result)
    with pytest.raises(MissingDependencyError, match=r"install aura-ums\[foxglove\]"):
        write_replay_mcap(tmp_path / "a.mcap", fake_replay(truth=False))
    assert not (tmp_path / "a.mcap").exists()


def test_missing_mcap_is_a_clear_error(sim: Sim, monkeypatch: pytest.MonkeyPatch) -> None:
    for name in [m for m in sys.modules if m == "mcap" or m.startswith("mcap.")]:
        monkeypatch.setitem(sys.modules, name, None)
    with pytest.raises(MissingDependencyError, match=r"reading MCAP needs the optional package 'mcap'"):
        mcap_channels(sim.path)


def test_a_real_replay(tmp_path: Path) -> None:
    from aura_ums.logs import ReplayOptions, replay_log, synthetic_log
    from aura_ums.uncertainty import LandmarkClass, TerrainTable

    log = synthetic_log(np.random.default_rng(3), duration=10.0)
    table = TerrainTable({"floor": TerrainTable.default()["tile"]})
    replay = replay_log(log, table, ReplayOptions(landmark_class=LandmarkClass.POINT))
    path = write_replay_mcap(tmp_path / "replay.mcap", replay)
    channels = mcap_channels(path)
    assert channels["/meadows"] == "foxglove.SceneUpdate"  # the replay's arena
    assert channels["/truth"] == "foxglove.SceneUpdate"
    messages = read_messages(path)
    assert len(messages["/map/polygon"]) == len(replay.steps) > 0
    (landmarks,) = messages["/landmarks"]
    drawn = {e["id"]: e for e in landmarks.data["entities"]}
    assert set(drawn) == {lm.id for lm in log.landmarks}
    assert all("spheres" in entity for entity in drawn.values())  # Class II in this replay
    for step, message, polygon in zip(
        replay.steps, messages["/metrics"], messages["/map/polygon"], strict=True
    ):
        assert message.data["inside"] == (None if step.inside is None else int(step.inside))
        assert message.data["relocalized"] == int(step.relocalized)
        (line,) = only_entity(polygon)["lines"]
        np.testing.assert_allclose(points_xy(line), step.map.polygon.vertices, atol=1e-12)


def test_images_are_checked_before_writing(sim: Sim, tmp_path: Path) -> None:
    color = np.zeros((4, 5, 3), dtype=np.uint8)
    bad = dataclasses.replace(sim.result, images=(*sim.result.images[:-1], color))
    last = len(sim.result.images) - 1
    with pytest.raises(
        InputError, match=rf"result\.images\[{last}\]: expected a 2-D uint8 grayscale image, got \(4, 5, 3\)"
    ):
        write_simulation_mcap(tmp_path / "bad.mcap", sim.scenario, bad)
    assert not (tmp_path / "bad.mcap").exists()
    too_many = dataclasses.replace(sim.result, images=(*sim.result.images, sim.result.images[0]))
    with pytest.raises(InputError, match=r"result\.images: expected at most \d+ images, got \d+"):
        write_simulation_mcap(tmp_path / "bad.mcap", sim.scenario, too_many)


def test_a_sliced_replay_draws_its_slices_stacked_by_heading(tmp_path: Path) -> None:
    from aura_ums.logs import ReplayOptions, replay_log, synthetic_log
    from aura_ums.manager import ManagerSettings
    from aura_ums.uncertainty import LandmarkClass, TerrainTable

    log = synthetic_log(np.random.default_rng(3), duration=10.0)
    table = TerrainTable({"floor": TerrainTable.default()["tile"]})
    options = ReplayOptions(settings=ManagerSettings(slice_width=0.05), landmark_class=LandmarkClass.POINT)
    replay = replay_log(log, table, options)
    messages = read_messages(write_replay_mcap(tmp_path / "sliced.mcap", replay))
    assert len(messages["/map/slices"]) == len(replay.steps)
    assert max(len(step.map.slices) for step in replay.steps) > 1
    for step, message in zip(replay.steps, messages["/map/slices"], strict=True):
        lines = only_entity(message)["lines"]
        pieces = step.map.slices
        assert len(lines) == len(pieces) >= 1
        for index, (line, piece) in enumerate(zip(lines, pieces, strict=True)):
            np.testing.assert_allclose(points_xy(line), piece.polygon.vertices, atol=1e-12)
            assert {round(p["z"], 9) for p in line["points"]} == {round(0.05 * (index + 1), 9)}
    # a product map has no slices: no channel
    plain = replay_log(log, table, ReplayOptions(landmark_class=LandmarkClass.POINT))
    assert "/map/slices" not in mcap_channels(write_replay_mcap(tmp_path / "plain.mcap", plain))
