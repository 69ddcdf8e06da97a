"""The compiled Expecter against its numpy reference on windows, and the reference's soundness.

The kernel's own input (and its bad input): tests/_native.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

import numpy as np
import pytest

from aura_ums import _native
from aura_ums._native import _expecter as native_expecter
from aura_ums.expecter import Expecter, ImageWindow
from aura_ums.geometry import ConvexPolygon, HeadingWedge
from aura_ums.uncertainty import (
    GroundLineLandmark,
    Landmark,
    PointLandmark,
    SpatialUncertaintyMap,
    VerticalLineLandmark,
)
from tests.expecter.expecter_helpers import (
    CAMERAS,
    extreme_poses,
    landmark_points,
    random_landmark,
    random_map,
    visible_pixels,
)

T = TypeVar("T")

compiled = pytest.mark.skipif(
    not _native.NATIVE, reason="the C kernels are not in use (not built, or AURA_UMS_NATIVE=0)"
)


def on_reference(call: Callable[..., T], *args: object) -> T:
    """Return ``call(*args)`` run on the numpy reference (the one switch turned off for it)."""
    saved, _native.expecter_points = _native.expecter_points, native_expecter.expecter_points_reference
    try:
        return call(*args)
    finally:
        _native.expecter_points = saved


def both(
    expecter: Expecter, the_map: SpatialUncertaintyMap, landmark: Landmark
) -> tuple[ImageWindow | None, ImageWindow | None]:
    """The window by the compiled kernel and by the numpy reference."""
    return expecter.bounds(the_map, landmark), on_reference(expecter.bounds, the_map, landmark)


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
        ours, reference = both(expecter, the_map, landmark)
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
                *both(expecter, the_map, landmark), f"{landmark.id}, {polygon.vertex_count} vertices, {wedge}"
            )


@pytest.mark.parametrize("kind", ["I", "II", "III"])
def test_numpy_reference_is_sound(kind: str, rng: np.random.Generator) -> None:
    # The reference is what runs without a compiler; the soundness tests cover whichever runs.
    for name, camera in CAMERAS.items():
        expecter = Expecter(camera)
        the_map = random_map(rng, wide_wedge=name == "distorted")
        landmark = random_landmark(rng, kind, the_map.center)
        poses = np.vstack([the_map.sample_poses(500, rng), extreme_poses(the_map)])
        pixels = visible_pixels(camera, poses, landmark_points(landmark, rng))
        window = on_reference(expecter.bounds, the_map, landmark)
        if window is None:
            assert len(pixels) == 0
            continue
        assert np.all((pixels[:, 0] >= window.u_min) & (pixels[:, 0] <= window.u_max)), name
        assert np.all((pixels[:, 1] >= window.v_min) & (pixels[:, 1] <= window.v_max)), name
