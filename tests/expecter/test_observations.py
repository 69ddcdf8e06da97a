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
    distort,
    fold_radius,
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
        (
            lambda: observe_ground_line(
                CAMERA, EDGE, SEGMENT, expected_angle=0.0, time=0.0, pixel_error=1e300
            ),
            r"^pixel_error: expected a number in \[0, 100000\] px, got 1e\+300$",
        ),
        (
            lambda: observe_point(CAMERA, CORNER, PIXEL, time=0.0, pixel_error=1e6),
            r"^pixel_error: expected a number in \[0, 100000\] px, got 1000000\.0$",
        ),
    ],
)
def test_bad_input_is_refused_naming_the_argument(call: object, match: str) -> None:
    assert callable(call)
    with pytest.raises(InputError, match=match):
        call()


def _angle_off(truth: float, centre: float) -> float:
    """|truth - centre| on the circle, radians."""
    return abs((truth - centre + math.pi) % (2.0 * math.pi) - math.pi)


def test_observers_hold_the_truth_of_points_within_and_beyond_the_lens_fold() -> None:
    # Strong barrel lenses on a wide image (the image's edges lie beyond the image of the
    # fold): ground points up to 80 degrees off the optical axis, many beyond the fold, where
    # the distortion polynomial used to put them on pixels of nearer rays, and the observers
    # then bounded the nearer ray, excluding the truth (up to 14 m off a ground line's offset).
    rng = np.random.default_rng(45)
    bounds = CalibrationBounds(fx=3.0, fy=3.0, cx=2.0, cy=2.0, pan=0.005, tilt=0.005, height=0.02)
    checked, folded_into_the_image = [0, 0, 0], 0
    for trial in range(600):
        distortion = (
            float(rng.uniform(-0.3, -0.1)),
            float(rng.uniform(-0.05, 0.01)),
            float(rng.uniform(-0.003, 0.003)),
            float(rng.uniform(-0.003, 0.003)),
            0.0,
        )
        cx, cy = 320.0 + float(rng.uniform(-20.0, 20.0)), 240.0 + float(rng.uniform(-20.0, 20.0))
        height, left = float(rng.uniform(0.5, 2.0)), float(rng.choice([0.0, -0.2]))
        pan, tilt = float(rng.uniform(-0.5, 0.5)), float(rng.uniform(-0.1, 0.3))
        camera = Camera(
            CameraIntrinsics(300.0, 300.0, cx, cy, 640, 480, distortion),
            CameraMount(height, 0.0, left, pan, tilt),
        )
        within = bounds if trial % 2 else None
        move = rng.uniform(-1.0, 1.0, 7) if within is not None else np.zeros(7)
        true_camera = Camera(
            CameraIntrinsics(
                300.0 + 3.0 * move[0],
                300.0 + 3.0 * move[1],
                cx + 2.0 * move[2],
                cy + 2.0 * move[3],
                640,
                480,
                distortion,
            ),
            CameraMount(height + 0.02 * move[4], 0.0, left, pan + 0.005 * move[5], tilt + 0.005 * move[6]),
        )
        pixel_error = float(rng.choice([0.0, 0.5, 1.0]))
        heading = float(rng.uniform(-math.pi, math.pi))
        pose = Pose(0.0, 0.0, heading)
        azimuth = heading + pan + float(rng.uniform(-1.4, 1.4))
        distance = math.exp(float(rng.uniform(math.log(0.5), math.log(30.0))))
        ground = np.array([distance * math.cos(azimuth), distance * math.sin(azimuth)])
        direction = rng.normal(size=2)
        direction /= np.linalg.norm(direction)
        second = ground + float(rng.uniform(1.0, 3.0)) * direction
        points = [(*ground, 0.0), (*second, 0.0)]
        frame = true_camera.to_camera_frame(pose.as_array(), points)[0]
        x, y = frame[:, 0] / frame[:, 2], frame[:, 1] / frame[:, 2]
        beyond = (frame[:, 2] > 0.0) & (np.hypot(x, y) > fold_radius(distortion))
        if bool(beyond[0]):
            u, v = distort(x[:1], y[:1], distortion)
            folded_into_the_image += bool(
                0.0 <= 297.0 * u[0] + cx <= 639.0 and 0.0 <= 300.0 * v[0] + cy <= 479.0
            )
        pixels = true_camera.project(pose, points)
        assert not np.any(np.isfinite(pixels[beyond])), "a ray beyond the fold was imaged"
        pixels += pixel_error * rng.uniform(-1.0, 1.0, (2, 2))
        seen = np.isfinite(pixels).all(axis=1) & np.all((pixels >= 0.0) & (pixels <= [639.0, 479.0]), axis=1)
        kind = trial % 3
        if not seen[0] or (kind == 2 and (not seen[1] or np.hypot(*(pixels[1] - pixels[0])) < 5.0)):
            continue
        sensor = (left * -math.sin(heading), left * math.cos(heading))
        bearing = math.atan2(ground[1] - sensor[1], ground[0] - sensor[0]) - heading
        try:
            if kind == 0:
                pole = VerticalLineLandmark("pole", float(ground[0]), float(ground[1]), 0.0, 3.0)
                b = observe_vertical_line(
                    camera, pole, pixels[0], time=0.0, pixel_error=pixel_error, bounds=within
                )
                assert _angle_off(bearing, b.bearing) <= b.bearing_error + 1e-9, trial
            elif kind == 1:
                corner = PointLandmark("corner", float(ground[0]), float(ground[1]), 0.0)
                rb = observe_point(
                    camera,
                    corner,
                    pixels[0],
                    time=0.0,
                    pixel_error=pixel_error,
                    bounds=within,
                    max_range=100.0,
                )
                assert _angle_off(bearing, rb.bearing) <= rb.bearing_error + 1e-9, trial
                assert rb.range_min - 1e-9 <= math.hypot(*(ground - sensor)) <= rb.range_max + 1e-9, trial
            else:
                edge = GroundLineLandmark("edge", ground - 20.0 * direction, ground + 20.0 * direction)
                angle = math.atan2(direction[1], direction[0]) - heading
                hint = angle + float(rng.uniform(-0.5, 0.5))
                line = observe_ground_line(
                    camera,
                    edge,
                    pixels.reshape(-1),
                    expected_angle=hint,
                    time=0.0,
                    pixel_error=pixel_error,
                    bounds=within,
                )
                normal = np.array([-direction[1], direction[0]])
                offset = float(normal @ (np.array(sensor) - edge.start))
                assert _angle_off(angle, line.angle) <= line.angle_error + 1e-9, trial
                assert abs(offset - line.offset) <= line.offset_error + 1e-9, trial
        except InputError:
            continue  # refused (the horizon, a box reaching the fold, a short segment): no observation
        checked[kind] += 1
    assert min(checked) >= 40, checked
    assert folded_into_the_image >= 30, folded_into_the_image
