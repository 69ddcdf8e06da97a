"""The turn-and-run uncertainty transform on plain numbers and arrays.

Every bound here holds for every outcome of the generative model of
:meth:`TerrainStats.sample_motion` whose standard normals satisfy |z| <= sigmas.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from aura_ums.geometry import minkowski_sum, outer_annular_sector, outer_disk, simplify_outer
from aura_ums.geometry._angles import TWO_PI
from aura_ums.uncertainty._motion import TurnAndRun
from aura_ums.uncertainty._terrain import TerrainStats

_compiled_grow_polygon: Callable[..., bytes] | None
_compiled_grow_commands: Callable[..., tuple[bytes, float, float, float, float, float]] | None
try:  # the compiled kernels, when the build had a C compiler
    from aura_ums.geometry._kernels import grow_commands as _compiled_grow_commands
    from aura_ums.geometry._kernels import grow_polygon as _compiled_grow_polygon
except ImportError:  # pragma: no cover - exercised on machines without a compiler
    _compiled_grow_polygon = _compiled_grow_commands = None


def compiled_kernel() -> Callable[..., bytes] | None:
    """Return the compiled growth kernel, or None when the extension was not built."""
    return _compiled_grow_polygon


def compiled_sequence_kernel() -> Callable[..., tuple[bytes, float, float, float, float, float]] | None:
    """Return the compiled kernel of a run of growths on one terrain, or None when not built."""
    return _compiled_grow_commands


#: Largest vertex count a grown map keeps; beyond it an outer approximation merges edges.
DEFAULT_MAX_VERTICES = 64

_SKITTER_SIDES = 8


def _clip(value: float, lo: float, hi: float) -> float:
    return lo if value < lo else hi if value > hi else value


class MotionBounds(NamedTuple):
    """Bounds on one turn-and-run outcome at a given number of standard deviations.

    Attributes
    ----------
    turn_min, turn_max : float
        Range of the actual turn, radians (ordered, so ``turn_min <= turn_max``).
    turn_mean : float
        Turn at z1 = 0, radians: the update of the most probable heading.
    run_min, run_max : float
        Range of the actual run length along its arc, metres.
    run_mean : float
        Run at z3 = 0, metres: the update of the most probable position.
    chord_min : float
        Smallest straight-line distance from the run's start to its end, metres.
    skitter_radius : float
        Largest skitter displacement during the turn, metres.
    drift_max : float
        Largest heading change during the run, radians, either side.
    """

    turn_min: float
    turn_max: float
    turn_mean: float
    run_min: float
    run_max: float
    run_mean: float
    chord_min: float
    skitter_radius: float
    drift_max: float


def motion_bounds(stats: TerrainStats, command: TurnAndRun, sigmas: float) -> MotionBounds:
    """Return the bounds of ``command``'s outcome on ``stats`` at ``sigmas`` standard deviations.

    Examples
    --------
    >>> from aura_ums.uncertainty import TerrainTable
    >>> b = motion_bounds(TerrainTable.default()["concrete"], TurnAndRun(0.0, 0.0), 3.0)
    >>> (b.run_max, b.skitter_radius, b.turn_min, b.turn_max)   # a zero-length command
    (0.0, 0.0, 0.0, 0.0)
    """
    turn, run = command.turn, command.run
    rotation_kept = 1.0 - stats.rotation_loss
    rotation_spread = sigmas * stats.rotation_sd
    fraction_lo = _clip(rotation_kept - rotation_spread, 0.0, 1.0)
    fraction_hi = _clip(rotation_kept + rotation_spread, 0.0, 1.0)
    fraction_mean = _clip(rotation_kept, 0.0, 1.0)
    a, b = turn * fraction_lo, turn * fraction_hi
    run_kept = 1.0 - stats.translation_loss
    run_spread = sigmas * stats.translation_sd
    inertial = stats.translation_inertial_loss
    run_lo = _clip(run * (run_kept - run_spread) - inertial, 0.0, run)
    run_hi = _clip(run * (run_kept + run_spread) - inertial, 0.0, run)
    run_mean = _clip(run * run_kept - inertial, 0.0, run)
    drift = stats.drift
    drift_max = drift * run_hi
    # The chord of an arc of length d turning by at most drift*d is at least
    # 2*sin(drift*d/2)/drift, which grows with d while drift*d <= pi.
    if drift == 0.0:
        chord_min = run_lo
    elif drift_max <= math.pi:
        chord_min = 2.0 * math.sin(drift * run_lo / 2.0) / drift
    else:
        chord_min = 0.0
    return MotionBounds(
        turn_min=min(a, b),
        turn_max=max(a, b),
        turn_mean=turn * fraction_mean,
        run_min=run_lo,
        run_max=run_hi,
        run_mean=run_mean,
        chord_min=chord_min,
        skitter_radius=abs(turn) * max(0.0, stats.skitter + sigmas * stats.skitter_sd),
        drift_max=drift_max,
    )


def grow_polygon(
    vertices: NDArray[np.float64],
    heading_lo: float,
    heading_hi: float,
    bounds: MotionBounds,
    max_vertices: int = DEFAULT_MAX_VERTICES,
) -> NDArray[np.float64]:
    """Return the outer polygon of every position reachable from a polygon-and-wedge map.

    Parameters
    ----------
    vertices : ndarray, shape (n, 2)
        Counter-clockwise convex polygon of start positions, metres.
    heading_lo, heading_hi : float
        Start headings run counter-clockwise from ``heading_lo`` to ``heading_hi``,
        radians, unwrapped (``heading_hi - heading_lo`` is the wedge's width).
    bounds : MotionBounds
        Bounds of the command's outcome.
    max_vertices : int
        Cap on the result's vertex count.

    Returns
    -------
    ndarray, shape (m, 2)
        The polygon ``P + skitter disk + hull(run endpoints)``, counter-clockwise.
    """
    if _compiled_grow_polygon is not None:
        # Polygons hold C-contiguous float64 arrays already; converting costs a call.
        grown = _compiled_grow_polygon(
            vertices if vertices.flags.c_contiguous else np.ascontiguousarray(vertices, dtype=np.float64),
            heading_lo,
            heading_hi,
            bounds.turn_min,
            bounds.turn_max,
            bounds.drift_max,
            bounds.chord_min,
            bounds.run_max,
            bounds.skitter_radius,
            max_vertices,
        )
        # Bytes are immutable, so the array is read-only as map values must be.
        return np.frombuffer(grown, dtype=np.float64).reshape(-1, 2)
    return grow_polygon_reference(vertices, heading_lo, heading_hi, bounds, max_vertices)


def grow_polygon_reference(
    vertices: NDArray[np.float64],
    heading_lo: float,
    heading_hi: float,
    bounds: MotionBounds,
    max_vertices: int = DEFAULT_MAX_VERTICES,
) -> NDArray[np.float64]:
    """Pure-numpy :func:`grow_polygon`: the reference the compiled kernel is tested against."""
    parts = [vertices]
    if bounds.run_max > 0.0:
        # Run endpoints: chords of length chord_min..run_max whose direction is the
        # post-turn heading plus half the arc's heading change.
        start = heading_lo + bounds.turn_min - bounds.drift_max / 2.0
        stop = heading_hi + bounds.turn_max + bounds.drift_max / 2.0
        if heading_hi - heading_lo >= TWO_PI:
            stop = start + TWO_PI
        parts.append(outer_annular_sector(bounds.chord_min, bounds.run_max, start, stop))
    if bounds.skitter_radius > 0.0:
        parts.append(outer_disk(np.zeros(2), bounds.skitter_radius, _SKITTER_SIDES))
    if len(parts) == 1:
        return vertices
    grown = minkowski_sum(*parts)
    if len(grown) > max_vertices:
        grown = simplify_outer(grown, max_vertices)
    return grown


def grow_wedge(center: float, cw: float, ccw: float, bounds: MotionBounds) -> tuple[float, float, float]:
    """Return the new (centre, cw, ccw) of a heading wedge after a command.

    The centre moves by the mean turn; the extents take the range of the actual
    turn asymmetrically (a counter-clockwise turn that falls short widens the
    clockwise side) and widen by the run's drift on both sides.
    """
    new_center = center + bounds.turn_mean
    new_cw = cw + (bounds.turn_mean - bounds.turn_min) + bounds.drift_max
    new_ccw = ccw + (bounds.turn_max - bounds.turn_mean) + bounds.drift_max
    if new_cw + new_ccw >= TWO_PI:
        return new_center, math.pi, math.pi
    return new_center, new_cw, new_ccw
