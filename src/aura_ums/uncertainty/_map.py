"""The spatial uncertainty map: a convex polygon of positions and a compass wedge of headings.

A map is either a *product* (the paper's: every position of the polygon with every heading
of the wedge) or *sliced* (``_slices``): a convex polygon of positions per interval of a
fixed global heading grid, which keeps the coupling of position and heading that a long run
creates. The polygon and the wedge of a sliced map are its summary: the hull of the slices'
polygons and the smallest wedge holding their intervals.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums import _native
from aura_ums._validate import (
    SIGMAS,
    START_RADIUS,
    check_rng,
    finite_float,
    float_array,
    integer_at_least,
    nonnegative_float,
    points_array,
    read_only,
    vertex_cap,
)
from aura_ums.errors import InputError
from aura_ums.geometry import (
    POSITION_TOLERANCE,
    ConvexPolygon,
    HeadingWedge,
    Pose,
    convex_hull,
    outer_disk,
    points_in_convex,
    polygon_area,
    wrap_angle,
)
from aura_ums.uncertainty._growth import DEFAULT_MAX_VERTICES
from aura_ums.uncertainty._landmarks import Landmark, Observation
from aura_ums.uncertainty._motion import TurnAndRun
from aura_ums.uncertainty._reduce import Kept, Reduced, Reduction, reduce_checked, reduce_kept, reduce_map
from aura_ums.uncertainty._slices import (
    DEFAULT_MAX_SLICES,
    DEFAULT_SLICE_WIDTH,
    HeadingSlice,
    SliceSet,
    cell_count,
    distributed,
    heading_slices,
    packed,
    point_in,
    slice_cap,
    split_product,
    summary_polygon,
)
from aura_ums.uncertainty._slices import contains as slices_contain
from aura_ums.uncertainty._slices import contains_one as slices_contain_one
from aura_ums.uncertainty._terrain import TerrainStats

_START_DISK_SIDES = 16
#: Most poses :meth:`SpatialUncertaintyMap.sample_poses` draws at once (24 bytes each, 240 MB):
#: 10**12 asked for 7.28 TiB.
MAX_SAMPLES = 10_000_000


def sample_count(value: object, name: str) -> int:
    """Return a count of poses to draw, an integer in [0, :data:`MAX_SAMPLES`], or raise naming ``name``."""
    count = integer_at_least(value, name, 0)
    if count > MAX_SAMPLES:
        raise InputError(
            f"{name}: expected at most {MAX_SAMPLES} poses (about {24 * MAX_SAMPLES // 10**6} MB), "
            f"got {count} (about {24 * count / 1e9:.3g} GB)"
        )
    return count


@dataclass(frozen=True, slots=True, eq=False, init=False)
class SpatialUncertaintyMap:
    """Where the robot may be (a convex polygon) and which way it may face (a wedge).

    The map is a guaranteed region: every pose whose position lies in ``polygon``
    and whose heading lies in ``wedge`` is possible, and no other is. ``center`` is
    the most probable position and ``wedge.center`` the most probable heading.

    Parameters
    ----------
    polygon : ConvexPolygon
        Possible positions, metres, world frame.
    center : array_like, shape (2,)
        Most probable position (x, y), metres; must lie in ``polygon``.
    wedge : HeadingWedge
        Possible headings, radians.

    Examples
    --------
    >>> import math
    >>> from aura_ums.uncertainty import TerrainTable
    >>> start = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.3, math.radians(5))
    >>> grown = start.grow(TurnAndRun(math.pi / 4, 9.0), TerrainTable.default()["concrete"])
    >>> grown.area > start.area, grown.contains(Pose(6.0, 6.0, math.pi / 4))
    (True, True)
    >>> start.grow(TurnAndRun(0.0, 0.0), TerrainTable.default()["grass"]).area == start.area
    True
    """

    # The polygon; for a sliced map the hull of its slices, built on first use (a frame's
    # growth and reductions each make a map, and only the last one's summary is read).
    _polygon: ConvexPolygon | None = field(repr=False, compare=False)
    center: NDArray[np.float64]
    wedge: HeadingWedge
    # The most probable pose, built on first use: the Expecter, the schemas and the
    # manager's meadow lookups ask for it several times per frame.
    _pose: Pose | None = field(init=False, repr=False, compare=False)
    # The slices of a sliced map (None: a product map), the grid's cell count and the cap
    # on the slice count.
    _slices: SliceSet | None = field(init=False, repr=False, compare=False)
    _cells: int = field(init=False, repr=False, compare=False)
    _max_slices: int = field(init=False, repr=False, compare=False)

    def __init__(self, polygon: ConvexPolygon, center: ArrayLike, wedge: HeadingWedge) -> None:
        if not isinstance(polygon, ConvexPolygon):
            raise InputError(f"polygon: expected a ConvexPolygon, got {type(polygon).__name__}")
        if not isinstance(wedge, HeadingWedge):
            raise InputError(f"wedge: expected a HeadingWedge, got {type(wedge).__name__}")
        point = points_array(center, "center", min_rows=1)
        if point.shape != (1, 2):
            raise InputError(f"center: expected one (x, y) point, got shape {point.shape}")
        if not polygon.contains(point, tolerance=1e-6)[0]:
            raise InputError(f"center: expected a point inside the polygon, got {point[0].tolist()}")
        object.__setattr__(self, "_polygon", polygon)
        object.__setattr__(self, "center", read_only(point[0].copy()))
        object.__setattr__(self, "wedge", wedge)
        object.__setattr__(self, "_pose", None)
        object.__setattr__(self, "_slices", None)
        object.__setattr__(self, "_cells", 0)
        object.__setattr__(self, "_max_slices", 0)

    @classmethod
    def _trusted(
        cls, polygon: ConvexPolygon, center: NDArray[np.float64], wedge: HeadingWedge
    ) -> SpatialUncertaintyMap:
        center.setflags(write=False)
        return cls._made(polygon, center, wedge, None, 0, 0)

    @classmethod
    def _at(cls, polygon: ConvexPolygon, x: float, y: float, wedge: HeadingWedge) -> SpatialUncertaintyMap:
        """:meth:`_trusted` with the centre given as numbers (a kernel's), made read-only at no cost."""
        # A view of the two numbers' bytes: read-only, and cheaper than np.array and setflags.
        return cls._made(polygon, np.frombuffer(_pack_point(x, y), dtype=np.float64), wedge, None, 0, 0)

    @classmethod
    def _sliced(
        cls,
        slices: SliceSet,
        center: NDArray[np.float64],
        wedge: HeadingWedge,
        cells: int,
        max_slices: int,
        polygon: ConvexPolygon | None = None,
    ) -> SpatialUncertaintyMap:
        """Build a sliced map from its slices and their summary wedge (as the slice kernels give it)."""
        center.setflags(write=False)
        return cls._made(polygon, center, wedge, slices, cells, max_slices)

    def _moved(self, dx: float, dy: float, *, merge: bool = False) -> SpatialUncertaintyMap:
        """Return this map moved by (dx, dy) metres, headings kept (a frame moved next to it).

        With ``merge``, each polygon is the hull of its moved vertices
        (:func:`~aura_ums.geometry.convex_hull` keeping straight vertices), which holds it:
        far from the origin two vertices a rounding step apart make an edge that points
        anywhere, and its line would cut into the polygon; the hull drops the one that does.
        """
        step = np.array([dx, dy])
        center = self.center + step
        slices = self._slices
        if slices is None:
            vertices = self.polygon.vertices + step
            if merge:
                vertices = convex_hull(vertices, straight=True)
            return SpatialUncertaintyMap._trusted(ConvexPolygon._trusted(vertices), center, self.wedge)
        if merge:
            polygons = [convex_hull(polygon + step, straight=True) for polygon in slices.polygons()]
            points = np.concatenate(polygons)
            counts = np.array([len(polygon) for polygon in polygons], dtype=np.int64)
        else:
            points, counts = slices.points + step, slices.counts
        points.setflags(write=False)
        return SpatialUncertaintyMap._sliced(
            slices._replace(points=points, counts=counts), center, self.wedge, self._cells, self._max_slices
        )

    @classmethod
    def _made(
        cls,
        polygon: ConvexPolygon | None,
        center: NDArray[np.float64],
        wedge: HeadingWedge,
        slices: SliceSet | None,
        cells: int,
        max_slices: int,
    ) -> SpatialUncertaintyMap:
        """Set every slot of a new map by the slots' own setters: every growth and reduction builds one."""
        result = object.__new__(cls)
        _set_polygon(result, polygon)
        _set_center(result, center)
        _set_wedge(result, wedge)
        _set_pose(result, None)
        _set_slices(result, slices)
        _set_cells(result, cells)
        _set_max_slices(result, max_slices)
        return result

    @property
    def polygon(self) -> ConvexPolygon:
        """Possible positions (metres, world frame); for a sliced map the hull of its slices."""
        polygon = self._polygon
        if polygon is None:
            slices = self._slices
            assert slices is not None  # only a sliced map defers its polygon
            polygon = ConvexPolygon._trusted(summary_polygon(slices))
            _set_polygon(self, polygon)
        return polygon

    @property
    def is_sliced(self) -> bool:
        """Whether the map keeps heading slices (else it is the paper's product map)."""
        return self._slices is not None

    @property
    def slice_width(self) -> float | None:
        """Width of the heading grid's cells, radians; None for a product map."""
        return None if self._slices is None else 2.0 * math.pi / self._cells

    @property
    def max_slices(self) -> int | None:
        """Cap on the slice count; None for a product map."""
        return None if self._slices is None else self._max_slices

    @property
    def slices(self) -> tuple[HeadingSlice, ...]:
        """The map as heading slices, ordered by heading: one (the polygon and wedge) for a product map.

        Every pose of the map lies in some slice: its position in the slice's polygon and
        its heading in the slice's interval.

        Examples
        --------
        >>> start = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.5, math.radians(3))
        >>> len(start.slices), len(start.with_slices(math.radians(2)).slices)
        (1, 4)
        """
        slices = self._slices
        if slices is None:
            wedge = self.wedge
            lo = (wedge.center - wedge.cw) % (2.0 * math.pi)
            return (HeadingSlice(self.polygon, lo, wedge.width),)
        return heading_slices(slices)

    def with_slices(
        self, slice_width: float = DEFAULT_SLICE_WIDTH, max_slices: int = DEFAULT_MAX_SLICES
    ) -> SpatialUncertaintyMap:
        """Return this map as a sliced map: one slice per heading cell the wedge covers.

        The pose set is the same (a product map's polygon at every covered cell's part of
        the wedge); growth and reductions then act slice by slice, keeping position and
        heading coupled. A sliced map is returned as it is when its grid and cap are these,
        else first taken back to its summary.

        Parameters
        ----------
        slice_width : float
            Widest grid cell, radians, in (0, 2 pi]; the grid has a whole number of cells,
            the first starting at heading 0.
        max_slices : int
            Cap on the slice count (>= 1): beyond it neighbours merge (an outer bound).

        Examples
        --------
        >>> start = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.5, math.radians(5))
        >>> sliced = start.with_slices(math.radians(2))
        >>> sliced.is_sliced, len(sliced.slices), sliced.area == start.area
        (True, 6, True)
        >>> len(start.with_slices(math.radians(2), max_slices=1).slices)   # capped: one slice
        1
        """
        width = finite_float(slice_width, "slice_width")
        if not 0.0 < width <= 2.0 * math.pi:
            raise InputError(f"slice_width: expected radians in (0, 2 pi], got {width!r}")
        cap = slice_cap(max_slices)
        cells = cell_count(width)
        if self._slices is not None and self._cells == cells and self._max_slices == cap:
            return self
        wedge = self.wedge
        polygon = self.polygon
        vertices = polygon.vertices
        slices, summary = split_product(
            vertices, wedge.center - wedge.cw, wedge.width, cells, cap, wedge.center
        )
        return SpatialUncertaintyMap._sliced(slices, self.center, summary, cells, cap, polygon)

    @classmethod
    def from_slices(
        cls,
        slices: Sequence[HeadingSlice],
        center: ArrayLike,
        wedge: HeadingWedge,
        *,
        slice_width: float,
        max_slices: int,
    ) -> SpatialUncertaintyMap:
        """Build a sliced map from its parts (validated), as :attr:`slices` and the summary give them.

        The wedge is kept as given (a saved map is restored bit for bit); it must hold
        every slice's interval, and ``center`` must lie in some slice's polygon.

        Parameters
        ----------
        slices : sequence of HeadingSlice
            At least one and at most ``max_slices``, ordered by ``lo`` (radians in
            [0, 2 pi)), each ``width`` in [0, 2 pi].
        center : array_like, shape (2,)
            Most probable position, metres.
        wedge : HeadingWedge
            The summary wedge; its centre is the most probable heading.
        slice_width : float
            The grid's cell width, radians, in (0, 2 pi].
        max_slices : int
            Cap on the slice count, >= 1.

        Examples
        --------
        >>> start = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 0.5, 0.1).with_slices()
        >>> again = SpatialUncertaintyMap.from_slices(
        ...     start.slices, start.center, start.wedge, slice_width=start.slice_width, max_slices=48)
        >>> again.contains(Pose(0.1, 0.1, 0.05)), len(again.slices) == len(start.slices)
        (True, True)
        >>> SpatialUncertaintyMap.from_slices([], (0, 0), start.wedge, slice_width=0.1, max_slices=4)
        Traceback (most recent call last):
        ...
        aura_ums.errors.InputError: slices: expected 1 to 4 heading slices, got 0
        """
        width = finite_float(slice_width, "slice_width")
        if not 0.0 < width <= 2.0 * math.pi:
            raise InputError(f"slice_width: expected radians in (0, 2 pi], got {width!r}")
        cap = slice_cap(max_slices)
        if not isinstance(wedge, HeadingWedge):
            raise InputError(f"wedge: expected a HeadingWedge, got {type(wedge).__name__}")
        if not 1 <= len(slices) <= cap:
            raise InputError(f"slices: expected 1 to {cap} heading slices, got {len(slices)}")
        polygons: list[NDArray[np.float64]] = []
        los: list[float] = []
        his: list[float] = []
        for index, piece in enumerate(slices):
            if not isinstance(piece, HeadingSlice) or not isinstance(piece.polygon, ConvexPolygon):
                raise InputError(f"slices[{index}]: expected a HeadingSlice, got {type(piece).__name__}")
            lo = finite_float(piece.lo, f"slices[{index}].lo")
            span = finite_float(piece.width, f"slices[{index}].width")
            if not 0.0 <= lo < 2.0 * math.pi or not 0.0 <= span <= 2.0 * math.pi:
                raise InputError(
                    f"slices[{index}]: expected lo in [0, 2 pi) and width in [0, 2 pi], got {lo!r}, {span!r}"
                )
            if los and lo < los[-1]:
                raise InputError(
                    f"slices[{index}].lo: expected slices ordered by lo, got {lo!r} after {los[-1]!r}"
                )
            if not (wedge.contains(lo) and wedge.contains(lo + span)):
                raise InputError(
                    f"slices[{index}]: expected an interval inside the wedge, got {lo!r} + {span!r}"
                )
            polygons.append(piece.polygon.vertices)
            los.append(lo)
            his.append(lo + span)
        point = points_array(center, "center", min_rows=1)
        if point.shape != (1, 2):
            raise InputError(f"center: expected one (x, y) point, got shape {point.shape}")
        if not any(points_in_convex(p, point, 1e-6)[0] for p in polygons):
            raise InputError(f"center: expected a point inside a slice's polygon, got {point[0].tolist()}")
        result = object.__new__(cls)
        _set_polygon(result, None)
        _set_center(result, read_only(point[0].copy()))
        _set_wedge(result, wedge)
        _set_pose(result, None)
        points, counts, lo_array, hi_array, sources = packed(polygons, los, his)
        points.setflags(write=False)
        _set_slices(result, SliceSet(points, counts, lo_array, hi_array, sources))
        _set_cells(result, cell_count(width))
        _set_max_slices(result, cap)
        return result

    def without_slices(self) -> SpatialUncertaintyMap:
        """Return the product map of this map's summary (its polygon and wedge); itself when a product."""
        if self._slices is None:
            return self
        return SpatialUncertaintyMap._trusted(self.polygon, self.center, self.wedge)

    @classmethod
    def from_pose(cls, pose: Pose, position_radius: float, heading_halfwidth: float) -> SpatialUncertaintyMap:
        """Start a map around a pose.

        Parameters
        ----------
        pose : Pose
            Most probable pose.
        position_radius : float
            Radius of the disk of possible positions, metres, >= 0 (an outer polygon of
            the disk is used; 0 gives a point).
        heading_halfwidth : float
            Half-width of the heading wedge, radians, >= 0 (pi or more: any heading).
        """
        if not isinstance(pose, Pose):
            raise InputError(f"pose: expected a Pose, got {type(pose).__name__} {pose!r}")
        radius = START_RADIUS.check(position_radius, "position_radius")
        halfwidth = nonnegative_float(heading_halfwidth, "heading_halfwidth")
        center = np.array([pose.x, pose.y])
        polygon = ConvexPolygon._trusted(outer_disk(center, radius, _START_DISK_SIDES))
        if halfwidth >= math.pi:
            wedge = HeadingWedge.full_circle(pose.heading)
        else:
            wedge = HeadingWedge(pose.heading, halfwidth, halfwidth)
        return cls._trusted(polygon, center, wedge)

    @classmethod
    def from_polygon(
        cls, polygon: ConvexPolygon, center: ArrayLike, wedge: HeadingWedge
    ) -> SpatialUncertaintyMap:
        """Build a map from its parts (validated: the centre must lie in the polygon)."""
        return cls(polygon, center, wedge)

    @property
    def area(self) -> float:
        """Area of the position polygon, square metres."""
        return self.polygon.area

    @property
    def heading(self) -> float:
        """Most probable heading, radians in (-pi, pi]."""
        return self.wedge.center

    def most_probable_pose(self) -> Pose:
        """Return the map's centre and most probable heading as a Pose, a pose the map contains.

        The centre lies in the polygon (in the home slice's for a sliced map) within
        ``POSITION_TOLERANCE``: a reduction that cuts it away moves it to the nearest point
        the reduced polygon holds. The heading is the wedge's centre, the end of a one-sided
        wedge; a point polygon's centre is the point.
        """
        pose = self._pose
        if pose is None:
            pose = Pose(float(self.center[0]), float(self.center[1]), self.wedge.center)
            _set_pose(self, pose)
        return pose

    def grow(
        self,
        command: TurnAndRun,
        terrain: TerrainStats,
        *,
        sigmas: float = 3.0,
        max_vertices: int = DEFAULT_MAX_VERTICES,
    ) -> SpatialUncertaintyMap:
        """Return the map after a turn-and-run command on a terrain (the paper's growth).

        Contains every outcome of :meth:`TerrainStats.sample_motion` whose standard
        normals satisfy |z| <= ``sigmas``, from every pose of this map. The centre moves
        by the mean motion; the wedge takes the range of the turn asymmetrically and
        widens by the drift; the polygon is this one Minkowski-summed with the skitter
        disk and the region of run endpoints, arcs replaced by outer polygons.

        Parameters
        ----------
        command : TurnAndRun
            The commanded motion.
        terrain : TerrainStats
            Statistics of the terrain the motion happens on.
        sigmas : float
            Number of standard deviations bounded, in [0.1, 100] (3 keeps >= 99 % in practice).
        max_vertices : int
            Cap on the polygon's vertex count (>= 3); beyond it an outer approximation.
        """
        if not isinstance(command, TurnAndRun):
            raise InputError(f"command: expected a TurnAndRun, got {type(command).__name__}")
        if not isinstance(terrain, TerrainStats):
            raise InputError(f"terrain: expected TerrainStats, got {type(terrain).__name__}")
        bound = SIGMAS.check(sigmas, "sigmas")
        return self._grow_many((command,), terrain, bound, vertex_cap(max_vertices))

    def _grow_many(
        self,
        commands: Sequence[TurnAndRun],
        terrain: TerrainStats,
        sigmas: float,
        max_vertices: int = DEFAULT_MAX_VERTICES,
    ) -> SpatialUncertaintyMap:
        """Grow by each command in turn on one terrain: bit for bit a loop of :meth:`grow`.

        For callers that validated their arguments (the manager's position reports): one
        call of the growth kernel for the whole run.
        """
        if not commands:
            return self
        values: list[float] = []
        for command in commands:
            values += (command.turn, command.run)
        if self._slices is not None:
            return _grow_sliced(self, self._slices, values, terrain, sigmas, max_vertices)
        wedge, (x, y) = self.wedge, self.center.tolist()
        vertices, x, y, heading, cw, ccw = _native.grow_commands(
            self.polygon.vertices,
            x,
            y,
            wedge.center,
            wedge.cw,
            wedge.ccw,
            terrain,
            sigmas,
            values,
            max_vertices,
        )
        return SpatialUncertaintyMap._at(
            ConvexPolygon._trusted(vertices), x, y, HeadingWedge._trusted(heading, cw, ccw)
        )

    def reduce(
        self, observation: Observation, landmark: Landmark, *, max_vertices: int = DEFAULT_MAX_VERTICES
    ) -> Reduction:
        """Return the map reduced by one observation of a landmark (the paper's reductions).

        A set-membership intersection: the reduced map keeps every pose of this map
        that agrees with the observation within its error bounds (where the exact set
        is not a convex polygon and a wedge, an outer bound of it), and lies inside
        this map.

        - Class I (:class:`BearingObservation` of a :class:`VerticalLineLandmark`): the
          positions from which the landmark is seen at the bearing for some heading of
          the wedge form a cone at the landmark; the polygon is cut by it, then the
          wedge narrows to the headings that see the landmark at the bearing from what
          remains. Position, heading or both shrink, depending on which is larger.
        - Class II (:class:`RangeBearingObservation` of a :class:`PointLandmark`): the
          same cone, also cut by the range annulus, so the extent along the line of
          sight shrinks too; then the wedge narrows as in Class I.
        - Class III (:class:`GroundLineObservation` of a :class:`GroundLineLandmark`):
          the angle narrows the wedge directly, the offset cuts a strip parallel to the
          line (the true line is taken parallel to the mapped one, within its
          ``position_uncertainty``).

        Landmark position uncertainty and the observation's ``sensor_offset`` are
        allowed for (soundly, possibly loosely). The centre is kept when it is still
        possible, else moved to the nearest possible position and heading.

        Parameters
        ----------
        observation : BearingObservation or RangeBearingObservation or GroundLineObservation
            What the robot observed, with its error bounds.
        landmark : VerticalLineLandmark or PointLandmark or GroundLineLandmark
            The landmark observed: of the observation's class and with its ``landmark_id``.
        max_vertices : int
            Cap on the polygon's vertex count (>= 3); it may be exceeded only by a prior
            that already has more vertices, since the result must stay inside the prior.

        Returns
        -------
        Reduction
            The reduced map with what changed; ``consistent=False`` and this very map
            when no pose agrees with the observation (the caller decides what that means).

        Raises
        ------
        InputError
            When the observation and landmark are of different classes or ids.

        Examples
        --------
        >>> import math
        >>> from aura_ums.uncertainty import BearingObservation, VerticalLineLandmark
        >>> prior = SpatialUncertaintyMap.from_pose(Pose(0, 0, 0), 2.0, math.radians(1))
        >>> pole = VerticalLineLandmark("pole", 10.0, 0.0, 0.0, 5.0)
        >>> seen = prior.reduce(BearingObservation("pole", 0.0, 0.0, math.radians(1)), pole)
        >>> seen.consistent, seen.area_after < 0.5 * seen.area_before, seen.map.contains(Pose(0, 0, 0))
        (True, True, True)
        >>> behind = prior.reduce(BearingObservation("pole", 0.0, math.pi, 0.01), pole)
        >>> behind.consistent, behind.map is prior, behind.reason != ""   # empty intersection
        (False, True, True)
        """
        return reduce_map(self, observation, landmark, max_vertices)

    def _reduce_checked(
        self,
        observation: Observation,
        landmark: Landmark,
        max_vertices: int = DEFAULT_MAX_VERTICES,
        *,
        measured: bool = True,
    ) -> Reduced:
        """:meth:`reduce` for a caller that paired the landmark with the observation by id and class.

        Returns (reduced map, area before, area after), or why no pose agrees: the
        manager reads nothing else, so no :class:`Reduction` is built. Without
        ``measured`` a sliced map's areas may be NaN (see ``reduce_checked``).
        """
        return reduce_checked(self, observation, landmark, max_vertices, measured=measured)

    def _reduce_jointly(
        self, pairs: Sequence[tuple[Observation, Landmark]], sector: float, max_vertices: int
    ) -> SpatialUncertaintyMap | str:
        """:func:`~aura_ums.uncertainty.reduce_jointly` for checked pairs: the map, or why none agrees.

        For the map manager, which reads no area and pairs each observation with its
        landmark by id and class itself (``sector`` in (0, 2 pi], ``max_vertices >= 3``).
        """
        # The joint reduction builds maps of this class: its module imports this one.
        from aura_ums.uncertainty._joint import joint_reduced

        return joint_reduced(self, pairs, sector, max_vertices)

    def _reduce_kept(
        self, observation: Observation, landmark: Landmark, max_vertices: int = DEFAULT_MAX_VERTICES
    ) -> Kept:
        """:meth:`_reduce_checked`, telling only whether the result is the same set (see ``reduce_kept``)."""
        return reduce_kept(self, observation, landmark, max_vertices)

    @overload
    def contains(self, pose: Pose, y: None = None, heading: None = None) -> bool: ...
    @overload
    def contains(
        self, pose: ArrayLike, y: ArrayLike | None = None, heading: ArrayLike | None = None
    ) -> bool | NDArray[np.bool_]: ...
    def contains(
        self, pose: Pose | ArrayLike, y: ArrayLike | None = None, heading: ArrayLike | None = None
    ) -> bool | NDArray[np.bool_]:
        """Tell whether pose(s) lie in the map: position in the polygon and heading in the wedge.

        Call it with a :class:`Pose`, with ``x``, ``y`` and ``heading`` as scalars or
        equally shaped arrays (metres, metres, radians), or with one array of poses of shape
        ``(3,)`` or ``(n, 3)``, as :meth:`sample_poses` and
        :meth:`~aura_ums.uncertainty.TerrainStats.sample_motions` give them. A boundary
        tolerance of ``POSITION_TOLERANCE`` metres and ``ANGLE_TOLERANCE`` radians applies.

        Examples
        --------
        >>> start = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 1.0, 0.1)
        >>> start.contains(start.sample_poses(4, np.random.default_rng(0))).tolist()
        [True, True, True, True]
        >>> start.contains([0.0, 0.0, 3.0])       # the position is in, the heading is not
        False
        """
        if isinstance(pose, Pose):
            if y is not None or heading is not None:
                raise InputError("contains: expected a Pose alone, or x, y and heading, got a Pose and more")
            return self._contains_one(pose.x, pose.y, pose.heading)
        if (
            type(pose) is float
            and type(y) is float
            and type(heading) is float
            and math.isfinite(pose)
            and math.isfinite(y)
            and math.isfinite(heading)
        ):
            return self._contains_one(pose, y, heading)
        if y is None and heading is None:
            rows = float_array(pose, "poses")
            if rows.shape[-1:] != (3,) or rows.ndim > 2:
                raise InputError(
                    "contains: expected a Pose, x, y and heading, or poses of shape (3,) or (n, 3), "
                    f"got {rows.shape}"
                )
            pose, y, heading = rows[..., 0], rows[..., 1], rows[..., 2]
        elif y is None or heading is None:
            raise InputError("contains: expected a Pose, or x, y and heading, got x and only one of them")
        xs, ys, hs = float_array(pose, "x"), float_array(y, "y"), float_array(heading, "heading")
        if not (xs.shape == ys.shape == hs.shape):
            shapes = f"{xs.shape}, {ys.shape}, {hs.shape}"
            raise InputError(f"contains: expected x, y and heading of one shape, got {shapes}")
        scalar = xs.ndim == 0
        shape = xs.shape
        points = np.column_stack([xs.reshape(-1), ys.reshape(-1)])
        if self._slices is not None:
            inside = slices_contain(self._slices, points, hs.reshape(-1), POSITION_TOLERANCE)
        else:
            inside = self.polygon.contains(points, tolerance=POSITION_TOLERANCE)
            inside &= np.asarray(self.wedge.contains(hs.reshape(-1)), dtype=bool)
        if scalar:
            return bool(inside[0])
        return inside.reshape(shape)

    def _contains_one(self, x: float, y: float, heading: float) -> bool:
        """:meth:`contains` for one pose of finite floats: the same operations, without arrays.

        A replay asks this of every step's map; through one-element arrays it cost about ten
        times as much.
        """
        if self._slices is not None:
            return slices_contain_one(self._slices, x, y, heading, POSITION_TOLERANCE)
        polygon = self.polygon
        return self.wedge.contains(heading) and point_in(
            polygon.vertices, x, y, POSITION_TOLERANCE, polygon.area
        )

    def sample_poses(self, count: int, rng: np.random.Generator) -> NDArray[np.float64]:
        """Draw ``count`` poses uniformly from the map: rows of x (m), y (m), heading (rad).

        A sliced map draws a slice for each pose with a chance proportional to its area times
        its heading width (a small floor keeps degenerate slices possible), then a pose in it.
        """
        count = sample_count(count, "count")
        check_rng(rng)
        slices = self._slices
        if slices is not None:
            polygons = slices.polygons()
            los, his = slices.lo.tolist(), slices.hi.tolist()
            weights = np.array(
                [
                    (polygon_area(p) + 1e-12) * (h - lo + 1e-12)
                    for p, lo, h in zip(polygons, los, his, strict=True)
                ]
            )
            chosen = rng.choice(len(polygons), size=count, p=weights / weights.sum())
            rows = np.empty((count, 3))
            for index in np.unique(chosen).tolist():
                picked = chosen == index
                lo, hi = los[index], his[index]
                rows[picked, :2] = ConvexPolygon._trusted(polygons[index]).sample(int(picked.sum()), rng)
                rows[picked, 2] = wrap_angle(lo + rng.uniform(0.0, 1.0, int(picked.sum())) * (hi - lo))
            return rows
        positions = self.polygon.sample(count, rng)
        wedge = self.wedge
        headings = wrap_angle(wedge.center - wedge.cw + rng.uniform(0.0, 1.0, count) * wedge.width)
        return np.column_stack([positions, headings])

    def __repr__(self) -> str:
        sliced = "" if self._slices is None else f", slices={len(self._slices.lo)}"
        return (
            f"SpatialUncertaintyMap(center=({self.center[0]:.4g}, {self.center[1]:.4g}), "
            f"area={self.area:.4g} m^2, vertices={self.polygon.vertex_count}, "
            f"heading={self.wedge.center:.4g} rad -{self.wedge.cw:.3g}/+{self.wedge.ccw:.3g}{sliced})"
        )


# Two float64 numbers as bytes, in the machine's order (np.frombuffer's float64).
_pack_point = struct.Struct("=2d").pack

# Setters of the slots (frozen: the dataclass's own __setattr__ refuses).
_set_polygon: Callable[[SpatialUncertaintyMap, ConvexPolygon | None], None] = SpatialUncertaintyMap.__dict__[
    "_polygon"
].__set__
_set_slices: Callable[[SpatialUncertaintyMap, SliceSet | None], None] = SpatialUncertaintyMap.__dict__[
    "_slices"
].__set__
_set_cells: Callable[[SpatialUncertaintyMap, int], None] = SpatialUncertaintyMap.__dict__["_cells"].__set__
_set_max_slices: Callable[[SpatialUncertaintyMap, int], None] = SpatialUncertaintyMap.__dict__[
    "_max_slices"
].__set__
_set_center: Callable[[SpatialUncertaintyMap, NDArray[np.float64]], None] = SpatialUncertaintyMap.__dict__[
    "center"
].__set__
_set_wedge: Callable[[SpatialUncertaintyMap, HeadingWedge], None] = SpatialUncertaintyMap.__dict__[
    "wedge"
].__set__
_set_pose: Callable[[SpatialUncertaintyMap, Pose | None], None] = SpatialUncertaintyMap.__dict__[
    "_pose"
].__set__


def _grow_sliced(
    current: SpatialUncertaintyMap,
    slices: SliceSet,
    values: list[float],
    terrain: TerrainStats,
    sigmas: float,
    max_vertices: int,
) -> SpatialUncertaintyMap:
    """Grow each slice over its own headings, then put the grown slices back on the grid.

    Each slice is a product map of its polygon and interval, grown as such (sound for its
    poses); its grown interval is cut at the grid's cells, and each cell takes the hull of
    the polygons that reach it. The most probable pose grows in the slice that holds its
    heading, as a product map's does. Two kernel calls, whatever the slice count.
    """
    x, y = current.center.tolist()
    heading = current.wedge.center
    grown = _native.grow_slices(
        slices.points,
        slices.counts,
        slices.lo,
        slices.hi,
        x,
        y,
        heading,
        terrain,
        sigmas,
        values,
        max_vertices,
    )
    cells, cap = current._cells, current._max_slices
    each_own = np.arange(len(grown.counts), dtype=np.int64)
    grid, wedge = distributed(
        grown.points, grown.counts, grown.starts, grown.stops, each_own,
        cells, max_vertices, cap, grown.heading,
    )  # fmt: skip
    return SpatialUncertaintyMap._sliced(grid, np.array([grown.x, grown.y]), wedge, cells, cap)
