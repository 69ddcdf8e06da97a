"""Robustness to outliers: a working map under typical bounds, re-seeded from an envelope map.

Real sensors are heavy-tailed. Bounds wide enough for every error make the map useless;
bounds that hold "only" 99% of the time let the 1% either empty the map (caught: the
reduction is inconsistent) or, worse, shrink it onto a wrong region that later
observations still agree with. The :class:`EnvelopeLocalizer` runs two
:class:`~aura_ums.manager.UncertaintyMapManager` s over the same motion:

- the *working* manager reduces by observations with their typical (calibrated) bounds:
  it is the map reported and used;
- the *envelope* manager reduces by the same observations with worst-case bounds, so it
  stays sound through outliers, at the price of being larger.

The consistency gate is the working manager's own: an observation with which no pose of
the map agrees is rejected and counted, never applied. When ``relocalize_after`` of the
last ``relocalize_window`` observations were rejected as inconsistent, the working map is
presumed wrong (the paper's "a landmark shown to be incorrect", seen from the other side):
it is re-localized from the envelope map, reduced by the current frame's observations
under typical bounds, and the count of re-localizations goes up.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from aura_ums._validate import integer_at_least
from aura_ums.errors import InputError
from aura_ums.manager import (
    REJECT_CLASS_MISMATCH,
    REJECT_STALE,
    REJECT_UNKNOWN_LANDMARK,
    Blackboard,
    ManagerStep,
    PositionReport,
    UncertaintyMapManager,
)
from aura_ums.uncertainty import DEFAULT_MAX_VERTICES, Observation, SpatialUncertaintyMap, TerrainTable
from aura_ums.world import MeadowMap

_NOT_GEOMETRIC = {REJECT_STALE, REJECT_UNKNOWN_LANDMARK, REJECT_CLASS_MISMATCH}


@dataclass(frozen=True, slots=True, eq=False)
class EnvelopeStep:
    """The outcome of one :meth:`EnvelopeLocalizer.update`.

    Attributes
    ----------
    working, envelope : ManagerStep
        The two managers' steps (``envelope`` is None when the localizer has none).
    relocalized : bool
        Whether the working map was re-seeded from the envelope in this update.
    map : SpatialUncertaintyMap
        The working map after the update, re-seeded or not (what the localizer reports).
    """

    working: ManagerStep
    envelope: ManagerStep | None
    relocalized: bool
    map: SpatialUncertaintyMap


class EnvelopeLocalizer:
    """A working map kept honest by an envelope map (see the module notes).

    Parameters
    ----------
    initial_map : SpatialUncertaintyMap
        Where the robot starts (both maps start here).
    meadow_map : MeadowMap
        The meadows' terrains and the landmarks.
    table : TerrainTable
        The terrains' statistics.
    sigmas : float
        Standard deviations bounded by the growth, > 0.
    envelope : bool
        Keep an envelope and re-localize from it (False: the working manager alone, with
        its consistency gate only).
    relocalize_after : int
        Inconsistent observations, >= 1, among the last ``relocalize_window`` that make
        the working map presumed wrong.
    relocalize_window : int
        Observations remembered, >= ``relocalize_after``.
    joint_above : float or None
        Wedge width (radians) above which both managers reduce by the observations of one
        instant together (see :class:`~aura_ums.manager.UncertaintyMapManager`); None: one by one.
    max_vertices : int
        Cap on the working map polygon's vertex count, >= 3 (see
        :class:`~aura_ums.manager.UncertaintyMapManager`).
    envelope_max_vertices : int or None
        The same cap for the envelope map, >= 3; None: ``max_vertices``. The envelope only
        guards the working map, so a coarser one costs little but a looser re-seed.

    Raises
    ------
    InputError
        For a bad argument.

    Examples
    --------
    >>> import math
    >>> from aura_ums.uncertainty import BearingObservation, Pose, TerrainTable, TurnAndRun
    >>> from aura_ums.world import make_grid_world
    >>> world = make_grid_world(2, 3)                 # poles at (0, 0), (10, 0), (0, 10), (10, 10)
    >>> start = SpatialUncertaintyMap.from_pose(Pose(2.5, 2.5, 0.0), 0.2, 0.05)
    >>> localizer = EnvelopeLocalizer(start, world, TerrainTable.default(), relocalize_after=1)
    >>> localizer.post_report(PositionReport(1.0, TurnAndRun(0.0, 0.5)))
    >>> bearing = math.atan2(-2.5, 7.0)               # pole_0_2 at (10, 0) from (3, 2.5)
    >>> localizer.observe(BearingObservation("pole_0_2", 1.0, bearing, 0.01),
    ...                   BearingObservation("pole_0_2", 1.0, bearing, 0.05))
    >>> step = localizer.update(1.0)
    >>> step.relocalized, len(step.working.accepted), localizer.map.area < start.area * 4
    (False, 1, True)
    >>> localizer.observe(BearingObservation("pole_0_2", 1.0, bearing + 2.0, 0.01))   # wrong
    >>> step = localizer.update(1.0)
    >>> localizer.inconsistent_count, step.relocalized, localizer.relocalizations
    (1, True, 1)
    """

    __slots__ = (
        "_envelope",
        "_envelope_board",
        "_meadow_map",
        "_recent",
        "_relocalize_after",
        "_working",
        "_working_board",
    )

    def __init__(
        self,
        initial_map: SpatialUncertaintyMap,
        meadow_map: MeadowMap,
        table: TerrainTable,
        *,
        sigmas: float = 3.0,
        envelope: bool = True,
        relocalize_after: int = 1,
        relocalize_window: int = 1,
        joint_above: float | None = math.pi / 2,
        max_vertices: int = DEFAULT_MAX_VERTICES,
        envelope_max_vertices: int | None = None,
    ) -> None:
        for name, value in (("relocalize_after", relocalize_after), ("relocalize_window", relocalize_window)):
            integer_at_least(value, name, 1)
        if envelope_max_vertices is not None:
            integer_at_least(envelope_max_vertices, "envelope_max_vertices", 3)
        if relocalize_window < relocalize_after:
            raise InputError(
                f"relocalize_window: expected >= relocalize_after ({relocalize_after}), "
                f"got {relocalize_window}"
            )
        self._working = UncertaintyMapManager(
            initial_map, meadow_map, table, sigmas=sigmas, joint_above=joint_above, max_vertices=max_vertices
        )
        self._meadow_map = meadow_map
        self._working_board = Blackboard()
        self._envelope: UncertaintyMapManager | None = None
        self._envelope_board = Blackboard()
        if envelope:
            self._envelope = UncertaintyMapManager(
                initial_map,
                meadow_map,
                table,
                sigmas=sigmas,
                joint_above=joint_above,
                max_vertices=max_vertices if envelope_max_vertices is None else envelope_max_vertices,
            )
        self._relocalize_after = relocalize_after
        self._recent: deque[bool] = deque(maxlen=relocalize_window)

    @property
    def map(self) -> SpatialUncertaintyMap:
        """The working map: the one to report and use."""
        return self._working.map

    @property
    def envelope_map(self) -> SpatialUncertaintyMap | None:
        """The envelope map, or None without an envelope."""
        return None if self._envelope is None else self._envelope.map

    @property
    def relocalizations(self) -> int:
        """Times the working map was re-seeded from the envelope."""
        return self._working.relocalizations

    @property
    def rejected_counts(self) -> Mapping[str, int]:
        """The working manager's rejections, by reason."""
        return self._working.rejected_counts

    @property
    def accepted_count(self) -> int:
        """Observations that reduced the working map."""
        return self._working.accepted_count

    @property
    def inconsistent_count(self) -> int:
        """Observations rejected by the working map's consistency gate (no pose agrees)."""
        return sum(n for reason, n in self._working.rejected_counts.items() if reason not in _NOT_GEOMETRIC)

    def post_report(self, report: PositionReport) -> None:
        """Post a position report (the motion since the previous one) to both managers."""
        self._working_board.post_report(report)
        if self._envelope is not None:
            self._envelope_board.post_report(report)

    def observe(self, working: Observation, envelope: Observation | None = None) -> None:
        """Post an observation with typical bounds, and the same one with worst-case bounds.

        ``envelope`` defaults to ``working`` (the same bounds for both maps).
        """
        self._working_board.identified.post(working)
        if self._envelope is not None:
            self._envelope_board.identified.post(working if envelope is None else envelope)

    def update(self, now: float) -> EnvelopeStep:
        """Bring both maps to ``now``; re-localize the working map when it is presumed wrong."""
        envelope_step = (
            None if self._envelope is None else self._envelope.update(self._envelope_board, now=now)
        )
        step = self._working.update(self._working_board, now=now)
        for outcome in step.outcomes:
            if outcome.reason not in _NOT_GEOMETRIC:
                self._recent.append(not outcome.accepted)
        relocalized = False
        new_map = step.map
        if self._envelope is not None and sum(self._recent) >= self._relocalize_after:
            new_map = self._reseed(self._envelope.map, [o.observation for o in step.outcomes])
            self._working.relocalize(new_map)
            self._recent.clear()
            relocalized = True
        return EnvelopeStep(step, envelope_step, relocalized, new_map)

    def _reseed(
        self, envelope_map: SpatialUncertaintyMap, observations: Sequence[Observation]
    ) -> SpatialUncertaintyMap:
        current = envelope_map
        landmarks = self._meadow_map
        for observation in observations:
            try:
                landmark = landmarks.landmark(observation.landmark_id).landmark
            except KeyError:
                continue
            if observation.landmark_class is not landmark.landmark_class:
                continue
            reduction = current.reduce(observation, landmark, max_vertices=self._working.max_vertices)
            if reduction.consistent:
                current = reduction.map
        return current

    def __repr__(self) -> str:
        return (
            f"EnvelopeLocalizer(area={self.map.area:.4g} m^2, inconsistent={self.inconsistent_count}, "
            f"relocalizations={self.relocalizations}, envelope={'yes' if self._envelope else 'no'})"
        )
