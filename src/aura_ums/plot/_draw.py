"""Small drawing helpers shared by the figures: maps, wedges and sample clouds."""

from __future__ import annotations

import math

import numpy as np
from matplotlib.axes import Axes
from matplotlib.patches import Polygon as PolygonPatch
from matplotlib.patches import Wedge as WedgePatch
from numpy.typing import NDArray

from aura_ums.uncertainty import SpatialUncertaintyMap

MAP_COLOR = "tab:blue"
SAMPLE_COLOR = "tab:orange"


def draw_map(
    axes: Axes,
    uncertainty_map: SpatialUncertaintyMap,
    *,
    color: str = MAP_COLOR,
    label: str | None = None,
    wedge_length: float | None = None,
) -> None:
    """Draw a map's polygon, its centre and its heading wedge (centre and side lines)."""
    vertices = uncertainty_map.polygon.vertices
    if len(vertices) >= 3:
        axes.add_patch(PolygonPatch(vertices, closed=True, fill=True, alpha=0.18, color=color, label=label))
        axes.add_patch(PolygonPatch(vertices, closed=True, fill=False, lw=1.5, color=color))
    else:
        axes.plot(vertices[:, 0], vertices[:, 1], "o-", color=color, label=label)
    cx, cy = uncertainty_map.center
    axes.plot([cx], [cy], "+", color=color, ms=10, mew=2)
    xmin, ymin, xmax, ymax = uncertainty_map.polygon.bounds
    length = wedge_length or max(0.6, 0.6 * max(xmax - xmin, ymax - ymin))
    wedge = uncertainty_map.wedge
    for angle, style in (
        (wedge.center, "-"),
        (wedge.center - wedge.cw, "--"),
        (wedge.center + wedge.ccw, "--"),
    ):
        axes.plot(
            [cx, cx + length * math.cos(angle)], [cy, cy + length * math.sin(angle)], style, color=color, lw=1
        )


def draw_samples(axes: Axes, poses: NDArray[np.float64], *, label: str = "sampled true outcomes") -> None:
    """Scatter sampled true positions."""
    axes.scatter(poses[:, 0], poses[:, 1], s=2, alpha=0.35, color=SAMPLE_COLOR, label=label, linewidths=0)


def draw_compass(axes: Axes, uncertainty_map: SpatialUncertaintyMap, title: str) -> None:
    """Draw the heading wedge on a compass circle: filled where the robot may face."""
    wedge = uncertainty_map.wedge
    axes.add_patch(WedgePatch((0.0, 0.0), 1.0, 0.0, 360.0, fill=False, lw=1, color="0.4"))
    lo = math.degrees(wedge.center - wedge.cw)
    hi = math.degrees(wedge.center + wedge.ccw)
    axes.add_patch(WedgePatch((0.0, 0.0), 1.0, lo, hi, alpha=0.3, color=MAP_COLOR))
    for angle, style in ((wedge.center, "-"), (math.radians(lo), "--"), (math.radians(hi), "--")):
        axes.plot([0, math.cos(angle)], [0, math.sin(angle)], style, color=MAP_COLOR)
    axes.set_xlim(-1.15, 1.15)
    axes.set_ylim(-1.15, 1.15)
    axes.set_aspect("equal")
    axes.set_axis_off()
    axes.set_title(title, fontsize=9)
