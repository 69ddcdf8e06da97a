"""The paper's growth figures (5, 6, 7) and the demo report built from them."""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import NDArray

from aura_ums._validate import integer_at_least
from aura_ums.plot._draw import draw_compass, draw_map, draw_samples
from aura_ums.uncertainty import (
    FOOT,
    Pose,
    SpatialUncertaintyMap,
    TerrainStats,
    TerrainTable,
    TurnAndRun,
    growth_tightness,
    simulate_containment,
)

#: Terrain of the paper's sidewalk experiment.
PAPER_TERRAIN = "concrete"
_SAMPLES = 3000


def _propagate(
    start: SpatialUncertaintyMap,
    moves: list[TurnAndRun],
    terrain: TerrainStats,
    rng: np.random.Generator,
) -> tuple[list[SpatialUncertaintyMap], list[NDArray[np.float64]]]:
    """Grow the map through ``moves`` and move sampled true poses alongside (untruncated noise)."""
    maps = [start]
    poses = start.sample_poses(_SAMPLES, rng)
    clouds = [poses]
    for command in moves:
        maps.append(maps[-1].grow(command, terrain))
        poses = terrain.sample_motions(poses, command, rng)
        clouds.append(poses)
    return maps, clouds


def _finish(axes_list: list[object], figure: Figure, path: Path) -> Path:
    for axes in axes_list:
        axes.set_aspect("equal", adjustable="datalim")  # type: ignore[attr-defined]
        axes.grid(True, lw=0.3)  # type: ignore[attr-defined]
        axes.set_xlabel("x (m)")  # type: ignore[attr-defined]
        axes.set_ylabel("y (m)")  # type: ignore[attr-defined]
    figure.tight_layout()
    figure.savefig(path, dpi=130)
    return path


def figure5(out: Path, rng: np.random.Generator, terrain: TerrainStats) -> Path:
    """Figure 5: a point, a 45 degree turn, then a 30 ft run."""
    start = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.0, 0.0)
    maps, clouds = _propagate(start, [TurnAndRun(math.radians(45), 30 * FOOT)], terrain, rng)
    figure = Figure(figsize=(6, 5.5))
    axes = figure.add_subplot()
    draw_samples(axes, clouds[1])
    draw_map(axes, maps[1], label="uncertainty map (3 sigma)")
    axes.plot([0], [0], "ks")
    axes.annotate("S", (0, 0), textcoords="offset points", xytext=(-12, -4))
    axes.legend(loc="upper left", fontsize=8)
    axes.set_title("Figure 5: point uncertainty transform (45 deg turn, 30 ft run)", fontsize=10)
    return _finish([axes], figure, out / "figure5_point_transform.png")


def figure6(out: Path, rng: np.random.Generator, terrain: TerrainStats) -> Path:
    """Figure 6: the wedge before and after a 90 degree counter-clockwise turn and run."""
    start = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.0, math.radians(5))
    maps, clouds = _propagate(start, [TurnAndRun(math.radians(90), 30 * FOOT)], terrain, rng)
    before, after = maps
    figure = Figure(figsize=(8, 4.2))
    left, right = figure.add_subplot(1, 2, 1), figure.add_subplot(1, 2, 2)
    draw_compass(left, before, "(a) original: +-5 deg")
    cw_growth = math.degrees(after.wedge.cw - before.wedge.cw)
    ccw_growth = math.degrees(after.wedge.ccw - before.wedge.ccw)
    draw_compass(
        right,
        after,
        f"(b) after 90 deg CCW turn and 30 ft run\n"
        f"clockwise +{cw_growth:.1f} deg, counter-clockwise +{ccw_growth:.1f} deg",
    )
    headings = clouds[1][:, 2]
    right.scatter(0.93 * np.cos(headings), 0.93 * np.sin(headings), s=3, alpha=0.2, color="tab:orange")
    figure.suptitle("Figure 6: angular uncertainty", fontsize=10)
    figure.tight_layout()
    path = out / "figure6_heading_wedge.png"
    figure.savefig(path, dpi=130)
    return path


def figure7(out: Path, rng: np.random.Generator, terrain: TerrainStats) -> Path:
    """Figure 7: (a) Figure 5's map; (b) a 45 degree turn and run; (c) a run, a 180 degree turn, a run."""
    start = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.0, 0.0)
    first = TurnAndRun(math.radians(45), 30 * FOOT)
    maps_b, clouds_b = _propagate(start, [first, TurnAndRun(math.radians(45), 30 * FOOT)], terrain, rng)
    maps_c, clouds_c = _propagate(
        start, [first, TurnAndRun(0.0, 30 * FOOT), TurnAndRun(math.pi, 30 * FOOT)], terrain, rng
    )
    figure = Figure(figsize=(14, 4.8))
    panels = [figure.add_subplot(1, 3, k) for k in (1, 2, 3)]
    draw_samples(panels[0], clouds_b[1])
    draw_map(panels[0], maps_b[1])
    panels[0].set_title("(a) starting map (Figure 5)", fontsize=9)
    draw_samples(panels[1], clouds_b[2])
    draw_map(panels[1], maps_b[1], color="0.5")
    draw_map(panels[1], maps_b[2])
    panels[1].set_title("(b) 45 deg turn and 30 ft run applied to (a)", fontsize=9)
    draw_samples(panels[2], clouds_c[3])
    draw_map(panels[2], maps_c[1], color="0.5")
    draw_map(panels[2], maps_c[2], color="0.3")
    draw_map(panels[2], maps_c[3])
    panels[2].set_title("(c) 30 ft run, then 180 deg turn and 30 ft run", fontsize=9)
    figure.suptitle("Figure 7: map uncertainty transform", fontsize=10)
    return _finish(list(panels), figure, out / "figure7_map_transform.png")


def draw_growth_figures(out: str | Path, *, seed: int = 0, terrain: str = PAPER_TERRAIN) -> list[Path]:
    """Draw the paper's Figures 5, 6 and 7 into ``out`` with sampled true outcomes over them.

    Parameters
    ----------
    out : str or Path
        Folder to write PNG files into (created if missing).
    seed : int
        Seed of the sampled outcomes.
    terrain : str
        Name of the terrain in the default table.

    Returns
    -------
    list of Path
        The written files.

    Examples
    --------
    Drawing the three figures takes about half a second; a terrain missing from the
    default table is refused before anything is drawn:

    >>> import tempfile
    >>> [path.name for path in draw_growth_figures(tempfile.mkdtemp(), seed=1)]
    ['figure5_point_transform.png', 'figure6_heading_wedge.png', 'figure7_map_transform.png']
    >>> draw_growth_figures(tempfile.mkdtemp(), terrain="moon")
    Traceback (most recent call last):
    ...
    aura_ums.errors.UnknownTerrainError: terrain: expected one of concrete, grass, gravel, tile, got 'moon'
    """
    seed = integer_at_least(seed, "seed", 0)
    stats = TerrainTable.default()[terrain]
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    return [figure5(folder, rng, stats), figure6(folder, rng, stats), figure7(folder, rng, stats)]


def draw_all_figures(out: str | Path, *, seed: int = 0) -> list[Path]:
    """Draw every figure of the paper that aura-ums reproduces so far (3, 4, 5, 6, 7) into ``out``.

    Returns
    -------
    list of Path
        The written PNG files.

    Examples
    --------
    Drawing every figure takes about a second; a negative seed is refused before anything
    is drawn:

    >>> import tempfile
    >>> draw_all_figures(tempfile.mkdtemp(), seed=-1)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: seed: expected an integer >= 0, got -1
    """
    from aura_ums.plot._expecter import draw_expecter_figures
    from aura_ums.plot._reduction import draw_path_figure

    seed = integer_at_least(seed, "seed", 0)
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    written = [draw_path_figure(folder, np.random.default_rng(seed))]
    written.extend(draw_expecter_figures(folder, seed=seed))
    written.extend(draw_growth_figures(folder, seed=seed))
    return written


def _figure4_window_rows() -> list[str]:
    """Rows of the report's window table: polygon against disk model, Figure 4 scenario."""
    from aura_ums.expecter import Expecter, disk_model_map, figure4_scenario

    scenario = figure4_scenario()
    expecter = Expecter(scenario.camera)
    disk = disk_model_map(scenario.map)
    rows = []
    for landmark in scenario.landmarks:
        ours = expecter.bounds(scenario.map, landmark)
        theirs = expecter.bounds(disk, landmark)
        if ours is None or theirs is None:
            rows.append(f"| {landmark.id} | not in view | not in view | - |")
            continue
        polygon_size = f"{ours.width:.0f} x {ours.height:.0f}"
        disk_size = f"{theirs.width:.0f} x {theirs.height:.0f}"
        rows.append(f"| {landmark.id} | {polygon_size} | {disk_size} | {ours.area / theirs.area:.3f} |")
    return rows


def _random_moves(rng: np.random.Generator, table: TerrainTable) -> list[tuple[TurnAndRun, TerrainStats]]:
    names = sorted(table)
    return [
        (
            TurnAndRun(float(rng.uniform(-math.pi, math.pi)), float(rng.uniform(0.0, 10.0))),
            table[names[int(rng.integers(len(names)))]],
        )
        for _ in range(int(rng.integers(1, 21)))
    ]


def write_growth_report(out: str | Path, *, seed: int = 0) -> Path:
    """Write the report: the paper's figures and ``summary.md`` with measured figures.

    The summary holds soundness (truncated noise), calibration (untruncated noise at
    2 and 3 sigma) and tightness per terrain, each measured on seeded samples.

    Returns
    -------
    Path
        The written ``summary.md``.

    Examples
    --------
    The report takes a few seconds (``aura-ums demo`` writes it, then adds the experiment);
    a negative seed is refused before any figure is drawn or the summary written:

    >>> import tempfile
    >>> out = Path(tempfile.mkdtemp())
    >>> write_growth_report(out, seed=-1)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: seed: expected an integer >= 0, got -1
    >>> (out / "summary.md").exists()
    False
    """
    seed = integer_at_least(seed, "seed", 0)
    folder = Path(out)
    figures = draw_all_figures(folder / "figures", seed=seed)
    table = TerrainTable.default()
    rng = np.random.default_rng(seed)
    started = time.perf_counter()
    rows = []
    for sigmas in (2.0, 3.0):
        sound_inside = sound_total = calib_inside = calib_total = 0
        for _ in range(150):
            start = SpatialUncertaintyMap.from_pose(
                Pose(0.0, 0.0, float(rng.uniform(-math.pi, math.pi))), float(rng.uniform(0, 0.5)), 0.05
            )
            moves = _random_moves(rng, table)
            sound = simulate_containment(start, moves, rng, poses=40, sigmas=sigmas, truncate=sigmas)
            calib = simulate_containment(start, moves, rng, poses=40, sigmas=sigmas, include_extremes=False)
            sound_inside += sound.inside
            sound_total += sound.total
            calib_inside += calib.inside
            calib_total += calib.total
        rows.append(
            f"| {sigmas:.0f} | {sound_inside / sound_total:.4%} of {sound_total} "
            f"| {calib_inside / calib_total:.4%} of {calib_total} |"
        )
    point = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.0, 0.0)
    command = TurnAndRun(math.radians(45), 30 * FOOT)
    tightness = []
    for name in sorted(table):
        result = growth_tightness(point, command, table[name], rng)
        tightness.append(
            f"| {name} | {result.map_area:.3f} | {result.sample_hull_area:.3f} | {result.ratio:.3f} |"
        )
    windows = _figure4_window_rows()
    elapsed = time.perf_counter() - started
    lines = [
        "# aura-ums report",
        "",
        f"Seed {seed}. Terrain statistics: the built-in illustrative table (`TerrainTable.default()`).",
        "",
        "## Figures",
        "",
        *[f"- [{path.name}](figures/{path.name})" for path in figures],
        "",
        "## Containment of sampled true poses",
        "",
        "150 random sequences of 1-20 turn-and-run moves per row, all four terrains, 40 true start",
        "poses per sequence (plus the polygon's vertices at the wedge's extreme headings for",
        "soundness), checked after every move.",
        "",
        "| sigmas | soundness (noise truncated at sigmas) | calibration (Gaussian noise) |",
        "| --- | --- | --- |",
        *rows,
        "",
        "## Tightness of one move from a point (45 deg turn, 30 ft run)",
        "",
        "| terrain | map area (m^2) | hull of 20,000 truncated samples (m^2) | ratio |",
        "| --- | --- | --- | --- |",
        *tightness,
        "",
        "## Expectation windows in the Figure 4 scenario",
        "",
        "Guaranteed windows (before margins, not clipped) of the elongated polygonal map and of",
        "the paper's disk model (a circle around the centre enclosing the polygon, same wedge).",
        "",
        "| landmark | polygon window (px) | disk-model window (px) | polygon / disk area |",
        "| --- | --- | --- | --- |",
        *windows,
        "",
        f"Measured in {elapsed:.1f} s. Reproduce with `aura-ums demo --out report --seed {seed}`.",
        "",
    ]
    summary = folder / "summary.md"
    summary.write_text("\n".join(lines), encoding="utf-8")
    return summary
