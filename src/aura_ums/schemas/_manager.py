"""The schema manager: instantiates find-landmark schemas and steps them frame by frame."""

from __future__ import annotations

import types
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from aura_ums._validate import items_of
from aura_ums.errors import InputError
from aura_ums.geometry import ImageWindow
from aura_ums.manager import IdentifiedLandmarkBuffer
from aura_ums.schemas._frame import Frame
from aura_ums.schemas._schema import FindLandmarkSchema
from aura_ums.schemas._state import SchemaReport, SchemaState, SchemaStatus
from aura_ums.uncertainty import Observation


@dataclass(frozen=True, slots=True)
class StepReport:
    """What the schema manager did with one frame.

    Parameters
    ----------
    time : float
        The frame's time, seconds.
    schemas : tuple of SchemaReport
        One report per instantiated schema, in instantiation order: state, window,
        evaluation value, hit and posted observation.
    posted : tuple of Observation
        The observations posted to the identified landmark buffer this frame.
    missed : tuple of str
        Ids of the landmarks predicted but not found (a window was searched, nothing matched).
    suspects : tuple of str
        Ids of the tracked landmarks that became suspect this frame.
    consecutive_missed : int
        Frames in a row, up to this one, in which landmarks were predicted and none was found.
    ambiguous : tuple of str
        Ids whose identification was withheld: it lay where another mapped landmark of the
        same kind may appear (see :meth:`SchemaManager.step`).

    Examples
    --------
    >>> window = ImageWindow(300, 100, 340, 260)
    >>> searched = SchemaReport("pole", SchemaStatus(SchemaState.DISCOVERING), window, 0.0, False, None, None)
    >>> step = StepReport(1.0, (searched,), (), ("pole",), (), 1)
    >>> step.predicted, step.found, step.report("pole").value
    (('pole',), (), 0.0)
    >>> step.report("lamppost")                          # no schema looks for it
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: landmark_id: expected one of pole, got 'lamppost'
    """

    time: float
    schemas: tuple[SchemaReport, ...]
    posted: tuple[Observation, ...]
    missed: tuple[str, ...]
    suspects: tuple[str, ...]
    consecutive_missed: int
    ambiguous: tuple[str, ...] = ()

    @property
    def predicted(self) -> tuple[str, ...]:
        """Ids of the landmarks for which a window was searched this frame."""
        return tuple(r.landmark_id for r in self.schemas if r.predicted)

    @property
    def found(self) -> tuple[str, ...]:
        """Ids of the landmarks that matched this frame (confirmed or still being discovered)."""
        return tuple(r.landmark_id for r in self.schemas if r.hit)

    def report(self, landmark_id: str) -> SchemaReport:
        """Return the report of the schema looking for ``landmark_id``.

        Raises
        ------
        InputError
            When no schema looks for that landmark.
        """
        for report in self.schemas:
            if report.landmark_id == landmark_id:
                return report
        known = ", ".join(r.landmark_id for r in self.schemas) or "none"
        raise InputError(f"landmark_id: expected one of {known}, got {landmark_id!r}")


@dataclass(frozen=True, slots=True)
class SchemaManagerState:
    """A schema manager's mutable state, for save and restore (:meth:`SchemaManager.export_state`).

    Parameters
    ----------
    statuses : tuple of (str, SchemaStatus)
        Each instantiation's status, in instantiation order.
    last_time : float or None
        Time of the last frame stepped.
    counters : tuple of int
        frames, predicted_total, missed_total, missed_frames, posted_total, consecutive_missed,
        ambiguous_total.

    Examples
    --------
    >>> SchemaManager().export_state()                  # no schema, no frame yet
    SchemaManagerState(statuses=(), last_time=None, counters=(0, 0, 0, 0, 0, 0, 0))
    >>> saved = SchemaManagerState((("pole", SchemaStatus()),), 1.0, (1, 1, 1, 1, 0, 1, 0))
    >>> SchemaManager().restore_state(saved)            # a manager without that schema
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: state: expected statuses for [], got ['pole']
    """

    statuses: tuple[tuple[str, SchemaStatus], ...]
    last_time: float | None
    counters: tuple[int, int, int, int, int, int, int]


class SchemaManager:
    """Holds the find-landmark schema instantiations of a leg and steps them on every frame.

    The paper's motor schema manager, for find-landmark schemas: it instantiates the
    schemas the pilot passes (:meth:`instantiate`), keeps each instantiation's
    :class:`SchemaStatus`, steps every schema on every frame (:meth:`step`), posts their
    identifications to the :class:`~aura_ums.manager.IdentifiedLandmarkBuffer` and counts
    the landmarks that were predicted but not found, for lost detection.

    The manager is mutable on purpose: it is the one owner of the instantiations' states
    and counters, which change with every frame; schemas, frames and reports are
    immutable values.

    Counting for lost detection: a landmark is *predicted* in a frame when its schema
    is awake and searched a window (not None) and *found* when the evaluation reached the
    threshold (a hit, confirmed or not yet). A frame in which some landmark was predicted
    and none found is a *missed frame*; :attr:`consecutive_missed` counts them in a row,
    back to 0 on any frame where a landmark is found; a frame without any prediction
    leaves it unchanged (it is no evidence either way).

    Parameters
    ----------
    schemas : iterable of FindLandmarkSchema
        Schemas to instantiate now (more may be added with :meth:`instantiate`).
    buffer : IdentifiedLandmarkBuffer or None
        Where identifications are posted; a new empty buffer when None.

    Raises
    ------
    InputError
        For a schema of the wrong type or two schemas for one landmark.

    Examples
    --------
    >>> import math
    >>> import numpy as np
    >>> from aura_ums.camera import Camera, CameraIntrinsics, CameraMount
    >>> from aura_ums.expecter import Expecter, PerceptualStrategy
    >>> from aura_ums.uncertainty import Pose, SpatialUncertaintyMap, VerticalLineLandmark
    >>> from aura_ums.world import LandmarkRecord
    >>> camera = Camera(CameraIntrinsics(500, 500, 320, 240, 640, 480), CameraMount(height=1.0))
    >>> pole = VerticalLineLandmark("pole", 10.0, 0.0, 0.0, 4.0, position_uncertainty=0.1)
    >>> record = LandmarkRecord(pole, PerceptualStrategy.LINE_FINDER, {"min_length": 30.0}, 20.0, 500.0, 2)
    >>> manager = SchemaManager([FindLandmarkSchema(record, Expecter(camera))])
    >>> snapshot = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.3, math.radians(2))
    >>> blank = np.full((480, 640), 60, dtype=np.uint8)
    >>> manager.step(Frame(0.0, blank, snapshot)).missed         # predicted, not found
    ('pole',)
    >>> seen = blank.copy()
    >>> seen[140:240, 318:323] = 200
    >>> [len(manager.step(Frame(t, seen, snapshot)).posted) for t in (0.1, 0.2, 0.3)]
    [0, 1, 1]
    >>> len(manager.buffer), manager.consecutive_missed, dict(manager.states)
    (2, 0, {'pole': <SchemaState.TRACKING: 'tracking'>})
    >>> manager.step(Frame(0.3, seen, snapshot))                # time must move on
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: frame.time: expected a time after the previous frame's 0.3, got 0.3
    """

    __slots__ = (
        "_ambiguous_total",
        "_buffer",
        "_consecutive_missed",
        "_frames",
        "_last_time",
        "_missed_frames",
        "_missed_total",
        "_posted_total",
        "_predicted_total",
        "_schemas",
        "_status",
    )

    def __init__(
        self, schemas: Iterable[FindLandmarkSchema] = (), *, buffer: IdentifiedLandmarkBuffer | None = None
    ) -> None:
        if buffer is None:
            buffer = IdentifiedLandmarkBuffer()
        elif not isinstance(buffer, IdentifiedLandmarkBuffer):
            raise InputError(
                f"buffer: expected an IdentifiedLandmarkBuffer or None, got {type(buffer).__name__}"
            )
        self._buffer = buffer
        self._schemas: list[FindLandmarkSchema] = []
        self._status: dict[str, SchemaStatus] = {}
        self._last_time: float | None = None
        self._frames = 0
        self._predicted_total = 0
        self._missed_total = 0
        self._missed_frames = 0
        self._posted_total = 0
        self._consecutive_missed = 0
        self._ambiguous_total = 0
        self.instantiate(schemas)

    def instantiate(self, schemas: Iterable[FindLandmarkSchema]) -> None:
        """Create instantiations of ``schemas``, each HIBERNATING until its first frame.

        Raises
        ------
        InputError
            For a schema of the wrong type, or for a landmark that already has one (the
            others of the call are then not instantiated either).
        """
        if isinstance(schemas, (FindLandmarkSchema, Mapping)):
            one = isinstance(schemas, FindLandmarkSchema)
            kind = "one FindLandmarkSchema" if one else type(schemas).__name__
            raise InputError(f"schemas: expected an iterable of FindLandmarkSchema, got {kind}")
        new = list(items_of(schemas, "schemas", "an iterable of FindLandmarkSchema"))
        seen = set(self._status)
        for position, schema in enumerate(new):
            if not isinstance(schema, FindLandmarkSchema):
                raise InputError(
                    f"schemas[{position}]: expected a FindLandmarkSchema, got {type(schema).__name__}"
                )
            if schema.landmark_id in seen:
                raise InputError(
                    f"schemas[{position}]: expected one schema per landmark, got {schema.landmark_id!r} again"
                )
            seen.add(schema.landmark_id)
        for schema in new:
            self._schemas.append(schema)
            self._status[schema.landmark_id] = SchemaStatus()

    @property
    def schemas(self) -> tuple[FindLandmarkSchema, ...]:
        """The instantiated schemas, in instantiation order."""
        return tuple(self._schemas)

    @property
    def buffer(self) -> IdentifiedLandmarkBuffer:
        """The identified landmark buffer the schemas post to."""
        return self._buffer

    @property
    def states(self) -> Mapping[str, SchemaState]:
        """Read-only mapping from landmark id to its schema's current state."""
        return types.MappingProxyType({k: v.state for k, v in self._status.items()})

    def status(self, landmark_id: str) -> SchemaStatus:
        """Return the current status of the schema looking for ``landmark_id``."""
        try:
            return self._status[landmark_id]
        except (KeyError, TypeError):
            known = ", ".join(self._status) or "none"
            raise InputError(f"landmark_id: expected one of {known}, got {landmark_id!r}") from None

    @property
    def consecutive_missed(self) -> int:
        """Frames in a row in which landmarks were predicted and none was found."""
        return self._consecutive_missed

    @property
    def frames(self) -> int:
        """Frames stepped so far."""
        return self._frames

    @property
    def missed_frames(self) -> int:
        """Frames so far in which landmarks were predicted and none was found."""
        return self._missed_frames

    @property
    def predicted_total(self) -> int:
        """Landmark predictions so far (one per schema per frame with a window)."""
        return self._predicted_total

    @property
    def missed_total(self) -> int:
        """Landmarks predicted but not found so far (one per schema per frame)."""
        return self._missed_total

    @property
    def posted_total(self) -> int:
        """Observations posted to the buffer so far."""
        return self._posted_total

    def step(self, frame: Frame) -> StepReport:
        """Step every schema on one frame; post identifications; update the lost-detection counts.

        An identification is withheld (listed in :attr:`StepReport.ambiguous`, not posted)
        when it lies inside the Expecter's bounds of another landmark of the same class and
        perceptual strategy: from some pose of the map that other landmark could appear
        there, and a wrong identification would prune the true pose away.

        Parameters
        ----------
        frame : Frame
            The next frame: its time must be later than the previous frame's.

        Returns
        -------
        StepReport

        Raises
        ------
        InputError
            For a frame of the wrong type or not later than the previous one, or an image
            whose size is not a schema camera's.
        """
        if not isinstance(frame, Frame):
            raise InputError(f"frame: expected a Frame, got {type(frame).__name__}")
        if self._last_time is not None and not frame.time > self._last_time:
            raise InputError(
                f"frame.time: expected a time after the previous frame's {self._last_time!r}, "
                f"got {frame.time!r}"
            )
        reports = tuple(schema.step(frame, self._status[schema.landmark_id]) for schema in self._schemas)
        ambiguous = self._ambiguous(frame, reports)
        posted: list[Observation] = []
        for report in reports:
            self._status[report.landmark_id] = report.status
            if report.observation is not None and report.landmark_id not in ambiguous:
                self._buffer.post(report.observation)
                posted.append(report.observation)
        self._last_time = frame.time
        predicted = [r for r in reports if r.predicted]
        missed = tuple(r.landmark_id for r in predicted if not r.hit)
        self._frames += 1
        self._predicted_total += len(predicted)
        self._missed_total += len(missed)
        self._posted_total += len(posted)
        if any(r.hit for r in reports):
            self._consecutive_missed = 0
        elif predicted:
            self._consecutive_missed += 1
            self._missed_frames += 1
        suspects = tuple(r.landmark_id for r in reports if r.state is SchemaState.SUSPECT)
        self._ambiguous_total += len(ambiguous)
        return StepReport(
            frame.time,
            reports,
            tuple(posted),
            missed,
            suspects,
            self._consecutive_missed,
            tuple(r.landmark_id for r in reports if r.landmark_id in ambiguous),
        )

    def _ambiguous(self, frame: Frame, reports: tuple[SchemaReport, ...]) -> set[str]:
        """Ids whose identification lies where another mapped landmark of the same kind may appear.

        The Expecter's bounds hold a landmark's projection from every pose of the map. A
        detection inside another landmark's bounds, by the same perceptual strategy and of
        the same class, may be that other landmark: no pose of the map tells them apart,
        and posting it could prune the true pose away. Such an identification is withheld
        (the schema keeps its state; nothing is posted this frame).
        """
        result: set[str] = set()
        # Awake schemas computed their bounds this frame; only hibernating ones did not.
        bounds: dict[str, ImageWindow | None] = {
            r.landmark_id: r.bounds for r in reports if r.state is not SchemaState.HIBERNATING
        }
        for report in reports:
            if report.observation is None or report.detection is None:
                continue
            schema = self._by_id(report.landmark_id)
            u, v = report.detection.point
            for other in self._schemas:
                if (
                    other is schema
                    or other.record.landmark_class is not schema.record.landmark_class
                    or other.record.strategy is not schema.record.strategy
                ):
                    continue
                if other.landmark_id not in bounds:
                    bounds[other.landmark_id] = other.expecter.bounds(frame.map, other.record.landmark)
                window = bounds[other.landmark_id]
                inside = window is not None and window.u_min <= u <= window.u_max
                if inside and window is not None and window.v_min <= v <= window.v_max:
                    result.add(report.landmark_id)
                    break
        return result

    @property
    def ambiguous_total(self) -> int:
        """Identifications withheld so far because another landmark of the same kind may be there."""
        return self._ambiguous_total

    def _by_id(self, landmark_id: str) -> FindLandmarkSchema:
        return next(schema for schema in self._schemas if schema.landmark_id == landmark_id)

    def export_state(self) -> SchemaManagerState:
        """Return the instantiations' statuses and the counters (immutable values), for saving."""
        return SchemaManagerState(
            tuple((schema.landmark_id, self._status[schema.landmark_id]) for schema in self._schemas),
            self._last_time,
            (
                self._frames,
                self._predicted_total,
                self._missed_total,
                self._missed_frames,
                self._posted_total,
                self._consecutive_missed,
                self._ambiguous_total,
            ),
        )

    def restore_state(self, state: SchemaManagerState) -> None:
        """Restore what :meth:`export_state` returned, onto a manager with the same schemas.

        Raises
        ------
        InputError
            When the state is not a SchemaManagerState or names other landmarks.
        """
        if not isinstance(state, SchemaManagerState):
            raise InputError(f"state: expected a SchemaManagerState, got {type(state).__name__}")
        ids = [ident for ident, _ in state.statuses]
        if ids != [schema.landmark_id for schema in self._schemas]:
            raise InputError(
                f"state: expected statuses for {[s.landmark_id for s in self._schemas]}, got {ids}"
            )
        self._status = dict(state.statuses)
        self._last_time = state.last_time
        (
            self._frames,
            self._predicted_total,
            self._missed_total,
            self._missed_frames,
            self._posted_total,
            self._consecutive_missed,
            self._ambiguous_total,
        ) = state.counters

    def __len__(self) -> int:
        return len(self._schemas)

    def __repr__(self) -> str:
        counts: dict[str, int] = {}
        for status in self._status.values():
            counts[status.state.value] = counts.get(status.state.value, 0) + 1
        summary = ", ".join(f"{n} {state}" for state, n in counts.items()) or "no schemas"
        return f"SchemaManager({summary}; {self._frames} frames)"
