"""The paper's Figure 4: image windows from an elongated polygonal map and from the disk model."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Polygon as PolygonPatch
from matplotlib.patches import Rectangle

from aura_ums._files import as_path
from aura_ums._validate import integer_at_least
from aura_ums.expecter import Expecter, ImageWindow, disk_model_map, figure4_scenario
from aura_ums.uncertainty import PointLandmark, SpatialUncertaintyMap

_SAMPLES = 600
_COLORS = ("tab:blue", "tab:orange")


def draw_expecter_figures(out_dir: str | Path, *, seed: int = 0) -> list[Path]:
    """Draw the paper's Figure 4 (polygon versus disk windows) and save it as PNG files.

    Two files: ``figure4_top_view.png`` (top view: the elongated polygonal map, its
    disk model and the two landmarks) and ``figure4_windows.png`` (the 640 x 480
    image: for each landmark the guaranteed window of the polygon map, solid, and of the
    disk model, dashed, with the projections from poses sampled in each map as dots).
    Landmark 1, ahead on the path, gets a tall window; landmark 2, beside it, a wide one.

    Parameters
    ----------
    out_dir : str or Path
        Folder to write to (created if missing).
    seed : int
        Seed of the pose samples.

    Returns
    -------
    list of Path
        The files written.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     [p.name for p in draw_expecter_figures(folder)]
    ['figure4_top_view.png', 'figure4_windows.png']
    """
    seed = integer_at_least(seed, "seed", 0)
    folder = as_path(out_dir, "out_dir")
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    scenario = figure4_scenario()
    disk = disk_model_map(scenario.map)
    expecter = Expecter(scenario.camera)

    map_figure = Figure(figsize=(7.0, 4.5))
    FigureCanvasAgg(map_figure)
    _draw_top_view(map_figure.add_subplot(1, 1, 1), scenario.map, disk, scenario.landmarks)
    map_path = folder / "figure4_top_view.png"
    map_figure.savefig(map_path, dpi=110)

    image_figure = Figure(figsize=(11.0, 4.6))
    FigureCanvasAgg(image_figure)
    k = scenario.camera.intrinsics
    for column, (title, model) in enumerate((("polygonal map", scenario.map), ("disk model", disk))):
        ax = image_figure.add_subplot(1, 2, column + 1)
        _image_frame(ax, k.width, k.height, f"Image windows, {title}")
        poses = model.sample_poses(_SAMPLES, rng)
        for landmark, color in zip(scenario.landmarks, _COLORS, strict=True):
            pixels = scenario.camera.project(poses, [(landmark.x, landmark.y, landmark.z)])[:, 0, :]
            ax.plot(pixels[:, 0], pixels[:, 1], ".", ms=2.0, color=color, alpha=0.5)
            window = expecter.bounds(model, landmark)
            if window is not None:
                _rectangle(ax, window, color, "-" if model is scenario.map else "--", landmark.id)
        ax.legend(loc="lower left", fontsize=8)
    windows_path = folder / "figure4_windows.png"
    image_figure.savefig(windows_path, dpi=110)
    return [map_path, windows_path]


def _draw_top_view(
    ax: Axes,
    polygon_map: SpatialUncertaintyMap,
    disk: SpatialUncertaintyMap,
    landmarks: tuple[PointLandmark, PointLandmark],
) -> None:
    ax.add_patch(
        PolygonPatch(
            disk.polygon.vertices, closed=True, fill=False, ls="--", color="grey", label="disk model"
        )
    )
    ax.add_patch(
        PolygonPatch(polygon_map.polygon.vertices, closed=True, alpha=0.4, color="tab:green", label="polygon")
    )
    for landmark, color in zip(landmarks, _COLORS, strict=True):
        ax.plot([landmark.x], [landmark.y], "o", color=color, label=f"{landmark.id} ({landmark.symbol})")
    ax.set_aspect("equal")
    ax.set_xlim(-3.0, 13.0)
    ax.set_ylim(-3.0, 4.5)
    ax.set_xlabel("x east (m)")
    ax.set_ylabel("y north (m)")
    ax.set_title("Elongated map along the path, its disk model, two landmarks")
    ax.legend(loc="lower right", fontsize=8)


def _image_frame(ax: Axes, width: int, height: int, title: str) -> None:
    ax.add_patch(Rectangle((-0.5, -0.5), width, height, fill=False, color="black", lw=1.5))
    ax.set_xlim(-20.0, width + 20.0)
    ax.set_ylim(height + 20.0, -20.0)  # v runs down
    ax.set_aspect("equal")
    ax.set_xlabel("u (pixels)")
    ax.set_ylabel("v (pixels)")
    ax.set_title(title)


def _rectangle(ax: Axes, window: ImageWindow, color: str, style: str, name: str) -> None:
    ax.add_patch(
        Rectangle(
            (window.u_min, window.v_min),
            window.width,
            window.height,
            fill=False,
            ls=style,
            lw=1.5,
            color=color,
            label=f"{name}: {window.width:.0f} x {window.height:.0f} px",
        )
    )
