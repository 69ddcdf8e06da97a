"""Projection basics: principal point, pan and tilt signs, behind the camera, distortion round trip."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums.camera import (
    CalibrationBounds,
    Camera,
    CameraIntrinsics,
    CameraMount,
    distort,
    fold_radius,
    robot_from_camera_rotation,
    undistort_points,
    within_fold,
)
from aura_ums.errors import InputError
from aura_ums.uncertainty import Pose

INTRINSICS = CameraIntrinsics(500.0, 480.0, 320.0, 240.0, 640, 480)


def camera(**mount: float) -> Camera:
    return Camera(INTRINSICS, CameraMount(**{"height": 1.0, **mount}))


def test_point_straight_ahead_projects_to_principal_point() -> None:
    # heading north: robot left is west, so the optical centre is at (2.2, 3.3)
    pixel = camera(forward=0.3, left=-0.2).project(Pose(2.0, 3.0, math.pi / 2), [(2.2, 13.0, 1.0)])
    np.testing.assert_allclose(pixel, [[320.0, 240.0]], atol=1e-9)


def test_pan_is_counter_clockwise() -> None:
    left_point = [(10.0, 10.0, 1.0)]  # 45 degrees to the robot's left
    assert camera().project(Pose(0, 0, 0), left_point)[0, 0] < 320.0  # seen on the left of the image
    np.testing.assert_allclose(camera(pan=math.pi / 4).project(Pose(0, 0, 0), left_point)[0], [320.0, 240.0])


def test_tilt_is_positive_below_the_horizon() -> None:
    low_point = [(10.0, 0.0, 1.0 - 10.0 * math.tan(0.2))]
    assert camera().project(Pose(0, 0, 0), low_point)[0, 1] > 240.0  # below the centre of the image
    np.testing.assert_allclose(camera(tilt=0.2).project(Pose(0, 0, 0), low_point)[0], [320.0, 240.0])


def test_point_behind_the_camera_is_nan() -> None:
    pixels = camera(pan=0.4, tilt=0.3).project(Pose(0, 0, 0), [(-5.0, 1.0, 0.0), (5.0, 0.0, 0.0)])
    assert np.isnan(pixels[0]).all()
    assert np.isfinite(pixels[1]).all()


def test_undistort_without_distortion_is_the_pinhole_inverse() -> None:
    result = undistort_points(INTRINSICS, [(820.0, 0.0), (320.0, 240.0)])
    np.testing.assert_allclose(result, [[1.0, -0.5], [0.0, 0.0]])


distortions = st.tuples(
    st.floats(-0.3, 0.1),
    st.floats(-0.05, 0.05),
    st.floats(-0.003, 0.003),
    st.floats(-0.003, 0.003),
    st.floats(-0.01, 0.01),
)


@given(distortion=distortions, x=st.floats(-0.6, 0.6), y=st.floats(-0.5, 0.5))
def test_undistort_inverts_the_distortion(
    distortion: tuple[float, float, float, float, float], x: float, y: float
) -> None:
    intrinsics = CameraIntrinsics(500.0, 505.0, 320.0, 240.0, 640, 480, distortion)
    pixel = Camera(intrinsics, CameraMount(1.0)).project_camera_frame([(2 * x, 2 * y, 2.0)])
    np.testing.assert_allclose(undistort_points(intrinsics, pixel), [[x, y]], atol=1e-10)


def test_undistort_beyond_the_fold_is_nan() -> None:
    strong = CameraIntrinsics(500.0, 500.0, 320.0, 240.0, 640, 480, (-1.0, 0.0, 0.0, 0.0, 0.0))
    result = undistort_points(strong, [(639.0, 479.0), (330.0, 250.0)])
    assert np.isnan(result[0]).all()
    assert np.isfinite(result[1]).all()


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"intrinsics": "camera", "pixels": [(0, 0)]}, "intrinsics: expected CameraIntrinsics"),
        ({"intrinsics": INTRINSICS, "pixels": [(0, 0, 0)]}, r"pixels: expected an \(n, 2\) array"),
        ({"intrinsics": INTRINSICS, "pixels": [(0, math.nan)]}, "pixels: expected finite coordinates"),
        ({"intrinsics": INTRINSICS, "pixels": [(0, 0)], "iterations": 0}, "iterations: expected a positive"),
    ],
)
def test_undistort_refuses_bad_input(kwargs: dict[str, object], match: str) -> None:
    with pytest.raises(InputError, match=match):
        undistort_points(**kwargs)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("field", "value", "match"),
    [
        ("fx", -1.0, "CalibrationBounds.fx: expected a non-negative number"),
        ("tilt", math.nan, "CalibrationBounds.tilt: expected a finite number"),
        ("height", math.inf, "CalibrationBounds.height: expected a finite number"),
        ("pan", "0.1", "CalibrationBounds.pan: expected a finite number"),
    ],
)
def test_calibration_bounds_are_validated(field: str, value: object, match: str) -> None:
    with pytest.raises(InputError, match=match):
        CalibrationBounds(**{field: value})  # type: ignore[arg-type]


def test_calibration_bounds_default_to_an_exact_calibration() -> None:
    bounds = CalibrationBounds()
    assert all(getattr(bounds, name) == 0.0 for name in CalibrationBounds.field_names())


def test_project_refuses_poses_of_the_wrong_shape() -> None:
    # a (2, 2) array of poses raised numpy's "cannot reshape array of size 4 into shape (3)"
    camera = Camera(CameraIntrinsics(500.0, 500.0, 319.5, 239.5, 640, 480), CameraMount(height=1.0))
    with pytest.raises(
        InputError,
        match=r"pose: expected a Pose, or x, y and heading of shape \(3,\) or \(m, 3\), got \(2, 2\)",
    ):
        camera.project(np.zeros((2, 2)), [(5.0, 0.0, 1.0)])


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"fx": 1e-300}, r"CameraIntrinsics\.fx: expected a number in \[1, 1e\+06\] px, got 1e-300"),
        ({"cy": 1e300}, r"CameraIntrinsics\.cy: expected a number in \[-100000, 100000\] px, got 1e\+300"),
        (
            {"width": 2_000_000},
            r"CameraIntrinsics\.width: expected an integer in \[1, 20000\] px, got 2000000",
        ),
        ({"height": 0}, r"CameraIntrinsics\.height: expected an integer in \[1, 20000\] px, got 0"),
        (
            {"distortion": (0.1, 1e300, 0.0, 0.0, 0.0)},
            r"CameraIntrinsics\.distortion\[1\]: expected a number in \[-1000, 1000\], got 1e\+300",
        ),
    ],
)
def test_intrinsics_built_in_code_have_the_camera_files_ranges(
    arguments: dict[str, object], message: str
) -> None:
    # a camera file was refused these values; built in code, an image 2e6 px wide was taken
    values: dict[str, object] = {
        "fx": 500.0,
        "fy": 480.0,
        "cx": 320.0,
        "cy": 240.0,
        "width": 640,
        "height": 480,
    }
    with pytest.raises(InputError, match=message):
        CameraIntrinsics(**{**values, **arguments})  # type: ignore[arg-type]
    assert CameraIntrinsics(1.0, 1e6, -1e5, 1e5, 1, 20_000, (-1000.0, 1000.0, 0.0, 0.0, 0.0)).width == 1


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"height": 1e300}, r"CameraMount\.height: expected a height <= 100 m above the ground, got 1e\+300"),
        ({"height": 1.0, "forward": 1e300}, r"CameraMount\.forward: expected a number in \[-100, 100\] m"),
        ({"height": 1.0, "pan": 1e300}, r"CameraMount\.pan: expected a number in \[-1000, 1000\] rad"),
    ],
)
def test_a_mount_built_in_code_has_the_camera_files_ranges(arguments: dict[str, float], message: str) -> None:
    with pytest.raises(InputError, match=message):
        CameraMount(**arguments)
    assert CameraMount(100.0, forward=-100.0, left=100.0).height == 100.0


@pytest.mark.parametrize("length", [4, 5, 8, 12, 14])
def test_intrinsics_take_every_length_of_opencvs_distortion_vector(length: int) -> None:
    """As a camera file does: the vector of any of OpenCV's lengths, kept as (k1, k2, p1, p2, k3)."""
    vector = [-0.1, 0.01, 0.001, -0.002, 0.003, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0][:length]
    k = CameraIntrinsics(500, 500, 320, 240, 640, 480, distortion=vector)  # type: ignore[arg-type]
    assert k.distortion == (-0.1, 0.01, 0.001, -0.002, 0.003 if length > 4 else 0.0)


def test_intrinsics_refuse_distortion_aura_ums_does_not_model() -> None:
    with pytest.raises(
        InputError, match=r"^CameraIntrinsics\.distortion: expected 4, 5, 8, 12 or 14 .*, got 3$"
    ):
        CameraIntrinsics(500, 500, 320, 240, 640, 480, distortion=(0.1, 0.0, 0.0))  # type: ignore[arg-type]
    with pytest.raises(
        InputError, match=r"expected the coefficients beyond k3 .* to be zero .*, got \[0\.5, 0\.0, 0\.0\]"
    ):
        CameraIntrinsics(500, 500, 320, 240, 640, 480, distortion=(0.1, 0.0, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0))  # type: ignore[arg-type]
    with pytest.raises(
        InputError, match=r"^CameraIntrinsics\.distortion\[1\]: expected a number in \[-1000, 1000\]"
    ):
        CameraIntrinsics(500, 500, 320, 240, 640, 480, distortion=(0.1, 2000.0, 0.0, 0.0))  # type: ignore[arg-type]


# --------------------------------------------------------------------------- the lens's fold

#: Trial 1045 of the soundness attack on the observers (seed 1): a barrel lens that folds at a
#: normalized radius of 1.29, 52 degrees off the optical axis.
FOLDING = (-0.14037735976465748, -0.019756094563861994, 0.0011521003782993247, -0.002270688788373455, 0.0)


def test_fold_radius_of_a_radial_lens_is_the_first_root_of_the_slope() -> None:
    # r (1 + k1 r^2 + k2 r^4) has slope 1 + 3 k1 r^2 + 5 k2 r^4: a quadratic in r^2
    assert fold_radius((-0.14, 0.0, 0.0, 0.0, 0.0)) == pytest.approx(1.0 / math.sqrt(0.42), rel=1e-11)
    k1, k2 = FOLDING[0], FOLDING[1]
    s = (-3.0 * k1 - math.sqrt(9.0 * k1 * k1 - 20.0 * k2)) / (10.0 * k2)
    assert fold_radius((k1, k2, 0.0, 0.0, 0.0)) == pytest.approx(math.sqrt(s), rel=1e-11)
    # a slope with two positive roots (1 - 0.3 s + 0.0125 s^2: s = 4 and 20): the first
    assert fold_radius((-0.1, 0.0025, 0.0, 0.0, 0.0)) == pytest.approx(2.0, rel=1e-11)
    # never above the fold: the radius returned is within it (rounded inwards)
    assert fold_radius((-0.14, 0.0, 0.0, 0.0, 0.0)) <= 1.0 / math.sqrt(0.42)


def test_tangential_terms_move_the_fold_inwards() -> None:
    radial = fold_radius((*FOLDING[:2], 0.0, 0.0, 0.0))
    assert 1.28 < fold_radius(FOLDING) < radial < 1.31


@pytest.mark.parametrize(
    "distortion",
    [
        (0.0, 0.0, 0.0, 0.0, 0.0),
        (0.1, 0.01, 0.0, 0.0, 0.002),  # pincushion
        (-0.1, 0.05, 0.0, 0.0, 0.0),  # barrel, but 1 - 0.3 s + 0.25 s^2 never vanishes
        (0.0, 0.0, 0.0, 0.0, 1e-300),
        None,
    ],
)
def test_a_lens_that_never_folds_images_every_ray_in_front_as_before(
    distortion: tuple[float, float, float, float, float] | None,
) -> None:
    assert fold_radius(distortion) == math.inf
    lens = CameraIntrinsics(300.0, 300.0, 320.0, 240.0, 640, 480, distortion)
    points = np.array([[x, y, 1.0] for x in (-40.0, -3.0, 0.0, 0.7, 25.0) for y in (-9.0, 0.0, 2.0)])
    x, y = points[:, 0], points[:, 1]
    if distortion is not None:
        x, y = distort(x, y, distortion)  # the polynomial, however far off axis
    pixels = Camera(lens, CameraMount(1.0)).project_camera_frame(points)
    np.testing.assert_array_equal(pixels, np.column_stack([300.0 * x + 320.0, 300.0 * y + 240.0]))


def test_a_tiny_leading_coefficient_does_not_hide_the_fold() -> None:
    # The companion matrix's roots of 1 - 0.9 r^2 + 7e-150 r^6 lose the root at r = 1.054.
    assert fold_radius((-0.3, 0.0, 0.0, 0.0, 1e-150)) == pytest.approx(1.0 / math.sqrt(0.9), rel=1e-11)
    assert fold_radius((-0.3, 0.0, 0.0, 0.0, -5e-324)) == pytest.approx(1.0 / math.sqrt(0.9), rel=1e-11)
    # a fold that far out is none: 1 - 7e-150 r^6 vanishes at r = 7e24, below the horizon 1e30
    assert fold_radius((0.0, 0.0, 0.0, 0.0, -1e-150)) == pytest.approx(7.23020026e24, rel=1e-8)
    assert fold_radius((0.0, 0.0, 0.0, 0.0, -1e-190)) == math.inf


def test_fold_radius_takes_any_form_of_the_vector_and_refuses_bad_ones() -> None:
    assert fold_radius([-0.14, 0.0, 0.0, 0.0]) == fold_radius((-0.14, 0.0, 0.0, 0.0, 0.0))  # type: ignore[arg-type]
    assert fold_radius(np.array(FOLDING)) == fold_radius(FOLDING)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="distortion: expected finite numbers, got non-finite values"):
        fold_radius((math.nan, 0.0, 0.0, 0.0, 0.0))
    with pytest.raises(InputError, match=r"distortion: expected 4, 5, 8, 12 or 14 .*, got 3"):
        fold_radius((0.1, 0.0, 0.0))  # type: ignore[arg-type]


@given(
    distortion=st.tuples(
        st.floats(-2.0, 0.5),
        st.floats(-1.0, 1.0),
        st.floats(-0.05, 0.05),
        st.floats(-0.05, 0.05),
        st.floats(-1.0, 1.0),
    ),
    seed=st.integers(0, 2**32 - 1),
)
def test_the_lens_is_one_to_one_within_its_fold(
    distortion: tuple[float, float, float, float, float], seed: int
) -> None:
    # Within the fold the Jacobian of the distortion is positive definite, so the map is
    # strictly monotone on the disk: (d(a) - d(b)) . (a - b) > 0, no two rays share a pixel.
    limit = min(fold_radius(distortion), 1e3)
    rng = np.random.default_rng(seed)
    radius = limit * np.sqrt(rng.uniform(0.0, 1.0, (2, 400)))
    angle = rng.uniform(-math.pi, math.pi, (2, 400))
    ax, ay = radius[0] * np.cos(angle[0]), radius[0] * np.sin(angle[0])
    bx, by = radius[1] * np.cos(angle[1]), radius[1] * np.sin(angle[1])
    (dax, day), (dbx, dby) = distort(ax, ay, distortion), distort(bx, by, distortion)
    assert np.all((dax - dbx) * (ax - bx) + (day - dby) * (ay - by) > 0.0)
    k1, k2, p1, p2, k3 = distortion
    r2 = ax * ax + ay * ay
    rho = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
    slope = k1 + r2 * (2.0 * k2 + r2 * 3.0 * k3)
    j00 = rho + 2.0 * ax * ax * slope + 2.0 * p1 * ay + 6.0 * p2 * ax
    j11 = rho + 2.0 * ay * ay * slope + 6.0 * p1 * ay + 2.0 * p2 * ax
    j01 = 2.0 * ax * ay * slope + 2.0 * p1 * ax + 2.0 * p2 * ay
    assert np.all((j00 > 0.0) & (j00 * j11 - j01 * j01 > 0.0))


def test_projection_beyond_the_fold_is_nan_like_behind_the_camera() -> None:
    # The regression: 63 degrees off axis, beyond the fold at 52 degrees, the polynomial put a
    # ground point at (256, 296), inside the image (undistorted it lies at (-176, 600)), over
    # the pixels of a ray within the fold.
    true_camera = Camera(
        CameraIntrinsics(295.0, 300.0, 314.1104361779169, 256.3198179581066, 640, 480, FOLDING),
        CameraMount(2.02, left=-0.2, pan=-0.5),
    )
    pose = Pose(0.0, 0.0, -2.9644228825344228)
    beyond = (-2.6389038271351124, -2.0229579890451834, 0.0)
    frame = true_camera.to_camera_frame(pose.as_array(), [beyond])[0, 0]
    assert math.hypot(frame[0] / frame[2], frame[1] / frame[2]) > fold_radius(FOLDING)
    polynomial = distort(np.array([frame[0] / frame[2]]), np.array([frame[1] / frame[2]]), FOLDING)
    assert 0.0 < 295.0 * polynomial[0][0] + 314.11 < 640.0  # the pixel the polynomial gave, in the image
    assert np.isnan(true_camera.project(pose, [beyond])).all()
    # 17 degrees off axis, on the same line on the ground: imaged
    within = (-10.630440158822351, 7.151084478052063, 0.0)
    assert np.isfinite(true_camera.project(pose, [within])).all()
    # on the fold's edge, at every angle around the axis: imaged just inside, NaN just outside
    limit = fold_radius(FOLDING)
    angle = np.linspace(-math.pi, math.pi, 16)
    edge = np.column_stack([np.cos(angle), np.sin(angle), np.ones(16)])
    inside = true_camera.project_camera_frame(edge * [limit * (1 - 1e-9), limit * (1 - 1e-9), 1.0])
    outside = true_camera.project_camera_frame(edge * [limit * (1 + 1e-9), limit * (1 + 1e-9), 1.0])
    assert np.isfinite(inside).all()
    assert np.isnan(outside).all()


def test_undistort_finds_no_ray_beyond_the_fold() -> None:
    # The top-left corner of this image is reached by no ray within the fold; the iteration
    # converged on the ray at r = 2.44, beyond the fold (1.29), where the lens images nothing.
    lens = CameraIntrinsics(300.0, 300.0, 314.11, 257.62, 640, 480, FOLDING)
    result = undistort_points(lens, [(0.0, 0.0), (391.38736871558046, 304.14233415635124)])
    assert np.isnan(result[0]).all()
    assert math.hypot(*result[1]) < fold_radius(FOLDING)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (
            lambda: camera().project_camera_frame([[1.0, 2.0]]),
            r"^points_camera: expected shape \(\.\.\., 3\), got \(1, 2\)$",
        ),
        (
            lambda: camera().project_camera_frame([]),
            r"^points_camera: expected shape \(\.\.\., 3\), got \(0,\)$",
        ),
        (
            lambda: camera().project_camera_frame(1.0),
            r"^points_camera: expected shape \(\.\.\., 3\), got \(\)$",
        ),
        (lambda: camera().project_camera_frame(None), "^points_camera: expected numbers, got None$"),  # type: ignore[arg-type]
        (
            lambda: camera().project_camera_frame([[math.nan, 0.0, 5.0]]),
            "^points_camera: expected finite numbers, got non-finite values$",
        ),
        (
            lambda: camera().project_camera_frame([[1e300, 0.0, 5.0]]),
            r"^points_camera: expected coordinates a number in \[-1e\+07, 1e\+07\] m, got 1e\+300$",
        ),
        (
            lambda: camera().to_camera_frame([1.0, 2.0], [[10.0, 0.0, 1.0]]),
            r"^poses: expected x, y and heading of shape \(3,\) or \(m, 3\), got \(2,\)$",
        ),
        (
            lambda: camera().to_camera_frame(np.zeros((2, 2, 3)), [[10.0, 0.0, 1.0]]),
            r"^poses: expected x, y and heading of shape \(3,\) or \(m, 3\), got \(2, 2, 3\)$",
        ),
        (lambda: robot_from_camera_rotation(None, 0.0), "^pan: expected a finite number, got None$"),  # type: ignore[arg-type]
        (lambda: robot_from_camera_rotation(math.nan, 0.0), "^pan: expected a finite number, got nan$"),
        (lambda: robot_from_camera_rotation(0.0, math.inf), "^tilt: expected a finite number, got inf$"),
        (
            lambda: robot_from_camera_rotation(0.0, 1e4),
            r"^tilt: expected a number in \[-1000, 1000\] rad, got 10000\.0$",
        ),
        (
            lambda: distort(np.array([0.1]), np.array([0.1]), None),  # type: ignore[arg-type]
            r"^coefficients: expected 4, 5, 8, 12 or 14 distortion coefficients, got None$",
        ),
        (
            lambda: distort([0.1], [0.1], (0.1, 0.0, 0.0)),  # type: ignore[arg-type]
            r"^coefficients: expected 4, 5, 8, 12 or 14 distortion coefficients, got 3$",
        ),
        (
            lambda: distort([0.1], [0.1], (0.1, 1e4, 0.0, 0.0, 0.0)),
            r"^coefficients\[1\]: expected a number in \[-1000, 1000\], got 10000\.0$",
        ),
        (lambda: distort(None, [0.1], (0.1, 0.0, 0.0, 0.0, 0.0)), "^x: expected numbers, got None$"),  # type: ignore[arg-type]
        (
            lambda: distort([0.1], [math.nan], (0.1, 0.0, 0.0, 0.0, 0.0)),
            "^y: expected finite numbers, got non-finite values$",
        ),
        (
            lambda: distort([1e300], [0.1], (0.1, 0.0, 0.0, 0.0, 0.0)),
            r"^x: expected coordinates a number in \[-1e\+30, 1e\+30\], got 1e\+300$",
        ),
        (
            lambda: distort([0.1, 0.2], [0.1], (0.1, 0.0, 0.0, 0.0, 0.0)),
            r"^y: expected the shape of x \(2,\), got \(1,\)$",
        ),
        (lambda: within_fold(None, [0.1], None), "^x: expected numbers, got None$"),  # type: ignore[arg-type]
        (lambda: within_fold([0.1], ["a"], None), r"^y: expected numbers, got \['a'\]$"),
        (lambda: within_fold([0.1], [0.1, 0.2], None), r"^y: expected the shape of x \(1,\), got \(2,\)$"),
    ],
)
def test_projection_helpers_refuse_bad_input(call: object, match: str) -> None:
    assert callable(call)
    with pytest.raises(InputError, match=match):
        call()


def test_checked_helpers_give_the_results_of_before() -> None:
    x, y = np.array([0.0, 0.5, -0.3]), np.array([0.0, 0.1, 0.2])
    xd, yd = distort(list(x), list(y), (-0.1, 0.01, 0.001, -0.002, 0.003))
    r2 = x * x + y * y
    radial = 1.0 + r2 * (-0.1 + r2 * (0.01 + r2 * 0.003))
    assert xd.tolist() == (x * radial + 2.0 * 0.001 * x * y + -0.002 * (r2 + 2.0 * x * x)).tolist()
    assert yd.tolist() == (y * radial + 0.001 * (r2 + 2.0 * y * y) + 2.0 * -0.002 * x * y).tolist()
    assert within_fold([0.0, np.nan], [0.0, 0.0], (-0.14, 0.0, 0.0, 0.0, 0.0)).tolist() == [True, False]
    lens = Camera(INTRINSICS, CameraMount(1.0, pan=0.2, tilt=0.1))
    poses, points = (
        np.array([[1.0, 2.0, 0.3], [0.0, 0.0, -0.2]]),
        np.array([[10.0, 3.0, 0.5], [8.0, -1.0, 0.0]]),
    )
    assert (
        lens.project(poses, points).tolist()
        == lens.project_camera_frame(lens.to_camera_frame(poses, points)).tolist()
    )
