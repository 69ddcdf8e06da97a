"""The camera: intrinsics, mount, projection, and pixels turned into bounded observations."""

from aura_ums.camera._model import (
    NEAR_PLANE,
    Camera,
    CameraIntrinsics,
    CameraMount,
    distort,
    robot_from_camera_rotation,
)

__all__ = [
    "NEAR_PLANE",
    "Camera",
    "CameraIntrinsics",
    "CameraMount",
    "distort",
    "robot_from_camera_rotation",
]
