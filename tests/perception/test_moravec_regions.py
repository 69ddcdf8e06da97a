"""Moravec's interest operator and the region segmenter on synthetic images."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums.errors import InputError
from aura_ums.expecter import ImageWindow
from aura_ums.perception import MoravecOperator, Region, RegionSegmenter, otsu_threshold


def checkerboard(size: int = 80, square: int = 20) -> np.ndarray:
    v, u = np.mgrid[0:size, 0:size]
    return np.where(((u // square) + (v // square)) % 2 == 0, 40.0, 210.0)


def test_checkerboard_corners_are_found() -> None:
    points = MoravecOperator(suppression=4).find(checkerboard())
    # Inner corners of an 80 px board of 20 px squares: at 19.5, 39.5, 59.5 in each axis.
    expected = np.array([(u, v) for u in (19.5, 39.5, 59.5) for v in (19.5, 39.5, 59.5)])
    assert points.shape == (9, 3)
    distance = np.hypot(*(points[:, None, :2] - expected[None]).transpose(2, 0, 1))
    assert distance.min(axis=0).max() <= 1.0  # X-junctions are symmetric: found within a pixel
    assert np.all(points[:, 2] > 1000.0)


def test_single_corner_is_found_near_it() -> None:
    image = np.zeros((40, 40))
    image[20:, 20:] = 200.0
    points = MoravecOperator().find(image)
    assert points.shape == (1, 3)
    assert np.hypot(points[0, 0] - 19.5, points[0, 1] - 19.5) <= 2.5


def test_straight_edges_give_no_corner() -> None:
    image = np.zeros((40, 40))
    image[:, 20:] = 200.0  # vertical edge
    assert MoravecOperator().find(image).shape == (0, 3)
    image = np.zeros((40, 40))
    image[np.triu_indices(40)] = 200.0  # diagonal edge
    assert MoravecOperator().find(image).shape == (0, 3)


def test_weak_noise_stays_below_threshold() -> None:
    rng = np.random.default_rng(1)
    assert MoravecOperator(threshold=200.0).find(rng.normal(100.0, 3.0, (60, 60))).shape == (0, 3)


def test_window_offsets_and_restriction() -> None:
    board = checkerboard()
    points = MoravecOperator(suppression=4).find(board, ImageWindow(30.0, 30.0, 50.0, 50.0))
    assert points.shape == (1, 3)
    assert points[0, :2] == pytest.approx([39.5, 39.5], abs=1.0)
    with pytest.raises(InputError, match="window: expected a window overlapping the 80 x 80 image"):
        MoravecOperator().find(board, ImageWindow(-30.0, 0.0, -10.0, 5.0))


def test_empty_and_tiny_images() -> None:
    assert MoravecOperator().find(np.zeros((0, 0))).shape == (0, 3)
    assert MoravecOperator().find(np.zeros((5, 5))).shape == (0, 3)


@given(du=st.integers(0, 30), dv=st.integers(0, 30))
def test_translating_content_translates_points(du: int, dv: int) -> None:
    image = np.zeros((100, 100))
    image[30:50, 30:45] = 180.0
    moved = np.roll(image, (dv, du), axis=(0, 1))
    before = MoravecOperator().find(image)
    after = MoravecOperator().find(moved)
    assert after[:, :2] == pytest.approx(before[:, :2] + [du, dv])


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"size": 4}, "size: expected an odd integer, got 4"),
        ({"size": 1}, "size: expected an integer >= 3, got 1"),
        ({"suppression": 0}, "suppression: expected an integer >= 1"),
        ({"threshold": -1.0}, "threshold: expected a non-negative number"),
    ],
)
def test_moravec_bad_parameters(kwargs: dict[str, object], message: str) -> None:
    with pytest.raises(InputError, match=message):
        MoravecOperator(**kwargs)  # type: ignore[arg-type]


def test_moravec_bad_image() -> None:
    with pytest.raises(InputError, match=r"expected a 2-D grayscale array \(h, w\), got shape \(4, 4, 3\)"):
        MoravecOperator().find(np.zeros((4, 4, 3)))


def test_regions_of_two_blocks() -> None:
    image = np.full((60, 80), 30, dtype=np.uint8)
    image[10:20, 10:30] = 200  # 200 pixels
    image[40:50, 50:55] = 220  # 50 pixels
    regions = RegionSegmenter().find(image)
    assert [(r.area, r.bright) for r in regions] == [(4550, False), (200, True), (50, True)]
    block = regions[1]
    assert block == Region(200, 200.0, (10, 10, 29, 19), (19.5, 14.5), True)


def test_regions_in_a_window_are_in_full_image_coordinates() -> None:
    image = np.full((60, 80), 30.0)
    image[40:50, 50:55] = 220.0
    regions = RegionSegmenter(threshold=100.0, min_area=5).find(image, ImageWindow(45, 35, 70, 55))
    bright = [r for r in regions if r.bright]
    assert len(bright) == 1
    assert bright[0].bbox == (50, 40, 54, 49)
    assert bright[0].centroid == (52.0, 44.5)


def test_regions_min_area_and_flat_image() -> None:
    image = np.full((20, 20), 9.0)
    regions = RegionSegmenter().find(image)
    assert regions == (Region(400, 9.0, (0, 0, 19, 19), (9.5, 9.5), False),)
    assert RegionSegmenter(min_area=401).find(image) == ()
    assert RegionSegmenter().find(np.zeros((0, 5))) == ()


def test_otsu_separates_two_populations() -> None:
    rng = np.random.default_rng(2)
    pixels = np.concatenate([rng.normal(50, 5, 500), rng.normal(180, 5, 500)]).reshape(20, 50)
    assert 70.0 < otsu_threshold(pixels) < 160.0
    with pytest.raises(InputError, match="image: expected at least one pixel"):
        otsu_threshold(np.zeros((0, 3)))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [({"threshold": np.nan}, "threshold: expected a finite number"), ({"min_area": 0}, "min_area: expected")],
)
def test_region_bad_parameters(kwargs: dict[str, object], message: str) -> None:
    with pytest.raises(InputError, match=message):
        RegionSegmenter(**kwargs)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("bins", "message"),
    [
        (0, r"^bins: expected an integer in \[2, 1000000\], got 0$"),
        (1, r"^bins: expected an integer in \[2, 1000000\], got 1$"),
        (1.5, r"^bins: expected an integer in \[2, 1000000\], got 1\.5$"),
        ("3", r"^bins: expected an integer in \[2, 1000000\], got '3'$"),
        (True, r"^bins: expected an integer in \[2, 1000000\], got True$"),
        (
            10**12,
            r"^bins: expected an integer in \[2, 1000000\], got 1000000000000 "
            r"\(about 4\.8e\+04 GB of histogram\)$",
        ),
    ],
)
def test_otsu_bad_bins(bins: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        otsu_threshold(np.zeros((4, 4)), bins)  # type: ignore[arg-type]
    two: Any = np.int64(2)  # numpy integers are integers
    assert otsu_threshold([[10, 10, 200, 200]], two) == otsu_threshold([[10, 10, 200, 200]], 2)


@pytest.mark.parametrize(
    "call", [otsu_threshold, MoravecOperator().find, MoravecOperator().response, RegionSegmenter().find]
)
def test_gray_levels_beyond_the_range_are_refused(call: object) -> None:
    assert callable(call)
    with pytest.raises(
        InputError, match=r"^image: expected gray levels a number in \[-1e\+12, 1e\+12\], got -1e\+300"
    ):
        call(np.full((8, 8), -1e300))
    call(np.full((8, 8), -1e12))  # the range's end: no overflow (warnings are errors)


def test_region_bad_image() -> None:
    with pytest.raises(InputError, match="got dtype bool"):
        RegionSegmenter().find(np.zeros((4, 4), dtype=bool))
