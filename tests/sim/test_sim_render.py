from __future__ import annotations

import math

import numpy as np
import pytest
from matplotlib.path import Path as MplPath
from numpy.typing import NDArray

from aura_ums.camera import Camera, CameraIntrinsics, CameraMount, fold_radius
from aura_ums.errors import InputError
from aura_ums.perception import FastLineFinder, evaluate_vertical_line
from aura_ums.sim import Building, GroundStripe, Pole, Scene, SyntheticCamera
from aura_ums.sim._render import fill_polygon
from aura_ums.uncertainty import PointLandmark, Pose
from aura_ums.world import sample_world

PAPER_CAMERA = Camera(
    CameraIntrinsics(549.0, 549.0, 255.5, 239.5, 512, 480), CameraMount(1.2, tilt=math.radians(3.0))
)
FINDER = FastLineFinder(orientation=math.pi / 2, min_length=30.0)


def _paper_scene(seed: int = 0, *, clutter: int = 30) -> Scene:
    return Scene.from_meadow_map(sample_world("paper_sidewalk"), np.random.default_rng(seed), clutter=clutter)


def _with(base: Scene, *, poles: tuple[Pole, ...] = (), buildings: tuple[Building, ...] = ()) -> Scene:
    return Scene(
        poles=poles, buildings=buildings, patches=base.patches, stripes=base.stripes, texture=base.texture
    )


def _column_at(
    camera: Camera, pose: Pose, bottom: tuple[float, float, float], top: tuple[float, float, float], v: float
) -> float:
    """Image column of the projected vertical segment bottom-top at image row v."""
    (ub, vb), (ut, vt) = camera.project(pose, [bottom, top])
    return float(ub + (v - vb) * (ut - ub) / (vt - vb))


def test_image_has_the_camera_size_and_is_deterministic_per_seed() -> None:
    scene = _paper_scene()
    pose = Pose(1.0, 0.1, 0.05)
    first = SyntheticCamera(PAPER_CAMERA, scene, np.random.default_rng(5), clutter_lines=5)
    second = SyntheticCamera(PAPER_CAMERA, scene, np.random.default_rng(5), clutter_lines=5)
    images = [first.render(pose), first.render(pose)]
    assert images[0].shape == (480, 512)
    assert images[0].dtype == np.uint8
    assert np.array_equal(images[0], second.render(pose))
    assert np.array_equal(images[1], second.render(pose))
    assert not np.array_equal(images[0], images[1])  # fresh noise and clutter each frame
    other = SyntheticCamera(PAPER_CAMERA, scene, np.random.default_rng(6), clutter_lines=5)
    assert not np.array_equal(images[0], other.render(pose))


def test_scene_is_deterministic_per_seed() -> None:
    a, b, c = _paper_scene(1), _paper_scene(1), _paper_scene(2)
    assert a.texture is not None
    assert b.texture is not None
    assert c.texture is not None
    assert np.array_equal(a.texture, b.texture)
    assert [s.start.tolist() for s in a.stripes] == [s.start.tolist() for s in b.stripes]
    assert not np.array_equal(a.texture, c.texture)


def test_without_noise_the_image_depends_on_the_pose_only() -> None:
    scene = _paper_scene()
    pose = Pose(2.0, -0.2, 0.1)
    a = SyntheticCamera(PAPER_CAMERA, scene, np.random.default_rng(1), noise=0.0).render(pose)
    b = SyntheticCamera(PAPER_CAMERA, scene, np.random.default_rng(2), noise=0.0).render(pose)
    assert np.array_equal(a, b)


@pytest.mark.parametrize("seed", range(6))
def test_thin_pole_is_found_by_the_line_finder_at_its_projected_column(seed: int) -> None:
    rng = np.random.default_rng(seed)
    x, y = rng.uniform(8.0, 15.0), rng.uniform(-3.0, 3.0)
    pose = Pose(rng.uniform(-1.0, 1.0), rng.uniform(-0.5, 0.5), rng.uniform(-0.25, 0.25))
    pole = Pole(x, y, 0.0, 5.0, radius=0.02)
    camera = SyntheticCamera(
        PAPER_CAMERA, _with(_paper_scene(seed), poles=(pole,)), rng, noise=2.0, clutter_lines=5
    )
    found = evaluate_vertical_line(FINDER.find_detailed(camera.render(pose)))
    assert found.point is not None
    expected = _column_at(PAPER_CAMERA, pose, (x, y, 0.0), (x, y, 5.0), found.point[1])
    assert abs(found.point[0] - expected) <= 2.0


@pytest.mark.parametrize("seed", range(4))
def test_thick_pole_edges_bracket_the_projected_column(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    x, y = rng.uniform(6.0, 12.0), rng.uniform(-2.0, 2.0)
    pose = Pose(0.0, 0.0, rng.uniform(-0.2, 0.2))
    pole = Pole(x, y, 0.0, 6.0, radius=0.15)
    image = SyntheticCamera(PAPER_CAMERA, _with(_paper_scene(seed), poles=(pole,)), rng).render(pose)
    ((u, _),) = PAPER_CAMERA.project(pose, [(x, y, 2.0)])
    half_width = 0.15 * 549.0 / math.hypot(x - pose.x, y - pose.y)
    lines = FINDER.find_detailed(image)
    columns = 0.5 * (lines.segments[:, 0] + lines.segments[:, 2])
    left = columns[(columns < u) & (columns > u - half_width - 3.0)]
    right = columns[(columns > u) & (columns < u + half_width + 3.0)]
    assert len(left)
    assert len(right)
    assert abs(0.5 * (left.mean() + right.mean()) - u) <= 2.0


def test_building_corner_edge_is_found_at_the_projected_corner() -> None:
    world = sample_world("paper_sidewalk")
    scene = Scene.from_meadow_map(world, np.random.default_rng(0), clutter=0)
    corner = world.landmark("east_engineering_corner").landmark
    assert isinstance(corner, PointLandmark)
    pose = Pose(3.0, 0.0, 0.2)
    image = SyntheticCamera(PAPER_CAMERA, scene, np.random.default_rng(0)).render(pose)
    (_, v_top), (_, v_bottom) = PAPER_CAMERA.project(
        pose, [(corner.x, corner.y, 7.0), (corner.x, corner.y, 0.0)]
    )
    lines = FINDER.find_detailed(image)
    mid_u = 0.5 * (lines.segments[:, 0] + lines.segments[:, 2])
    mid_v = 0.5 * (lines.segments[:, 1] + lines.segments[:, 3])
    on_corner = (mid_v > v_top) & (mid_v < v_bottom)
    expected = np.array(
        [
            _column_at(PAPER_CAMERA, pose, (corner.x, corner.y, 0.0), (corner.x, corner.y, 7.0), v)
            for v in mid_v
        ]
    )
    assert np.any(on_corner & (np.abs(mid_u - expected) <= 2.0))


def test_landmarks_behind_the_camera_are_not_drawn() -> None:
    base = _paper_scene()
    pose = Pose(5.0, 0.0, 0.0)
    behind = (Pole(1.0, 0.3, 0.0, 8.0, 0.3), Pole(-3.0, -2.0, 0.0, 8.0, 0.3))
    shed = (Building([(0.0, -1.0), (2.0, -1.0), (2.0, 1.0), (0.0, 1.0)], 0.0, 4.0),)
    empty = SyntheticCamera(PAPER_CAMERA, _with(base), np.random.default_rng(9)).render(pose)
    drawn = SyntheticCamera(PAPER_CAMERA, _with(base, poles=behind, buildings=shed), np.random.default_rng(9))
    assert np.array_equal(drawn.render(pose), empty)
    assert np.all(np.isnan(PAPER_CAMERA.project(pose, [(1.0, 0.3, 4.0), (-3.0, -2.0, 4.0)])))


def test_object_straddling_the_camera_plane_is_clipped_not_mirrored() -> None:
    pose = Pose(0.0, 0.0, 0.0)
    # a wall running from behind the robot to 10 m ahead, 2 m to its left
    wall = Building([(-5.0, 2.0), (10.0, 2.0), (10.0, 2.5), (-5.0, 2.5)], 0.0, 3.0, shades=(30.0, 30.0))
    image = SyntheticCamera(
        PAPER_CAMERA, Scene(buildings=(wall,)), np.random.default_rng(0), noise=0.0
    ).render(pose)
    dark = image == 30
    assert dark[:, :100].any()  # its visible part is on the left
    assert not dark[:, 300:].any()  # nothing mirrored to the right


def test_painter_order_puts_the_nearer_pole_in_front() -> None:
    near = Pole(5.0, 0.0, 0.0, 3.0, 0.2, shade=20.0)
    far = Pole(10.0, 0.0, 0.0, 6.0, 0.4, shade=250.0)
    for poles in ((near, far), (far, near)):
        camera = SyntheticCamera(PAPER_CAMERA, Scene(poles=poles), np.random.default_rng(0), noise=0.0)
        image = camera.render(Pose(0.0, 0.0, 0.0))
        ((u, v),) = PAPER_CAMERA.project(Pose(0.0, 0.0, 0.0), [(5.0, 0.0, 1.0)])
        assert image[round(v), round(u)] == 20


def test_ground_stripe_is_drawn_where_it_projects() -> None:
    stripe = GroundStripe((3.0, -0.5), (12.0, -0.5), 0.2, 250.0)
    pose = Pose(0.0, 0.0, 0.0)
    image = SyntheticCamera(
        PAPER_CAMERA, Scene(stripes=(stripe,)), np.random.default_rng(0), noise=0.0
    ).render(pose)
    pixels = PAPER_CAMERA.project(pose, [(x, -0.5, 0.0) for x in (4.0, 6.0, 9.0)])
    for u, v in pixels:
        assert image[round(v), round(u)] == 250


def test_sky_above_and_ground_below_the_horizon() -> None:
    scene = Scene(ground_shade=100.0, sky_shades=(200.0, 200.0))
    image = SyntheticCamera(PAPER_CAMERA, scene, np.random.default_rng(0), noise=0.0).render(
        Pose(0.0, 0.0, 0.0)
    )
    horizon = 239.5 - 549.0 * math.tan(math.radians(3.0))
    assert np.all(image[: math.floor(horizon) - 1] == 200)
    assert np.all(image[math.ceil(horizon) + 1 :] == 100)


def test_noise_has_the_requested_spread() -> None:
    scene = Scene(ground_shade=100.0, sky_shades=(100.0, 100.0))
    image = SyntheticCamera(PAPER_CAMERA, scene, np.random.default_rng(0), noise=5.0).render(
        Pose(0.0, 0.0, 0.0)
    )
    assert float(image.mean()) == pytest.approx(100.0, abs=0.1)
    assert float(image.std()) == pytest.approx(5.0, rel=0.05)


def _random_polygon(rng: np.random.Generator, convex: bool) -> NDArray[np.float64]:
    n = int(rng.integers(3, 9))
    angles = np.sort(rng.uniform(0.0, 2.0 * math.pi, n))
    radii = np.full(n, rng.uniform(3.0, 25.0)) if convex else rng.uniform(3.0, 25.0, n)
    centre = rng.uniform(-5.0, 45.0, 2)
    return np.column_stack([centre[0] + radii * np.cos(angles), centre[1] + radii * np.sin(angles)])


@pytest.mark.parametrize("convex", [True, False])
def test_fill_polygon_matches_matplotlib_contains_points(convex: bool) -> None:
    rng = np.random.default_rng(11)
    vv, uu = np.mgrid[0:40, 0:50]
    centres = np.column_stack([uu.ravel(), vv.ravel()]).astype(float)
    for _ in range(30):
        polygon = _random_polygon(rng, convex)
        image = np.zeros((40, 50), dtype=np.float32)
        fill_polygon(image, polygon, 1.0)
        inside = MplPath(polygon).contains_points(centres).reshape(40, 50)
        assert np.array_equal(image == 1.0, inside)


def test_bad_arguments_are_refused() -> None:
    for noise in (-1.0, 256.0, 1e300):
        with pytest.raises(InputError, match=r"noise: expected a number in \[0, 255\] gray levels, got "):
            SyntheticCamera(PAPER_CAMERA, Scene(), np.random.default_rng(0), noise=noise)
    many = r"clutter_lines: expected at most 1,000,000 lines \(.*: 190 s a frame\), got 1000000000000"
    with pytest.raises(InputError, match=many):
        SyntheticCamera(PAPER_CAMERA, Scene(), np.random.default_rng(0), clutter_lines=10**12)
    with pytest.raises(InputError, match="clutter_lines: expected an integer >= 0"):
        SyntheticCamera(PAPER_CAMERA, Scene(), np.random.default_rng(0), clutter_lines=-2)
    with pytest.raises(InputError, match="scene: expected a Scene"):
        SyntheticCamera(PAPER_CAMERA, None, np.random.default_rng(0))  # type: ignore[arg-type]
    camera = SyntheticCamera(PAPER_CAMERA, Scene(), np.random.default_rng(0))
    with pytest.raises(InputError, match="pose: expected a Pose"):
        camera.render((0.0, 0.0, 0.0))  # type: ignore[arg-type]


def test_distorted_camera_renders() -> None:
    intrinsics = CameraIntrinsics(
        500.0, 500.0, 319.5, 239.5, 640, 480, distortion=(-0.1, 0.01, 0.0, 0.0, 0.0)
    )
    camera = Camera(intrinsics, CameraMount(1.0, tilt=0.05))
    scene = Scene(poles=(Pole(8.0, 0.0, 0.0, 5.0, 0.2),))
    image = SyntheticCamera(camera, scene, np.random.default_rng(0), noise=0.0).render(Pose(0.0, 0.0, 0.0))
    ((u, v),) = camera.project(Pose(0.0, 0.0, 0.0), [(8.0, 0.0, 2.0)])
    assert image[round(v), round(u)] == 45


#: A barrel lens on a wide image: it folds 57 degrees off axis (r = 1.543), and the image's
#: corners lie beyond the image of the fold, where it images nothing.
FOLDING_CAMERA = Camera(
    CameraIntrinsics(300.0, 300.0, 319.5, 239.5, 640, 480, distortion=(-0.14, 0.0, 0.0, 0.0, 0.0)),
    CameraMount(1.0),
)


def test_a_pole_beyond_the_lens_fold_is_not_drawn() -> None:
    # 63 degrees to the left of the optical axis the polynomial put the pole at u = 49, inside
    # the image, over the rays of 43 degrees; the camera images no ray beyond the fold.
    pose = Pose(0.0, 0.0, 0.0)
    pole = Pole(1.0, math.tan(math.radians(63.0)), 0.0, 2.0, 0.05, shade=20.0)
    empty = SyntheticCamera(FOLDING_CAMERA, Scene(), np.random.default_rng(0), noise=0.0).render(pose)
    drawn = SyntheticCamera(FOLDING_CAMERA, Scene(poles=(pole,)), np.random.default_rng(0), noise=0.0)
    assert np.array_equal(drawn.render(pose), empty)
    assert np.isnan(FOLDING_CAMERA.project(pose, [(pole.x, pole.y, 1.0)])).all()


def test_a_wall_crossing_the_lens_fold_is_drawn_up_to_it() -> None:
    # A wall 1 m to the left from 3 m ahead to 0.1 m ahead: 18 to 84 degrees off axis. Its part
    # within the fold is drawn where it projects; nothing is drawn past the fold's image.
    pose = Pose(0.0, 0.0, 0.0)
    wall = Building([(0.1, 1.0), (3.0, 1.0), (3.0, 1.2), (0.1, 1.2)], 0.0, 1.5, shades=(30.0, 30.0))
    image = SyntheticCamera(
        FOLDING_CAMERA, Scene(buildings=(wall,)), np.random.default_rng(0), noise=0.0
    ).render(pose)
    for ahead in (1.0, 2.0, 2.9):  # 45, 27 and 19 degrees off axis, at the camera's height
        ((u, v),) = FOLDING_CAMERA.project(pose, [(ahead, 1.0, 1.0)])
        assert image[round(v), round(u)] == 30
    limit = fold_radius(FOLDING_CAMERA.intrinsics.distortion)
    fold_image = limit * (1.0 - 0.14 * limit**2)  # the distorted radius of the fold
    vv, uu = np.mgrid[0:480, 0:640]
    outside = np.hypot((uu - 319.5) / 300.0, (vv - 239.5) / 300.0) > fold_image * 1.001
    assert not (image[outside] == 30).any()
    assert (image[~outside] == 30).sum() > 1000
