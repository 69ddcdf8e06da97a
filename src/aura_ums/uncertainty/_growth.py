"""Growth's public face: the default vertex cap and the bounds of one command.

The growth itself, its numpy reference and its compiled kernel, is in ``aura_ums._native``;
:meth:`SpatialUncertaintyMap.grow` calls it.
"""

from __future__ import annotations

from aura_ums._native import MotionBounds as MotionBounds
from aura_ums._native import motion_bounds as _motion_bounds
from aura_ums.uncertainty._motion import TurnAndRun
from aura_ums.uncertainty._terrain import TerrainStats

#: Largest vertex count a grown map keeps; beyond it an outer approximation merges edges.
DEFAULT_MAX_VERTICES = 64


def motion_bounds(stats: TerrainStats, command: TurnAndRun, sigmas: float) -> MotionBounds:
    """Return the bounds of ``command``'s outcome on ``stats`` at ``sigmas`` standard deviations.

    Every outcome of :meth:`TerrainStats.sample_motion` whose standard normals satisfy
    |z| <= sigmas lies within them.

    Examples
    --------
    >>> from aura_ums.uncertainty import TerrainTable
    >>> b = motion_bounds(TerrainTable.default()["concrete"], TurnAndRun(0.0, 0.0), 3.0)
    >>> (b.run_max, b.skitter_radius, b.turn_min, b.turn_max)   # a zero-length command
    (0.0, 0.0, 0.0, 0.0)
    """
    return _motion_bounds(stats, command.turn, command.run, sigmas)
