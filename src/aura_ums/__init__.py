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

from __future__ import annotations

import importlib

# typing.TYPE_CHECKING without importing typing (with re and enum, a few milliseconds): the
# console script reaches the command line's Ctrl-C handler that much sooner. Type checkers
# take any TYPE_CHECKING as true.
TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any

    from aura_ums._metrics import Metrics
    from aura_ums.camera import (
        CalibrationBounds,
        Camera,
        CameraIntrinsics,
        CameraMount,
        load_calibration_bounds,
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
    "load_calibration_bounds",
    "load_camera",
    "load_opencv_calibration",
    "observe_ground_line",
    "observe_point",
    "observe_vertical_line",
    "plan_route",
    "sample_world",
    "wrap_angle",
]

#: Where each name of ``__all__`` is defined, imported on first use (PEP 562): ``import
#: aura_ums`` loads neither numpy nor the kernels, so that the command line is ready for a
#: Ctrl-C before it loads them, and ``from aura_ums.geometry import ...`` loads geometry
#: alone. ``tests/test_public_api.py`` checks it against the imports above (for type checkers).
_HOMES: dict[str, str] = {
    "Metrics": "aura_ums._metrics",
    "CalibrationBounds": "aura_ums.camera",
    "Camera": "aura_ums.camera",
    "CameraIntrinsics": "aura_ums.camera",
    "CameraMount": "aura_ums.camera",
    "load_calibration_bounds": "aura_ums.camera",
    "load_camera": "aura_ums.camera",
    "load_opencv_calibration": "aura_ums.camera",
    "AuraUmsError": "aura_ums.errors",
    "FileFormatError": "aura_ums.errors",
    "InputError": "aura_ums.errors",
    "MissingDependencyError": "aura_ums.errors",
    "UnknownLandmarkError": "aura_ums.errors",
    "UnknownTerrainError": "aura_ums.errors",
    "Expecter": "aura_ums.expecter",
    "ImageWindow": "aura_ums.expecter",
    "PerceptualStrategy": "aura_ums.expecter",
    "observe_ground_line": "aura_ums.expecter",
    "observe_point": "aura_ums.expecter",
    "observe_vertical_line": "aura_ums.expecter",
    "ConvexPolygon": "aura_ums.geometry",
    "HeadingWedge": "aura_ums.geometry",
    "wrap_angle": "aura_ums.geometry",
    "Blackboard": "aura_ums.manager",
    "IdentifiedLandmarkBuffer": "aura_ums.manager",
    "ManagerSettings": "aura_ums.manager",
    "MapProfile": "aura_ums.manager",
    "PositionReport": "aura_ums.manager",
    "UncertaintyMapManager": "aura_ums.manager",
    "FastLineFinder": "aura_ums.perception",
    "MoravecOperator": "aura_ums.perception",
    "RegionSegmenter": "aura_ums.perception",
    "FindLandmarkSchema": "aura_ums.schemas",
    "Frame": "aura_ums.schemas",
    "Pilot": "aura_ums.schemas",
    "SchemaManager": "aura_ums.schemas",
    "SchemaState": "aura_ums.schemas",
    "FOOT": "aura_ums.uncertainty",
    "BearingObservation": "aura_ums.uncertainty",
    "GroundLineLandmark": "aura_ums.uncertainty",
    "GroundLineObservation": "aura_ums.uncertainty",
    "Landmark": "aura_ums.uncertainty",
    "LandmarkClass": "aura_ums.uncertainty",
    "Observation": "aura_ums.uncertainty",
    "PointLandmark": "aura_ums.uncertainty",
    "Pose": "aura_ums.uncertainty",
    "RangeBearingObservation": "aura_ums.uncertainty",
    "Reduction": "aura_ums.uncertainty",
    "SpatialUncertaintyMap": "aura_ums.uncertainty",
    "TerrainStats": "aura_ums.uncertainty",
    "TerrainTable": "aura_ums.uncertainty",
    "TurnAndRun": "aura_ums.uncertainty",
    "VerticalLineLandmark": "aura_ums.uncertainty",
    "LandmarkRecord": "aura_ums.world",
    "Meadow": "aura_ums.world",
    "MeadowMap": "aura_ums.world",
    "ShortTermMemory": "aura_ums.world",
    "plan_route": "aura_ums.world",
    "sample_world": "aura_ums.world",
}


if not TYPE_CHECKING:  # hidden from type checkers, which would take any name as Any

    def __getattr__(name: str) -> Any:
        home = _HOMES.get(name)
        if home is not None:
            value = getattr(importlib.import_module(home), name)
        elif not name.startswith("__") and _find_spec(f"{__name__}.{name}") is not None:
            value = importlib.import_module(f"{__name__}.{name}")  # a subpackage, as after its import
        else:
            raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
        globals()[name] = value
        return value

    def _find_spec(name: str) -> object:
        # importlib.util on first use: it loads contextlib and collections, which the
        # console script would otherwise load before its Ctrl-C handler is in place.
        import importlib.util

        return importlib.util.find_spec(name)

    def __dir__() -> list[str]:
        return sorted({*globals(), *_HOMES})
