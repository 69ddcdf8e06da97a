"""Scenario files: a TOML file naming a map, a terrain table, a camera, a start and a route.

The format (paths are relative to the scenario file; angles in degrees where the key
says ``_deg``, radians otherwise; every other unit SI)::

    name = "paper_sidewalk"             # optional, default: the file's stem
    description = "..."                 # optional
    map = "sample:paper_sidewalk"       # a GeoJSON meadow map, or sample:<name>
    terrain = "default"                 # optional: a terrain table TOML file, or "default" (the
                                        # built-in); default: the table the map names, else built-in
    camera = "paper_camera.toml"        # a camera TOML file (aura_ums.camera.load_camera)
    landmarks = ["lamppost_107"]        # optional: ids the robot uses (default: all)
    confirm_frames = 1                  # optional: consecutive frames that confirm a discovery,
                                        # for every landmark (default: each landmark's own)
    frame_spacing = 1.0                 # optional: metres of commanded run between frames
    # or: frame_rate = 2.0 (frames per second) with speed = 0.5 (m/s)
    inject_wrong_rate = 0.0             # optional: share of identifications made wrong (0 to 1)

    [start]                             # the believed start: centre and bounds
    x = 0.0
    y = 0.0
    heading_deg = 0.0                   # or heading (radians)
    position_radius = 0.3048            # metres, >= 0
    heading_halfwidth_deg = 3.0         # or heading_halfwidth (radians), >= 0

    [route]                             # exactly one of:
    commands = [{turn_deg = 0.0, run = 3.048}]   # turn_deg or turn, run (m)
    # waypoints = [[5.0, 0.0], [5.0, 4.0]]       # straight legs from the start
    # goal = [20.0, 0.0]                         # legs planned with aura_ums.world.plan_route

    [manager]                           # optional: aura_ums.manager.ManagerSettings
    area_limit = 25.0                   # m^2: the robot is lost above it (default: no limit)
    missed_limit = 3                    # frames in a row of landmarks predicted, none found
    robust = true                       # envelope map and re-localization from it
    # ... any field of ManagerSettings, by its name (its unit, range and default are
    # there); angles in radians, or in degrees as <name>_deg; "none" for None.
    # profile = "sliced"                # a MapProfile: product, sliced or relaxed, under the keys

    [render]                            # optional: the synthetic camera and scene
    noise = 2.0                         # gray levels (sd); clutter = 0 (ground strips);
    clutter_lines = 0                   # per frame; pole_radius = 0.12; stripe_width = 0.1;
    building_width = 15.0               # building_depth = 10.0; building_base = 0.0

Frames are taken at the start, at the end of every command, and, with a frame spacing,
every ``frame_spacing`` metres of commanded run along the route. Every number has a
physical range (:data:`KEY_RANGES`, listed in docs/formats.md), and the work a run
implies (frames times pixels, clutter strips) is estimated before anything is allocated:
a scenario above :data:`MAX_RUN_SECONDS` or :data:`MAX_RUN_BYTES` is refused, the
message stating the estimate. Files that hold
``area_limit`` and ``missed_limit`` in a ``[lost]`` table (the earlier format) are read
as before.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from aura_ums._files import Fields, describe, load_toml
from aura_ums._validate import (
    ANGLE,
    COORDINATE,
    LENGTH,
    START_RADIUS,
    Range,
    finite_float,
    items_of,
    nonnegative_float,
    read_only,
)
from aura_ums.camera import Camera, camera_calibration_file, load_camera
from aura_ums.errors import FileFormatError, InputError
from aura_ums.expecter import Expecter
from aura_ums.geometry import wrap_angle
from aura_ums.manager import ManagerSettings, MapProfile, SettingInfo
from aura_ums.schemas import FindLandmarkSchema
from aura_ums.sim._render import CLUTTER_LINES, NOISE, SyntheticCamera
from aura_ums.sim._robot import SimulatedRobot
from aura_ums.sim._scene import CLUTTER, Scene
from aura_ums.uncertainty import Pose, SpatialUncertaintyMap, TerrainTable, TurnAndRun
from aura_ums.world import LandmarkRecord, MeadowMap, plan_route, sample_world

_TOP_KEYS = (
    "name",
    "description",
    "map",
    "terrain",
    "camera",
    "landmarks",
    "confirm_frames",
    "frame_spacing",
    "frame_rate",
    "inject_wrong_rate",
    "speed",
    "start",
    "route",
    "manager",
    "lost",
    "render",
)
_START_KEYS = (
    "x",
    "y",
    "heading",
    "heading_deg",
    "position_radius",
    "heading_halfwidth",
    "heading_halfwidth_deg",
)
_RENDER_KEYS = (
    "noise",
    "clutter",
    "clutter_lines",
    "pole_radius",
    "stripe_width",
    "building_width",
    "building_depth",
    "building_base",
)
#: The physical range of every number of a scenario file, by key (docs/formats.md lists them).
KEY_RANGES: dict[str, Range] = {
    "x": COORDINATE,
    "y": COORDINATE,
    "heading": ANGLE,
    "position_radius": START_RADIUS,
    "heading_halfwidth": Range(0.0, ANGLE.high, "rad"),
    "turn": ANGLE,
    "run": LENGTH,
    "point": COORDINATE,
    "frame_spacing": Range(0.0, LENGTH.high, "m", low_open=True),
    "frame_rate": Range(0.0, 1000.0, "1/s", low_open=True),
    "speed": Range(0.0, 100.0, "m/s", low_open=True),
    "noise": NOISE,
    "clutter": CLUTTER,
    "clutter_lines": CLUTTER_LINES,
    "pole_radius": Range(0.0, 100.0, "m", low_open=True),
    "stripe_width": Range(0.0, 100.0, "m", low_open=True),
    "building_width": Range(0.0, 1000.0, "m", low_open=True),
    "building_depth": Range(0.0, 1000.0, "m", low_open=True),
    "building_base": Range(0.0, 1000.0, "m"),
}
# The synthetic camera's costs, measured on one core with scenarios/paper_sidewalk.toml
# (a 512 x 480 frame in 10 ms; 0.15 s with 4000 clutter strips; 45 MB of buffers): a frame
# renders each pixel in about 40 ns and each clutter strip in about 35 us; the
# camera keeps about 180 bytes a pixel, the scene about 400 a strip. A clutter line is
# drawn as its own polygon in every frame: about 190 us (2000 and 8000 lines, 0.40 and 1.49
# s a frame; it was counted as a strip, and 1e6 lines, 13 minutes a run, were let through).
# Besides rendering, a frame costs the loop about 8 ms (perception, the Expecter, the manager):
# paper_sidewalk.toml with frame_spacing 0.02, 0.01 and 0.005 m (610, 1219 and 2438 frames)
# ran in 13.8, 30.2 and 45.5 s, 19 to 25 ms a frame, where rendering alone was estimated
# at 11 ms, so a run estimated at 290 s took about twice that.
_SECONDS_PER_FRAME = 8e-3
_SECONDS_PER_PIXEL = 4e-8
_SECONDS_PER_STRIP = 3.5e-5
_SECONDS_PER_LINE = 1.9e-4
_BYTES_PER_PIXEL = 200
_BYTES_PER_STRIP = 400
#: Longest estimated time of one simulated run, seconds.
MAX_RUN_SECONDS = 600.0
#: Most estimated memory of one simulated run's camera and scene, bytes.
MAX_RUN_BYTES = 4e9
#: Most Monte Carlo runs of one call: each run's result stays in memory (about 20 kB).
MAX_RUNS = 100_000
_RUN_RESULT_BYTES = 20_000
#: Frames a run's camera could afford: past the limits with more, the count is to blame.
_FEW_FRAMES = 1000
_SAMPLE_PREFIX = "sample:"
_START_DRAWS = 100


@dataclass(frozen=True, slots=True)
class StartState:
    """The believed start: most probable pose and the bounds of the uncertainty around it.

    Parameters
    ----------
    pose : Pose
        Most probable start pose.
    position_radius : float
        Metres, >= 0: the true position is within this distance.
    heading_halfwidth : float
        Radians, >= 0: the true heading is within this angle of ``pose.heading``.

    Examples
    --------
    >>> StartState(Pose(0.0, 0.0, 0.0), 0.3, 0.05)
    StartState(pose=Pose(x=0.0, y=0.0, heading=0.0), position_radius=0.3, heading_halfwidth=0.05)
    >>> StartState(Pose(0.0, 0.0, 0.0), 0, 0).position_radius   # a start known exactly
    0.0
    >>> StartState(Pose(0.0, 0.0, 0.0), -0.3, 0.05)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: StartState.position_radius: expected a non-negative number, got -0.3
    """

    pose: Pose
    position_radius: float
    heading_halfwidth: float

    def __post_init__(self) -> None:
        if not isinstance(self.pose, Pose):
            raise InputError(f"StartState.pose: expected a Pose, got {type(self.pose).__name__}")
        object.__setattr__(
            self, "position_radius", nonnegative_float(self.position_radius, "StartState.position_radius")
        )
        object.__setattr__(
            self,
            "heading_halfwidth",
            nonnegative_float(self.heading_halfwidth, "StartState.heading_halfwidth"),
        )


@dataclass(frozen=True, slots=True)
class RenderSettings:
    """Settings of the synthetic scene and camera (see :class:`Scene` and :class:`SyntheticCamera`).

    Parameters
    ----------
    noise : float
        Sensor noise, gray levels (standard deviation).
    clutter : int
        Random strips on the ground of the scene.
    clutter_lines : int
        Random line segments drawn over every image.
    pole_radius, stripe_width : float
        Metres: Class I poles' radius, Class III strips' width.
    building_width, building_depth, building_base : float
        Metres: size of the box drawn at each Class II landmark and the height of its floor.

    Examples
    --------
    >>> settings = RenderSettings()
    >>> settings.noise, settings.clutter, settings.pole_radius
    (2.0, 0, 0.12)
    >>> clean = dataclasses.replace(RenderSettings(), noise=0.0)    # noise-free images
    >>> clean.noise, clean.clutter
    (0.0, 0)
    >>> RenderSettings(noise=-4.0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: RenderSettings.noise: expected a number in [0, 255] gray levels, got -4.0
    """

    noise: float = 2.0
    clutter: int = 0
    clutter_lines: int = 0
    pole_radius: float = 0.12
    stripe_width: float = 0.1
    building_width: float = 15.0
    building_depth: float = 10.0
    building_base: float = 0.0

    def __post_init__(self) -> None:
        # The scenario file's ranges (KEY_RANGES), for settings built in code too.
        for key in _RENDER_KEYS:
            value, where, bounds = getattr(self, key), f"RenderSettings.{key}", KEY_RANGES[key]
            if key in ("clutter", "clutter_lines"):
                if (
                    isinstance(value, bool)
                    or not isinstance(value, (int, np.integer))
                    or not bounds.contains(float(value))
                ):
                    raise InputError(f"{where}: expected an integer in {bounds.interval()}, got {value!r}")
                object.__setattr__(self, key, int(value))
            else:
                object.__setattr__(self, key, bounds.check(value, where))


@dataclass(frozen=True, slots=True)
class SimulatedFrame:
    """One frame of a simulated run.

    Parameters
    ----------
    index : int
        0 for the start, then 1, 2, ...
    command : TurnAndRun or None
        The command executed since the previous frame (None for the first frame).
    pose : Pose
        The robot's true pose when the image was taken.
    image : ndarray of uint8, shape (height, width)
        What the camera saw (read-only).
    distance : float
        Commanded run from the start to this frame, metres.

    Examples
    --------
    >>> image = np.zeros((48, 64), dtype=np.uint8)
    >>> first = SimulatedFrame(0, None, Pose(0.0, 0.0, 0.0), image, 0.0)   # the start frame
    >>> first.command is None, first.distance, first.image.shape
    (True, 0.0, (48, 64))
    >>> later = SimulatedFrame(1, TurnAndRun(0.0, 2.0), Pose(2.0, 0.0, 0.0), image, 2.0)
    >>> later.command.run == later.distance
    True
    """

    index: int
    command: TurnAndRun | None
    pose: Pose
    image: NDArray[np.uint8]
    distance: float


class _Reader:
    """Typed access to a parsed scenario document; every failure names the file and key."""

    def __init__(self, source: str) -> None:
        self.source = source
        self.fields = Fields(source)
        self.files: list[tuple[str, Path]] = []  # the files the document names, by key

    def fail(self, where: str, message: str) -> FileFormatError:
        return self.fields.error(where, message)

    def table(self, document: Mapping[str, object], name: str, *, required: bool) -> dict[str, object]:
        value = document.get(name)
        if value is None:
            if required:
                raise self.fail(f"[{name}]", "expected this table, got none")
            return {}
        return self.fields.table(value, f"[{name}]")

    def keys(self, table: Mapping[str, object], allowed: tuple[str, ...], where: str, sep: str = " ") -> None:
        self.fields.keys(table, allowed, where)  # the key path puts " " after a [table], "." elsewhere

    def string(self, value: object, where: str) -> str:
        return self.fields.string(value, where, nonempty=True)

    def number(self, value: object, where: str) -> float:
        return self.fields.number(value, where)

    def positive(self, value: object, where: str) -> float:
        return self.fields.positive(value, where)

    def nonnegative(self, value: object, where: str) -> float:
        return self.fields.nonnegative(value, where)

    def integer(self, value: object, where: str, minimum: int) -> int:
        return self.fields.integer(value, where, minimum)

    def ranged(self, value: object, where: str, key: str, *, scale: float = 1.0) -> float:
        """Return a number in the range of ``key`` (:data:`KEY_RANGES`)."""
        return self.fields.ranged(value, where, KEY_RANGES[key], scale=scale)

    def point(self, value: object, where: str) -> tuple[float, float]:
        if not isinstance(value, list) or len(value) != 2:
            raise self.fail(where, f"expected [x, y] in metres, got {describe(value)}")
        return (self.ranged(value[0], f"{where}[0]", "point"), self.ranged(value[1], f"{where}[1]", "point"))

    def angle(
        self, table: Mapping[str, object], name: str, where: str, *, required: bool, sep: str = " "
    ) -> float:
        radians, degrees = table.get(name), table.get(f"{name}_deg")
        if radians is not None and degrees is not None:
            raise self.fail(f"{where}{sep}{name}_deg", f"expected {name} or {name}_deg, got both")
        if degrees is not None:
            return self.ranged(degrees, f"{where}{sep}{name}_deg", name, scale=math.pi / 180.0)
        if radians is not None:
            return self.ranged(radians, f"{where}{sep}{name}", name)
        if required:
            raise self.fail(
                f"{where}{sep}{name}_deg", f"expected {name}_deg (or {name} in radians), got none"
            )
        return 0.0

    def path(self, value: object, where: str, base: Path) -> Path:
        text = self.string(value, where)
        path = Path(text)
        found = path if path.is_absolute() else base / path
        self.files.append((where, found))
        return found


@dataclass(frozen=True, slots=True, eq=False)
class Scenario:
    r"""A simulation scenario: world, terrain statistics, camera, start, route and limits.

    Read one with :meth:`from_toml` (format in this module's documentation); build the
    true robot, the scene and the synthetic camera from it; or :meth:`simulate` the whole
    route, frame by frame.

    Parameters
    ----------
    name : str
        Short name.
    description : str
        Free text.
    meadow_map : MeadowMap
        The world.
    terrain : TerrainTable
        Terrain statistics, holding every meadow's terrain.
    camera : Camera
        The robot's camera.
    start : StartState
        The believed start.
    commands : tuple of TurnAndRun
        The route as commands, in order.
    landmark_ids : tuple of str
        The landmarks the robot uses, in map order.
    frame_spacing : float or None
        Metres of commanded run between frames (None: frames at the start and at the end
        of every command only).
    settings : ManagerSettings
        The map manager's settings: when to declare the robot lost, outlier recovery, ...
    render : RenderSettings
        Settings of the synthetic scene and camera.
    inject_wrong_rate : float
        Share, in [0, 1], of the identifications posted that the loop makes wrong before the
        manager sees them (each by chance): the landmark's id swapped for another of its
        class, or, with none, the bearing (a line's angle) turned by 3 rad. A
        misidentification no gate can tell from a good one when the map agrees with it;
        for testing outlier handling (:attr:`ManagerSettings.relaxed_q`). 0: none.
    source : str
        The file it was read from (``""`` when built in code).
    files : tuple of (str, Path)
        The files that file names, each with its key (``("camera", Path(...))``, as read:
        relative to the scenario's folder), and the calibration file its camera file names
        (``"camera's calibration"``); empty when built in code.

    Examples
    --------
    >>> import math, pathlib, tempfile
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "cam.toml").write_text(
    ...     "[intrinsics]\nfx = 549\nfy = 549\ncx = 255.5\ncy = 239.5\nwidth = 512\nheight = 480\n"
    ...     "[mount]\nheight = 1.2\ntilt_deg = 3\n")
    >>> _ = (folder / "walk.toml").write_text(
    ...     'map = "sample:paper_sidewalk"\ncamera = "cam.toml"\nframe_spacing = 2.0\n'
    ...     "[start]\nx = 0.0\ny = 0.0\nheading_deg = 0.0\nposition_radius = 0.3\n"
    ...     "heading_halfwidth_deg = 2.0\n[route]\ncommands = [{turn_deg = 0.0, run = 5.0}]\n")
    >>> scenario = Scenario.from_toml(folder / "walk.toml")
    >>> [(key, path.name) for key, path in scenario.files]     # the files it names
    [('camera', 'cam.toml')]
    >>> [command.run for command in scenario.legs()]       # a frame every 2 m, and at the stop
    [2.0, 2.0, 1.0]
    >>> frames = list(scenario.simulate(np.random.default_rng(0)))
    >>> len(frames), frames[-1].image.shape, frames[-1].distance
    (4, (480, 512), 5.0)
    >>> _ = (folder / "bad.toml").write_text('map = "sample:moon"\ncamera = "cam.toml"\n')
    >>> Scenario.from_toml(folder / "bad.toml")              # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: ...bad.toml: map: expected one of indoor_corridor, ..., got 'moon'
    """

    name: str
    description: str
    meadow_map: MeadowMap
    terrain: TerrainTable
    camera: Camera
    start: StartState
    commands: tuple[TurnAndRun, ...]
    landmark_ids: tuple[str, ...]
    frame_spacing: float | None = None
    settings: ManagerSettings = field(default_factory=ManagerSettings)
    render: RenderSettings = RenderSettings()
    source: str = ""
    inject_wrong_rate: float = 0.0
    files: tuple[tuple[str, Path], ...] = ()
    #: Most Monte Carlo runs of one call (:meth:`check_runs`; :func:`aura_ums.campaign.run_seeds` too).
    max_runs: ClassVar[int] = MAX_RUNS

    def __post_init__(self) -> None:
        for name, kind in (
            ("meadow_map", MeadowMap),
            ("terrain", TerrainTable),
            ("camera", Camera),
            ("start", StartState),
            ("settings", ManagerSettings),
            ("render", RenderSettings),
        ):
            value = getattr(self, name)
            if not isinstance(value, kind):
                raise InputError(f"Scenario.{name}: expected a {kind.__name__}, got {type(value).__name__}")
        commands = items_of(self.commands, "Scenario.commands", "a sequence of TurnAndRun")
        for index, command in enumerate(commands):
            if not isinstance(command, TurnAndRun):
                raise InputError(f"Scenario.commands[{index}]: expected a TurnAndRun, got {command!r}")
        object.__setattr__(self, "commands", commands)
        ids = tuple(self.landmark_ids)
        seen: set[str] = set()
        for index, ident in enumerate(ids):
            self.meadow_map.landmark(ident)  # raises, naming the id, when unknown
            if ident in seen:
                raise InputError(
                    f"Scenario.landmark_ids[{index}]: expected each id once, got {ident!r} again"
                )
            seen.add(ident)
        object.__setattr__(self, "landmark_ids", ids)
        if self.frame_spacing is not None:
            spacing = finite_float(self.frame_spacing, "Scenario.frame_spacing")
            if spacing <= 0.0:
                raise InputError(
                    f"Scenario.frame_spacing: expected a positive number or None, got {spacing!r}"
                )
            object.__setattr__(self, "frame_spacing", spacing)
        rate = finite_float(self.inject_wrong_rate, "Scenario.inject_wrong_rate")
        if not 0.0 <= rate <= 1.0:
            raise InputError(f"Scenario.inject_wrong_rate: expected a number in [0, 1], got {rate!r}")
        object.__setattr__(self, "inject_wrong_rate", rate)
        self._refuse_too_much_work()

    def frame_count(self) -> int:
        """Return the number of frames a run takes, without cutting the route (see :meth:`legs`).

        An upper bound by at most one frame per command (a leg ending within the tolerance
        of a frame is not cut again).
        """
        if self.frame_spacing is None:
            return len(self.commands) + 1
        route = math.fsum(command.run for command in self.commands)
        return int(min(math.ceil(route / self.frame_spacing), 2**62)) + len(self.commands) + 1

    def estimate(self) -> tuple[float, float]:
        """Return the estimated time (seconds) and memory (bytes) of one run of :meth:`simulate`.

        From the measured costs: the loop's per frame, the synthetic camera's pixels,
        clutter strips and clutter lines of every frame, the camera's buffers and the
        scene's strips.

        Examples
        --------
        >>> import pathlib
        >>> scenario = Scenario.from_toml(pathlib.Path("scenarios") / "paper_sidewalk.toml")
        >>> seconds, memory = scenario.estimate()
        >>> round(seconds, 2), round(memory / 1e6)
        (0.08, 49)
        """
        k = self.camera.intrinsics
        pixels = float(k.width) * float(k.height)
        seconds = float(self.frame_count()) * sum(self._frame_seconds().values())
        memory = pixels * _BYTES_PER_PIXEL + float(self.render.clutter) * _BYTES_PER_STRIP
        return seconds, memory

    def _frame_seconds(self) -> dict[str, float]:
        """Return a frame's estimated seconds by the field that sets each part (see :meth:`estimate`)."""
        k = self.camera.intrinsics
        return {
            "Scenario.camera": _SECONDS_PER_FRAME + float(k.width) * float(k.height) * _SECONDS_PER_PIXEL,
            "Scenario.render.clutter": float(self.render.clutter) * _SECONDS_PER_STRIP,
            "Scenario.render.clutter_lines": float(self.render.clutter_lines) * _SECONDS_PER_LINE,
        }

    def _refuse_too_much_work(self) -> None:
        seconds, memory = self.estimate()
        if seconds <= MAX_RUN_SECONDS and memory <= MAX_RUN_BYTES:
            return
        k = self.camera.intrinsics
        work = (
            f"{self.frame_count()} frames of {k.width} x {k.height} px, {self.render.clutter} clutter "
            f"strips and {self.render.clutter_lines} lines: about {seconds:.3g} s and "
            f"{memory / 1e9:.3g} GB a run"
        )
        limits = f"at most {MAX_RUN_SECONDS:g} s and {MAX_RUN_BYTES / 1e9:g} GB a run"
        # Name the input that makes the run too big: a frame's costliest part when a few
        # frames of it would already be too many, else the number of frames.
        per_frame = seconds / self.frame_count()
        parts = self._frame_seconds()
        costliest = max(parts, key=lambda part: parts[part])
        if memory > MAX_RUN_BYTES:
            clutter = self.render.clutter * _BYTES_PER_STRIP > memory / 2
            name = "Scenario.render.clutter" if clutter else "Scenario.camera"
        elif parts[costliest] * _FEW_FRAMES > MAX_RUN_SECONDS:
            name = costliest
        elif self.frame_spacing is not None and per_frame * (len(self.commands) + 1) <= MAX_RUN_SECONDS:
            name = "Scenario.frame_spacing"
        elif self.frame_spacing is None:
            name = "Scenario.commands"  # a frame after each command: too many commands
        else:
            name = costliest
        raise InputError(f"{name}: expected {limits}, got {work}")

    def check_runs(self, runs: object) -> int:
        """Return ``runs`` checked: an integer in [1, ``MAX_RUNS``] (100,000), refused with the estimate.

        Examples
        --------
        >>> import pathlib
        >>> scenario = Scenario.from_toml(pathlib.Path("scenarios") / "paper_sidewalk.toml")
        >>> scenario.check_runs(40)
        40
        >>> scenario.check_runs(10**9)  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        aura_ums.errors.InputError: runs: expected an integer in [1, 100000], got 1000000000 (about ... s ...)
        """
        if isinstance(runs, bool) or not isinstance(runs, int) or not 1 <= runs <= MAX_RUNS:
            seconds, _ = self.estimate()
            count = runs if isinstance(runs, int) and not isinstance(runs, bool) else 0
            estimate = (
                f" (about {count * seconds:.3g} s and {count * _RUN_RESULT_BYTES / 1e9:.3g} GB of results)"
                if count > MAX_RUNS
                else ""
            )
            raise InputError(f"runs: expected an integer in [1, {MAX_RUNS}], got {runs!r}{estimate}")
        return runs

    # --- reading ---------------------------------------------------------------------------

    @classmethod
    def from_toml(cls, path: str | Path) -> Scenario:
        """Read a scenario file (format: this module's documentation).

        Parameters
        ----------
        path : str or Path
            The TOML file; the paths in it are relative to its folder.

        Returns
        -------
        Scenario
            The scenario, with its map, terrain table and camera loaded.

        Raises
        ------
        FileFormatError
            Naming the scenario file and the key (``map``, ``[start] x``,
            ``[route] commands[2].run``, ...): unreadable file, malformed TOML, unknown or
            missing keys, wrong types or values out of range, and files it names that do
            not load (their own error is quoted).
        """
        reader = _Reader(str(path))
        document = load_toml(path, kind="scenario")
        return cls._from_document(document, reader, Path(path).parent, Path(path).stem)

    @classmethod
    def _from_document(
        cls, document: Mapping[str, object], reader: _Reader, base: Path, stem: str
    ) -> Scenario:
        reader.keys(document, _TOP_KEYS, "")
        name = reader.string(document.get("name", stem), "name")
        description = document.get("description", "")
        if not isinstance(description, str):
            raise reader.fail("description", f"expected a string, got {describe(description)}")
        given = _load_terrain(document, reader, base)
        meadow_map = _with_confirm_frames(_load_map(document, reader, base, given), document, reader)
        # Without a terrain of its own, the scenario takes the table its map names, else the built-in one.
        terrain = given
        if terrain is None:
            terrain = (
                meadow_map.terrain_table if meadow_map.terrain_table is not None else TerrainTable.default()
            )
            _check_terrains(meadow_map, terrain, reader)
        if "camera" not in document:
            raise reader.fail("camera", "expected the path of a camera TOML file, got none")
        camera_path = reader.path(document["camera"], "camera", base)
        try:
            camera = load_camera(camera_path)
            calibration = camera_calibration_file(camera_path)
        except FileFormatError as exc:
            raise reader.fail("camera", f"expected a camera file that loads, got: {exc}") from None
        if calibration is not None:  # the calibration file the camera file names is read too
            reader.files.append(("camera's calibration", calibration))
        _check_strategies(meadow_map, camera, reader, str(document["map"]))
        landmark_ids = _landmark_ids(document, reader, meadow_map)
        start = _start(reader.table(document, "start", required=True), reader, meadow_map)
        commands = _route(reader.table(document, "route", required=True), reader, meadow_map, start.pose)
        spacing = _frame_spacing(document, reader)
        settings = _settings(document, reader)
        render = _render(reader.table(document, "render", required=False), reader)
        rate = reader.nonnegative(document.get("inject_wrong_rate", 0.0), "inject_wrong_rate")
        if rate > 1.0:
            raise reader.fail("inject_wrong_rate", f"expected a number in [0, 1], got {rate!r}")
        try:
            return cls(
                name,
                description,
                meadow_map,
                terrain,
                camera,
                start,
                commands,
                landmark_ids,
                spacing,
                settings,
                render,
                reader.source,
                rate,
                tuple(reader.files),
            )
        except InputError as exc:
            field_name, _, message = str(exc).partition(": ")
            where = {
                "Scenario.render.clutter": "[render] clutter",
                "Scenario.render.clutter_lines": "[render] clutter_lines",
                "Scenario.frame_spacing": (
                    "frame_spacing"
                    if "frame_spacing" in document
                    else "frame_rate and speed (the frame spacing)"
                ),
                "Scenario.commands": "[route]",
            }.get(field_name, field_name.removeprefix("Scenario."))
            raise reader.fail(where, message) from None

    # --- using -----------------------------------------------------------------------------

    @property
    def landmarks(self) -> tuple[LandmarkRecord, ...]:
        """The landmark records the robot uses (:attr:`landmark_ids`), in map order."""
        return tuple(self.meadow_map.landmark(i) for i in self.landmark_ids)

    def initial_map(self) -> SpatialUncertaintyMap:
        """Return the spatial uncertainty map at the start (:meth:`SpatialUncertaintyMap.from_pose`)."""
        s = self.start
        return SpatialUncertaintyMap.from_pose(s.pose, s.position_radius, s.heading_halfwidth)

    def legs(self) -> tuple[TurnAndRun, ...]:
        """Return the commands cut where frames are taken: a frame follows each leg.

        A command's turn stays with its first leg; the later legs of it only run.
        """
        if self.frame_spacing is None:
            return self.commands
        legs: list[TurnAndRun] = []
        travelled = 0.0
        tolerance = 1e-9 * max(1.0, self.frame_spacing)
        for command in self.commands:
            turn, remaining = command.turn, command.run
            while True:
                to_next = self.frame_spacing - math.fmod(travelled, self.frame_spacing)
                if to_next <= tolerance:
                    # On a frame's place but for rounding (0.4 + 0.4 + ... just short of 1.2):
                    # a leg of 1e-17 m would leave `travelled` unchanged, and this loop with it.
                    to_next += self.frame_spacing
                if to_next >= remaining - tolerance:
                    legs.append(TurnAndRun(turn, remaining))
                    travelled += remaining
                    break
                legs.append(TurnAndRun(turn, to_next))
                turn, remaining, travelled = 0.0, remaining - to_next, travelled + to_next
        return tuple(legs)

    def sample_true_start(self, rng: np.random.Generator) -> Pose:
        """Draw a true start uniformly in the start disk and wedge (inside a meadow).

        Draws again (up to 100 times) when the position falls outside every meadow, then
        falls back on the believed start.
        """
        s = self.start
        for _ in range(_START_DRAWS):
            radius = s.position_radius * math.sqrt(rng.uniform())
            angle = rng.uniform(-math.pi, math.pi)
            heading = s.pose.heading + rng.uniform(-1.0, 1.0) * s.heading_halfwidth
            x, y = s.pose.x + radius * math.cos(angle), s.pose.y + radius * math.sin(angle)
            if self.meadow_map.meadow_at(x, y) is not None:
                return Pose(x, y, heading)
        return s.pose

    def scene(self, rng: np.random.Generator) -> Scene:
        """Build the scene of the map with :attr:`render`'s settings (texture, clutter from ``rng``)."""
        r = self.render
        return Scene.from_meadow_map(
            self.meadow_map,
            rng,
            pole_radius=r.pole_radius,
            stripe_width=r.stripe_width,
            building_size=(r.building_width, r.building_depth),
            building_base=r.building_base,
            clutter=r.clutter,
        )

    def synthetic_camera(self, rng: np.random.Generator, *, scene: Scene | None = None) -> SyntheticCamera:
        """Return a synthetic camera on this scenario's camera (scene from ``rng`` unless given)."""
        r = self.render
        the_scene = self.scene(rng) if scene is None else scene
        return SyntheticCamera(self.camera, the_scene, rng, noise=r.noise, clutter_lines=r.clutter_lines)

    def robot(self, pose: Pose, rng: np.random.Generator, *, truncate: float | None = None) -> SimulatedRobot:
        """Return the true robot at ``pose`` in this scenario's world."""
        return SimulatedRobot(self.meadow_map, self.terrain, pose, rng, truncate=truncate)

    def simulate(
        self, rng: np.random.Generator, *, exact_start: bool = False, truncate: float | None = None
    ) -> Iterator[SimulatedFrame]:
        """Drive the route and yield a frame at the start and after every leg (:meth:`legs`).

        ``rng`` is split (``rng.spawn``) into the start's, the robot's and the camera's
        generators, so a seed fixes the whole run.

        Parameters
        ----------
        rng : numpy.random.Generator
            Source of randomness.
        exact_start : bool
            Start at the believed start pose instead of one drawn within its bounds.
        truncate : float, optional
            Clip the motion model's normals (see :class:`SimulatedRobot`).
        """
        start_rng, motion_rng, camera_rng = rng.spawn(3)
        pose = self.start.pose if exact_start else self.sample_true_start(start_rng)
        robot = self.robot(pose, motion_rng, truncate=truncate)
        camera = self.synthetic_camera(camera_rng)
        distance = 0.0

        def shot() -> NDArray[np.uint8]:
            image = camera.render(robot.pose)
            image.setflags(write=False)
            return image

        yield SimulatedFrame(0, None, robot.pose, shot(), distance)
        for index, leg in enumerate(self.legs(), start=1):
            robot.execute(leg)
            distance += leg.run
            yield SimulatedFrame(index, leg, robot.pose, shot(), distance)

    def __repr__(self) -> str:
        return (
            f"Scenario(name={self.name!r}, commands={len(self.commands)}, "
            f"landmarks={len(self.landmark_ids)}, source={self.source!r})"
        )


# ------------------------------------------------------------------------------ parts


def _load_terrain(document: Mapping[str, object], reader: _Reader, base: Path) -> TerrainTable | None:
    """Return the scenario's terrain table; None when it names none (the map's table, else the built-in)."""
    if "terrain" not in document:
        return None
    value = document["terrain"]
    if value == "default":
        return TerrainTable.default()
    path = reader.path(value, "terrain", base)
    try:
        return TerrainTable.from_toml(path)
    except FileFormatError as exc:
        raise reader.fail("terrain", f"expected a terrain table file that loads, got: {exc}") from None


def _check_terrains(meadow_map: MeadowMap, terrain: TerrainTable, reader: _Reader) -> None:
    """Refuse a table without the terrain of a meadow, naming both (the scenario's ``terrain``)."""
    for meadow in meadow_map.meadows:
        if meadow.terrain not in terrain:
            raise reader.fail(
                "terrain",
                f"expected a table with the terrain {meadow.terrain!r} of meadow {meadow.id!r}, "
                f"got terrains {', '.join(sorted(terrain))}",
            )


def _load_map(
    document: Mapping[str, object], reader: _Reader, base: Path, terrain: TerrainTable | None
) -> MeadowMap:
    if "map" not in document:
        raise reader.fail("map", "expected a GeoJSON meadow map path or sample:<name>, got none")
    value = reader.string(document["map"], "map")
    if value.startswith(_SAMPLE_PREFIX):
        try:
            meadow_map = sample_world(value[len(_SAMPLE_PREFIX) :])
        except InputError as exc:
            raise reader.fail("map", str(exc).split(": ", 1)[-1]) from None
        if terrain is not None:
            _check_terrains(meadow_map, terrain, reader)
        return meadow_map
    path = reader.path(value, "map", base)
    try:
        return MeadowMap.from_geojson(path, terrain_table=terrain)
    except FileFormatError as exc:
        raise reader.fail("map", f"expected a meadow map file that loads, got: {exc}") from None


def _check_strategies(meadow_map: MeadowMap, camera: Camera, reader: _Reader, source: str) -> None:
    """Refuse, naming the map, a landmark whose strategy or parameters perception cannot run.

    The map's reader (world) sits below perception and cannot build a detector; each
    landmark's find-landmark schema is built once here, where the scenario is read,
    rather than when a run starts (where the message named the landmark, not the file).
    """
    expecter = Expecter(camera)
    for record in meadow_map.landmarks:
        try:
            FindLandmarkSchema(record, expecter)
        except InputError as exc:
            raise reader.fail("map", f"expected a meadow map file that loads, got: {source}: {exc}") from None


def _with_confirm_frames(meadow_map: MeadowMap, document: Mapping[str, object], reader: _Reader) -> MeadowMap:
    """Return the map with every landmark's ``confirm_frames`` set by the scenario's key, if given.

    Frames far apart (the paper's still images, 10 to 20 ft apart) have no tracking between
    them: each image must identify its landmarks on its own, with ``confirm_frames = 1``.
    """
    if "confirm_frames" not in document:
        return meadow_map
    frames = reader.integer(document["confirm_frames"], "confirm_frames", 1)
    return MeadowMap(
        meadow_map.meadows,
        [dataclasses.replace(record, confirm_frames=frames) for record in meadow_map.landmarks],
        terrain_table=meadow_map.terrain_table,
        terrain_table_file=meadow_map.terrain_table_file,
    )


def _landmark_ids(document: Mapping[str, object], reader: _Reader, meadow_map: MeadowMap) -> tuple[str, ...]:
    if "landmarks" not in document:
        return tuple(record.id for record in meadow_map.landmarks)
    value = document["landmarks"]
    if not isinstance(value, list):
        raise reader.fail("landmarks", f"expected a list of landmark ids, got {describe(value)}")
    known = {record.id for record in meadow_map.landmarks}
    seen: set[str] = set()
    for index, item in enumerate(value):
        where = f"landmarks[{index}]"
        ident = reader.string(item, where)
        if ident not in known:
            raise reader.fail(where, f"expected the id of a landmark of the map, got {describe(ident)}")
        if ident in seen:
            raise reader.fail(where, f"expected each id once, got {describe(ident)} again")
        seen.add(ident)
    chosen = set(value)
    return tuple(record.id for record in meadow_map.landmarks if record.id in chosen)


def _start(table: Mapping[str, object], reader: _Reader, meadow_map: MeadowMap) -> StartState:
    reader.keys(table, _START_KEYS, "[start]")
    values: dict[str, float] = {}
    for key in ("x", "y", "position_radius"):
        if key not in table:
            raise reader.fail(f"[start] {key}", "expected this key, got none")
    values["x"] = reader.ranged(table["x"], "[start] x", "x")
    values["y"] = reader.ranged(table["y"], "[start] y", "y")
    radius = reader.ranged(table["position_radius"], "[start] position_radius", "position_radius")
    heading = reader.angle(table, "heading", "[start]", required=True)
    halfwidth = reader.angle(table, "heading_halfwidth", "[start]", required=True)
    if halfwidth < 0.0:
        raise reader.fail(
            "[start] heading_halfwidth_deg", f"expected a non-negative angle, got {halfwidth!r}"
        )
    if meadow_map.meadow_at(values["x"], values["y"]) is None:
        raise reader.fail(
            "[start] x", f"expected a start inside a meadow, got ({values['x']}, {values['y']})"
        )
    return StartState(Pose(values["x"], values["y"], heading), radius, halfwidth)


def _commands_through(
    points: NDArray[np.float64], pose: Pose, reader: _Reader, where: str
) -> list[TurnAndRun]:
    commands: list[TurnAndRun] = []
    x, y, heading = pose.x, pose.y, pose.heading
    for index, (px, py) in enumerate(points):
        dx, dy = float(px) - x, float(py) - y
        run = math.hypot(dx, dy)
        if run == 0.0:
            raise reader.fail(
                f"{where}[{index}]", f"expected a point away from the previous one, got ({px}, {py})"
            )
        if not LENGTH.contains(run):
            raise reader.fail(
                f"{where}[{index}]",
                f"expected a point at most {LENGTH.high:g} m from the previous one (a leg's run), "
                f"got ({px}, {py}), {run:.6g} m away",
            )
        direction = math.atan2(dy, dx)
        commands.append(TurnAndRun(wrap_angle(direction - heading), run))
        x, y, heading = float(px), float(py), direction
    return commands


def _route(
    table: Mapping[str, object], reader: _Reader, meadow_map: MeadowMap, pose: Pose
) -> tuple[TurnAndRun, ...]:
    commands, where = _route_commands(table, reader, meadow_map, pose)
    _check_inside(commands, pose, meadow_map, reader, where)
    return commands


def _check_inside(
    commands: tuple[TurnAndRun, ...], pose: Pose, meadow_map: MeadowMap, reader: _Reader, where: str
) -> None:
    """Refuse a route whose commanded legs leave the meadows, naming the first such leg.

    The simulation found it only when the robot got there, with a message that named
    neither the file nor the leg (a run across a gap between meadows was simulated on).
    """
    import shapely  # deferred: only a scenario's route needs it here

    turns = np.array([command.turn for command in commands])
    runs = np.array([command.run for command in commands])
    headings = pose.heading + np.cumsum(turns)
    ends = np.array([pose.x, pose.y]) + np.cumsum(
        runs[:, None] * np.stack([np.cos(headings), np.sin(headings)], 1), 0
    )
    starts = np.vstack([[pose.x, pose.y], ends[:-1]])
    area = shapely.union_all([shapely.Polygon(meadow.polygon.vertices) for meadow in meadow_map.meadows])
    legs = shapely.linestrings(np.stack([starts, ends], 1))
    inside = shapely.covers(area.buffer(1e-6), legs)
    if not inside.all():
        index = int(np.argmin(inside))
        place = where if where.endswith("goal") else f"{where}[{index}]"
        (x0, y0), (x1, y1) = starts[index], ends[index]
        raise reader.fail(
            place,
            f"expected a route inside the map's meadows, got a leg from ({x0:.6g}, {y0:.6g}) to "
            f"({x1:.6g}, {y1:.6g}) that leaves them",
        )


def _route_commands(
    table: Mapping[str, object], reader: _Reader, meadow_map: MeadowMap, pose: Pose
) -> tuple[tuple[TurnAndRun, ...], str]:
    reader.keys(table, ("commands", "waypoints", "goal"), "[route]")
    given = [key for key in ("commands", "waypoints", "goal") if key in table]
    if len(given) != 1:
        found = ", ".join(given) if given else "none"
        raise reader.fail("[route]", f"expected exactly one of commands, waypoints, goal, got {found}")
    key = given[0]
    where = f"[route] {key}"
    value = table[key]
    if key == "goal":
        goal = reader.point(value, where)
        try:
            route = plan_route(meadow_map, (pose.x, pose.y), goal)
        except InputError as exc:
            raise reader.fail(where, f"expected a goal reachable from the start, got: {exc}") from None
        if len(route.waypoints) < 2:
            raise reader.fail(where, f"expected a goal away from the start, got {list(goal)}")
        return tuple(_commands_through(route.waypoints[1:], pose, reader, where)), where
    if not isinstance(value, list) or not value:
        raise reader.fail(where, f"expected a non-empty list, got {describe(value)}")
    if key == "waypoints":
        points = np.array([reader.point(item, f"{where}[{i}]") for i, item in enumerate(value)])
        return tuple(_commands_through(points, pose, reader, where)), where
    commands: list[TurnAndRun] = []
    for index, item in enumerate(value):
        place = f"{where}[{index}]"
        if not isinstance(item, dict):
            raise reader.fail(place, f"expected a table {{turn_deg = ..., run = ...}}, got {describe(item)}")
        reader.keys(item, ("turn", "turn_deg", "run"), place, ".")
        turn = reader.angle(item, "turn", place, required=False, sep=".")
        if "run" not in item:
            raise reader.fail(f"{place}.run", "expected the run in metres, got none")
        commands.append(TurnAndRun(turn, reader.ranged(item["run"], f"{place}.run", "run")))
    return tuple(commands), where


def _frame_spacing(document: Mapping[str, object], reader: _Reader) -> float | None:
    spacing, rate, speed = document.get("frame_spacing"), document.get("frame_rate"), document.get("speed")
    if spacing is not None and rate is not None:
        raise reader.fail("frame_rate", "expected frame_spacing or frame_rate, got both")
    if spacing is not None:
        if speed is not None:
            raise reader.fail("speed", "expected speed only with frame_rate, got it with frame_spacing")
        return reader.ranged(spacing, "frame_spacing", "frame_spacing")
    if rate is not None:
        if speed is None:
            raise reader.fail("speed", "expected the speed (m/s) that goes with frame_rate, got none")
        return reader.ranged(speed, "speed", "speed") / reader.ranged(rate, "frame_rate", "frame_rate")
    if speed is not None:
        raise reader.fail("speed", "expected speed only with frame_rate, got no frame_rate")
    return None


def _settings(document: Mapping[str, object], reader: _Reader) -> ManagerSettings:
    """Read ``[manager]`` (and the earlier ``[lost]``) into :class:`ManagerSettings`."""
    manager = reader.table(document, "manager", required=False)
    lost = reader.table(document, "lost", required=False)
    infos = {f.name: SettingInfo.of(f) for f in dataclasses.fields(ManagerSettings)}
    angles = tuple(f"{name}_deg" for name, info in infos.items() if info.unit == "rad")
    reader.keys(manager, (*infos, *angles, "profile"), "[manager]")
    reader.keys(lost, ("area_limit", "missed_limit"), "[lost]")
    base = None
    if "profile" in manager:
        # The profile's fields are the base the table's own keys override, as on the command line.
        named = manager["profile"]
        names = [profile.value for profile in MapProfile]
        if not isinstance(named, str) or named not in names:
            raise reader.fail("[manager] profile", f"expected one of {', '.join(names)}, got {named!r}")
        base = MapProfile(named).settings()
    values: dict[str, object] = {}
    places: dict[str, str] = {}
    for table, name in ((lost, "lost"), (manager, "manager")):
        for key, value in table.items():
            if key == "profile" and table is manager:
                continue
            setting, degrees = (key[:-4], True) if key in angles else (key, False)
            where = f"[{name}] {key}"
            if setting in places:
                raise reader.fail(where, f"expected one value of {setting}, got another in {places[setting]}")
            if degrees and isinstance(value, (int, float)) and not isinstance(value, bool):
                value = math.radians(value)
            elif value == "none" and infos[setting].nullable:
                value = None
            values[setting], places[setting] = value, where
    return ManagerSettings.from_dict(
        values, base=base, fail=lambda key, message: reader.fail(places.get(key, f"[manager] {key}"), message)
    )


def _render(table: Mapping[str, object], reader: _Reader) -> RenderSettings:
    reader.keys(table, _RENDER_KEYS, "[render]")
    default = RenderSettings()
    values: dict[str, float | int] = {}
    for key in _RENDER_KEYS:
        where = f"[render] {key}"
        if key not in table:
            values[key] = getattr(default, key)
        elif key in ("clutter", "clutter_lines"):
            count = reader.integer(table[key], where, 0)
            bounds = KEY_RANGES[key]
            if count > bounds.high:
                raise reader.fail(where, f"expected at most {bounds.high:g} {bounds.unit}, got {count}")
            values[key] = count
        else:
            values[key] = reader.ranged(table[key], where, key)
    return RenderSettings(
        noise=float(values["noise"]),
        clutter=int(values["clutter"]),
        clutter_lines=int(values["clutter_lines"]),
        pole_radius=float(values["pole_radius"]),
        stripe_width=float(values["stripe_width"]),
        building_width=float(values["building_width"]),
        building_depth=float(values["building_depth"]),
        building_base=float(values["building_base"]),
    )


def waypoints_array(scenario: Scenario) -> NDArray[np.float64]:
    """Return the commanded positions after each command, ``(n + 1, 2)`` from the start (read-only).

    Examples
    --------
    >>> from aura_ums.camera import CameraIntrinsics, CameraMount
    >>> from aura_ums.world import sample_world
    >>> camera = Camera(CameraIntrinsics(500, 500, 320, 240, 640, 480), CameraMount(1.0))
    >>> route = (TurnAndRun(0, 2.0), TurnAndRun(math.pi / 2, 0.5))
    >>> s = Scenario("s", "", sample_world("paper_sidewalk"), TerrainTable.default(), camera,
    ...              StartState(Pose(0, 0, 0), 0.3, 0.05), route, ())
    >>> waypoints_array(s).round(6).tolist()
    [[0.0, 0.0], [2.0, 0.0], [2.0, 0.5]]
    """
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario: expected a Scenario, got {type(scenario).__name__}")
    x, y, heading = scenario.start.pose.x, scenario.start.pose.y, scenario.start.pose.heading
    points = [(x, y)]
    for command in scenario.commands:
        heading += command.turn
        x, y = x + command.run * math.cos(heading), y + command.run * math.sin(heading)
        points.append((x, y))
    return read_only(np.array(points))
