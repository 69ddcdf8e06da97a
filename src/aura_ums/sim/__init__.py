"""The simulator: the true robot, the synthetic camera and scenario files.

:class:`SimulatedRobot` moves as the terrain model of the meadows it crosses says;
:class:`SyntheticCamera` renders grayscale images of a :class:`Scene` (built from a
meadow map's landmarks) from the robot's true pose; :class:`Scenario` reads a TOML file
naming a map, a terrain table, a camera, a start and a route; :func:`run_scenario` drives a
scenario through the closed loop (pilot, schemas, Expecter, perception, buffer, manager)
and returns a :class:`RunResult`.
"""

from aura_ums.sim._loop import (
    FrameRecord,
    LoopState,
    PerceptionMode,
    RunResult,
    check_render_consistency,
    run_scenario,
    summarize_runs,
)
from aura_ums.sim._render import SyntheticCamera
from aura_ums.sim._robot import SimulatedRobot
from aura_ums.sim._scenario import (
    RenderSettings,
    Scenario,
    SimulatedFrame,
    StartState,
    waypoints_array,
)
from aura_ums.sim._scene import (
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
    "Building",
    "FrameRecord",
    "GroundPatch",
    "GroundStripe",
    "LoopState",
    "PerceptionMode",
    "Pole",
    "RenderSettings",
    "RunResult",
    "Scenario",
    "Scene",
    "SimulatedFrame",
    "SimulatedRobot",
    "StartState",
    "SyntheticCamera",
    "check_render_consistency",
    "ground_texture",
    "landmark_points",
    "random_clutter",
    "run_scenario",
    "summarize_runs",
    "waypoints_array",
]
