"""Planar geometry: poses, compass wedges, convex polygons and the convex operations the rest needs.

This package imports nothing else of aura-ums but its validation and errors.
"""

from aura_ums.geometry._angles import angle_difference, wrap_angle
from aura_ums.geometry._arcs import Arc, intersect_arcs, nearest_on_polygon, subtended_arc
from aura_ums.geometry._convex import (
    checks_every_edge,
    clip_halfplane,
    convex_hull,
    cross2,
    edge_distances,
    minkowski_sum,
    outer_annular_sector,
    outer_arc,
    outer_disk,
    points_in_convex,
    polygon_area,
    simplify_outer,
)
from aura_ums.geometry._polygon import POSITION_TOLERANCE, ConvexPolygon, regular_polygon
from aura_ums.geometry._pose import Pose
from aura_ums.geometry._wedge import HeadingWedge, wedges_contain
from aura_ums.geometry._window import UNBOUNDED_PIXELS, ImageWindow

__all__ = [
    "POSITION_TOLERANCE",
    "UNBOUNDED_PIXELS",
    "Arc",
    "ConvexPolygon",
    "HeadingWedge",
    "ImageWindow",
    "Pose",
    "angle_difference",
    "checks_every_edge",
    "clip_halfplane",
    "convex_hull",
    "cross2",
    "edge_distances",
    "intersect_arcs",
    "minkowski_sum",
    "nearest_on_polygon",
    "outer_annular_sector",
    "outer_arc",
    "outer_disk",
    "points_in_convex",
    "polygon_area",
    "regular_polygon",
    "simplify_outer",
    "subtended_arc",
    "wedges_contain",
    "wrap_angle",
]
