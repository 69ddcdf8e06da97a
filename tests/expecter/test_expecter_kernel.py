"""The compiled Expecter kernel against the numpy reference, the fallback, and the kernel's bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from expecter_helpers import (
    CAMERAS,
    extreme_poses,
    landmark_points,
    random_landmark,
    random_map,
    visible_pixels,
)

from aura_ums.expecter import Expecter, ImageWindow
from aura_ums.expecter import _expecter as expecter_module
from aura_ums.expecter._expecter import _bounds
from aura_ums.geometry import ConvexPolygon, HeadingWedge
from aura_ums.uncertainty import (
    GroundLineLandmark,
    Landmark,
    PointLandmark,
    SpatialUncertaintyMap,
    VerticalLineLandmark,
)

KERNEL = expecter_module._compiled_expecter_points
compiled = pytest.mark.skipif(KERNEL is None, reason="the C kernels were not built (no compiler)")

#: Window sides far off the image (under distortion near the camera plane) come from a
#: branch and bound stopped after a fixed number of rounds: both paths are sound there, but
#: their last digits need not agree. Within this many pixels of the image they must.
NEAR_IMAGE = 1e6


def sides(window: ImageWindow) -> tuple[float, float, float, float]:
    return (window.u_min, window.v_min, window.u_max, window.v_max)


def assert_agree(first: ImageWindow | None, second: ImageWindow | None, label: str) -> None:
    assert (first is None) == (second is None), f"{label}: {first} vs {second}"
    if first is None or second is None:
        return
    for a, b in zip(sides(first), sides(second), strict=True):
        if abs(b) < NEAR_IMAGE:
            assert abs(a - b) <= 1e-9 * max(1.0, abs(b)), f"{label}: {first} vs {second}"


def random_case(rng: np.random.Generator, index: int) -> tuple[str, SpatialUncertaintyMap, Landmark]:
    name = list(CAMERAS)[index % len(CAMERAS)]
    the_map = random_map(rng, wide_wedge=index % 4 == 3)
    if index % 11 == 5:  # every heading
        the_map = SpatialUncertaintyMap(the_map.polygon, the_map.center, HeadingWedge.full_circle(0.3))
    elif index % 11 == 7:  # one heading
        the_map = SpatialUncertaintyMap(the_map.polygon, the_map.center, HeadingWedge(0.1, 0.0, 0.0))
    landmark = random_landmark(rng, ("I", "II", "III")[index % 3], the_map.center, ahead=index % 5 != 2)
    return name, the_map, landmark


@compiled
def test_compiled_kernel_agrees_with_the_numpy_reference(rng: np.random.Generator) -> None:
    nones = 0
    for index in range(600):
        name, the_map, landmark = random_case(rng, index)
        expecter = Expecter(CAMERAS[name])
        ours = _bounds(expecter, the_map, landmark, compiled=True)
        reference = _bounds(expecter, the_map, landmark, compiled=False)
        assert_agree(ours, reference, f"case {index} ({name})")
        nones += ours is None
    assert 0 < nones < 300  # both outcomes were exercised


@compiled
@pytest.mark.parametrize(
    "landmark",
    [
        VerticalLineLandmark("flat_pole", 6.0, 0.5, 1.0, 1.0, position_uncertainty=0.2),  # one level
        PointLandmark("exact", 8.0, -1.0, 0.5),  # no position disk
        GroundLineLandmark("across", (0.5, -4.0), (0.5, 4.0), position_uncertainty=0.1),  # partly behind
        VerticalLineLandmark("inside", 0.2, 0.0, 0.0, 3.0),  # inside the polygon: cut by the plane
    ],
)
def test_degenerate_and_cut_cases_agree(landmark: Landmark) -> None:
    expecter = Expecter(CAMERAS["tilted_panned_offset"])
    for polygon in (
        ConvexPolygon([(-0.5, -0.2), (0.5, -0.2), (0.5, 0.2), (-0.5, 0.2)]),
        ConvexPolygon([(0.0, 0.0)]),  # a point
        ConvexPolygon([(-0.4, 0.0), (0.4, 0.1)]),  # a segment
    ):
        center = polygon.vertices.mean(axis=0)
        for wedge in (HeadingWedge(0.0, 0.0, 0.0), HeadingWedge(0.2, 0.3, 0.1), HeadingWedge.full_circle()):
            the_map = SpatialUncertaintyMap(polygon, center, wedge)
            assert_agree(
                _bounds(expecter, the_map, landmark, compiled=True),
                _bounds(expecter, the_map, landmark, compiled=False),
                f"{landmark.id}, {polygon.vertex_count} vertices, {wedge}",
            )


@pytest.mark.parametrize("kind", ["I", "II", "III"])
def test_numpy_fallback_is_sound(kind: str, rng: np.random.Generator) -> None:
    # The fallback is what runs without a compiler: the soundness tests cover the kernel.
    for name, camera in CAMERAS.items():
        expecter = Expecter(camera)
        the_map = random_map(rng, wide_wedge=name == "distorted")
        landmark = random_landmark(rng, kind, the_map.center)
        poses = np.vstack([the_map.sample_poses(500, rng), extreme_poses(the_map)])
        pixels = visible_pixels(camera, poses, landmark_points(landmark, rng))
        window = _bounds(expecter, the_map, landmark, compiled=False)
        if window is None:
            assert len(pixels) == 0
            continue
        assert np.all((pixels[:, 0] >= window.u_min) & (pixels[:, 0] <= window.u_max)), name
        assert np.all((pixels[:, 1] >= window.v_min) & (pixels[:, 1] <= window.v_max)), name


def test_bounds_falls_back_when_the_extension_is_missing(monkeypatch: pytest.MonkeyPatch) -> None:
    expecter = Expecter(CAMERAS["plain"])
    the_map = SpatialUncertaintyMap.from_polygon(
        ConvexPolygon([(-0.3, -0.1), (0.3, -0.1), (0.3, 0.1), (-0.3, 0.1)]),
        (0.0, 0.0),
        HeadingWedge(0, 0.05, 0.05),
    )
    pole = VerticalLineLandmark("pole", 9.0, 0.5, 0.0, 4.0, position_uncertainty=0.1)
    monkeypatch.setattr(expecter_module, "_compiled_expecter_points", None)
    window = expecter.bounds(the_map, pole)
    assert window == _bounds(expecter, the_map, pole, compiled=False)
    assert window is not None
    assert window.width > 0.0


@compiled
@pytest.mark.parametrize(
    ("change", "error", "match"),
    [
        ({"vertices": np.zeros((3, 3))}, ValueError, r"vertices: expected a C-contiguous \(n, 2\) float64"),
        ({"vertices": np.zeros((3, 2), dtype=np.float32)}, ValueError, "got format 'f'"),
        ({"vertices": "abc"}, TypeError, "vertices: expected"),
        ({"base_count": 3}, ValueError, r"base_count: expected an integer in \[1, 2\], got 3"),
        ({"level_count": 0}, ValueError, r"level_count: expected an integer in \[1, 2\], got 0"),
        ({"radius": math.nan}, ValueError, "radius: expected a finite number"),
        ({"radius": -1.0}, ValueError, "expected radius >= 0"),
        ({"arc_step": 0.0}, ValueError, "arc_step > 0"),
        ({"forward": "x"}, TypeError, "forward: expected a real number, got str"),
    ],
)
def test_kernel_refuses_bad_arguments(change: dict[str, object], error: type[Exception], match: str) -> None:
    arguments: dict[str, object] = {
        "vertices": np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
        "base_count": 1,
        "disk_sides": 64,
        "full_circle": 0,
        "level_count": 2,
        "base_ax": 5.0,
        "base_ay": 0.0,
        "base_bx": 5.0,
        "base_by": 0.0,
        "radius": 0.1,
        "heading_lo": -0.1,
        "heading_width": 0.2,
        "arc_step": math.pi / 64,
    }
    names = [f"r{i}{j}" for i in range(3) for j in range(3)]
    rotation = dict(zip(names, Expecter(CAMERAS["plain"])._rotation, strict=True))
    arguments |= rotation | {"forward": 0.0, "left": 0.0, "dz_lo": -1.0, "dz_hi": 2.0, "cut_plane": 5e-7}
    assert KERNEL is not None
    assert KERNEL(*arguments.values()) is not None  # the unchanged call works
    arguments |= change
    with pytest.raises(error, match=match):
        KERNEL(*arguments.values())
