"""The world model: long-term memory (the meadow map), short-term memory and the navigator.

Long-term memory (:class:`MeadowMap`) partitions free space into convex meadows, each
with a terrain type and the list of landmarks visible from it; :class:`LandmarkRecord`
holds what the pilot needs to parameterize a find-landmark schema. :func:`plan_route`
finds straight legs through the meadow graph, :func:`commands_for` splits a motion
command by the meadows (terrains) it crosses, and :class:`ShortTermMemory` instantiates
the meadows and candidate landmarks of one leg.

File format (GeoJSON)
---------------------
A meadow map file is a GeoJSON FeatureCollection, editable with QGIS or any GeoJSON tool.
Coordinates are **metres in the world frame** (x east, y north), not longitude and
latitude: no reprojection is done and a ``crs`` member, if any, is ignored. An optional
top-level ``"terrain_table"`` member names a terrain table TOML file (relative to the
GeoJSON file) that the meadows' terrains are checked against.

Meadows are ``Polygon`` features (one ring, convex, either orientation; the ring may
repeat its first vertex, as GeoJSON requires) with properties:

- ``kind``: ``"meadow"``; ``id``: unique string; ``terrain``: terrain name;
- ``landmarks``: list of ids of landmark features visible from the meadow (optional).

Landmarks are ``Point`` features (Class I and II) or ``LineString`` features of two
positions, start and end (Class III), with properties:

- ``kind``: ``"landmark"``; ``id``: unique string (the instance, e.g. ``"lamppost_107"``);
- ``class``: ``"I"`` (vertical line: ``z_bottom``, ``z_top`` in metres), ``"II"``
  (point: ``z`` in metres) or ``"III"`` (ground line);
- ``symbol``: symbolic class (default ``""``); ``position_uncertainty``: metres
  (default 0);
- ``strategy``: ``"line_finder"``, ``"interest_operator"`` or ``"region_segmenter"``, one
  its class supports (:meth:`PerceptualStrategy.for_class`: Class I a line finder or region
  segmenter, Class II an interest operator, Class III a line finder); ``parameters``: object
  of numbers for the strategy, named as :attr:`PerceptualStrategy.parameters` lists (default
  ``{}``);
- ``activation_range`` (m, in (0, 10000]), ``recognition_threshold`` (>= 0),
  ``confirm_frames`` (integer in [1, 10000], default 3).

Properties whose value is ``null`` count as absent (GIS tools write them); any other
property is refused, so that typing mistakes are caught. Ids are unique across all
features. Every error names the file, the feature (index and id) and the property.

Examples
--------
>>> from aura_ums.world import plan_route, sample_world
>>> world = sample_world("paper_sidewalk")
>>> route = plan_route(world, (0.0, 0.0), (12.192, 0.0))
>>> route.meadow_ids
('sidewalk_west', 'sidewalk_middle', 'sidewalk_east')
"""

from aura_ums.world._ltm import LandmarkRecord, Meadow, MeadowMap, PerceptualStrategy
from aura_ums.world._navigator import (
    RUN_TOLERANCE,
    Route,
    RunPiece,
    commands_for,
    grow_through,
    meadows_in_reach,
    outer_terrain,
    plan_route,
    split_run,
)
from aura_ums.world._samples import make_grid_world, sample_world
from aura_ums.world._stm import ShortTermMemory

__all__ = [
    "RUN_TOLERANCE",
    "LandmarkRecord",
    "Meadow",
    "MeadowMap",
    "PerceptualStrategy",
    "Route",
    "RunPiece",
    "ShortTermMemory",
    "commands_for",
    "grow_through",
    "make_grid_world",
    "meadows_in_reach",
    "outer_terrain",
    "plan_route",
    "sample_world",
    "split_run",
]
