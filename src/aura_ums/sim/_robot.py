"""The simulated robot: true motion drawn from the terrain model of the meadows it crosses."""

from __future__ import annotations

import math

import numpy as np

from aura_ums._validate import check_rng, finite_float
from aura_ums.errors import InputError
from aura_ums.uncertainty import Pose, TerrainTable, TurnAndRun
from aura_ums.world import Meadow, MeadowMap, split_run


class SimulatedRobot:
    """The true robot of a simulation: it moves as the terrain model says, not as commanded.

    A command is executed in steps, each drawn with
    :meth:`~aura_ums.uncertainty.TerrainStats.sample_motion` of one meadow's terrain:

    1. the turn, ``TurnAndRun(command.turn, 0)``, with the statistics of the meadow the
       robot stands in;
    2. the run, cut by :func:`~aura_ums.world.split_run` from the true pose after the turn,
       along the true heading, for the commanded distance; each piece
       ``TurnAndRun(0, piece.distance)`` is drawn with its own meadow's statistics, from
       the true pose the previous piece ended at.

    :func:`~aura_ums.world.grow_through` bounds this for every pose of a map, wherever its
    run crosses a boundary (:func:`~aura_ums.world.meadows_in_reach`). Where the robot is
    outside every meadow (it skittered or ran off the map), the meadow it was last in
    counts; a map partly outside every meadow is bounded only if that meadow is in reach.

    Parameters
    ----------
    meadow_map : MeadowMap
        The world's meadows and their terrains.
    table : TerrainTable
        Terrain statistics; every meadow's terrain must be in it.
    pose : Pose
        The true starting pose; it must lie in a meadow.
    rng : numpy.random.Generator
        Source of randomness; the robot draws from it alone, so a seed fixes its path.
    truncate : float, optional
        Clip the model's standard normals to +-``truncate`` (see ``sample_motion``); with
        the growth's ``sigmas`` the truth then stays inside the grown maps.

    Raises
    ------
    InputError
        When the start lies outside every meadow.
    UnknownTerrainError
        When a meadow's terrain is not in ``table``.

    Examples
    --------
    >>> import numpy as np
    >>> from aura_ums.uncertainty import Pose, TerrainTable, TurnAndRun
    >>> from aura_ums.world import make_grid_world
    >>> world = make_grid_world(1, 3)                     # concrete, grass, gravel
    >>> robot = SimulatedRobot(world, TerrainTable.default(), Pose(2.5, 2.5, 0.0), np.random.default_rng(1))
    >>> after = robot.execute(TurnAndRun(0.0, 10.0))
    >>> [terrain for _, terrain in robot.last_steps]      # the turn, then one piece per meadow
    ['concrete', 'concrete', 'grass', 'gravel']
    >>> 11.0 < after.x < 12.5 and robot.pose == after     # short of the commanded 12.5 m
    True
    >>> SimulatedRobot(world, TerrainTable.default(), Pose(-5.0, 0.0, 0.0), np.random.default_rng(1))
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: pose: expected a start inside a meadow, got (-5.0, 0.0)
    """

    __slots__ = ("_commanded", "_last_meadow", "_last_steps", "_map", "_pose", "_rng", "_table", "_truncate")

    def __init__(
        self,
        meadow_map: MeadowMap,
        table: TerrainTable,
        pose: Pose,
        rng: np.random.Generator,
        *,
        truncate: float | None = None,
    ) -> None:
        if not isinstance(meadow_map, MeadowMap):
            raise InputError(f"meadow_map: expected a MeadowMap, got {type(meadow_map).__name__}")
        if not isinstance(table, TerrainTable):
            raise InputError(f"table: expected a TerrainTable, got {type(table).__name__}")
        if not isinstance(pose, Pose):
            raise InputError(f"pose: expected a Pose, got {type(pose).__name__}")
        check_rng(rng)
        if truncate is not None:
            limit = finite_float(truncate, "truncate")
            if limit <= 0.0:
                raise InputError(f"truncate: expected a positive number or None, got {limit!r}")
            truncate = limit
        for meadow in meadow_map.meadows:
            table[meadow.terrain]  # raises UnknownTerrainError naming the terrain
        start = meadow_map.meadow_at(pose.x, pose.y)
        if start is None:
            raise InputError(f"pose: expected a start inside a meadow, got ({pose.x!r}, {pose.y!r})")
        self._map = meadow_map
        self._table = table
        self._pose = pose
        self._rng = rng
        self._truncate = truncate
        self._last_meadow: Meadow = start
        self._last_steps: tuple[tuple[TurnAndRun, str], ...] = ()
        self._commanded = 0.0

    @property
    def pose(self) -> Pose:
        """The current true pose."""
        return self._pose

    @property
    def meadow(self) -> Meadow:
        """The meadow the robot is in (or was last in, when it is outside every meadow)."""
        return self._last_meadow

    @property
    def last_steps(self) -> tuple[tuple[TurnAndRun, str], ...]:
        """The steps of the last :meth:`execute`: each command drawn and the terrain it used."""
        return self._last_steps

    @property
    def commanded_distance(self) -> float:
        """Total commanded run so far, metres (the odometer of the commands)."""
        return self._commanded

    def _locate(self, pose: Pose) -> Meadow:
        meadow = self._map.meadow_at(pose.x, pose.y)
        if meadow is not None:
            self._last_meadow = meadow
        return self._last_meadow

    def _step(self, steps: list[tuple[TurnAndRun, str]], command: TurnAndRun, terrain: str) -> None:
        stats = self._table[terrain]
        self._pose = stats.sample_motion(self._pose, command, self._rng, truncate=self._truncate)
        steps.append((command, terrain))

    def execute(self, command: TurnAndRun) -> Pose:
        """Carry out ``command`` and return the new true pose (also kept as :attr:`pose`).

        Parameters
        ----------
        command : TurnAndRun
            The commanded motion.

        Returns
        -------
        Pose
            The true pose after the command.
        """
        if not isinstance(command, TurnAndRun):
            raise InputError(f"command: expected a TurnAndRun, got {type(command).__name__}")
        steps: list[tuple[TurnAndRun, str]] = []
        self._step(steps, TurnAndRun(command.turn, 0.0), self._locate(self._pose).terrain)
        if command.run > 0.0:
            start = self._pose
            try:
                pieces = [
                    (piece.distance, piece.terrain)
                    for piece in split_run(self._map, (start.x, start.y), start.heading, command.run)
                ]
            except InputError:  # the run meets no meadow: the last meadow's terrain throughout
                pieces = [(command.run, self._locate(start).terrain)]
            for distance, terrain in pieces:
                if distance > 0.0:
                    self._step(steps, TurnAndRun(0.0, distance), terrain)
        self._locate(self._pose)
        self._last_steps = tuple(steps)
        self._commanded += command.run
        return self._pose

    def __repr__(self) -> str:
        p = self._pose
        return (
            f"SimulatedRobot(pose=({p.x:.3f}, {p.y:.3f}, {math.degrees(p.heading):.2f} deg), "
            f"meadow={self._last_meadow.id!r})"
        )
