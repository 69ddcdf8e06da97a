"""Short-term memory: the meadows instantiated for one leg, and their candidate landmarks."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely
from numpy.typing import ArrayLike

from aura_ums._validate import nonnegative_float, sequence_of
from aura_ums.errors import InputError
from aura_ums.world._ltm import LandmarkRecord, Meadow, MeadowMap
from aura_ums.world._navigator import RUN_TOLERANCE, _point

Point = tuple[float, float]


@dataclass(frozen=True, slots=True)
class ShortTermMemory:
    """The part of long-term memory instantiated for one leg (the paper's STM).

    Build it with :meth:`for_leg`. The meadows are those the leg traverses (in order along
    the leg), then the ones adjacent to them and the other nearby ones (by distance to the
    leg, then map order); the
    landmarks are those visible from any of them, each once, in the order the meadows list
    them. They are the candidates the pilot parameterizes find-landmark schemas for.

    Parameters
    ----------
    leg : tuple of two (x, y)
        The leg's start and end, metres.
    meadows : tuple of Meadow
        The instantiated meadows: traversed first, then nearby.
    traversed : tuple of str
        Ids of the meadows the leg passes through, in order along it.
    landmarks : tuple of LandmarkRecord
        The candidate landmarks, without repeats.
    nearby : float
        The distance (m) within which meadows were instantiated.

    Examples
    --------
    >>> from aura_ums.world import make_grid_world
    >>> world = make_grid_world(1, 6, cell=5.0)
    >>> stm = ShortTermMemory.for_leg(world, (2.5, 2.5), (7.5, 2.5), nearby=0.0)
    >>> stm.leg, stm.traversed
    (((2.5, 2.5), (7.5, 2.5)), ('cell_0_0', 'cell_0_1'))
    >>> stm.meadow_ids, stm.landmark_ids   # the adjacent cell_0_2 too, and the poles seen from them
    (('cell_0_0', 'cell_0_1', 'cell_0_2'), ('pole_0_0', 'pole_0_2'))
    >>> turn = ShortTermMemory.for_leg(world, (2.5, 2.5), (2.5, 2.5), nearby=0.0)   # a turn in place
    >>> turn.traversed, turn.meadow_ids
    (('cell_0_0',), ('cell_0_0', 'cell_0_1'))
    >>> ShortTermMemory("junk", (), (), (), 0.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: leg: expected the leg's (start, end), two (x, y) points, got 'junk'
    >>> ShortTermMemory(stm.leg, stm.meadows, ("cell_0_5",), stm.landmarks, 0.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: traversed: expected ids of the instantiated meadows, got 'cell_0_5'
    """

    leg: tuple[Point, Point]
    meadows: tuple[Meadow, ...]
    traversed: tuple[str, ...]
    landmarks: tuple[LandmarkRecord, ...]
    nearby: float

    def __post_init__(self) -> None:
        if not isinstance(self.leg, (tuple, list)) or len(self.leg) != 2:
            raise InputError(f"leg: expected the leg's (start, end), two (x, y) points, got {self.leg!r}")
        start, end = (_point(point, f"leg[{index}]") for index, point in enumerate(self.leg))
        object.__setattr__(self, "leg", ((float(start[0]), float(start[1])), (float(end[0]), float(end[1]))))
        object.__setattr__(self, "meadows", sequence_of(self.meadows, Meadow, "meadows"))
        object.__setattr__(self, "landmarks", sequence_of(self.landmarks, LandmarkRecord, "landmarks"))
        object.__setattr__(self, "traversed", tuple(self.traversed))
        ids = {m.id for m in self.meadows}
        for ident in self.traversed:
            if ident not in ids:
                raise InputError(f"traversed: expected ids of the instantiated meadows, got {ident!r}")
        object.__setattr__(self, "nearby", nonnegative_float(self.nearby, "nearby"))

    @classmethod
    def for_leg(
        cls, meadow_map: MeadowMap, start: ArrayLike, end: ArrayLike, *, nearby: float = 10.0
    ) -> ShortTermMemory:
        """Instantiate the meadows of a leg from ``start`` to ``end`` and gather their landmarks.

        Parameters
        ----------
        meadow_map : MeadowMap
            Long-term memory.
        start, end : array_like, shape (2,)
            The leg, metres. They may be equal (a leg of zero length: the robot turns in
            place), or lie outside the meadows (then only nearby meadows are found).
        nearby : float
            Meadows within this distance (m, >= 0) of the leg are instantiated too.
            Meadows adjacent to a traversed meadow always are, however far (the paper's
            "adjacent and other nearby meadows").

        Returns
        -------
        ShortTermMemory

        Examples
        --------
        >>> from aura_ums.world import make_grid_world
        >>> world = make_grid_world(1, 6, cell=5.0)
        >>> stm = ShortTermMemory.for_leg(world, (2.5, 2.5), (7.5, 2.5), nearby=0.0)
        >>> stm.traversed, [m.id for m in stm.meadows]
        (('cell_0_0', 'cell_0_1'), ['cell_0_0', 'cell_0_1', 'cell_0_2'])
        >>> [r.id for r in stm.landmarks]
        ['pole_0_0', 'pole_0_2']
        >>> ShortTermMemory.for_leg(world, (100, 100), (101, 100), nearby=1.0).meadows
        ()
        """
        if not isinstance(meadow_map, MeadowMap):
            raise InputError(f"meadow_map: expected a MeadowMap, got {type(meadow_map).__name__}")
        a = _point(start, "start")
        b = _point(end, "end")
        reach = nonnegative_float(nearby, "nearby")
        index = {m.id: k for k, m in enumerate(meadow_map.meadows)}
        direction = b - a
        length = float(np.hypot(*direction))
        traversed: list[Meadow] = []
        if length == 0.0:
            traversed.extend(meadow_map.meadows_containing(float(a[0]), float(a[1])))
        else:
            unit = direction / length
            line = shapely.LineString([a, b])
            spans: list[tuple[float, int, Meadow]] = []
            for meadow in meadow_map.meadows_near([a, b], 0.0):
                piece = shapely.intersection(line, meadow_map.shape(meadow.id))
                along = (shapely.get_coordinates(piece) - a) @ unit
                if len(along) and float(along.max() - along.min()) > RUN_TOLERANCE:
                    spans.append((float(along.min()), index[meadow.id], meadow))
            traversed.extend(meadow for _, _, meadow in sorted(spans, key=lambda s: (s[0], s[1])))
        taken = {m.id for m in traversed}
        geometry = shapely.Point(a) if length == 0.0 else shapely.LineString([a, b])
        adjacent = {n.id for m in traversed for n in meadow_map.neighbours(m.id)}
        others = [
            m for m in meadow_map.meadows_near([a, b], reach) if m.id not in taken and m.id not in adjacent
        ]
        others.extend(meadow_map.meadow(i) for i in adjacent - taken)
        distances = [float(shapely.distance(geometry, meadow_map.shape(m.id))) for m in others]
        near = [m for _, _, m in sorted(zip(distances, (index[m.id] for m in others), others, strict=True))]
        meadows = (*traversed, *near)
        seen: dict[str, LandmarkRecord] = {}
        for meadow in meadows:
            for landmark_id in meadow.landmark_ids:
                if landmark_id not in seen:
                    seen[landmark_id] = meadow_map.landmark(landmark_id)
        leg = ((float(a[0]), float(a[1])), (float(b[0]), float(b[1])))
        return cls(leg, meadows, tuple(m.id for m in traversed), tuple(seen.values()), reach)

    @property
    def meadow_ids(self) -> tuple[str, ...]:
        """Ids of the instantiated meadows, in order."""
        return tuple(m.id for m in self.meadows)

    @property
    def landmark_ids(self) -> tuple[str, ...]:
        """Ids of the candidate landmarks, in order."""
        return tuple(r.id for r in self.landmarks)
