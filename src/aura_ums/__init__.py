"""aura-ums: guaranteed spatial uncertainty management for a mobile robot.

A convex polygon of where the robot may be and a compass wedge of which way it may
face, grown from turn-and-run commands and terrain statistics (Arkin, AuRA).

Examples
--------
>>> import math
>>> import aura_ums as ums
>>> start = ums.SpatialUncertaintyMap.from_pose(ums.Pose(0, 0, 0), 0.3, math.radians(2))
>>> grown = start.grow(ums.TurnAndRun(math.pi / 4, 30 * ums.FOOT), ums.TerrainTable.default()["concrete"])
>>> grown.contains(grown.most_probable_pose())
True
"""

from aura_ums._metrics import Metrics
from aura_ums.camera import (
    CalibrationBounds,
    Camera,
    CameraIntrinsics,
    CameraMount,
    load_camera,
    load_opencv_calibration,
)
from aura_ums.errors import (
    AuraUmsError,
    FileFormatError,
    InputError,
    MissingDependencyError,
    UnknownLandmarkError,
    UnknownTerrainError,
)
from aura_ums.expecter import (
    Expecter,
    ImageWindow,
    PerceptualStrategy,
    observe_ground_line,
    observe_point,
    observe_vertical_line,
)
from aura_ums.geometry import ConvexPolygon, HeadingWedge, wrap_angle
from aura_ums.manager import (
    Blackboard,
    IdentifiedLandmarkBuffer,
    ManagerSettings,
    MapProfile,
    PositionReport,
    UncertaintyMapManager,
)
from aura_ums.perception import FastLineFinder, MoravecOperator, RegionSegmenter
from aura_ums.schemas import FindLandmarkSchema, Frame, Pilot, SchemaManager, SchemaState
from aura_ums.uncertainty import (
    FOOT,
    BearingObservation,
    GroundLineLandmark,
    GroundLineObservation,
    Landmark,
    LandmarkClass,
    Observation,
    PointLandmark,
    Pose,
    RangeBearingObservation,
    Reduction,
    SpatialUncertaintyMap,
    TerrainStats,
    TerrainTable,
    TurnAndRun,
    VerticalLineLandmark,
)
from aura_ums.world import LandmarkRecord, Meadow, MeadowMap, ShortTermMemory, plan_route, sample_world

__version__ = "0.1.0"

__all__ = [
    "FOOT",
    "AuraUmsError",
    "BearingObservation",
    "Blackboard",
    "CalibrationBounds",
    "Camera",
    "CameraIntrinsics",
    "CameraMount",
    "ConvexPolygon",
    "Expecter",
    "FastLineFinder",
    "FileFormatError",
    "FindLandmarkSchema",
    "Frame",
    "GroundLineLandmark",
    "GroundLineObservation",
    "HeadingWedge",
    "IdentifiedLandmarkBuffer",
    "ImageWindow",
    "InputError",
    "Landmark",
    "LandmarkClass",
    "LandmarkRecord",
    "ManagerSettings",
    "MapProfile",
    "Meadow",
    "MeadowMap",
    "Metrics",
    "MissingDependencyError",
    "MoravecOperator",
    "Observation",
    "PerceptualStrategy",
    "Pilot",
    "PointLandmark",
    "Pose",
    "PositionReport",
    "RangeBearingObservation",
    "Reduction",
    "RegionSegmenter",
    "SchemaManager",
    "SchemaState",
    "ShortTermMemory",
    "SpatialUncertaintyMap",
    "TerrainStats",
    "TerrainTable",
    "TurnAndRun",
    "UncertaintyMapManager",
    "UnknownLandmarkError",
    "UnknownTerrainError",
    "VerticalLineLandmark",
    "__version__",
    "load_camera",
    "load_opencv_calibration",
    "observe_ground_line",
    "observe_point",
    "observe_vertical_line",
    "plan_route",
    "sample_world",
    "wrap_angle",
]
