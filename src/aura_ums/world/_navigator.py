"""The navigator: routes through the meadow graph, and terrain along a straight run.

:func:`plan_route` turns a start and a goal into straight legs through the portals between
meadows (the paper's "linear piecewise segments"). :func:`split_run` cuts one straight run
where it crosses meadow boundaries, and :func:`commands_for` turns a turn-and-run command
into one growth step per meadow, so that :meth:`SpatialUncertaintyMap.grow` applies each
meadow's terrain statistics to the part of the run made on it.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from itertools import pairwise

import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray
from shapely.geometry.base import BaseGeometry

from aura_ums._validate import (
    SIGMAS,
    finite_float,
    integer_at_least,
    items_of,
    nonnegative_float,
    points_array,
    read_only,
    sequence_of,
)
from aura_ums.errors import InputError, OutsideMapError
from aura_ums.geometry import POSITION_TOLERANCE, outer_annular_sector
from aura_ums.uncertainty import Pose, SpatialUncertaintyMap, TerrainStats, TerrainTable, TurnAndRun
from aura_ums.world._ltm import Meadow, MeadowMap

#: Stretches of a run shorter than this (m) are rounding, not a meadow crossed.
RUN_TOLERANCE = 1e-9

#: Maps with more meadows than this find those near a run through their tree, not a scan.
_SCAN_LIMIT = 32

_START = -1
_GOAL = -2


def _point(value: ArrayLike, name: str) -> NDArray[np.float64]:
    array = points_array(value, name, min_rows=1)
    if array.shape != (1, 2):
        raise InputError(f"{name}: expected one (x, y) point, got shape {array.shape}")
    return np.array(array[0], dtype=np.float64)


def _xy(point: NDArray[np.float64]) -> str:
    return f"({float(point[0])!r}, {float(point[1])!r})"


@dataclass(frozen=True, slots=True, eq=False, init=False)
class Route:
    """A route of straight legs through the meadow map.

    Parameters
    ----------
    waypoints : array_like, shape (n, 2)
        Start, the portal midpoints crossed, goal; metres; no two consecutive equal.
    meadow_ids : sequence of str
        The meadow containing each leg (``n - 1`` ids); a route of one waypoint (start
        equals goal) has no leg and names the one meadow it is in.

    Examples
    --------
    >>> route = Route([(0, 0), (3, 4), (3, 10)], ["a", "b"])
    >>> route.length, route.legs.shape
    (11.0, (2, 2, 2))
    >>> Route([(1, 1)], ["a"]).length        # start == goal: no leg
    0.0
    """

    waypoints: NDArray[np.float64]
    meadow_ids: tuple[str, ...]

    def __init__(self, waypoints: ArrayLike, meadow_ids: tuple[str, ...] | list[str]) -> None:
        points = points_array(waypoints, "waypoints", min_rows=1)
        ids = items_of(meadow_ids, "meadow_ids", "a sequence of meadow ids")
        if len(points) == 1 and len(ids) != 1:
            raise InputError(
                f"meadow_ids: expected 1 id (a route of one waypoint, no leg, names the meadow it is in), "
                f"got {len(ids)}"
            )
        if len(points) > 1 and len(ids) != len(points) - 1:
            raise InputError(f"meadow_ids: expected {len(points) - 1} ids (one per leg), got {len(ids)}")
        for index, ident in enumerate(ids):
            if not isinstance(ident, str) or not ident:
                raise InputError(f"meadow_ids[{index}]: expected a non-empty string, got {ident!r}")
        if len(points) > 1 and np.any(np.all(points[1:] == points[:-1], axis=1)):
            raise InputError("waypoints: expected no two consecutive waypoints equal, got a repeat")
        object.__setattr__(self, "waypoints", read_only(points.copy()))
        object.__setattr__(self, "meadow_ids", ids)

    @property
    def legs(self) -> NDArray[np.float64]:
        """The legs as a read-only ``(n - 1, 2, 2)`` array: ``legs[i] = (start_i, end_i)``."""
        legs = np.stack([self.waypoints[:-1], self.waypoints[1:]], axis=1)
        return read_only(legs)

    @property
    def leg_lengths(self) -> NDArray[np.float64]:
        """Length of each leg, metres."""
        return np.asarray(np.hypot(*(self.waypoints[1:] - self.waypoints[:-1]).T), dtype=np.float64)

    @property
    def length(self) -> float:
        """Total length, metres."""
        return float(self.leg_lengths.sum())

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Route):
            return NotImplemented
        return self.meadow_ids == other.meadow_ids and np.array_equal(self.waypoints, other.waypoints)

    def __repr__(self) -> str:
        return f"Route({len(self.waypoints) - 1} legs, {self.length:.6g} m, meadows {list(self.meadow_ids)})"

    __hash__ = None  # type: ignore[assignment]


def plan_route(meadow_map: MeadowMap, start: ArrayLike, goal: ArrayLike) -> Route:
    """Plan a shortest route of straight legs through portal midpoints (A* with networkx).

    The search runs on the portal graph (the line graph of meadow adjacency): its nodes
    are the midpoints of the portals, start and goal; two of them are joined when one
    meadow holds both, by a straight leg inside that (convex) meadow, weighted by its
    length. The heuristic is the straight-line distance to the goal, so the route is the
    shortest among those through portal midpoints. Every leg lies in one meadow, so the
    route stays in free space.

    Parameters
    ----------
    meadow_map : MeadowMap
        The map.
    start, goal : array_like, shape (2,)
        Points (x, y) in metres, each inside some meadow.

    Returns
    -------
    Route
        Waypoints start, portal midpoints, goal; the meadow of each leg.

    Raises
    ------
    InputError
        When start or goal lies outside every meadow, or no chain of adjacent meadows
        joins them.

    Examples
    --------
    >>> from aura_ums.world import make_grid_world
    >>> world = make_grid_world(3, 3, cell=5.0)
    >>> route = plan_route(world, (2.5, 2.5), (12.5, 2.5))
    >>> route.waypoints.tolist(), route.meadow_ids
    ([[2.5, 2.5], [5.0, 2.5], [10.0, 2.5], [12.5, 2.5]], ('cell_0_0', 'cell_0_1', 'cell_0_2'))
    >>> plan_route(world, (2.5, 2.5), (40.0, 2.5))
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: goal: expected a point inside a meadow, got (40.0, 2.5)
    """
    if not isinstance(meadow_map, MeadowMap):
        raise InputError(f"meadow_map: expected a MeadowMap, got {type(meadow_map).__name__}")
    source = _point(start, "start")
    target = _point(goal, "goal")
    start_meadows = meadow_map.meadows_containing(float(source[0]), float(source[1]))
    if not start_meadows:
        raise InputError(f"start: expected a point inside a meadow, got {_xy(source)}")
    goal_meadows = meadow_map.meadows_containing(float(target[0]), float(target[1]))
    if not goal_meadows:
        raise InputError(f"goal: expected a point inside a meadow, got {_xy(target)}")
    goal_ids = {m.id for m in goal_meadows}
    for meadow in start_meadows:
        if meadow.id in goal_ids:
            if np.array_equal(source, target):
                return Route([source], [meadow.id])
            return Route([source, target], [meadow.id])

    positions: list[NDArray[np.float64]] = []
    by_meadow: dict[str, list[int]] = {m.id: [] for m in meadow_map.meadows}
    for a, b, segment in meadow_map.portals():
        node = len(positions)
        positions.append(0.5 * (segment[0] + segment[1]))
        by_meadow[a].append(node)
        by_meadow[b].append(node)
    points = {node: positions[node] for node in range(len(positions))}
    points[_START] = source
    points[_GOAL] = target

    # Imported here: networkx takes about a second to import, and only path planning needs it.
    import networkx as nx

    graph = nx.Graph()
    graph.add_nodes_from(points)
    for meadow_id, nodes in by_meadow.items():
        for i, u in enumerate(nodes):
            for v in nodes[i + 1 :]:
                graph.add_edge(u, v, weight=float(np.hypot(*(positions[u] - positions[v]))), meadow=meadow_id)
    for end, meadows in ((_START, start_meadows), (_GOAL, goal_meadows)):
        for meadow in meadows:
            for node in by_meadow[meadow.id]:
                if not graph.has_edge(end, node):
                    weight = float(np.hypot(*(points[end] - positions[node])))
                    graph.add_edge(end, node, weight=weight, meadow=meadow.id)

    def heuristic(u: int, v: int) -> float:
        return float(np.hypot(*(points[u] - points[v])))

    try:
        found: list[int] = [int(node) for node in nx.astar_path(graph, _START, _GOAL, heuristic, "weight")]
    except nx.NetworkXNoPath:
        raise InputError(
            f"goal: expected a point reachable from start through adjacent meadows, got "
            f"{_xy(target)} in {goal_meadows[0].id!r}, "
            f"not connected to {start_meadows[0].id!r}"
        ) from None
    waypoints = [points[found[0]]]
    meadow_ids: list[str] = []
    for u, v in pairwise(found):
        if np.array_equal(points[v], waypoints[-1]):
            continue  # start or goal exactly on a portal midpoint: no leg
        waypoints.append(points[v])
        meadow_ids.append(str(graph.edges[u, v]["meadow"]))
    if not meadow_ids:
        meadow_ids.append(start_meadows[0].id)
    return Route(np.array(waypoints), meadow_ids)


@dataclass(frozen=True, slots=True)
class RunPiece:
    """One part of a straight run, made in one meadow on one terrain.

    Parameters
    ----------
    distance : float
        Length of the part, metres, >= 0.
    terrain : str
        The meadow's terrain.
    meadow_id : str
        The meadow.

    Examples
    --------
    >>> RunPiece(2.5, "grass", "lawn")
    RunPiece(distance=2.5, terrain='grass', meadow_id='lawn')
    >>> RunPiece(-1.0, "grass", "lawn")
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: RunPiece.distance: expected a non-negative number, got -1.0
    """

    distance: float
    terrain: str
    meadow_id: str

    def __post_init__(self) -> None:
        object.__setattr__(self, "distance", nonnegative_float(self.distance, "RunPiece.distance"))
        for name in ("terrain", "meadow_id"):
            value = getattr(self, name)
            if not isinstance(value, str) or not value:
                raise InputError(f"RunPiece.{name}: expected a non-empty string, got {value!r}")


def split_run(meadow_map: MeadowMap, start: ArrayLike, heading: float, distance: float) -> list[RunPiece]:
    """Cut a straight run where it crosses meadow boundaries, in order along the run.

    The run goes ``distance`` metres from ``start`` in direction ``heading`` (radians,
    counter-clockwise from +x). It is clipped against the (convex) meadows it meets;
    each maximal part inside one meadow is a piece. Consecutive pieces on the same terrain
    stay separate when their meadows differ (one piece per meadow crossed). Where the run
    follows a boundary shared by two meadows, the first in map order takes it.

    Parts of the run outside every meadow (a gap, or the run leaving the map) are added to
    the piece before them: the robot is taken to stay on the terrain of the last meadow it
    was in. A run that *starts* outside every meadow takes the first meadow it enters.

    Parameters
    ----------
    meadow_map : MeadowMap
        The map.
    start : array_like, shape (2,)
        Where the run starts, metres.
    heading : float
        Direction of the run, radians.
    distance : float
        Length of the run, metres, >= 0. A zero-length run gives one zero piece in the
        start meadow.

    Returns
    -------
    list of RunPiece
        Pieces in order; their distances add up to ``distance`` (to rounding).

    Raises
    ------
    InputError
        When the run meets no meadow at all.

    Examples
    --------
    >>> from aura_ums.world import make_grid_world
    >>> world = make_grid_world(1, 3, cell=5.0)      # terrains concrete, grass, gravel
    >>> [(p.distance, p.terrain) for p in split_run(world, (2.5, 2.5), 0.0, 10.0)]
    [(2.5, 'concrete'), (5.0, 'grass'), (2.5, 'gravel')]
    >>> [(p.distance, p.meadow_id) for p in split_run(world, (2.5, 2.5), 0.0, 0.0)]
    [(0.0, 'cell_0_0')]
    """
    if not isinstance(meadow_map, MeadowMap):
        raise InputError(f"meadow_map: expected a MeadowMap, got {type(meadow_map).__name__}")
    origin = _point(start, "start")
    angle = finite_float(heading, "heading")
    length = nonnegative_float(distance, "distance")
    return _split(meadow_map, origin, angle, length, "start, heading, distance")


def _split(
    meadow_map: MeadowMap, origin: NDArray[np.float64], angle: float, length: float, names: str
) -> list[RunPiece]:
    """:func:`split_run` of checked arguments; a run off the map is refused naming the caller's ``names``."""
    if length <= RUN_TOLERANCE:
        # Too short to cut by meadow boundaries: one piece on the start meadow's terrain.
        meadow = meadow_map.meadow_at(float(origin[0]), float(origin[1]))
        if meadow is not None:
            return [RunPiece(length, meadow.terrain, meadow.id)]
        if length == 0.0:
            raise _outside_every_meadow(names, origin, angle, length)
    spans = _run_spans(meadow_map, float(origin[0]), float(origin[1]), angle, length)
    if not spans:
        raise _outside_every_meadow(names, origin, angle, length)
    cuts = sorted({0.0, length, *(lo for lo, _, _ in spans), *(hi for _, hi, _ in spans)})
    owners: list[int | None] = []
    for lo, hi in pairwise(cuts):
        owner = None
        if hi - lo > RUN_TOLERANCE:
            covering = [i for a, b, i in spans if a <= lo + RUN_TOLERANCE and b >= hi - RUN_TOLERANCE]
            owner = min(covering) if covering else None
        owners.append(owner)
    first = next(owner for owner in owners if owner is not None)
    filled: list[int] = []
    for owner in owners:
        filled.append(owner if owner is not None else (filled[-1] if filled else first))
    pieces: list[RunPiece] = []
    begin = 0.0
    for k, owner in enumerate(filled):
        if k + 1 == len(filled) or filled[k + 1] != owner:
            end = cuts[k + 1]
            meadow = meadow_map.meadows[owner]
            pieces.append(RunPiece(end - begin, meadow.terrain, meadow.id))
            begin = end
    return pieces


def _run_spans(
    meadow_map: MeadowMap, x: float, y: float, heading: float, length: float
) -> list[tuple[float, float, int]]:
    """Return the parts of a run inside each meadow: ``(from, to, meadow index)``, metres along it.

    Meadows are convex, so each part is one interval, found by clipping the run against
    the meadow's edges (Cyrus-Beck) on plain floats: a run is split at every growth step,
    and this is far cheaper than building shapely geometries for it. Boundaries belong to
    the meadow (closed sets), as in a shapely intersection.
    """
    dx, dy = math.cos(heading), math.sin(heading)
    ex, ey = x + length * dx, y + length * dy
    left, right, bottom, top = min(x, ex), max(x, ex), min(y, ey), max(y, ey)
    spans: list[tuple[float, float, int]] = []
    clip = meadow_map._clip
    candidates: Iterable[int] = range(len(clip))
    if len(clip) > _SCAN_LIMIT:  # a large map: let its tree pick the meadows near the run
        line = shapely.LineString([(x, y), (ex, ey)])
        candidates = sorted(int(i) for i in meadow_map._tree.query(line, predicate="intersects"))
    for index in candidates:
        xmin, ymin, xmax, ymax, edges = clip[index]
        if xmax < left or xmin > right or ymax < bottom or ymin > top:
            continue
        lo, hi = 0.0, length
        for ax, ay, ux, uy in edges:
            outside = ux * (x - ax) + uy * (y - ay)  # > 0: the start is outside this edge
            rate = ux * dx + uy * dy  # how fast the run moves outward
            if rate == 0.0:
                if outside > 0.0:
                    hi = -1.0
                    break
                continue
            t = -outside / rate
            if rate > 0.0:
                hi = min(hi, t)
            else:
                lo = max(lo, t)
            if lo > hi:
                break
        if hi - lo > RUN_TOLERANCE:
            spans.append((lo, hi, index))
    return spans


def commands_for(
    meadow_map: MeadowMap, pose: Pose, command: TurnAndRun, table: TerrainTable
) -> list[tuple[TurnAndRun, TerrainStats]]:
    """Split a turn-and-run command into one growth step per meadow crossed.

    The run is split (:func:`split_run`) along the commanded direction ``pose.heading +
    command.turn`` from ``(pose.x, pose.y)`` (typically the map's most probable pose).
    The turn happens in the start meadow, so the first step carries the turn and the first
    piece; each later piece is ``TurnAndRun(0.0, piece)`` with its own meadow's terrain.
    Parts outside every meadow count on the terrain of the meadow before them (see
    :func:`split_run`). This is the paper's split: growing through the steps in order
    applies each terrain's statistics to the most probable pose's part of the run. It is
    not a bound for the other poses of a map, whose runs cross boundaries elsewhere (and
    each step pays the fixed inertial loss again, which one true run does not):
    :func:`grow_through` grows soundly.

    Parameters
    ----------
    meadow_map : MeadowMap
        The map.
    pose : Pose
        Where the command starts (metres, radians).
    command : TurnAndRun
        The command.
    table : TerrainTable
        Statistics of the meadows' terrains.

    Returns
    -------
    list of (TurnAndRun, TerrainStats)
        The growth steps, in order; the runs add up to ``command.run``.

    Raises
    ------
    UnknownTerrainError
        When a meadow's terrain is not in ``table``.
    OutsideMapError
        When the run meets no meadow (or a run of length 0 starts outside every meadow).

    Examples
    --------
    >>> from aura_ums.uncertainty import Pose, TerrainTable, TurnAndRun
    >>> from aura_ums.world import make_grid_world
    >>> world, table = make_grid_world(1, 3), TerrainTable.default()
    >>> steps = commands_for(world, Pose(2.5, 2.5, 0.5), TurnAndRun(-0.5, 10.0), table)
    >>> [command for command, _ in steps]
    [TurnAndRun(turn=-0.5, run=2.5), TurnAndRun(turn=0.0, run=5.0), TurnAndRun(turn=0.0, run=2.5)]
    >>> steps[1][1] == table["grass"]
    True
    >>> commands_for(world, Pose(7.0, 2.5, 0.0), TurnAndRun(1.0, 0.0), table) == [
    ...     (TurnAndRun(1.0, 0.0), table["grass"])]                      # a turn only
    True
    """
    if not isinstance(pose, Pose):
        raise InputError(f"pose: expected a Pose, got {type(pose).__name__}")
    if not isinstance(table, TerrainTable):
        raise InputError(f"table: expected a TerrainTable, got {type(table).__name__}")
    if not isinstance(command, TurnAndRun):
        raise InputError(f"command: expected a TurnAndRun, got {type(command).__name__}")
    pieces = _split_for("pose, command", meadow_map, pose, command)
    return _steps(pieces, command, table)


def _steps(
    pieces: list[RunPiece], command: TurnAndRun, table: TerrainTable
) -> list[tuple[TurnAndRun, TerrainStats]]:
    """Return the growth steps of a command's run pieces: the turn with the first, then each run."""
    steps = [(TurnAndRun(command.turn, pieces[0].distance), table[pieces[0].terrain])]
    steps.extend((TurnAndRun(0.0, piece.distance), table[piece.terrain]) for piece in pieces[1:])
    return steps


def _outside_every_meadow(names: str, origin: NDArray[np.float64], angle: float, length: float) -> InputError:
    """Return the error of a run that meets no meadow, worded for the arguments ``names`` it came from.

    A run of length 0 names the first of them only (its start: no heading or distance matters),
    and is an :class:`InputError` (there is no run to grow elsewhere); a longer one an
    :class:`OutsideMapError`.
    """
    if length == 0.0:
        start = names.split(", ")[0]
        return InputError(
            f"{start}: expected a point inside a meadow for a zero-length run, got {_xy(origin)}"
        )
    return OutsideMapError(
        f"{names}: expected a run that meets a meadow, got one from {_xy(origin)} of {length!r} m at "
        f"heading {angle!r} outside every meadow"
    )


def _split_for(names: str, meadow_map: MeadowMap, pose: Pose, command: TurnAndRun) -> list[RunPiece]:
    """:func:`split_run` of a command from a pose, a run off the map worded for the caller's ``names``."""
    if not isinstance(meadow_map, MeadowMap):
        raise InputError(f"meadow_map: expected a MeadowMap, got {type(meadow_map).__name__}")
    return _split(meadow_map, np.array([pose.x, pose.y]), pose.heading + command.turn, command.run, names)


def grow_through(
    uncertainty_map: SpatialUncertaintyMap,
    meadow_map: MeadowMap,
    command: TurnAndRun,
    table: TerrainTable,
    *,
    sigmas: float = 3.0,
    max_vertices: int = 64,
) -> SpatialUncertaintyMap:
    """Grow a spatial uncertainty map by a command through the meadows its poses may cross.

    Every pose of the map may meet other meadows than the most probable one does, so the
    terrains are those of every meadow within reach: within the commanded run (plus the
    skitter of the turn) of the map's polygon. With one such meadow, the map grows as
    :meth:`~aura_ums.uncertainty.SpatialUncertaintyMap.grow` on its terrain. With several,
    it grows on their outer terrain (:func:`outer_terrain`), which bounds the motion
    whatever meadows a true run crosses and wherever it crosses them: the true robot draws
    each piece on its own meadow's terrain (:class:`~aura_ums.sim.SimulatedRobot`), and
    loses each piece's inertial loss. The first metres that every true run spends in the
    meadow every pose stands in grow on that meadow's terrain; their growth also loses
    whatever of the pieces' losses the rest of the run is too short to lose. The
    paper splits the run where the most probable pose's run crosses a boundary
    (:func:`commands_for`); that is not sound for the poses whose runs cross elsewhere.
    ``sigmas`` and ``max_vertices`` (whose defaults are ``grow``'s) go to the growth.

    Raises
    ------
    UnknownTerrainError
        When a meadow's terrain is not in ``table``.
    OutsideMapError
        When no meadow is within reach of the map.

    Examples
    --------
    >>> from aura_ums.uncertainty import Pose, SpatialUncertaintyMap, TerrainTable, TurnAndRun
    >>> from aura_ums.world import make_grid_world
    >>> start = SpatialUncertaintyMap.from_pose(Pose(2.5, 2.5, 0.0), 0.1, 0.01)
    >>> grown = grow_through(start, make_grid_world(1, 3), TurnAndRun(0.0, 10.0), TerrainTable.default())
    >>> bool(grown.area > start.area)
    True
    >>> far = SpatialUncertaintyMap.from_pose(Pose(50.0, 50.0, 0.0), 0.1, 0.01)   # off the map
    >>> table = TerrainTable.default()
    >>> grow_through(far, make_grid_world(1, 3), TurnAndRun(0.0, 1.0), table)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.OutsideMapError: uncertainty_map, command: expected a map within reach of a meadow, ...
    """
    bound = _checked_growth_arguments(meadow_map, uncertainty_map, command, table, sigmas)
    meadow, prefix = _first_meadow_run(meadow_map, uncertainty_map, command, table, bound)
    if meadow is not None and meadow_map._meadow_index[meadow.id] in meadow_map._overlapping:
        # A meadow earlier in map order may take part of it: a run in it can leave it and come back.
        meadow, prefix = None, 0.0
    if meadow is not None and prefix >= command.run:
        # Every true run stays in the one meadow every pose stands in (most growths).
        return uncertainty_map.grow(command, table[meadow.terrain], sigmas=bound, max_vertices=max_vertices)
    inside = None if meadow is None else meadow_map._meadow_index[meadow.id]
    near, terrains, covered = _reach(meadow_map, uncertainty_map, command, table, bound, inside)
    if not near:
        raise OutsideMapError(
            f"uncertainty_map, command: expected a map within reach of a meadow, got one whose polygon "
            f"(centre {_xy(uncertainty_map.center)}) is more than the run of {command.run!r} m and its "
            "skitter from every meadow"
        )
    if covered and len(near) == 1:
        return uncertainty_map.grow(command, terrains[0], sigmas=bound, max_vertices=max_vertices)
    pieces = _most_pieces(meadow_map, uncertainty_map, command, near, terrains, bound)
    if meadow is None or prefix <= RUN_TOLERANCE:
        terrain = _outer_terrain(terrains, pieces, command, bound)
        return uncertainty_map.grow(command, terrain, sigmas=bound, max_vertices=max_vertices)
    # Every true run stays in the meadow it starts in for its first `prefix` metres: that
    # part grows on the meadow's terrain, the rest on the outer terrain of every meadow in
    # reach, which pays the inertial losses. A true piece in that meadow is at least `prefix`
    # long and loses its loss as a whole: the first part runs at least its least kept
    # fraction less that loss (the robot may have lost it all before the next meadow's
    # drift takes over), and at most its largest kept fraction, no more than its length.
    rest = TurnAndRun(0.0, command.run - prefix)
    terrain = _outer_terrain(terrains, pieces, rest, bound, first=False)
    own = table[meadow.terrain]
    low, high = _kept_interval([own], bound)
    shortest = max(0.0, prefix * low - own.translation_inertial_loss)
    own = _running(own, prefix, shortest, prefix * min(1.0, high), bound)
    first = uncertainty_map.grow(
        TurnAndRun(command.turn, prefix), own, sigmas=bound, max_vertices=max_vertices
    )
    return first.grow(rest, terrain, sigmas=bound, max_vertices=max_vertices)


def _most_pieces(
    meadow_map: MeadowMap,
    uncertainty_map: SpatialUncertaintyMap,
    command: TurnAndRun,
    near: Sequence[Meadow],
    terrains: Sequence[TerrainStats],
    sigmas: float,
) -> int:
    """Return how many pieces the meadows in reach may cut a true run into (each loses its inertial loss).

    A straight run cuts each convex meadow once, and its parts outside every meadow join the
    piece before them: one piece per meadow. But a run along a boundary two meadows share
    alternates between them (the first in map order takes the shared part): at most one
    piece per interval between the meadows' ``2 n`` cut points. A true run can follow an edge
    only if a heading of the turned wedge is parallel to it and a start (a vertex of the
    polygon, moved by the turn's skitter) can lie on its line.
    """
    count = len(near)
    if command.run <= 0.0 or any(meadow_map._meadow_index[m.id] in meadow_map._overlapping for m in near):
        return 2 * count + 1
    start, stop = _turned_headings(uncertainty_map, command, terrains, sigmas)
    width = stop - start + 2.0 * _PARALLEL
    reach = _skitter(command, terrains, sigmas) + POSITION_TOLERANCE
    planes = np.concatenate([meadow_map._halfplanes[meadow_map._meadow_index[m.id]] for m in near])
    # an edge runs along its outward normal turned by a quarter turn, either way
    parallel = np.mod(planes[:, 3] + math.pi / 2.0 - start + _PARALLEL, math.pi) <= width
    if not np.any(parallel):
        return count
    offsets = uncertainty_map.polygon.vertices @ planes[parallel, :2].T  # (vertex, edge), metres
    offset = planes[parallel, 2]
    on_line = (offsets.min(axis=0) - reach <= offset) & (offset <= offsets.max(axis=0) + reach)
    return 2 * count + 1 if np.any(on_line) else count


#: Radians: headings this close to an edge's direction count as running along it.
_PARALLEL = 1e-9


def _kept_interval(terrains: Sequence[TerrainStats], sigmas: float) -> tuple[float, float]:
    """Return the least (at least 0) and largest kept fraction of a run on ``terrains`` at ``sigmas``.

    The largest may pass 1: a run that keeps more than it was commanded loses its inertial
    loss from that, before the clip to its length.
    """
    low = min(1.0 - t.translation_loss - sigmas * t.translation_sd for t in terrains)
    high = max(1.0 - t.translation_loss + sigmas * t.translation_sd for t in terrains)
    return max(0.0, low), high


def _running(
    terrain: TerrainStats, run: float, shortest: float, longest: float, sigmas: float
) -> TerrainStats:
    """Return ``terrain`` with no inertial loss, whose ``run`` metres last ``shortest`` to ``longest`` m."""
    if run > 0.0:
        # Rounded outwards: the growth recomputes the ends from the middle and the spread.
        high = min(1.0, longest / run * (1.0 + 1e-12))
        low = max(0.0, min(shortest, longest) / run * (1.0 - 1e-12))
    else:
        high = low = 1.0
    return dataclasses.replace(
        terrain,
        translation_loss=min(_BELOW_ONE, 1.0 - (high + low) / 2.0),
        translation_inertial_loss=0.0,
        translation_sd=(high - low) / (2.0 * sigmas),
    )


def _covers(meadow_map: MeadowMap, indices: NDArray[np.intp], hull: BaseGeometry) -> bool:
    """Whether the meadows at ``indices`` cover ``hull`` (to the tolerance; they do not overlap)."""
    shapes = [meadow_map._shapes[int(i)] for i in indices]
    area = float(shapely.area(hull))
    if area > 0.0:
        held = float(shapely.area(shapely.intersection(shapes, hull)).sum())
        return held >= area * (1.0 - 1e-9) - POSITION_TOLERANCE**2
    return bool(shapely.covers(shapely.buffer(shapely.union_all(shapes), POSITION_TOLERANCE), hull))


def _skitter(command: TurnAndRun, terrains: Sequence[TerrainStats], sigmas: float) -> float:
    """Return how far the turn's skitter may move the robot on any of ``terrains``, metres."""
    return abs(command.turn) * max(max(0.0, t.skitter + sigmas * t.skitter_sd) for t in terrains)


def _turned_headings(
    uncertainty_map: SpatialUncertaintyMap,
    command: TurnAndRun,
    terrains: Sequence[TerrainStats],
    sigmas: float,
) -> tuple[float, float]:
    """Return the headings (start <= stop, radians) the wedge may have after the turn on ``terrains``."""
    low = min(max(0.0, 1.0 - t.rotation_loss - sigmas * t.rotation_sd) for t in terrains)
    high = max(min(1.0, 1.0 - t.rotation_loss + sigmas * t.rotation_sd) for t in terrains)
    wedge = uncertainty_map.wedge
    start = wedge.center - wedge.cw + min(command.turn * low, command.turn * high)
    return start, start + wedge.cw + wedge.ccw + abs(command.turn) * (high - low)


def _every_terrain(meadow_map: MeadowMap, table: TerrainTable) -> list[TerrainStats]:
    return [table[name] for name in meadow_map.terrains]


def _meadow_holding(meadow_map: MeadowMap, x: float, y: float) -> int | None:
    """Return the index of a meadow holding (x, y), boundary included, or None (a small map: a scan)."""
    if len(meadow_map.meadows) > _SCAN_LIMIT:
        meadow = meadow_map.meadow_at(x, y)
        return None if meadow is None else meadow_map._meadow_index[meadow.id]
    for index, (xmin, ymin, xmax, ymax, edges) in enumerate(meadow_map._clip):
        if (
            xmin <= x <= xmax
            and ymin <= y <= ymax
            and all(nx * (x - ax) + ny * (y - ay) <= 0.0 for ax, ay, nx, ny in edges)
        ):
            return index
    return None


def _first_meadow_run(
    meadow_map: MeadowMap,
    uncertainty_map: SpatialUncertaintyMap,
    command: TurnAndRun,
    table: TerrainTable,
    sigmas: float,
) -> tuple[Meadow | None, float]:
    """Return the one meadow every pose of the map stands in, and how far every true run stays in it.

    (None, 0) unless the polygon, widened by the turn's skitter and a tolerance, lies inside
    one meadow. The distance is the longest ``t <= command.run`` for which the region the
    true runs sweep in their first ``t`` metres (:func:`meadows_in_reach`) stays inside
    it: on every edge's inner side, for every vertex of the polygon moved ``t`` metres in
    any heading of the turned wedge.
    """
    vertices = uncertainty_map.polygon.vertices
    index = _meadow_holding(meadow_map, float(vertices[0, 0]), float(vertices[0, 1]))
    if index is None:
        return None, 0.0
    meadow = meadow_map.meadows[index]
    planes = meadow_map._halfplanes[index]
    stats = [table[meadow.terrain]]
    margin = _skitter(command, stats, sigmas) + POSITION_TOLERANCE
    slack = planes[:, 2] - margin - vertices @ planes[:, :2].T  # metres, (polygon vertex, edge)
    if not np.all(slack >= 0.0):
        return None, 0.0
    start, stop = _turned_headings(uncertainty_map, command, stats, sigmas)
    width = stop - start
    # How fast a run in the heading sector [start, start + width] nears each edge, m/m: the
    # largest cosine between a heading of it and the edge's outward normal.
    normal = planes[:, 3]
    if width >= 2.0 * math.pi:
        rates = np.ones(len(planes))
    else:
        inside = np.mod(normal - start, 2.0 * math.pi) <= width
        rates = np.where(inside, 1.0, np.maximum(np.cos(start - normal), np.cos(start + width - normal)))
    nearing = rates > 0.0
    if not np.any(nearing):
        return meadow, command.run
    return meadow, float(min(command.run, (slack[:, nearing] / rates[nearing]).min()))


def meadows_in_reach(
    meadow_map: MeadowMap,
    uncertainty_map: SpatialUncertaintyMap,
    command: TurnAndRun,
    table: TerrainTable,
    sigmas: float,
) -> tuple[Meadow, ...]:
    """Return the meadows a true pose of the map may stand in or run through during ``command``.

    The true robot (:class:`~aura_ums.sim.SimulatedRobot`) turns in the meadow it stands in,
    one the map's polygon meets; the turn's skitter moves it by at most ``|turn|`` times the
    largest ``skitter + sigmas * skitter_sd`` of their terrains; then its run is cut by
    meadows along the straight line of ``command.run`` metres from there, in its heading
    after the turn: a heading of the map's wedge turned by the turn's bounds on those
    terrains. Every meadow within the skitter of the region those lines sweep is in reach,
    in map order. A map off every meadow turns on the terrain of one the run may reach in
    any direction; with none, the result is empty.

    Examples
    --------
    >>> from aura_ums.uncertainty import Pose, SpatialUncertaintyMap, TerrainTable, TurnAndRun
    >>> from aura_ums.world import make_grid_world
    >>> world, table = make_grid_world(1, 3), TerrainTable.default()      # 5 m cells
    >>> start = SpatialUncertaintyMap.from_pose(Pose(2.5, 2.5, 0.0), 0.5, 0.1)
    >>> [m.id for m in meadows_in_reach(world, start, TurnAndRun(0.0, 1.5), table, 3.0)]
    ['cell_0_0']
    >>> [m.id for m in meadows_in_reach(world, start, TurnAndRun(0.0, 2.5), table, 3.0)]
    ['cell_0_0', 'cell_0_1']
    >>> [m.id for m in meadows_in_reach(world, start, TurnAndRun(math.pi, 2.5), table, 3.0)]   # west: none
    ['cell_0_0']
    """
    bound = _checked_growth_arguments(meadow_map, uncertainty_map, command, table, sigmas)
    return _reach(meadow_map, uncertainty_map, command, table, bound)[0]


def _checked_growth_arguments(
    meadow_map: object, uncertainty_map: object, command: object, table: object, sigmas: object
) -> float:
    """Refuse arguments of grow_through or meadows_in_reach of the wrong type; return sigmas checked."""
    if not isinstance(uncertainty_map, SpatialUncertaintyMap):
        raise InputError(
            f"uncertainty_map: expected a SpatialUncertaintyMap, got {type(uncertainty_map).__name__}"
        )
    if not isinstance(meadow_map, MeadowMap):
        raise InputError(f"meadow_map: expected a MeadowMap, got {type(meadow_map).__name__}")
    if not isinstance(table, TerrainTable):
        raise InputError(f"table: expected a TerrainTable, got {type(table).__name__}")
    if not isinstance(command, TurnAndRun):
        raise InputError(f"command: expected a TurnAndRun, got {type(command).__name__}")
    return SIGMAS.check(sigmas, "sigmas")


def _reach(
    meadow_map: MeadowMap,
    uncertainty_map: SpatialUncertaintyMap,
    command: TurnAndRun,
    table: TerrainTable,
    sigmas: float,
    inside: int | None = None,
) -> tuple[tuple[Meadow, ...], list[TerrainStats], bool]:
    """:func:`meadows_in_reach`, the terrains a true run may move on, and whether the meadows cover the map.

    Where they do not cover its polygon, a true pose may stand outside every meadow and
    turn (and, on a run that meets no meadow, run) on the terrain of the meadow it was last
    in: the terrains are then every terrain of the map, theirs too.
    ``inside``: the index of a meadow known to hold the whole polygon (no query needed).
    """
    vertices = uncertainty_map.polygon.vertices
    hull: BaseGeometry = (
        shapely.Polygon(vertices) if len(vertices) >= 3 else shapely.MultiPoint(vertices).convex_hull
    )
    tree = meadow_map._tree
    if inside is not None:
        standing, covered = np.array([inside]), True
    else:
        # Within the tolerance, as MeadowMap.meadow_at (and so the true robot) finds them.
        standing = np.sort(tree.query(hull, predicate="dwithin", distance=POSITION_TOLERANCE))
        covered = bool(len(standing)) and _covers(meadow_map, standing, hull)
    every = [] if covered else _every_terrain(meadow_map, table)
    if not len(standing):
        # Off every meadow: the meadows the run may reach after a skitter on any terrain.
        farthest = command.run + _skitter(command, every, sigmas)
        standing = np.sort(tree.query(hull, predicate="dwithin", distance=max(farthest, POSITION_TOLERANCE)))
    if not len(standing):
        return (), [], False
    turning = [table[meadow_map.meadows[int(i)].terrain] for i in standing] if covered else every
    skitter = _skitter(command, turning, sigmas)
    swept = hull
    if command.run > 0.0:
        start, stop = _turned_headings(uncertainty_map, command, turning, sigmas)
        sector = outer_annular_sector(0.0, command.run, start, stop)
        ends = (vertices[:, None, :] + sector[None, :, :]).reshape(-1, 2)
        swept = shapely.MultiPoint(np.concatenate((vertices, ends))).convex_hull
    near = tree.query(swept, predicate="dwithin", distance=max(skitter, POSITION_TOLERANCE))
    reached = tuple(
        meadow_map.meadows[i] for i in sorted({int(i) for i in near} | {int(i) for i in standing})
    )
    return reached, [table[meadow.terrain] for meadow in reached] + every, covered


def outer_terrain(
    terrains: Sequence[TerrainStats], pieces: int, command: TurnAndRun, sigmas: float, *, first: bool = True
) -> TerrainStats:
    """Return terrain statistics whose growth by ``command`` bounds a run through any of ``terrains``.

    The true run may cross the terrains' meadows in up to ``pieces`` pieces, each drawn on
    its own terrain (with its own fixed inertial loss, as :class:`~aura_ums.sim.SimulatedRobot`
    draws them), and the turn on any of them. At ``sigmas``, the true run of ``R = command.run``
    metres is then at least ``R`` times the least kept fraction less ``pieces`` of the largest
    inertial losses, and at most ``R`` times the largest kept fraction less the least inertial
    loss (nothing less when not ``first``: the rest of a run whose start, and its loss, grew
    already); the returned statistics have no inertial loss and a kept fraction and spread that
    give exactly that interval. The turn's kept fraction covers every terrain's interval;
    drift, skitter and its spread are the largest. Valid for this command and ``sigmas`` only.

    Examples
    --------
    >>> from aura_ums.uncertainty import TerrainTable, TurnAndRun
    >>> table = TerrainTable.default()
    >>> outer = outer_terrain([table["concrete"], table["grass"]], 2, TurnAndRun(0.5, 2.0), 3.0)
    >>> outer.drift == max(table["concrete"].drift, table["grass"].drift), outer.translation_inertial_loss
    (True, 0.0)
    >>> outer_terrain([table["concrete"]], 1, TurnAndRun(0.0, 0.0), 3.0).translation_sd   # nothing to run
    0.0
    >>> outer_terrain([], 1, TurnAndRun(0.0, 1.0), 3.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: terrains: expected at least one TerrainStats, got none
    """
    stats = sequence_of(terrains, TerrainStats, "terrains")
    if not stats:
        raise InputError("terrains: expected at least one TerrainStats, got none")
    count = integer_at_least(pieces, "pieces", 1)
    if not isinstance(command, TurnAndRun):
        raise InputError(f"command: expected a TurnAndRun, got {type(command).__name__}")
    if not isinstance(first, bool):
        raise InputError(f"first: expected a bool, got {type(first).__name__}")
    return _outer_terrain(stats, count, command, SIGMAS.check(sigmas, "sigmas"), first=first)


def _outer_terrain(
    terrains: Sequence[TerrainStats], pieces: int, command: TurnAndRun, sigmas: float, *, first: bool = True
) -> TerrainStats:
    """:func:`outer_terrain` for checked arguments (at least one terrain, pieces >= 1, sigmas in range)."""
    run = command.run
    low, high = _kept_interval(terrains, sigmas)
    losses = [t.translation_inertial_loss for t in terrains]
    paid = min(losses) if first else 0.0
    longest = min(run, max(0.0, run * high - paid))
    shortest = min(longest, max(0.0, run * low - pieces * max(losses)))
    turn_high = max(min(1.0, 1.0 - t.rotation_loss + sigmas * t.rotation_sd) for t in terrains)
    turn_low = min(max(0.0, 1.0 - t.rotation_loss - sigmas * t.rotation_sd) for t in terrains)
    turning = TerrainStats(
        rotation_loss=min(_BELOW_ONE, 1.0 - (turn_high + turn_low) / 2.0),
        rotation_sd=(turn_high - turn_low) / (2.0 * sigmas) * (1.0 + 1e-12),
        translation_loss=0.0,
        translation_inertial_loss=0.0,
        translation_sd=0.0,
        drift=max(t.drift for t in terrains),
        skitter=max(t.skitter for t in terrains),
        skitter_sd=max(t.skitter_sd for t in terrains),
    )
    return _running(turning, run, shortest, longest, sigmas)


#: The largest loss a TerrainStats takes (its range is [0, 1)): nothing kept at all.
_BELOW_ONE = math.nextafter(1.0, 0.0)
