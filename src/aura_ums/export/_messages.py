"""Build the Foxglove messages of runs and replays, and the channels they go on (needs ``foxglove-sdk``).

One builder for both sinks: :class:`SimulationChannels` and :class:`ReplayChannels` open
their channels on an SDK context (an MCAP file's in ``_writer``, a WebSocket server's in
``_live``) and publish a frame or a step on them. The topics, schemas and messages are
therefore the same in a file and in a live view, and a Foxglove layout made for one works
for the other. Messages are the SDK's own types (protobuf, schemas embedded by the SDK);
the metrics channel is JSON with a JSON schema.

Imported only after the public functions of :mod:`aura_ums.export` have checked that the
optional dependency is installed.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import foxglove
import numpy as np
from foxglove import channels as fc
from foxglove import messages as fm
from numpy.typing import NDArray

from aura_ums.export._scene import (
    heading_color,
    slice_height,
    terrain_color,
    wedge_fan,
    wedge_radius,
    window_rectangle,
    yaw_quaternion,
)
from aura_ums.export._types import LogLandmarkLike, ReplayStepLike, RobotLogLike
from aura_ums.manager import ManagerState
from aura_ums.sim import FrameRecord, Scenario
from aura_ums.uncertainty import (
    PointLandmark,
    Pose,
    SpatialUncertaintyMap,
    VerticalLineLandmark,
)
from aura_ums.world import MeadowMap

if TYPE_CHECKING:
    from aura_ums.logs import WindowRow

# The topics, each named once (docs/interop.md lists them).
MEADOWS = "/meadows"
LANDMARKS = "/landmarks"
POLYGON = "/map/polygon"
GROWN = "/map/grown"
WEDGE = "/map/wedge"
SLICES = "/map/slices"
CENTER = "/map/center"
TRUTH = "/truth"
IMAGE = "/camera/image"
ANNOTATIONS = "/camera/annotations"
METRICS = "/metrics"

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
#: RGBA of the windows of the baselines beside ours (replay with a camera), by method.
# The windows drawn thin and unlabelled beside ours: the focus map's, and the baselines'.
_SECONDARY_COLORS: Mapping[str, _RGBA] = {
    "aura-ums focus": (0.10, 0.80, 0.80, 0.9),
    "EKF 3-sigma box": (1.00, 0.65, 0.10, 0.9),
    "disk model": (0.75, 0.45, 1.00, 0.9),
}
_NOT_JUDGED_COLOR: _RGBA = (0.70, 0.70, 0.70, 1.0)
#: Half-size (pixels) of the cross drawn at a measured Class II pixel.
_CROSS = 6.0

_SIMULATION_METRICS_SCHEMA: dict[str, Any] = {
    "title": "aura_ums.SimulationMetrics",
    "description": "One frame of an aura-ums simulation run (SI units; counts per frame).",
    "type": "object",
    "properties": {
        "run": {"type": "integer", "description": "Monte Carlo run, 1 for the first (and a file's only) run"},
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


def slices_entity(stamp: fm.Timestamp, the_map: SpatialUncertaintyMap) -> fm.SceneUpdate:
    """Return the map's heading slices: one closed line per slice, stacked by heading.

    Slice ``i`` (in heading order) is drawn ``slice_height(i)`` above the ground and
    coloured by the heading at its middle, so a 3D view shows position against heading.
    A map that is not sliced deletes the entity instead of leaving stale slices.
    """
    if not the_map.is_sliced:
        deletion = fm.SceneEntityDeletion(
            timestamp=stamp, type=fm.SceneEntityDeletionType.MatchingId, id="slices"
        )
        return fm.SceneUpdate(deletions=[deletion])
    lines = []
    for index, piece in enumerate(the_map.slices):
        lines.append(
            fm.LinePrimitive(
                type=fm.LinePrimitiveLineType.LineLoop,
                thickness=_LINE_WIDTH / 2.0,
                points=_points3(piece.polygon.vertices, slice_height(index)),
                color=_color(heading_color(piece.lo + piece.width / 2.0)),
            )
        )
    entity = fm.SceneEntity(
        timestamp=stamp,
        frame_id=WORLD_FRAME,
        id="slices",
        lines=lines,
        metadata=_metadata(slices=str(len(lines)), slice_width_rad=f"{the_map.slice_width:.9g}"),
    )
    return _update(entity)


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


def window_annotations(
    stamp: fm.Timestamp, rows: Sequence[WindowRow], width: int, height: int
) -> fm.ImageAnnotations:
    """Return a replay frame's windows (labelled rectangles) and measured pixels (cyan marks).

    Our window (method ``"aura-ums"``) is green when the measured pixel lies in it, red
    when not, grey when not judged, labelled with the landmark id; the focus map's window
    (``"aura-ums focus"``) is teal, the baselines' windows (EKF 3-sigma box, disk model) are
    orange and violet. The measured pixels of our rows in
    view are one ``LINE_LIST``: a full-height column for a Class I (bearing-only) row, a
    cross for a Class II point.
    """
    rectangles, texts, marks = [], [], []
    # Ours last, on top: without the relaxed intersection the focus window is the same rectangle.
    for row in sorted(rows, key=lambda row: row.method not in _SECONDARY_COLORS):
        ours = row.method not in _SECONDARY_COLORS
        if row.window is not None:
            if not ours:
                rgba = _SECONDARY_COLORS[row.method]
            elif row.inside is None:
                rgba = _NOT_JUDGED_COLOR
            else:
                rgba = _FOUND_COLOR if row.inside else _MISSED_COLOR
            corners = window_rectangle(row.window, width, height)
            rectangles.append(
                fm.PointsAnnotation(
                    timestamp=stamp,
                    type=fm.PointsAnnotationType.LineLoop,
                    points=[fm.Point2(x=float(u), y=float(v)) for u, v in corners],
                    outline_color=_color(rgba),
                    thickness=2.0 if ours else 1.0,
                    metadata=_metadata(
                        landmark_id=row.landmark_id,
                        method=row.method,
                        inside="not judged" if row.inside is None else ("yes" if row.inside else "no"),
                    ),
                )
            )
            if ours:
                texts.append(
                    fm.TextAnnotation(
                        timestamp=stamp,
                        position=fm.Point2(
                            x=float(corners[0, 0]) + 2.0, y=float(corners[0, 1]) + _ANNOTATION_FONT + 2.0
                        ),
                        text=row.landmark_id,
                        font_size=_ANNOTATION_FONT,
                        text_color=_color(rgba),
                        background_color=_color(_TEXT_BACKGROUND),
                    )
                )
        if ours and row.in_view:
            u = row.measured_u + 0.5
            if math.isnan(row.measured_v):  # a column: Class I judges the column only
                marks += [fm.Point2(x=u, y=0.0), fm.Point2(x=u, y=float(height))]
            else:
                v = row.measured_v + 0.5
                marks += [
                    fm.Point2(x=u - _CROSS, y=v),
                    fm.Point2(x=u + _CROSS, y=v),
                    fm.Point2(x=u, y=v - _CROSS),
                    fm.Point2(x=u, y=v + _CROSS),
                ]
    if marks:
        rectangles.append(
            fm.PointsAnnotation(
                timestamp=stamp,
                type=fm.PointsAnnotationType.LineList,
                points=marks,
                outline_color=_color(_DETECTION_COLOR),
                thickness=1.0,
                metadata=_metadata(measured="yes"),
            )
        )
    return fm.ImageAnnotations(points=rectangles, texts=texts)


# --- metrics ----------------------------------------------------------------------------------


def simulation_metrics(record: FrameRecord, run: int) -> dict[str, Any]:
    """Return one frame's ``/metrics`` message (schema ``aura_ums.SimulationMetrics``)."""
    after = record.map_after
    return {
        "run": run,
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
        "lost": int(record.state is ManagerState.LOST),
        "frame_ms": record.frame_ms,
    }


def _flag(value: bool | None) -> int | None:
    return None if value is None else int(bool(value))


def replay_metrics(index: int, step: ReplayStepLike) -> dict[str, Any]:
    """Return one step's ``/metrics`` message (schema ``aura_ums.ReplayMetrics``)."""
    return {
        "step": index,
        "time": float(step.time),
        "area_m2": step.map.area,
        "wedge_width_rad": step.map.wedge.width,
        "inside": _flag(step.inside),
        "accepted": int(step.accepted),
        "rejected": int(step.rejected),
        "lost": int(step.state is ManagerState.LOST),
        "update_us": float(step.update_us),
        "relocalized": int(bool(getattr(step, "relocalized", False))),
        "envelope_inside": _flag(getattr(step, "envelope_inside", None)),
    }


def _json_channel(topic: str, schema: dict[str, Any], context: foxglove.Context) -> foxglove.Channel:
    return foxglove.Channel(
        topic,
        schema=foxglove.Schema(
            name=str(schema["title"]), encoding="jsonschema", data=json.dumps(schema).encode("utf-8")
        ),
        message_encoding="json",
        context=context,
    )


# --- the channels of a run and of a replay ----------------------------------------------------


class SimulationChannels:
    """The channels of a simulation run on one SDK context, and how a frame is published on them.

    Parameters
    ----------
    context : foxglove.Context
        The context whose sink (an MCAP file, a WebSocket server) receives the messages.
    scenario : Scenario
        The scenario run: its meadows, landmarks and camera size.
    images : bool
        Open ``/camera/image`` (the frames' images).
    sliced : bool
        Open ``/map/slices`` (the maps are heading-sliced).
    """

    def __init__(self, context: foxglove.Context, scenario: Scenario, *, images: bool, sliced: bool) -> None:
        self._scenario = scenario
        intrinsics = scenario.camera.intrinsics
        self._size = (intrinsics.width, intrinsics.height)
        self.meadows = fc.SceneUpdateChannel(MEADOWS, context=context)
        self.landmarks = fc.SceneUpdateChannel(LANDMARKS, context=context)
        self.polygon = fc.SceneUpdateChannel(POLYGON, context=context)
        self.grown = fc.SceneUpdateChannel(GROWN, context=context)
        self.wedge = fc.SceneUpdateChannel(WEDGE, context=context)
        self.center = fc.SceneUpdateChannel(CENTER, context=context)
        self.truth = fc.SceneUpdateChannel(TRUTH, context=context)
        self.annotations = fc.ImageAnnotationsChannel(ANNOTATIONS, context=context)
        self.camera = fc.RawImageChannel(IMAGE, context=context) if images else None
        self.metrics = _json_channel(METRICS, _SIMULATION_METRICS_SCHEMA, context)
        self.slices = fc.SceneUpdateChannel(SLICES, context=context) if sliced else None

    @property
    def static_topics(self) -> tuple[str, ...]:
        """The topics published once, at the start (:meth:`scene`)."""
        return (MEADOWS, LANDMARKS)

    def scene(self, ns: int, topics: Sequence[str] | None = None) -> None:
        """Publish the meadows and landmarks at log time ``ns`` (only ``topics`` when given)."""
        stamp, world = _stamp(ns), self._scenario.meadow_map
        if topics is None or MEADOWS in topics:
            self.meadows.log(_update(*meadow_entities(stamp, world)), log_time=ns)
        if topics is None or LANDMARKS in topics:
            drawn = landmark_entities(stamp, world, self._scenario.landmark_ids)
            self.landmarks.log(_update(*drawn), log_time=ns)

    def frame(self, record: FrameRecord, image: NDArray[np.uint8] | None, ns: int, run: int = 1) -> None:
        """Publish one frame at log time ``ns``: the maps, the truth, the image, the windows, the metrics."""
        stamp = _stamp(ns)
        after = record.map_after
        lost = record.state is ManagerState.LOST
        self.polygon.log(
            _update(polygon_entity("polygon", stamp, after, _LOST_COLOR if lost else _MAP_COLOR)), log_time=ns
        )
        self.grown.log(_update(polygon_entity("grown", stamp, record.map_before, _GROWN_COLOR)), log_time=ns)
        self.wedge.log(_update(wedge_entity(stamp, after)), log_time=ns)
        if self.slices is not None:
            self.slices.log(slices_entity(stamp, after), log_time=ns)
        self.center.log(_update(pose_entity("center", stamp, center_pose(after), _MAP_COLOR)), log_time=ns)
        self.truth.log(_update(pose_entity("truth", stamp, record.true_pose, _TRUTH_COLOR)), log_time=ns)
        if self.camera is not None and image is not None:
            self.camera.log(raw_image(stamp, image), log_time=ns)
        self.annotations.log(frame_annotations(stamp, record, *self._size), log_time=ns)
        self.metrics.log(simulation_metrics(record, run), log_time=ns)


class ReplayChannels:
    """The channels of a log replay on one SDK context, and how a step is published on them.

    Parameters
    ----------
    context : foxglove.Context
        The context whose sink receives the messages.
    log : RobotLogLike
        The log: its landmarks, when there is no ``world``.
    world : MeadowMap or None
        The replay's arena (:func:`aura_ums.logs.log_meadow_map`): ``/meadows``, and the
        landmarks drawn by class; None draws the log's landmarks.
    truth : bool
        Open ``/truth`` (the log has ground truth).
    sliced : bool
        Open ``/map/slices``.
    image_size : (int, int) or None
        ``(width, height)`` pixels of the camera the windows are for: opens
        ``/camera/image`` (a blank canvas of that size: logs carry no images) and
        ``/camera/annotations``; None for a replay without a camera.
    """

    def __init__(
        self,
        context: foxglove.Context,
        log: RobotLogLike,
        world: MeadowMap | None,
        *,
        truth: bool,
        sliced: bool,
        image_size: tuple[int, int] | None,
    ) -> None:
        self._log, self._world, self._size = log, world, image_size
        self.landmarks = fc.SceneUpdateChannel(LANDMARKS, context=context)
        self.meadows = None if world is None else fc.SceneUpdateChannel(MEADOWS, context=context)
        self.polygon = fc.SceneUpdateChannel(POLYGON, context=context)
        self.wedge = fc.SceneUpdateChannel(WEDGE, context=context)
        self.center = fc.SceneUpdateChannel(CENTER, context=context)
        self.truth = fc.SceneUpdateChannel(TRUTH, context=context) if truth else None
        self.metrics = _json_channel(METRICS, _REPLAY_METRICS_SCHEMA, context)
        self.slices = fc.SceneUpdateChannel(SLICES, context=context) if sliced else None
        self.camera = self.annotations = None
        self._canvas = b""
        if image_size is not None:
            self.camera = fc.RawImageChannel(IMAGE, context=context)
            self.annotations = fc.ImageAnnotationsChannel(ANNOTATIONS, context=context)
            self._canvas = bytes(image_size[0] * image_size[1])

    @property
    def static_topics(self) -> tuple[str, ...]:
        """The topics published once, at the start (:meth:`scene`)."""
        return (LANDMARKS,) if self.meadows is None else (LANDMARKS, MEADOWS)

    def scene(self, ns: int, topics: Sequence[str] | None = None) -> None:
        """Publish the landmarks (and the arena's meadows) at log time ``ns`` (only ``topics`` when given)."""
        stamp = _stamp(ns)
        if self.meadows is not None and self._world is not None and (topics is None or MEADOWS in topics):
            self.meadows.log(_update(*meadow_entities(stamp, self._world)), log_time=ns)
        if topics is None or LANDMARKS in topics:
            if self._world is None:
                drawn = log_landmark_entities(stamp, self._log.landmarks)
            else:
                drawn = landmark_entities(stamp, self._world, [r.id for r in self._world.landmarks])
            self.landmarks.log(_update(*drawn), log_time=ns)

    def step(self, index: int, step: ReplayStepLike, ns: int, windows: Sequence[WindowRow] = ()) -> None:
        """Publish step ``index`` at log time ``ns``: map, truth, windows (with a camera), metrics."""
        stamp = _stamp(ns)
        lost = step.state is ManagerState.LOST
        self.polygon.log(
            _update(polygon_entity("polygon", stamp, step.map, _LOST_COLOR if lost else _MAP_COLOR)),
            log_time=ns,
        )
        self.wedge.log(_update(wedge_entity(stamp, step.map)), log_time=ns)
        if self.slices is not None:
            self.slices.log(slices_entity(stamp, step.map), log_time=ns)
        self.center.log(_update(pose_entity("center", stamp, center_pose(step.map), _MAP_COLOR)), log_time=ns)
        if self.truth is not None:
            if step.truth is None:  # unknown here: remove the last arrow rather than leave it
                deletion = fm.SceneEntityDeletion(
                    timestamp=stamp, type=fm.SceneEntityDeletionType.MatchingId, id="truth"
                )
                self.truth.log(fm.SceneUpdate(deletions=[deletion]), log_time=ns)
            else:
                self.truth.log(_update(pose_entity("truth", stamp, step.truth, _TRUTH_COLOR)), log_time=ns)
        if self.camera is not None and self.annotations is not None and self._size is not None:
            width, height = self._size
            canvas = fm.RawImage(
                timestamp=stamp,
                frame_id=CAMERA_FRAME,
                width=width,
                height=height,
                encoding="mono8",
                step=width,
                data=self._canvas,
            )
            self.camera.log(canvas, log_time=ns)
            self.annotations.log(window_annotations(stamp, windows, width, height), log_time=ns)
        self.metrics.log(replay_metrics(index, step), log_time=ns)
