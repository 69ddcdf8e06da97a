"""The camera: intrinsics, mount, projection, and pixels turned into bounded measurements.

This package imports nothing else of aura-ums but geometry, validation and errors: it
bounds bearings, ranges and ground lines in the robot frame, and the observers of
:mod:`aura_ums.expecter` (:func:`~aura_ums.expecter.observe_vertical_line` and its kin)
turn them into observations of landmarks.
"""

from aura_ums.camera._io import (
    camera_calibration_file,
    camera_info_intrinsics,
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
    fold_radius,
    robot_from_camera_rotation,
    within_fold,
)
from aura_ums.camera._observe import (
    CalibrationBounds,
    bound_ground_line,
    bound_point,
    bound_vertical_line,
    undistort_points,
)

__all__ = [
    "NEAR_PLANE",
    "CalibrationBounds",
    "Camera",
    "CameraIntrinsics",
    "CameraMount",
    "bound_ground_line",
    "bound_point",
    "bound_vertical_line",
    "camera_calibration_file",
    "camera_info_intrinsics",
    "camera_to_toml",
    "distort",
    "fold_radius",
    "load_calibration_bounds",
    "load_camera",
    "load_opencv_calibration",
    "robot_from_camera_rotation",
    "undistort_points",
    "within_fold",
]
