"""ROS bags to robot logs: a synthetic run written with ``rosbags`` and read back exactly."""

from __future__ import annotations

import dataclasses
import math
import os
import shutil
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore
from rosbags.typesys.store import Typestore

from aura_ums.camera import Camera, CameraIntrinsics, CameraMount
from aura_ums.errors import FileFormatError, InputError, MissingDependencyError
from aura_ums.logs import LogLandmark, LogMeta, load_log
from aura_ums.logs._rosbag import import_rosbag, read_camera_info, read_rosbag

T0 = 1_700_000_000  # epoch seconds of the first stamp
LANDMARKS = (
    LogLandmark("pole", 4.0, 2.0, 0.05, 0.0, 3.0, "lamppost"),
    LogLandmark("corner", 1.0, -3.0, 0.1),
    LogLandmark("door", -2.0, 1.5),
)


@dataclass
class Run:
    """A synthetic trajectory: velocities at 10 Hz, true poses, and observations of the landmarks."""

    time: np.ndarray[Any, np.dtype[np.float64]]
    v: np.ndarray[Any, np.dtype[np.float64]]
    omega: np.ndarray[Any, np.dtype[np.float64]]
    x: np.ndarray[Any, np.dtype[np.float64]]
    y: np.ndarray[Any, np.dtype[np.float64]]
    heading: np.ndarray[Any, np.dtype[np.float64]]
    # (time, landmark id, bearing (any angle), range or None, bearing error or None)
    observations: list[tuple[float, str, float, float | None, float | None]] = field(default_factory=list)


def synthetic_run() -> Run:
    rng = np.random.default_rng(11)
    n = 30
    time = T0 + 0.1 * np.arange(n, dtype=np.float64) + 0.0123
    v = 0.5 + 0.2 * np.sin(np.arange(n) / 5.0)
    omega = 0.3 * np.cos(np.arange(n) / 7.0)
    heading = np.concatenate(([0.4], 0.4 + np.cumsum(omega[:-1] * 0.1)))
    x = np.concatenate(([0.0], np.cumsum(v[:-1] * np.cos(heading[:-1]) * 0.1)))
    y = np.concatenate(([0.0], np.cumsum(v[:-1] * np.sin(heading[:-1]) * 0.1)))
    run = Run(time, v, omega, x, y, heading)
    for i in range(0, n, 3):
        for j, landmark in enumerate(LANDMARKS):
            dx, dy = landmark.x - x[i], landmark.y - y[i]
            bearing = math.atan2(dy, dx) - heading[i] + (2 * math.pi if j == 2 else 0.0)  # one unwrapped
            distance = math.hypot(dx, dy) if (i + j) % 2 else None
            error = float(rng.uniform(0.01, 0.05)) if j == 1 else None
            run.observations.append((float(time[i]) + 0.001 * j, landmark.id, bearing, distance, error))
    return run


def stamp(store: Typestore, seconds: float) -> Any:
    sec = math.floor(seconds)
    return store.types["builtin_interfaces/msg/Time"](sec=sec, nanosec=round((seconds - sec) * 1e9))


def header(store: Typestore, seconds: float, frame: str = "") -> Any:
    return store.types["std_msgs/msg/Header"](stamp=stamp(store, seconds), frame_id=frame)


def vector(store: Typestore, x: float = 0.0, y: float = 0.0, z: float = 0.0, kind: str = "Vector3") -> Any:
    return store.types[f"geometry_msgs/msg/{kind}"](x=x, y=y, z=z)


def pose(store: Typestore, x: float, y: float, heading: float) -> Any:
    q = store.types["geometry_msgs/msg/Quaternion"](
        x=0.0, y=0.0, z=math.sin(heading / 2), w=math.cos(heading / 2)
    )
    return store.types["geometry_msgs/msg/Pose"](position=vector(store, x, y, kind="Point"), orientation=q)


def twist(store: Typestore, v: float, omega: float) -> Any:
    return store.types["geometry_msgs/msg/Twist"](linear=vector(store, v), angular=vector(store, z=omega))


def odometry_message(store: Typestore, run: Run, i: int) -> Any:
    t = store.types
    return t["nav_msgs/msg/Odometry"](
        header=header(store, float(run.time[i]), "odom"),
        child_frame_id="base_link",
        pose=t["geometry_msgs/msg/PoseWithCovariance"](
            pose=pose(store, float(run.x[i]), float(run.y[i]), float(run.heading[i])), covariance=np.zeros(36)
        ),
        twist=t["geometry_msgs/msg/TwistWithCovariance"](
            twist=twist(store, float(run.v[i]), float(run.omega[i])), covariance=np.zeros(36)
        ),
    )


def observation_message(store: Typestore, obs: tuple[float, str, float, float | None, float | None]) -> Any:
    time, ident, bearing, distance, error = obs
    x = math.nan if distance is None else distance
    return store.types["geometry_msgs/msg/PointStamped"](
        header=header(store, time, ident), point=vector(store, x, bearing, error or 0.0, kind="Point")
    )


Message = tuple[int, Any]  # receive time ns, message


def write_bag(
    path: Path, topics: dict[str, tuple[str, Sequence[Message]]], storage: StoragePlugin = StoragePlugin.MCAP
) -> Path:
    store = get_typestore(Stores.ROS2_HUMBLE)
    with Writer(path, version=9, storage_plugin=storage) as writer:
        for topic, (msgtype, messages) in topics.items():
            connection = writer.add_connection(topic, msgtype, typestore=store)
            for received, message in messages:
                writer.write(connection, received, store.serialize_cdr(message, msgtype))
    return path


def ns(seconds: float) -> int:
    return round(seconds * 1e9)


def standard_topics(run: Run, store: Typestore) -> dict[str, tuple[str, Sequence[Message]]]:
    odometry = [(ns(float(t)) + 5_000_000, odometry_message(store, run, i)) for i, t in enumerate(run.time)]
    observations = [(ns(o[0]) + 7_000_000, observation_message(store, o)) for o in run.observations]
    truth = [
        (
            ns(float(t)),
            store.types["geometry_msgs/msg/PoseStamped"](
                header=header(store, float(t), "map"),
                pose=pose(store, float(run.x[i]), float(run.y[i]), float(run.heading[i])),
            ),
        )
        for i, t in enumerate(run.time)
    ]
    return {
        "/odom": ("nav_msgs/msg/Odometry", odometry),
        "/landmarks": ("geometry_msgs/msg/PointStamped", observations),
        "/truth": ("geometry_msgs/msg/PoseStamped", truth),
    }


@pytest.fixture(scope="module")
def run() -> Run:
    return synthetic_run()


@pytest.fixture(scope="module")
def bag(run: Run, tmp_path_factory: pytest.TempPathFactory) -> Path:
    store = get_typestore(Stores.ROS2_HUMBLE)
    return write_bag(tmp_path_factory.mktemp("bags") / "walk", standard_topics(run, store))


def read(bag: Path, **overrides: Any) -> Any:
    arguments: dict[str, Any] = {
        "odom_topic": "/odom",
        "observations_topic": "/landmarks",
        "landmarks": LANDMARKS,
        "groundtruth_topic": "/truth",
    }
    arguments.update(overrides)
    return read_rosbag(bag, **arguments)


def wrapped(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


# --- the round trip -------------------------------------------------------------------------


@pytest.mark.parametrize("storage", [StoragePlugin.MCAP, StoragePlugin.SQLITE3], ids=["mcap", "sqlite3"])
def test_the_bag_is_read_as_written(run: Run, tmp_path: Path, storage: StoragePlugin) -> None:
    store = get_typestore(Stores.ROS2_HUMBLE)
    log = read(write_bag(tmp_path / "bag", standard_topics(run, store), storage))
    assert log.odometry is not None
    np.testing.assert_allclose(log.odometry.time, run.time, rtol=0, atol=1e-6)
    np.testing.assert_array_equal(log.odometry.v, run.v)
    np.testing.assert_array_equal(log.odometry.omega, run.omega)
    assert log.groundtruth is not None
    np.testing.assert_allclose(log.groundtruth.time, run.time, rtol=0, atol=1e-6)
    np.testing.assert_allclose(log.groundtruth.x, run.x, atol=1e-12)
    np.testing.assert_allclose(log.groundtruth.y, run.y, atol=1e-12)
    np.testing.assert_allclose(log.groundtruth.heading, [wrapped(h) for h in run.heading], atol=1e-12)
    assert len(log.observations) == len(run.observations)
    for got, (time, ident, bearing, distance, error) in zip(log.observations, run.observations, strict=True):
        assert got.landmark_id == ident
        assert math.isclose(got.time, time, abs_tol=1e-6)
        assert math.isclose(got.bearing, wrapped(bearing), abs_tol=1e-12)
        assert got.range == distance
        assert got.bearing_error == error
        assert got.range_error is None
    assert log.landmarks == LANDMARKS
    assert log.meta.name == "bag"
    assert "/odom" in log.meta.source
    assert "/truth" in log.meta.source


def test_import_writes_a_log_that_loads_back_equal(bag: Path, tmp_path: Path) -> None:
    meta = LogMeta("walk", terrain="concrete", bearing_error=0.02)
    log = import_rosbag(
        bag,
        tmp_path / "log",
        odom_topic="/odom",
        observations_topic="/landmarks",
        landmarks=LANDMARKS,
        meta=meta,
        groundtruth_topic="/truth",
    )
    loaded = load_log(tmp_path / "log")
    assert log.path == loaded.path == tmp_path / "log"
    assert loaded.meta == meta
    assert loaded.landmarks == log.landmarks
    assert loaded.observations == log.observations
    for name in ("time", "v", "omega"):
        np.testing.assert_array_equal(getattr(loaded.odometry, name), getattr(log.odometry, name))
    for name in ("time", "x", "y", "heading"):
        np.testing.assert_array_equal(getattr(loaded.groundtruth, name), getattr(log.groundtruth, name))
    with pytest.raises(InputError, match=r"folder: expected a folder without a log"):
        import_rosbag(
            bag, tmp_path / "log", odom_topic="/odom", observations_topic="/landmarks", landmarks=LANDMARKS
        )


def test_landmarks_from_a_csv_file(bag: Path, tmp_path: Path) -> None:
    csv = tmp_path / "landmarks.csv"
    csv.write_text(
        "id,x,y,position_uncertainty,symbol\npole,4,2,0.05,lamppost\ncorner,1,-3,0.1,x\ndoor,-2,1.5,0,x\n"
    )
    log = read(bag, landmarks=csv, groundtruth_topic=None)
    assert [item.id for item in log.landmarks] == ["pole", "corner", "door"]
    assert log.groundtruth is None
    # Sightings of landmarks the list does not hold are dropped and counted, as import mrclam
    # drops unknown barcodes (the whole bag was refused).
    csv.write_text("id,x,y\npole,4,2\n")
    fewer = read(bag, landmarks=csv)
    assert {item.landmark_id for item in fewer.observations} == {"pole"}
    dropped = len(log.observations) - len(fewer.observations)
    assert dropped > 0
    assert f"dropped {dropped} observations on /landmarks of ids not in the landmark list ('corner' " in (
        fewer.meta.source
    )
    # A list that holds none of the ids sighted is refused: the wrong list, not a few strangers.
    csv.write_text("id,x,y\ntree,4,2\n")
    with pytest.raises(
        FileFormatError,
        match=r"message \d+: expected header\.frame_id to be a landmark id \(tree\), got '\w+' "
        r"\(and no message names one\)",
    ):
        read(bag, landmarks=csv)
    with pytest.raises(FileFormatError, match=r"none\.csv: expected a landmarks CSV file, got no such file"):
        read(bag, landmarks=tmp_path / "none.csv")


def test_twist_commands_take_the_receive_time(run: Run, tmp_path: Path) -> None:
    store = get_typestore(Stores.ROS2_HUMBLE)
    received = [ns(float(t)) for t in run.time]
    commands = [
        (r, twist(store, float(v), float(w))) for r, v, w in zip(received, run.v, run.omega, strict=True)
    ]
    # stamped commands arrive out of order; an unset (zero) stamp takes the receive time
    stamped_type = store.types["geometry_msgs/msg/TwistStamped"]
    stamped = [
        (received[i], stamped_type(header=header(store, float(run.time[i])), twist=commands[i][1]))
        for i in (2, 0, 1)
    ]
    unset = stamped_type(header=header(store, 0.0), twist=twist(store, 0.25, 0.0))
    topics = standard_topics(run, store)
    path = write_bag(
        tmp_path / "bag",
        {
            "/cmd_vel": ("geometry_msgs/msg/Twist", commands),
            "/cmd_stamped": ("geometry_msgs/msg/TwistStamped", [*stamped, (received[5], unset)]),
            "/landmarks": topics["/landmarks"],
        },
    )
    log = read(path, odom_topic="/cmd_vel", groundtruth_topic=None)
    np.testing.assert_allclose(log.odometry.time, run.time, rtol=0, atol=1e-6)
    np.testing.assert_array_equal(log.odometry.v, run.v)
    log = read(path, odom_topic="/cmd_stamped", groundtruth_topic=None)
    np.testing.assert_allclose(log.odometry.time, [*run.time[:3], run.time[5]], rtol=0, atol=1e-6)
    np.testing.assert_array_equal(log.odometry.v, [*run.v[:3], 0.25])


def test_a_ros1_bag_is_read_too(tmp_path: Path) -> None:
    from rosbags.rosbag1 import Writer as Writer1

    store = get_typestore(Stores.ROS1_NOETIC)
    t = store.types

    def header1(seconds: float, frame: str = "") -> Any:
        return t["std_msgs/msg/Header"](seq=0, stamp=stamp(store, seconds), frame_id=frame)

    times = [10.0, 10.5, 11.25]
    with Writer1(tmp_path / "old.bag") as writer:
        motion = writer.add_connection("/cmd", "geometry_msgs/msg/TwistStamped", typestore=store)
        seen = writer.add_connection("/seen", "geometry_msgs/msg/PointStamped", typestore=store)
        for i, time in enumerate(times):
            command = t["geometry_msgs/msg/TwistStamped"](
                header=header1(time), twist=twist(store, 0.1 * i, -0.2)
            )
            writer.write(motion, ns(time), store.serialize_ros1(command, "geometry_msgs/msg/TwistStamped"))
            point = vector(store, 2.0 + i, 0.3, 0.0, kind="Point")
            observation = t["geometry_msgs/msg/PointStamped"](header=header1(time + 0.1, "pole"), point=point)
            writer.write(
                seen, ns(time + 0.1), store.serialize_ros1(observation, "geometry_msgs/msg/PointStamped")
            )
    log = read(tmp_path / "old.bag", odom_topic="/cmd", observations_topic="/seen", groundtruth_topic=None)
    assert log.odometry is not None
    np.testing.assert_allclose(log.odometry.time, times)
    np.testing.assert_allclose(log.odometry.v, [0.0, 0.1, 0.2])
    np.testing.assert_array_equal(log.odometry.omega, [-0.2, -0.2, -0.2])
    assert [o.range for o in log.observations] == [2.0, 3.0, 4.0]
    assert log.meta.name == "old"


# --- errors -----------------------------------------------------------------------------------


def test_missing_wrong_and_empty_topics(bag: Path, run: Run, tmp_path: Path) -> None:
    with pytest.raises(
        FileFormatError, match=r"walk: topic /scan: expected the motion topic in the bag, got no such "
    ):
        read(bag, odom_topic="/scan")
    with pytest.raises(
        FileFormatError, match=r"topics: /landmarks \(geometry_msgs/msg/PointStamped\), /odom \("
    ):
        read(bag, odom_topic="/scan")
    with pytest.raises(
        FileFormatError,
        match=r"topic /odom: expected observation messages of type geometry_msgs/msg/PointStamped, "
        r"got nav_msgs/msg/Odometry",
    ):
        read(bag, observations_topic="/odom")
    with pytest.raises(
        FileFormatError, match=r"topic /landmarks: expected motion messages of type nav_msgs/msg/Od"
    ):
        read(bag, odom_topic="/landmarks")
    store = get_typestore(Stores.ROS2_HUMBLE)
    topics = standard_topics(run, store)
    empty = write_bag(
        tmp_path / "empty", {"/odom": topics["/odom"], "/landmarks": ("geometry_msgs/msg/PointStamped", [])}
    )
    with pytest.raises(
        FileFormatError, match=r"empty: topic /landmarks: expected at least one observation message"
    ):
        read(empty, groundtruth_topic=None)


@pytest.mark.parametrize(
    ("change", "match"),
    [
        (lambda m: setattr(m.point, "x", -1.0), r"message 0: expected point\.x to be a range >= 0 m"),
        (lambda m: setattr(m.point, "y", math.nan), r"message 0: expected point\.y to be a finite bearing"),
        (lambda m: setattr(m.point, "z", -0.1), r"message 0: expected point\.z to be a bearing error bound"),
        # 1.5e9 ns were carried into the seconds (1.5 s late), a stamp no ROS clock writes
        (
            lambda m: setattr(m.header.stamp, "nanosec", 1_500_000_000),
            r"message 0: expected header\.stamp\.nanosec in \[0, 1e9\), got 1500000000",
        ),
    ],
)
def test_bad_observations_name_the_message(
    run: Run, tmp_path: Path, change: Callable[[Any], None], match: str
) -> None:
    store = get_typestore(Stores.ROS2_HUMBLE)
    topics = standard_topics(run, store)
    _, observations = topics["/landmarks"]
    change(observations[0][1])
    path = write_bag(tmp_path / "bad", topics)
    with pytest.raises(FileFormatError, match=rf"bad: topic /landmarks, {match}"):
        read(path)


def test_a_repeated_stamp_keeps_the_last_message_and_says_so(run: Run, tmp_path: Path) -> None:
    # As the MRCLAM importer keeps the last row of a repeated time (it refused the bag before).
    store = get_typestore(Stores.ROS2_HUMBLE)
    topics = standard_topics(run, store)
    kind, odometry = topics["/odom"]
    again = odometry_message(store, run, 4)
    again.twist.twist.linear.x = 0.123  # republished with another value: the later one counts
    topics["/odom"] = (kind, [*odometry, (odometry[-1][0] + 1, again)])
    truth_kind, truth = topics["/truth"]
    topics["/truth"] = (
        truth_kind,
        [*truth, (truth[-1][0] + 1, truth[2][1]), (truth[-1][0] + 2, truth[2][1])],
    )
    path = write_bag(tmp_path / "again", topics)
    log = read(path)
    clean = read(write_bag(tmp_path / "clean", standard_topics(run, store)))
    assert len(log.odometry.time) == len(clean.odometry.time)
    assert log.odometry.v[4] == 0.123
    np.testing.assert_array_equal(np.delete(log.odometry.v, 4), np.delete(clean.odometry.v, 4))
    np.testing.assert_array_equal(log.groundtruth.x, clean.groundtruth.x)
    assert log.meta.source.endswith(
        "; dropped 1 repeated motion time on /odom (kept the last message)"
        "; dropped 2 repeated ground truth times on /truth (kept the last message)"
    )
    # A meta of the user's keeps its source, with the notes after it.
    mine = read(path, meta=LogMeta("mine", source="lab run 7"))
    assert mine.meta.source.startswith("lab run 7; dropped 1 repeated motion time on /odom")


def test_bad_arguments(bag: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    with pytest.raises(FileFormatError, match=r"nothing: expected a ROS bag .* got no such file or folder"):
        read(tmp_path / "nothing")
    (tmp_path / "folder").mkdir()
    # rosbags' own message named the folder as the missing metadata file.
    with pytest.raises(
        FileFormatError,
        match=r"folder: expected a rosbag2 folder holding metadata\.yaml \(ros2 bag record writes it\), "
        r"got none$",
    ):
        read(tmp_path / "folder")
    lone = tmp_path / "lone"
    lone.mkdir()
    shutil.copy(next(bag.glob("*.mcap")), lone / "run.mcap")
    with pytest.raises(
        FileFormatError, match=r"got none; name a storage file to read it alone \(.*lone/run\.mcap\)$"
    ):
        read(lone)
    assert read(lone / "run.mcap").odometry is not None
    with pytest.raises(InputError, match=r"odom_topic: expected a topic name such as '/odom', got ''"):
        read(bag, odom_topic="")
    with pytest.raises(InputError, match=r"meta: expected a LogMeta or None, got str"):
        read(bag, meta="walk")
    with pytest.raises(InputError, match=r"landmarks\[0\]: expected a LogLandmark, got tuple"):
        read(bag, landmarks=[("pole", 4.0, 2.0)])
    for name in [m for m in sys.modules if m == "rosbags" or m.startswith("rosbags.")]:
        monkeypatch.setitem(sys.modules, name, None)
    with pytest.raises(MissingDependencyError, match=r"install aura-ums\[ros\]"):
        read(bag)


def test_a_bag_that_is_or_holds_a_named_pipe_is_refused_not_waited_on(bag: Path, tmp_path: Path) -> None:
    pipe = tmp_path / "walk.bag"
    os.mkfifo(pipe)
    with pytest.raises(FileFormatError, match=r"walk\.bag: expected a ROS bag file, got a named pipe"):
        read(pipe)
    folder = tmp_path / "walk"
    folder.mkdir()
    os.mkfifo(folder / "metadata.yaml")
    with pytest.raises(FileFormatError, match=r"metadata\.yaml: expected a ROS bag file, got a named pipe"):
        read(folder)
    landmarks = tmp_path / "landmarks.csv"
    os.mkfifo(landmarks)
    with pytest.raises(FileFormatError, match=r"landmarks\.csv: expected a CSV file, got a named pipe"):
        read(bag, landmarks=landmarks)


def test_a_damaged_or_endless_bag_is_refused_naming_it(bag: Path, tmp_path: Path) -> None:
    """Damaged bytes fail inside rosbags' parsers with their own errors: each is named, no traceback."""
    magic_only = tmp_path / "m.mcap"
    magic_only.write_bytes(b"\x89MCAP0\r\n")
    with pytest.raises(FileFormatError, match=r"m\.mcap: expected a readable ROS bag, got "):
        read(magic_only)
    damaged = tmp_path / "damaged"
    shutil.copytree(bag, damaged)
    for storage in damaged.glob("*.db3"):
        data = bytearray(storage.read_bytes())
        middle = len(data) // 2
        data[middle : middle + 2000] = b"\xff" * 2000
        storage.write_bytes(bytes(data))
    try:  # what the damage hits decides whether a message still reads: either is sound
        read(damaged)
        said = str(damaged)
    except FileFormatError as exc:  # any other exception fails the test
        said = str(exc)
    assert said.startswith(str(damaged))
    endless = tmp_path / "zero.bag"
    endless.symlink_to("/dev/zero")
    with pytest.raises(FileFormatError, match=r"zero\.bag: expected a ROS bag file, got a device"):
        read(endless)


def _set(messages: list[Message], index: int, part: str, **values: float) -> list[Message]:
    """The messages with fields of one message's ``part`` (a dotted path) set to ``values``."""
    target = messages[index][1]
    for name in part.split("."):
        target = getattr(target, name)
    for name, value in values.items():
        setattr(target, name, value)
    return messages


def _shifted(store: Typestore, messages: Sequence[Message], seconds: float, first: int = 0) -> list[Message]:
    """The messages from ``first`` on stamped ``seconds`` later (header and receive time)."""
    moved: list[Message] = []
    for index, (received, message) in enumerate(messages):
        if index >= first:
            time = message.header.stamp.sec + message.header.stamp.nanosec * 1e-9 + seconds
            message.header.stamp = stamp(store, time)
            received += ns(seconds)
        moved.append((received, message))
    return moved


@pytest.mark.parametrize(
    ("topic", "change", "match"),
    [
        # accepted on import, refused on replay: the import wrote a log nothing could read
        (
            "/landmarks",
            lambda store, ms: _set(ms, 0, "point", y=1e300),
            r"topic /landmarks, message 0: expected bearing to be a number in \[-1000, 1000\] rad, "
            r"got 1e\+300",
        ),
        (
            "/landmarks",
            lambda store, ms: _set(ms, 1, "point", x=1e308),
            r"topic /landmarks, message 1: expected range to be a number in \[0, 10000\] m, got 1e\+308",
        ),
        (
            "/odom",
            lambda store, ms: _set(ms, 0, "twist.twist.linear", x=1e308),
            r"topic /odom, message 0: expected v to be a number in \[-100, 100\] m/s, got 1e\+308",
        ),
        (
            "/odom",
            lambda store, ms: _shifted(store, ms, 30 * 86400.0, first=10),
            r"topic /odom, message 10: expected motion messages at most 86400 s apart, got 2\.592e\+06 s",
        ),
        # a zero quaternion became heading 0 in silence
        (
            "/truth",
            lambda store, ms: _set(ms, 3, "pose.orientation", w=0.0, z=0.0),
            r"topic /truth, message 3: expected a finite pose and a unit orientation quaternion, got .*"
            r"orientation \(0\.0, 0\.0, 0\.0, 0\.0\)",
        ),
        # each topic continuous, the observations 30 days after the motion
        (
            "/landmarks",
            lambda store, ms: _shifted(store, ms, 30 * 86400.0),
            r"expected the times of topic /odom and topic /landmarks to overlap \(at most 86400 s apart\)",
        ),
    ],
    ids=["bearing-1e300", "range-1e308", "speed-1e308", "clock-jump", "zero-quaternion", "clock-offset"],
)
def test_what_a_log_may_not_hold_is_refused_on_import(
    run: Run, tmp_path: Path, topic: str, change: Callable[[Typestore, Sequence[Message]], Any], match: str
) -> None:
    store = get_typestore(Stores.ROS2_HUMBLE)
    topics = standard_topics(run, store)
    kind, messages = topics[topic]
    topics[topic] = (kind, change(store, list(messages)))
    path = write_bag(tmp_path / "bad", topics)
    with pytest.raises(FileFormatError, match=match):
        read(path)


def test_a_topic_the_bags_index_counts_as_empty_is_read_when_it_has_messages(
    run: Run, tmp_path: Path
) -> None:
    # called "expected at least one observation message, got none" on the index's word alone
    store = get_typestore(Stores.ROS2_HUMBLE)
    path = write_bag(tmp_path / "miscounted", standard_topics(run, store), StoragePlugin.SQLITE3)
    metadata = path / "metadata.yaml"
    text = metadata.read_text()
    miscounted = text.replace(
        "- message_count: 30\n    topic_metadata:\n      name: /landmarks",
        "- message_count: 0\n    topic_metadata:\n      name: /landmarks",
    )
    assert miscounted != text
    metadata.write_text(miscounted)
    assert len(read(path).observations) == len(run.observations)


# --- a camera's calibration: sensor_msgs/CameraInfo -------------------------------------------

# The calibration of tests/camera/test_io.py's ROS_YAML, as a driver publishes it.
CAMERA_INFO = {
    "width": 640,
    "height": 480,
    "distortion_model": "plumb_bob",
    "d": [-0.1, 0.01, 0.0, 0.0, 0.0],
    "k": [554.25, 0.0, 320.5, 0.0, 554.25, 240.5, 0.0, 0.0, 1.0],
    "r": [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
    "p": [554.25, 0.0, 320.5, 0.0, 0.0, 554.25, 240.5, 0.0, 0.0, 0.0, 1.0, 0.0],
}
ROS_CAMERA = Camera(
    CameraIntrinsics(554.25, 554.25, 320.5, 240.5, 640, 480, (-0.1, 0.01, 0.0, 0.0, 0.0)), CameraMount(0.3)
)


def camera_info(store: Typestore, seconds: float, ros1: bool = False, **fields: Any) -> Any:
    t = store.types
    values = {**CAMERA_INFO, **fields}
    arrays = {name: np.array(values[name], dtype=np.float64) for name in ("d", "k", "r", "p")}
    if ros1:
        arrays = {name.upper(): array for name, array in arrays.items()}
        head = t["std_msgs/msg/Header"](seq=0, stamp=stamp(store, seconds), frame_id="camera")
    else:
        head = header(store, seconds, "camera")
    roi = t["sensor_msgs/msg/RegionOfInterest"](
        **{
            "x_offset": 0,
            "y_offset": 0,
            "height": 0,
            "width": 0,
            "do_rectify": False,
            **values.get("roi", {}),
        }
    )
    return t["sensor_msgs/msg/CameraInfo"](
        header=head,
        height=values["height"],
        width=values["width"],
        distortion_model=values["distortion_model"],
        binning_x=values.get("binning_x", 0),
        binning_y=values.get("binning_y", 0),
        roi=roi,
        **arrays,
    )


def camera_bag(path: Path, *messages: Any) -> Path:
    info = [(ns(T0 + i), message) for i, message in enumerate(messages)]
    return write_bag(path, {"/camera/camera_info": ("sensor_msgs/msg/CameraInfo", info)})


def test_a_camera_info_reads_as_the_ros_calibration_file(tmp_path: Path) -> None:
    store = get_typestore(Stores.ROS2_HUMBLE)
    # The first message is the calibration; later ones are not read.
    bag = camera_bag(
        tmp_path / "cam", camera_info(store, T0), camera_info(store, T0 + 1, distortion_model="x")
    )
    assert read_camera_info(bag, "/camera/camera_info", CameraMount(0.3)) == ROS_CAMERA
    extras = camera_info(
        store, T0, distortion_model="rational_polynomial", d=[-0.1, 0.01, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    )
    bag = camera_bag(tmp_path / "rational", extras)
    assert read_camera_info(bag, "/camera/camera_info", CameraMount(0.3)) == ROS_CAMERA


def test_an_empty_distortion_vector_is_no_distortion(tmp_path: Path) -> None:
    # As ROS's image_geometry reads it (a rectified or simulated camera's); it was refused.
    store = get_typestore(Stores.ROS2_HUMBLE)
    for model in ("plumb_bob", "rational_polynomial"):
        bag = camera_bag(tmp_path / model, camera_info(store, T0, distortion_model=model, d=[]))
        camera = read_camera_info(bag, "/camera/camera_info", CameraMount(0.3))
        assert camera == dataclasses.replace(
            ROS_CAMERA, intrinsics=dataclasses.replace(ROS_CAMERA.intrinsics, distortion=(0.0,) * 5)
        )


def test_a_ros1_camera_info_is_read_too(tmp_path: Path) -> None:
    from rosbags.rosbag1 import Writer as Writer1

    store = get_typestore(Stores.ROS1_NOETIC)
    with Writer1(tmp_path / "old.bag") as writer:
        connection = writer.add_connection("/camera_info", "sensor_msgs/msg/CameraInfo", typestore=store)
        message = camera_info(store, 10.0, ros1=True)
        writer.write(connection, ns(10.0), store.serialize_ros1(message, "sensor_msgs/msg/CameraInfo"))
    assert read_camera_info(tmp_path / "old.bag", "/camera_info", CameraMount(0.3)) == ROS_CAMERA


@pytest.mark.parametrize(
    ("fields", "match"),
    [
        (
            {"distortion_model": "equidistant", "d": [0.1, 0.0, 0.0, 0.0]},
            r"topic /camera/camera_info, message 0, distortion_model: expected distortion_model plumb_bob or "
            r"rational_polynomial, got 'equidistant'$",
        ),
        (
            {"r": [0.9998, 0.02, 0.0, -0.02, 0.9998, 0.0, 0.0, 0.0, 1.0]},
            r"message 0, r: expected the identity \(a monocular camera: aura-ums models no rectification\)",
        ),
        ({"k": [0.0] * 9}, r"message 0, k: expected \[\[fx, 0, cx\], \[0, fy, cy\], \[0, 0, 1\]\], got"),
        (
            {"d": [-0.1, 0.01]},
            r"message 0, d: expected 4 or 5 \(k1, k2, p1, p2\[, k3\]\) coefficients \(or none: no "
            r"distortion\) for distortion_model plumb_bob, got 2$",
        ),
        (
            {"k": [554.25, 0.0, 320.5, 0.0, math.nan, 240.5, 0.0, 0.0, 1.0]},
            r"message 0, k\[4\]: expected a finite",
        ),
        ({"width": 0}, r"message 0, width: expected an integer >= 1, got 0$"),
        ({"binning_x": 2}, r"message 0, binning_x: expected 0 or 1 \(an unbinned image\), got 2$"),
        (
            {"roi": {"x_offset": 10, "width": 320, "height": 240}},
            r"message 0, roi: expected no region of interest \(the full image the calibration describes\), "
            r"got x_offset 10, y_offset 0, width 320, height 240$",
        ),
    ],
)
def test_a_camera_info_aura_ums_does_not_model_is_refused(
    tmp_path: Path, fields: dict[str, Any], match: str
) -> None:
    store = get_typestore(Stores.ROS2_HUMBLE)
    bag = camera_bag(tmp_path / "cam", camera_info(store, T0, **fields))
    with pytest.raises(FileFormatError, match=match) as caught:
        read_camera_info(bag, "/camera/camera_info", CameraMount(0.3))
    assert caught.value.path == str(bag)


def test_a_camera_info_topic_must_be_there_and_of_its_type(bag: Path, tmp_path: Path) -> None:
    with pytest.raises(
        FileFormatError,
        match=r"walk: topic /camera_info: expected the camera info topic in the bag, got no such",
    ):
        read_camera_info(bag, "/camera_info", CameraMount(0.3))
    with pytest.raises(
        FileFormatError,
        match=r"topic /odom: expected camera info messages of type sensor_msgs/msg/CameraInfo, got nav_msgs",
    ):
        read_camera_info(bag, "/odom", CameraMount(0.3))
    with pytest.raises(InputError, match=r"mount: expected CameraMount, got float$"):
        read_camera_info(bag, "/odom", 0.3)  # type: ignore[arg-type]
    with pytest.raises(FileFormatError, match=r"nowhere: expected a ROS bag \(a rosbag2 folder or a ROS 1"):
        read_camera_info(tmp_path / "nowhere", "/camera_info", CameraMount(0.3))
