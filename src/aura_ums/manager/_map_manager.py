"""The uncertainty map manager: the one writer of the spatial uncertainty map, and lost detection."""

from __future__ import annotations

import bisect
import dataclasses
import math
import operator
import types
from collections import deque
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from aura_ums._validate import Choice, finite_float
from aura_ums.errors import FileFormatError, InputError, OutsideMapError, UnknownLandmarkError
from aura_ums.manager import _relaxed
from aura_ums.manager._blackboard import Blackboard, PositionReport
from aura_ums.manager._codec import Reader, decode_relaxed, dump_document, encode_map, encode_relaxed
from aura_ums.manager._reasons import RejectReason
from aura_ums.manager._relaxed import Branch, RelaxedState
from aura_ums.manager._settings import ManagerSettings
from aura_ums.uncertainty import (
    BearingObservation,
    Composite,
    GroundLineObservation,
    Landmark,
    Observation,
    RangeBearingObservation,
    SpatialUncertaintyMap,
    TerrainStats,
    TerrainTable,
    TurnAndRun,
    grow_from_anchor,
    intersect_maps,
)
from aura_ums.world import MeadowMap, grow_through, outer_terrain

_KIND = "aura-ums/uncertainty-map-manager"

_report_time = operator.attrgetter("time")

#: Grown maps whose anchors the manager remembers (the relaxed intersection grows one per branch).
_LINEAGES_KEPT = 256
#: Anchors one map keeps: the newest and older ones spread over anchor_span, thinned
#: so that their ages stay roughly in geometric progression.
_ANCHORS_KEPT = 3


@dataclass(frozen=True, slots=True)
class _Anchor:
    """A map the truth was in at ``time`` (s), and the moves since then as one composite."""

    map: SpatialUncertaintyMap
    time: float
    composite: Composite


class ManagerState(Choice):
    """Whether the robot knows where it is (:attr:`NOMINAL`) or has declared itself lost.

    Examples
    --------
    >>> from aura_ums.uncertainty import Pose, TerrainTable
    >>> from aura_ums.world import make_grid_world
    >>> start = SpatialUncertaintyMap.from_pose(Pose(2.5, 2.5, 0.0), 0.1, 0.01)
    >>> manager = UncertaintyMapManager(start, make_grid_world(1, 3), TerrainTable.default())
    >>> manager.update(Blackboard(), now=1.0).state   # a small map, no landmark missed
    <ManagerState.NOMINAL: 'nominal'>
    >>> ManagerState("lost")
    <ManagerState.LOST: 'lost'>
    >>> ManagerState("found")
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: ManagerState: expected one of 'nominal', 'lost', got 'found'
    """

    #: Landmarks are being found and the map is small enough to be useful.
    NOMINAL = "nominal"
    #: The map grew too large, or predicted landmarks were missed too often: stop and look.
    LOST = "lost"


@dataclass(frozen=True, slots=True)
class ObservationOutcome:
    """What the manager did with one identified observation.

    The maps are kept, not their areas: a sliced map's area is a hull of every slice, the
    costliest part of a reduction, so it is taken only when asked for.

    Attributes
    ----------
    observation : BearingObservation or RangeBearingObservation or GroundLineObservation
        The observation taken from the identified landmark buffer.
    accepted : bool
        True when the map was reduced by it (a consistent reduction; with
        ``relaxed_q > 0``: some branch of the relaxed intersection kept it).
    reason : RejectReason or None
        Why it was rejected; None when accepted.
    map_before, map_after : SpatialUncertaintyMap
        The map before and after (the same map when rejected). With ``relaxed_q > 0``:
        the primary branch's (the fewest exclusions), the tight map.
    area_before, area_after : float
        Area of the maps' polygons, square metres (equal when rejected).
    wedge_width_before, wedge_width_after : float
        Width of the maps' heading wedges, radians (equal when rejected).

    Examples
    --------
    >>> from aura_ums.uncertainty import BearingObservation, Pose
    >>> start = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 1.0, 0.2)
    >>> seen = BearingObservation("pole", 0.0, 0.5, 0.01)
    >>> kept = ObservationOutcome(seen, False, RejectReason.UNKNOWN_LANDMARK, start, start)
    >>> kept.area_after == kept.area_before == start.area, kept.wedge_width_after
    (True, 0.4)
    """

    observation: Observation
    accepted: bool
    reason: RejectReason | None
    map_before: SpatialUncertaintyMap
    map_after: SpatialUncertaintyMap

    @property
    def area_before(self) -> float:
        """Area of the map before, square metres."""
        return self.map_before.area

    @property
    def area_after(self) -> float:
        """Area of the map after, square metres."""
        return self.map_after.area

    @property
    def wedge_width_before(self) -> float:
        """Width of the heading wedge before, radians."""
        return self.map_before.wedge.width

    @property
    def wedge_width_after(self) -> float:
        """Width of the heading wedge after, radians."""
        return self.map_after.wedge.width


@dataclass(frozen=True, slots=True, eq=False)
class ManagerStep:
    """The outcome of one :meth:`UncertaintyMapManager.update`.

    Attributes
    ----------
    time : float
        The ``now`` the update ran to, seconds.
    map : SpatialUncertaintyMap
        The map after the update (a snapshot: the manager never changes it in place).
    state : ManagerState
        The state after the update.
    lost_reason : str
        Why the robot is lost (``""`` when :attr:`ManagerState.NOMINAL`).
    outcomes : tuple of ObservationOutcome
        Every observation taken from the buffer, in time order (what became of it in the
        working map).
    grown_reports : int
        Number of position reports the map was grown by in this update.
    relocalized : bool
        Whether the map was re-localized from the envelope map in this update (``map`` is
        then the re-seeded one).
    envelope_map : SpatialUncertaintyMap or None
        The envelope map after the update (None without :attr:`ManagerSettings.robust`).
    excluded : tuple of observations
        The observations that became *excluded* in this update (``relaxed_q > 0``): every
        branch of the relaxed intersection still held counts it among its wrong ones, so
        no pose of the map had to agree with it. Each is reported once, in the update
        where that first holds (it may have arrived in an earlier one); one excluded on
        arrival also has the outcome :attr:`RejectReason.EXCLUDED`. Always empty with
        ``relaxed_q = 0``.
    focus_map : SpatialUncertaintyMap or None
        The map after the update of the relaxed intersection's primary branch (see
        :attr:`UncertaintyMapManager.focus_map`); None with ``relaxed_q = 0``, where it is
        ``map`` itself (read :attr:`focus`).

    Examples
    --------
    >>> from aura_ums.uncertainty import BearingObservation, Pose, TerrainTable, TurnAndRun
    >>> from aura_ums.world import make_grid_world
    >>> start = SpatialUncertaintyMap.from_pose(Pose(2.5, 2.5, 0.0), 0.1, 0.01)
    >>> manager = UncertaintyMapManager(start, make_grid_world(1, 3), TerrainTable.default())
    >>> board = Blackboard()
    >>> step = manager.update(board, now=1.0)   # nothing posted: the start map itself
    >>> step.map is start, step.outcomes, step.grown_reports, step.focus is step.map
    (True, (), 0, True)
    >>> board.post_report(PositionReport(2.0, TurnAndRun(0.0, 2.0)))
    >>> board.identified.post(BearingObservation("pole_9_9", 2.0, 0.0, 0.01))   # not in the map
    >>> step = manager.update(board, now=2.0, missed_in_a_row=3)
    >>> step.time, step.grown_reports, step.accepted, step.rejected[0].reason.value
    (2.0, 1, (), 'unknown landmark id')
    >>> step.state, step.lost_reason
    (<ManagerState.LOST: 'lost'>, '3 frames in a row with predicted landmarks not found >= missed_limit 3')
    """

    time: float
    map: SpatialUncertaintyMap
    state: ManagerState
    lost_reason: str
    outcomes: tuple[ObservationOutcome, ...]
    grown_reports: int
    relocalized: bool = False
    envelope_map: SpatialUncertaintyMap | None = None
    excluded: tuple[Observation, ...] = ()
    focus_map: SpatialUncertaintyMap | None = None

    @classmethod
    def _made(
        cls,
        time: float,
        uncertainty_map: SpatialUncertaintyMap,
        state: ManagerState,
        lost_reason: str,
        outcomes: tuple[ObservationOutcome, ...],
        grown_reports: int,
        relocalized: bool,
        envelope_map: SpatialUncertaintyMap | None,
        excluded: tuple[Observation, ...],
        focus_map: SpatialUncertaintyMap | None,
    ) -> ManagerStep:
        """Build a step by the slots' own setters: half the cost of the frozen dataclass's ``__init__``."""
        step = object.__new__(cls)
        _set_step_time(step, time)
        _set_step_map(step, uncertainty_map)
        _set_step_state(step, state)
        _set_step_lost_reason(step, lost_reason)
        _set_step_outcomes(step, outcomes)
        _set_step_grown_reports(step, grown_reports)
        _set_step_relocalized(step, relocalized)
        _set_step_envelope_map(step, envelope_map)
        _set_step_excluded(step, excluded)
        _set_step_focus_map(step, focus_map)
        return step

    @property
    def focus(self) -> SpatialUncertaintyMap:
        """The map to search first: :attr:`focus_map`, or :attr:`map` without the relaxed intersection."""
        return self.map if self.focus_map is None else self.focus_map

    @property
    def accepted(self) -> tuple[ObservationOutcome, ...]:
        """The outcomes of the observations that reduced the map."""
        return tuple(o for o in self.outcomes if o.accepted)

    @property
    def rejected(self) -> tuple[ObservationOutcome, ...]:
        """The outcomes of the observations that were rejected, with their reasons."""
        return tuple(o for o in self.outcomes if not o.accepted)


# The slots' own setters (frozen: the dataclass's __setattr__ refuses), for ManagerStep._made.
(
    _set_step_time,
    _set_step_map,
    _set_step_state,
    _set_step_lost_reason,
    _set_step_outcomes,
    _set_step_grown_reports,
    _set_step_relocalized,
    _set_step_envelope_map,
    _set_step_excluded,
    _set_step_focus_map,
) = (field.__set__ for field in (ManagerStep.__dict__[f.name] for f in dataclasses.fields(ManagerStep)))


class UncertaintyMapManager:
    """The uncertainty map manager: the only writer of the robot's spatial uncertainty map.

    Each :meth:`update` takes the identified observations up to ``now`` from the
    blackboard's buffer, in time order. Before each, it grows the map by the position
    reports up to the observation's time stamp; then it reduces the map by the
    observation, using the landmark's geometry from the meadow map. Finally it grows the
    map by the remaining reports up to ``now``. Every report is grown by exactly once
    (the manager keeps the index of the last report it consumed), with
    :func:`~aura_ums.world.grow_through`: on the terrain of the one meadow within reach of
    the map, or on the outer terrain of every meadow within reach (a true run may cross
    them anywhere).

    A report covers the motion since the previous one; an observation between two reports
    is applied to the map grown to the earlier one, so reports should be at least as
    frequent as camera frames (post one per frame).

    Rejections (the map is kept and the reason counted): an observation older than the
    map's time (the map was grown past it), an unknown landmark id, an observation of
    another class than its landmark, and an inconsistent reduction (no pose of the map
    agrees with it: most likely a misidentified landmark) -- never an emptied map.

    Observations of one instant (equal time stamps) reduce the map together
    (:func:`~aura_ums.uncertainty.reduce_jointly`, the wedge split into sectors of
    ``joint_sector``) when the map's wedge is wider than ``joint_above``: one by one, a
    bearing says nearly nothing about position while the heading is wide open, but two
    or more seen from one heading do. Those that pass the checks above share the joint
    reduction's areas and widths in their outcomes. When no heading agrees with all of
    them, they are taken one by one instead, so the consistency gate rejects the odd one.

    Outlier recovery (with :attr:`ManagerSettings.robust`, the default): real sensors
    are heavy-tailed. Bounds wide enough for every error make the map useless; bounds
    that hold "only" 99% of the time let the 1% shrink the map onto a wrong region that
    later observations may still agree with. So the manager keeps two maps over the same
    motion: the *working* map, reduced by the observations as posted (their typical
    bounds) -- the one reported and used -- and an *envelope* map, reduced by the same
    observations under worst-case bounds (``envelope_factor`` times wider, or the twins
    the caller gives :meth:`update`), which stays sound through outliers at the price of
    being larger. When ``relocalize_after`` of the last ``relocalize_window`` observations
    that reached a reduction were inconsistent with the working map, it is presumed
    wrong (the paper's "a landmark shown to be incorrect", seen from the other side) and
    re-localized: re-seeded from the envelope map, reduced by the update's consistent
    observations taken at its time, under their typical bounds. The same code runs in
    simulation, in replay and live.

    Wrong landmarks (with :attr:`ManagerSettings.relaxed_q` ``= q > 0``): a misidentified
    landmark can be consistent with both maps and still wrong; a gate cannot see it. The
    working map (and the envelope) is then a *q-relaxed intersection* over the last
    ``relaxed_window = N`` sightings (observations that passed the checks above):
    branches, each a map and the sightings of the window it excludes, at most q. Each
    sighting reduces every branch (one it empties dies) and spawns from each branch with
    fewer than q exclusions a copy that excludes it (a branch that excluded a sighting of a
    landmark ignores that landmark's next sightings while it is in the window: a misread
    landmark tends to be misread again); when an excluded sighting leaves the
    window, its branch merges into the one with the same exclusions minus it (hull of the
    polygons, union of the wedges: :func:`~aura_ums.uncertainty.union_of_maps`). The map
    reported is the outer bound of every branch, with the centre and most probable heading
    of the branch with the fewest exclusions. Guarantee: the truth stays inside whenever the
    wrong sightings among any N consecutive ones name at most q landmarks -- in particular
    whenever at most q of them are wrong (and the growth and the right sightings' bounds
    hold). A sighting every surviving branch excludes is *excluded*
    (:attr:`ManagerStep.excluded`; :attr:`RejectReason.EXCLUDED` when so on arrival, not an
    inconsistency). Only when every branch dies does the consistency gate apply, and
    with it re-localization. The cost: up to ``sum(C(N, k), k <= q)`` branches, each
    grown and reduced. ``relaxed_q = 0`` runs the single map exactly as before.

    Lost detection (the paper: "if no landmarks are recognized even though several have
    been predicted, the robot would declare itself lost, stop, and then start searching
    larger windows"): after an update the state is :attr:`ManagerState.LOST` when the
    map's area exceeds ``area_limit``, or when ``missed_in_a_row`` (the schema manager's
    :attr:`~aura_ums.schemas.SchemaManager.consecutive_missed`) reaches ``missed_limit`` and
    no landmark was found in this update. LOST persists until a landmark is found again (a
    consistent reduction), provided the map is then within ``area_limit``. While LOST,
    :attr:`should_stop_and_look` is True (the simulator or vehicle stops and searches) and
    :attr:`window_scale` is ``lost_window_scale`` (the caller widens the Expecter's image
    windows by it about their centres); otherwise they are False and 1.0.

    Parameters
    ----------
    initial_map : SpatialUncertaintyMap
        Where the robot starts (bootstrapped or known from a previous leg); the envelope
        map starts here too.
    meadow_map : MeadowMap
        Long-term memory: the meadows' terrains and the landmarks' geometry.
    table : TerrainTable
        Statistics of the meadows' terrains.
    settings : ManagerSettings or None
        Sigmas, limits, joint reduction, vertex caps and outlier recovery (see
        :class:`ManagerSettings`); None: the defaults.

    Raises
    ------
    InputError
        For an argument of the wrong type.
    UnknownTerrainError
        When ``table`` lacks the terrain of a meadow of ``meadow_map`` (refused here, not
        at the first run through that meadow).

    Examples
    --------
    >>> import math
    >>> from aura_ums.uncertainty import BearingObservation, Pose, TerrainTable, TurnAndRun
    >>> from aura_ums.world import make_grid_world
    >>> world = make_grid_world(2, 3)                 # poles at (0, 0), (10, 0), (0, 10), (10, 10)
    >>> start = SpatialUncertaintyMap.from_pose(Pose(2.5, 2.5, 0.0), 0.2, 0.05)
    >>> settings = ManagerSettings(area_limit=50.0)
    >>> manager = UncertaintyMapManager(start, world, TerrainTable.default(), settings)
    >>> board = Blackboard()
    >>> board.post_report(PositionReport(1.0, TurnAndRun(0.0, 2.0)))
    >>> board.identified.post(BearingObservation("pole_0_2", 1.0, math.atan2(-2.5, 5.5), 0.01))
    >>> board.identified.post(BearingObservation("pole_9_9", 1.0, 0.0, 0.01))     # not in the map
    >>> step = manager.update(board, now=1.0)
    >>> len(step.accepted), step.rejected[0].reason.value, step.state.value
    (1, 'unknown landmark id', 'nominal')
    >>> seen = step.accepted[0]                       # a small map: the heading narrows
    >>> seen.wedge_width_after < seen.wedge_width_before, seen.area_after <= seen.area_before
    (True, True)
    >>> board.identified.post(BearingObservation("pole_0_2", 1.0, math.atan2(-2.5, 5.5) + 2.0, 0.01))
    >>> step = manager.update(board, now=1.0)         # inconsistent: re-localized from the envelope
    >>> step.rejected[0].reason.name, step.relocalized, manager.relocalizations
    ('NO_POSITION', True, 1)
    >>> step.envelope_map.area >= step.map.area
    True
    >>> manager.update(board, now=2.0, missed_in_a_row=3).state    # predicted, not found: lost
    <ManagerState.LOST: 'lost'>
    >>> manager.should_stop_and_look, manager.window_scale
    (True, 2.0)
    """

    __slots__ = (
        "_accepted",
        "_anchor_growth",
        "_anchor_span",
        "_area_limit",
        "_consumed",
        "_envelope",
        "_envelope_factor",
        "_excluded",
        "_grown",
        "_joint_above",
        "_joint_sector",
        "_landmarks",
        "_last_now",
        "_latest",
        "_latest_committed",
        "_lineages",
        "_lost_reason",
        "_map",
        "_map_time",
        "_max_vertices",
        "_meadow_map",
        "_missed_limit",
        "_only_terrain",
        "_recent",
        "_rejected",
        "_relaxed",
        "_relocalizations",
        "_settings",
        "_sigmas",
        "_state",
        "_table",
    )

    def __init__(
        self,
        initial_map: SpatialUncertaintyMap,
        meadow_map: MeadowMap,
        table: TerrainTable,
        settings: ManagerSettings | None = None,
    ) -> None:
        if not isinstance(initial_map, SpatialUncertaintyMap):
            raise InputError(
                f"initial_map: expected a SpatialUncertaintyMap, got {type(initial_map).__name__}"
            )
        if not isinstance(meadow_map, MeadowMap):
            raise InputError(f"meadow_map: expected a MeadowMap, got {type(meadow_map).__name__}")
        if not isinstance(table, TerrainTable):
            raise InputError(f"table: expected a TerrainTable, got {type(table).__name__}")
        if settings is None:
            settings = ManagerSettings()
        elif not isinstance(settings, ManagerSettings):
            raise InputError(f"settings: expected ManagerSettings or None, got {type(settings).__name__}")
        for meadow in meadow_map.meadows:
            table.require(meadow.terrain, where="table", whose=f"the meadow {meadow.id!r} of meadow_map")
        self._meadow_map = meadow_map
        self._table = table
        self._only_terrain: TerrainStats | None = None
        self._landmarks: dict[str, Landmark] = {}  # by id, as found in the meadow map
        self._settings = settings
        # The settings the hot paths read, as plain attributes.
        self._sigmas = settings.sigmas
        self._area_limit = settings.area_limit
        self._missed_limit = settings.missed_limit
        self._joint_above = settings.joint_above
        self._joint_sector = settings.joint_sector
        self._max_vertices = settings.max_vertices
        self._envelope_factor = settings.envelope_factor
        self._anchor_growth = settings.anchor_growth
        self._anchor_span = settings.anchor_span
        # Each map the anchored growth made -> (that map, its anchors). A map found here
        # grows on from its anchors; keyed by identity, so the relaxed intersection's
        # branches each keep theirs.
        self._lineages: dict[int, tuple[SpatialUncertaintyMap, tuple[_Anchor, ...]]] = {}
        # The last map the anchored growth made, in this update and as committed: a map it
        # does not know is that one reduced (single map only), so it keeps its anchors.
        self._latest: SpatialUncertaintyMap | None = None
        self._latest_committed: SpatialUncertaintyMap | None = None
        self._map = _in_form(initial_map, settings)
        # The branches of the relaxed intersection; None with relaxed_q = 0 (one map, the gate).
        self._relaxed: RelaxedState | None = RelaxedState.start(self._map) if settings.relaxed_q else None
        self._excluded = 0
        self._map_time: float | None = None
        self._consumed = 0
        #: The ``now`` of the last update (None before the first, and in a restored manager).
        self._last_now: float | None = None
        self._state = ManagerState.NOMINAL
        self._lost_reason = ""
        self._accepted = 0
        self._rejected: dict[RejectReason, int] = {}
        self._grown = 0
        self._relocalizations = 0
        # Whether each of the latest observations that reached a reduction was inconsistent.
        self._recent: deque[bool] = deque(maxlen=settings.relocalize_window)
        self._envelope: UncertaintyMapManager | None = None
        if settings.robust:
            cap = settings.envelope_max_vertices
            # The envelope's own lost state and recovery are never read: limits off, no envelope.
            # It stays a product map: the fallback needs containment more than tightness, and
            # a sliced envelope would double a sliced manager's cost.
            envelope_settings = dataclasses.replace(
                settings,
                robust=False,
                area_limit=None,
                max_vertices=settings.max_vertices if cap is None else cap,
                slice_width=None,
            )
            self._envelope = UncertaintyMapManager(initial_map, meadow_map, table, envelope_settings)

    # --- what others read --------------------------------------------------------------

    @property
    def map(self) -> SpatialUncertaintyMap:
        """The current map: an immutable snapshot, safe to hand to the Expecter and pilot."""
        return self._map

    @property
    def focus_map(self) -> SpatialUncertaintyMap:
        """The map of the poses that agree with every recent sighting: where to search first.

        With the relaxed intersection (``relaxed_q > 0``), :attr:`map` is the outer bound of
        its branches, each of which excludes up to ``q`` of the latest sightings; this is
        the map of its primary branch, the one that excludes the fewest (the most recent
        first among equals). It lies inside :attr:`map`, and holds the truth whenever the
        sightings that branch trusts are right. A sighting that leaves the window merges the
        branch that excluded it back into this one: when the guarantee's assumption holds
        (see :class:`ManagerSettings`), the truth is back in it once every wrong sighting has
        left the window. A window from it is no wider than one from :attr:`map`, whose
        window is the one guaranteed: search this one first, and the other when the
        landmark is not in it. Without the relaxed intersection, :attr:`map`.
        """
        return self._map if self._relaxed is None else self._relaxed.primary

    @property
    def state(self) -> ManagerState:
        """NOMINAL, or LOST (see the class notes)."""
        return self._state

    @property
    def lost_reason(self) -> str:
        """Why the robot is lost; ``""`` when NOMINAL."""
        return self._lost_reason

    @property
    def should_stop_and_look(self) -> bool:
        """True while LOST: the robot should stop and search (wider windows, rotating if need be)."""
        return self._state is ManagerState.LOST

    @property
    def window_scale(self) -> float:
        """Factor by which to widen the Expecter's windows: ``lost_window_scale`` while LOST, else 1."""
        return self._settings.lost_window_scale if self._state is ManagerState.LOST else 1.0

    @property
    def map_time(self) -> float | None:
        """Time of the last position report grown into the map, seconds; None before any."""
        return self._map_time

    @property
    def consumed_reports(self) -> int:
        """Number of the blackboard's position reports consumed (index of the next one)."""
        return self._consumed

    @property
    def accepted_count(self) -> int:
        """Observations that reduced the map, since construction."""
        return self._accepted

    @property
    def rejected_counts(self) -> Mapping[RejectReason, int]:
        """Observations rejected since construction, by reason (a read-only copy)."""
        return types.MappingProxyType(dict(self._rejected))

    @property
    def rejected_count(self) -> int:
        """Observations rejected since construction, all reasons together."""
        return sum(self._rejected.values())

    @property
    def relocalizations(self) -> int:
        """Times the map was re-localized (from the envelope or by :meth:`relocalize`) since construction."""
        return self._relocalizations

    @property
    def grown_reports(self) -> int:
        """Position reports grown into the map since construction."""
        return self._grown

    @property
    def excluded_count(self) -> int:
        """Observations excluded by the relaxed intersection since construction (see :class:`ManagerStep`)."""
        return self._excluded

    @property
    def branch_count(self) -> int:
        """Branches of the relaxed intersection the map is the outer bound of (1 with ``relaxed_q = 0``)."""
        return 1 if self._relaxed is None else len(self._relaxed.branches)

    @property
    def inconsistent_count(self) -> int:
        """Observations rejected by the consistency gate (no pose of the map agrees), since construction."""
        return sum(n for reason, n in self._rejected.items() if reason.inconsistent)

    @property
    def settings(self) -> ManagerSettings:
        """The settings the manager runs with."""
        return self._settings

    @property
    def envelope_map(self) -> SpatialUncertaintyMap | None:
        """The envelope map (worst-case bounds); None without :attr:`ManagerSettings.robust`."""
        return None if self._envelope is None else self._envelope._map

    # --- the update --------------------------------------------------------------------

    def update(
        self,
        blackboard: Blackboard,
        *,
        now: float,
        missed_in_a_row: int = 0,
        envelope: Sequence[Observation] | None = None,
    ) -> ManagerStep:
        """Bring the map up to ``now``: grow to each observation, reduce by it, grow to ``now``.

        The identified observations with ``time <= now`` are drained from
        ``blackboard.identified``; the position reports with ``time <= now`` not yet
        consumed are grown into the map (and into the envelope map, which is reduced by
        the same observations under worst-case bounds). When the working map is presumed
        wrong, it is re-localized from the envelope (see the class notes). The update is
        all or nothing: when it raises, neither the manager nor the blackboard has changed.

        Parameters
        ----------
        blackboard : Blackboard
            Where the position reports and identified observations are (always the same one).
        now : float
            The time to bring the map to, seconds.
        missed_in_a_row : int
            The schema manager's count of frames in a row in which landmarks were
            predicted and none found, >= 0.
        envelope : sequence of observations, or None
            The envelope map's twins of the observations this update drains, in the order
            drained (time order; posting order within a time): the same sighting, of the
            same class, landmark and time, under worst-case bounds. None: the drained
            observations with their bounds widened ``envelope_factor`` times. Unused
            without :attr:`ManagerSettings.robust`.

        Returns
        -------
        ManagerStep
            The new map, state and what became of each observation.

        Raises
        ------
        InputError
            For a bad argument (an ``envelope`` that does not pair with the drained
            observations); for a blackboard that is not the one this manager has been
            reading (fewer reports than consumed, or a different last consumed report); for a
            ``now`` before :attr:`map_time` (the map cannot go back in time) or before the
            last update's ``now`` (its steps cannot either, even with no report grown yet). A
            map beyond reach of every meadow (it left the mapped free space; the meadow map
            knows no walls) is not refused: it grows on the outer terrain of every terrain of
            the meadow map (:func:`~aura_ums.world.outer_terrain`).

        Examples
        --------
        >>> from aura_ums.uncertainty import Pose, TerrainTable, TurnAndRun
        >>> from aura_ums.world import make_grid_world
        >>> start = SpatialUncertaintyMap.from_pose(Pose(2.5, 2.5, 0.0), 0.1, 0.01)
        >>> manager = UncertaintyMapManager(start, make_grid_world(1, 3), TerrainTable.default())
        >>> board = Blackboard()
        >>> manager.update(board, now=1.0).map is start      # nothing reported: nothing changes
        True
        >>> board.post_report(PositionReport(2.0, TurnAndRun(0.0, 8.0)))   # crosses two meadows
        >>> step = manager.update(board, now=2.0)
        >>> step.grown_reports, manager.consumed_reports, step.map.area > start.area
        (1, 1, True)
        """
        if not isinstance(blackboard, Blackboard):
            raise InputError(f"blackboard: expected a Blackboard, got {type(blackboard).__name__}")
        time = finite_float(now, "now")
        if isinstance(missed_in_a_row, bool) or not isinstance(missed_in_a_row, int) or missed_in_a_row < 0:
            raise InputError(f"missed_in_a_row: expected a non-negative integer, got {missed_in_a_row!r}")
        self._check_blackboard(blackboard)
        if self._map_time is not None and time < self._map_time:
            # The map already holds the motion up to its last report: it cannot be brought back.
            raise InputError(
                f"now: expected a time at or after the map's ({self._map_time!r} s, its last position "
                f"report grown), got {time!r}"
            )
        if self._last_now is not None and time < self._last_now:
            # Before any report is grown the map has no time, but the steps must not go back.
            raise InputError(
                f"now: expected a time at or after the last update's ({self._last_now!r} s), got {time!r}"
            )

        identified = blackboard.identified
        pending = identified.peek(time)
        # Single-threaded by contract: the commit below drains exactly these.
        # The reports this update consumes (the envelope map has consumed as many).
        reports = blackboard.reports_until(time, start=self._consumed)
        index = self._consumed + len(reports)
        outcomes: list[ObservationOutcome] = []
        excluded: list[Observation] = []
        current, map_time, branches = self._advance(reports, pending, outcomes, excluded)
        outer = self._envelope
        if outer is not None:
            twins = self._twins(pending, envelope)
            # The envelope's outcomes are never reported: not recording them saves a record
            # (and a rejected map's area) per observation.
            wide, wide_time, wide_branches = outer._advance(reports, twins, None, None)

        # Commit: nothing above changed the manager or the blackboard.
        identified._drop_first(len(pending))  # identified.drain(time): exactly ``pending``
        grown = len(reports)
        found = self._commit(current, index, map_time, outcomes, branches, len(excluded))
        relocalized = False
        if outer is not None:
            outer._commit(wide, index, wide_time, (), wide_branches, 0)
            recent = self._recent
            for outcome in outcomes:
                reason = outcome.reason
                # EXCLUDED met the map and was absorbed by the relaxed intersection: not inconsistent.
                if reason is None or reason.reached_reduction:
                    recent.append(reason is not None and reason.inconsistent)
            if sum(recent) >= self._settings.relocalize_after:
                # Not the observations the map found inconsistent: one is as likely a misread
                # (a gross outlier) as the map wrong, and one that is consistent with the wider
                # envelope map would cut the re-seeded map to its own region.
                # Nor those taken before the motion the envelope map has grown since (a stale
                # one included): they tell where the robot was, not where it is.
                agreeing = [
                    o.observation
                    for o in outcomes
                    if (o.reason is None or not o.reason.inconsistent)
                    and (wide_time is None or o.observation.time >= wide_time)
                ]
                self._reseed_from(wide, agreeing)
                self._relocalizations += 1
                recent.clear()
                relocalized = True
        self._update_state(found, missed_in_a_row)
        self._last_now = time
        return ManagerStep._made(
            time,
            self._map,
            self._state,
            self._lost_reason,
            tuple(outcomes),
            grown,
            relocalized,
            None if outer is None else outer._map,
            tuple(excluded),
            None if self._relaxed is None else self._relaxed.primary,
        )

    def _advance(
        self,
        reports: Sequence[PositionReport],
        pending: Sequence[Observation],
        outcomes: list[ObservationOutcome] | None,
        excluded: list[Observation] | None,
    ) -> tuple[SpatialUncertaintyMap, float | None, RelaxedState | None]:
        """Grow by ``reports`` and reduce by ``pending`` in time order, changing nothing.

        Returns the map, its time and the relaxed intersection's branches (None with
        ``relaxed_q = 0``), to commit. What became of each observation is appended to
        ``outcomes``, and the observations newly excluded to ``excluded`` (None: not recorded).
        """
        self._latest = self._latest_committed  # an update that raised made nothing
        if self._relaxed is not None:
            return self._advance_relaxed(self._relaxed, reports, pending, outcomes, excluded)
        current, map_time = self._map, self._map_time
        index = 0
        for start, index, instant in _instants(reports, pending):
            current, map_time = self._grow(current, reports, start, index, map_time)
            if len(instant) == 1:
                observation = instant[0]
                current = self._reduce(
                    current, observation, self._landmark_for(observation, map_time), outcomes
                )
            else:
                current = self._reduce_instant(current, instant, map_time, outcomes)
        if index < len(reports):
            current, map_time = self._grow(current, reports, index, len(reports), map_time)
        return current, map_time, None

    def _advance_relaxed(
        self,
        state: RelaxedState,
        reports: Sequence[PositionReport],
        pending: Sequence[Observation],
        outcomes: list[ObservationOutcome] | None,
        excluded: list[Observation] | None,
    ) -> tuple[SpatialUncertaintyMap, float | None, RelaxedState]:
        """:meth:`_advance` for the branches of the relaxed intersection (``relaxed_q > 0``)."""
        map_time = self._map_time
        index = 0
        for start, index, instant in _instants(reports, pending):
            state, map_time = self._grow_branches(state, reports, start, index, map_time)
            state = self._relax_instant(state, instant, map_time, outcomes, joint=True)
            state, fresh = _relaxed.newly_excluded(state)
            if excluded is not None:
                excluded += fresh
        state, map_time = self._grow_branches(state, reports, index, len(reports), map_time)
        return _relaxed.outer_map(state, self._max_vertices), map_time, state

    def _grow_branches(
        self,
        state: RelaxedState,
        reports: Sequence[PositionReport],
        start: int,
        stop: int,
        map_time: float | None,
    ) -> tuple[RelaxedState, float | None]:
        """Grow every branch by ``reports[start:stop]``; return them and the last report's time."""
        if start == stop:
            return state, map_time
        state = _relaxed.grow(
            state, lambda m: self._grow(m, reports, start, stop, map_time)[0], self._max_vertices
        )
        return state, reports[stop - 1].time

    def _relax_instant(
        self,
        state: RelaxedState,
        observations: Sequence[Observation],
        map_time: float | None,
        outcomes: list[ObservationOutcome] | None,
        *,
        joint: bool,
    ) -> RelaxedState:
        """Reduce the branches by the observations of one instant (the relaxed intersection).

        The sightings enter the window in chunks of at most ``relaxed_window`` (so that no
        window holds more than the guarantee speaks of). When every branch dies, the
        chunk meets the consistency gate instead, branch by branch, as with ``relaxed_q = 0``.
        """
        settings = self._settings
        checked = [self._landmark_for(observation, map_time) for observation in observations]
        before = state.primary
        verdicts: dict[int, ObservationOutcome] = {}
        sightings = [
            (position, observation, found)
            for position, (observation, found) in enumerate(zip(observations, checked, strict=True))
            if not isinstance(found, RejectReason)
        ]
        span = settings.relaxed_window
        for start in range(0, len(sightings), span):
            chunk = sightings[start : start + span]
            pairs = [(observation, landmark) for _, observation, landmark in chunk]
            state, serials = _relaxed.admit(state, [o for o, _ in pairs], span, self._max_vertices)
            prior = state.primary

            def reduce(
                current: SpatialUncertaintyMap,
                keep: Sequence[int],
                pairs: list[tuple[Observation, Landmark]] = pairs,
            ) -> SpatialUncertaintyMap | None:
                # Jointly only with every sighting of the chunk: a copy excluding some is a
                # looser hypothesis, and the joint reduction's cost grows with the wedge.
                together = joint and len(keep) == len(pairs)
                return self._reduce_all(current, [pairs[index] for index in keep], joint=together)

            relaxed = _relaxed.relax(state, serials, settings.relaxed_q, reduce)
            if relaxed is not None:
                state = relaxed
                after = state.primary
                everywhere = frozenset.intersection(*(branch.ignored for branch in state.branches))
                for (position, observation, _), serial in zip(chunk, serials, strict=True):
                    dropped = serial in everywhere
                    verdicts[position] = ObservationOutcome(
                        observation,
                        not dropped,
                        RejectReason.EXCLUDED if dropped else None,
                        prior,
                        prior if dropped else after,
                    )
                continue
            # Every branch died: the gate, branch by branch; the primary's outcomes are reported.
            gated: list[Branch] = []
            for rank, branch in enumerate(state.branches):
                record: list[ObservationOutcome] | None = [] if rank == 0 else None
                if joint:
                    reduced = self._reduce_instant(branch.map, [o for o, _ in pairs], map_time, record)
                else:
                    reduced = branch.map
                    for observation, landmark in pairs:
                        reduced = self._reduce(reduced, observation, landmark, record)
                gated.append(Branch(branch.excluded, reduced, branch.carried))
                if record is not None:
                    for (position, _, _), outcome in zip(chunk, record, strict=True):
                        verdicts[position] = outcome
            state = dataclasses.replace(state, branches=tuple(gated))
        if outcomes is not None:
            for position, (observation, found) in enumerate(zip(observations, checked, strict=True)):
                if isinstance(found, RejectReason):
                    outcomes.append(ObservationOutcome(observation, False, found, before, before))
                else:
                    outcomes.append(verdicts[position])
        return state

    def _reduce_all(
        self,
        current: SpatialUncertaintyMap,
        pairs: Sequence[tuple[Observation, Landmark]],
        *,
        joint: bool,
    ) -> SpatialUncertaintyMap | None:
        """Reduce by every pair (jointly when the wedge is wide); None when no pose agrees with all.

        A reduction that cuts nothing returns the map it was given (the very object): the
        relaxed intersection then spawns no copy that would merely repeat it.
        """
        if (
            joint
            and self._joint_above is not None
            and current.wedge.width > self._joint_above
            and _coupled(observation for observation, _ in pairs) >= 2
        ):
            together = current._reduce_jointly(pairs, self._joint_sector, self._max_vertices)
            if not isinstance(together, str):
                return together
        for observation, landmark in pairs:
            # Inside the prior with its area (> 0) and its wedge's width: the same set.
            found = current._reduce_kept(observation, landmark, self._max_vertices)
            if isinstance(found, str):
                return None
            reduced, same = found
            if not same:
                current = reduced
        return current

    def _commit(
        self,
        current: SpatialUncertaintyMap,
        index: int,
        map_time: float | None,
        outcomes: Sequence[ObservationOutcome],
        branches: RelaxedState | None,
        excluded: int,
    ) -> bool:
        """Take what :meth:`_advance` returned; return whether an observation reduced the map."""
        self._grown += index - self._consumed
        self._map, self._consumed, self._map_time = current, index, map_time
        self._latest_committed = self._latest
        self._relaxed = branches
        self._excluded += excluded
        found = False
        for outcome in outcomes:
            reason = outcome.reason
            if reason is None:
                self._accepted += 1
                found = True
            else:
                self._rejected[reason] = self._rejected.get(reason, 0) + 1
        return found

    def _twins(
        self, pending: Sequence[Observation], envelope: Sequence[Observation] | None
    ) -> list[Observation]:
        """Return the envelope's observations: ``envelope`` checked against ``pending``, or widened ones."""
        if envelope is None:
            factor = self._envelope_factor
            return [_widened(observation, factor) for observation in pending]
        # A list or a tuple is told first: the check against the Sequence ABC costs more.
        if (
            type(envelope) is not list
            and type(envelope) is not tuple
            and (isinstance(envelope, (str, bytes)) or not isinstance(envelope, Sequence))
        ):
            raise InputError(
                f"envelope: expected a sequence of observations or None, got {type(envelope).__name__}"
            )
        if len(envelope) != len(pending):
            raise InputError(
                f"envelope: expected one observation per identified observation drained ({len(pending)}), "
                f"got {len(envelope)}"
            )
        for position, (ours, twin) in enumerate(zip(pending, envelope, strict=True)):
            if type(twin) is not type(ours) or twin.landmark_id != ours.landmark_id or twin.time != ours.time:
                raise InputError(
                    f"envelope[{position}]: expected a {type(ours).__name__} of {ours.landmark_id!r} at "
                    f"t={ours.time!r} (the drained observation's twin), got {twin!r}"
                )
        return list(envelope)

    def _reseed_from(self, envelope_map: SpatialUncertaintyMap, observations: Sequence[Observation]) -> None:
        """Re-seed the map from the envelope map and the update's consistent observations (typical bounds).

        With ``relaxed_q > 0`` the branches restart from the envelope map with an empty
        window, and the observations go through the relaxed intersection one by one.
        """
        state = self._relaxed
        self._latest = self._latest_committed = None  # the old anchors may have lost the truth
        if state is None:
            self._map = _in_form(self._reseed(envelope_map, observations), self._settings)
            return
        state = RelaxedState.start(_in_form(envelope_map, self._settings), state.next_serial)
        for observation in observations:
            state = self._relax_instant(state, [observation], None, None, joint=False)
        self._relaxed = state
        self._map = _relaxed.outer_map(state, self._max_vertices)

    def _reseed(
        self, envelope_map: SpatialUncertaintyMap, observations: Sequence[Observation]
    ) -> SpatialUncertaintyMap:
        """Return the envelope map reduced by the observations with their typical bounds, where consistent."""
        current = envelope_map
        for observation in observations:
            try:
                landmark = self._meadow_map.landmark(observation.landmark_id).landmark
            except UnknownLandmarkError:
                continue
            if not observation.landmark_class.observes(landmark.landmark_class):
                continue
            found = current._reduce_checked(observation, landmark, self._max_vertices)
            if not isinstance(found, str):
                current = found[0]
        return current

    def relocalize(self, new_map: SpatialUncertaintyMap) -> None:
        """Replace the map by one re-derived elsewhere (re-localization), keeping the clock.

        The map's time and the consumed position reports stay: ``new_map`` must describe
        the robot at :attr:`map_time`. The state returns to :attr:`ManagerState.NOMINAL`
        (the new map is the response to being lost) and :attr:`relocalizations` counts it.
        For a re-localization found by other means (a GPS fix, an operator); with
        :attr:`ManagerSettings.robust` the manager re-localizes from its envelope map by
        itself. The envelope map is kept as it is.

        Raises
        ------
        InputError
            When ``new_map`` is not a :class:`SpatialUncertaintyMap`.

        Examples
        --------
        >>> from aura_ums.uncertainty import Pose, TerrainTable
        >>> from aura_ums.world import make_grid_world
        >>> start = SpatialUncertaintyMap.from_pose(Pose(2.5, 2.5, 0.0), 0.1, 0.01)
        >>> manager = UncertaintyMapManager(start, make_grid_world(1, 1), TerrainTable.default())
        >>> wider = SpatialUncertaintyMap.from_pose(Pose(2.5, 2.5, 0.0), 1.0, 0.5)
        >>> manager.relocalize(wider)
        >>> manager.map is wider, manager.relocalizations
        (True, 1)
        >>> manager.relocalize("here")
        Traceback (most recent call last):
        ...
        aura_ums.errors.InputError: new_map: expected a SpatialUncertaintyMap, got str
        """
        if not isinstance(new_map, SpatialUncertaintyMap):
            raise InputError(f"new_map: expected a SpatialUncertaintyMap, got {type(new_map).__name__}")
        self._map = _in_form(new_map, self._settings)
        self._latest = self._latest_committed = None  # the old anchors may have lost the truth
        if self._relaxed is not None:
            self._relaxed = RelaxedState.start(self._map, self._relaxed.next_serial)
        self._relocalizations += 1
        self._recent.clear()  # the inconsistencies were the old map's
        self._state, self._lost_reason = ManagerState.NOMINAL, ""

    def _check_blackboard(self, blackboard: Blackboard) -> None:
        count = blackboard.report_count
        if count < self._consumed:
            raise InputError(
                f"blackboard: expected the one this manager reads, with at least {self._consumed} "
                f"position reports (consumed so far), got {count}"
            )
        if self._consumed:
            released = blackboard.released_reports
            if released >= self._consumed:
                raise InputError(
                    f"blackboard: expected the one this manager reads, keeping its last consumed report "
                    f"{self._consumed - 1}, got one that forgot the reports before {released}"
                )
            # blackboard.report(self._consumed - 1), whose index the checks above bound.
            last = blackboard._reports[self._consumed - 1 - released].time
            if last != self._map_time:
                raise InputError(
                    f"blackboard: expected the one this manager reads, whose report {self._consumed - 1} "
                    f"is at t={self._map_time!r}, got t={last!r}"
                )

    def _grow(
        self,
        current: SpatialUncertaintyMap,
        reports: Sequence[PositionReport],
        start: int,
        stop: int,
        map_time: float | None,
    ) -> tuple[SpatialUncertaintyMap, float | None]:
        """Grow by ``reports[start:stop]``; return the map and the last report's time."""
        if start == stop:
            return current, map_time
        terrain = self._only_terrain
        if terrain is None and len(self._meadow_map.meadows) == 1:
            # One meadow, one terrain: there is nothing to split the runs by (and a run that
            # leaves it would fall back to this terrain anyway). Both are immutable: look
            # the terrain up once (here, so that a missing one fails where it always did).
            terrain = self._only_terrain = self._table[self._meadow_map.meadows[0].terrain]
        if terrain is not None:
            commands = [report.command for report in reports[start:stop]]
            if self._anchor_growth:
                since = reports[start].time if map_time is None else map_time
                now = reports[stop - 1].time
                return self._grow_anchored(current, since, now, commands, terrain), now
            return (
                current._grow_many(commands, terrain, self._sigmas, self._max_vertices),
                reports[stop - 1].time,
            )
        for index in range(start, stop):
            report = reports[index]
            current = self._grow_one(current, report.command)
            map_time = report.time
        return current, map_time

    def _grow_anchored(
        self,
        current: SpatialUncertaintyMap,
        since: float,
        now: float,
        commands: Sequence[TurnAndRun],
        terrain: TerrainStats,
    ) -> SpatialUncertaintyMap:
        """Grow each anchor of ``current`` (at ``since``, s) to ``now`` by ``commands``; intersect.

        ``current`` is a map this growth made (its anchors go on), or the last one it made,
        reduced (its anchors go on, and ``current`` joins them), or any other map (a start,
        a re-seed, a branch of the relaxed intersection): its own only anchor. Each anchor
        held the truth, so each grown anchor does, and so does their intersection; an old
        anchor's fixed per-move distance is paid once, however many corrections followed it.
        """
        lineages = self._lineages
        entry = lineages.get(id(current))
        if entry is not None and entry[0] is current:
            anchors = _thinned(entry[1], now, self._anchor_span)
        else:
            anchors = ()
            latest = self._latest
            if self._relaxed is None and latest is not None:
                kept = lineages.get(id(latest))
                if kept is not None and kept[0] is latest:
                    anchors = kept[1]
            anchors = _thinned((*anchors, _Anchor(current, since, Composite())), now, self._anchor_span)
        anchors = tuple(_Anchor(a.map, a.time, a.composite.extended(commands, terrain)) for a in anchors)
        sigmas, cap = self._sigmas, self._max_vertices
        grown = [grow_from_anchor(a.map, a.composite, terrain, sigmas, cap) for a in reversed(anchors)]
        result = intersect_maps(grown[0], grown[1:], cap)
        lineages.pop(id(result), None)
        lineages[id(result)] = (result, anchors)
        if len(lineages) > _LINEAGES_KEPT:
            del lineages[next(iter(lineages))]
        self._latest = result
        return result

    def _grow_one(self, current: SpatialUncertaintyMap, command: TurnAndRun) -> SpatialUncertaintyMap:
        try:
            return grow_through(
                current,
                self._meadow_map,
                command,
                self._table,
                sigmas=self._sigmas,
                max_vertices=self._max_vertices,
            )
        except OutsideMapError:
            pass
        # No meadow within reach of the map (it left mapped free space; the map knows no
        # walls): the robot moves on the terrain of the meadow it was last in, one of them.
        terrains = [self._table[name] for name in self._meadow_map.terrains]
        terrain = outer_terrain(terrains, 1, command, self._sigmas)
        return current.grow(command, terrain, sigmas=self._sigmas, max_vertices=self._max_vertices)

    def _reduce_instant(
        self,
        current: SpatialUncertaintyMap,
        observations: Sequence[Observation],
        map_time: float | None,
        outcomes: list[ObservationOutcome] | None,
    ) -> SpatialUncertaintyMap:
        """Reduce by observations of one instant: jointly when the wedge is wide, else one by one."""
        # One map time for the instant: each observation's landmark (or rejection) holds for both ways.
        checked = [self._landmark_for(observation, map_time) for observation in observations]
        if self._joint_above is not None and current.wedge.width > self._joint_above:
            sightings = [
                (o, found)
                for o, found in zip(observations, checked, strict=True)
                if not isinstance(found, RejectReason)
            ]
            if _coupled(observation for observation, _ in sightings) >= 2:
                # Paired by id and class (_landmark_for): the pairs reduce_jointly would check.
                joint = current._reduce_jointly(sightings, self._joint_sector, self._max_vertices)
                if not isinstance(joint, str):
                    reduced = joint
                    if outcomes is None:
                        return reduced
                    for observation, found in zip(observations, checked, strict=True):
                        if isinstance(found, RejectReason):
                            outcomes.append(ObservationOutcome(observation, False, found, current, current))
                        else:
                            outcomes.append(ObservationOutcome(observation, True, None, current, reduced))
                    return reduced
        for observation, found in zip(observations, checked, strict=True):
            current = self._reduce(current, observation, found, outcomes)
        return current

    def _landmark_for(self, observation: Observation, map_time: float | None) -> Landmark | RejectReason:
        """Return the landmark an observation names, or why it is rejected before any reduction."""
        if map_time is not None and observation.time < map_time:
            return RejectReason.STALE
        # The meadow map is immutable: each landmark is looked up once.
        landmark = self._landmarks.get(observation.landmark_id)
        if landmark is None:
            try:
                landmark = self._meadow_map.landmark(observation.landmark_id).landmark
            except UnknownLandmarkError:
                return RejectReason.UNKNOWN_LANDMARK
            self._landmarks[observation.landmark_id] = landmark
        if not observation.landmark_class.observes(landmark.landmark_class):
            return RejectReason.CLASS_MISMATCH
        return landmark

    def _reduce(
        self,
        current: SpatialUncertaintyMap,
        observation: Observation,
        landmark: Landmark | RejectReason,
        outcomes: list[ObservationOutcome] | None,
    ) -> SpatialUncertaintyMap:
        """Reduce by one observation and its landmark (from :meth:`_landmark_for`, or why not)."""
        if isinstance(landmark, RejectReason):
            reason = landmark
        else:
            # Found by the observation's id, of its class: the pair reduce() would check.
            found = current._reduce_checked(observation, landmark, self._max_vertices, measured=False)
            if not isinstance(found, str):
                reduced = found[0]
                if outcomes is not None:
                    outcomes.append(ObservationOutcome(observation, True, None, current, reduced))
                return reduced
            # The reductions word their reasons; each is a RejectReason's value.
            reason = RejectReason(found)
        if outcomes is not None:
            # Rejected: the map stays, and so do its area and width.
            outcomes.append(ObservationOutcome(observation, False, reason, current, current))
        return current

    def _update_state(self, found: bool, missed_in_a_row: int) -> None:
        reasons: list[str] = []
        # The area only against a limit: most maps are new each update, their area not yet known.
        if self._area_limit is not None and (area := self._map.area) > self._area_limit:
            reasons.append(f"map area {area:.6g} m^2 > area_limit {self._area_limit:g} m^2")
        if not found and missed_in_a_row >= self._missed_limit:
            reasons.append(
                f"{missed_in_a_row} frames in a row with predicted landmarks not found "
                f">= missed_limit {self._missed_limit}"
            )
        if reasons:
            self._state, self._lost_reason = ManagerState.LOST, "; ".join(reasons)
        elif found or self._state is ManagerState.NOMINAL:
            self._state, self._lost_reason = ManagerState.NOMINAL, ""
        # else: still LOST, for the reason recorded when it became so

    # --- save and restore --------------------------------------------------------------

    def to_json(self) -> str:
        """Return the manager's whole state as JSON text.

        The maps (polygon vertices, centre, wedge; the working map and the envelope map)
        are written with ``repr`` precision, so :meth:`from_json` restores them bit for
        bit; with them go the state, the counters, the settings
        (:meth:`ManagerSettings.to_dict`), the recent inconsistencies and the index and
        time of the last consumed position report. The meadow map and terrain table are
        not saved: they are long-term memory, given again on restore. Save the
        :class:`Blackboard` too (:meth:`Blackboard.to_json`).

        Examples
        --------
        >>> from aura_ums.uncertainty import Pose, TerrainTable
        >>> from aura_ums.world import make_grid_world
        >>> world, table = make_grid_world(1, 3), TerrainTable.default()
        >>> start = SpatialUncertaintyMap.from_pose(Pose(2.5, 2.5, 0.3), 0.1, 0.01)
        >>> manager = UncertaintyMapManager(start, world, table, ManagerSettings(area_limit=40.0))
        >>> again = UncertaintyMapManager.from_json(manager.to_json(), world, table)
        >>> again.map.polygon.vertices.tobytes() == start.polygon.vertices.tobytes()
        True
        >>> again.settings == manager.settings
        True
        """
        outer = self._envelope
        # Written only with relaxed_q > 0: documents of the gate alone read as they always did.
        relaxed: dict[str, object] = (
            {} if self._relaxed is None else {"relaxed": encode_relaxed(self._relaxed)}
        )
        if outer is not None and outer._relaxed is not None:
            envelope_relaxed = {"relaxed": encode_relaxed(outer._relaxed)}
        else:
            envelope_relaxed = {}
        return dump_document(
            _KIND,
            {
                "map": encode_map(self._map),
                "map_time": self._map_time,
                "consumed_reports": self._consumed,
                "state": self._state.value,
                "lost_reason": self._lost_reason,
                "counters": {
                    "accepted": self._accepted,
                    "rejected": {reason.value: count for reason, count in self._rejected.items()},
                    "grown_reports": self._grown,
                    "relocalizations": self._relocalizations,
                    **({"excluded": self._excluded} if self._relaxed is not None else {}),
                },
                "settings": self._settings.to_dict(),
                "envelope": None
                if outer is None
                else {"map": encode_map(outer._map), "recent": list(self._recent), **envelope_relaxed},
                **relaxed,
            },
        )

    @staticmethod
    def saved_settings(text: str, *, source: str = "<manager JSON>") -> ManagerSettings:
        """Return the settings a manager saved by :meth:`to_json` runs with.

        As :meth:`from_json` would restore them (a document saved before a setting
        existed runs as it did), without restoring the manager.

        Raises
        ------
        FileFormatError
            When the text is not such a document, naming ``source``, the place and what is wrong.

        Examples
        --------
        >>> from aura_ums.uncertainty import Pose, TerrainTable
        >>> from aura_ums.world import make_grid_world
        >>> start = SpatialUncertaintyMap.from_pose(Pose(2.5, 2.5, 0.0), 0.1, 0.01)
        >>> settings = ManagerSettings(relaxed_q=1, relaxed_window=5)
        >>> manager = UncertaintyMapManager(start, make_grid_world(1, 3), TerrainTable.default(), settings)
        >>> UncertaintyMapManager.saved_settings(manager.to_json()) == settings
        True
        >>> UncertaintyMapManager.saved_settings('{"format": "aura-ums/uncertainty-map-manager"}')
        Traceback (most recent call last):
        ...
        aura_ums.errors.FileFormatError: <manager JSON>: version: expected 1, got nothing
        """
        return _saved_document(Reader(source), text)[1]

    @classmethod
    def from_json(
        cls,
        text: str,
        meadow_map: MeadowMap,
        table: TerrainTable,
        *,
        source: str = "<manager JSON>",
    ) -> UncertaintyMapManager:
        """Restore a manager saved by :meth:`to_json`, with its long-term memory.

        A document saved before a setting existed is restored as it ran: without
        ``joint_above``, one by one; without ``robust``, with no envelope. Any other
        setting it lacks takes its default.

        Parameters
        ----------
        text : str
            The JSON text.
        meadow_map : MeadowMap
            The meadow map (the same as when saved).
        table : TerrainTable
            The terrain table (the same as when saved).
        source : str
            Name used in error messages (e.g. the file it was read from).

        Raises
        ------
        FileFormatError
            When the text is not such a document, naming the place and what is wrong.

        Examples
        --------
        >>> from aura_ums.uncertainty import TerrainTable
        >>> from aura_ums.world import make_grid_world
        >>> UncertaintyMapManager.from_json("[1, 2]", make_grid_world(1, 1), TerrainTable.default())
        Traceback (most recent call last):
        ...
        aura_ums.errors.FileFormatError: <manager JSON>: expected an object, got an array
        """
        if not isinstance(meadow_map, MeadowMap):
            raise InputError(f"meadow_map: expected a MeadowMap, got {type(meadow_map).__name__}")
        if not isinstance(table, TerrainTable):
            raise InputError(f"table: expected a TerrainTable, got {type(table).__name__}")
        reader = Reader(source)
        data, settings = _saved_document(reader, text)
        uncertainty_map = reader.uncertainty_map(data["map"], "map")
        manager = cls(uncertainty_map, meadow_map, table, settings)
        manager._map_time = reader.optional_number(data["map_time"], "map_time")
        manager._consumed = reader.integer(data["consumed_reports"], "consumed_reports")
        if (manager._consumed == 0) != (manager._map_time is None):
            reader.fail("map_time", "expected null exactly when consumed_reports is 0")
        state = reader.string(data["state"], "state")
        try:
            manager._state = ManagerState(state)
        except ValueError:
            reader.fail("state", f"expected one of {[s.value for s in ManagerState]}, got {state!r}")
        manager._lost_reason = reader.string(data["lost_reason"], "lost_reason")
        counters = reader.mapping(
            data["counters"],
            "counters",
            ("accepted", "rejected", "grown_reports", "relocalizations"),
            optional=("excluded",),
        )
        if "excluded" in counters:
            manager._excluded = reader.integer(counters["excluded"], "counters.excluded")
        manager._relocalizations = reader.integer(counters["relocalizations"], "counters.relocalizations")
        manager._accepted = reader.integer(counters["accepted"], "counters.accepted")
        manager._grown = reader.integer(counters["grown_reports"], "counters.grown_reports")
        rejected = reader.mapping(counters["rejected"], "counters.rejected")
        for key, count in rejected.items():
            place = f"counters.rejected[{key!r}]"
            try:
                reason = RejectReason(key)
            except ValueError:
                reader.fail(place, f"expected one of {[r.value for r in RejectReason]}, got {key!r}")
            manager._rejected[reason] = reader.integer(count, place)
        manager._relaxed = manager._restore_relaxed(reader, data.get("relaxed"), "relaxed")
        manager._restore_envelope(reader, data.get("envelope"))
        return manager

    def _restore_relaxed(self, reader: Reader, value: object, where: str) -> RelaxedState | None:
        """Decode the relaxed intersection's state: present exactly when ``relaxed_q > 0``."""
        settings = self._settings
        if not settings.relaxed_q:
            if value is not None:
                reader.fail(where, "expected none (settings.relaxed_q is 0), got a value")
            return None
        if value is None:
            reader.fail(where, "expected the branches (settings.relaxed_q > 0), got none")
        return decode_relaxed(reader, value, where, settings.relaxed_q, settings.relaxed_window)

    def _restore_envelope(self, reader: Reader, value: object) -> None:
        """Restore the envelope map and the recent inconsistencies saved by :meth:`to_json`."""
        outer = self._envelope
        if outer is None:
            if value is not None:
                reader.fail("envelope", "expected null (settings.robust is false), got a value")
            return
        if value is None:
            reader.fail("envelope", "expected the envelope map (settings.robust is true), got none")
        data = reader.mapping(value, "envelope", ("map", "recent"), optional=("relaxed",))
        outer._map = reader.uncertainty_map(data["map"], "envelope.map")
        outer._relaxed = outer._restore_relaxed(reader, data.get("relaxed"), "envelope.relaxed")
        outer._map_time, outer._consumed = self._map_time, self._consumed
        recent = reader.array(data["recent"], "envelope.recent")
        window = self._settings.relocalize_window
        if len(recent) > window or not all(isinstance(item, bool) for item in recent):
            reader.fail(
                "envelope.recent",
                f"expected at most {window} booleans (relocalize_window), got {len(recent)} items"
                + ("" if all(isinstance(item, bool) for item in recent) else ", not all booleans"),
            )
        self._recent.extend(recent)

    def __repr__(self) -> str:
        return (
            f"UncertaintyMapManager({self._state.value}, area={self._map.area:.4g} m^2, "
            f"reports consumed={self._consumed}, accepted={self._accepted}, rejected={self.rejected_count})"
        )


def _coupled(observations: Iterable[Observation]) -> int:
    """Count the observations that tie position to heading: an angle bounded by less than pi.

    Reducing jointly pays only for two or more of them seen from one heading. A bearing
    bounded by pi or more (an envelope calibrated on a misread landmark) says nothing of the
    heading, and a frame of such sightings reduced jointly cost an envelope 40 times the
    update time of the map itself.
    """
    count = 0
    for observation in observations:
        if isinstance(observation, GroundLineObservation):
            count += observation.angle_error < math.pi
        else:
            count += observation.bearing_error < math.pi
    return count


#: What a saved document lacking a setting ran with: one by one before joint reductions,
#: without an envelope before outlier recovery; the defaults otherwise.
_BEFORE_SETTINGS = ManagerSettings(joint_above=None, robust=False, relaxed_q=0)


def _saved_document(reader: Reader, text: str) -> tuple[dict[str, Any], ManagerSettings]:
    """Return a saved manager's top-level keys, checked, and the settings it runs with."""
    keys = ("format", "version", "map", "map_time", "consumed_reports", "state", "lost_reason")
    data = reader.mapping(
        reader.document(text, _KIND),
        "",
        (*keys, "counters", "settings"),
        optional=("envelope", "relaxed"),
    )
    settings = ManagerSettings.from_dict(
        reader.mapping(data["settings"], "settings"),
        base=_BEFORE_SETTINGS,
        fail=lambda key, message: FileFormatError(reader.source, f"settings.{key}", message),
    )
    return data, settings


def _thinned(anchors: tuple[_Anchor, ...], now: float, span: float) -> tuple[_Anchor, ...]:
    """Keep the newest anchor and at most a few older ones of at most ``span`` seconds, spread in age.

    Beyond the count, the anchor dropped is the one whose neighbours are closest in time
    relative to the older neighbour's age: what is kept spreads roughly geometrically.
    """
    kept = [a for a in anchors[:-1] if now - a.time <= span] + [anchors[-1]]
    while len(kept) > _ANCHORS_KEPT:
        gaps = [
            (kept[i + 1].time - kept[i - 1].time) / max(now - kept[i - 1].time, 1e-9)
            for i in range(1, len(kept) - 1)
        ]
        del kept[1 + gaps.index(min(gaps))]
    return tuple(kept)


def _instants(
    reports: Sequence[PositionReport], pending: Sequence[Observation]
) -> Iterator[tuple[int, int, Sequence[Observation]]]:
    """Yield each instant of ``pending`` (time order) after the reports to grow by before it.

    Each item is ``(start, stop, observations)``: the reports ``start:stop`` end at or
    before the instant, and ``observations`` are those of ``pending`` sharing its time.
    """
    index = 0
    first = 0
    while first < len(pending):
        instant = pending[first].time
        last = first + 1
        while last < len(pending) and pending[last].time == instant:
            last += 1
        stop = bisect.bisect_right(reports, instant, lo=index, key=_report_time)
        yield index, stop, pending[first:last]
        index = stop
        first = last


def _in_form(uncertainty_map: SpatialUncertaintyMap, settings: ManagerSettings) -> SpatialUncertaintyMap:
    """Return the map sliced as ``settings.slice_width`` says (None: the product map)."""
    if settings.slice_width is None:
        return uncertainty_map.without_slices()
    return uncertainty_map.with_slices(settings.slice_width, settings.max_slices)


def _widened(observation: Observation, factor: float) -> Observation:
    """Return ``observation`` with its error bounds ``factor`` (>= 1) times wider, about their centres."""
    if factor == 1.0:
        return observation
    if isinstance(observation, BearingObservation):
        return dataclasses.replace(observation, bearing_error=observation.bearing_error * factor)
    if isinstance(observation, RangeBearingObservation):
        middle = (observation.range_min + observation.range_max) / 2.0
        half = (observation.range_max - observation.range_min) / 2.0 * factor
        return dataclasses.replace(
            observation,
            bearing_error=observation.bearing_error * factor,
            range_min=max(0.0, middle - half),
            range_max=middle + half,
        )
    if isinstance(observation, GroundLineObservation):
        return dataclasses.replace(
            observation,
            offset_error=observation.offset_error * factor,
            angle_error=observation.angle_error * factor,
        )
    raise InputError(f"observation: expected an observation of Class I, II or III, got {observation!r}")
