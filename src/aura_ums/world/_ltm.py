"""Long-term memory: landmark records, meadows and the meadow map (the paper's LTM).

A meadow map is a partition of the robot's free space into convex meadows, each with a
terrain type and the list of landmarks visible *from* it (they need not lie in it). Two
meadows are adjacent when their boundaries share a segment of positive length: the robot
passes from one to the other through that segment, the *portal*.
"""

from __future__ import annotations

import math
import types
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import (
    ACTIVATION_RANGE,
    MAX_CONFIRM_FRAMES,
    Choice,
    finite_float,
    items_of,
    points_array,
    read_only,
)
from aura_ums.errors import InputError, UnknownLandmarkError, UnknownTerrainError
from aura_ums.geometry import POSITION_TOLERANCE, ConvexPolygon
from aura_ums.uncertainty import (
    GroundLineLandmark,
    Landmark,
    LandmarkClass,
    PointLandmark,
    TerrainTable,
    VerticalLineLandmark,
)

if TYPE_CHECKING:
    from shapely.geometry import Polygon
    from shapely.geometry.base import BaseGeometry

#: Gaps between meadows up to this many metres still make them adjacent (rounding in files).
_ADJACENCY_TOLERANCE = 1e-6

#: A portal narrower than this (m) does not make two meadows adjacent: they touch at a corner.
_MIN_PORTAL_WIDTH = 1e-3

#: Meadows whose interiors overlap by more than this area (m^2) are refused.
_OVERLAP_TOLERANCE = 1e-6

_LANDMARK_TYPES = (VerticalLineLandmark, PointLandmark, GroundLineLandmark)


class PerceptualStrategy(Choice):
    """The perceptual algorithm a find-landmark schema runs inside its window.

    The strategy decides how much context (margin) the window needs around the place
    where the landmark is guaranteed to appear (the paper's Figure 8).

    Examples
    --------
    >>> PerceptualStrategy("interest_operator")   # as a map file's ``strategy`` names it
    <PerceptualStrategy.INTEREST_OPERATOR: 'interest_operator'>
    >>> from aura_ums.world import sample_world
    >>> sample_world("paper_sidewalk").landmark("lamppost_107").strategy
    <PerceptualStrategy.LINE_FINDER: 'line_finder'>
    >>> PerceptualStrategy("hough")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: PerceptualStrategy: expected one of ..., got 'hough'
    """

    #: Fast line finder: fits lines to gradient runs; needs long context on each side.
    LINE_FINDER = "line_finder"
    #: Moravec-style interest operator: a small neighbourhood per point suffices.
    INTEREST_OPERATOR = "interest_operator"
    #: Region segmenter: needs some surrounding region to compare against.
    REGION_SEGMENTER = "region_segmenter"

    @classmethod
    def for_class(cls, landmark_class: LandmarkClass) -> tuple[PerceptualStrategy, ...]:
        """Return the strategies that can find a landmark class, its usual one first.

        The paper's: a line finder for vertical and ground lines (a region segmenter also
        finds a vertical line), an interest operator for points. A :class:`LandmarkRecord`
        must name one of its class's; the Expecter's default margin is that of the usual one.

        Examples
        --------
        >>> from aura_ums.uncertainty import LandmarkClass
        >>> [s.value for s in PerceptualStrategy.for_class(LandmarkClass.POINT)]
        ['interest_operator']
        >>> PerceptualStrategy.for_class("II")
        Traceback (most recent call last):
        ...
        aura_ums.errors.InputError: landmark_class: expected a LandmarkClass, got 'II'
        """
        if not isinstance(landmark_class, LandmarkClass):
            raise InputError(f"landmark_class: expected a LandmarkClass, got {landmark_class!r}")
        return _CLASS_STRATEGIES[landmark_class]

    @property
    def parameters(self) -> tuple[str, ...]:
        """The names this strategy reads from a :attr:`LandmarkRecord.parameters`.

        What each means, and its range, is the perceptual algorithm's (see
        :mod:`aura_ums.schemas`).

        Examples
        --------
        >>> PerceptualStrategy.REGION_SEGMENTER.parameters
        ('threshold', 'min_area', 'min_aspect')
        """
        return _STRATEGY_PARAMETERS[self]


# The strategies that can find each landmark class, its usual one first; and the parameter
# names each strategy reads (PerceptualStrategy.for_class and .parameters read them).
_CLASS_STRATEGIES: Mapping[LandmarkClass, tuple[PerceptualStrategy, ...]] = types.MappingProxyType(
    {
        LandmarkClass.VERTICAL_LINE: (PerceptualStrategy.LINE_FINDER, PerceptualStrategy.REGION_SEGMENTER),
        LandmarkClass.POINT: (PerceptualStrategy.INTEREST_OPERATOR,),
        LandmarkClass.GROUND_LINE: (PerceptualStrategy.LINE_FINDER,),
    }
)
_STRATEGY_PARAMETERS: Mapping[PerceptualStrategy, tuple[str, ...]] = types.MappingProxyType(
    {
        PerceptualStrategy.LINE_FINDER: (
            "orientation",
            "tolerance",
            "min_length",
            "min_gradient",
            "min_contrast",
            "smoothing",
            "buckets",
        ),
        PerceptualStrategy.INTEREST_OPERATOR: ("window", "min_interest", "suppression"),
        PerceptualStrategy.REGION_SEGMENTER: ("threshold", "min_area", "min_aspect"),
    }
)


class _MapError(InputError):
    """An inconsistency between several items of a meadow map; ``ids`` names them."""

    def __init__(self, ids: tuple[str, ...], field: str, message: str) -> None:
        self.ids = ids
        self.field = field
        self.detail = message
        super().__init__(f"{' and '.join(repr(i) for i in ids)} {field}: {message}")


def _identifier(value: object, name: str) -> str:
    if not isinstance(value, str) or not value:
        raise InputError(f"{name}: expected a non-empty string, got {value!r}")
    return value


@dataclass(frozen=True, slots=True)
class LandmarkRecord:
    """What long-term memory holds about one landmark (the paper's landmark list entry).

    Parameters
    ----------
    landmark : VerticalLineLandmark or PointLandmark or GroundLineLandmark
        The landmark: its ``id`` is the instance (``"lamppost_107"``), its ``symbol`` the
        symbolic class (``"lamppost"``), its type the landmark class (I, II or III).
    strategy : PerceptualStrategy
        Means of identification: the perceptual algorithm its find-landmark schema runs,
        one that can find the landmark's class (:meth:`PerceptualStrategy.for_class`).
    parameters : Mapping[str, float]
        The strategy's parameters (e.g. ``orientation``: expected image-line angle in
        radians, ``tolerance``: radians, ``min_length``: pixels), named among those it
        reads (:attr:`PerceptualStrategy.parameters`); values finite numbers (their ranges
        are the algorithm's, checked when a schema is built). Stored as a read-only mapping.
    activation_range : float
        Metres, in (0, 10,000]: the find-landmark schema wakes from hibernation when the robot may be
        within this distance of the landmark.
    recognition_threshold : float
        Evaluation value (>= 0, on the scale of the strategy's evaluation function) that
        an image structure must reach to count as the landmark: for lines, length (px) times
        contrast (gray levels per px); for corners, the Moravec response.
    confirm_frames : int
        Number of consecutive frames (1 to 10,000) that must confirm a discovery.

    Raises
    ------
    InputError
        For a value of the wrong type or out of range, a strategy that cannot find the
        landmark's class, or a parameter the strategy does not read, naming the landmark and
        the field.

    Examples
    --------
    >>> import math
    >>> pole = VerticalLineLandmark("lamppost_107", 8.5, -1.8, 0.0, 4.5, symbol="lamppost")
    >>> record = LandmarkRecord(pole, PerceptualStrategy.LINE_FINDER,
    ...                         {"orientation": math.pi / 2, "tolerance": 0.17}, 20.0, 0.6)
    >>> record.id, record.symbol, record.landmark_class, record.confirm_frames
    ('lamppost_107', 'lamppost', <LandmarkClass.VERTICAL_LINE: 'I'>, 3)
    >>> LandmarkRecord(pole, PerceptualStrategy.LINE_FINDER, {}, 0.0, 0.6)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: lamppost_107.activation_range: expected a number in (0, 10000] m, got 0.0
    """

    landmark: Landmark
    strategy: PerceptualStrategy
    parameters: Mapping[str, float]
    activation_range: float
    recognition_threshold: float
    confirm_frames: int = 3

    def __post_init__(self) -> None:
        if not isinstance(self.landmark, _LANDMARK_TYPES):
            raise InputError(
                "landmark: expected a VerticalLineLandmark, PointLandmark or GroundLineLandmark, "
                f"got {type(self.landmark).__name__}"
            )
        name = self.landmark.id
        if not isinstance(self.strategy, PerceptualStrategy):
            raise InputError(f"{name}.strategy: expected a PerceptualStrategy, got {self.strategy!r}")
        if not isinstance(self.parameters, Mapping):
            raise InputError(
                f"{name}.parameters: expected a mapping of names to numbers, got {self.parameters!r}"
            )
        landmark_class = self.landmark.landmark_class
        supported = _CLASS_STRATEGIES[landmark_class]
        if self.strategy not in supported:
            allowed = ", ".join(strategy.value for strategy in supported)
            raise InputError(
                f"{name}.strategy: expected {allowed} for a Class {landmark_class.value} landmark, "
                f"got {self.strategy.value}"
            )
        known = _STRATEGY_PARAMETERS[self.strategy]
        checked: dict[str, float] = {}
        for key, value in self.parameters.items():
            _identifier(key, f"{name}.parameters key")
            if key not in known:
                raise InputError(f"{name}.parameters: expected names among {', '.join(known)}, got {key!r}")
            checked[key] = finite_float(value, f"{name}.parameters.{key}")
        object.__setattr__(self, "parameters", types.MappingProxyType(checked))
        object.__setattr__(
            self,
            "activation_range",
            ACTIVATION_RANGE.check(self.activation_range, f"{name}.activation_range"),
        )
        threshold = finite_float(self.recognition_threshold, f"{name}.recognition_threshold")
        if threshold < 0.0:
            raise InputError(
                f"{name}.recognition_threshold: expected a non-negative number, got {threshold!r}"
            )
        object.__setattr__(self, "recognition_threshold", threshold)
        frames = self.confirm_frames
        if (
            isinstance(frames, bool)
            or not isinstance(frames, (int, np.integer))
            or not 1 <= frames <= MAX_CONFIRM_FRAMES
        ):
            raise InputError(
                f"{name}.confirm_frames: expected an integer in [1, {MAX_CONFIRM_FRAMES}], got {frames!r}"
            )
        object.__setattr__(self, "confirm_frames", int(frames))

    @property
    def id(self) -> str:
        """The landmark's instance name, e.g. ``"lamppost_107"``."""
        return self.landmark.id

    @property
    def symbol(self) -> str:
        """The landmark's symbolic class, e.g. ``"lamppost"``."""
        return self.landmark.symbol

    @property
    def landmark_class(self) -> LandmarkClass:
        """The landmark class (I, II or III), from the landmark's type."""
        return self.landmark.landmark_class

    def distance(self, points: ArrayLike) -> NDArray[np.float64]:
        """Return the horizontal distance (m) from each point ``(n, 2)`` to the landmark.

        For a ground line it is the distance to the segment. Used with
        :attr:`activation_range` to decide when a schema wakes.

        Examples
        --------
        >>> edge = GroundLineLandmark("edge", (0, 0), (10, 0))
        >>> LandmarkRecord(edge, PerceptualStrategy.LINE_FINDER, {}, 5.0, 0.5).distance(
        ...     [(5, 3), (13, 4)]).tolist()
        [3.0, 5.0]
        """
        pts = points_array(points, "points")
        if isinstance(self.landmark, GroundLineLandmark):
            a, b = self.landmark.start, self.landmark.end
            d = b - a
            t = np.clip(((pts - a) @ d) / float(d @ d), 0.0, 1.0)
            nearest = a + t[:, None] * d
            return np.asarray(np.hypot(*(pts - nearest).T), dtype=np.float64)
        return np.asarray(np.hypot(pts[:, 0] - self.landmark.x, pts[:, 1] - self.landmark.y))

    def __hash__(self) -> int:
        return hash((self.landmark, self.strategy, self.activation_range, self.recognition_threshold))


@dataclass(frozen=True, slots=True)
class Meadow:
    """A convex region of free space with one terrain type (a node of the meadow map).

    Parameters
    ----------
    id : str
        Unique name in its map.
    polygon : ConvexPolygon
        The region, metres in the world frame, of positive area.
    terrain : str
        Terrain type, a name in the terrain table the map is used with.
    landmark_ids : tuple of str
        Ids of the landmarks visible from somewhere in the meadow (they need not lie in
        it), without repeats. Any iterable of strings is accepted and stored as a tuple.

    Examples
    --------
    >>> m = Meadow("walk", ConvexPolygon([(0, -1), (12, -1), (12, 1), (0, 1)]), "concrete", ["pole"])
    >>> m.landmark_ids, m.polygon.area
    (('pole',), 24.0)
    >>> Meadow("line", ConvexPolygon([(0, 0), (1, 0)]), "tile")
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: line.polygon: expected a polygon of positive area, got 2 vertices and area 0.0
    """

    id: str
    polygon: ConvexPolygon
    terrain: str
    landmark_ids: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        ident = _identifier(self.id, "Meadow.id")
        if not isinstance(self.polygon, ConvexPolygon):
            raise InputError(f"{ident}.polygon: expected a ConvexPolygon, got {type(self.polygon).__name__}")
        if self.polygon.vertex_count < 3 or not self.polygon.area > 0.0:
            raise InputError(
                f"{ident}.polygon: expected a polygon of positive area, got "
                f"{self.polygon.vertex_count} vertices and area {self.polygon.area!r}"
            )
        _identifier(self.terrain, f"{ident}.terrain")
        if isinstance(self.landmark_ids, str) or not isinstance(self.landmark_ids, Iterable):
            raise InputError(f"{ident}.landmark_ids: expected a sequence of ids, got {self.landmark_ids!r}")
        ids = tuple(self.landmark_ids)
        seen: set[str] = set()  # a set, not ids[:index]: that was quadratic (99 s at 10^5 ids)
        for index, landmark_id in enumerate(ids):
            _identifier(landmark_id, f"{ident}.landmark_ids[{index}]")
            if landmark_id in seen:
                raise InputError(
                    f"{ident}.landmark_ids[{index}]: expected each id once, got {landmark_id!r} again"
                )
            seen.add(landmark_id)
        object.__setattr__(self, "landmark_ids", ids)

    def __hash__(self) -> int:
        return hash((self.id, self.terrain, self.landmark_ids))


@dataclass(frozen=True, slots=True, eq=False, init=False)
class MeadowMap:
    """The meadow map: convex meadows of free space and the landmarks they see (LTM).

    Coordinates are metres in the world frame (x east, y north). The map is validated
    once, on construction; it then answers spatial queries through a shapely ``STRtree``
    and knows which meadows are adjacent (share a boundary segment at least 1 mm long,
    gaps up to 1e-6 m closed).

    Parameters
    ----------
    meadows : iterable of Meadow
        At least one; unique ids; interiors must not overlap (more than 1e-6 m^2): the
        meadows partition free space.
    landmarks : iterable of LandmarkRecord
        The landmark records; unique ids, distinct from the meadow ids. Every id in a
        meadow's ``landmark_ids`` must be among them.
    terrain_table : TerrainTable, optional
        When given, every meadow's terrain must be a name in it.
    terrain_table_file : str, optional
        Name of the terrain table file the map goes with (as written in its GeoJSON file,
        relative to it). Kept for saving; reading it is the loader's business.

    Notes
    -----
    Two maps are equal when their meadows, landmarks and ``terrain_table_file`` are: the
    ``terrain_table`` they were checked against is context, not content (a GeoJSON file
    holds only the table's file name).

    Raises
    ------
    InputError
        For any inconsistency, naming the meadows or landmarks involved.
    UnknownTerrainError
        When ``terrain_table`` is given and a meadow's terrain is not in it.

    Examples
    --------
    >>> from aura_ums.geometry import ConvexPolygon
    >>> west = Meadow("west", ConvexPolygon([(0, 0), (5, 0), (5, 2), (0, 2)]), "concrete")
    >>> east = Meadow("east", ConvexPolygon([(5, 0), (9, 0), (9, 2), (5, 2)]), "grass")
    >>> world = MeadowMap([west, east])
    >>> [m.id for m in world.neighbours("west")], world.meadow_at(6.0, 1.0).id
    (['east'], 'east')
    >>> world.portal("west", "east").tolist()
    [[5.0, 0.0], [5.0, 2.0]]
    >>> world.meadow_at(20.0, 0.0) is None        # outside every meadow
    True
    >>> over = Meadow("over", ConvexPolygon([(4, 0), (6, 0), (6, 1)]), "tile")
    >>> MeadowMap([west, over])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: 'west' and 'over' polygon: expected meadows that do not overlap, got ...m^2
    """

    meadows: tuple[Meadow, ...]
    landmarks: tuple[LandmarkRecord, ...]
    terrain_table: TerrainTable | None
    terrain_table_file: str | None
    _meadow_index: Mapping[str, int]
    _landmark_index: Mapping[str, int]
    _shapes: tuple[Polygon, ...]
    _tree: shapely.STRtree
    _clip: tuple[tuple[float, float, float, float, tuple[tuple[float, float, float, float], ...]], ...]
    _halfplanes: tuple[NDArray[np.float64], ...]
    _portals: Mapping[tuple[str, str], NDArray[np.float64]]
    _adjacent: Mapping[str, tuple[str, ...]]
    _overlapping: frozenset[int]

    def __init__(
        self,
        meadows: Iterable[Meadow],
        landmarks: Iterable[LandmarkRecord] = (),
        *,
        terrain_table: TerrainTable | None = None,
        terrain_table_file: str | None = None,
    ) -> None:
        try:
            self._setup(meadows, landmarks, terrain_table, terrain_table_file)
        except _MapError as exc:
            raise InputError(str(exc)) from None

    @classmethod
    def _create(
        cls,
        meadows: Iterable[Meadow],
        landmarks: Iterable[LandmarkRecord],
        terrain_table: TerrainTable | None,
        terrain_table_file: str | None,
    ) -> MeadowMap:
        """Build a map, raising :class:`_MapError` (which names the items) on inconsistencies."""
        meadow_map = object.__new__(cls)
        meadow_map._setup(meadows, landmarks, terrain_table, terrain_table_file)
        return meadow_map

    def _setup(
        self,
        meadows: Iterable[Meadow],
        landmarks: Iterable[LandmarkRecord],
        terrain_table: TerrainTable | None,
        terrain_table_file: str | None,
    ) -> None:
        meadow_tuple = items_of(meadows, "meadows", "a sequence of Meadow")
        landmark_tuple = items_of(landmarks, "landmarks", "a sequence of LandmarkRecord")
        if not meadow_tuple:
            raise InputError("meadows: expected at least one meadow, got none")
        for index, meadow in enumerate(meadow_tuple):
            if not isinstance(meadow, Meadow):
                raise InputError(f"meadows[{index}]: expected a Meadow, got {type(meadow).__name__}")
        for index, record in enumerate(landmark_tuple):
            if not isinstance(record, LandmarkRecord):
                raise InputError(
                    f"landmarks[{index}]: expected a LandmarkRecord, got {type(record).__name__}"
                )
        if terrain_table is not None and not isinstance(terrain_table, TerrainTable):
            raise InputError(f"terrain_table: expected a TerrainTable or None, got {terrain_table!r}")
        if terrain_table_file is not None:
            _identifier(terrain_table_file, "terrain_table_file")

        meadow_index: dict[str, int] = {}
        for index, meadow in enumerate(meadow_tuple):
            if meadow.id in meadow_index:
                raise _MapError((meadow.id,), "id", "expected a unique meadow id, got it twice")
            meadow_index[meadow.id] = index
        landmark_index: dict[str, int] = {}
        for index, record in enumerate(landmark_tuple):
            if record.id in landmark_index or record.id in meadow_index:
                raise _MapError((record.id,), "id", "expected a unique id, got it twice")
            landmark_index[record.id] = index
        for meadow in meadow_tuple:
            for position, landmark_id in enumerate(meadow.landmark_ids):
                if landmark_id not in landmark_index:
                    raise _MapError(
                        (meadow.id,),
                        f"landmark_ids[{position}]",
                        f"expected the id of a landmark of the map, got {landmark_id!r}",
                    )
            if terrain_table is not None and meadow.terrain not in terrain_table:
                known = ", ".join(sorted(terrain_table))
                raise UnknownTerrainError(
                    f"{meadow.id!r} terrain: expected one of {known}, got {meadow.terrain!r}"
                )

        shapes = tuple(shapely.Polygon(m.polygon.vertices) for m in meadow_tuple)
        tree = shapely.STRtree(shapes)
        portals, adjacent, overlapping = _adjacency(meadow_tuple, shapes, tree)

        object.__setattr__(self, "meadows", meadow_tuple)
        object.__setattr__(self, "landmarks", landmark_tuple)
        object.__setattr__(self, "terrain_table", terrain_table)
        object.__setattr__(self, "terrain_table_file", terrain_table_file)
        object.__setattr__(self, "_meadow_index", types.MappingProxyType(meadow_index))
        object.__setattr__(self, "_landmark_index", types.MappingProxyType(landmark_index))
        object.__setattr__(self, "_shapes", shapes)
        object.__setattr__(self, "_tree", tree)
        object.__setattr__(self, "_clip", tuple(_clip_edges(m.polygon.vertices) for m in meadow_tuple))
        object.__setattr__(self, "_halfplanes", tuple(_halfplanes(m.polygon.vertices) for m in meadow_tuple))
        object.__setattr__(self, "_portals", types.MappingProxyType(portals))
        object.__setattr__(self, "_adjacent", types.MappingProxyType(adjacent))
        object.__setattr__(self, "_overlapping", overlapping)

    # --- loading and saving ----------------------------------------------------------------

    @classmethod
    def from_geojson(cls, path: str | Path, *, terrain_table: TerrainTable | None = None) -> MeadowMap:
        """Read a meadow map from a GeoJSON file (format: :mod:`aura_ums.world` docs).

        Parameters
        ----------
        path : str or Path
            The GeoJSON FeatureCollection. Coordinates are metres in the world frame; a
            ``crs`` member, if any, is ignored (no reprojection).
        terrain_table : TerrainTable, optional
            Table to check the meadows' terrains against. Without it, the table the file
            names in its ``terrain_table`` member (a TOML path relative to the file) is
            read, if any; otherwise terrains are not checked.

        Raises
        ------
        FileFormatError
            Naming the file, the feature (index and id) and the property, for unreadable
            files, malformed JSON, wrong geometry, missing or invalid properties,
            non-convex or overlapping meadows, unknown landmark ids, unknown terrains and
            duplicate ids.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> from aura_ums.world import make_grid_world
        >>> world = make_grid_world(2, 3)
        >>> with tempfile.TemporaryDirectory() as folder:
        ...     path = pathlib.Path(folder) / "grid.geojson"
        ...     world.to_geojson(path)
        ...     MeadowMap.from_geojson(path) == world
        True
        """
        from aura_ums.world._geojson import read_geojson

        return read_geojson(path, terrain_table=terrain_table)

    @classmethod
    def from_geojson_dict(
        cls,
        document: object,
        *,
        source: str = "<geojson>",
        base: str | Path = ".",
        terrain_table: TerrainTable | None = None,
    ) -> MeadowMap:
        """Build a meadow map from a parsed GeoJSON document (see :meth:`from_geojson`).

        ``source`` names the document in error messages; a ``terrain_table`` member is
        resolved relative to the folder ``base``.

        Examples
        --------
        >>> ring = [[0, 0], [0, 2], [4, 2], [4, 0], [0, 0]]          # clockwise is fine
        >>> walk = {"type": "Feature", "geometry": {"type": "Polygon", "coordinates": [ring]},
        ...         "properties": {"kind": "meadow", "id": "walk", "terrain": "concrete"}}
        >>> world = MeadowMap.from_geojson_dict({"type": "FeatureCollection", "features": [walk]})
        >>> world.meadow("walk").polygon.vertices.tolist()
        [[0.0, 0.0], [4.0, 0.0], [4.0, 2.0], [0.0, 2.0]]
        >>> walk["properties"]["landmarks"] = ["pole"]
        >>> MeadowMap.from_geojson_dict({"type": "FeatureCollection", "features": [walk]})
        Traceback (most recent call last):
        ...
        aura_ums.errors.FileFormatError: <geojson>: features[0] (id 'walk') properties.landmarks[0]: \
expected the id of a landmark feature, got 'pole'
        """
        from aura_ums.world._geojson import parse_geojson

        return parse_geojson(document, source=source, base=Path(base), terrain_table=terrain_table)

    def to_geojson_dict(self) -> dict[str, object]:
        """Return the map as a GeoJSON FeatureCollection (plain dicts, lists, floats).

        Meadows come first, then landmarks, each in map order. Floats are kept exactly, so
        ``MeadowMap.from_geojson_dict(m.to_geojson_dict()) == m``.

        Examples
        --------
        >>> from aura_ums.world import make_grid_world
        >>> document = make_grid_world(1, 1).to_geojson_dict()
        >>> [f["properties"]["kind"] for f in document["features"]]
        ['meadow', 'landmark']
        >>> document["features"][0]["geometry"]["coordinates"][0][-1]   # rings are closed
        [0.0, 0.0]
        """
        from aura_ums.world._geojson import to_document

        return to_document(self)

    def to_geojson(self, path: str | Path) -> None:
        """Write the map to a GeoJSON file that :meth:`from_geojson` reads back exactly.

        One feature per line; floats are written with ``repr`` precision. The file is
        written atomically (its folder made when missing): a failed write, on a full disk
        say, leaves the old file, or none.

        Raises
        ------
        FileFormatError
            When the file cannot be written, with the system's reason.
        """
        from aura_ums.world._geojson import write_geojson

        write_geojson(self, path)

    # --- lookups ---------------------------------------------------------------------------

    def meadow(self, meadow_id: str) -> Meadow:
        """Return the meadow named ``meadow_id``.

        Raises
        ------
        UnknownTerrainError
            (a ``KeyError``) when the map has no such meadow.
        """
        try:
            index = self._meadow_index.get(meadow_id)
        except TypeError:  # unhashable: checked only here, off the lookups' path
            raise InputError(
                f"meadow: expected a meadow id (a str), got {type(meadow_id).__name__}"
            ) from None
        if index is None:
            raise UnknownTerrainError(f"meadow: expected the id of a meadow of this map, got {meadow_id!r}")
        return self.meadows[index]

    def landmark(self, landmark_id: str) -> LandmarkRecord:
        """Return the landmark record named ``landmark_id``.

        Raises
        ------
        UnknownLandmarkError
            (a ``KeyError``) when the map has no such landmark.
        """
        try:
            index = self._landmark_index.get(landmark_id)
        except TypeError:  # unhashable: checked only here, off the lookups' path
            raise InputError(
                f"landmark: expected a landmark id (a str), got {type(landmark_id).__name__}"
            ) from None
        if index is None:
            raise UnknownLandmarkError(
                f"landmark: expected the id of a landmark of this map, got {landmark_id!r}"
            )
        return self.landmarks[index]

    def landmarks_visible_from(self, meadow_id: str) -> tuple[LandmarkRecord, ...]:
        """Return the records of the landmarks visible from a meadow, in its list's order."""
        return tuple(self.landmark(i) for i in self.meadow(meadow_id).landmark_ids)

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """Bounding box ``(x_min, y_min, x_max, y_max)`` of all meadows, metres."""
        boxes = np.array([m.polygon.bounds for m in self.meadows])
        return (
            float(boxes[:, 0].min()),
            float(boxes[:, 1].min()),
            float(boxes[:, 2].max()),
            float(boxes[:, 3].max()),
        )

    @property
    def terrains(self) -> tuple[str, ...]:
        """The terrain names of the meadows, each once, sorted.

        Examples
        --------
        >>> from aura_ums.world import make_grid_world
        >>> make_grid_world(1, 5).terrains                    # five cells, four terrains
        ('concrete', 'grass', 'gravel', 'tile')
        """
        return tuple(sorted({meadow.terrain for meadow in self.meadows}))

    # --- spatial queries -------------------------------------------------------------------

    def meadows_containing(self, x: float, y: float) -> tuple[Meadow, ...]:
        """Return every meadow containing (x, y) (boundary included), in map order.

        A point on a shared boundary is in both meadows.
        """
        point = shapely.Point(finite_float(x, "x"), finite_float(y, "y"))
        hits = self._tree.query(point, predicate="dwithin", distance=POSITION_TOLERANCE)
        return tuple(self.meadows[int(i)] for i in np.sort(hits))

    def meadow_at(self, x: float, y: float) -> Meadow | None:
        """Return the meadow containing (x, y), or None outside every meadow.

        On a boundary shared by several meadows, the first in map order.
        """
        found = self.meadows_containing(x, y)
        return found[0] if found else None

    def meadows_at(self, points: ArrayLike) -> tuple[Meadow | None, ...]:
        """Return, for each point of ``(n, 2)``, the meadow containing it or None (vectorized).

        Examples
        --------
        >>> from aura_ums.world import make_grid_world
        >>> world = make_grid_world(1, 2)
        >>> [m.id if m else None for m in world.meadows_at([(1, 1), (7, 1), (50, 0)])]
        ['cell_0_0', 'cell_0_1', None]
        """
        pts = points_array(points, "points")
        found: list[Meadow | None] = [None] * len(pts)
        if len(pts):
            hits = self._tree.query(shapely.points(pts), predicate="dwithin", distance=POSITION_TOLERANCE)
            # Walk the pairs backwards so that the first meadow in map order wins.
            order = np.lexsort((-hits[1], -hits[0]))
            for point_index, meadow_index in hits[:, order].T:
                found[int(point_index)] = self.meadows[int(meadow_index)]
        return tuple(found)

    def meadows_near(self, points: ArrayLike, distance: float) -> tuple[Meadow, ...]:
        """Return the meadows within ``distance`` metres of the polyline through ``points``.

        A single point is allowed. Meadows come in map order.
        """
        pts = points_array(points, "points", min_rows=1)
        reach = finite_float(distance, "distance")
        if reach < 0.0:
            raise InputError(f"distance: expected a non-negative number, got {reach!r}")
        geometry = shapely.Point(pts[0]) if len(pts) == 1 else shapely.LineString(pts)
        hits = self._tree.query(geometry, predicate="dwithin", distance=max(reach, POSITION_TOLERANCE))
        return tuple(self.meadows[int(i)] for i in np.sort(hits))

    def shape(self, meadow_id: str) -> Polygon:
        """Return a meadow's polygon as a shapely Polygon."""
        return self._shapes[self._meadow_index[self.meadow(meadow_id).id]]

    def neighbours(self, meadow_id: str) -> tuple[Meadow, ...]:
        """Return the meadows adjacent to ``meadow_id`` (sharing a portal), in map order."""
        return tuple(self.meadow(i) for i in self._adjacent[self.meadow(meadow_id).id])

    def portal(self, a: str, b: str) -> NDArray[np.float64]:
        """Return the portal between adjacent meadows ``a`` and ``b``: a read-only ``(2, 2)`` segment.

        Its midpoint is where routes cross from one meadow to the other.

        Raises
        ------
        InputError
            When the two meadows are not adjacent.
        """
        first, second = self.meadow(a).id, self.meadow(b).id
        key = (first, second) if self._meadow_index[first] < self._meadow_index[second] else (second, first)
        found = self._portals.get(key)
        if found is None:
            raise InputError(f"meadows: expected two adjacent meadows, got {a!r} and {b!r}")
        return found

    def portals(self) -> Iterable[tuple[str, str, NDArray[np.float64]]]:
        """Yield every portal as ``(meadow_a, meadow_b, segment (2, 2))``, each pair once."""
        for (a, b), segment in self._portals.items():
            yield a, b, segment

    def __len__(self) -> int:
        return len(self.meadows)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, MeadowMap):
            return NotImplemented
        return (
            self.meadows == other.meadows
            and self.landmarks == other.landmarks
            and self.terrain_table_file == other.terrain_table_file
        )

    def __repr__(self) -> str:
        return f"MeadowMap({len(self.meadows)} meadows, {len(self.landmarks)} landmarks)"

    __hash__ = None  # type: ignore[assignment]


def _halfplanes(vertices: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return a convex meadow as half-planes, shape (k, 4).

    Per edge: the unit outward normal ``(nx, ny)``, the offset ``c`` (inside:
    ``nx x + ny y <= c``, metres) and the normal's angle (radians).
    """
    edges = np.roll(vertices, -1, axis=0) - vertices
    lengths = np.hypot(edges[:, 0], edges[:, 1])
    keep = lengths > 0.0
    normals = np.column_stack((edges[keep, 1], -edges[keep, 0])) / lengths[keep, None]  # ccw: outward
    offsets = np.einsum("ij,ij->i", normals, vertices[keep])
    planes = np.column_stack((normals, offsets, np.arctan2(normals[:, 1], normals[:, 0])))
    planes.setflags(write=False)
    return planes


def _clip_edges(
    vertices: NDArray[np.float64],
) -> tuple[float, float, float, float, tuple[tuple[float, float, float, float], ...]]:
    """Return a convex meadow as plain floats for clipping runs: bounding box and edges.

    Per edge: a point ``(ax, ay)`` and the outward normal ``(nx, ny)``; inside is
    ``n . (p - a) <= 0``.
    """
    points = [(float(x), float(y)) for x, y in vertices]
    edges = []
    for (ax, ay), (bx, by) in zip(points, points[1:] + points[:1], strict=True):
        edges.append((ax, ay, by - ay, ax - bx))  # counter-clockwise: outward is the edge turned right
    xs, ys = [x for x, _ in points], [y for _, y in points]
    return min(xs), min(ys), max(xs), max(ys), tuple(edges)


def _adjacency(
    meadows: Sequence[Meadow], shapes: Sequence[Polygon], tree: shapely.STRtree
) -> tuple[dict[tuple[str, str], NDArray[np.float64]], dict[str, tuple[str, ...]], frozenset[int]]:
    """Find the portals between meadows; refuse overlapping meadows.

    Also return the indices of the meadows that overlap another within the tolerance: a
    straight run may then leave one of them and come back (growth through meadows counts
    its pieces accordingly).
    """
    pairs = tree.query(list(shapes), predicate="dwithin", distance=_ADJACENCY_TOLERANCE)
    keep = pairs[0] < pairs[1]
    first, second = pairs[0][keep], pairs[1][keep]
    a_shapes = np.array(shapes, dtype=object)[first]
    b_shapes = np.array(shapes, dtype=object)[second]
    exact = shapely.intersection(a_shapes, b_shapes)
    overlap = shapely.area(exact)
    for i, j, area in zip(first, second, overlap, strict=True):
        if area > _OVERLAP_TOLERANCE:
            raise _MapError(
                (meadows[int(i)].id, meadows[int(j)].id),
                "polygon",
                f"expected meadows that do not overlap, got an overlap of {float(area):.6g} m^2",
            )
    # Exactly touching meadows share a segment; otherwise look for the part of one boundary
    # within the tolerance of the other (rounding in files leaves slivers of gap).
    segments = [_portal_segment(touching) for touching in exact]
    retry = np.flatnonzero([segment is None for segment in segments])
    if len(retry):
        near = shapely.intersection(
            shapely.boundary(a_shapes[retry]), shapely.buffer(b_shapes[retry], _ADJACENCY_TOLERANCE)
        )
        for k, close in zip(retry, near, strict=True):
            segments[int(k)] = _portal_segment(close)
    portals: dict[tuple[str, str], NDArray[np.float64]] = {}
    neighbours: dict[str, list[int]] = {m.id: [] for m in meadows}
    for i, j, segment in zip(first, second, segments, strict=True):
        if segment is None:
            continue
        a, b = meadows[int(i)].id, meadows[int(j)].id
        portals[(a, b)] = read_only(segment)
        neighbours[a].append(int(j))
        neighbours[b].append(int(i))
    adjacent = {name: tuple(meadows[k].id for k in sorted(found)) for name, found in neighbours.items()}
    overlapping = frozenset(
        int(k) for i, j, area in zip(first, second, overlap, strict=True) if area > 0.0 for k in (i, j)
    )
    return portals, adjacent, overlapping


def _portal_segment(geometry: BaseGeometry) -> NDArray[np.float64] | None:
    """Return the ends of the (near-)straight shared boundary piece, or None when too short."""
    if geometry.is_empty or shapely.length(geometry) < _MIN_PORTAL_WIDTH:
        return None
    coordinates = shapely.get_coordinates(geometry)
    start = coordinates[np.argmax(np.hypot(*(coordinates - coordinates[0]).T))]
    end = coordinates[np.argmax(np.hypot(*(coordinates - start).T))]
    if math.hypot(*(end - start)) < _MIN_PORTAL_WIDTH:
        return None
    # Store the portal in a canonical direction (lexicographic), so that it does not
    # depend on the vertex order of the polygons.
    ends = np.array([start, end], dtype=np.float64)
    if (ends[1, 0], ends[1, 1]) < (ends[0, 0], ends[0, 1]):
        ends = ends[::-1].copy()
    return ends
