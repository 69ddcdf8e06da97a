"""The compiled kernels, one wrapper per concept, each with its numpy reference (private).

Each kernel has exactly two implementations: a numpy reference, the specification, and a
C one (``*.c`` here, one extension module ``aura_ums._native._kernels``) that repeats it
operation for operation for speed. This is the one place that picks between them, once,
when aura-ums is imported: the C one when the extension was built, unless the environment
sets ``AURA_UMS_NATIVE=0``; the numpy reference otherwise (:data:`NATIVE`).

Only the layer that owns a kernel calls it, as ``_native.<kernel>``: ``uncertainty`` the
growth, the reductions and the slices' kernels, ``expecter`` its points, ``schemas`` the
polygon distance, ``logs`` the numeric CSV rows. This package imports nothing of aura-ums
but ``geometry`` (and ``_files``, whose CSV reader is a kernel's reference).
"""

import os

from aura_ums._native import _csv, _distance, _expecter, _growth, _reduce, _slices
from aura_ums._native._expecter import ExpectedPoints
from aura_ums._native._extension import BUILT, points_view
from aura_ums._native._growth import Grown, MotionBounds, MotionModel, motion_bounds
from aura_ums._native._reduce import (
    CONE_PIECE,
    SECTOR_PIECE,
    SECTOR_ROW,
    TOLERANCE,
    ConeKernel,
    EmptyReason,
    RawReduction,
    ReducedSectors,
    StripKernel,
    arc_parts,
    cap_inside,
)
from aura_ums._native._slices import (
    ANGLE_SLACK,
    Distributed,
    GrownSlices,
    ReducedSlices,
    clamp_into,
    home_slice,
    narrowed,
    summary_wedge,
)

#: Whether the kernels run compiled: the extension was built, and ``AURA_UMS_NATIVE=0`` was
#: not set when aura-ums was imported.
NATIVE = BUILT and os.environ.get("AURA_UMS_NATIVE", "").strip() != "0"

grow_commands = _growth.grow_commands_compiled if NATIVE else _growth.grow_commands_reference
reduce_cone: ConeKernel = _reduce.reduce_cone_compiled if NATIVE else _reduce.reduce_cone_reference
reduce_strip: StripKernel = _reduce.reduce_strip_compiled if NATIVE else _reduce.reduce_strip_reference
reduce_sectors = _reduce.reduce_sectors_compiled if NATIVE else _reduce.reduce_sectors_reference
expecter_points = _expecter.expecter_points_compiled if NATIVE else _expecter.expecter_points_reference
polygon_distance = _distance.polygon_distance_compiled if NATIVE else _distance.polygon_distance_reference
point_in_solid_convex = (
    _distance.point_in_solid_convex_compiled if NATIVE else _distance.point_in_solid_convex_reference
)
merge_groups = _slices.merge_groups_compiled if NATIVE else _slices.merge_groups_reference
distribute_slices = _slices.distribute_slices_compiled if NATIVE else _slices.distribute_slices_reference
grow_slices = _slices.grow_slices_compiled if NATIVE else _slices.grow_slices_reference
reduce_cone_slices = _slices.reduce_cone_slices_compiled if NATIVE else _slices.reduce_cone_slices_reference
reduce_strip_slices = (
    _slices.reduce_strip_slices_compiled if NATIVE else _slices.reduce_strip_slices_reference
)
parse_float_rows = _csv.parse_float_rows_compiled if NATIVE else _csv.parse_float_rows_reference

__all__ = [
    "ANGLE_SLACK",
    "BUILT",
    "CONE_PIECE",
    "NATIVE",
    "SECTOR_PIECE",
    "SECTOR_ROW",
    "TOLERANCE",
    "Distributed",
    "EmptyReason",
    "ExpectedPoints",
    "Grown",
    "GrownSlices",
    "MotionBounds",
    "MotionModel",
    "RawReduction",
    "ReducedSectors",
    "ReducedSlices",
    "arc_parts",
    "cap_inside",
    "clamp_into",
    "distribute_slices",
    "expecter_points",
    "grow_commands",
    "grow_slices",
    "home_slice",
    "merge_groups",
    "motion_bounds",
    "narrowed",
    "parse_float_rows",
    "point_in_solid_convex",
    "points_view",
    "polygon_distance",
    "reduce_cone",
    "reduce_cone_slices",
    "reduce_sectors",
    "reduce_strip",
    "reduce_strip_slices",
    "summary_wedge",
]
