"""Windows under calibration bounds: they hold for every camera within the bounds.

The true camera is drawn within the bounds (uniformly, and at the corners of the bounds'
box: each parameter at either end), and the landmark seen from the map's poses through it
must land in the window of ``Expecter(camera, calibration_bounds)``. Without the bounds the
same draws fall outside, so the check can fail.
"""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from aura_ums.camera import CalibrationBounds, Camera, CameraIntrinsics, CameraMount
from aura_ums.errors import InputError
from aura_ums.expecter import Expecter
from aura_ums.geometry import ImageWindow
from aura_ums.uncertainty import PointLandmark, Pose, SpatialUncertaintyMap
from tests.expecter.expecter_helpers import (
    CAMERAS,
    extreme_poses,
    landmark_points,
    random_landmark,
    random_map,
    visible_pixels,
)

#: About what a careful calibration gives: focal lengths and centre to a few pixels, pan and
#: tilt to half a degree, the height to 2 cm.
BOUNDS = CalibrationBounds(
    fx=6.0, fy=5.0, cx=4.0, cy=3.0, pan=math.radians(0.5), tilt=math.radians(0.5), height=0.02
)
NAMES = CalibrationBounds.field_names()


def true_camera(camera: Camera, bounds: CalibrationBounds, signs: tuple[float, ...]) -> Camera:
    """Return the camera, each bounded parameter moved by ``sign * bound`` (NAMES' order, in [-1, 1])."""
    move = dict(zip(NAMES, signs, strict=True))
    k, m = camera.intrinsics, camera.mount
    intrinsics = dataclasses.replace(
        k,
        fx=k.fx + move["fx"] * bounds.fx,
        fy=k.fy + move["fy"] * bounds.fy,
        cx=k.cx + move["cx"] * bounds.cx,
        cy=k.cy + move["cy"] * bounds.cy,
    )
    mount = dataclasses.replace(
        m,
        pan=m.pan + move["pan"] * bounds.pan,
        tilt=m.tilt + move["tilt"] * bounds.tilt,
        height=m.height + move["height"] * bounds.height,
    )
    return Camera(intrinsics, mount)


def draws(rng: np.random.Generator, count: int) -> list[tuple[float, ...]]:
    """Sign vectors: ``count`` uniform ones and every pan/tilt/height corner with the intrinsics at ends."""
    uniform = [tuple(rng.uniform(-1.0, 1.0, len(NAMES)).tolist()) for _ in range(count)]
    corners = [
        (sx, sx, sc, sc, pan, tilt, height)
        for sx, sc, pan, tilt, height in itertools.product((-1.0, 1.0), repeat=5)
    ]
    return uniform + corners


def outside(window: ImageWindow | None, pixels: np.ndarray) -> int:
    """How many pixels (k, 2) lie outside ``window`` (an ImageWindow)."""
    assert window is not None
    u, v = pixels[:, 0], pixels[:, 1]
    inside = (u >= window.u_min) & (u <= window.u_max) & (v >= window.v_min) & (v <= window.v_max)
    return int((~inside).sum())


@pytest.mark.parametrize("kind", ["I", "II", "III"])
def test_every_camera_within_the_bounds_sees_the_landmark_inside_the_window(
    kind: str, rng: np.random.Generator
) -> None:
    checked = 0
    for name, camera in CAMERAS.items():
        expecter = Expecter(camera, BOUNDS)
        for index in range(3):
            the_map = random_map(rng, wide_wedge=index == 2)
            landmark = random_landmark(rng, kind, the_map.center, ahead=index != 1)
            poses = np.vstack([the_map.sample_poses(60, rng), extreme_poses(the_map)])
            points = landmark_points(landmark, rng)
            window = expecter.bounds(the_map, landmark)
            for signs in draws(rng, 12):
                pixels = visible_pixels(true_camera(camera, BOUNDS, signs), poses, points)
                checked += len(pixels)
                if window is None:
                    assert len(pixels) == 0, (
                        f"{name} map {index}: None, yet {len(pixels)} visible projections"
                    )
                    continue
                assert outside(window, pixels) == 0, f"{name} map {index}, camera moved by {signs}"
    assert checked > 10_000


def test_without_the_bounds_a_camera_within_them_sees_the_landmark_outside() -> None:
    """Why the bounds are needed: half a degree of pan moves a corner 10 m ahead by about 4 px."""
    camera = CAMERAS["plain"]
    known = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.0, 0.0)
    corner = PointLandmark("corner", 10.0, 0.0, 2.0)
    panned = true_camera(camera, BOUNDS, (0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0))
    pixel = visible_pixels(panned, np.array([[0.0, 0.0, 0.0]]), np.array([[10.0, 0.0, 2.0]]))
    assert outside(Expecter(camera).bounds(known, corner), pixel) == 1
    assert outside(Expecter(camera, BOUNDS).bounds(known, corner), pixel) == 0


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), kind=st.sampled_from(["I", "II", "III"]))
def test_the_windows_with_bounds_hold_those_without(seed: int, kind: str) -> None:
    rng = np.random.default_rng(seed)
    camera = CAMERAS["tilted_panned_offset"]
    the_map = random_map(rng)
    landmark = random_landmark(rng, kind, the_map.center)
    exact = Expecter(camera).bounds(the_map, landmark)
    loose = Expecter(camera, BOUNDS).bounds(the_map, landmark)
    if exact is None:
        return
    assert loose is not None
    assert loose.u_min <= exact.u_min
    assert loose.v_min <= exact.v_min
    assert loose.u_max >= exact.u_max
    assert loose.v_max >= exact.v_max


def test_zero_bounds_are_an_exact_camera() -> None:
    camera = CAMERAS["distorted"]
    expecter = Expecter(camera, CalibrationBounds())
    assert expecter.calibration_bounds is None
    assert expecter == Expecter(camera)


def test_a_landmark_far_behind_stays_out_of_view_within_the_bounds() -> None:
    """Half a degree cannot turn a landmark behind the camera into view: still None, not the whole frame."""
    camera = CAMERAS["plain"]
    known = SpatialUncertaintyMap.from_pose(Pose(0.0, 0.0, 0.0), 0.2, 0.05)
    behind = PointLandmark("behind", -10.0, 0.5, 2.0)
    assert Expecter(camera, BOUNDS).bounds(known, behind) is None


def test_bad_calibration_bounds_are_refused() -> None:
    camera = Camera(CameraIntrinsics(500.0, 400.0, 320.0, 240.0, 640, 480), CameraMount(height=1.0))
    with pytest.raises(
        InputError, match=r"^calibration_bounds: expected CalibrationBounds or None, got dict$"
    ):
        Expecter(camera, {"pan": 0.01})  # type: ignore[arg-type]
    with pytest.raises(
        InputError,
        match=r"^calibration_bounds\.fy: expected a bound below the camera's fy \(400\.0 px\), got 400\.0$",
    ):
        Expecter(camera, CalibrationBounds(fy=400.0))
