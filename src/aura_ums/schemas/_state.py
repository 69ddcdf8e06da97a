"""Life-cycle states of a find-landmark schema, what it remembers between frames, and its reports."""

from __future__ import annotations

from dataclasses import dataclass

from aura_ums._validate import Choice
from aura_ums.expecter import ImageWindow
from aura_ums.uncertainty import Observation, Pose


class SchemaState(Choice):
    """Where a find-landmark schema instantiation is in its life cycle (the paper's SI states).

    ``HIBERNATING`` until the robot may be within the landmark's activation range;
    ``DISCOVERING`` while it looks in the Expecter's window and counts consecutive
    matches; ``TRACKING`` once a discovery is confirmed, following the landmark from
    frame to frame; ``SUSPECT`` on the frame a tracked landmark is given up (it stopped
    matching): the map may be partially invalid. A suspect schema discovers again on the
    next frame.

    Examples
    --------
    >>> [state.value for state in SchemaState]
    ['hibernating', 'discovering', 'tracking', 'suspect']
    >>> SchemaState("tracking")
    <SchemaState.TRACKING: 'tracking'>
    >>> SchemaState("lost")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: SchemaState: expected one of ..., got 'lost'
    """

    HIBERNATING = "hibernating"
    DISCOVERING = "discovering"
    TRACKING = "tracking"
    SUSPECT = "suspect"


@dataclass(frozen=True, slots=True)
class Detection:
    """Where a schema found its landmark in one frame.

    Parameters
    ----------
    time : float
        The frame's time, seconds.
    value : float
        The evaluation function's value (on the scale of the landmark's recognition threshold).
    point : tuple of float
        ``(u, v)``, full-image pixels: the line's midpoint (Class I and III), the interest
        point (Class II) or the region's centroid.
    box : ImageWindow
        The extent of what was found: the segment's or region's bounding box, or the point.
    segment : tuple of float or None
        ``(u1, v1, u2, v2)`` of the line found, pixels; None for a point or a region.
    pose : Pose
        The map's most probable pose in that frame (the reference for predicting motion).

    Examples
    --------
    >>> box = ImageWindow(50, 10, 51, 90)
    >>> line = Detection(2.0, 960.0, (50.5, 50.0), box, (50, 10, 51, 90), Pose(0, 0, 0))
    >>> line.point, line.box.height
    ((50.5, 50.0), 80.0)
    >>> corner = Detection(2.0, 400.0, (12.0, 11.0), ImageWindow(12, 11, 12, 11), None, Pose(0, 0, 0))
    >>> corner.segment is None, corner.box.area                # a point: no segment, an empty box
    (True, 0.0)
    """

    time: float
    value: float
    point: tuple[float, float]
    box: ImageWindow
    segment: tuple[float, float, float, float] | None
    pose: Pose


@dataclass(frozen=True, slots=True)
class SchemaStatus:
    """What a find-landmark schema instantiation carries from one frame to the next.

    Parameters
    ----------
    state : SchemaState
        Its life-cycle state after the frame.
    hits : int
        Consecutive frames in which the landmark matched (discovery counts up to the
        confirm count; tracking keeps counting).
    misses : int
        Consecutive tracking frames in which it did not match.
    detection : Detection or None
        The last match: while discovering, the last unconfirmed one; while tracking, the
        last one, which the tracking window follows.

    Examples
    --------
    >>> SchemaStatus()
    SchemaStatus(state=<SchemaState.HIBERNATING: 'hibernating'>, hits=0, misses=0, detection=None)
    """

    state: SchemaState = SchemaState.HIBERNATING
    hits: int = 0
    misses: int = 0
    detection: Detection | None = None


@dataclass(frozen=True, slots=True)
class SchemaReport:
    """What one find-landmark schema did in one frame.

    Parameters
    ----------
    landmark_id : str
        The landmark the schema looks for.
    status : SchemaStatus
        Its status after the frame (``status.state`` is also :attr:`state`).
    window : ImageWindow or None
        The window searched: the Expecter's (discovering) or the tracking window; None
        when the schema hibernates or the landmark cannot be in view.
    value : float or None
        The evaluation function's value in the window (0 when nothing fits); None when
        the perceptual strategy did not run.
    hit : bool
        Whether the value reached the recognition threshold with a usable detection (one
        the camera can turn into an observation).
    observation : Observation or None
        The observation posted to the identified landmark buffer: on the frame that
        confirms a discovery and on every tracking frame with a hit; None otherwise.
    detection : Detection or None
        This frame's match, when it was a hit.
    bounds : ImageWindow or None
        The Expecter's guaranteed bounds of the landmark's projection this frame (before
        margin and clipping); None when the schema hibernates or the landmark cannot be
        in view.
    focus_window : ImageWindow or None
        The focus map's window (:attr:`Frame.focus`), searched before the guaranteed one
        while discovering; :attr:`window` is then this window when it held the match, the
        guaranteed one when not. None when no focus window was searched.

    Examples
    --------
    >>> window = ImageWindow(300, 100, 340, 260)
    >>> searched = SchemaReport("pole", SchemaStatus(SchemaState.DISCOVERING), window, 0.0, False, None, None)
    >>> searched.state, searched.predicted, searched.missed      # a window, nothing in it
    (<SchemaState.DISCOVERING: 'discovering'>, True, True)
    >>> asleep = SchemaReport("pole", SchemaStatus(), None, None, False, None, None)
    >>> asleep.state, asleep.predicted, asleep.missed           # hibernating: no window at all
    (<SchemaState.HIBERNATING: 'hibernating'>, False, False)
    """

    landmark_id: str
    status: SchemaStatus
    window: ImageWindow | None
    value: float | None
    hit: bool
    observation: Observation | None
    detection: Detection | None
    bounds: ImageWindow | None = None
    focus_window: ImageWindow | None = None

    @property
    def state(self) -> SchemaState:
        """The schema's state after the frame."""
        return self.status.state

    @property
    def predicted(self) -> bool:
        """Whether a window was predicted (the schema is awake and the landmark may be in view)."""
        return self.window is not None

    @property
    def missed(self) -> bool:
        """Predicted but not found: a window was searched and nothing matched."""
        return self.window is not None and not self.hit
