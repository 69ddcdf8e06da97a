"""The find-landmark schema: one landmark's perceptual strategy, evaluation and life cycle."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from aura_ums._validate import integer_at_least, nonnegative_float
from aura_ums.camera import CalibrationBounds
from aura_ums.errors import InputError
from aura_ums.expecter import Expecter, ImageWindow, margin_pixels
from aura_ums.schemas._frame import Frame
from aura_ums.schemas._perceive import (
    Detector,
    build_detector,
    detect,
    may_be_within,
    observe,
    predicted_shift,
)
from aura_ums.schemas._state import Detection, SchemaReport, SchemaState, SchemaStatus
from aura_ums.uncertainty import Observation
from aura_ums.world import LandmarkRecord

#: Pixels added on every side of the last detection's extent to make the tracking window.
TRACKING_MARGIN = 16.0
#: Consecutive tracking frames without a match after which a tracked landmark becomes suspect.
DEFAULT_LOST_FRAMES = 2


def check_tracking_settings(
    lost_frames: object, tracking_margin: object, pixel_error: object, bounds: object
) -> tuple[float, float]:
    """Check the tracking settings of a schema (and of the pilot that hands them on).

    Returns ``(tracking_margin, pixel_error)`` as floats; raises :class:`InputError` naming
    the bad one.
    """
    integer_at_least(lost_frames, "lost_frames", 1)
    margin = nonnegative_float(tracking_margin, "tracking_margin")
    error = nonnegative_float(pixel_error, "pixel_error")
    if bounds is not None and not isinstance(bounds, CalibrationBounds):
        raise InputError(f"bounds: expected CalibrationBounds or None, got {type(bounds).__name__}")
    return margin, error


def _grown_clipped(window: ImageWindow, margin: float, width: int, height: int) -> ImageWindow | None:
    """``window.expanded(margin).clipped(width, height)``, building one window instead of two."""
    u0, v0 = max(window.u_min - margin, -0.5), max(window.v_min - margin, -0.5)
    u1, v1 = min(window.u_max + margin, width - 0.5), min(window.v_max + margin, height - 0.5)
    if u0 > u1 or v0 > v1:
        return None
    return ImageWindow._trusted(u0, v0, u1, v1)


def widen(window: ImageWindow, scale: float, width: int, height: int) -> ImageWindow:
    """Return ``window`` scaled by ``scale`` (>= 1) about its centre, clipped to the image.

    ``inf`` gives the whole image.

    Examples
    --------
    >>> widen(ImageWindow(10, 10, 30, 20), 2.0, 640, 480)
    ImageWindow(u_min=0.0, v_min=5.0, u_max=40.0, v_max=25.0)
    >>> widen(ImageWindow(10, 10, 30, 20), math.inf, 640, 480)
    ImageWindow(u_min=-0.5, v_min=-0.5, u_max=639.5, v_max=479.5)
    """
    if math.isinf(scale):
        return ImageWindow._trusted(-0.5, -0.5, width - 0.5, height - 0.5)
    du = 0.5 * (scale - 1.0) * (window.u_max - window.u_min)
    dv = 0.5 * (scale - 1.0) * (window.v_max - window.v_min)
    wide = ImageWindow(window.u_min - du, window.v_min - dv, window.u_max + du, window.v_max + dv)
    return wide.clipped(width, height) or window


@dataclass(frozen=True, slots=True)
class FindLandmarkSchema:
    """A find-landmark schema, slot-filled for one landmark by the pilot (the paper's schema).

    The schema is an immutable value: its parameters and a pure :meth:`step` from one
    frame and the previous :class:`SchemaStatus` to a :class:`SchemaReport` carrying the
    next status. The :class:`SchemaManager` keeps each instantiation's status.

    Life cycle, per frame:

    - **HIBERNATING** while no position of the map is within ``activation_range`` of
      where the landmark may be (the distance from the map's polygon, edges included,
      to the landmark's point or segment, less its ``position_uncertainty``). The
      perceptual strategy does not run. Any state returns here when the robot leaves
      the range.
    - **DISCOVERING**: the Expecter's window (None: the landmark cannot be in view
      this frame); the perceptual strategy runs on that window only and the evaluation
      function scores what it found (after a first hit, in the window that follows it,
      as in tracking, so that the confirming hits are of one thing). A *hit* is a value
      >= the recognition threshold with a detection that the camera can turn into a
      bounded observation. Discovery is confirmed after ``confirm_frames`` consecutive
      hits; a miss, or a frame where the landmark cannot be in view, resets the count;
      nothing is posted before the confirming frame, so a match in fewer frames (a
      transient) is never posted.
    - **TRACKING**: the window follows the last detection (see *Tracking window*); every
      hit gives an observation. After ``lost_frames`` consecutive misses the landmark is
      **SUSPECT** for that frame (the map may be partially invalid) and the schema
      discovers again, in the Expecter's window, from the next frame. A landmark that
      leaves the view (the Expecter or the prediction puts it outside the image) goes
      back to discovering without becoming suspect.

    Tracking window
    ---------------
    The extent of the last detection (its segment's bounding box, or its point) is
    shifted by the predicted image motion and grown by ``tracking_margin`` pixels, then
    cut to the Expecter's window (nothing outside it can be the landmark; when they do
    not overlap the Expecter's window is searched). The motion model: the detection's
    pixel is back-projected from the map's most probable pose at detection time to a
    world point at the landmark's known distance (Class I and II: its horizontal range
    from the camera; Class III: the ground plane) and projected from the current most
    probable pose; the difference is the shift. It is exact for the change of the most
    probable pose; the margin absorbs the rest (the true motion's departure from it).

    Observations
    ------------
    Made by the camera with the frame's time: Class I from the detected line's midpoint
    (:func:`observe_vertical_line`); Class II from the interest point
    (:func:`observe_point`, pixel error increased by Moravec's ``size // 2`` localization
    bound, range capped by the farthest position of the map); Class III from the segment
    (:func:`observe_ground_line`, ``expected_angle`` from the map's most probable heading).

    Parameters
    ----------
    record : LandmarkRecord
        The landmark, its perceptual strategy and parameters, activation range,
        recognition threshold and confirm count (see :mod:`aura_ums.schemas` for the
        supported strategies and parameter names per class).
    expecter : Expecter
        Predicts windows; its camera makes the observations.
    lost_frames : int
        Consecutive tracking misses that make a landmark suspect (>= 1).
    tracking_margin : float
        Pixels (>= 0) around the predicted detection.
    pixel_error : float
        Bound on a detected pixel's error, pixels (>= 0).
    bounds : CalibrationBounds or None
        Bounds on the camera's calibration; None for an exact calibration.

    Attributes
    ----------
    detector : FastLineFinder or MoravecOperator or RegionSegmenter
        The perceptual strategy, parameterized from the record (a line finder's buckets
        tuned to the record's ``orientation``).
    margin : float
        Pixels the Expecter adds to its window for this strategy
        (:func:`~aura_ums.expecter.margin_pixels` of the record's strategy).

    Raises
    ------
    InputError
        For arguments of the wrong type or out of range, a strategy the landmark's class
        has no schema for, or an unknown parameter name.

    Examples
    --------
    >>> import math
    >>> import numpy as np
    >>> from aura_ums.camera import Camera, CameraIntrinsics, CameraMount
    >>> from aura_ums.expecter import PerceptualStrategy
    >>> from aura_ums.uncertainty import Pose, SpatialUncertaintyMap, VerticalLineLandmark
    >>> camera = Camera(CameraIntrinsics(500, 500, 320, 240, 640, 480), CameraMount(height=1.0))
    >>> pole = VerticalLineLandmark("pole", 10.0, 0.0, 0.0, 4.0, position_uncertainty=0.1)
    >>> record = LandmarkRecord(pole, PerceptualStrategy.LINE_FINDER,
    ...                         {"orientation": math.pi / 2, "min_length": 30.0}, 20.0, 500.0, 2)
    >>> schema = FindLandmarkSchema(record, Expecter(camera))
    >>> snapshot = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.3, math.radians(2))
    >>> image = np.full((480, 640), 60, dtype=np.uint8)
    >>> image[140:240, 318:323] = 200                       # the pole, 5 px wide at u = 320
    >>> first = schema.step(Frame(0.0, image, snapshot))
    >>> first.state, first.hit, first.observation           # one hit: not yet posted
    (<SchemaState.DISCOVERING: 'discovering'>, True, None)
    >>> second = schema.step(Frame(0.1, image, snapshot), first.status)
    >>> second.state, abs(second.observation.bearing) < 0.01   # confirmed: posted, bearing ~ 0
    (<SchemaState.TRACKING: 'tracking'>, True)
    >>> far = SpatialUncertaintyMap.from_pose(Pose(-50, 0, 0), 0.3, 0.0)
    >>> schema.step(Frame(0.2, image, far), second.status).state    # out of range
    <SchemaState.HIBERNATING: 'hibernating'>
    """

    record: LandmarkRecord
    expecter: Expecter
    lost_frames: int = DEFAULT_LOST_FRAMES
    tracking_margin: float = TRACKING_MARGIN
    pixel_error: float = 0.5
    bounds: CalibrationBounds | None = None
    detector: Detector = field(init=False, repr=False)
    margin: float = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if not isinstance(self.record, LandmarkRecord):
            raise InputError(f"record: expected a LandmarkRecord, got {type(self.record).__name__}")
        if not isinstance(self.expecter, Expecter):
            raise InputError(f"expecter: expected an Expecter, got {type(self.expecter).__name__}")
        margin, error = check_tracking_settings(
            self.lost_frames, self.tracking_margin, self.pixel_error, self.bounds
        )
        object.__setattr__(self, "tracking_margin", margin)
        object.__setattr__(self, "pixel_error", error)
        object.__setattr__(self, "detector", build_detector(self.record))
        object.__setattr__(self, "margin", margin_pixels(self.record.strategy))

    @property
    def landmark_id(self) -> str:
        """The landmark's id."""
        return self.record.id

    @property
    def confirm_frames(self) -> int:
        """Consecutive hits that confirm a discovery (the record's ``confirm_frames``)."""
        return self.record.confirm_frames

    @property
    def recognition_threshold(self) -> float:
        """The evaluation value a match must reach."""
        return self.record.recognition_threshold

    @property
    def activation_range(self) -> float:
        """Metres: the schema wakes when the robot may be this close to the landmark."""
        return self.record.activation_range

    def is_active(self, frame: Frame) -> bool:
        """Whether the robot may be within the activation range in this frame's map."""
        return may_be_within(frame.map, self.record.landmark, self.record.activation_range)

    def step(self, frame: Frame, status: SchemaStatus | None = None) -> SchemaReport:
        """Process one frame: wake or hibernate, search the window, evaluate, identify.

        Parameters
        ----------
        frame : Frame
            The image (of the camera's size), its time and the map snapshot.
        status : SchemaStatus or None
            The status after the previous frame; None for a new instantiation.

        Returns
        -------
        SchemaReport
            The window, the evaluation value, whether it was a hit, the observation to
            post (if any) and the new status.

        Raises
        ------
        InputError
            For a frame or status of the wrong type, or an image whose size is not the
            camera's.
        """
        if not isinstance(frame, Frame):
            raise InputError(f"frame: expected a Frame, got {type(frame).__name__}")
        if status is None:
            status = SchemaStatus()
        elif not isinstance(status, SchemaStatus):
            raise InputError(f"status: expected a SchemaStatus or None, got {type(status).__name__}")
        k = self.expecter.camera.intrinsics
        height, width = frame.image.shape
        if width != k.width or height != k.height:
            raise InputError(
                f"frame.image: expected the camera's {k.width}x{k.height} image, got {width}x{height}"
            )
        if not self.is_active(frame):
            return SchemaReport(
                self.record.id, SchemaStatus(SchemaState.HIBERNATING), None, None, False, None, None
            )
        # The guaranteed bounds go into the report too, so that the manager's ambiguity
        # check reuses them instead of asking the Expecter again.
        return self._step_awake(frame, status, self.expecter.bounds(frame.map, self.record.landmark))

    def _step_awake(self, frame: Frame, status: SchemaStatus, bounds: ImageWindow | None) -> SchemaReport:
        k = self.expecter.camera.intrinsics
        ident = self.record.id
        guaranteed = None if bounds is None else _grown_clipped(bounds, self.margin, k.width, k.height)
        if guaranteed is not None and frame.window_scale != 1.0:
            guaranteed = widen(guaranteed, frame.window_scale, k.width, k.height)
        if status.state is SchemaState.TRACKING and status.detection is not None:
            return self._track(frame, status, status.detection, guaranteed, bounds)
        if guaranteed is None:  # awake, but the landmark cannot be in view
            return SchemaReport(
                ident, SchemaStatus(SchemaState.DISCOVERING), None, None, False, None, None, bounds
            )
        search: ImageWindow | None = guaranteed
        following = status.state is SchemaState.DISCOVERING and status.hits > 0
        if following and status.detection is not None and not math.isinf(frame.window_scale):
            # Confirming hits must be of one thing: follow the unconfirmed match as tracking does.
            search = self.tracking_window(frame, status.detection, guaranteed)
        if search is None:  # it would have left the view: discovery starts again
            status, search = SchemaStatus(SchemaState.DISCOVERING), guaranteed
        first = self._focus_window(frame, guaranteed) if search is guaranteed else None
        value, detection, observation = (None, None, None) if first is None else self._look(frame, first)
        if first is not None and detection is not None and observation is not None:
            search = first
        else:  # no focus window, or nothing in it: the guaranteed (or following) window
            value, detection, observation = self._look(frame, search)
        if detection is None or observation is None:
            return SchemaReport(
                ident, SchemaStatus(SchemaState.DISCOVERING), search, value, False, None, None, bounds, first
            )
        hits = status.hits + 1 if status.state is SchemaState.DISCOVERING else 1
        if hits >= self.record.confirm_frames:
            confirmed = SchemaStatus(SchemaState.TRACKING, hits, 0, detection)
            return SchemaReport(ident, confirmed, search, value, True, observation, detection, bounds, first)
        pending = SchemaStatus(SchemaState.DISCOVERING, hits, 0, detection)
        return SchemaReport(ident, pending, search, value, True, None, detection, bounds, first)

    def _focus_window(self, frame: Frame, guaranteed: ImageWindow) -> ImageWindow | None:
        """Return the focus map's window, inside ``guaranteed``; None without one or when it is all of it.

        Not while the windows are widened (lost): the focus map then says little.
        """
        if frame.focus is None or frame.window_scale != 1.0:
            return None
        bounds = self.expecter.bounds(frame.focus, self.record.landmark)
        if bounds is None:
            return None
        k = self.expecter.camera.intrinsics
        grown = _grown_clipped(bounds, self.margin, k.width, k.height)
        if grown is None:
            return None
        # The focus map lies inside the map, so its window inside the guaranteed one: the cut
        # only keeps rounding from reaching outside.
        u0, v0 = max(grown.u_min, guaranteed.u_min), max(grown.v_min, guaranteed.v_min)
        u1, v1 = min(grown.u_max, guaranteed.u_max), min(grown.v_max, guaranteed.v_max)
        if u0 > u1 or v0 > v1:
            return None
        first = ImageWindow._trusted(u0, v0, u1, v1)
        return None if first == guaranteed else first

    # -- internals ---------------------------------------------------------------------

    def _track(
        self,
        frame: Frame,
        status: SchemaStatus,
        last: Detection,
        guaranteed: ImageWindow | None,
        bounds: ImageWindow | None,
    ) -> SchemaReport:
        ident = self.record.id
        if guaranteed is not None and math.isinf(frame.window_scale):
            window: ImageWindow | None = guaranteed  # the full-frame baseline: no tracking window
        else:
            window = None if guaranteed is None else self.tracking_window(frame, last, guaranteed)
        if guaranteed is None or window is None:  # left the view: discover again, not suspect
            return SchemaReport(
                ident, SchemaStatus(SchemaState.DISCOVERING), None, None, False, None, None, bounds
            )
        value, detection, observation = self._look(frame, window)
        if detection is not None and observation is not None:
            kept = SchemaStatus(SchemaState.TRACKING, status.hits + 1, 0, detection)
            return SchemaReport(ident, kept, window, value, True, observation, detection, bounds)
        misses = status.misses + 1
        if misses >= self.lost_frames:
            return SchemaReport(
                ident, SchemaStatus(SchemaState.SUSPECT, 0, misses), window, value, False, None, None, bounds
            )
        waiting = SchemaStatus(SchemaState.TRACKING, status.hits, misses, last)
        return SchemaReport(ident, waiting, window, value, False, None, None, bounds)

    def tracking_window(self, frame: Frame, last: Detection, guaranteed: ImageWindow) -> ImageWindow | None:
        """Return the window in which a tracked landmark is searched (see *Tracking window* above).

        None when the prediction puts the landmark behind the camera or off the image.
        """
        camera = self.expecter.camera
        shift = predicted_shift(camera, self.record.landmark, last, frame.map.most_probable_pose())
        if shift is None:
            return None
        du, dv = shift
        box, m, k = last.box, self.tracking_margin, camera.intrinsics
        # The moved box grown by the margin, clipped to the image (None: off the image), then
        # cut to the guaranteed window (all of it when they do not overlap): one window built.
        u0, v0 = max(box.u_min + du - m, -0.5), max(box.v_min + dv - m, -0.5)
        u1, v1 = min(box.u_max + du + m, k.width - 0.5), min(box.v_max + dv + m, k.height - 0.5)
        if u0 > u1 or v0 > v1:
            return None
        u0, v0 = max(u0, guaranteed.u_min), max(v0, guaranteed.v_min)
        u1, v1 = min(u1, guaranteed.u_max), min(v1, guaranteed.v_max)
        if u0 > u1 or v0 > v1:
            return guaranteed
        return ImageWindow._trusted(u0, v0, u1, v1)

    def _look(self, frame: Frame, window: ImageWindow) -> tuple[float, Detection | None, Observation | None]:
        """Run the strategy in the window; return the value, and the detection and observation of a hit."""
        camera = self.expecter.camera
        value, detection = detect(self.detector, self.record, frame, window, camera=camera)
        if detection is None or not value >= self.record.recognition_threshold or not math.isfinite(value):
            return value, None, None
        try:
            observation = observe(
                camera,
                self.record,
                detection,
                frame.map,
                pixel_error=self.pixel_error,
                bounds=self.bounds,
                detector=self.detector,
            )
        except InputError:  # e.g. a "corner" above the horizon: not a view of this landmark
            return value, None, None
        return value, detection, observation
