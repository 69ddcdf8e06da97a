"""The observers: the camera's bounds on what pixels measure, attached to the landmark seen."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

import aura_ums
from aura_ums.camera import (
    CalibrationBounds,
    Camera,
    CameraIntrinsics,
    CameraMount,
    bound_ground_line,
    bound_point,
    bound_vertical_line,
)
from aura_ums.errors import InputError
from aura_ums.expecter import observe_ground_line, observe_point, observe_vertical_line
from aura_ums.geometry import Pose
from aura_ums.uncertainty import (
    BearingObservation,
    GroundLineLandmark,
    GroundLineObservation,
    PointLandmark,
    RangeBearingObservation,
    VerticalLineLandmark,
)

CAMERA = Camera(
    CameraIntrinsics(500.0, 500.0, 320.0, 240.0, 640, 480, distortion=(-0.1, 0.02, 0.0, 0.0, 0.0)),
    CameraMount(1.2, forward=0.4, left=0.1, pan=0.2, tilt=0.15),
)
BOUNDS = CalibrationBounds(fx=3.0, fy=3.0, cx=2.0, cy=2.0, pan=0.01, tilt=0.01, height=0.02)
POLE = VerticalLineLandmark("pole", 10.0, 0.0, 0.0, 3.0)
CORNER = PointLandmark("corner", 10.0, 0.0, 0.0)
EDGE = GroundLineLandmark("edge", (0.0, -2.0), (20.0, -2.0))


def ground_pixels(rng: np.random.Generator, count: int) -> np.ndarray:
    """``count`` random pixels well below the horizon (which is near v = 164 for this camera)."""
    return np.column_stack([rng.uniform(40.0, 600.0, count), rng.uniform(260.0, 470.0, count)])


def test_each_observation_is_the_cameras_bound_on_the_landmark_seen(rng: np.random.Generator) -> None:
    pixels = ground_pixels(rng, 60)
    for k in range(0, len(pixels) - 1, 2):
        time, error = float(rng.uniform(0.0, 100.0)), float(rng.uniform(0.0, 1.5))
        pixel, segment = pixels[k], np.concatenate([pixels[k], pixels[k + 1]])
        bearing = observe_vertical_line(CAMERA, POLE, pixel, time=time, pixel_error=error, bounds=BOUNDS)
        assert bearing == BearingObservation(
            "pole",
            time,
            *bound_vertical_line(CAMERA, pixel, pixel_error=error, bounds=BOUNDS),
            CAMERA.mount.sensor_offset,
        )
        point = observe_point(
            CAMERA, CORNER, pixel, time=time, pixel_error=error, bounds=BOUNDS, max_range=50.0
        )
        assert point == RangeBearingObservation(
            "corner",
            time,
            *bound_point(CAMERA, pixel, 0.0, pixel_error=error, bounds=BOUNDS, max_range=50.0),
            CAMERA.mount.sensor_offset,
        )
        line = observe_ground_line(
            CAMERA, EDGE, segment, expected_angle=0.3, time=time, pixel_error=error, bounds=BOUNDS
        )
        assert line == GroundLineObservation(
            "edge",
            time,
            *bound_ground_line(CAMERA, segment, expected_angle=0.3, pixel_error=error, bounds=BOUNDS),
            CAMERA.mount.sensor_offset,
        )


def test_the_point_landmarks_height_is_the_plane_of_the_range() -> None:
    lamp = PointLandmark("lamp", 10.0, 0.0, 3.0)
    pixel = CAMERA.project(Pose(0.0, 0.0, 0.0), [(10.0, 0.0, 3.0)])[0]
    seen = observe_point(CAMERA, lamp, pixel, time=0.0, pixel_error=0.0)
    assert seen.range_min == pytest.approx(math.hypot(10.0 - 0.4, 0.1), abs=1e-8)
    assert (seen.bearing, seen.bearing_error, seen.range_min, seen.range_max) == bound_point(
        CAMERA, pixel, 3.0, pixel_error=0.0
    )


def test_the_observers_are_the_top_level_names() -> None:
    assert aura_ums.observe_vertical_line is observe_vertical_line
    assert aura_ums.observe_point is observe_point
    assert aura_ums.observe_ground_line is observe_ground_line


WRONG_POLE: Any = POLE
WRONG_CORNER: Any = CORNER
WRONG_CAMERA: Any = "camera"
WRONG_TIME: Any = "now"
PIXEL = (320.0, 300.0)
SEGMENT = (100.0, 400.0, 200.0, 300.0)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (
            lambda: observe_vertical_line(CAMERA, WRONG_CORNER, PIXEL, time=0.0),
            "landmark: expected VerticalLineLandmark, got PointLandmark",
        ),
        (
            lambda: observe_point(CAMERA, WRONG_POLE, PIXEL, time=0.0),
            "landmark: expected PointLandmark, got VerticalLineLandmark",
        ),
        (
            lambda: observe_ground_line(CAMERA, WRONG_POLE, SEGMENT, expected_angle=0.0, time=0.0),
            "landmark: expected GroundLineLandmark, got VerticalLineLandmark",
        ),
        (lambda: observe_vertical_line(CAMERA, POLE, PIXEL, time=math.inf), "time: expected a finite number"),
        (lambda: observe_point(CAMERA, CORNER, PIXEL, time=math.nan), "time: expected a finite number"),
        (
            lambda: observe_ground_line(CAMERA, EDGE, SEGMENT, expected_angle=0.0, time=WRONG_TIME),
            "time: expected a finite number",
        ),
        (
            lambda: observe_vertical_line(WRONG_CAMERA, POLE, PIXEL, time=0.0),
            "camera: expected Camera, got str",
        ),
        (
            lambda: observe_point(CAMERA, CORNER, (320.0, 100.0), time=0.0),
            "pixel: expected a pixel below the horizon",
        ),
        (
            lambda: observe_ground_line(CAMERA, EDGE, (1.0, 2.0, 3.0), expected_angle=0.0, time=0.0),
            r"segment: expected \(u1, v1, u2, v2\)",
        ),
    ],
)
def test_bad_input_is_refused_naming_the_argument(call: object, match: str) -> None:
    assert callable(call)
    with pytest.raises(InputError, match=match):
        call()
