"""Growth's public face: the default vertex cap and the bounds of one command.

The growth itself, its numpy reference and its compiled kernel, is in ``aura_ums._native``;
:meth:`SpatialUncertaintyMap.grow` calls it.
"""

from __future__ import annotations

from aura_ums._native import MotionBounds as MotionBounds
from aura_ums._native import motion_bounds as _motion_bounds
from aura_ums._validate import SIGMAS
from aura_ums.errors import InputError
from aura_ums.uncertainty._motion import TurnAndRun
from aura_ums.uncertainty._terrain import TerrainStats

#: Largest vertex count a grown map keeps; beyond it an outer approximation merges edges.
DEFAULT_MAX_VERTICES = 64
#: Largest vertex cap where a cap sizes arrays (:func:`union_of_maps` takes that many supporting
#: directions; a cap of 10**12 asked for 7.28 TiB), and the manager settings' ``max_vertices``.
MAX_VERTICES = 100_000


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
    >>> motion_bounds(TerrainTable.default()["concrete"], TurnAndRun(0.0, 1.0), float("nan"))
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: sigmas: expected a finite number, got nan
    """
    if not isinstance(stats, TerrainStats):
        raise InputError(f"stats: expected a TerrainStats, got {type(stats).__name__}")
    if not isinstance(command, TurnAndRun):
        raise InputError(f"command: expected a TurnAndRun, got {type(command).__name__}")
    return _motion_bounds(stats, command.turn, command.run, SIGMAS.check(sigmas, "sigmas"))
