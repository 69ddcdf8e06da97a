"""Edge cases of the Expecter: behind, inside, partly behind, full circle, margins, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from aura_ums.camera import Camera, CameraIntrinsics, CameraMount
from aura_ums.errors import InputError
from aura_ums.expecter import Expecter, ImageWindow, PerceptualStrategy, disk_model_window
from aura_ums.expecter._window import DEFAULT_MARGINS
from aura_ums.geometry import UNBOUNDED_PIXELS, ConvexPolygon, HeadingWedge
from aura_ums.uncertainty import (
    GroundLineLandmark,
    Landmark,
    PointLandmark,
    Pose,
    SpatialUncertaintyMap,
    VerticalLineLandmark,
)
from tests.expecter.expecter_helpers import CAMERAS, extreme_poses, landmark_points, visible_pixels

CAMERA = CAMERAS["tilted_panned_offset"]
STRIP = ConvexPolygon([(-2.0, -0.3), (2.0, -0.3), (2.0, 0.3), (-2.0, 0.3)])


def _map(wedge: HeadingWedge, polygon: ConvexPolygon = STRIP) -> SpatialUncertaintyMap:
    return SpatialUncertaintyMap(polygon, (0.0, 0.0), wedge)


def _assert_sound(camera: Camera, the_map: SpatialUncertaintyMap, landmark: Landmark, seed: int) -> None:
    rng = np.random.default_rng(seed)
    poses = np.vstack([the_map.sample_poses(2000, rng), extreme_poses(the_map, per_edge=8)])
    pixels = visible_pixels(camera, poses, landmark_points(landmark, rng, count=41))
    window = Expecter(camera).bounds(the_map, landmark)
    assert window is not None
    assert np.all((pixels[:, 0] >= window.u_min) & (pixels[:, 0] <= window.u_max))
    assert np.all((pixels[:, 1] >= window.v_min) & (pixels[:, 1] <= window.v_max))


@pytest.mark.parametrize(
    "landmark",
    [
        PointLandmark("behind", -12.0, 0.5, 1.0),
        VerticalLineLandmark("behind_pole", -9.0, -1.0, 0.0, 8.0, position_uncertainty=0.5),
        GroundLineLandmark("behind_edge", (-15.0, -3.0), (-6.0, 3.0)),
    ],
)
def test_landmark_behind_for_every_pose_gives_none(landmark: Landmark) -> None:
    the_map = _map(HeadingWedge(0.0, 0.1, 0.1))
    expecter = Expecter(CAMERAS["plain"])
    assert expecter.bounds(the_map, landmark) is None
    assert expecter.window(the_map, landmark) is None


def test_landmark_off_the_image_for_every_pose_gives_none() -> None:
    # In front of the camera but far to the side: the guaranteed window misses the image.
    the_map = _map(HeadingWedge(0.0, 0.01, 0.01))
    expecter = Expecter(CAMERAS["plain"])
    landmark = PointLandmark("far_left", 5.0, 20.0, 1.0)
    bounds = expecter.bounds(the_map, landmark)
    assert bounds is not None
    assert bounds.u_max < 0.0
    assert expecter.window(the_map, landmark, margin=0.0) is None


@pytest.mark.parametrize(
    "landmark",
    [
        VerticalLineLandmark("pole_inside", 0.5, 0.1, 0.0, 3.0),
        PointLandmark("point_inside", -0.5, 0.0, 0.3, position_uncertainty=0.2),
        GroundLineLandmark("edge_inside", (-1.0, 0.0), (8.0, 0.0)),
    ],
)
def test_landmark_inside_the_polygon(landmark: Landmark) -> None:
    the_map = _map(HeadingWedge(0.0, 0.2, 0.2))
    _assert_sound(CAMERA, the_map, landmark, seed=1)
    window = Expecter(CAMERA).window(the_map, landmark)
    assert window is not None
    assert window.u_min >= -0.5
    assert window.u_max <= 639.5


def test_partially_behind_is_bounded_and_clipped() -> None:
    # A path edge from behind the robot to far ahead: part of it is behind the camera.
    landmark = GroundLineLandmark("path_edge", (-10.0, -1.5), (25.0, -1.5))
    the_map = _map(HeadingWedge(0.0, 0.05, 0.05))
    expecter = Expecter(CAMERAS["plain"])
    bounds = expecter.bounds(the_map, landmark)
    assert bounds is not None
    assert bounds.v_max > 1e5  # reaches the near plane: far below the image
    window = expecter.window(the_map, landmark)
    assert window == bounds.expanded(24.0).clipped(640, 480)
    assert window is not None
    assert window.v_max == 479.5
    _assert_sound(CAMERAS["plain"], the_map, landmark, seed=2)
    _assert_sound(CAMERAS["distorted"], the_map, landmark, seed=3)


@pytest.mark.parametrize("camera_name", ["tilted_panned_offset", "distorted"])
def test_full_circle_wedge(camera_name: str) -> None:
    the_map = _map(HeadingWedge.full_circle(0.3))
    landmark = VerticalLineLandmark("lamppost", 8.0, 2.0, 0.0, 4.0)
    _assert_sound(CAMERAS[camera_name], the_map, landmark, seed=4)
    window = Expecter(CAMERAS[camera_name]).window(the_map, landmark)
    assert window is not None
    assert window.width == 640.0  # any heading: it may appear anywhere across


def test_exact_pose_gives_the_projection() -> None:
    point_map = SpatialUncertaintyMap.from_pose(Pose(1.0, -2.0, 0.2), 0.0, 0.0)
    landmark = PointLandmark("corner", 9.0, 1.0, 2.5)
    for camera in CAMERAS.values():
        window = Expecter(camera).bounds(point_map, landmark)
        pixel = camera.project(Pose(1.0, -2.0, 0.2), [(9.0, 1.0, 2.5)])[0]
        assert window is not None
        assert window.width < 1e-3
        assert window.height < 1e-3
        assert window.contains(pixel)


def test_margins_by_strategy() -> None:
    assert (
        DEFAULT_MARGINS[PerceptualStrategy.LINE_FINDER] > DEFAULT_MARGINS[PerceptualStrategy.REGION_SEGMENTER]
    )
    assert (
        DEFAULT_MARGINS[PerceptualStrategy.REGION_SEGMENTER]
        > DEFAULT_MARGINS[PerceptualStrategy.INTEREST_OPERATOR]
    )
    assert set(DEFAULT_MARGINS) == set(PerceptualStrategy)
    the_map = _map(HeadingWedge(0.0, 0.02, 0.02))
    landmark = PointLandmark("corner", 12.0, 0.5, 1.0)
    expecter = Expecter(CAMERAS["plain"])
    bounds = expecter.bounds(the_map, landmark)
    lines = expecter.window(the_map, landmark, margin=PerceptualStrategy.LINE_FINDER)
    corners = expecter.window(the_map, landmark, margin=PerceptualStrategy.INTEREST_OPERATOR)
    assert bounds is not None
    assert lines is not None
    assert corners is not None
    assert lines.area > corners.area > bounds.area
    assert lines.width - corners.width == pytest.approx(2 * (24.0 - 4.0))
    assert expecter.window(the_map, landmark, margin=0.0) == bounds


def test_the_default_margin_is_that_of_the_strategy_usual_for_the_class() -> None:
    # A point is looked for with an interest operator (4 px of context), not a line finder's 24.
    the_map = _map(HeadingWedge(0.0, 0.02, 0.02))
    expecter = Expecter(CAMERAS["plain"])
    corner = PointLandmark("corner", 12.0, 0.5, 1.0)
    pole = VerticalLineLandmark("pole", 12.0, 0.5, 0.0, 1.5)
    for landmark, strategy in (
        (corner, PerceptualStrategy.INTEREST_OPERATOR),
        (pole, PerceptualStrategy.LINE_FINDER),
    ):
        default = expecter.window(the_map, landmark)
        assert default is not None
        assert default == expecter.window(the_map, landmark, margin=strategy)
        assert disk_model_window(expecter, the_map, landmark) == disk_model_window(
            expecter, the_map, landmark, margin=strategy
        )
        assert disk_model_window(expecter, the_map, landmark, clip=False) == disk_model_window(
            expecter, the_map, landmark, margin=strategy, clip=False
        )
    # Behind the camera there is no window, whatever the margin.
    assert expecter.window(the_map, PointLandmark("behind", -12.0, 0.0, 1.0)) is None


def test_unbounded_sentinel_is_finite() -> None:
    window = ImageWindow(-UNBOUNDED_PIXELS, 0.0, UNBOUNDED_PIXELS, 1.0)
    assert window.expanded(10.0).u_max == UNBOUNDED_PIXELS
    assert window.clipped(640, 480) == ImageWindow(-0.5, 0.0, 639.5, 1.0)


def test_image_window_basics() -> None:
    window = ImageWindow(10.0, 20.0, 50.0, 40.0)
    assert (window.width, window.height, window.area) == (40.0, 20.0, 800.0)
    inside = window.contains(np.array([[10.0, 20.0], [50.0, 40.0], [50.1, 30.0], [np.nan, 30.0]]))
    assert inside.tolist() == [True, True, False, False]
    assert window.contains((30.0, 30.0)).shape == ()
    assert window.expanded(0.0) == window
    assert window.clipped(30, 30) == ImageWindow(10.0, 20.0, 29.5, 29.5)
    assert ImageWindow(-50.0, -50.0, -1.0, -1.0).clipped(640, 480) is None


def test_bad_input_is_refused() -> None:
    expecter = Expecter(CAMERAS["plain"])
    the_map = _map(HeadingWedge(0.0, 0.1, 0.1))
    landmark = PointLandmark("corner", 10.0, 0.0, 1.0)
    with pytest.raises(InputError, match="camera: expected a Camera"):
        Expecter("camera")  # type: ignore[arg-type]
    with pytest.raises(InputError, match="map: expected a SpatialUncertaintyMap"):
        expecter.bounds("map", landmark)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="landmark: expected a VerticalLineLandmark"):
        expecter.window(the_map, (10.0, 0.0))  # type: ignore[arg-type]
    with pytest.raises(InputError, match="margin: expected a non-negative number"):
        expecter.window(the_map, landmark, margin=-1.0)
    with pytest.raises(InputError, match="margin: expected a finite number"):
        expecter.window(the_map, landmark, margin=math.nan)
    with pytest.raises(InputError, match="margin: expected a finite number"):
        expecter.window(the_map, landmark, margin="line_finder")  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"ImageWindow.u_min: expected a finite number"):
        ImageWindow(math.inf, 0.0, 1.0, 1.0)
    with pytest.raises(InputError, match=r"ImageWindow.v_max: expected >= v_min"):
        ImageWindow(0.0, 5.0, 1.0, 1.0)
    with pytest.raises(InputError, match="width: expected a positive integer"):
        ImageWindow(0.0, 0.0, 1.0, 1.0).clipped(0, 480)
    with pytest.raises(InputError, match=r"pixels: expected shape \(\.\.\., 2\)"):
        ImageWindow(0.0, 0.0, 1.0, 1.0).contains([1.0, 2.0, 3.0])
    with pytest.raises(InputError, match="margin: expected a non-negative number"):
        ImageWindow(0.0, 0.0, 1.0, 1.0).expanded(-2.0)


def test_wide_camera_intrinsics_shape_the_window() -> None:
    # The same scene seen with twice the focal length: the window doubles about the centre.
    landmark = PointLandmark("corner", 10.0, 0.3, 2.0)
    the_map = _map(HeadingWedge(0.0, 0.02, 0.02))
    narrow = Camera(CameraIntrinsics(500.0, 500.0, 0.0, 0.0, 640, 480), CameraMount(height=1.0))
    wide = Camera(CameraIntrinsics(1000.0, 1000.0, 0.0, 0.0, 640, 480), CameraMount(height=1.0))
    a = Expecter(narrow).bounds(the_map, landmark)
    b = Expecter(wide).bounds(the_map, landmark)
    assert a is not None
    assert b is not None
    assert b.width == pytest.approx(2.0 * a.width, rel=1e-6)
    assert b.height == pytest.approx(2.0 * a.height, rel=1e-6)
