"""Monte Carlo checks of the growth bound: containment and tightness.

Users run these on their own terrain tables and command patterns to see how often
the truth stays inside and how much room the bound leaves.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from aura_ums._validate import SIGMAS, check_rng, items_of
from aura_ums.errors import InputError
from aura_ums.geometry import convex_hull, polygon_area
from aura_ums.uncertainty._map import SpatialUncertaintyMap, sample_count
from aura_ums.uncertainty._motion import TurnAndRun
from aura_ums.uncertainty._terrain import TerrainStats


@dataclass(frozen=True, slots=True)
class ContainmentResult:
    """How many sampled true poses stayed inside the grown maps.

    Attributes
    ----------
    inside : int
        Sampled poses inside the map, summed over every step.
    total : int
        Sampled poses checked, summed over every step.
    per_step : tuple of float
        Fraction inside after each command.

    Examples
    --------
    >>> ContainmentResult(inside=297, total=300, per_step=(1.0, 0.99, 0.98)).rate
    0.99
    >>> ContainmentResult(0, 0, ()).rate   # nothing checked: nothing escaped
    1.0
    >>> from aura_ums.uncertainty import Pose, TerrainTable
    >>> start = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.0, 0.0)
    >>> moves = [(TurnAndRun(0.5, 3.0), TerrainTable.default()["grass"])] * 2
    >>> result = simulate_containment(start, moves, np.random.default_rng(1), poses=20, truncate=3.0)
    >>> result.inside == result.total, result.per_step
    (True, (1.0, 1.0))
    """

    inside: int
    total: int
    per_step: tuple[float, ...]

    @property
    def rate(self) -> float:
        """Fraction of checked poses inside, in [0, 1]."""
        return self.inside / self.total if self.total else 1.0


def simulate_containment(
    start: SpatialUncertaintyMap,
    moves: Sequence[tuple[TurnAndRun, TerrainStats]],
    rng: np.random.Generator,
    *,
    poses: int = 100,
    sigmas: float = 3.0,
    truncate: float | None = None,
    include_extremes: bool = True,
) -> ContainmentResult:
    """Grow a map through ``moves`` and count sampled true poses inside it after each one.

    True start poses are drawn uniformly from ``start`` and, with
    ``include_extremes``, also placed at its vertices with its extreme headings (where a
    bound is tightest). Each then moves by :meth:`TerrainStats.sample_motion`.

    Parameters
    ----------
    start : SpatialUncertaintyMap
        Map of possible start poses.
    moves : sequence of (TurnAndRun, TerrainStats)
        Commands and the terrain each happens on.
    rng : numpy.random.Generator
        Source of randomness.
    poses : int
        Uniformly drawn true start poses.
    sigmas : float
        Standard deviations the map bounds.
    truncate : float, optional
        Clip the model's normals to +-truncate (use ``sigmas`` to check soundness).
    include_extremes : bool
        Add the polygon's vertices with the wedge's two extreme headings.

    Examples
    --------
    >>> from aura_ums.uncertainty import Pose, TerrainTable
    >>> start = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.0, 0.0)
    >>> moves = [(TurnAndRun(0.5, 3.0), TerrainTable.default()["grass"])] * 3
    >>> simulate_containment(start, moves, np.random.default_rng(1), truncate=3.0).rate
    1.0
    """
    _check_start(start)
    steps = items_of(moves, "moves", "a sequence of (TurnAndRun, TerrainStats) pairs")
    for index, move in enumerate(steps):
        if (
            not isinstance(move, tuple)
            or len(move) != 2
            or not isinstance(move[0], TurnAndRun)
            or not isinstance(move[1], TerrainStats)
        ):
            raise InputError(f"moves[{index}]: expected a (TurnAndRun, TerrainStats) pair, got {move!r}")
    if sample_count(poses, "poses") < 1:
        raise InputError(f"poses: expected at least 1, got {poses}")
    check_rng(rng)
    SIGMAS.check(sigmas, "sigmas")
    state = start.sample_poses(poses, rng)
    if include_extremes:
        wedge = start.wedge
        vertices = start.polygon.vertices
        extremes = [np.column_stack([vertices, np.full(len(vertices), h)]) for h in (wedge.lo, wedge.hi)]
        state = np.vstack([state, *extremes])
    current = start
    inside = 0
    total = 0
    per_step: list[float] = []
    for command, terrain in steps:
        state = terrain.sample_motions(state, command, rng, truncate=truncate)
        current = current.grow(command, terrain, sigmas=sigmas)
        hits = int(np.count_nonzero(current.contains(state[:, 0], state[:, 1], state[:, 2])))
        inside += hits
        total += len(state)
        per_step.append(hits / len(state))
    return ContainmentResult(inside, total, tuple(per_step))


@dataclass(frozen=True, slots=True)
class TightnessResult:
    """Area of a grown map against the hull of sampled outcomes.

    Attributes
    ----------
    map_area : float
        Area of the grown map's polygon, m^2.
    sample_hull_area : float
        Area of the convex hull of the sampled true positions, m^2.
    samples : ndarray, shape (n, 3)
        The sampled true poses.

    Examples
    --------
    >>> TightnessResult(map_area=12.0, sample_hull_area=10.0, samples=np.zeros((0, 3))).ratio
    1.2
    >>> TightnessResult(0.5, 0.0, np.zeros((1, 3))).ratio   # the samples span no area
    inf
    >>> from aura_ums.uncertainty import Pose, TerrainTable
    >>> start = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.0, 0.0)
    >>> still = growth_tightness(start, TurnAndRun(0.0, 0.0), TerrainTable.default()["tile"],
    ...                          np.random.default_rng(0), samples=50)
    >>> still.map_area, still.sample_hull_area, still.ratio, still.samples.shape   # no motion
    (0.0, 0.0, 1.0, (50, 3))
    """

    map_area: float
    sample_hull_area: float
    samples: NDArray[np.float64]

    @property
    def ratio(self) -> float:
        """``map_area / sample_hull_area`` (>= 1 for a sound bound; inf for a zero hull)."""
        if self.sample_hull_area <= 0.0:
            return float("inf") if self.map_area > 0.0 else 1.0
        return self.map_area / self.sample_hull_area


def growth_tightness(
    start: SpatialUncertaintyMap,
    command: TurnAndRun,
    terrain: TerrainStats,
    rng: np.random.Generator,
    *,
    samples: int = 20_000,
    sigmas: float = 3.0,
) -> TightnessResult:
    """Compare one grown map's area with the hull of ``samples`` truncated outcomes.

    Examples
    --------
    >>> from aura_ums.uncertainty import Pose, TerrainTable
    >>> start = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.0, 0.0)
    >>> result = growth_tightness(start, TurnAndRun(0.8, 9.0), TerrainTable.default()["tile"],
    ...                           np.random.default_rng(0), samples=5000)
    >>> 1.0 <= result.ratio < 2.0
    True
    """
    _check_start(start)
    sample_count(samples, "samples")
    check_rng(rng)
    grown = start.grow(command, terrain, sigmas=sigmas)
    state = start.sample_poses(samples, rng)
    outcomes = terrain.sample_motions(state, command, rng, truncate=sigmas)
    hull = convex_hull(outcomes[:, :2])
    return TightnessResult(grown.area, polygon_area(hull), outcomes)


def _check_start(start: object) -> None:
    if not isinstance(start, SpatialUncertaintyMap):
        raise InputError(f"start: expected a SpatialUncertaintyMap, got {type(start).__name__}")
