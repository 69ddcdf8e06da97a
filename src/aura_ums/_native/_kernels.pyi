from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray
from typing_extensions import Buffer

# Vertices: a C-contiguous (n, 2) float64 buffer, usually an array.
Vertices = NDArray[np.float64] | Buffer
# Items: a C-contiguous 1-D float64 (headings) or int64 (counts, sources) buffer.
Items = NDArray[np.float64] | NDArray[np.int64] | Buffer

ARC_STEP: float
TINY_ANGLE: float
PARALLEL_EPS: float
NOISE_EDGE: float
FARTHEST_MERGE: float
EXTENDABLE: float
SUPPORT_MARGIN: float
SAME_POINT: float
MERGE_EPS: float
COLLINEAR_EPS: float
TOLERANCE: float
TANGENT_STEP: float
FULL_DISK_SIDES: int
SKITTER_SIDES: int
SENSOR_ARC_SIDES: int
NO_POSITION: int
NO_SENSOR_POSITION: int
NO_BEARING_HEADING: int
NO_LINE_HEADING: int
NO_OFFSET_POSITION: int

def grow_commands(
    vertices: Vertices,
    center_x: float,
    center_y: float,
    wedge_center: float,
    wedge_cw: float,
    wedge_ccw: float,
    rotation_loss: float,
    rotation_sd: float,
    translation_loss: float,
    translation_sd: float,
    translation_inertial_loss: float,
    drift: float,
    skitter: float,
    skitter_sd: float,
    sigmas: float,
    commands: Sequence[float],
    max_vertices: int,
    /,
) -> tuple[bytes, float, float, float, float, float]: ...
def reduce_cone(
    vertices: Vertices,
    center_x: float,
    center_y: float,
    wedge_center: float,
    wedge_cw: float,
    wedge_ccw: float,
    forward: float,
    left: float,
    landmark_x: float,
    landmark_y: float,
    widen: float,
    bearing: float,
    bearing_error: float,
    range_min: float,
    range_max: float,
    piece: float,
    max_vertices: int,
    /,
) -> tuple[bytes, float, float, float, float, float, float] | int: ...
def reduce_strip(
    vertices: Vertices,
    center_x: float,
    center_y: float,
    wedge_center: float,
    wedge_cw: float,
    wedge_ccw: float,
    forward: float,
    left: float,
    start_x: float,
    start_y: float,
    end_x: float,
    end_y: float,
    position_uncertainty: float,
    offset: float,
    offset_error: float,
    angle: float,
    angle_error: float,
    max_vertices: int,
    /,
) -> tuple[bytes, float, float, float, float, float, float] | int: ...
def expecter_points(
    vertices: Vertices,
    base_count: int,
    disk_sides: int,
    full_circle: int,
    level_count: int,
    base_ax: float,
    base_ay: float,
    base_bx: float,
    base_by: float,
    radius: float,
    heading_lo: float,
    heading_width: float,
    arc_step: float,
    r00: float,
    r01: float,
    r02: float,
    r10: float,
    r11: float,
    r12: float,
    r20: float,
    r21: float,
    r22: float,
    forward: float,
    left: float,
    dz_lo: float,
    dz_hi: float,
    cut_plane: float,
    /,
) -> tuple[bytes, float, float, float, float] | None: ...
def reduce_sectors(
    vertices: Vertices,
    center_x: float,
    center_y: float,
    lo: float,
    step: float,
    count: int,
    half: float,
    arguments: Sequence[float],
    max_vertices: int,
    /,
) -> tuple[bytes, bytes, bytes, bytes]: ...
def polygon_distance(vertices: Vertices, ax: float, ay: float, bx: float, by: float, /) -> float: ...
def point_in_solid_convex(vertices: Vertices, x: float, y: float, tolerance: float, /) -> bool: ...
def merge_groups(points: Vertices, counts: Sequence[int], max_vertices: int, /) -> tuple[bytes, ...]: ...
def distribute_slices(
    points: Vertices,
    counts: Items,
    starts: Items,
    stops: Items,
    sources: Items,
    cells: int,
    max_vertices: int,
    max_slices: int,
    heading: float,
    /,
) -> tuple[bytes, bytes, bytes, bytes, bytes, float, float, float]: ...
def grow_slices(
    points: Vertices,
    counts: Items,
    lo: Items,
    hi: Items,
    center_x: float,
    center_y: float,
    heading: float,
    rotation_loss: float,
    rotation_sd: float,
    translation_loss: float,
    translation_sd: float,
    translation_inertial_loss: float,
    drift: float,
    skitter: float,
    skitter_sd: float,
    sigmas: float,
    commands: Sequence[float],
    max_vertices: int,
    /,
) -> tuple[bytes, bytes, bytes, bytes, float, float, float]: ...
def reduce_cone_slices(
    points: Vertices,
    counts: Items,
    lo: Items,
    hi: Items,
    center_x: float,
    center_y: float,
    heading: float,
    forward: float,
    left: float,
    landmark_x: float,
    landmark_y: float,
    widen: float,
    bearing: float,
    bearing_error: float,
    range_min: float,
    range_max: float,
    piece: float,
    max_vertices: int,
    /,
) -> tuple[bytes, bytes, bytes, bytes, float, float, float, float, float] | int: ...
def reduce_strip_slices(
    points: Vertices,
    counts: Items,
    lo: Items,
    hi: Items,
    center_x: float,
    center_y: float,
    heading: float,
    forward: float,
    left: float,
    start_x: float,
    start_y: float,
    end_x: float,
    end_y: float,
    position_uncertainty: float,
    offset: float,
    offset_error: float,
    angle: float,
    angle_error: float,
    max_vertices: int,
    /,
) -> tuple[bytes, bytes, bytes, bytes, float, float, float, float, float] | int: ...
def parse_float_rows(data: Buffer, rows: int, columns: int, /) -> bytearray | None: ...
