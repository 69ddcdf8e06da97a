"""Read ROS bags into robot logs, with the pure-Python ``rosbags`` package (extra ``ros``).

A bag (a rosbag2 folder, sqlite3 or MCAP storage; ROS 1 ``.bag`` files are read by the
same reader) gives a :class:`~aura_ums.logs.RobotLog` from three topics:

**Motion** (``odom_topic``), as velocities held from each message to the next
(:class:`~aura_ums.logs.Odometry`):

- ``nav_msgs/msg/Odometry``: ``v = twist.twist.linear.x`` (m/s, forward in the robot
  frame), ``omega = twist.twist.angular.z`` (rad/s, counter-clockwise), at ``header.stamp``;
- ``geometry_msgs/msg/TwistStamped``: ``twist.linear.x`` and ``twist.angular.z`` at
  ``header.stamp`` (velocity commands);
- ``geometry_msgs/msg/Twist``: the same, at the bag's receive time (it has no stamp).

**Observations** (``observations_topic``): ROS has no standard landmark message, so the
convention is a ``geometry_msgs/msg/PointStamped`` per observation, needing no custom
message definitions:

- ``header.frame_id``: the landmark's id (as in the landmark list);
- ``header.stamp``: the time of the observation;
- ``point.x``: range, metres, horizontal, >= 0; ``0`` or ``NaN`` for a bearing-only one;
- ``point.y``: bearing, radians from the robot's heading to the landmark, counter-clockwise
  positive (any angle; wrapped to (-pi, pi]);
- ``point.z``: bound on the bearing error, radians, > 0; ``0`` or ``NaN`` takes the log's
  :attr:`~aura_ums.logs.LogMeta.bearing_error`. The range error bound always comes from
  the log's meta (:meth:`~aura_ums.logs.LogMeta.range_bound`).

**Ground truth** (optional ``groundtruth_topic``): ``nav_msgs/msg/Odometry``
(``pose.pose``), ``geometry_msgs/msg/PoseStamped`` (``pose``) or
``geometry_msgs/msg/PoseWithCovarianceStamped`` (``pose.pose``): ``position.x``, ``.y``
(m, world frame) and the yaw of ``orientation`` (rad).

Times are seconds: the header stamp (``sec + nanosec * 1e-9``); a stamp of exactly zero
(unset) takes the bag's receive time. Each topic's messages are sorted by time; of
odometry or ground-truth messages stamped with one time, the last in the topic is kept
(counted in the log's ``source``). Every error names the bag, the topic and,
for a bad message, its index in the topic (0 for the first).

**The camera** (:func:`read_camera_info`): the first ``sensor_msgs/msg/CameraInfo`` of a
topic (``width``, ``height``, ``distortion_model``, ``d``, ``k``, ``r``; ROS 1's ``D``,
``K``, ``R``), checked as a ROS calibration file is.
"""

from __future__ import annotations

import importlib
import itertools
import math
import os
import stat
import struct
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from aura_ums._files import as_path, present
from aura_ums._validate import ROW_GAP
from aura_ums.camera import Camera, CameraMount, camera_info_intrinsics
from aura_ums.errors import AuraUmsError, FileFormatError, InputError, MissingDependencyError
from aura_ums.logs._io import (
    COLUMN_RANGES,
    Units,
    _read_landmarks,
    _within,
    clock_jump,
    plural,
    renumbered,
    write_log,
)
from aura_ums.logs._log import (
    GroundTruth,
    LogLandmark,
    LogMeta,
    LogObservation,
    Odometry,
    RobotLog,
    printable,
)

#: Message types read as motion (velocities).
MOTION_TYPES = ("nav_msgs/msg/Odometry", "geometry_msgs/msg/TwistStamped", "geometry_msgs/msg/Twist")
#: The message type of observations (see the convention in :mod:`aura_ums.logs._rosbag`).
OBSERVATION_TYPE = "geometry_msgs/msg/PointStamped"
#: The message type of a camera's calibration (:func:`read_camera_info`).
CAMERA_INFO_TYPE = "sensor_msgs/msg/CameraInfo"
#: Message types read as ground truth (poses).
GROUNDTRUTH_TYPES = (
    "nav_msgs/msg/Odometry",
    "geometry_msgs/msg/PoseStamped",
    "geometry_msgs/msg/PoseWithCovarianceStamped",
)


def _require_rosbags() -> None:
    try:
        importlib.import_module("rosbags.highlevel")
        importlib.import_module("rosbags.typesys")
    except ImportError as exc:
        raise MissingDependencyError(
            f"reading ROS bags needs the optional package 'rosbags' (import failed: {exc}); "
            "install aura-ums[ros]"
        ) from exc


def _topic(value: object, name: str) -> str:
    if not isinstance(value, str) or not value.strip():
        raise InputError(f"{name}: expected a topic name such as '/odom', got {value!r}")
    return value


def _no_pipes(path: Path) -> None:
    """Refuse a bag that is, or holds, a pipe, socket or device: rosbags would wait on it or read forever.

    (``/dev/zero`` as a bag grew to 24 GB before it was killed.)
    """
    try:
        items = [path, *(path.iterdir() if path.is_dir() else ())]
        modes = [(item, item.stat().st_mode) for item in items]
    except OSError:
        return  # unreadable: the reader says so, naming the bag
    for item, mode in modes:
        if stat.S_ISFIFO(mode) or stat.S_ISSOCK(mode):
            raise FileFormatError(str(item), "", "expected a ROS bag file, got a named pipe or socket")
        if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
            raise FileFormatError(str(item), "", "expected a ROS bag file, got a device")


def _landmarks(value: object) -> tuple[LogLandmark, ...]:
    if isinstance(value, (str, os.PathLike)):
        path = Path(value)
        if not present(path):  # a folder or a pipe: the reader names what it is
            raise FileFormatError(str(path), "", "expected a landmarks CSV file, got no such file")
        listed = _read_landmarks(path, Units())
        if not listed:  # else every observation is refused as naming no landmark, the file unnamed
            raise FileFormatError(str(path), "", "expected a landmark per row after the header, got no row")
        return listed
    if not isinstance(value, Sequence):
        raise InputError(
            "landmarks: expected a sequence of LogLandmark or a landmarks.csv path, "
            f"got {type(value).__name__}"
        )
    for index, item in enumerate(value):
        if not isinstance(item, LogLandmark):
            raise InputError(f"landmarks[{index}]: expected a LogLandmark, got {type(item).__name__}")
    return tuple(value)


def _yaw(q: Any) -> float:
    """Heading (rad) of a quaternion ``(x, y, z, w)``: the rotation about +z; NaN for no rotation.

    A quaternion of (near) zero norm is no orientation: atan2 gave it heading 0.
    """
    norm = math.sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w)
    if not norm > 1e-6:
        return math.nan
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def _in_range(bag: _Bag, where: str, values: dict[str, float]) -> None:
    """Refuse a value a log file could not hold (``COLUMN_RANGES``): the import would be refused on replay."""
    for column, value in values.items():
        bounds = COLUMN_RANGES[column]
        if math.isfinite(value) and not bounds.contains(value):
            raise bag.fail(where, f"expected {column} to be {bounds.text()}, got {value!r}")


class _Bag:
    """An open bag: its topics, and each topic's messages with their times."""

    def __init__(self, reader: Any, path: Path, error: type[Exception]) -> None:
        self.reader = reader
        self.path = path
        self.error = error
        self.topics: dict[str, str | None] = {name: info.msgtype for name, info in reader.topics.items()}
        self.counts: dict[str, int] = {name: info.msgcount for name, info in reader.topics.items()}
        #: What the reading changed, for the log's ``source`` (repeated times dropped).
        self.notes: list[str] = []

    def fail(self, where: str, message: str) -> FileFormatError:
        return FileFormatError(str(self.path), where, message)

    def check(self, topic: str, allowed: Sequence[str], role: str) -> str:
        """Return the topic's message type after checking it is present, of a type read, not empty."""
        if topic not in self.topics:
            present = ", ".join(f"{name} ({kind})" for name, kind in sorted(self.topics.items())) or "none"
            raise self.fail(
                f"topic {topic}",
                f"expected the {role} topic in the bag, got no such topic; topics: {present}",
            )
        kind = self.topics[topic]
        if kind is None or kind not in allowed:
            raise self.fail(
                f"topic {topic}",
                f"expected {role} messages of type {' or '.join(allowed)}, got {kind or 'several types'}",
            )
        # The count is the bag's index (metadata.yaml); a damaged one says 0 of a topic that
        # has messages: look before calling it empty.
        if self.counts[topic] == 0 and next(self.messages(topic), None) is None:
            raise self.fail(f"topic {topic}", f"expected at least one {role} message, got none")
        return kind

    def messages(self, topic: str) -> Iterator[tuple[int, int, Any]]:
        """(index in the topic, receive time ns, message) in receive order."""
        connections = [c for c in self.reader.connections if c.topic == topic]
        for index, (connection, received, raw) in enumerate(self.reader.messages(connections=connections)):
            try:
                message = self.reader.deserialize(raw, connection.msgtype)
            except self.error as exc:  # corrupt data, or a definition that does not match it
                raise self.fail(
                    f"topic {topic}, message {index}", f"expected a {connection.msgtype}, got {exc}"
                ) from exc
            yield index, received, message


def _time(bag: _Bag, where: str, header: Any, received: int) -> float:
    """Return a message's time, s: its header's stamp, or the receive time when the stamp is unset (zero)."""
    stamp = header.stamp
    if stamp.sec == 0 and stamp.nanosec == 0:
        return received * 1e-9
    if not 0 <= stamp.nanosec < 1_000_000_000:
        # A stamp's nanoseconds are its fraction of a second: more was carried into the seconds.
        raise bag.fail(where, f"expected header.stamp.nanosec in [0, 1e9), got {stamp.nanosec!r}")
    return float(stamp.sec) + float(stamp.nanosec) * 1e-9


def _sorted_rows(
    bag: _Bag, topic: str, rows: list[tuple[float, int, tuple[float, ...]]], role: str
) -> tuple[np.ndarray[Any, np.dtype[np.float64]], int]:
    """Rows (time, values...) sorted by time, and how many repeated times were dropped.

    Of the messages stamped with one time the last in the topic is kept, as the MRCLAM
    importer keeps the last row of a repeated time: a republished or re-stamped message.
    """
    rows.sort(key=lambda row: (row[0], row[1]))
    _no_clock_jump(bag, topic, [(time, index) for time, index, _ in rows], role)
    kept = [
        row for row, after in itertools.zip_longest(rows, rows[1:]) if after is None or after[0] != row[0]
    ]
    return np.array([(t, *values) for t, _, values in kept], dtype=np.float64), len(rows) - len(kept)


def _no_clock_jump(bag: _Bag, topic: str, times: list[tuple[float, int]], role: str) -> None:
    """Refuse a time out of range or two messages more than a day apart (a log reader's rule)."""
    stamps = np.array([time for time, _ in times], dtype=np.float64)
    indices = np.array([index for _, index in times], dtype=np.int64)
    outside = np.flatnonzero(~_within(stamps, COLUMN_RANGES["time"]))
    if outside.size:
        _in_range(bag, f"topic {topic}, message {indices[outside[0]]}", {"time": float(stamps[outside[0]])})
    jump = clock_jump(stamps, indices, held=False)
    if jump is not None:
        row = jump[0]
        raise bag.fail(
            f"topic {topic}, message {indices[row]}",
            f"expected {role} messages at most {ROW_GAP.high:g} s apart, got "
            f"{stamps[row] - stamps[row - 1]:.6g} s after message {indices[row - 1]}: a clock jump",
        )


def _motion(bag: _Bag, topic: str, kind: str) -> Odometry:
    rows: list[tuple[float, int, tuple[float, ...]]] = []
    for index, received, message in bag.messages(topic):
        where = f"topic {topic}, message {index}"
        if kind == "nav_msgs/msg/Odometry":
            time, twist = _time(bag, where, message.header, received), message.twist.twist
        elif kind == "geometry_msgs/msg/TwistStamped":
            time, twist = _time(bag, where, message.header, received), message.twist
        else:
            time, twist = received * 1e-9, message
        v, omega = float(twist.linear.x), float(twist.angular.z)
        if not (math.isfinite(v) and math.isfinite(omega)):
            raise bag.fail(
                f"topic {topic}, message {index}",
                f"expected finite velocities, got linear.x {v!r} and angular.z {omega!r}",
            )
        _in_range(bag, f"topic {topic}, message {index}", {"v": v, "omega": omega})
        rows.append((time, index, (v, omega)))
    table, repeats = _sorted_rows(bag, topic, rows, "motion")
    if repeats:
        bag.notes.append(
            f"dropped {plural(repeats, 'repeated motion time')} on {topic} (kept the last message)"
        )
    return Odometry(table[:, 0], table[:, 1], table[:, 2])


def _quaternion(q: Any) -> str:
    return f"({float(q.x)!r}, {float(q.y)!r}, {float(q.z)!r}, {float(q.w)!r})"


def _groundtruth(bag: _Bag, topic: str, kind: str) -> GroundTruth:
    rows: list[tuple[float, int, tuple[float, ...]]] = []
    for index, received, message in bag.messages(topic):
        pose = message.pose if kind == "geometry_msgs/msg/PoseStamped" else message.pose.pose
        x, y = float(pose.position.x), float(pose.position.y)
        heading = _yaw(pose.orientation)
        if not all(math.isfinite(value) for value in (x, y, heading)):
            raise bag.fail(
                f"topic {topic}, message {index}",
                f"expected a finite pose and a unit orientation quaternion, got x {x!r}, y {y!r}, "
                f"orientation {_quaternion(pose.orientation)}",
            )
        where = f"topic {topic}, message {index}"
        _in_range(bag, where, {"x": x, "y": y})
        rows.append((_time(bag, where, message.header, received), index, (x, y, heading)))
    table, repeats = _sorted_rows(bag, topic, rows, "ground truth")
    if repeats:
        bag.notes.append(
            f"dropped {plural(repeats, 'repeated ground truth time')} on {topic} (kept the last message)"
        )
    return GroundTruth(table[:, 0], table[:, 1], table[:, 2], table[:, 3])


def _observations(bag: _Bag, topic: str, known: dict[str, LogLandmark]) -> tuple[LogObservation, ...]:
    found: list[tuple[float, int, LogObservation]] = []
    listed = ", ".join(list(known)[:20]) + (", ..." if len(known) > 20 else "")
    # Sightings of what the landmark list does not hold (other markers, other robots) are
    # dropped and counted, as import mrclam drops unknown barcodes; a bag of nothing else is refused.
    unknown: dict[str, int] = {}
    first_unknown = ""
    for index, received, message in bag.messages(topic):
        where = f"topic {topic}, message {index}"
        ident = message.header.frame_id
        if ident not in known:
            if not unknown:
                first_unknown = (
                    f"{where}: expected header.frame_id to be a landmark id ({listed}), got {ident!r}"
                )
            unknown[ident] = unknown.get(ident, 0) + 1
            continue
        x, y, z = float(message.point.x), float(message.point.y), float(message.point.z)
        if not math.isfinite(y):
            raise bag.fail(where, f"expected point.y to be a finite bearing (rad), got {y!r}")
        if x < 0.0 or math.isinf(x):
            raise bag.fail(
                where, f"expected point.x to be a range >= 0 m (0 or NaN: bearing only), got {x!r}"
            )
        if z < 0.0 or math.isinf(z):
            raise bag.fail(
                where,
                f"expected point.z to be a bearing error bound > 0 rad (0 or NaN: the log's), got {z!r}",
            )
        values = {"bearing": y, "range": x if x > 0.0 else math.nan}
        _in_range(bag, where, {**values, "bearing_error": z if z > 0.0 else math.nan})
        time = _time(bag, where, message.header, received)
        observation = LogObservation(
            time,
            ident,
            y,
            range=x if x > 0.0 else None,
            bearing_error=z if z > 0.0 else None,
            line=index,
        )
        found.append((time, index, observation))
    if unknown and not found:
        where, _, message = first_unknown.partition(": ")
        raise bag.fail(where, f"{message} (and no message names one)")
    if unknown:
        shown = ", ".join(f"{ident!r} {count}" for ident, count in sorted(unknown.items())[:10])
        more = ", ..." if len(unknown) > 10 else ""
        bag.notes.append(
            f"dropped {plural(sum(unknown.values()), 'observation')} on {topic} of ids not in the landmark "
            f"list ({shown}{more})"
        )
    found.sort(key=lambda item: (item[0], item[1]))
    _no_clock_jump(bag, topic, [(time, index) for time, index, _ in found], "observation")
    return tuple(observation for _, _, observation in found)


def _bag_path(bag_path: object) -> Path:
    """Return ``bag_path`` as a Path to something present, and neither a pipe nor a device."""
    path = as_path(bag_path, "bag_path", "a path")
    if not present(path):
        raise FileFormatError(
            str(path),
            "",
            "expected a ROS bag (a rosbag2 folder or a ROS 1 .bag file), got no such file or folder",
        )
    _no_pipes(path)
    return path


@contextmanager
def _opened(path: Path) -> Iterator[_Bag]:
    """Open a bag; every failure of rosbags while it is read becomes a FileFormatError naming it."""
    _require_rosbags()
    try:
        bare = path.is_dir() and not (path / "metadata.yaml").exists()
        lone = (
            sorted(item.name for item in path.iterdir() if item.suffix in (".db3", ".mcap")) if bare else []
        )
    except OSError:  # unreadable: the reader says so, naming the bag
        bare, lone = False, []
    if bare:
        # rosbags' own message named the folder as the missing metadata file.
        hint = f"; name a storage file to read it alone ({path / lone[0]})" if lone else ""
        raise FileFormatError(
            str(path),
            "",
            f"expected a rosbag2 folder holding metadata.yaml (ros2 bag record writes it), got none{hint}",
        )
    from rosbags.highlevel import AnyReader, AnyReaderError
    from rosbags.rosbag1 import ReaderError as Bag1Error
    from rosbags.rosbag2 import ReaderError as Bag2Error
    from rosbags.typesys import Stores, get_typestore

    try:
        with AnyReader([path], default_typestore=get_typestore(Stores.LATEST)) as reader:
            yield _Bag(reader, path, AnyReaderError)
    except AuraUmsError:
        raise
    except (AnyReaderError, Bag1Error, Bag2Error, OSError) as exc:  # no metadata.yaml, unreadable, damaged
        raise FileFormatError(str(path), "", f"expected a readable ROS bag, got {exc}") from exc
    except (ValueError, LookupError, EOFError, struct.error, TypeError, ArithmeticError, MemoryError) as exc:
        # Bytes that are no bag at all, or a damaged one: rosbags' parsers fail as they meet them
        # (a UnicodeDecodeError on a header, a short read, an ord() of nothing, a length beyond
        # any size), not with AnyReaderError.
        raise FileFormatError(
            str(path), "", f"expected a readable ROS bag, got {type(exc).__name__}: {exc}"
        ) from exc


def read_rosbag(
    bag_path: str | os.PathLike[str],
    *,
    odom_topic: str,
    observations_topic: str,
    landmarks: Sequence[LogLandmark] | str | os.PathLike[str],
    meta: LogMeta | None = None,
    groundtruth_topic: str | None = None,
) -> RobotLog:
    """Read a ROS bag into a robot log (topics and the observation convention: module notes).

    Parameters
    ----------
    bag_path : str or path-like
        A rosbag2 folder (with ``metadata.yaml``; sqlite3 or MCAP storage), or a ROS 1
        ``.bag`` file.
    odom_topic : str
        Motion: ``nav_msgs/msg/Odometry``, ``geometry_msgs/msg/TwistStamped`` or
        ``geometry_msgs/msg/Twist``.
    observations_topic : str
        Observations: ``geometry_msgs/msg/PointStamped`` (frame_id = landmark id,
        x = range m, y = bearing rad, z = bearing error bound rad).
    landmarks : sequence of LogLandmark, or path
        The landmark list, or a ``landmarks.csv`` file in the log format (SI units).
    meta : LogMeta or None
        The log's metadata; None: ``LogMeta(<bag name>)`` with its default bounds, and a
        ``source`` naming the bag and topics.
    groundtruth_topic : str or None
        True poses: ``nav_msgs/msg/Odometry``, ``geometry_msgs/msg/PoseStamped`` or
        ``geometry_msgs/msg/PoseWithCovarianceStamped``.

    Returns
    -------
    RobotLog
        Motion as :class:`Odometry`; each observation's ``line`` is its message index in
        the topic; ``path`` is None.

    Raises
    ------
    MissingDependencyError
        When ``rosbags`` is not installed (``pip install aura-ums[ros]``).
    InputError
        For arguments of the wrong type.
    FileFormatError
        Naming the bag and topic: a missing bag, a missing topic (listing those present),
        a topic of another message type, an empty topic, an observation topic naming no
        listed landmark, a bad message (with its index: negative range, non-finite values, a
        clock jump). Of motion or ground-truth messages stamped with one time the last is
        kept, and observations of ids not in the landmark list are dropped; the log's
        ``source`` says how many of each.

    Examples
    --------
    >>> read_rosbag("no_such_bag", odom_topic="/odom", observations_topic="/landmarks",
    ...             landmarks=())                                    # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: no_such_bag: expected a ROS bag (...), got no such file or folder
    """
    odom = _topic(odom_topic, "odom_topic")
    observed = _topic(observations_topic, "observations_topic")
    truth = None if groundtruth_topic is None else _topic(groundtruth_topic, "groundtruth_topic")
    if meta is not None and not isinstance(meta, LogMeta):
        raise InputError(f"meta: expected a LogMeta or None, got {type(meta).__name__}")
    path = _bag_path(bag_path)
    listed = _landmarks(landmarks)
    with _opened(path) as bag:
        kinds = {odom: bag.check(odom, MOTION_TYPES, "motion")}
        kinds[observed] = bag.check(observed, (OBSERVATION_TYPE,), "observation")
        if truth is not None:
            kinds[truth] = bag.check(truth, GROUNDTRUTH_TYPES, "ground truth")
        odometry = _motion(bag, odom, kinds[odom])
        observations = _observations(bag, observed, {item.id: item for item in listed})
        groundtruth = None if truth is None else _groundtruth(bag, truth, kinds[truth])
        notes = bag.notes
    if meta is None:
        topics = f"motion {odom}, observations {observed}" + (f", ground truth {truth}" if truth else "")
        # A file name may hold what a log name may not (a line break): kept readable, as printed.
        name = printable(path.stem or path.name).strip() or "bag"
        meta = LogMeta(name, source=printable("; ".join([f"ROS bag {path.name} ({topics})", *notes])))
    elif notes:
        meta = replace(
            meta, source=printable("; ".join([meta.source, *notes]) if meta.source else "; ".join(notes))
        )
    try:
        log = RobotLog(meta, listed, observations, odometry=odometry, groundtruth=groundtruth)
    except InputError as exc:  # e.g. duplicate landmark ids in the list
        raise InputError(f"{path}: {exc}") from exc
    names = {"motion": f"topic {odom}", "observations": f"topic {observed}", "ground truth": f"topic {truth}"}
    problem = log.unaligned_clocks(names)
    if problem is not None:
        raise FileFormatError(str(path), "", problem)
    return log


def read_camera_info(bag_path: str | os.PathLike[str], topic: str, mount: CameraMount) -> Camera:
    """Read the camera of a bag's first ``sensor_msgs/CameraInfo`` on ``topic``, on a mount.

    The message is checked as a ROS calibration file is
    (:func:`~aura_ums.camera.camera_info_intrinsics`, :func:`~aura_ums.camera.load_opencv_calibration`):
    ``distortion_model`` ``plumb_bob`` or ``rational_polynomial`` (k4-k6 zero), an identity
    ``r``, an unbinned full image. A driver publishes the same calibration with every image:
    the first message is taken, the others are not read.

    Parameters
    ----------
    bag_path : str or path-like
        A rosbag2 folder or a ROS 1 ``.bag`` file.
    topic : str
        The CameraInfo topic (``/camera/camera_info``).
    mount : CameraMount
        Where the camera sits on the robot (a CameraInfo does not say).

    Returns
    -------
    Camera
        The calibrated camera.

    Raises
    ------
    MissingDependencyError
        When ``rosbags`` is not installed (``pip install aura-ums[ros]``).
    InputError
        For arguments of the wrong type.
    FileFormatError
        Naming the bag, the topic and the message's field: a missing bag or topic, a
        topic of another type or empty, a calibration aura-ums does not model.

    Examples
    --------
    >>> read_camera_info("no_such_bag", "/camera_info", CameraMount(0.3))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: no_such_bag: expected a ROS bag (...), got no such file or folder
    """
    name = _topic(topic, "topic")
    if not isinstance(mount, CameraMount):
        raise InputError(f"mount: expected CameraMount, got {type(mount).__name__}")
    path = _bag_path(bag_path)
    with _opened(path) as bag:
        bag.check(name, (CAMERA_INFO_TYPE,), "camera info")
        index, _, message = next(bag.messages(name))
        intrinsics = camera_info_intrinsics(message, str(path), f"topic {name}, message {index}")
    return Camera(intrinsics, mount)


def import_rosbag(
    bag_path: str | os.PathLike[str],
    out_dir: str | os.PathLike[str],
    *,
    odom_topic: str,
    observations_topic: str,
    landmarks: Sequence[LogLandmark] | str | os.PathLike[str],
    meta: LogMeta | None = None,
    groundtruth_topic: str | None = None,
    overwrite: bool = False,
) -> RobotLog:
    """Read a ROS bag with :func:`read_rosbag` and write it as a log folder (:func:`write_log`).

    Parameters are those of :func:`read_rosbag`, plus ``out_dir`` (the log folder to write)
    and ``overwrite`` (replace an existing log there).

    Returns
    -------
    RobotLog
        The log as :func:`load_log` reads it back: ``path`` is ``out_dir`` and each
        observation's ``line`` is its line in the written ``observations.csv``.

    Raises
    ------
    MissingDependencyError, InputError, FileFormatError
        As :func:`read_rosbag` and :func:`write_log`.

    Examples
    --------
    >>> import tempfile
    >>> out = Path(tempfile.mkdtemp()) / "log"
    >>> import_rosbag("no_such_bag", out, odom_topic="/odom", observations_topic="/landmarks",
    ...               landmarks=())                                      # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: no_such_bag: expected a ROS bag (...), got no such file or folder
    >>> out.exists()                                   # refused before anything is written
    False
    """
    log = read_rosbag(
        bag_path,
        odom_topic=odom_topic,
        observations_topic=observations_topic,
        landmarks=landmarks,
        meta=meta,
        groundtruth_topic=groundtruth_topic,
    )
    folder = write_log(log, out_dir, overwrite=overwrite)
    return replace(log, observations=renumbered(log.observations), path=folder)
