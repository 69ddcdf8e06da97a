"""The paper's Figure 4 scenario, shared by the figure and the benchmark.

A robot drives east along a path: its map is long along the path (range along the path
is poorly known) and narrow across it (the path edge keeps it centred), with a small
heading wedge. Landmark 1 lies on the path ahead, so the uncertainty runs along the line
of sight and its window is tall; landmark 2 stands beside the path, so the same
uncertainty runs across the line of sight and its window is wide. The disk model (a
circle enclosing the polygon) gives both a large, squarer window.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from aura_ums._validate import integer_at_least
from aura_ums.camera import Camera, CameraIntrinsics, CameraMount
from aura_ums.geometry import ConvexPolygon, HeadingWedge
from aura_ums.uncertainty import PointLandmark, SpatialUncertaintyMap


@dataclass(frozen=True, slots=True)
class Figure4Scenario:
    """Camera, elongated map and the two landmarks of the Figure 4 scenario.

    Examples
    --------
    >>> s = figure4_scenario(vertices=8)
    >>> s.camera.intrinsics.width, s.map.polygon.vertex_count, [lm.symbol for lm in s.landmarks]
    (640, 8, ['manhole cover', 'sign corner'])
    >>> s.map = None                                      # a value: it cannot change
    Traceback (most recent call last):
    ...
    dataclasses.FrozenInstanceError: cannot assign to field 'map'
    """

    camera: Camera
    map: SpatialUncertaintyMap
    landmarks: tuple[PointLandmark, PointLandmark]


def figure4_scenario(vertices: int = 16) -> Figure4Scenario:
    """Return the Figure 4 scenario; ``vertices`` (>= 3) sets the polygon's vertex count.

    Examples
    --------
    >>> s = figure4_scenario()
    >>> s.map.polygon.vertex_count, [lm.id for lm in s.landmarks]
    (16, ['landmark_1', 'landmark_2'])
    >>> figure4_scenario(2)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: vertices: expected an integer >= 3, got 2
    """
    vertices = integer_at_least(vertices, "vertices", 3)
    camera = Camera(
        CameraIntrinsics(400.0, 400.0, 319.5, 239.5, 640, 480),
        CameraMount(height=1.2, forward=0.2, tilt=math.radians(8.0)),
    )
    angles = np.arange(vertices) * (2.0 * math.pi / vertices)
    ellipse = np.column_stack([2.0 * np.cos(angles), 0.15 * np.sin(angles)])
    polygon = ConvexPolygon(ellipse)
    wedge = HeadingWedge(0.0, math.radians(1.0), math.radians(1.0))
    the_map = SpatialUncertaintyMap(polygon, (0.0, 0.0), wedge)
    ahead = PointLandmark("landmark_1", 4.6, 0.0, 0.0, symbol="manhole cover")
    beside = PointLandmark("landmark_2", 12.0, 3.0, 3.0, symbol="sign corner")
    return Figure4Scenario(camera, the_map, (ahead, beside))
