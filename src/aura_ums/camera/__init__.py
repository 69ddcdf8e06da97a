"""The camera: intrinsics, mount, projection, and pixels turned into bounded observations."""

from aura_ums.camera._io import (
    camera_to_toml,
    load_calibration_bounds,
    load_camera,
    load_opencv_calibration,
)
from aura_ums.camera._model import (
    NEAR_PLANE,
    Camera,
    CameraIntrinsics,
    CameraMount,
    distort,
    robot_from_camera_rotation,
)
from aura_ums.camera._observe import (
    GROUND_LINE_SPLITS,
    SAFETY_ABSOLUTE,
    SAFETY_RELATIVE,
    UNDISTORT_ITERATIONS,
    UNDISTORT_TOLERANCE,
    CalibrationBounds,
    observe_ground_line,
    observe_point,
    observe_vertical_line,
    undistort_points,
)

__all__ = [
    "GROUND_LINE_SPLITS",
    "NEAR_PLANE",
    "SAFETY_ABSOLUTE",
    "SAFETY_RELATIVE",
    "UNDISTORT_ITERATIONS",
    "UNDISTORT_TOLERANCE",
    "CalibrationBounds",
    "Camera",
    "CameraIntrinsics",
    "CameraMount",
    "camera_to_toml",
    "distort",
    "load_calibration_bounds",
    "load_camera",
    "load_opencv_calibration",
    "observe_ground_line",
    "observe_point",
    "observe_vertical_line",
    "robot_from_camera_rotation",
    "undistort_points",
]
