"""Projection basics: principal point, pan and tilt signs, behind the camera, distortion round trip."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums.camera import CalibrationBounds, Camera, CameraIntrinsics, CameraMount, undistort_points
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
