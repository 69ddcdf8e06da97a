"""Random kernel inputs shared by the tests of aura_ums._native: polygons, wedges, terrains, commands."""

from __future__ import annotations

import importlib
import math
from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray

from aura_ums import _native
from aura_ums.geometry import ConvexPolygon, convex_hull, regular_polygon
from aura_ums.uncertainty import TerrainStats

Array = NDArray[np.float64]

#: Tests that compare the C kernels with their references, or call them directly.
built = pytest.mark.skipif(not _native.BUILT, reason="the C extension was not built (no compiler)")
#: Tests that only mean something while the kernels run compiled (not under AURA_UMS_NATIVE=0).
native = pytest.mark.skipif(
    not _native.NATIVE, reason="the C kernels are not in use (not built, or AURA_UMS_NATIVE=0)"
)


def kernels() -> Any:
    """The extension module itself, untyped: for calls with deliberately wrong arguments."""
    return importlib.import_module("aura_ums._native._kernels")


def random_polygon(rng: np.random.Generator, *, many: bool = False) -> Array:
    """A convex CCW polygon: usually a random hull, sometimes a point, a segment, a sliver,
    a regular polygon, or one too fine to merge (edges far below 1e-6 of its coordinates).

    ``many``: at least 40 vertices (to drive a vertex cap).
    """
    kind = int(rng.integers(0, 8)) if not many else int(rng.integers(5, 8))
    shift = rng.choice([0.0, 1.0, 1e3, -5e4]) * rng.uniform(-1.0, 1.0, 2)
    if kind == 0:
        return np.asarray(shift.reshape(1, 2) + rng.normal(size=(1, 2)), dtype=np.float64)
    if kind == 1:
        return convex_hull(shift + rng.normal(size=(2, 2)) * rng.uniform(0.01, 5.0))
    if kind == 2:  # a sliver
        base = rng.normal(size=(int(rng.integers(3, 30)), 2)) * np.array([rng.uniform(0.5, 5.0), 1e-7])
        return convex_hull(base + shift)
    if kind in (3, 4):
        count = int(rng.integers(3, 60))
        spread = rng.uniform(0.01, 10.0) * rng.uniform(0.05, 1.0, 2)
        return convex_hull(shift + rng.normal(size=(count, 2)) * spread)
    if kind == 5:  # regular, many vertices
        count = int(rng.integers(40, 300))
        return regular_polygon(tuple(shift.tolist()), float(rng.uniform(0.01, 5.0)), count).vertices.copy()
    if kind == 6:  # too fine to merge: every edge below 1e-6 of the coordinates
        count = int(rng.integers(40, 400))
        center = (1e4 * rng.choice([-1.0, 1.0]), 1e4 * rng.uniform(-1.0, 1.0))
        return regular_polygon(center, float(rng.uniform(1e-4, 1e-3)), count).vertices.copy()
    # A long thin ellipse of many vertices: nearly parallel neighbours along its sides.
    count = int(rng.integers(40, 300))
    t = np.arange(count) * (2.0 * math.pi / count)
    angle = rng.uniform(-math.pi, math.pi)
    x, y = rng.uniform(1.0, 20.0) * np.cos(t), rng.uniform(1e-4, 0.05) * np.sin(t)
    rotated = np.column_stack(
        [math.cos(angle) * x - math.sin(angle) * y, math.sin(angle) * x + math.cos(angle) * y]
    )
    return convex_hull(rotated + shift)


def random_wedge(rng: np.random.Generator) -> tuple[float, float, float]:
    """(centre, cw, ccw), radians: full circles, the +-pi seam, nearly known, wide, and plain."""
    kind = int(rng.integers(0, 5))
    center = float(rng.uniform(-math.pi, math.pi))
    if kind == 0:
        return center, math.pi, math.pi
    if kind == 1:
        return math.pi - float(rng.uniform(0.0, 0.1)), *rng.uniform(0.05, 0.6, 2).tolist()
    if kind == 2:
        return center, *rng.uniform(0.0, 0.02, 2).tolist()
    if kind == 3:
        return center, *rng.uniform(1.2, 2.5, 2).tolist()
    return center, *rng.uniform(0.0, 0.6, 2).tolist()


def random_terrain(rng: np.random.Generator) -> TerrainStats:
    """Terrain statistics, each field zero now and then (the reproducers' terrains among them)."""
    values = [
        rng.uniform(0.0, 0.5),  # translation_loss
        rng.uniform(0.0, 0.3),  # translation_inertial_loss
        rng.uniform(0.0, 0.3),  # translation_sd
        rng.uniform(0.0, 1.0),  # drift
        rng.uniform(0.0, 0.6),  # rotation_loss
        rng.uniform(0.0, 0.3),  # rotation_sd
        rng.uniform(0.0, 0.3),  # skitter
        rng.uniform(0.0, 0.2),  # skitter_sd
    ]
    return TerrainStats(*(0.0 if rng.uniform() < 0.3 else float(value) for value in values))


def random_commands(rng: np.random.Generator, count: int) -> list[float]:
    """``count`` (turn, run) commands, flat: zero turns, zero runs, half-turns and tiny steps."""
    values: list[float] = []
    for _ in range(count):
        turn = float(rng.choice([0.0, math.pi, -math.pi, rng.uniform(-4.0, 4.0), rng.uniform(-1e-3, 1e-3)]))
        run = float(rng.choice([0.0, rng.uniform(0.0, 10.0), rng.uniform(0.0, 0.02)]))
        values += (turn, run)
    return values


def contains(outer: Array, points: Array, tolerance: float) -> bool:
    """Whether every point lies in the convex hull of ``outer`` (within ``tolerance`` metres).

    The hull, not ``outer``'s own edges: a kernel may keep two vertices a rounding step
    apart, and the edge between them points anywhere (at 2e4 m, an edge of 3.6e-12 m cut
    0.26 m into a polygon that both kernels gave bit for bit).
    """
    return bool(np.all(ConvexPolygon.from_points(outer).contains(points, tolerance=tolerance)))


def scale_of(*polygons: Array) -> float:
    """1 plus the largest coordinate: the size rounding errors scale with."""
    return 1.0 + max(float(np.abs(polygon).max()) for polygon in polygons)
