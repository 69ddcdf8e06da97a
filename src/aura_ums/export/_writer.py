"""Build Foxglove messages from runs and replays, and write them to MCAP (needs ``foxglove-sdk``).

Imported only by the public functions of :mod:`aura_ums.export`, after they have checked
that the optional dependency is installed. Messages are the Foxglove SDK's own types
(protobuf encoded, schemas embedded by the SDK), the container is written by its MCAP
writer; the metrics channel is JSON with a JSON schema.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import foxglove
import numpy as np
from foxglove import channels as fc
from foxglove import messages as fm
from numpy.typing import NDArray

from aura_ums import __version__
from aura_ums._files import atomic_path
from aura_ums.errors import FileFormatError, InputError
from aura_ums.export._scene import (
    seconds_to_nanoseconds,
    terrain_color,
    wedge_fan,
    wedge_radius,
    window_rectangle,
    yaw_quaternion,
)
from aura_ums.export._types import LogLandmarkLike, ReplayLike
from aura_ums.manager import ManagerState
from aura_ums.sim import FrameRecord, RunResult, Scenario
from aura_ums.uncertainty import (
    PointLandmark,
    Pose,
    SpatialUncertaintyMap,
    VerticalLineLandmark,
)
from aura_ums.world import MeadowMap

#: Frame of every 3D entity (metres, x east, y north).
WORLD_FRAME = "world"
#: Frame of the camera images and their annotations.
CAMERA_FRAME = "camera"

_RGBA = tuple[float, float, float, float]
_MAP_COLOR: _RGBA = (0.10, 0.35, 0.95, 1.0)
_LOST_COLOR: _RGBA = (0.90, 0.15, 0.15, 1.0)
_GROWN_COLOR: _RGBA = (0.45, 0.70, 1.00, 0.7)
_WEDGE_COLOR: _RGBA = (1.00, 0.60, 0.05, 0.9)
_TRUTH_COLOR: _RGBA = (0.10, 0.75, 0.20, 1.0)
_FOUND_COLOR: _RGBA = (0.10, 0.85, 0.25, 1.0)
_MISSED_COLOR: _RGBA = (1.00, 0.30, 0.20, 1.0)
_DETECTION_COLOR: _RGBA = (0.10, 0.90, 1.00, 1.0)
_TEXT_BACKGROUND: _RGBA = (0.0, 0.0, 0.0, 0.6)
_WHITE: _RGBA = (1.0, 1.0, 1.0, 1.0)
_LANDMARK_COLORS: Mapping[str, _RGBA] = {
    "I": (0.95, 0.85, 0.10, 1.0),
    "II": (0.95, 0.35, 0.85, 1.0),
    "III": (0.10, 0.85, 0.95, 1.0),
}
_UNUSED_ALPHA = 0.35
_MAP_Z = 0.02
_LINE_WIDTH = 0.05
_ARROW_LENGTH = 0.8
_LABEL_SIZE = 0.3
_MIN_POLE = 0.1
_MIN_SPHERE = 0.2
_ANNOTATION_FONT = 12.0

_SIMULATION_METRICS_SCHEMA: dict[str, Any] = {
    "title": "aura_ums.SimulationMetrics",
    "description": "One frame of an aura-ums simulation run (SI units; counts per frame).",
    "type": "object",
    "properties": {
        "frame": {"type": "integer", "description": "frame index, 0 for the start"},
        "time": {"type": "number", "description": "s"},
        "area_m2": {"type": "number", "description": "map area after the frame, m^2"},
        "area_before_m2": {"type": "number", "description": "map area before the reductions, m^2"},
        "wedge_width_rad": {"type": "number", "description": "heading wedge width after the frame, rad"},
        "inside": {"type": "integer", "description": "1 when the true pose is inside the map, else 0"},
        "accepted": {"type": "integer", "description": "observations that reduced the map"},
        "rejected": {"type": "integer", "description": "observations the manager rejected"},
        "windows": {"type": "integer", "description": "expectation windows searched"},
        "found": {"type": "integer", "description": "landmarks matched in their windows"},
        "lost": {"type": "integer", "description": "1 when the manager's state is LOST"},
        "frame_ms": {"type": "number", "description": "milliseconds of the loop"},
    },
}

_REPLAY_METRICS_SCHEMA: dict[str, Any] = {
    "title": "aura_ums.ReplayMetrics",
    "description": "One step of an aura-ums log replay (SI units; counts per step).",
    "type": "object",
    "properties": {
        "step": {"type": "integer", "description": "step index"},
        "time": {"type": "number", "description": "s (the log's clock)"},
        "area_m2": {"type": "number", "description": "map area after the step, m^2"},
        "wedge_width_rad": {"type": "number", "description": "heading wedge width, rad"},
        "inside": {
            "type": ["integer", "null"],
            "description": "1 when the true pose is inside the map, 0 when not, null without ground truth",
        },
        "accepted": {"type": "integer", "description": "observations that reduced the map"},
        "rejected": {"type": "integer", "description": "observations the manager rejected"},
        "lost": {"type": "integer", "description": "1 when the manager's state is LOST"},
        "update_us": {"type": "number", "description": "microseconds of the map update"},
        "relocalized": {"type": "integer", "description": "1 when the map was re-seeded from the envelope"},
        "envelope_inside": {
            "type": ["integer", "null"],
            "description": "1 when the true pose is inside the envelope map, 0 when not, null when unknown",
        },
    },
}


# --- small message helpers -------------------------------------------------------------------


def _color(rgba: _RGBA, alpha: float | None = None) -> fm.Color:
    r, g, b, a = rgba
    return fm.Color(r=r, g=g, b=b, a=a if alpha is None else alpha)


def _stamp(ns: int) -> fm.Timestamp:
    sec, nsec = divmod(ns, 1_000_000_000)
    return fm.Timestamp(sec, nsec)


def _points3(xy: NDArray[np.float64], z: float) -> list[fm.Point3]:
    return [fm.Point3(x=float(x), y=float(y), z=z) for x, y in xy]


def _pose3(x: float, y: float, z: float = 0.0, heading: float = 0.0) -> fm.Pose:
    qx, qy, qz, qw = yaw_quaternion(heading)
    return fm.Pose(
        position=fm.Vector3(x=x, y=y, z=z),
        orientation=fm.Quaternion(x=qx, y=qy, z=qz, w=qw),
    )


def _label(text: str, x: float, y: float, z: float, rgba: _RGBA = _WHITE) -> fm.TextPrimitive:
    return fm.TextPrimitive(
        pose=_pose3(x, y, z), billboard=True, font_size=_LABEL_SIZE, color=_color(rgba), text=text
    )


def _metadata(**values: str) -> list[fm.KeyValuePair]:
    return [fm.KeyValuePair(key=k, value=v) for k, v in values.items()]


def _update(*entities: fm.SceneEntity) -> fm.SceneUpdate:
    return fm.SceneUpdate(entities=list(entities))


# --- 3D scene ---------------------------------------------------------------------------------


def polygon_entity(
    entity_id: str, stamp: fm.Timestamp, the_map: SpatialUncertaintyMap, rgba: _RGBA
) -> fm.SceneEntity:
    """Return the map's polygon as a closed line (``LINE_LOOP``) just above the ground."""
    line = fm.LinePrimitive(
        type=fm.LinePrimitiveLineType.LineLoop,
        thickness=_LINE_WIDTH,
        points=_points3(the_map.polygon.vertices, _MAP_Z),
        color=_color(rgba),
    )
    return fm.SceneEntity(
        timestamp=stamp,
        frame_id=WORLD_FRAME,
        id=entity_id,
        lines=[line],
        metadata=_metadata(area_m2=f"{the_map.area:.6g}", vertices=str(the_map.polygon.vertex_count)),
    )


def wedge_entity(stamp: fm.Timestamp, the_map: SpatialUncertaintyMap) -> fm.SceneEntity:
    """Return the heading wedge as a fan from the map's centre (two rays and an arc)."""
    radius = wedge_radius(the_map.center, the_map.polygon.vertices)
    fan = wedge_fan(the_map.center, the_map.wedge, radius)
    line = fm.LinePrimitive(
        type=fm.LinePrimitiveLineType.LineLoop,
        thickness=_LINE_WIDTH / 2.0,
        points=_points3(fan, _MAP_Z),
        color=_color(_WEDGE_COLOR),
    )
    wedge = the_map.wedge
    return fm.SceneEntity(
        timestamp=stamp,
        frame_id=WORLD_FRAME,
        id="wedge",
        lines=[line],
        metadata=_metadata(
            center_rad=f"{wedge.center:.9g}", cw_rad=f"{wedge.cw:.9g}", ccw_rad=f"{wedge.ccw:.9g}"
        ),
    )


def pose_entity(entity_id: str, stamp: fm.Timestamp, pose: Pose, rgba: _RGBA) -> fm.SceneEntity:
    """Return an arrow at a pose, pointing along its heading."""
    arrow = fm.ArrowPrimitive(
        pose=_pose3(pose.x, pose.y, 2.0 * _MAP_Z, pose.heading),
        shaft_length=0.7 * _ARROW_LENGTH,
        shaft_diameter=0.06 * _ARROW_LENGTH,
        head_length=0.3 * _ARROW_LENGTH,
        head_diameter=0.18 * _ARROW_LENGTH,
        color=_color(rgba),
    )
    return fm.SceneEntity(timestamp=stamp, frame_id=WORLD_FRAME, id=entity_id, arrows=[arrow])


def center_pose(the_map: SpatialUncertaintyMap) -> Pose:
    """Return the map's centre with the wedge's central heading."""
    x, y = (float(v) for v in the_map.center)
    return Pose(x, y, the_map.wedge.center)


def meadow_entities(stamp: fm.Timestamp, world: MeadowMap) -> list[fm.SceneEntity]:
    """Return each meadow as an entity: a translucent fill coloured by terrain, its outline and a label."""
    entities = []
    for meadow in world.meadows:
        v = meadow.polygon.vertices
        rgba = terrain_color(meadow.terrain)
        # convex: a fan of triangles from the first vertex tiles it
        triangles = np.concatenate([v[[0, i, i + 1]] for i in range(1, len(v) - 1)])
        cx, cy = (float(c) for c in v.mean(axis=0))
        entities.append(
            fm.SceneEntity(
                timestamp=stamp,
                frame_id=WORLD_FRAME,
                id=meadow.id,
                triangles=[fm.TriangleListPrimitive(points=_points3(triangles, 0.0), color=_color(rgba))],
                lines=[
                    fm.LinePrimitive(
                        type=fm.LinePrimitiveLineType.LineLoop,
                        thickness=_LINE_WIDTH / 2.0,
                        points=_points3(v, 0.005),
                        color=_color(rgba, 0.9),
                    )
                ],
                texts=[_label(f"{meadow.id} ({meadow.terrain})", cx, cy, 0.05)],
                metadata=_metadata(terrain=meadow.terrain, landmarks=",".join(meadow.landmark_ids)),
            )
        )
    return entities


def landmark_entities(stamp: fm.Timestamp, world: MeadowMap, used: Sequence[str]) -> list[fm.SceneEntity]:
    """Return each landmark of a meadow map as an entity: Class I a cylinder, II a sphere, III a ground line.

    Landmarks the robot does not use are drawn translucent.
    """
    entities = []
    for record in world.landmarks:
        landmark = record.landmark
        klass = record.landmark_class.value
        alpha = None if record.id in used else _UNUSED_ALPHA
        color = _color(_LANDMARK_COLORS[klass], alpha)
        radius = landmark.position_uncertainty
        entity: dict[str, Any] = {}
        if isinstance(landmark, VerticalLineLandmark):
            d = max(2.0 * radius, _MIN_POLE)
            h = landmark.z_top - landmark.z_bottom
            entity["cylinders"] = [
                fm.CylinderPrimitive(
                    pose=_pose3(landmark.x, landmark.y, landmark.z_bottom + h / 2.0),
                    size=fm.Vector3(x=d, y=d, z=h),
                    bottom_scale=1.0,
                    top_scale=1.0,
                    color=color,
                )
            ]
            top = (landmark.x, landmark.y, landmark.z_top)
        elif isinstance(landmark, PointLandmark):
            d = max(2.0 * radius, _MIN_SPHERE)
            entity["spheres"] = [
                fm.SpherePrimitive(
                    pose=_pose3(landmark.x, landmark.y, landmark.z),
                    size=fm.Vector3(x=d, y=d, z=d),
                    color=color,
                )
            ]
            top = (landmark.x, landmark.y, landmark.z)
        else:
            ends = np.vstack((landmark.start, landmark.end))
            entity["lines"] = [
                fm.LinePrimitive(
                    type=fm.LinePrimitiveLineType.LineStrip,
                    thickness=max(2.0 * radius, _LINE_WIDTH),
                    points=_points3(ends, 0.01),
                    color=color,
                )
            ]
            mx, my = (float(c) for c in ends.mean(axis=0))
            top = (mx, my, 0.01)
        entities.append(
            fm.SceneEntity(
                timestamp=stamp,
                frame_id=WORLD_FRAME,
                id=record.id,
                texts=[_label(record.id, top[0], top[1], top[2] + _LABEL_SIZE)],
                metadata=_metadata(
                    landmark_class=klass,
                    symbol=record.symbol,
                    position_uncertainty_m=f"{radius:.6g}",
                    used="yes" if alpha is None else "no",
                ),
                **entity,
            )
        )
    return entities


def log_landmark_entities(stamp: fm.Timestamp, landmarks: Sequence[LogLandmarkLike]) -> list[fm.SceneEntity]:
    """Return each log landmark as an entity: a cylinder from ``z_bottom`` to ``z_top``, else a sphere."""
    entities = []
    for landmark in landmarks:
        x, y = float(landmark.x), float(landmark.y)
        radius = float(landmark.position_uncertainty)
        zb, zt = _height(landmark.z_bottom), _height(landmark.z_top)
        color = _color(_LANDMARK_COLORS["I"])
        entity: dict[str, Any] = {}
        if zb is not None and zt is not None and zt > zb:
            d = max(2.0 * radius, _MIN_POLE)
            entity["cylinders"] = [
                fm.CylinderPrimitive(
                    pose=_pose3(x, y, (zb + zt) / 2.0),
                    size=fm.Vector3(x=d, y=d, z=zt - zb),
                    bottom_scale=1.0,
                    top_scale=1.0,
                    color=color,
                )
            ]
            top = zt
        else:
            d = max(2.0 * radius, _MIN_SPHERE)
            top = zb if zb is not None else (zt if zt is not None else 0.0)
            entity["spheres"] = [
                fm.SpherePrimitive(pose=_pose3(x, y, top), size=fm.Vector3(x=d, y=d, z=d), color=color)
            ]
        entities.append(
            fm.SceneEntity(
                timestamp=stamp,
                frame_id=WORLD_FRAME,
                id=str(landmark.id),
                texts=[_label(str(landmark.id), x, y, top + _LABEL_SIZE)],
                metadata=_metadata(symbol=str(landmark.symbol), position_uncertainty_m=f"{radius:.6g}"),
                **entity,
            )
        )
    return entities


def _height(value: object) -> float | None:
    if value is None or isinstance(value, bool) or not isinstance(value, (int, float, np.number)):
        return None
    result = float(value)
    return result if math.isfinite(result) else None


# --- camera -----------------------------------------------------------------------------------


def raw_image(stamp: fm.Timestamp, image: NDArray[np.uint8]) -> fm.RawImage:
    """Return a grayscale frame as a ``mono8`` raw image."""
    height, width = image.shape
    return fm.RawImage(
        timestamp=stamp,
        frame_id=CAMERA_FRAME,
        width=width,
        height=height,
        encoding="mono8",
        step=width,
        data=np.ascontiguousarray(image).tobytes(),
    )


def frame_annotations(
    stamp: fm.Timestamp, record: FrameRecord, width: int, height: int
) -> fm.ImageAnnotations:
    """Return the frame's expectation windows (labelled rectangles) and detections (line segments).

    One ``LINE_LOOP`` points annotation per window, green when its landmark was found and
    red when not, labelled with the landmark id; the detections, when the record has them,
    are one ``LINE_LIST`` of their segments.
    """
    found = set(record.found)
    rectangles, texts = [], []
    for landmark_id, window in record.windows:
        corners = window_rectangle(window, width, height)
        rgba = _FOUND_COLOR if landmark_id in found else _MISSED_COLOR
        rectangles.append(
            fm.PointsAnnotation(
                timestamp=stamp,
                type=fm.PointsAnnotationType.LineLoop,
                points=[fm.Point2(x=float(u), y=float(v)) for u, v in corners],
                outline_color=_color(rgba),
                thickness=2.0,
                metadata=_metadata(landmark_id=landmark_id, found="yes" if landmark_id in found else "no"),
            )
        )
        texts.append(
            fm.TextAnnotation(
                timestamp=stamp,
                position=fm.Point2(
                    x=float(corners[0, 0]) + 2.0, y=float(corners[0, 1]) + _ANNOTATION_FONT + 2.0
                ),
                text=landmark_id,
                font_size=_ANNOTATION_FONT,
                text_color=_color(rgba),
                background_color=_color(_TEXT_BACKGROUND),
            )
        )
    detections: Sequence[tuple[str, Sequence[float]]] = getattr(record, "detections", ())
    if detections:
        points = []
        for _, (u1, v1, u2, v2) in detections:
            points += [
                fm.Point2(x=float(u1) + 0.5, y=float(v1) + 0.5),
                fm.Point2(x=float(u2) + 0.5, y=float(v2) + 0.5),
            ]
        rectangles.append(
            fm.PointsAnnotation(
                timestamp=stamp,
                type=fm.PointsAnnotationType.LineList,
                points=points,
                outline_color=_color(_DETECTION_COLOR),
                thickness=2.0,
                metadata=_metadata(detections=",".join(i for i, _ in detections)),
            )
        )
    return fm.ImageAnnotations(points=rectangles, texts=texts)


# --- writing ----------------------------------------------------------------------------------


#: Reports ``(done, total)`` units of work after each one (the CLI draws it as a bar).
Progress = Callable[[int, int], None]


@contextmanager
def _mcap(path: Path, kind: str, name: str) -> Iterator[foxglove.Context]:
    """Open an MCAP file on a private SDK context (nothing leaks to the global one).

    The file is written under a scratch name beside ``path`` and renamed onto it once
    closed: an error, a Ctrl-C or a kill leaves the old file (or none), never a part.
    """
    context = foxglove.Context()
    try:
        with atomic_path(path) as scratch:
            writer = foxglove.open_mcap(scratch, allow_overwrite=False, context=context)
            with writer:
                writer.write_metadata(
                    "aura_ums", {"kind": kind, "name": name, "aura_ums_version": __version__}
                )
                yield context
    except OSError as exc:
        raise FileFormatError(str(path), "", f"expected a writable file, got {exc.strerror or exc}") from exc


def _report(progress: Progress | None, done: int, total: int) -> None:
    if progress is not None:
        progress(done, total)


def _json_channel(topic: str, schema: dict[str, Any], context: foxglove.Context) -> foxglove.Channel:
    return foxglove.Channel(
        topic,
        schema=foxglove.Schema(
            name=str(schema["title"]), encoding="jsonschema", data=json.dumps(schema).encode("utf-8")
        ),
        message_encoding="json",
        context=context,
    )


def write_simulation(
    path: Path,
    scenario: Scenario,
    result: RunResult,
    camera_topic_images: bool,
    progress: Progress | None = None,
) -> Path:
    """Write a simulation run; see :func:`aura_ums.export.write_simulation_mcap`."""
    records = result.records
    if not records:
        raise InputError("result.records: expected at least one frame, got none")
    images = result.images
    if camera_topic_images and not images:
        raise InputError(
            "result.images: expected the frames' images (run_scenario(..., keep_images=True)), got none; "
            "pass camera_topic_images=False to export without them"
        )
    if len(images) > len(records):
        raise InputError(f"result.images: expected at most {len(records)} images, got {len(images)}")
    for index, image in enumerate(images if camera_topic_images else ()):
        if not isinstance(image, np.ndarray) or image.ndim != 2 or image.dtype != np.uint8:
            raise InputError(
                f"result.images[{index}]: expected a 2-D uint8 grayscale image, "
                f"got {getattr(image, 'shape', type(image).__name__)} of {getattr(image, 'dtype', '?')}"
            )
    # images are those of the last call of run_scenario: the last frames (after a resume)
    first_image = len(records) - len(images)
    times = [seconds_to_nanoseconds(r.time, f"records[{i}].time") for i, r in enumerate(records)]
    intrinsics = scenario.camera.intrinsics
    with _mcap(path, "simulation", scenario.name) as context:
        meadows = fc.SceneUpdateChannel("/meadows", context=context)
        landmarks = fc.SceneUpdateChannel("/landmarks", context=context)
        polygon = fc.SceneUpdateChannel("/map/polygon", context=context)
        grown = fc.SceneUpdateChannel("/map/grown", context=context)
        wedge = fc.SceneUpdateChannel("/map/wedge", context=context)
        center = fc.SceneUpdateChannel("/map/center", context=context)
        truth = fc.SceneUpdateChannel("/truth", context=context)
        annotations = fc.ImageAnnotationsChannel("/camera/annotations", context=context)
        camera = fc.RawImageChannel("/camera/image", context=context) if camera_topic_images else None
        metrics = _json_channel("/metrics", _SIMULATION_METRICS_SCHEMA, context)

        stamp0 = _stamp(times[0])
        meadows.log(_update(*meadow_entities(stamp0, scenario.meadow_map)), log_time=times[0])
        landmarks.log(
            _update(*landmark_entities(stamp0, scenario.meadow_map, scenario.landmark_ids)), log_time=times[0]
        )
        for index, (record, ns) in enumerate(zip(records, times, strict=True)):
            stamp = _stamp(ns)
            lost = record.state is ManagerState.LOST
            after = record.map_after
            polygon.log(
                _update(polygon_entity("polygon", stamp, after, _LOST_COLOR if lost else _MAP_COLOR)),
                log_time=ns,
            )
            grown.log(_update(polygon_entity("grown", stamp, record.map_before, _GROWN_COLOR)), log_time=ns)
            wedge.log(_update(wedge_entity(stamp, after)), log_time=ns)
            center.log(_update(pose_entity("center", stamp, center_pose(after), _MAP_COLOR)), log_time=ns)
            truth.log(_update(pose_entity("truth", stamp, record.true_pose, _TRUTH_COLOR)), log_time=ns)
            if camera is not None and index >= first_image:
                camera.log(raw_image(stamp, images[index - first_image]), log_time=ns)
            annotations.log(
                frame_annotations(stamp, record, intrinsics.width, intrinsics.height), log_time=ns
            )
            metrics.log(
                {
                    "frame": record.index,
                    "time": record.time,
                    "area_m2": after.area,
                    "area_before_m2": record.map_before.area,
                    "wedge_width_rad": after.wedge.width,
                    "inside": int(record.inside),
                    "accepted": record.accepted,
                    "rejected": len(record.rejected),
                    "windows": len(record.windows),
                    "found": len(record.found),
                    "lost": int(lost),
                    "frame_ms": record.frame_ms,
                },
                log_time=ns,
            )
            _report(progress, index + 1, len(records))
    return path


def _flag(value: bool | None) -> int | None:
    return None if value is None else int(bool(value))


def _replay_world(replay: ReplayLike) -> MeadowMap | None:
    """Return the arena a :class:`aura_ums.logs.ReplayResult` replayed in (None for other replays)."""
    from aura_ums.logs import ReplayOptions, RobotLog, log_meadow_map

    options = getattr(replay, "options", None)
    if not isinstance(options, ReplayOptions) or not isinstance(replay.log, RobotLog):
        return None
    return log_meadow_map(replay.log, options.landmark_class, margin=options.arena_margin)


def write_replay(path: Path, replay: ReplayLike, progress: Progress | None = None) -> Path:
    """Write a replay; see :func:`aura_ums.export.write_replay_mcap`."""
    steps = tuple(replay.steps)
    if not steps:
        raise InputError("replay.steps: expected at least one step, got none")
    times = [seconds_to_nanoseconds(s.time, f"replay.steps[{i}].time") for i, s in enumerate(steps)]
    world = _replay_world(replay)
    with _mcap(path, "replay", str(replay.log.meta.name)) as context:
        landmarks = fc.SceneUpdateChannel("/landmarks", context=context)
        if world is not None:
            meadows = fc.SceneUpdateChannel("/meadows", context=context)
            meadows.log(_update(*meadow_entities(_stamp(times[0]), world)), log_time=times[0])
        polygon = fc.SceneUpdateChannel("/map/polygon", context=context)
        wedge = fc.SceneUpdateChannel("/map/wedge", context=context)
        center = fc.SceneUpdateChannel("/map/center", context=context)
        has_truth = any(s.truth is not None for s in steps)
        truth = fc.SceneUpdateChannel("/truth", context=context) if has_truth else None
        metrics = _json_channel("/metrics", _REPLAY_METRICS_SCHEMA, context)

        if world is None:
            drawn = log_landmark_entities(_stamp(times[0]), replay.log.landmarks)
        else:
            drawn = landmark_entities(_stamp(times[0]), world, [r.id for r in world.landmarks])
        landmarks.log(_update(*drawn), log_time=times[0])
        for index, (step, ns) in enumerate(zip(steps, times, strict=True)):
            stamp = _stamp(ns)
            lost = step.state is ManagerState.LOST
            polygon.log(
                _update(polygon_entity("polygon", stamp, step.map, _LOST_COLOR if lost else _MAP_COLOR)),
                log_time=ns,
            )
            wedge.log(_update(wedge_entity(stamp, step.map)), log_time=ns)
            center.log(_update(pose_entity("center", stamp, center_pose(step.map), _MAP_COLOR)), log_time=ns)
            if truth is not None:
                if step.truth is None:  # unknown here: remove the last arrow rather than leave it
                    deletion = fm.SceneEntityDeletion(
                        timestamp=stamp, type=fm.SceneEntityDeletionType.MatchingId, id="truth"
                    )
                    truth.log(fm.SceneUpdate(deletions=[deletion]), log_time=ns)
                else:
                    truth.log(_update(pose_entity("truth", stamp, step.truth, _TRUTH_COLOR)), log_time=ns)
            metrics.log(
                {
                    "step": index,
                    "time": float(step.time),
                    "area_m2": step.map.area,
                    "wedge_width_rad": step.map.wedge.width,
                    "inside": _flag(step.inside),
                    "accepted": int(step.accepted),
                    "rejected": int(step.rejected),
                    "lost": int(lost),
                    "update_us": float(step.update_us),
                    "relocalized": int(bool(getattr(step, "relocalized", False))),
                    "envelope_inside": _flag(getattr(step, "envelope_inside", None)),
                },
                log_time=ns,
            )
            _report(progress, index + 1, len(steps))
    return path
