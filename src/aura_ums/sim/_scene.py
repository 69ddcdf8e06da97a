"""The simulated world's geometry, as the synthetic camera draws it.

Everything is in the world frame (metres, x east, y north, z up) and gray levels
(0 black to 255 white). A :class:`Scene` holds flat-shaded primitives:

- :class:`Pole`: a vertical cylinder (a Class I landmark: pole, lamppost, door edge);
- :class:`Building`: a vertical prism on a convex footprint, its walls shaded alternately
  bright and dark so that every vertical corner edge shows (Class I), its top corners
  being points (Class II);
- :class:`GroundPatch`: a polygon on the ground (a meadow's terrain);
- :class:`GroundStripe`: a painted strip on the ground (a path edge, Class III; or clutter);
- a ground texture (world-anchored, so that it moves in the image as the robot moves).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np
from numpy.typing import ArrayLike, NDArray

from aura_ums._validate import (
    BLUR,
    COORDINATE,
    Range,
    check_rng,
    finite_float,
    integer_at_least,
    items_of,
    nonnegative_float,
    points_array,
    positive_float,
    read_only,
    world_points,
)
from aura_ums.errors import InputError
from aura_ums.uncertainty import GroundLineLandmark, PointLandmark, VerticalLineLandmark
from aura_ums.world import MeadowMap

#: Gray level of bare ground (outside every patch, or of a terrain without a shade).
_DEFAULT_GROUND_SHADE = 120.0

#: Gray levels of the default terrains' ground (other terrains get _DEFAULT_GROUND_SHADE).
_TERRAIN_SHADES: Mapping[str, float] = MappingProxyType(
    {"tile": 185.0, "concrete": 160.0, "gravel": 130.0, "grass": 95.0}
)

#: A Class I landmark closer than this (m, horizontally) to a Class II one is the vertical
#: corner edge of that point's building, not a pole of its own.
CORNER_MATCH_DISTANCE = 0.05

#: Most random strips of clutter (:func:`random_clutter`, a scenario's ``clutter``): a strip
#: takes about 400 bytes in the scene (the camera's too), so 4 GB, a run's memory limit.
CLUTTER = Range(0, 10_000_000, "strips")
#: Longest side of a ground texture tile, cells: 4096 took 4.6 s (19 s at a smoothing of 100
#: cells) and about 0.5 GB while it is made (float64 noise, its smoothed copy, the float32 tile).
MAX_TEXTURE_SIZE = 4096


def _shade(value: object, name: str) -> float:
    result = finite_float(value, name)
    if not 0.0 <= result <= 255.0:
        raise InputError(f"{name}: expected a gray level in [0, 255], got {result!r}")
    return result


def _area(points: NDArray[np.float64]) -> float:
    """Signed area of a polygon (positive when counter-clockwise)."""
    x, y = points[:, 0], points[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def _counter_clockwise(points: NDArray[np.float64]) -> NDArray[np.float64]:
    return points if _area(points) >= 0.0 else points[::-1].copy()


@dataclass(frozen=True, slots=True)
class Pole:
    """A vertical cylinder standing at (x, y) between two heights.

    Parameters
    ----------
    x, y : float
        Axis position, metres.
    z_bottom, z_top : float
        Heights of its ends, metres, bottom < top.
    radius : float
        Metres, > 0.
    shade : float
        Gray level.
    id : str
        The landmark it shows, or ``""``.

    Examples
    --------
    >>> Pole(8.5, -1.6, 0.0, 4.5, 0.12).shade
    45.0
    >>> Pole(0.0, 0.0, 2.0, 1.0, 0.1)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: Pole.z_top: expected > z_bottom (2.0), got 1.0
    """

    x: float
    y: float
    z_bottom: float
    z_top: float
    radius: float
    shade: float = 45.0
    id: str = ""

    def __post_init__(self) -> None:
        for name in ("x", "y", "z_bottom", "z_top"):
            object.__setattr__(self, name, finite_float(getattr(self, name), f"Pole.{name}"))
        if not self.z_top > self.z_bottom:
            raise InputError(f"Pole.z_top: expected > z_bottom ({self.z_bottom}), got {self.z_top}")
        object.__setattr__(self, "radius", positive_float(self.radius, "Pole.radius"))
        object.__setattr__(self, "shade", _shade(self.shade, "Pole.shade"))


@dataclass(frozen=True, slots=True, eq=False, init=False)
class Building:
    """A vertical prism on a convex footprint (a building, a box, a sign).

    Parameters
    ----------
    footprint : array_like, shape (n, 2)
        Convex polygon, metres, n >= 3, either orientation (stored counter-clockwise,
        read-only).
    z_bottom, z_top : float
        Heights of its floor and roof, metres, bottom < top.
    shades : tuple of two floats
        Gray levels of walls, alternating around the footprint so that neighbouring
        walls differ (a wall between two of the same shade, for odd n, gets their mean);
        the roof and the floor get the mean.
    id : str
        The landmark it shows, or ``""``.

    Examples
    --------
    >>> box = Building.from_corner(24.5, 6.0, 7.0, width=15.0, depth=10.0, toward=(1.0, 1.0))
    >>> box.footprint.tolist()
    [[24.5, 6.0], [39.5, 6.0], [39.5, 16.0], [24.5, 16.0]]
    >>> Building([(0, 0), (1, 0), (2, 0)], 0.0, 3.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: Building.footprint: expected a convex polygon of positive area, got area 0.0
    """

    footprint: NDArray[np.float64]
    z_bottom: float
    z_top: float
    shades: tuple[float, float]
    id: str

    def __init__(
        self,
        footprint: ArrayLike,
        z_bottom: float,
        z_top: float,
        shades: tuple[float, float] = (175.0, 105.0),
        id: str = "",
    ) -> None:
        object.__setattr__(self, "z_bottom", z_bottom)
        object.__setattr__(self, "z_top", z_top)
        object.__setattr__(self, "shades", shades)
        object.__setattr__(self, "id", id)
        points = world_points(footprint, "Building.footprint", min_rows=3)
        points = _counter_clockwise(points.copy())
        edges = np.roll(points, -1, axis=0) - points
        cross = edges[:, 0] * np.roll(edges[:, 1], -1) - edges[:, 1] * np.roll(edges[:, 0], -1)
        area = _area(points)
        if not area > 0.0 or np.any(cross < -1e-12):
            raise InputError(
                f"Building.footprint: expected a convex polygon of positive area, got area {area!r}"
            )
        object.__setattr__(self, "footprint", read_only(points))
        for name in ("z_bottom", "z_top"):
            object.__setattr__(self, name, finite_float(getattr(self, name), f"Building.{name}"))
        if not self.z_top > self.z_bottom:
            raise InputError(f"Building.z_top: expected > z_bottom ({self.z_bottom}), got {self.z_top}")
        if not isinstance(self.shades, (tuple, list)) or len(self.shades) != 2:
            raise InputError(f"Building.shades: expected two gray levels, got {self.shades!r}")
        bright, dark = (_shade(s, "Building.shades") for s in self.shades)
        object.__setattr__(self, "shades", (bright, dark))

    @classmethod
    def from_corner(
        cls,
        x: float,
        y: float,
        z_top: float,
        *,
        width: float,
        depth: float,
        toward: tuple[float, float] = (1.0, 1.0),
        direction: float = 0.0,
        z_bottom: float = 0.0,
        shades: tuple[float, float] = (175.0, 105.0),
        id: str = "",
    ) -> Building:
        """Return a rectangular box with a vertical corner edge at (x, y) up to ``z_top``.

        The box extends ``width`` metres along ``direction`` (radians) times the sign of
        ``toward[0]``, and ``depth`` metres along the perpendicular (direction + pi/2) times
        the sign of ``toward[1]``.
        """
        w, d = positive_float(width, "width"), positive_float(depth, "depth")
        angle = finite_float(direction, "direction")
        along = np.array([math.cos(angle), math.sin(angle)]) * (w if toward[0] >= 0.0 else -w)
        across = np.array([-math.sin(angle), math.cos(angle)]) * (d if toward[1] >= 0.0 else -d)
        corner = np.array([finite_float(x, "x"), finite_float(y, "y")])
        footprint = np.array([corner, corner + along, corner + along + across, corner + across])
        return cls(footprint, z_bottom, z_top, shades, id)

    def wall_shade(self, index: int) -> float:
        """Gray level of the wall from footprint vertex ``index`` to the next one."""
        n = len(self.footprint)
        if n % 2 == 1 and index == n - 1:
            return 0.5 * (self.shades[0] + self.shades[1])
        return self.shades[index % 2]


@dataclass(frozen=True, slots=True, eq=False, init=False)
class GroundPatch:
    """A polygon on the ground plane drawn in one gray level (a meadow's terrain).

    Parameters
    ----------
    polygon : array_like, shape (n, 2)
        A simple polygon, metres, n >= 3 (stored read-only).
    shade : float
        Gray level.

    Examples
    --------
    >>> lawn = GroundPatch([(0, 0), (4, 0), (4, 3), (0, 3)], 95)
    >>> lawn.polygon.shape, lawn.shade, lawn.polygon.flags.writeable
    ((4, 2), 95.0, False)
    >>> GroundPatch([(0, 0), (4, 0)], 95)                 # two points bound no area
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: GroundPatch.polygon: expected at least 3 points, got 2
    """

    polygon: NDArray[np.float64]
    shade: float

    def __init__(self, polygon: ArrayLike, shade: float) -> None:
        points = points_array(polygon, "GroundPatch.polygon", min_rows=3)
        object.__setattr__(self, "polygon", read_only(points.copy()))
        object.__setattr__(self, "shade", _shade(shade, "GroundPatch.shade"))


@dataclass(frozen=True, slots=True, eq=False, init=False)
class GroundStripe:
    """A straight strip painted on the ground: a path edge (Class III) or clutter.

    Parameters
    ----------
    start, end : array_like, shape (2,)
        Ends of its centre line, metres, distinct.
    width : float
        Metres, > 0.
    shade : float
        Gray level.
    id : str
        The landmark it shows, or ``""``.

    Examples
    --------
    >>> edge = GroundStripe((0.0, -1.5), (4.0, -1.5), 0.2, 60, id="path_edge")
    >>> edge.polygon().tolist()                           # its four corners, 0.1 m either side
    [[0.0, -1.6], [4.0, -1.6], [4.0, -1.4], [0.0, -1.4]]
    >>> GroundStripe((1, 2), (1, 2), 0.1, 60)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: GroundStripe.end: expected a point distinct from start, got [1.0, 2.0]
    """

    start: NDArray[np.float64]
    end: NDArray[np.float64]
    width: float
    shade: float
    id: str

    def __init__(self, start: ArrayLike, end: ArrayLike, width: float, shade: float, id: str = "") -> None:
        object.__setattr__(self, "id", id)
        a = points_array(start, "GroundStripe.start", min_rows=1)
        b = points_array(end, "GroundStripe.end", min_rows=1)
        if a.shape != (1, 2) or b.shape != (1, 2):
            raise InputError("GroundStripe: expected start and end as single (x, y) points")
        if np.array_equal(a, b):
            raise InputError(f"GroundStripe.end: expected a point distinct from start, got {b[0].tolist()}")
        object.__setattr__(self, "start", read_only(a[0].copy()))
        object.__setattr__(self, "end", read_only(b[0].copy()))
        object.__setattr__(self, "width", positive_float(width, "GroundStripe.width"))
        object.__setattr__(self, "shade", _shade(shade, "GroundStripe.shade"))

    def polygon(self) -> NDArray[np.float64]:
        """Return the strip's four corners on the ground, ``(4, 2)``, metres."""
        d = self.end - self.start
        normal = np.array([-d[1], d[0]]) * (0.5 * self.width / float(np.hypot(d[0], d[1])))
        return np.array([self.start - normal, self.end - normal, self.end + normal, self.start + normal])


def ground_texture(
    rng: np.random.Generator, *, size: int = 256, smoothing: float = 1.5
) -> NDArray[np.float32]:
    """Return a periodic random texture tile, zero mean and unit standard deviation.

    White noise smoothed by a Gaussian of ``smoothing`` cells (wrapping around), so that
    the tile repeats without seams. ``size`` is a power of two, at most 4096; ``smoothing``
    is in [0, 100] cells (an image blur's range: beyond, the tile is one grey).

    Examples
    --------
    >>> tile = ground_texture(np.random.default_rng(0), size=64)
    >>> tile.shape, round(float(tile.std()), 3), tile.flags.writeable
    ((64, 64), 1.0, False)
    >>> ground_texture(np.random.default_rng(0), size=64, smoothing=1e6)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: smoothing: expected a number in [0, 100] px, got 1000000.0
    """
    from scipy import ndimage  # deferred: scipy takes ~0.5 s to import

    if isinstance(size, bool) or not isinstance(size, int) or size < 4 or size & (size - 1):
        raise InputError(f"size: expected a power of two >= 4, got {size!r}")
    if size > MAX_TEXTURE_SIZE:
        raise InputError(
            f"size: expected at most {MAX_TEXTURE_SIZE} cells (a {MAX_TEXTURE_SIZE}-cell tile takes about "
            f"5 s and 0.5 GB; the time and memory grow with the square), got {size!r}"
        )
    # A Gaussian of sigma s cells costs 8 s + 1 products a cell: 1e6 cells hung.
    sigma = BLUR.check(smoothing, "smoothing")
    check_rng(rng)
    noise = rng.standard_normal((size, size))
    smooth = ndimage.gaussian_filter(noise, sigma, mode="wrap")
    smooth = (smooth - smooth.mean()) / max(float(smooth.std()), 1e-12)
    tile: NDArray[np.float32] = smooth.astype(np.float32)
    tile.setflags(write=False)
    return tile


def random_clutter(
    bounds: tuple[float, float, float, float],
    count: int,
    rng: np.random.Generator,
    *,
    length: tuple[float, float] = (0.2, 1.5),
    width: tuple[float, float] = (0.02, 0.06),
    shade: tuple[float, float] = (40.0, 90.0),
) -> tuple[GroundStripe, ...]:
    """Return ``count`` short dark strips (cracks, twigs, shadows) at random on the ground.

    Centres are uniform in ``bounds`` ``(x_min, y_min, x_max, y_max)``, directions uniform,
    lengths, widths and shades uniform in their ranges.

    Examples
    --------
    >>> cracks = random_clutter((0.0, 0.0, 10.0, 5.0), 3, np.random.default_rng(0))
    >>> len(cracks), all(0.0 <= c.start[0] <= 11.0 for c in cracks)
    (3, True)
    >>> random_clutter((0.0, 0.0, 10.0, 5.0), -1, np.random.default_rng(0))
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: count: expected an integer >= 0, got -1
    """
    check_rng(rng)
    integer_at_least(count, "count", 0)
    if count > CLUTTER.high:
        raise InputError(
            f"count: expected at most {CLUTTER.high:,.0f} strips (about 400 bytes each: 4 GB), "
            f"got {count!r} (about {count * 400 / 1e9:.3g} GB)"
        )
    corners = items_of(bounds, "bounds", "(x_min, y_min, x_max, y_max) in metres")
    if len(corners) != 4:
        raise InputError(f"bounds: expected (x_min, y_min, x_max, y_max) in metres, got {bounds!r}")
    x0, y0, x1, y1 = (COORDINATE.check(v, "bounds") for v in corners)
    centre = np.column_stack([rng.uniform(x0, x1, count), rng.uniform(y0, y1, count)])
    angle = rng.uniform(-math.pi, math.pi, count)
    half = 0.5 * rng.uniform(length[0], length[1], count)
    widths = rng.uniform(width[0], width[1], count)
    shades = rng.uniform(shade[0], shade[1], count)
    offset = np.column_stack([np.cos(angle), np.sin(angle)]) * half[:, None]
    return tuple(
        GroundStripe(c - o, c + o, float(w), float(s))
        for c, o, w, s in zip(centre, offset, widths, shades, strict=True)
    )


@dataclass(frozen=True, slots=True, eq=False)
class Scene:
    """The simulated world as the synthetic camera draws it (see the module's notes).

    Parameters
    ----------
    poles, buildings : tuple
        The upright objects, drawn far to near (painter's order by distance).
    patches : tuple of GroundPatch
        Ground polygons, drawn in order on the bare ground.
    stripes : tuple of GroundStripe
        Painted strips, drawn after the patches (path edges, clutter).
    texture : ndarray, shape (k, k), optional
        Periodic ground texture tile, its side a power of two (zero mean, unit spread; see
        :func:`ground_texture`), laid on the ground in cells of ``texture_cell`` metres;
        None for a flat ground.
    texture_cell : float
        Metres per texture cell, > 0.
    texture_contrast : float
        Standard deviation of the texture, gray levels (near the camera; it fades with
        distance as real texture does once it is finer than a pixel).
    ground_shade : float
        Gray level of the ground outside every patch.
    sky_shades : tuple of two floats
        Gray levels of the sky at the horizon and 30 degrees above it (and higher).

    Examples
    --------
    >>> scene = Scene(poles=(Pole(10.0, 0.0, 0.0, 5.0, 0.1),))
    >>> len(scene.poles), scene.texture is None
    (1, True)
    """

    poles: tuple[Pole, ...] = ()
    buildings: tuple[Building, ...] = ()
    patches: tuple[GroundPatch, ...] = ()
    stripes: tuple[GroundStripe, ...] = ()
    texture: NDArray[np.float32] | None = None
    texture_cell: float = 0.03
    texture_contrast: float = 8.0
    ground_shade: float = _DEFAULT_GROUND_SHADE
    sky_shades: tuple[float, float] = field(default=(215.0, 175.0))

    def __post_init__(self) -> None:
        for name, kind in (
            ("poles", Pole),
            ("buildings", Building),
            ("patches", GroundPatch),
            ("stripes", GroundStripe),
        ):
            items = items_of(getattr(self, name), f"Scene.{name}", f"a sequence of {kind.__name__}")
            for index, item in enumerate(items):
                if not isinstance(item, kind):
                    raise InputError(f"Scene.{name}[{index}]: expected a {kind.__name__}, got {item!r}")
            object.__setattr__(self, name, items)
        if self.texture is not None:
            tile = np.array(self.texture, dtype=np.float32)
            side = tile.shape[0] if tile.ndim == 2 else 0
            if tile.ndim != 2 or tile.shape[1] != side or side < 1 or side & (side - 1):
                raise InputError(
                    "Scene.texture: expected a square 2-D tile whose side is a power of two, "
                    f"got shape {tile.shape}"
                )
            if not np.all(np.isfinite(tile)):
                raise InputError("Scene.texture: expected finite values, got non-finite ones")
            tile.setflags(write=False)
            object.__setattr__(self, "texture", tile)
        object.__setattr__(self, "texture_cell", positive_float(self.texture_cell, "Scene.texture_cell"))
        object.__setattr__(
            self, "texture_contrast", nonnegative_float(self.texture_contrast, "Scene.texture_contrast")
        )
        object.__setattr__(self, "ground_shade", _shade(self.ground_shade, "Scene.ground_shade"))
        if len(self.sky_shades) != 2:
            raise InputError(f"Scene.sky_shades: expected two gray levels, got {self.sky_shades!r}")
        horizon, zenith = (_shade(s, "Scene.sky_shades") for s in self.sky_shades)
        object.__setattr__(self, "sky_shades", (horizon, zenith))

    @classmethod
    def from_meadow_map(
        cls,
        meadow_map: MeadowMap,
        rng: np.random.Generator,
        *,
        pole_radius: float = 0.12,
        pole_shade: float = 45.0,
        stripe_width: float = 0.1,
        stripe_shade: float = 220.0,
        building_size: tuple[float, float] = (15.0, 10.0),
        building_base: float = 0.0,
        terrain_shades: Mapping[str, float] = _TERRAIN_SHADES,
        clutter: int = 0,
        extra: Iterable[GroundStripe] = (),
    ) -> Scene:
        """Build the scene of a meadow map from its landmark records and meadows.

        - Meadows become ground patches shaded by terrain (``terrain_shades``; others get
          the default ``ground_shade`` of a :class:`Scene`).
        - Class I landmarks (:class:`~aura_ums.uncertainty.VerticalLineLandmark`) become
          poles of ``pole_radius`` between ``z_bottom`` and ``z_top``, unless one stands
          within 5 cm (horizontally) of a Class II landmark: it is then that
          building's vertical corner edge.
        - Class II landmarks (:class:`~aura_ums.uncertainty.PointLandmark`) become boxes
          of ``building_size`` (width along x, depth along y, metres) from ``building_base``
          up to the point's height, with that top corner at the point, extending away from
          the centre of the map (so that the corner faces the meadows and both walls at
          it show). A Class I edge at the corner raises the box to its ``z_top`` if higher.
        - Class III landmarks (:class:`~aura_ums.uncertainty.GroundLineLandmark`) become
          painted strips of ``stripe_width``.
        - ``clutter`` random strips (:func:`random_clutter`) over the map's bounds, then the
          ``extra`` strips, are added; the ground texture is drawn from ``rng``.

        Parameters
        ----------
        meadow_map : MeadowMap
            The world.
        rng : numpy.random.Generator
            Source of the ground texture and the clutter.

        Returns
        -------
        Scene
            The scene.

        Examples
        --------
        >>> from aura_ums.world import sample_world
        >>> scene = Scene.from_meadow_map(sample_world("paper_sidewalk"), np.random.default_rng(0))
        >>> [p.id for p in scene.poles], [b.id for b in scene.buildings]
        (['telephone_pole_12', 'lamppost_107'], ['east_engineering_corner'])
        >>> len(scene.patches), [s.id for s in scene.stripes]
        (8, ['sidewalk_north_edge', 'sidewalk_south_edge'])
        >>> Scene.from_meadow_map(sample_world("paper_sidewalk"), np.random.default_rng(0), pole_radius=0.0)
        Traceback (most recent call last):
        ...
        aura_ums.errors.InputError: pole_radius: expected a positive number, got 0.0
        """
        if not isinstance(meadow_map, MeadowMap):
            raise InputError(f"meadow_map: expected a MeadowMap, got {type(meadow_map).__name__}")
        radius = positive_float(pole_radius, "pole_radius")
        width, depth = (positive_float(v, "building_size") for v in building_size)
        base = finite_float(building_base, "building_base")
        x_min, y_min, x_max, y_max = meadow_map.bounds
        centre = (0.5 * (x_min + x_max), 0.5 * (y_min + y_max))
        landmarks = [record.landmark for record in meadow_map.landmarks]
        points = [lm for lm in landmarks if isinstance(lm, PointLandmark)]
        verticals = [lm for lm in landmarks if isinstance(lm, VerticalLineLandmark)]

        def corner_of(line: VerticalLineLandmark) -> PointLandmark | None:
            for point in points:
                if math.hypot(point.x - line.x, point.y - line.y) <= CORNER_MATCH_DISTANCE:
                    return point
            return None

        poles = tuple(
            Pole(lm.x, lm.y, lm.z_bottom, lm.z_top, radius, pole_shade, lm.id)
            for lm in verticals
            if corner_of(lm) is None and lm.z_top > lm.z_bottom
        )
        buildings: list[Building] = []
        for point in points:
            top = max([point.z, *(lm.z_top for lm in verticals if corner_of(lm) is point)])
            toward = (1.0 if point.x >= centre[0] else -1.0, 1.0 if point.y >= centre[1] else -1.0)
            buildings.append(
                Building.from_corner(
                    point.x, point.y, top, width=width, depth=depth, toward=toward, z_bottom=base, id=point.id
                )
            )
        patches = tuple(
            GroundPatch(
                meadow.polygon.vertices,
                terrain_shades.get(meadow.terrain, _DEFAULT_GROUND_SHADE),
            )
            for meadow in meadow_map.meadows
        )
        stripes = [
            GroundStripe(lm.start, lm.end, stripe_width, stripe_shade, lm.id)
            for lm in landmarks
            if isinstance(lm, GroundLineLandmark)
        ]
        stripes.extend(random_clutter(meadow_map.bounds, clutter, rng))
        stripes.extend(extra)
        return cls(
            poles=poles,
            buildings=tuple(buildings),
            patches=patches,
            stripes=tuple(stripes),
            texture=ground_texture(rng),
        )


def landmark_points(landmark: VerticalLineLandmark | PointLandmark) -> NDArray[np.float64]:
    """World points ``(k, 3)`` of a Class I (bottom, middle, top) or Class II landmark (the point).

    Examples
    --------
    >>> landmark_points(VerticalLineLandmark("p", 1.0, 2.0, 0.0, 4.0)).tolist()
    [[1.0, 2.0, 0.0], [1.0, 2.0, 2.0], [1.0, 2.0, 4.0]]
    """
    if isinstance(landmark, PointLandmark):
        return np.array([[landmark.x, landmark.y, landmark.z]])
    if not isinstance(landmark, VerticalLineLandmark):
        raise InputError(
            f"landmark: expected a VerticalLineLandmark or PointLandmark, got {type(landmark).__name__}"
        )
    zs = [landmark.z_bottom, 0.5 * (landmark.z_bottom + landmark.z_top), landmark.z_top]
    return np.array([[landmark.x, landmark.y, z] for z in zs])
