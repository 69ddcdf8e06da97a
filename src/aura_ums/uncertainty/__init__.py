"""The spatial uncertainty map, turn-and-run commands, terrain statistics and growth.

This package imports nothing of aura-ums but geometry, validation and errors.
"""

from aura_ums.geometry import Pose
from aura_ums.uncertainty._checks import (
    ContainmentResult,
    TightnessResult,
    growth_tightness,
    simulate_containment,
)
from aura_ums.uncertainty._growth import MAX_VERTICES as MAX_VERTICES  # not in __all__: the manager's caps
from aura_ums.uncertainty._growth import MotionBounds, motion_bounds
from aura_ums.uncertainty._horizon import Composite, anchor_bounds, grow_from_anchor, intersect_maps
from aura_ums.uncertainty._joint import MIN_SECTOR as MIN_SECTOR  # not in __all__: the manager's range
from aura_ums.uncertainty._joint import reduce_jointly
from aura_ums.uncertainty._landmarks import (
    BearingObservation,
    GroundLineLandmark,
    GroundLineObservation,
    Landmark,
    LandmarkClass,
    Observation,
    PointLandmark,
    RangeBearingObservation,
    VerticalLineLandmark,
)
from aura_ums.uncertainty._map import SpatialUncertaintyMap
from aura_ums.uncertainty._motion import FOOT, TurnAndRun
from aura_ums.uncertainty._reduce import Reduction
from aura_ums.uncertainty._slices import MAX_SLICES as MAX_SLICES  # not in __all__: the manager's caps
from aura_ums.uncertainty._slices import HeadingSlice, cell_count
from aura_ums.uncertainty._terrain import TerrainStats, TerrainTable
from aura_ums.uncertainty._union import union_of_maps, union_of_wedges

__all__ = [
    "FOOT",
    "BearingObservation",
    "Composite",
    "ContainmentResult",
    "GroundLineLandmark",
    "GroundLineObservation",
    "HeadingSlice",
    "Landmark",
    "LandmarkClass",
    "MotionBounds",
    "Observation",
    "PointLandmark",
    "Pose",
    "RangeBearingObservation",
    "Reduction",
    "SpatialUncertaintyMap",
    "TerrainStats",
    "TerrainTable",
    "TightnessResult",
    "TurnAndRun",
    "VerticalLineLandmark",
    "anchor_bounds",
    "cell_count",
    "grow_from_anchor",
    "growth_tightness",
    "intersect_maps",
    "motion_bounds",
    "reduce_jointly",
    "simulate_containment",
    "union_of_maps",
    "union_of_wedges",
]
