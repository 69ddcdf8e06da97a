"""Pixels to bounded bearings, ranges and ground lines: soundness (Monte Carlo, a true camera), errors."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import pytest

from aura_ums.camera import (
    CalibrationBounds,
    Camera,
    CameraIntrinsics,
    CameraMount,
    _observe,
    bound_ground_line,
    bound_point,
    bound_vertical_line,
    undistort_points,
)
from aura_ums.errors import InputError
from aura_ums.geometry import Pose, wrap_angle

CASES = 2000
WIDTH, HEIGHT = 640, 480


# ------------------------------------------------------------------ random scenes


def random_camera(rng: np.random.Generator) -> Camera:
    """A tilted, panned, offset and (mostly) distorted camera."""
    f = rng.uniform(450.0, 900.0)
    distortion = None
    if rng.random() < 0.75:
        distortion = (
            rng.uniform(-0.15, 0.05),
            rng.uniform(-0.02, 0.05),
            rng.uniform(-2e-3, 2e-3),
            rng.uniform(-2e-3, 2e-3),
            rng.uniform(-5e-3, 5e-3),
        )
    intrinsics = CameraIntrinsics(
        f,
        f * rng.uniform(0.98, 1.02),
        WIDTH / 2 + rng.uniform(-20.0, 20.0),
        HEIGHT / 2 + rng.uniform(-20.0, 20.0),
        WIDTH,
        HEIGHT,
        distortion,
    )
    mount = CameraMount(
        height=rng.uniform(0.6, 2.0),
        forward=rng.uniform(-0.5, 0.5),
        left=rng.uniform(-0.3, 0.3),
        pan=rng.uniform(-math.pi, math.pi),
        tilt=rng.uniform(-0.2, 0.6),
    )
    return Camera(intrinsics, mount)


def random_bounds(rng: np.random.Generator) -> CalibrationBounds:
    if rng.random() < 0.1:
        return CalibrationBounds()
    return CalibrationBounds(
        fx=rng.uniform(0.0, 10.0),
        fy=rng.uniform(0.0, 10.0),
        cx=rng.uniform(0.0, 5.0),
        cy=rng.uniform(0.0, 5.0),
        pan=rng.uniform(0.0, 0.02),
        tilt=rng.uniform(0.0, 0.02),
        height=rng.uniform(0.0, 0.05),
    )


def deviation(rng: np.random.Generator, bound: float) -> float:
    """A deviation within +-bound, at an end of the interval one time in two."""
    if rng.random() < 0.5:
        return bound * float(rng.choice([-1.0, 1.0]))
    return bound * rng.uniform(-1.0, 1.0)


def true_camera(nominal: Camera, bounds: CalibrationBounds, rng: np.random.Generator) -> Camera:
    k, m = nominal.intrinsics, nominal.mount
    intrinsics = replace(
        k,
        fx=k.fx + deviation(rng, bounds.fx),
        fy=k.fy + deviation(rng, bounds.fy),
        cx=k.cx + deviation(rng, bounds.cx),
        cy=k.cy + deviation(rng, bounds.cy),
    )
    mount = replace(
        m,
        pan=m.pan + deviation(rng, bounds.pan),
        tilt=m.tilt + deviation(rng, bounds.tilt),
        height=m.height + deviation(rng, bounds.height),
    )
    return Camera(intrinsics, mount)


def perturbed(rng: np.random.Generator, pixel: np.ndarray, error: float) -> np.ndarray | None:
    """The measured pixel: within +-error of the true one in u and v; None when it leaves the image."""
    measured = pixel + np.array([deviation(rng, error), deviation(rng, error)])
    if not (-0.5 <= measured[0] <= WIDTH - 0.5 and -0.5 <= measured[1] <= HEIGHT - 0.5):
        return None
    return np.asarray(measured, dtype=np.float64)


@dataclass(frozen=True)
class Scene:
    nominal: Camera
    bounds: CalibrationBounds
    truth: Camera
    pose: Pose
    pixel_error: float


def random_scene(rng: np.random.Generator) -> Scene:
    nominal = random_camera(rng)
    bounds = random_bounds(rng)
    pose = Pose(rng.uniform(-50, 50), rng.uniform(-50, 50), rng.uniform(-math.pi, math.pi))
    error = 0.0 if rng.random() < 0.1 else rng.uniform(0.0, 2.0)
    return Scene(nominal, bounds, true_camera(nominal, bounds, rng), pose, error)


def ray_world(scene: Scene, pixel: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """Optical centre and ray direction (world) of a pixel seen by the TRUE camera, or None off its model."""
    camera = scene.truth
    normalized = undistort_points(camera.intrinsics, pixel[None, :])[0]
    if not np.all(np.isfinite(normalized)):
        return None
    direction_robot = camera.mount.rotation() @ np.array([normalized[0], normalized[1], 1.0])
    c, s = math.cos(scene.pose.heading), math.sin(scene.pose.heading)
    rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    m = camera.mount
    centre = np.array([scene.pose.x, scene.pose.y, 0.0]) + rotation @ np.array([m.forward, m.left, m.height])
    return centre, rotation @ direction_robot


def true_pixel(scene: Scene, point: np.ndarray) -> np.ndarray | None:
    """The TRUE camera's image of a world point, or None when it is off the distortion model's domain."""
    pixel = scene.truth.project(scene.pose, point[None, :])[0]
    if not np.all(np.isfinite(pixel)):
        return None
    back = ray_world(scene, pixel)
    if back is None:
        return None
    centre, direction = back
    to_point = point - centre
    # principal branch only: the back-projected ray must point at the point
    if np.linalg.norm(np.cross(direction, to_point)) > 1e-6 * np.linalg.norm(direction) * np.linalg.norm(
        to_point
    ):
        return None
    return np.asarray(pixel, dtype=np.float64)


def sensor_xy(scene: Scene) -> np.ndarray:
    c, s = math.cos(scene.pose.heading), math.sin(scene.pose.heading)
    forward, left = scene.truth.mount.sensor_offset
    return np.array([scene.pose.x + c * forward - s * left, scene.pose.y + s * forward + c * left])


def random_image_pixel(rng: np.random.Generator) -> np.ndarray:
    return np.array([rng.uniform(-0.5, WIDTH - 0.5), rng.uniform(-0.5, HEIGHT - 0.5)])


def plane_point(scene: Scene, pixel: np.ndarray, z: float, max_range: float) -> np.ndarray | None:
    ray = ray_world(scene, pixel)
    if ray is None:
        return None
    centre, direction = ray
    if direction[2] * (z - centre[2]) <= 0.0 or abs(direction[2]) < 1e-9:
        return None
    point = centre + direction * (z - centre[2]) / direction[2]
    if math.hypot(*(point[:2] - centre[:2])) > max_range:
        return None
    return np.asarray(point, dtype=np.float64)


# ------------------------------------------------------------------ soundness


@dataclass
class Tally:
    checked: int = 0
    worst_ratio: float = 0.0  # largest |true - stated| / error: <= 1 is sound

    def add(self, deviation: float, error: float) -> None:
        self.worst_ratio = max(self.worst_ratio, abs(deviation) / error if error > 0 else math.inf)


def test_bearing_bound_is_sound(rng: np.random.Generator) -> None:
    tally = Tally()
    while tally.checked < CASES:
        scene = random_scene(rng)
        ray = ray_world(scene, random_image_pixel(rng))
        if ray is None:
            continue
        centre, direction = ray
        point = centre + direction / np.linalg.norm(direction) * rng.uniform(1.0, 40.0)
        if math.hypot(*(point[:2] - centre[:2])) < 0.3:
            continue
        pixel = true_pixel(scene, point)
        measured = None if pixel is None else perturbed(rng, pixel, scene.pixel_error)
        if measured is None:
            continue
        bearing, error = bound_vertical_line(
            scene.nominal, measured, pixel_error=scene.pixel_error, bounds=scene.bounds
        )
        sensor = sensor_xy(scene)
        truth = wrap_angle(math.atan2(point[1] - sensor[1], point[0] - sensor[0]) - scene.pose.heading)
        miss = wrap_angle(truth - bearing)
        assert abs(miss) <= error, (scene, measured, truth, bearing, error)
        tally.add(miss, error)
        tally.checked += 1
    assert tally.worst_ratio <= 1.0


def test_range_bearing_bound_is_sound(rng: np.random.Generator) -> None:
    tally, range_tally = Tally(), Tally()
    refusals: list[str] = []
    while tally.checked < CASES:
        scene = random_scene(rng)
        z = rng.uniform(0.0, 3.0)
        if abs(scene.truth.mount.height - z) < 0.2:
            continue
        point = plane_point(scene, random_image_pixel(rng), z, 60.0)
        if point is None:
            continue
        pixel = true_pixel(scene, point)
        measured = None if pixel is None else perturbed(rng, pixel, scene.pixel_error)
        if measured is None:
            continue
        try:
            bearing, bearing_error, range_min, range_max = bound_point(
                scene.nominal,
                measured,
                z,
                pixel_error=scene.pixel_error,
                bounds=scene.bounds,
                max_range=60.0,
            )
        except InputError as exc:  # the nominal camera puts the pixel above the horizon
            refusals.append(str(exc))
            continue
        sensor = sensor_xy(scene)
        true_bearing = wrap_angle(math.atan2(point[1] - sensor[1], point[0] - sensor[0]) - scene.pose.heading)
        true_range = math.hypot(point[0] - sensor[0], point[1] - sensor[1])
        miss = wrap_angle(true_bearing - bearing)
        assert abs(miss) <= bearing_error, (scene, measured, true_bearing, bearing, bearing_error)
        assert range_min <= true_range <= range_max, (scene, measured, true_range, range_min, range_max)
        centre = 0.5 * (range_min + range_max)
        range_tally.add(true_range - centre, 0.5 * (range_max - range_min))
        tally.add(miss, bearing_error)
        tally.checked += 1
    assert len(refusals) < CASES // 10
    assert all("horizon" in message for message in refusals)
    assert tally.worst_ratio <= 1.0
    assert range_tally.worst_ratio <= 1.0


def test_ground_line_bound_is_sound(rng: np.random.Generator) -> None:
    angle_tally, offset_tally = Tally(), Tally()
    refusals: list[str] = []
    while angle_tally.checked < CASES:
        scene = random_scene(rng)
        a = plane_point(scene, random_image_pixel(rng), 0.0, 30.0)
        b = plane_point(scene, random_image_pixel(rng), 0.0, 30.0)
        if a is None or b is None or np.linalg.norm(b[:2] - a[:2]) < 1.0:
            continue
        pixel_a, pixel_b = true_pixel(scene, a), true_pixel(scene, b)
        if pixel_a is None or pixel_b is None:
            continue
        measured_a, measured_b = (
            perturbed(rng, pixel_a, scene.pixel_error),
            perturbed(rng, pixel_b, scene.pixel_error),
        )
        if measured_a is None or measured_b is None:
            continue
        unit = (b[:2] - a[:2]) / np.linalg.norm(b[:2] - a[:2])
        start, end = (a[:2] - 2 * unit, b[:2] + 2 * unit)
        if rng.random() < 0.5:
            start, end, unit = end, start, -unit
        direction = math.atan2(end[1] - start[1], end[0] - start[0])
        sensor = sensor_xy(scene)
        true_angle = wrap_angle(direction - scene.pose.heading)
        true_offset = float(unit[0] * (sensor[1] - start[1]) - unit[1] * (sensor[0] - start[0]))
        ends = (measured_a, measured_b) if rng.random() < 0.5 else (measured_b, measured_a)
        segment = np.concatenate(ends)
        try:
            offset, offset_error, angle, angle_error = bound_ground_line(
                scene.nominal,
                segment,
                expected_angle=true_angle + rng.uniform(-1.55, 1.55),  # within 90 degrees
                pixel_error=scene.pixel_error,
                bounds=scene.bounds,
            )
        except InputError as exc:  # horizon within the bounds, or too short a segment
            refusals.append(str(exc))
            continue
        miss = wrap_angle(true_angle - angle)
        assert abs(miss) <= angle_error, (scene, segment, true_angle, angle, angle_error)
        assert abs(true_offset - offset) <= offset_error, (scene, segment, true_offset, offset, offset_error)
        angle_tally.add(miss, angle_error)
        offset_tally.add(true_offset - offset, offset_error)
        angle_tally.checked += 1
    assert len(refusals) < CASES // 5
    assert all("horizon" in message or "long enough" in message for message in refusals)
    assert angle_tally.worst_ratio <= 1.0
    assert offset_tally.worst_ratio <= 1.0


# ------------------------------------------------------------------ exactness and tightness

FLAT = Camera(CameraIntrinsics(500.0, 500.0, 320.0, 240.0, 640, 480), CameraMount(1.0, forward=0.4, left=0.1))


def test_exact_calibration_and_pixel_give_the_true_values() -> None:
    tilted = Camera(FLAT.intrinsics, replace(FLAT.mount, tilt=0.2, pan=0.3))
    pose = Pose(0.0, 0.0, 0.0)
    pixel = tilted.project(pose, [(9.0, 4.0, 0.0)])[0]
    bearing, bearing_error, range_min, range_max = bound_point(tilted, pixel, 0.0, pixel_error=0.0)
    assert bearing == pytest.approx(math.atan2(4.0 - 0.1, 9.0 - 0.4), abs=1e-9)
    assert bearing_error < 1e-8
    assert range_min == pytest.approx(math.hypot(8.6, 3.9), abs=1e-8)
    assert range_max - range_min < 1e-8


def test_pan_bound_adds_exactly_to_the_bearing_error() -> None:
    _, bearing_error = bound_vertical_line(
        FLAT, (200.0, 100.0), pixel_error=0.0, bounds=CalibrationBounds(pan=0.01)
    )
    assert bearing_error == pytest.approx(0.01, rel=1e-5)
    line = FLAT.project(Pose(0, 0, 0), [(6.0, -2.0, 0.0), (12.0, -2.0, 0.0)]).ravel()
    _, offset_error, _, angle_error = bound_ground_line(
        FLAT, line, expected_angle=0.0, pixel_error=0.0, bounds=CalibrationBounds(pan=0.01)
    )
    assert angle_error == pytest.approx(0.01, rel=1e-5)
    assert offset_error < 1e-8  # a rotation about the sensor keeps the distance to the line


def test_a_wide_ground_line_bound_keeps_the_orientation_the_hint_allows() -> None:
    """The angle interval is nearly half a turn: parts of both orientations lie within 90
    degrees of the hint. Orienting by the nominal chord alone took the reverse one, and the
    bounds excluded the true angle and offset (the offset by 28 m)."""
    camera = Camera(
        CameraIntrinsics(300.0, 300.0, 329.215677353786, 237.6014013822726, 640, 480),
        CameraMount(height=0.5, pan=0.2, tilt=0.1),
    )
    start, end = (
        np.array([-30.376837306192826, 20.778405793617633]),
        np.array([-37.188851285189614, -18.63728227027328]),
    )
    pose = Pose(0.0, 0.0, 3.061732917256518)
    pixels = [375.84544580130824, 213.7832707631455, 405.2297086536809, 210.81186070814087]  # within 2 px
    direction = end - start
    true_angle = wrap_angle(math.atan2(direction[1], direction[0]) - pose.heading)
    unit = direction / np.linalg.norm(direction)
    true_offset = float(unit[0] * (pose.y - start[1]) - unit[1] * (pose.x - start[0]))
    hint = true_angle - 0.334
    offset, offset_error, angle, angle_error = bound_ground_line(
        camera, pixels, expected_angle=hint, pixel_error=2.0
    )
    assert abs(wrap_angle(true_angle - angle)) <= angle_error
    assert abs(true_offset - offset) <= offset_error
    assert angle_error <= math.pi / 2 + 1e-5  # the hint bounds it to a half turn (and rounding)


def test_height_bound_scales_the_ground_offset() -> None:
    line = FLAT.project(Pose(0, 0, 0), [(6.0, -2.0, 0.0), (12.0, -2.0, 0.0)]).ravel()
    offset, offset_error, _, angle_error = bound_ground_line(
        FLAT, line, expected_angle=0.0, pixel_error=0.0, bounds=CalibrationBounds(height=0.1)
    )
    assert offset == pytest.approx(2.1, abs=1e-8)  # 2 m from the robot, the sensor 0.1 m to its left
    assert offset_error == pytest.approx(0.21, rel=1e-5)  # +-10 % of the height
    assert angle_error < 1e-8


def test_ground_line_orientation_follows_the_expected_angle() -> None:
    line = FLAT.project(Pose(0, 0, 0), [(6.0, -2.0, 0.0), (12.0, -2.0, 0.0)]).ravel()
    forward = bound_ground_line(FLAT, line, expected_angle=1.4, pixel_error=0.0)
    backward = bound_ground_line(FLAT, line, expected_angle=1.8, pixel_error=0.0)
    assert forward[2] == pytest.approx(0.0, abs=1e-6)
    assert abs(backward[2]) == pytest.approx(math.pi, abs=1e-6)
    assert backward[0] == pytest.approx(-forward[0])
    assert backward[1] == pytest.approx(forward[1])


def test_range_capped_by_max_range_near_the_horizon() -> None:
    pixel = FLAT.project(Pose(0, 0, 0), [(60.0, 0.1, 0.0)])[0]  # 1 m below the horizon at 60 m
    with pytest.raises(InputError, match=r"max_range: expected a bound on the range, .* reach the horizon"):
        bound_point(FLAT, pixel, 0.0, pixel_error=10.0)
    _, _, range_min, range_max = bound_point(FLAT, pixel, 0.0, pixel_error=10.0, max_range=80.0)
    assert range_max == 80.0
    assert 0.0 < range_min < 60.0


def test_point_above_the_camera() -> None:
    pixel = FLAT.project(Pose(0, 0, 0), [(10.0, 0.0, 3.0)])[0]
    _, _, range_min, range_max = bound_point(
        FLAT, pixel, 3.0, pixel_error=1.0, bounds=CalibrationBounds(height=0.05)
    )
    assert range_min <= 9.6 <= range_max
    with pytest.raises(InputError, match=r"expected a pixel above the horizon for a landmark at height 3\.0"):
        bound_point(FLAT, (320.0, 400.0), 3.0)


# ------------------------------------------------------------------ the one-pixel float path


def test_one_pixel_float_path_agrees_with_the_array_path(rng: np.random.Generator) -> None:
    # Class I and II observe one pixel with plain floats; the arrays of _rays are the reference.
    compared = 0
    while compared < 600:
        scene = random_scene(rng)
        camera = scene.nominal
        if compared % 2:
            camera = Camera(replace(camera.intrinsics, distortion=None), camera.mount)
        u, v = random_image_pixel(rng).tolist()
        try:
            rays = _observe._rays(camera, scene.bounds, np.array([[u, v]]), scene.pixel_error)
        except InputError:
            with pytest.raises(InputError, match="pixel: expected"):
                _observe._pixel_ray(camera, scene.bounds, u, v, scene.pixel_error)
            continue
        ray = _observe._pixel_ray(camera, scene.bounds, u, v, scene.pixel_error)
        expected = [rays.w.lo[0, 0], rays.w.hi[0, 0], rays.psi.lo[0, 0], rays.psi.hi[0, 0]]
        assert list(ray[:4]) == pytest.approx(expected, rel=1e-12, abs=1e-15)
        assert [ray.w0, ray.psi0] == pytest.approx([rays.w0[0], rays.psi0[0]], rel=1e-12, abs=1e-15)
        bearing, error = _observe._pixel_bearing(camera, scene.bounds, ray)
        reference, reference_error = _observe._bearing_bound(camera, scene.bounds, rays)
        assert wrap_angle(bearing - reference) == pytest.approx(0.0, abs=1e-12)
        assert error == pytest.approx(reference_error, rel=1e-9, abs=1e-15)
        compared += 1


def test_float_sine_and_cosine_ranges_agree_with_the_interval_ones(rng: np.random.Generator) -> None:
    lo = rng.uniform(-10.0, 10.0, 3000)
    hi = lo + np.where(rng.random(3000) < 0.1, 0.0, rng.uniform(0.0, 7.0, 3000))
    sine, cosine = _observe._isin(_observe._Interval(lo, hi)), _observe._icos(_observe._Interval(lo, hi))
    for k in range(len(lo)):
        assert _observe._sin_range(lo[k], hi[k]) == pytest.approx((sine.lo[k], sine.hi[k]), abs=1e-15)
        assert _observe._cos_range(lo[k], hi[k]) == pytest.approx((cosine.lo[k], cosine.hi[k]), abs=1e-15)


def test_pixel_given_as_floats_arrays_or_numpy_scalars_gives_the_same_bounds() -> None:
    pixel = FLAT.project(Pose(0, 0, 0), [(9.0, 1.0, 0.0)])[0]
    results = [
        bound_point(FLAT, form, 0.0, pixel_error=0.5)
        for form in (tuple(pixel.tolist()), pixel, (pixel[0], pixel[1]), [pixel.tolist()])
    ]
    assert all(r == results[0] for r in results)


# ------------------------------------------------------------------ input errors

GOOD_PIXEL = (320.0, 300.0)
# wrongly typed arguments, as a caller without a type checker might pass them
WRONG_CAMERA: Any = "camera"
WRONG_BOUNDS: Any = 0.1
GOOD_SEGMENT = (100.0, 400.0, 200.0, 300.0)


@pytest.mark.parametrize(
    ("call", "error", "match"),
    [
        (
            lambda: bound_vertical_line(FLAT, (640.0, 10.0)),
            InputError,
            r"pixel: expected a pixel inside the 640x480 image \(\[-0.5, 639.5\]",
        ),
        (
            lambda: bound_vertical_line(FLAT, (10.0, -0.6)),
            InputError,
            "pixel: expected a pixel inside",
        ),
        (
            lambda: bound_vertical_line(FLAT, (math.nan, 10.0)),
            InputError,
            "pixel: expected finite coordinates",
        ),
        (
            lambda: bound_vertical_line(FLAT, (1.0, 2.0, 3.0)),
            InputError,
            "pixel: expected an \\(n, 2\\) array",
        ),
        (
            lambda: bound_vertical_line(FLAT, [(1.0, 2.0), (3.0, 4.0)]),
            InputError,
            r"pixel: expected \(u, v\)",
        ),
        (
            lambda: bound_vertical_line(FLAT, GOOD_PIXEL, pixel_error=-1.0),
            InputError,
            r"pixel_error: expected a number in \[0, 100000\] px",
        ),
        (
            lambda: bound_vertical_line(WRONG_CAMERA, GOOD_PIXEL),
            InputError,
            "camera: expected Camera, got str",
        ),
        (
            lambda: bound_vertical_line(FLAT, GOOD_PIXEL, bounds=WRONG_BOUNDS),
            InputError,
            "bounds: expected CalibrationBounds, got float",
        ),
        (
            lambda: bound_vertical_line(FLAT, GOOD_PIXEL, bounds=CalibrationBounds(fy=500.0)),
            InputError,
            r"bounds.fy: expected less than the focal length fy \(500.0\)",
        ),
        (
            lambda: bound_point(FLAT, (320.0, 100.0), 0.0),
            InputError,
            "pixel: expected a pixel below the horizon",
        ),
        (
            lambda: bound_point(FLAT, GOOD_PIXEL, 0.0, bounds=CalibrationBounds(height=1.0)),
            InputError,
            "bounds.height: expected the camera height 1.0 .* to exclude",
        ),
        (
            lambda: bound_point(FLAT, GOOD_PIXEL, 0.0, max_range=-1.0),
            InputError,
            "max_range: expected a positive number",
        ),
        (
            lambda: bound_point(FLAT, GOOD_PIXEL, 0.0, max_range=1.0),
            InputError,
            "max_range: expected at least the smallest possible range",
        ),
        (
            lambda: bound_ground_line(FLAT, (1.0, 2.0, 3.0), expected_angle=0.0),
            InputError,
            r"segment: expected \(u1, v1, u2, v2\), got shape \(3,\)",
        ),
        (
            lambda: bound_ground_line(FLAT, (1.0, 2.0, 3.0, 900.0), expected_angle=0.0),
            InputError,
            "segment: expected a pixel inside",
        ),
        (
            lambda: bound_ground_line(FLAT, ("a", 1, 2, 3), expected_angle=0.0),
            InputError,
            "segment: expected",
        ),
        (
            lambda: bound_ground_line(FLAT, GOOD_SEGMENT, expected_angle=math.nan),
            InputError,
            "expected_angle: expected a finite number",
        ),
        (
            lambda: bound_ground_line(FLAT, (100.0, 400.0, 200.0, 100.0), expected_angle=0.0),
            InputError,
            "segment: expected both ends below the horizon, got end 2",
        ),
        (
            lambda: bound_ground_line(
                FLAT, (100.0, 400.0, 200.0, 250.0), expected_angle=0.0, pixel_error=20.0
            ),
            InputError,
            "segment: expected error bounds that keep both ends below the horizon",
        ),
        (
            lambda: bound_ground_line(
                FLAT, (100.0, 400.0, 101.0, 401.0), expected_angle=0.0, pixel_error=2.0
            ),
            InputError,
            "segment: expected a segment long enough",
        ),
        (
            lambda: bound_ground_line(
                FLAT, GOOD_SEGMENT, expected_angle=0.0, bounds=CalibrationBounds(height=1.5)
            ),
            InputError,
            "bounds.height: expected the camera height 1.0 .* to stay above the ground",
        ),
        (lambda: bound_point(FLAT, GOOD_PIXEL, None), InputError, "^z: expected a finite number, got None$"),  # type: ignore[arg-type]
        (
            lambda: bound_point(FLAT, GOOD_PIXEL, "1.0"),  # type: ignore[arg-type]
            InputError,
            "^z: expected a finite number, got '1.0'$",
        ),
        (lambda: bound_point(FLAT, GOOD_PIXEL, True), InputError, "^z: expected a finite number, got True$"),
        (
            lambda: bound_point(FLAT, GOOD_PIXEL, 1e5),
            InputError,
            r"^z: expected a number in \[-10000, 10000\] m, got 100000\.0$",
        ),
        (
            lambda: bound_ground_line(FLAT, GOOD_SEGMENT, expected_angle=0.0, pixel_error=1e300),
            InputError,
            r"^pixel_error: expected a number in \[0, 100000\] px, got 1e\+300$",
        ),
        (
            lambda: bound_point(FLAT, GOOD_PIXEL, 0.0, pixel_error=-1.0),
            InputError,
            r"^pixel_error: expected a number in \[0, 100000\] px, got -1\.0$",
        ),
        (
            lambda: bound_vertical_line(FLAT, GOOD_PIXEL, pixel_error=math.inf),
            InputError,
            "^pixel_error: expected a finite number, got inf$",
        ),
    ],
)
def test_bad_input_is_refused_naming_the_argument(call: object, error: type[Exception], match: str) -> None:
    assert callable(call)
    with pytest.raises(error, match=match):
        call()
