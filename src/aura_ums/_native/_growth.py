"""Growth by turn-and-run commands: the numpy reference and the compiled kernel behind one call.

Every bound here holds for every outcome of the generative model of
``TerrainStats.sample_motion`` whose standard normals satisfy |z| <= sigmas. The numpy
functions are the specification; ``growth.c`` repeats them operation for operation.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import NamedTuple, Protocol

import numpy as np
from numpy.typing import NDArray

from aura_ums._native import _extension
from aura_ums._native._extension import points_view
from aura_ums.geometry import minkowski_sum, outer_annular_sector, outer_disk, simplify_outer, wrap_angle

if _extension.BUILT:
    from aura_ums._native._kernels import grow_commands as _compiled_grow_commands

Array = NDArray[np.float64]

#: Sides of the outer polygon of the skitter disk.
SKITTER_SIDES = 8


class MotionModel(Protocol):
    """The terrain statistics growth reads (:class:`~aura_ums.uncertainty.TerrainStats` has them)."""

    @property
    def translation_loss(self) -> float:
        """Mean translational loss, fraction."""

    @property
    def translation_inertial_loss(self) -> float:
        """Fixed loss per move, metres."""

    @property
    def translation_sd(self) -> float:
        """Standard deviation of the translational error, fraction of the distance."""

    @property
    def drift(self) -> float:
        """Bound on the heading change per metre run, rad/m."""

    @property
    def rotation_loss(self) -> float:
        """Mean rotational loss, fraction."""

    @property
    def rotation_sd(self) -> float:
        """Standard deviation of the rotational error, fraction of the turn."""

    @property
    def skitter(self) -> float:
        """Mean translation per radian turned, m/rad."""

    @property
    def skitter_sd(self) -> float:
        """Its standard deviation, m/rad."""


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

    Examples
    --------
    >>> from aura_ums.uncertainty import TerrainTable
    >>> concrete = TerrainTable.default()["concrete"]
    >>> b = motion_bounds(concrete, 0.5, 2.0, 3.0)
    >>> b.turn_min <= b.turn_mean <= b.turn_max, b.chord_min <= b.run_min <= b.run_mean <= b.run_max
    (True, True)
    >>> round(b.turn_min, 3), b.turn_max, b.run_max   # never beyond the command itself
    (0.445, 0.5, 2.0)
    >>> left, right = motion_bounds(concrete, -0.5, 2.0, 3.0)[:2]   # a clockwise turn: still ordered
    >>> left, round(right, 3)
    (-0.5, -0.445)
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


class Grown(NamedTuple):
    """A map after a run of growths, as plain numbers.

    Attributes
    ----------
    vertices : ndarray, shape (m, 2)
        The polygon, counter-clockwise, metres; read-only when compiled.
    x, y : float
        The most probable position, metres.
    heading : float
        The most probable heading, radians, not wrapped (as ``HeadingWedge`` wraps it).
    cw, ccw : float
        The wedge's clockwise and counter-clockwise extents, radians.
    """

    vertices: Array
    x: float
    y: float
    heading: float
    cw: float
    ccw: float


def _clip(value: float, lo: float, hi: float) -> float:
    return lo if value < lo else hi if value > hi else value


def motion_bounds(terrain: MotionModel, turn: float, run: float, sigmas: float) -> MotionBounds:
    """Return the bounds of a command's outcome at ``sigmas`` standard deviations.

    Parameters
    ----------
    terrain : MotionModel
        The terrain's statistics.
    turn, run : float
        The commanded turn (radians) and run (metres, >= 0).
    sigmas : float
        Standard deviations bounded, > 0.

    Examples
    --------
    >>> from aura_ums.uncertainty import TerrainTable
    >>> b = motion_bounds(TerrainTable.default()["concrete"], 0.0, 0.0, 3.0)
    >>> (b.run_max, b.skitter_radius, b.turn_min, b.turn_max)   # a zero-length command
    (0.0, 0.0, 0.0, 0.0)
    """
    rotation_kept = 1.0 - terrain.rotation_loss
    rotation_spread = sigmas * terrain.rotation_sd
    fraction_lo = _clip(rotation_kept - rotation_spread, 0.0, 1.0)
    fraction_hi = _clip(rotation_kept + rotation_spread, 0.0, 1.0)
    fraction_mean = _clip(rotation_kept, 0.0, 1.0)
    a, b = turn * fraction_lo, turn * fraction_hi
    run_kept = 1.0 - terrain.translation_loss
    run_spread = sigmas * terrain.translation_sd
    inertial = terrain.translation_inertial_loss
    run_lo = _clip(run * (run_kept - run_spread) - inertial, 0.0, run)
    run_hi = _clip(run * (run_kept + run_spread) - inertial, 0.0, run)
    run_mean = _clip(run * run_kept - inertial, 0.0, run)
    drift = terrain.drift
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
        skitter_radius=abs(turn) * max(0.0, terrain.skitter + sigmas * terrain.skitter_sd),
        drift_max=drift_max,
    )


def grow_polygon(
    vertices: Array, heading_lo: float, heading_hi: float, bounds: MotionBounds, max_vertices: int
) -> Array:
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
        Cap on the result's vertex count (>= 3); a motion-free command keeps the input.

    Returns
    -------
    ndarray, shape (m, 2)
        ``P + skitter disk + hull(run endpoints)``, counter-clockwise, arcs replaced by
        outer polygons, then an outer polygon of at most ``max_vertices`` vertices.

    Examples
    --------
    >>> point = np.array([[3.0, 4.0]])
    >>> straight = MotionBounds(0.0, 0.0, 0.0, 1.0, 2.0, 1.5, 1.0, 0.0, 0.0)
    >>> grow_polygon(point, 0.0, 0.0, straight, 64).tolist()   # a segment along +x
    [[4.0, 4.0], [5.0, 4.0]]
    >>> still = MotionBounds(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    >>> grow_polygon(point, 0.0, 0.0, still, 64) is point      # no motion: the very input
    True
    """
    parts = [vertices]
    if bounds.run_max > 0.0:
        # Run endpoints: chords of length chord_min..run_max whose direction is the
        # post-turn heading plus half the arc's heading change.
        start = heading_lo + bounds.turn_min - bounds.drift_max / 2.0
        stop = heading_hi + bounds.turn_max + bounds.drift_max / 2.0
        if heading_hi - heading_lo >= math.tau:
            stop = start + math.tau
        parts.append(outer_annular_sector(bounds.chord_min, bounds.run_max, start, stop))
    if bounds.skitter_radius > 0.0:
        parts.append(outer_disk(np.zeros(2), bounds.skitter_radius, SKITTER_SIDES))
    if len(parts) == 1:
        return vertices
    grown = minkowski_sum(*parts)
    if len(grown) > max_vertices:
        grown = simplify_outer(grown, max_vertices)
    return grown


def grow_wedge(center: float, cw: float, ccw: float, bounds: MotionBounds) -> tuple[float, float, float]:
    """Return the new (centre, cw, ccw) of a heading wedge after a command, radians.

    The centre moves by the mean turn (not wrapped); the extents take the range of the
    actual turn asymmetrically (a counter-clockwise turn that falls short widens the
    clockwise side) and widen by the run's drift on both sides; a wedge of 2 pi or more
    becomes the full circle (pi, pi).
    """
    new_center = center + bounds.turn_mean
    new_cw = cw + (bounds.turn_mean - bounds.turn_min) + bounds.drift_max
    new_ccw = ccw + (bounds.turn_max - bounds.turn_mean) + bounds.drift_max
    if new_cw + new_ccw >= math.tau:
        return new_center, math.pi, math.pi
    return new_center, new_cw, new_ccw


def grow_commands_reference(
    vertices: Array,
    x: float,
    y: float,
    heading: float,
    cw: float,
    ccw: float,
    terrain: MotionModel,
    sigmas: float,
    commands: Sequence[float],
    max_vertices: int,
) -> Grown:
    """Grow a map by each (turn, run) command in turn, on one terrain.

    The numpy reference, the specification ``growth.c`` follows: ``aura_ums._native.grow_commands``
    is this function, or :func:`grow_commands_compiled` when the kernels run compiled.

    For each command: :func:`motion_bounds`, then :func:`grow_polygon`, :func:`grow_wedge`
    and the centre moved by the mean run along the new most probable heading.

    Parameters
    ----------
    vertices : ndarray, shape (n, 2)
        The polygon, counter-clockwise, metres, finite.
    x, y : float
        The most probable position, metres.
    heading : float
        The most probable heading, radians, in (-pi, pi].
    cw, ccw : float
        The wedge's extents, radians, >= 0.
    terrain : MotionModel
        The terrain's statistics.
    sigmas : float
        Standard deviations bounded, > 0.
    commands : sequence of float
        Turn (radians) and run (metres, >= 0) of each command, flat: turn, run, turn, ...
    max_vertices : int
        Cap on the polygon's vertex count, >= 3: every grown polygon has at most that many.

    Returns
    -------
    Grown
        The grown map; the input itself (and ``heading`` unchanged) for no commands.

    Examples
    --------
    >>> from aura_ums.uncertainty import TerrainTable
    >>> from aura_ums import _native
    >>> point, tile = np.array([[0.0, 0.0]]), TerrainTable.default()["tile"]
    >>> grown = _native.grow_commands(point, 0.0, 0.0, 0.0, 0.0, 0.0, tile, 3.0, [0.0, 2.0], 8)
    >>> len(grown.vertices) <= 8, round(grown.x, 3), grown.heading
    (True, 1.95, 0.0)
    >>> _native.grow_commands(point, 0.0, 0.0, 3.0, 0.1, 0.1, tile, 3.0, [], 8).heading   # no commands
    3.0
    """
    if len(commands) % 2:
        raise ValueError(f"commands: expected (turn, run) pairs, got {len(commands)} numbers")
    unwrapped = heading
    for index in range(0, len(commands), 2):
        bounds = motion_bounds(terrain, commands[index], commands[index + 1], sigmas)
        heading_lo = heading - cw
        vertices = grow_polygon(vertices, heading_lo, heading_lo + cw + ccw, bounds, max_vertices)
        unwrapped, cw, ccw = grow_wedge(heading, cw, ccw, bounds)
        x, y = x + bounds.run_mean * math.cos(unwrapped), y + bounds.run_mean * math.sin(unwrapped)
        heading = wrap_angle(unwrapped)
    return Grown(vertices, x, y, unwrapped, cw, ccw)


def grow_commands_compiled(
    vertices: Array,
    x: float,
    y: float,
    heading: float,
    cw: float,
    ccw: float,
    terrain: MotionModel,
    sigmas: float,
    commands: Sequence[float],
    max_vertices: int,
) -> Grown:
    """Compiled :func:`grow_commands` (needs the extension module: ``_extension.BUILT``)."""
    if not vertices.flags.c_contiguous:  # polygons hold C-contiguous float64 arrays already
        vertices = np.ascontiguousarray(vertices, dtype=np.float64)
    raw, x, y, heading, cw, ccw = _compiled_grow_commands(
        vertices,
        x,
        y,
        heading,
        cw,
        ccw,
        terrain.rotation_loss,
        terrain.rotation_sd,
        terrain.translation_loss,
        terrain.translation_sd,
        terrain.translation_inertial_loss,
        terrain.drift,
        terrain.skitter,
        terrain.skitter_sd,
        sigmas,
        commands,
        max_vertices,
    )
    return Grown(points_view(raw), x, y, heading, cw, ccw)
