"""The paper's Figure 3: a disk model against the convex polygon as a robot runs down a path."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Circle

from aura_ums._validate import COORDINATE, LENGTH, Range, check_rng, integer_at_least
from aura_ums.errors import InputError
from aura_ums.plot._draw import draw_map, draw_samples
from aura_ums.uncertainty import (
    GroundLineLandmark,
    GroundLineObservation,
    Pose,
    SpatialUncertaintyMap,
    TerrainTable,
    TurnAndRun,
)

#: The path's right-hand edge, 1.5 m to the right of a robot driving east along y = 0.
PATH_EDGE = GroundLineLandmark("path_edge", (-10.0, -1.5), (100.0, -1.5), symbol="path edge")
_OFFSET_ERROR = 0.10  # m: where the edge line falls in the image, after calibration error
_ANGLE_ERROR = math.radians(2.0)
#: Most steps of :func:`run_down_path`: 20,000 took 5.6 s (a map grown and reduced each, kept).
MAX_PATH_STEPS = 10_000
#: A step of :func:`run_down_path`, metres: a run of a command, > 0.
_STEP_LENGTH = Range(0.0, LENGTH.high, "m", low_open=True)


@dataclass(frozen=True, slots=True)
class PathRunStep:
    """One position of the run down the path: the map and its disk model.

    Examples
    --------
    >>> step = run_down_path(np.random.default_rng(0), steps=1)[0]
    >>> step.distance, step.uncertainty_map.area < step.disk_area    # the disk encloses the polygon
    (4.0, True)
    >>> point = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.0, 0.0)
    >>> PathRunStep(0.0, point, 0.0, Pose(0.0, 0.0, 0.0)).disk_area     # a known pose: no disk
    0.0
    """

    distance: float
    uncertainty_map: SpatialUncertaintyMap
    disk_radius: float
    truth: Pose

    @property
    def disk_area(self) -> float:
        """Area of the disk model around the map's centre that encloses the polygon, m^2."""
        return math.pi * self.disk_radius**2


def run_down_path(
    rng: np.random.Generator, *, steps: int = 6, step_length: float = 4.0, terrain: str = "concrete"
) -> list[PathRunStep]:
    """Drive east down a path, growing the map each step and reducing it by the seen path edge.

    The truth moves by the terrain's own model; the edge observation is synthesised
    from the true pose with errors anywhere inside its bounds.

    Examples
    --------
    >>> steps = run_down_path(np.random.default_rng(0), steps=3)
    >>> [s.distance for s in steps], [round(s.uncertainty_map.area / s.disk_area, 3) for s in steps]
    ([4.0, 8.0, 12.0], [0.209, 0.159, 0.112])
    >>> all(s.uncertainty_map.contains(s.truth) for s in steps)
    True
    >>> run_down_path(np.random.default_rng(0), steps=0)       # no step, no map
    []
    >>> run_down_path(np.random.default_rng(0), steps=10**12)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: steps: expected at most 10000 steps (about 0.3 ms and 1 kB a step: 3 s), \
got 1000000000000
    >>> run_down_path(np.random.default_rng(0), terrain="moon")
    Traceback (most recent call last):
    ...
    aura_ums.errors.UnknownTerrainError: terrain: expected one of concrete, grass, gravel, tile, got 'moon'
    """
    check_rng(rng)
    steps = integer_at_least(steps, "steps", 0)
    if steps > MAX_PATH_STEPS:
        raise InputError(
            f"steps: expected at most {MAX_PATH_STEPS} steps (about 0.3 ms and 1 kB a step: 3 s), "
            f"got {steps!r}"
        )
    length = _STEP_LENGTH.check(step_length, "step_length")
    if steps * length > COORDINATE.high:
        raise InputError(
            f"steps, step_length: expected a path of at most {COORDINATE.high:g} m (the coordinate range), "
            f"got {steps} steps of {length:g} m"
        )
    stats = TerrainTable.default()[terrain]
    truth = Pose(0.0, 0.0, 0.0)
    current = SpatialUncertaintyMap.from_pose(truth, 0.3, math.radians(3))
    result = []
    command = TurnAndRun(0.0, length)
    for index in range(steps):
        moved = stats.sample_motions(truth.as_array(), command, rng, truncate=3.0)[0]
        truth = Pose(float(moved[0]), float(moved[1]), float(moved[2]))
        current = current.grow(command, stats)
        # Seen from the truth: distance left of the edge, edge direction relative to heading.
        offset = truth.y - PATH_EDGE.start[1]
        angle = PATH_EDGE.direction - truth.heading
        observation = GroundLineObservation(
            PATH_EDGE.id,
            float(index),
            offset + float(rng.uniform(-_OFFSET_ERROR, _OFFSET_ERROR)),
            _OFFSET_ERROR,
            angle + float(rng.uniform(-_ANGLE_ERROR, _ANGLE_ERROR)),
            _ANGLE_ERROR,
        )
        reduction = current.reduce(observation, PATH_EDGE)
        if reduction.consistent:
            current = reduction.map
        radius = float(np.max(np.hypot(*(current.polygon.vertices - current.center).T)))
        result.append(PathRunStep(step_length * (index + 1), current, radius, truth))
    return result


def draw_path_figure(out: str | os.PathLike[str], rng: np.random.Generator) -> Path:
    """Figure 3: disk model versus convex polygon down a path whose edge is seen.

    Examples
    --------
    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> draw_path_figure(folder, np.random.default_rng(0)).name
    'figure3_disk_vs_polygon.png'
    >>> sorted(path.name for path in folder.iterdir())
    ['figure3_disk_vs_polygon.png']
    >>> draw_path_figure(str(folder), np.random.default_rng(0)).parent == folder   # a str works too
    True
    >>> draw_path_figure(folder, None)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: rng: expected a numpy.random.Generator, got NoneType
    """
    if not isinstance(out, (str, os.PathLike)):
        raise InputError(f"out: expected a folder path, got {type(out).__name__}")
    steps = run_down_path(rng)
    figure = Figure(figsize=(12, 4.2))
    axes = figure.add_subplot()
    axes.axhline(PATH_EDGE.start[1], color="0.3", lw=2, label="path edge (Class III landmark)")
    axes.axhline(1.5, color="0.7", lw=1, ls=":")
    for step in steps:
        draw_map(axes, step.uncertainty_map, wedge_length=0.8)
        axes.add_patch(
            Circle(tuple(step.uncertainty_map.center), step.disk_radius, fill=False, color="tab:red", ls="--")
        )
        axes.plot([step.truth.x], [step.truth.y], "k.", ms=4)
        axes.annotate(
            f"{step.uncertainty_map.area / step.disk_area:.0%}",
            (step.uncertainty_map.center[0], step.uncertainty_map.center[1] + step.disk_radius + 0.1),
            ha="center",
            fontsize=8,
        )
    draw_samples(axes, np.array([[s.truth.x, s.truth.y, s.truth.heading] for s in steps]), label="true poses")
    axes.plot([], [], "--", color="tab:red", label="disk model (encloses the polygon)")
    axes.set_aspect("equal", adjustable="datalim")
    axes.set_xlabel("x (m)")
    axes.set_ylabel("y (m)")
    axes.grid(True, lw=0.3)
    axes.legend(loc="upper left", fontsize=8)
    axes.set_title(
        "Figure 3: disk model versus convex polygon, running down a path whose edge is seen "
        "(labels: polygon area / disk area)",
        fontsize=10,
    )
    figure.tight_layout()
    path = Path(out) / "figure3_disk_vs_polygon.png"
    figure.savefig(path, dpi=130)
    return path
