"""The live view: a real client speaks the Foxglove WebSocket protocol to the server while a run computes."""

from __future__ import annotations

import dataclasses
import re
import socket
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from aura_ums.camera import Camera, CameraIntrinsics, CameraMount
from aura_ums.errors import InputError, MissingDependencyError
from aura_ums.export import (
    LiveOptions,
    LiveReplay,
    mcap_channels,
    serve_replay,
    serve_simulation,
    write_replay_mcap,
    write_simulation_mcap,
)
from aura_ums.logs import ReplayOptions, ReplayStep, WindowRow, replay_windows, synthetic_log
from aura_ums.sim import FrameRecord, Scenario, run_scenario
from aura_ums.uncertainty import LandmarkClass, TerrainTable
from tests.export.export_helpers import points_xy, read_messages
from tests.export.live_client import LiveClient, Received

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
FLOOR = TerrainTable({"floor": TerrainTable.default()["tile"]})
CAMERA = Camera(CameraIntrinsics(554.26, 554.26, 319.5, 239.5, 640, 480), CameraMount(0.3))
OPTIONS = ReplayOptions(landmark_class=LandmarkClass.POINT)
FAST = LiveOptions(port=0, rate=0.0)
#: The channels of a replay of a log with ground truth through a camera (docs/interop.md).
REPLAY_CHANNELS = {
    "/landmarks": "foxglove.SceneUpdate",
    "/meadows": "foxglove.SceneUpdate",
    "/map/polygon": "foxglove.SceneUpdate",
    "/map/wedge": "foxglove.SceneUpdate",
    "/map/center": "foxglove.SceneUpdate",
    "/truth": "foxglove.SceneUpdate",
    "/metrics": "aura_ums.ReplayMetrics",
    "/camera/image": "foxglove.RawImage",
    "/camera/annotations": "foxglove.ImageAnnotations",
}
LINE_LOOP_2D = 2
WAIT = 30.0  # seconds a test waits for the other side at most


def _in_thread(work: Callable[[], Any]) -> tuple[threading.Thread, dict[str, Any]]:
    """Run ``work`` in a thread; its result or error lands in the returned dict."""
    out: dict[str, Any] = {}

    def run() -> None:
        try:
            out["result"] = work()
        except BaseException as exc:  # handed to the test thread, which raises it
            out["error"] = exc

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    return thread, out


def _joined(thread: threading.Thread, out: dict[str, Any]) -> Any:
    thread.join(WAIT)
    assert not thread.is_alive(), "the computation did not finish"
    if "error" in out:
        raise out["error"]
    return out["result"]


@pytest.fixture(scope="module")
def log() -> Any:
    return synthetic_log(np.random.default_rng(3), duration=15.0)


@dataclasses.dataclass
class Watched:
    """What a client saw of a replay it watched live, and the replay itself."""

    channels: dict[str, Any]
    messages: list[Received]
    steps: tuple[ReplayStep, ...]
    windows: tuple[WindowRow, ...]
    published_when_first_seen: int


@pytest.fixture(scope="module")
def watched(log: Any) -> Watched:
    """Watch a replay through a camera: the replay waits, mid-way, for the client to see its first map."""
    seen_first = threading.Event()
    with serve_replay(log, OPTIONS, camera=CAMERA, options=FAST) as view, LiveClient(view.url) as client:
        channels = client.advertised(set(REPLAY_CHANNELS))
        client.subscribe(set(REPLAY_CHANNELS))
        assert view.wait_for_client(timeout=WAIT)

        def hook(step: ReplayStep, rows: tuple[WindowRow, ...]) -> None:
            view.step(step, rows)
            if view.published == 1:  # hold the replay until the client has the first map
                assert seen_first.wait(WAIT)

        thread, out = _in_thread(lambda: replay_windows(log, FLOOR, CAMERA, OPTIONS, after_step=hook))
        messages: list[Received] = []
        published_when_first_seen = -1
        while thread.is_alive() or client.pump(0.5):
            client.pump(0.2)
            messages += client.take()
            if not seen_first.is_set() and any(m.topic == "/map/polygon" for m in messages):
                published_when_first_seen = view.published
                seen_first.set()
        result, windows = _joined(thread, out)
        # the last messages, still on their way when the replay returned: up to the last step's metrics
        _read_until(client, messages, "/metrics", len(result.trace))
    return Watched(channels, messages, result.steps, windows.rows, published_when_first_seen)


def _read_until(client: LiveClient, messages: list[Received], topic: str, count: int) -> None:
    """Read until ``count`` messages of ``topic`` have come (each step's or frame's metrics come last)."""
    deadline = time.monotonic() + WAIT
    while sum(1 for m in messages if m.topic == topic) < count and time.monotonic() < deadline:
        client.pump(0.2)
        messages += client.take()


def _on(watched: Watched, topic: str) -> list[Received]:
    return [m for m in watched.messages if m.topic == topic]


def test_the_map_arrives_while_the_replay_computes(watched: Watched) -> None:
    assert watched.published_when_first_seen == 1 < len(watched.steps)
    polygons = _on(watched, "/map/polygon")
    assert len(polygons) == len(watched.steps)
    for step, message in zip(watched.steps, polygons, strict=True):
        assert message.log_time == round(step.time * 1e9)
        (entity,) = message.data["entities"]
        (line,) = entity["lines"]
        np.testing.assert_allclose(points_xy(line), step.map.polygon.vertices, atol=1e-12)


def test_every_channel_is_advertised_with_its_schema(watched: Watched) -> None:
    assert {topic: c.schema_name for topic, c in watched.channels.items()} == REPLAY_CHANNELS
    for topic, channel in watched.channels.items():
        expected = ("json", "jsonschema") if topic == "/metrics" else ("protobuf", "protobuf")
        assert (channel.encoding, channel.schema_encoding) == expected
    assert {m.topic for m in watched.messages} == set(REPLAY_CHANNELS)
    for message in watched.messages:
        assert message.schema_name == REPLAY_CHANNELS[message.topic]


def test_windows_arrive_as_annotations_of_their_step(watched: Watched) -> None:
    notes = _on(watched, "/camera/annotations")
    assert len(notes) == len(watched.steps)
    drawn = 0
    for step, message in zip(watched.steps, notes, strict=True):
        assert message.log_time == round(step.time * 1e9)
        rows = [r for r in watched.windows if r.time == step.time and r.window is not None]
        # Ours are drawn last, on top of the others (the focus window may be the same rectangle).
        rows.sort(key=lambda r: r.method == "aura-ums")
        loops = [p for p in message.data.get("points", []) if p["type"] == LINE_LOOP_2D]
        assert len(loops) == len(rows)
        for loop, row in zip(loops, rows, strict=True):
            metadata = {kv["key"]: kv["value"] for kv in loop["metadata"]}
            assert (metadata["landmark_id"], metadata["method"]) == (row.landmark_id, row.method)
            assert row.window is not None
            (u0, v0), _, (u1, v1), _ = points_xy(loop)
            assert u0 <= row.window.u_min + 0.5 + 1e-9
            assert u1 >= min(row.window.u_max + 0.5, 640.0) - 1e-9
            assert v0 <= row.window.v_min + 0.5 + 1e-9
            assert v1 >= min(row.window.v_max + 0.5, 480.0) - 1e-9
        drawn += len(loops)
    assert drawn > 10
    images = _on(watched, "/camera/image")
    assert len(images) == len(watched.steps)
    assert (images[0].data["width"], images[0].data["height"], images[0].data["encoding"]) == (
        640,
        480,
        "mono8",
    )


def test_metrics_and_the_static_scene_arrive(watched: Watched) -> None:
    metrics = _on(watched, "/metrics")
    assert [m.data["step"] for m in metrics] == list(range(len(watched.steps)))
    for step, message in zip(watched.steps, metrics, strict=True):
        assert message.data["inside"] == (None if step.inside is None else int(step.inside))
        assert message.data["area_m2"] == step.map.area
    assert len(_on(watched, "/landmarks")) >= 1
    assert len(_on(watched, "/meadows")) >= 1
    truths = _on(watched, "/truth")
    assert len(truths) == len(watched.steps)


# --- the same topics and schemas as the MCAP export ---------------------------------------


def _live_channels(serve: Callable[[], LiveReplay | Any], topics_wanted: int) -> dict[str, tuple[str, bytes]]:
    with serve() as view, LiveClient(view.url) as client:
        client.advertised(set(), timeout=0.5)
        while len(client.channels) < topics_wanted and client.pump(1.0):
            pass
        return {c.topic: (c.schema_name, c.schema) for c in client.channels.values()}


def _file_channels(path: Path) -> dict[str, tuple[str, bytes]]:
    from mcap.reader import make_reader

    with path.open("rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None
    return {
        c.topic: (summary.schemas[c.schema_id].name, summary.schemas[c.schema_id].data)
        for c in summary.channels.values()
    }


def test_a_replay_has_the_same_topics_and_schemas_live_and_in_a_file(log: Any, tmp_path: Path) -> None:
    result, windows = replay_windows(log, FLOOR, CAMERA, OPTIONS)
    path = write_replay_mcap(tmp_path / "replay.mcap", result, windows=windows)
    in_file = _file_channels(path)
    live = _live_channels(lambda: serve_replay(log, OPTIONS, camera=CAMERA, options=FAST), len(in_file))
    assert live == in_file
    assert set(mcap_channels(path)) == set(REPLAY_CHANNELS)


def test_a_simulation_has_the_same_topics_and_schemas_live_and_in_a_file(tmp_path: Path) -> None:
    scenario = Scenario.from_toml(SCENARIOS / "paper_sidewalk.toml")
    run = run_scenario(scenario, np.random.default_rng(1), keep_images=True)
    in_file = _file_channels(write_simulation_mcap(tmp_path / "run.mcap", scenario, run))
    live = _live_channels(lambda: serve_simulation(scenario, FAST), len(in_file))
    assert live == in_file


def test_a_replay_file_with_windows_draws_them(log: Any, tmp_path: Path) -> None:
    result, windows = replay_windows(log, FLOOR, CAMERA, OPTIONS)
    messages = read_messages(write_replay_mcap(tmp_path / "replay.mcap", result, windows=windows))
    loops = sum(
        sum(1 for p in m.data.get("points", []) if p["type"] == LINE_LOOP_2D)
        for m in messages["/camera/annotations"]
    )
    assert loops == sum(1 for r in windows.rows if r.window is not None) > 0
    with pytest.raises(InputError, match=r"windows: expected a WindowReport or None, got list"):
        write_replay_mcap(tmp_path / "x.mcap", result, windows=[])  # type: ignore[arg-type]


# --- simulations: runs one after another, a late subscriber ---------------------------------


def test_runs_follow_each_other_on_the_time_line_and_a_late_subscriber_gets_the_scene() -> None:
    scenario = Scenario.from_toml(SCENARIOS / "paper_sidewalk.toml")
    with serve_simulation(scenario, FAST) as view, LiveClient(view.url) as client:
        channels = client.advertised({"/metrics", "/map/polygon", "/landmarks", "/camera/image"})
        client.subscribe({"/metrics", "/map/polygon", "/camera/image"})
        assert view.wait_for_client(timeout=WAIT)
        seen: list[FrameRecord] = []

        def hook(record: FrameRecord, image: np.ndarray) -> None:
            view.frame(record, image)
            seen.append(record)

        runs = [run_scenario(scenario, rng, after_frame=hook) for rng in np.random.default_rng(0).spawn(2)]
        messages: list[Received] = []
        _read_until(client, messages, "/metrics", len(seen))
        client.subscribe({"/landmarks"})  # after both runs: the scene comes again with a next frame
        again = 0
        deadline = time.monotonic() + WAIT
        while not any(m.topic == "/landmarks" for m in messages) and time.monotonic() < deadline:
            view.frame(seen[-1])
            again += 1
            _read_until(client, messages, "/metrics", len(seen) + again)
        view.frame(seen[-1])  # once only: not with the frame after
        _read_until(client, messages, "/metrics", len(seen) + again + 1)
    assert "/landmarks" in channels
    metrics = [m for m in messages if m.topic == "/metrics"]
    frames = sum(len(r.records) for r in runs)
    assert [m.data["run"] for m in metrics[:frames]] == [1] * len(runs[0].records) + [2] * len(
        runs[1].records
    )
    times = [m.log_time for m in metrics[:frames]]  # then the last frame again
    assert times == sorted(times)
    assert len(set(times)) == len(times)
    assert sum(1 for m in messages if m.topic == "/landmarks") == 1
    images = [m for m in messages if m.topic == "/camera/image"]
    assert len(images) == frames  # the last frame again came without its image
    assert len(images[0].data["data"]) == images[0].data["width"] * images[0].data["height"]


# --- errors ------------------------------------------------------------------------------


def test_a_port_in_use_is_a_clear_error(log: Any) -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        with pytest.raises(
            InputError, match=rf"^port: expected a free port on 127\.0\.0\.1, got {port}, which is in use$"
        ):
            serve_replay(log, options=LiveOptions(port=port))


def test_bad_options_are_refused(log: Any) -> None:
    with pytest.raises(InputError, match=r"rate: expected a finite number >= 0"):
        LiveOptions(rate=-1.0)
    with pytest.raises(InputError, match=r"rate: expected a finite number >= 0"):
        LiveOptions(rate=float("nan"))
    for host in ("", "/tmp", "a b", "http://localhost", "localhost:8765", "-x", "[::1]"):
        with pytest.raises(
            InputError, match=rf"host: expected an address such as 127\.0\.0\.1 .*, got '{re.escape(host)}'"
        ):
            LiveOptions(host=host)
    for host in ("0.0.0.0", "::1", "localhost", "robot-7.lab.example.org"):
        assert LiveOptions(host=host).host == host
    with pytest.raises(InputError, match=r"port: expected an integer from 0 to 65535, got True"):
        LiveOptions(port=True)
    with pytest.raises(InputError, match=r"options: expected LiveOptions or None, got dict"):
        serve_replay(log, options={})  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"scenario: expected a Scenario, got str"):
        serve_simulation("paper")  # type: ignore[arg-type]
    with serve_replay(log, options=FAST) as view, pytest.raises(InputError, match=r"timeout: expected"):
        view.wait_for_client(timeout=-1.0)


def test_missing_foxglove_is_a_clear_error(log: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    for name in [m for m in sys.modules if m == "foxglove" or m.startswith("foxglove.")]:
        monkeypatch.setitem(sys.modules, name, None)
    with pytest.raises(
        MissingDependencyError,
        match=r"the live view needs the optional package 'foxglove-sdk'.*install aura-ums\[foxglove\]",
    ):
        serve_replay(log, options=FAST)


def test_pace_follows_the_log_times_at_the_rate(monkeypatch: pytest.MonkeyPatch) -> None:
    from aura_ums.export import _server

    clock = [100.0]
    slept: list[float] = []

    def sleep(seconds: float) -> None:
        slept.append(seconds)
        clock[0] += seconds

    # the server's module reads the clock through the time module: a fake clock for this test
    monkeypatch.setattr(time, "monotonic", lambda: clock[0])
    monkeypatch.setattr(time, "sleep", sleep)
    server = _server.LiveServer("pace", "127.0.0.1", 0, 2.0)
    try:
        server.pace(5_000_000_000)  # the origin
        server.pace(7_000_000_000)  # 2 s of log at twice the speed: 1 s later
        clock[0] += 3.0  # the computation was slow: no wait
        server.pace(8_000_000_000)
        server.pace(10_000_000_000)  # due 1 s after the last: (10 - 5) / 2 = 2.5 s after the origin
    finally:
        server.stop()
    assert slept == [1.0]
