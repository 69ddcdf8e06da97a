"""The closed loop, frame by frame: pilot -> schemas -> Expecter -> perception -> buffer -> manager.

Each frame of :func:`run_scenario`:

1. the true robot executes its command (the next leg of the route, or, while the map
   manager says the robot is lost, a turn in place to look around) and the command is
   posted to the blackboard as a time-stamped :class:`~aura_ums.manager.PositionReport`;
2. the synthetic camera renders the image from the true pose;
3. the manager grows the map to the frame's time; the pilot's find-landmark schemas step
   on the image with that map snapshot (the Expecter's windows, widened by the manager's
   ``window_scale`` while lost; the whole image in :attr:`PerceptionMode.FULL_FRAME`),
   posting their identifications to the identified landmark buffer;
4. the manager reduces the map by them (``prune=False``: they are dropped; growth only),
   with the scenario's :class:`~aura_ums.manager.ManagerSettings`: with ``robust``, it
   keeps an envelope map (the identifications' bounds widened by ``envelope_factor``) and
   re-localizes from it when an identification is inconsistent with the map, as in
   replay and live use.

Consistency of the synthetic world with the map (:func:`check_render_consistency`): the
camera renders Class I poles with a radius and Class III strips with a width, and the
line finder finds their *edges*, not their axes; a bearing from an edge is off the mapped
axis by up to the radius. The reductions stay sound only when every used landmark's
``position_uncertainty`` is at least the rendered pole radius (Class I poles; a Class I
edge at a building's corner has none) or half the strip width (Class III).
"""

from __future__ import annotations

import bisect
import dataclasses
import math
import statistics
import time as _time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from aura_ums._metrics import Metrics
from aura_ums._validate import Choice, check_rng, sequence_of
from aura_ums.errors import InputError
from aura_ums.expecter import ImageWindow
from aura_ums.geometry import wrap_angle
from aura_ums.manager import Blackboard, ManagerState, PositionReport, RejectReason, UncertaintyMapManager
from aura_ums.schemas import Frame, Pilot, SchemaManager, SchemaManagerState, StepReport
from aura_ums.sim._scenario import Scenario, waypoints_array
from aura_ums.sim._scene import CORNER_MATCH_DISTANCE
from aura_ums.uncertainty import (
    BearingObservation,
    GroundLineLandmark,
    GroundLineObservation,
    Observation,
    PointLandmark,
    Pose,
    RangeBearingObservation,
    SpatialUncertaintyMap,
    TurnAndRun,
    VerticalLineLandmark,
)
from aura_ums.world import MeadowMap, ShortTermMemory

#: Seconds between frames (the loop's clock).
_FRAME_PERIOD = 1.0
#: Radians of each look-around turn while lost (the turns go +a, -2a, +a: back to the start).
_LOOK_TURN = math.radians(15.0)
#: Frames in a row spent looking around while lost before the run gives up.
_MAX_LOOK_FRAMES = 12
_LOOK_PATTERN = (1.0, -2.0, 1.0)
#: Radians by which a wrong identification's bearing turns when no other landmark of its class exists.
_WRONG_TURN = 3.0


class PerceptionMode(Choice):
    """Where perception runs: in the Expecter's windows, or on the whole image (the baseline).

    Examples
    --------
    >>> [mode.value for mode in PerceptionMode]
    ['windows', 'full_frame', 'focus_first']
    >>> PerceptionMode("full_frame")
    <PerceptionMode.FULL_FRAME: 'full_frame'>
    >>> PerceptionMode("everywhere")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: PerceptionMode: expected one of ..., got 'everywhere'
    """

    #: In the Expecter's windows from the map (the guaranteed ones).
    WINDOWS = "windows"
    #: On the whole image, tracking included: the baseline.
    FULL_FRAME = "full_frame"
    #: A discovering schema searches the focus map's window first
    #: (:attr:`~aura_ums.manager.UncertaintyMapManager.focus_map`, narrower with the relaxed
    #: intersection), the guaranteed window where the landmark is not found there. A
    #: look-alike outside the focus window is then not seen to rival a match inside it: a
    #: wrong match this makes is one of the wrong sightings the relaxed intersection bounds.
    FOCUS_FIRST = "focus_first"


@dataclass(frozen=True, slots=True)
class FrameRecord:
    """What happened in one frame of the closed loop.

    Parameters
    ----------
    index : int
        0 for the start frame, then 1, 2, ...
    time : float
        Seconds.
    command : TurnAndRun or None
        The command executed before the frame (None for the start frame).
    moved : bool
        False when the robot stood still and turned to look around (lost).
    true_pose : Pose
        The true pose at the frame.
    inside : bool
        Whether the true pose is inside the map after the frame.
    map_before, map_after : SpatialUncertaintyMap
        The map grown to the frame's time (the snapshot the schemas used), and after reductions.
    windows : tuple of (str, ImageWindow)
        The windows searched, per landmark id.
    found : tuple of str
        Ids of the landmarks that matched.
    posted : tuple of str
        Ids of the identifications posted to the buffer.
    accepted : int
        Observations that reduced the map.
    rejected : tuple of RejectReason
        Reasons of the rejected observations.
    state : ManagerState
        The manager's state after the frame.
    frame_ms : float
        Milliseconds of the loop (schemas, perception and manager; not the rendering).
    detections : tuple of (str, (float, float, float, float))
        Per found landmark id (in :attr:`found` order), the image-space detection the
        perception matched, ``(u1, v1, u2, v2)`` full-image pixels: a line finder's segment
        (Class I and III); a point as ``(u, v, u, v)`` (a Class II interest point, or the
        centroid of a Class I region, the point its observation uses). Empty by default.
    injected : int
        Identifications of the frame made wrong (the scenario's ``inject_wrong_rate``).
    excluded : int
        Observations the manager's relaxed intersection excluded in the frame.
    ambiguous : int
        Landmarks found in the frame but not posted: each lay where another mapped landmark
        of the same kind may appear (:attr:`~aura_ums.schemas.StepReport.ambiguous`).

    Examples
    --------
    >>> grown = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.3, 0.05)
    >>> pruned = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.2, 0.02)
    >>> searched = (("pole", ImageWindow(300, 100, 340, 260)),)
    >>> record = FrameRecord(
    ...     0, 0.0, None, True, Pose(0.1, 0, 0), True, grown, pruned,
    ...     searched, ("pole",), ("pole",), 1, (), ManagerState.NOMINAL, 4.2,
    ... )
    >>> round(record.area_before, 3), round(record.area, 3), record.wedge_width_before, record.wedge_width
    (0.286, 0.127, 0.1, 0.04)
    >>> start = FrameRecord(0, 0.0, None, True, Pose(0, 0, 0), True, grown, grown, (), (), (), 0, (),
    ...                     ManagerState.NOMINAL, 0.8)
    >>> start.area == start.area_before, start.detections       # nothing searched, nothing found
    (True, ())
    """

    index: int
    time: float
    command: TurnAndRun | None
    moved: bool
    true_pose: Pose
    inside: bool
    map_before: SpatialUncertaintyMap
    map_after: SpatialUncertaintyMap
    windows: tuple[tuple[str, ImageWindow], ...]
    found: tuple[str, ...]
    posted: tuple[str, ...]
    accepted: int
    rejected: tuple[RejectReason, ...]
    state: ManagerState
    frame_ms: float
    detections: tuple[tuple[str, tuple[float, float, float, float]], ...] = ()
    injected: int = 0
    excluded: int = 0
    ambiguous: int = 0

    @property
    def area_before(self) -> float:
        """Area of the map before the frame's reductions, m^2."""
        return self.map_before.area

    @property
    def area(self) -> float:
        """Area of the map after the frame, m^2."""
        return self.map_after.area

    @property
    def wedge_width_before(self) -> float:
        """Width of the heading wedge before the frame's reductions, radians."""
        return self.map_before.wedge.width

    @property
    def wedge_width(self) -> float:
        """Width of the heading wedge after the frame, radians."""
        return self.map_after.wedge.width


@dataclass(frozen=True, slots=True)
class LoopState:
    """Everything needed to resume a run (:func:`run_scenario` ``stop_after`` / ``resume_from``).

    The manager and blackboard are their exact JSON (:meth:`UncertaintyMapManager.to_json`,
    :meth:`Blackboard.to_json`); the schema manager's statuses and counters are immutable
    values; the random generators are their ``bit_generator.state``.

    Examples
    --------
    >>> import pathlib
    >>> scenario = Scenario.from_toml(pathlib.Path("scenarios/paper_sidewalk.toml"))
    >>> state = run_scenario(scenario, np.random.default_rng(1), stop_after=1).saved   # one frame only
    >>> state.scenario, state.next_index, state.perception, len(state.records)
    ('paper_sidewalk', 1, <PerceptionMode.WINDOWS: 'windows'>, 1)
    >>> run_scenario(scenario, np.random.default_rng(1), resume_from="frame 1")
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: resume_from: expected a LoopState, got str
    """

    scenario: str
    prune: bool
    perception: PerceptionMode
    next_index: int
    leg: int
    instantiated: int
    look_frames: int
    true_pose: Pose
    manager_json: str
    blackboard_json: str
    schemas: SchemaManagerState
    motion_rng: dict[str, Any]
    camera_rng: dict[str, Any]
    scene_rng: dict[str, Any]
    records: tuple[FrameRecord, ...]


@dataclass(frozen=True, slots=True, eq=False)
class RunResult:
    """The outcome of :func:`run_scenario`: per-frame records and aggregates.

    Parameters
    ----------
    scenario : str
        The scenario's name.
    records : tuple of FrameRecord
        Every frame, in order (those before a resume included).
    final_map : SpatialUncertaintyMap
        The map after the last frame.
    completed : bool
        Whether the route was driven to its end (False when stopped early or given up lost).
    saved : LoopState or None
        The state to resume from, when stopped by ``stop_after``.
    predictions, hits : int
        Landmark windows searched, and matches in them, over the run.
    images : tuple of ndarray
        The images of the frames, when asked for (``keep_images``); else empty.

    Examples
    --------
    >>> grown = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.3, 0.05)
    >>> frame = FrameRecord(0, 0.0, None, True, Pose(0, 0, 0), True, grown, grown, (), (), (), 0, (),
    ...                     ManagerState.NOMINAL, 0.8)
    >>> result = RunResult("demo", (frame,), grown, True, None, 0, 0)
    >>> result.containment_rate, result.ever_lost, round(result.median_area, 3)
    (1.0, False, 0.286)
    >>> result.detection_rate                         # no window searched: undefined
    nan
    >>> empty = RunResult("none", (), grown, False, None, 0, 0)   # no frame: every rate undefined
    >>> empty.containment_rate, empty.median_area
    (nan, nan)
    """

    scenario: str
    records: tuple[FrameRecord, ...]
    final_map: SpatialUncertaintyMap
    completed: bool
    saved: LoopState | None
    predictions: int
    hits: int
    images: tuple[NDArray[np.uint8], ...] = field(default=(), repr=False)

    @property
    def containment_rate(self) -> float:
        """Fraction of frames whose true pose is inside the map after the frame (nan without frames)."""
        return sum(r.inside for r in self.records) / len(self.records) if self.records else math.nan

    @property
    def detection_rate(self) -> float:
        """Matches per searched window (nan when nothing was predicted)."""
        return self.hits / self.predictions if self.predictions else math.nan

    @property
    def median_area(self) -> float:
        """Median map area after each frame, m^2 (nan without frames)."""
        return statistics.median(r.area for r in self.records) if self.records else math.nan

    @property
    def median_wedge_width(self) -> float:
        """Median wedge width after each frame, radians (nan without frames)."""
        return statistics.median(r.wedge_width for r in self.records) if self.records else math.nan

    @property
    def median_frame_ms(self) -> float:
        """Median milliseconds per frame of the loop (nan without frames)."""
        return statistics.median(r.frame_ms for r in self.records) if self.records else math.nan

    @property
    def rejected(self) -> int:
        """Observations rejected by the manager (inconsistent or otherwise) over the run."""
        return sum(len(r.rejected) for r in self.records)

    @property
    def accepted(self) -> int:
        """Observations that reduced the map over the run."""
        return sum(r.accepted for r in self.records)

    @property
    def lost_frames(self) -> int:
        """Frames after which the manager's state was LOST."""
        return sum(r.state is ManagerState.LOST for r in self.records)

    @property
    def ever_lost(self) -> bool:
        """Whether the robot declared itself lost at some frame."""
        return self.lost_frames > 0


def check_render_consistency(scenario: Scenario, world: MeadowMap | None = None) -> None:
    """Check that the rendered landmarks are within the map's position uncertainty.

    Rule: a used Class I landmark drawn as a pole needs ``position_uncertainty >=
    render.pole_radius``; a used Class III landmark needs ``position_uncertainty >=
    render.stripe_width / 2`` (the line finder finds edges, not axes).

    Raises
    ------
    InputError
        Naming the landmark and both numbers.

    Examples
    --------
    >>> import dataclasses, pathlib
    >>> scenario = Scenario.from_toml(pathlib.Path("scenarios/paper_sidewalk.toml"))
    >>> check_render_consistency(scenario)
    >>> thick = dataclasses.replace(scenario, render=dataclasses.replace(scenario.render, pole_radius=0.5))
    >>> check_render_consistency(thick)           # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: scenarios/paper_sidewalk.toml: [render] pole_radius: telephone_pole_12: \
expected position_uncertainty >= the rendered pole radius 0.5 m, got 0.15
    """
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario: expected a Scenario, got {type(scenario).__name__}")
    if world is not None and not isinstance(world, MeadowMap):
        raise InputError(f"world: expected a MeadowMap or None, got {type(world).__name__}")
    drawn = scenario.meadow_map if world is None else world
    corners = [r.landmark for r in drawn.landmarks if isinstance(r.landmark, PointLandmark)]
    radius, half = scenario.render.pole_radius, scenario.render.stripe_width / 2.0
    for record in scenario.landmarks:
        landmark = record.landmark
        if isinstance(landmark, VerticalLineLandmark):
            edge = any(
                math.hypot(c.x - landmark.x, c.y - landmark.y) <= CORNER_MATCH_DISTANCE for c in corners
            )
            if not edge and landmark.position_uncertainty < radius:
                raise InputError(
                    f"{_render_key(scenario, 'pole_radius')}{record.id}: expected position_uncertainty "
                    f">= the rendered pole radius {radius:g} m, got {landmark.position_uncertainty:g}"
                )
        elif isinstance(landmark, GroundLineLandmark) and landmark.position_uncertainty < half:
            raise InputError(
                f"{_render_key(scenario, 'stripe_width')}{record.id}: expected position_uncertainty "
                f">= half the rendered strip width {half:g} m, got {landmark.position_uncertainty:g}"
            )


def _render_key(scenario: Scenario, key: str) -> str:
    """Return the scenario file and render setting at fault, as a message's prefix ("" when built in code).

    The check runs when a run starts (with the world drawn), long after the file was read:
    the message names the file and the setting, as the reader's would.
    """
    return f"{scenario.source}: [render] {key}: " if scenario.source else ""


def _generator(state: dict[str, Any]) -> np.random.Generator:
    bit_generator = getattr(np.random, str(state["bit_generator"]))()
    bit_generator.state = state
    return np.random.Generator(bit_generator)


def _route_indices(scenario: Scenario, legs: tuple[TurnAndRun, ...]) -> list[int]:
    """Index of the route command each leg belongs to."""
    ends: list[float] = []
    total = 0.0
    for command in scenario.commands:
        total += command.run
        ends.append(total)
    indices: list[int] = []
    travelled = 0.0
    for leg in legs:
        travelled += leg.run
        tolerance = 1e-9 * max(1.0, travelled)
        index = bisect.bisect_left(ends, travelled - tolerance)
        indices.append(min(index, len(ends) - 1))
    return indices


class _Loop:
    """The running loop: the robot, camera, pilot, schema manager, blackboard and map manager."""

    def __init__(
        self,
        scenario: Scenario,
        rng: np.random.Generator,
        *,
        prune: bool,
        perception: PerceptionMode,
        world: MeadowMap | None,
        resume_from: LoopState | None,
    ) -> None:
        self.scenario = scenario
        self.prune = prune
        self.perception = perception
        self.legs = scenario.legs()
        self.route_of_leg = _route_indices(scenario, self.legs)
        self.waypoints = waypoints_array(scenario)
        self.used = set(scenario.landmark_ids)
        self.pilot = Pilot(scenario.camera)
        drawn = scenario if world is None else _with_map(scenario, world)
        s = scenario
        if resume_from is None:
            start_rng, motion_rng, camera_rng = rng.spawn(3)
            self.scene_state = camera_rng.bit_generator.state
            true_start = s.sample_true_start(start_rng)
            self.robot = s.robot(true_start, motion_rng)
            self.motion_rng = motion_rng
            self.camera = drawn.synthetic_camera(camera_rng)
            self.camera_rng = camera_rng
            self.manager = UncertaintyMapManager(s.initial_map(), s.meadow_map, s.terrain, s.settings)
            self.board = Blackboard()
            self.schemas = SchemaManager(buffer=self.board.identified)
            self.instantiated = 0
            self.next_index, self.leg, self.look_frames = 0, 0, 0
            self.records: list[FrameRecord] = []
            self._instantiate_through(self.route_of_leg[0] if self.legs else 0)
        else:
            if resume_from.scenario != s.name:
                raise InputError(f"resume_from: expected a state of {s.name!r}, got {resume_from.scenario!r}")
            self.scene_state = resume_from.scene_rng
            self.camera_rng = _generator(resume_from.scene_rng)
            self.camera = drawn.synthetic_camera(self.camera_rng)
            self.camera_rng.bit_generator.state = resume_from.camera_rng
            self.motion_rng = _generator(resume_from.motion_rng)
            self.robot = s.robot(resume_from.true_pose, self.motion_rng)
            self.manager = UncertaintyMapManager.from_json(resume_from.manager_json, s.meadow_map, s.terrain)
            self.board = Blackboard.from_json(resume_from.blackboard_json)
            self.schemas = SchemaManager(buffer=self.board.identified)
            self.instantiated = 0
            self._instantiate_through(resume_from.instantiated - 1)
            self.schemas.restore_state(resume_from.schemas)
            self.next_index, self.leg = resume_from.next_index, resume_from.leg
            self.look_frames = resume_from.look_frames
            self.records = list(resume_from.records)
        self.predictions = sum(len(r.windows) for r in self.records)
        self.hits = sum(len(r.found) for r in self.records)

    def _instantiate_through(self, route_index: int) -> None:
        if not self.scenario.commands:
            return
        while self.instantiated <= min(route_index, len(self.scenario.commands) - 1):
            j = self.instantiated
            stm = ShortTermMemory.for_leg(self.scenario.meadow_map, self.waypoints[j], self.waypoints[j + 1])
            have = set(self.schemas.states)
            new = [
                schema
                for schema in self.pilot.schemas_for_leg(stm)
                if schema.landmark_id in self.used and schema.landmark_id not in have
            ]
            self.schemas.instantiate(new)
            self.instantiated += 1

    @property
    def done(self) -> bool:
        return self.next_index > 0 and (self.leg >= len(self.legs) or self.look_frames >= _MAX_LOOK_FRAMES)

    def step(self, keep: list[NDArray[np.uint8]] | None) -> NDArray[np.uint8]:
        """Run one frame, record it, and return its image."""
        index = self.next_index
        now = index * _FRAME_PERIOD
        command: TurnAndRun | None = None
        moved = True
        looking = self.prune and self.manager.should_stop_and_look
        if index > 0:
            if looking:
                command = TurnAndRun(_LOOK_TURN * _LOOK_PATTERN[self.look_frames % len(_LOOK_PATTERN)], 0.0)
                self.look_frames += 1
                moved = False
            else:
                command = self.legs[self.leg]
                self._instantiate_through(self.route_of_leg[self.leg])
                self.leg += 1
                self.look_frames = 0
            self.robot.execute(command)
            self.board.post_report(PositionReport(now, command))
        true_pose = self.robot.pose
        image = self.camera.render(true_pose)
        image.setflags(write=False)
        if keep is not None:
            keep.append(image)
        started = _time.perf_counter()
        grown = self.manager.update(self.board, now=now, missed_in_a_row=self.schemas.consecutive_missed)
        if self.perception is PerceptionMode.FULL_FRAME:
            scale = math.inf
        else:
            scale = self.manager.window_scale if self.prune else 1.0
        focus = grown.focus if self.perception is PerceptionMode.FOCUS_FIRST else None
        report = self.schemas.step(Frame(now, image, grown.map, window_scale=scale, focus=focus))
        injected = 0
        if not self.prune:
            self.board.identified.drain(until=now)
        elif self.scenario.inject_wrong_rate > 0.0:
            injected = self._inject(now)
        after = self.manager.update(self.board, now=now, missed_in_a_row=report.consecutive_missed)
        elapsed = 1000.0 * (_time.perf_counter() - started)
        windows = tuple((r.landmark_id, r.window) for r in report.schemas if r.window is not None)
        self.predictions += len(windows)
        self.hits += len(report.found)
        self.records.append(
            FrameRecord(
                index=index,
                time=now,
                command=command,
                moved=moved,
                true_pose=true_pose,
                inside=after.map.contains(true_pose),
                map_before=grown.map,
                map_after=after.map,
                windows=windows,
                found=report.found,
                posted=tuple(o.landmark_id for o in report.posted),
                accepted=len(after.accepted),
                rejected=tuple(o.reason for o in after.rejected if o.reason is not None),
                state=after.state,
                frame_ms=elapsed,
                detections=_detections(report),
                injected=injected,
                excluded=len(grown.excluded) + len(after.excluded),
                ambiguous=len(report.ambiguous),
            )
        )
        self.next_index += 1
        return image

    def _inject(self, now: float) -> int:
        """Make each identification up to ``now`` wrong with the scenario's rate; return how many.

        Draws from the camera's generator only when the rate is positive, so runs without
        injection are the runs they always were.
        """
        buffer = self.board.identified
        rng = self.camera_rng
        made = 0
        for observation in buffer.drain(until=now):
            if rng.random() < self.scenario.inject_wrong_rate:
                observation = _wrong(observation, self.scenario.meadow_map, rng)
                made += 1
            buffer.post(observation)
        return made

    def save(self) -> LoopState:
        return LoopState(
            scenario=self.scenario.name,
            prune=self.prune,
            perception=self.perception,
            next_index=self.next_index,
            leg=self.leg,
            instantiated=self.instantiated,
            look_frames=self.look_frames,
            true_pose=self.robot.pose,
            manager_json=self.manager.to_json(),
            blackboard_json=self.board.to_json(),
            schemas=self.schemas.export_state(),
            motion_rng=dict(self.motion_rng.bit_generator.state),
            camera_rng=dict(self.camera_rng.bit_generator.state),
            scene_rng=dict(self.scene_state),
            records=tuple(self.records),
        )


def _detections(report: StepReport) -> tuple[tuple[str, tuple[float, float, float, float]], ...]:
    """Per found landmark, its matched segment, or its point as a zero-length one (FrameRecord)."""
    found: list[tuple[str, tuple[float, float, float, float]]] = []
    for schema in report.schemas:
        detection = schema.detection
        if not schema.hit or detection is None:
            continue
        if detection.segment is not None:
            u1, v1, u2, v2 = (float(c) for c in detection.segment)
            found.append((schema.landmark_id, (u1, v1, u2, v2)))
        else:
            u, v = float(detection.point[0]), float(detection.point[1])
            found.append((schema.landmark_id, (u, v, u, v)))
    return tuple(found)


def _wrong(observation: Observation, world: MeadowMap, rng: np.random.Generator) -> Observation:
    """Return a misidentification: another landmark of the class, else the bearing (angle) turned 3 rad."""
    others = [
        record.id
        for record in world.landmarks
        if record.landmark.landmark_class is observation.landmark_class
        and record.id != observation.landmark_id
    ]
    if others:
        return dataclasses.replace(observation, landmark_id=others[int(rng.integers(len(others)))])
    if isinstance(observation, GroundLineObservation):
        return dataclasses.replace(observation, angle=wrap_angle(observation.angle + _WRONG_TURN))
    if isinstance(observation, (BearingObservation, RangeBearingObservation)):
        return dataclasses.replace(observation, bearing=wrap_angle(observation.bearing + _WRONG_TURN))
    raise InputError(f"observation: expected an observation of Class I, II or III, got {observation!r}")


def _with_map(scenario: Scenario, world: MeadowMap) -> Scenario:
    return dataclasses.replace(scenario, meadow_map=world, landmark_ids=())


def run_scenario(
    scenario: Scenario,
    rng: np.random.Generator,
    *,
    prune: bool = True,
    perception: PerceptionMode = PerceptionMode.WINDOWS,
    stop_after: int | None = None,
    resume_from: LoopState | None = None,
    world: MeadowMap | None = None,
    keep_images: bool = False,
    after_frame: Callable[[FrameRecord, NDArray[np.uint8]], None] | None = None,
) -> RunResult:
    """Drive a scenario's route through the closed loop, frame by frame (see the module notes).

    Parameters
    ----------
    scenario : Scenario
        The scenario: its meadow map is the robot's long-term memory.
    rng : numpy.random.Generator
        Source of every random draw (split into the start's, the robot's and the camera's);
        unused when resuming.
    prune : bool
        Reduce the map by the identified landmarks (False: growth only, no lost response).
    perception : PerceptionMode
        Run perception in the Expecter's windows, on the full frame (the baseline), or in
        the focus map's windows first (the guaranteed ones where the landmark is not there).
    stop_after : int or None
        Stop after this many frames in all (the start frame included) and return the
        state to resume from in :attr:`RunResult.saved`.
    resume_from : LoopState or None
        Continue a run stopped by ``stop_after``.
    world : MeadowMap or None
        The world the camera sees, when it differs from the map (moved landmarks).
    keep_images : bool
        Keep the frames' images in :attr:`RunResult.images` (frames of this call only).
    after_frame : callable or None
        Called after each frame of this call, in order, as ``after_frame(record, image)``:
        the frame's :class:`FrameRecord` and its grayscale image (read-only), to watch a
        run while it computes (the live view). Its time is not counted in ``frame_ms``.

    Returns
    -------
    RunResult

    Raises
    ------
    InputError
        For bad arguments, or a scenario whose rendering breaks the consistency rule
        (:func:`check_render_consistency`).

    Examples
    --------
    >>> import pathlib
    >>> scenario = Scenario.from_toml(pathlib.Path("scenarios/paper_sidewalk.toml"))
    >>> result = run_scenario(scenario, np.random.default_rng(1))
    >>> len(result.records), result.completed, result.containment_rate
    (4, True, 1.0)
    >>> half = run_scenario(scenario, np.random.default_rng(1), stop_after=2)
    >>> rest = run_scenario(scenario, np.random.default_rng(99), resume_from=half.saved)
    >>> rest.final_map.polygon.vertices.tobytes() == result.final_map.polygon.vertices.tobytes()
    True
    """
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario: expected a Scenario, got {type(scenario).__name__}")
    check_rng(rng)
    if not isinstance(perception, PerceptionMode):
        raise InputError(f"perception: expected a PerceptionMode, got {perception!r}")
    if stop_after is not None and (
        isinstance(stop_after, bool) or not isinstance(stop_after, int) or stop_after < 1
    ):
        raise InputError(f"stop_after: expected an integer >= 1 or None, got {stop_after!r}")
    if after_frame is not None and not callable(after_frame):
        raise InputError(f"after_frame: expected a callable or None, got {type(after_frame).__name__}")
    if resume_from is not None:
        if not isinstance(resume_from, LoopState):
            raise InputError(f"resume_from: expected a LoopState, got {type(resume_from).__name__}")
        prune, perception = resume_from.prune, resume_from.perception
    check_render_consistency(scenario, world)
    loop = _Loop(scenario, rng, prune=prune, perception=perception, world=world, resume_from=resume_from)
    images: list[NDArray[np.uint8]] | None = [] if keep_images else None
    while not loop.done:
        if stop_after is not None and loop.next_index >= stop_after:
            return RunResult(
                scenario.name,
                tuple(loop.records),
                loop.manager.map,
                False,
                loop.save(),
                loop.predictions,
                loop.hits,
                tuple(images or ()),
            )
        image = loop.step(images)
        if after_frame is not None:
            after_frame(loop.records[-1], image)
    completed = loop.leg >= len(loop.legs)
    return RunResult(
        scenario.name,
        tuple(loop.records),
        loop.manager.map,
        completed,
        None,
        loop.predictions,
        loop.hits,
        tuple(images or ()),
    )


def summarize_runs(results: list[RunResult] | tuple[RunResult, ...]) -> Metrics:
    """Return the Monte Carlo metrics of several runs, over all their frames.

    Keys (units and meanings: ``docs/metrics.md``): ``containment_rate`` (fraction of
    frames with the true pose inside the map), ``median_area_m2``,
    ``median_wedge_width_rad``, ``landmark_detection_rate`` (matches per searched window;
    None when no window was searched), ``inconsistent_observations`` (observations the
    manager rejected), ``accepted_observations``, ``median_frame_ms``, ``frames``,
    ``runs_lost`` (runs that declared themselves lost), ``runs_completed``,
    ``injected_observations`` (identifications made wrong), ``excluded_observations``
    (observations the relaxed intersection excluded), ``ambiguous_identifications``
    (landmarks found but withheld: another mapped landmark may appear where each was found).

    Examples
    --------
    >>> import pathlib
    >>> scenario = Scenario.from_toml(pathlib.Path("scenarios/paper_sidewalk.toml"))
    >>> metrics = summarize_runs([run_scenario(scenario, np.random.default_rng(s)) for s in (1, 2)])
    >>> metrics["frames"], metrics["containment_rate"]
    (8, 1.0)
    """
    results = sequence_of(results, RunResult, "results")
    records = [r for result in results for r in result.records]
    if not records:
        raise InputError("results: expected at least one run with frames, got none")
    predictions = sum(result.predictions for result in results)
    hits = sum(result.hits for result in results)
    return Metrics(
        {
            "containment_rate": sum(r.inside for r in records) / len(records),
            "median_area_m2": statistics.median(r.area for r in records),
            "median_wedge_width_rad": statistics.median(r.wedge_width for r in records),
            "landmark_detection_rate": hits / predictions if predictions else math.nan,
            "inconsistent_observations": sum(len(r.rejected) for r in records),
            "accepted_observations": sum(r.accepted for r in records),
            "median_frame_ms": statistics.median(r.frame_ms for r in records),
            "frames": len(records),
            "runs_lost": sum(result.ever_lost for result in results),
            "runs_completed": sum(result.completed for result in results),
            "injected_observations": sum(r.injected for r in records),
            "excluded_observations": sum(r.excluded for r in records),
            "ambiguous_identifications": sum(r.ambiguous for r in records),
        }
    )
