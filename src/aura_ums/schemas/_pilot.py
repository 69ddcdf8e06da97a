"""The pilot's part in uncertainty management: find-landmark schemas for a leg."""

from __future__ import annotations

from dataclasses import dataclass, field

from aura_ums.camera import CalibrationBounds, Camera
from aura_ums.errors import InputError
from aura_ums.expecter import Expecter
from aura_ums.manager import IdentifiedLandmarkBuffer
from aura_ums.schemas._manager import SchemaManager
from aura_ums.schemas._schema import (
    DEFAULT_LOST_FRAMES,
    TRACKING_MARGIN,
    FindLandmarkSchema,
    check_tracking_settings,
)
from aura_ums.world import ShortTermMemory


@dataclass(frozen=True, slots=True)
class Pilot:
    """Parameterizes find-landmark schemas for a leg and hands them to the schema manager.

    "Before initiating motion, the pilot accesses the landmark lists from the
    instantiated meadows in STM ... parameterizes the find-landmark schemas with
    information available from the landmark data ... sets activation criteria": one
    :class:`FindLandmarkSchema` per candidate landmark of the short-term memory, its
    perceptual strategy parameterized from the landmark record (a line finder tuned to
    the record's orientation), its activation range, threshold and confirm count from
    the record.

    Parameters
    ----------
    camera : Camera
        The camera the schemas observe with.
    expecter : Expecter or None
        The Expecter process; None builds one for ``camera`` and ``bounds`` (its windows hold
        for every camera within them). Its camera must be ``camera``.
    lost_frames, tracking_margin, pixel_error, bounds
        Passed to every schema (see :class:`FindLandmarkSchema`).

    Raises
    ------
    InputError
        For arguments of the wrong type or out of range, or an Expecter with another camera.

    Examples
    --------
    >>> from aura_ums.camera import Camera, CameraIntrinsics, CameraMount
    >>> from aura_ums.world import ShortTermMemory, sample_world
    >>> camera = Camera(CameraIntrinsics(500, 500, 320, 240, 640, 480), CameraMount(1.2, tilt=0.1))
    >>> stm = ShortTermMemory.for_leg(sample_world("paper_sidewalk"), (0.0, 0.0), (12.192, 0.0))
    >>> manager = Pilot(camera).start_leg(stm)
    >>> [(s.landmark_id, type(s.detector).__name__) for s in manager.schemas][:3]
    [('telephone_pole_12', 'FastLineFinder'), ('lamppost_107', 'FastLineFinder'), \
('sidewalk_north_edge', 'FastLineFinder')]
    >>> set(manager.states.values())                          # waiting for the robot to move
    {<SchemaState.HIBERNATING: 'hibernating'>}
    >>> Pilot(camera).schemas_for_leg(ShortTermMemory.for_leg(sample_world("paper_sidewalk"),
    ...                                                      (100, 100), (101, 100), nearby=0.0))
    ()
    """

    camera: Camera
    expecter: Expecter | None = field(default=None, kw_only=True)
    lost_frames: int = field(default=DEFAULT_LOST_FRAMES, kw_only=True)
    tracking_margin: float = field(default=TRACKING_MARGIN, kw_only=True)
    pixel_error: float = field(default=0.5, kw_only=True)
    bounds: CalibrationBounds | None = field(default=None, kw_only=True)

    def __post_init__(self) -> None:
        if not isinstance(self.camera, Camera):
            raise InputError(f"camera: expected a Camera, got {type(self.camera).__name__}")
        margin, error = check_tracking_settings(
            self.lost_frames, self.tracking_margin, self.pixel_error, self.bounds
        )
        object.__setattr__(self, "tracking_margin", margin)
        object.__setattr__(self, "pixel_error", error)
        if self.expecter is None:
            # Its windows hold for every camera within the bounds its observations allow for.
            object.__setattr__(self, "expecter", Expecter(self.camera, self.bounds))
        elif not isinstance(self.expecter, Expecter):
            raise InputError(f"expecter: expected an Expecter or None, got {type(self.expecter).__name__}")
        elif self.expecter.camera != self.camera:
            raise InputError(
                f"expecter: expected an Expecter for the pilot's camera, got one for {self.expecter.camera!r}"
            )

    def schemas_for_leg(self, stm: ShortTermMemory) -> tuple[FindLandmarkSchema, ...]:
        """Return one slot-filled find-landmark schema per candidate landmark of ``stm``, in its order.

        Raises
        ------
        InputError
            When ``stm`` is not a ShortTermMemory, or a landmark's strategy or parameters
            have no schema (naming the landmark).
        """
        if not isinstance(stm, ShortTermMemory):
            raise InputError(f"stm: expected a ShortTermMemory, got {type(stm).__name__}")
        expecter = self.expecter
        if expecter is None:  # pragma: no cover - set in __post_init__
            raise InputError("expecter: expected an Expecter, got None")
        return tuple(
            FindLandmarkSchema(
                record,
                expecter,
                lost_frames=self.lost_frames,
                tracking_margin=self.tracking_margin,
                pixel_error=self.pixel_error,
                bounds=self.bounds,
            )
            for record in stm.landmarks
        )

    def start_leg(
        self, stm: ShortTermMemory, *, buffer: IdentifiedLandmarkBuffer | None = None
    ) -> SchemaManager:
        """Parameterize the leg's schemas and pass them to a new :class:`SchemaManager`.

        Parameters
        ----------
        stm : ShortTermMemory
            The meadows and candidate landmarks of the leg.
        buffer : IdentifiedLandmarkBuffer or None
            Where the manager posts identifications (a new buffer when None).
        """
        return SchemaManager(self.schemas_for_leg(stm), buffer=buffer)
