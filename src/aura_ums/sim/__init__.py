"""The simulator: the true robot, the synthetic camera and scenario files.

:class:`SimulatedRobot` moves as the terrain model of the meadows it crosses says;
:class:`SyntheticCamera` renders grayscale images of a :class:`Scene` (built from a
meadow map's landmarks) from the robot's true pose; :class:`Scenario` reads a TOML file
naming a map, a terrain table, a camera, a start and a route.
"""

from aura_ums.sim._render import CLIP_NEAR, TEXTURE_FADE, SyntheticCamera, fill_polygon
from aura_ums.sim._robot import SimulatedRobot
from aura_ums.sim._scenario import (
    LostLimits,
    RenderSettings,
    Scenario,
    SimulatedFrame,
    StartState,
    waypoints_array,
)
from aura_ums.sim._scene import (
    CORNER_MATCH_DISTANCE,
    DEFAULT_GROUND_SHADE,
    TERRAIN_SHADES,
    Building,
    GroundPatch,
    GroundStripe,
    Pole,
    Scene,
    ground_texture,
    landmark_points,
    random_clutter,
)

__all__ = [
    "CLIP_NEAR",
    "CORNER_MATCH_DISTANCE",
    "DEFAULT_GROUND_SHADE",
    "TERRAIN_SHADES",
    "TEXTURE_FADE",
    "Building",
    "GroundPatch",
    "GroundStripe",
    "LostLimits",
    "Pole",
    "RenderSettings",
    "Scenario",
    "Scene",
    "SimulatedFrame",
    "SimulatedRobot",
    "StartState",
    "SyntheticCamera",
    "fill_polygon",
    "ground_texture",
    "landmark_points",
    "random_clutter",
    "waypoints_array",
]
