"""Sample worlds shipped with the package, and a generator of grid worlds."""

from __future__ import annotations

import math
from collections.abc import Iterable
from importlib import resources

import numpy as np

from aura_ums._validate import check_rng, finite_float, integer_at_least, items_of
from aura_ums.errors import InputError
from aura_ums.geometry import ConvexPolygon
from aura_ums.uncertainty import TerrainTable, VerticalLineLandmark
from aura_ums.world._ltm import LandmarkRecord, Meadow, MeadowMap, PerceptualStrategy

#: Most cells of :func:`make_grid_world` (rows times cols): each meadow takes about 0.6 ms to
#: build and check, so 10,000 take about 6 s (1000 x 1000 ran past 20 s, 10**12 never ended).
MAX_GRID_CELLS = 10_000
#: Seconds to build one meadow of a grid world, for the estimate in the message.
_SECONDS_PER_CELL = 6e-4

#: Names of the sample worlds in ``aura_ums/world/data`` (GeoJSON files).
SAMPLE_WORLDS = ("indoor_corridor", "paper_sidewalk")


def sample_world(name: str) -> MeadowMap:
    """Load a sample world shipped with aura-ums, checked against the default terrain table.

    ``"paper_sidewalk"``: the paper's campus experiment in metres; the robot walks
    12.2 m (40 ft) east from (0, 0) along a 2 m concrete sidewalk between grass meadows,
    past a telephone pole and a concrete lamppost (Class I), towards a building corner
    (Class II, with a Class I variant), the walk's edges being Class III lines.
    ``"indoor_corridor"``: a 30 m tile corridor with doorways into side rooms (door
    edges Class I, a sign corner Class II, wall bases Class III) and a concrete lobby.

    Parameters
    ----------
    name : str
        ``"paper_sidewalk"`` or ``"indoor_corridor"``.

    Raises
    ------
    InputError
        For an unknown name.

    Examples
    --------
    >>> world = sample_world("paper_sidewalk")
    >>> world.meadow_at(0.0, 0.0).terrain, world.landmark("lamppost_107").symbol
    ('concrete', 'lamppost')
    >>> sample_world("moon")
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: name: expected one of indoor_corridor, paper_sidewalk, got 'moon'
    """
    if name not in SAMPLE_WORLDS:
        raise InputError(f"name: expected one of {', '.join(SAMPLE_WORLDS)}, got {name!r}")
    resource = resources.files("aura_ums.world").joinpath("data", f"{name}.geojson")
    with resources.as_file(resource) as path:
        return MeadowMap.from_geojson(path, terrain_table=TerrainTable.default())


def make_grid_world(
    rows: int,
    cols: int,
    *,
    cell: float = 5.0,
    rng: np.random.Generator | None = None,
    remove: Iterable[tuple[int, int]] = (),
) -> MeadowMap:
    """Return a grid of square meadows, for tests and benchmarks.

    Meadow ``cell_{r}_{c}`` covers ``[c*cell, (c+1)*cell] x [r*cell, (r+1)*cell]``.
    Terrains cycle through the default table's names (sorted: concrete, grass, gravel,
    tile) by ``(r + c) % 4``, or are drawn at random with ``rng``. A pole (Class I,
    ``pole_{i}_{j}``, 3 m tall) stands at every grid node ``(j*cell, i*cell)`` with ``i``
    and ``j`` even; each meadow sees the one pole at its corners.

    Parameters
    ----------
    rows, cols : int
        Grid size, >= 1 each.
    cell : float
        Side of a meadow, metres, > 0.
    rng : numpy.random.Generator, optional
        Draw terrains at random instead of cycling.
    remove : iterable of (row, col)
        Cells to leave out (obstacles). At least one cell must remain.

    Examples
    --------
    >>> world = make_grid_world(2, 3, remove=[(1, 1)])
    >>> len(world), world.meadow("cell_0_1").terrain, [m.id for m in world.neighbours("cell_0_1")]
    (5, 'grass', ['cell_0_0', 'cell_0_2'])
    >>> make_grid_world(0, 3)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: rows: expected an integer >= 1, got 0
    >>> make_grid_world(1, 2, remove=[(5, 5)])
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: remove[0]: expected a (row, col) cell of the 1 x 2 grid, got (5, 5)
    """
    for name, value in (("rows", rows), ("cols", cols)):
        integer_at_least(value, name, 1)
    if rows * cols > MAX_GRID_CELLS:
        raise InputError(
            f"rows, cols: expected at most {MAX_GRID_CELLS} cells (about {_SECONDS_PER_CELL * 1e3:g} ms "
            f"each to build), got {rows} x {cols} = {rows * cols} cells "
            f"(about {rows * cols * _SECONDS_PER_CELL:.3g} s)"
        )
    side = finite_float(cell, "cell")
    if side <= 0.0:
        raise InputError(f"cell: expected a positive number, got {side!r}")
    if rng is not None:
        check_rng(rng)
    holes = {
        _grid_cell(item, f"remove[{index}]", rows, cols)
        for index, item in enumerate(items_of(remove, "remove", "a sequence of (row, col) cells"))
    }
    names = sorted(TerrainTable.default())
    meadows: list[Meadow] = []
    poles: dict[str, tuple[int, int]] = {}
    for r in range(rows):
        for c in range(cols):
            if (r, c) in holes:
                continue
            terrain = names[int(rng.integers(len(names)))] if rng is not None else names[(r + c) % len(names)]
            x0, y0, x1, y1 = c * side, r * side, (c + 1) * side, (r + 1) * side
            i, j = r + r % 2, c + c % 2  # the even node among the cell's corners
            pole = f"pole_{i}_{j}"
            poles[pole] = (i, j)
            square = ConvexPolygon([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])
            meadows.append(Meadow(f"cell_{r}_{c}", square, terrain, (pole,)))
    if not meadows:
        raise InputError("remove: expected at least one cell left, got every cell removed")
    records = [
        LandmarkRecord(
            VerticalLineLandmark(pole, j * side, i * side, 0.0, 3.0, symbol="pole"),
            PerceptualStrategy.LINE_FINDER,
            {"orientation": math.pi / 2, "tolerance": math.radians(10.0), "min_length": 30.0},
            activation_range=4.0 * side,
            recognition_threshold=0.5,
        )
        for pole, (i, j) in poles.items()
    ]
    return MeadowMap(meadows, records, terrain_table=TerrainTable.default())


def _grid_cell(item: object, name: str, rows: int, cols: int) -> tuple[int, int]:
    """Return ``item`` as a ``(row, col)`` cell of a ``rows`` x ``cols`` grid, or raise naming ``name``."""
    if (
        isinstance(item, (tuple, list))
        and len(item) == 2
        and all(isinstance(v, (int, np.integer)) and not isinstance(v, bool) for v in item)
        and 0 <= item[0] < rows
        and 0 <= item[1] < cols
    ):
        return int(item[0]), int(item[1])
    raise InputError(f"{name}: expected a (row, col) cell of the {rows} x {cols} grid, got {item!r}")
