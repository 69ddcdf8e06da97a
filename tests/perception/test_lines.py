"""The fast line finder on synthetic images: positions, windows, orientation, bad input."""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from aura_ums.errors import InputError, MissingDependencyError
from aura_ums.expecter import ImageWindow
from aura_ums.perception import FastLineFinder, LineBackend, LineSegments, orientation_difference

VERTICAL = math.pi / 2


def step_edge(
    height: int = 120, width: int = 160, column: int = 80, low: float = 20, high: float = 200
) -> np.ndarray:
    image = np.full((height, width), low, dtype=np.float64)
    image[:, column:] = high
    return image


def tilted_edge(angle: float, height: int = 120, width: int = 160) -> np.ndarray:
    """Bright on one side of a line through the centre with direction ``angle`` (antialiased)."""
    v, u = np.mgrid[0:height, 0:width].astype(np.float64)
    cu, cv = (width - 1) / 2, (height - 1) / 2
    signed = -(u - cu) * math.sin(angle) + (v - cv) * math.cos(angle)
    return np.asarray(30.0 + 170.0 * np.clip(signed + 0.5, 0.0, 1.0))


def test_vertical_step_edge_is_found_where_it_is() -> None:
    lines = FastLineFinder(VERTICAL).find_detailed(step_edge())
    assert len(lines) == 1
    x1, y1, x2, y2 = lines.segments[0]
    assert x1 == pytest.approx(79.5)
    assert x2 == pytest.approx(79.5)
    assert sorted([y1, y2]) == pytest.approx([1.0, 118.0])
    assert lines.contrast[0] == pytest.approx(90.0)  # step 180 -> gradient 90 on both sides
    assert lines.orientation[0] == pytest.approx(VERTICAL)


def test_dark_to_light_and_light_to_dark_bars_give_two_lines() -> None:
    image = np.zeros((100, 100))
    image[:, 40:60] = 150.0  # a bright bar: two edges of opposite polarity
    segments = FastLineFinder(VERTICAL).find(image)
    assert sorted(segments[:, 0]) == pytest.approx([39.5, 59.5])


@pytest.mark.parametrize("finder", [FastLineFinder(VERTICAL), FastLineFinder(overlap=False)])
def test_touching_edges_of_opposite_polarity_stay_two_lines(finder: FastLineFinder) -> None:
    # A 2-pixel bar: the dark-to-light support (columns 39, 40) touches the
    # light-to-dark support (41, 42); one region across both would be one fat line.
    image = np.zeros((100, 100))
    image[:, 40:42] = 150.0
    lines = finder.find_detailed(image)
    assert len(lines) == 2
    assert sorted(lines.midpoints[:, 0]) == pytest.approx([39.5, 41.5])


@pytest.mark.parametrize("degrees", [0.0, 20.0, 45.0, 70.0, 110.0, 160.0])
def test_tilted_edge_direction_and_position(degrees: float) -> None:
    angle = math.radians(degrees)
    image = tilted_edge(angle)
    lines = FastLineFinder(angle, tolerance=math.radians(3)).find_detailed(image)
    assert len(lines) >= 1
    best = lines.select([0])
    assert orientation_difference(best.orientation, angle)[0] < math.radians(1.5)
    assert best.length[0] > 80.0
    # The midpoint lies on the edge through the image centre.
    mu, mv = best.midpoints[0]
    distance = -(mu - 79.5) * math.sin(angle) + (mv - 59.5) * math.cos(angle)
    assert abs(distance) < 0.75


@pytest.mark.parametrize("overlap", [True, False])
def test_untuned_finds_every_direction(overlap: bool) -> None:
    image = np.full((120, 160), 40.0)
    image[20:100, 30:130] = 200.0  # a rectangle: two horizontal and two vertical edges
    lines = FastLineFinder(min_length=30, overlap=overlap).find_detailed(image)
    horizontal = lines.within(0.0, math.radians(2))
    vertical = lines.within(VERTICAL, math.radians(2))
    assert len(horizontal) == 2
    assert len(vertical) == 2
    assert sorted(horizontal.midpoints[:, 1]) == pytest.approx([19.5, 99.5], abs=0.01)
    assert sorted(vertical.midpoints[:, 0]) == pytest.approx([29.5, 129.5], abs=0.01)


def test_overlap_keeps_a_line_on_a_bucket_border_whole() -> None:
    # Gradient direction 22.5 deg off an axis sits on a border of 8 buckets (45 deg wide).
    angle = VERTICAL + math.radians(22.5)
    image = tilted_edge(angle, 160, 160)
    with_overlap = FastLineFinder(min_length=20, overlap=True).find_detailed(image)
    assert with_overlap.length.max() > 150.0
    assert len(with_overlap.within(angle, math.radians(3))) >= 1


def test_orientation_filtering() -> None:
    image = np.full((120, 160), 40.0)
    image[20:100, 30:130] = 200.0
    assert len(FastLineFinder(VERTICAL, min_length=30).find(image)) == 2
    assert len(FastLineFinder(0.0, min_length=30).find(image)) == 2
    assert len(FastLineFinder(math.radians(45), min_length=30).find(image)) == 0
    # Buckets tuned to 100 degrees still hold the vertical edges; the tolerance decides.
    assert len(FastLineFinder(math.radians(100), tolerance=math.radians(5), min_length=30).find(image)) == 0
    assert len(FastLineFinder(math.radians(100), tolerance=math.radians(12), min_length=30).find(image)) == 2


def test_length_and_contrast_filters() -> None:
    image = step_edge(low=100, high=110)  # contrast 5 gray levels per pixel
    assert len(FastLineFinder(VERTICAL).find(image)) == 1
    assert len(FastLineFinder(VERTICAL, min_contrast=6.0).find(image)) == 0
    assert len(FastLineFinder(VERTICAL, min_gradient=6.0).find(image)) == 0
    assert len(FastLineFinder(VERTICAL, min_length=200.0).find(image)) == 0


def test_window_gives_full_image_coordinates() -> None:
    image = step_edge()
    window = ImageWindow(60.0, 30.0, 100.0, 70.0)
    segments = FastLineFinder(VERTICAL).find(image, window)
    assert segments.shape == (1, 4)
    assert segments[0, [0, 2]] == pytest.approx([79.5, 79.5])
    assert sorted(segments[0, [1, 3]]) == pytest.approx([30.0, 70.0])


def test_window_excluding_the_edge_finds_nothing() -> None:
    assert FastLineFinder(VERTICAL).find(step_edge(), ImageWindow(0, 0, 60, 119)).shape == (0, 4)


def test_window_partly_outside_is_clipped() -> None:
    segments = FastLineFinder(VERTICAL).find(step_edge(), ImageWindow(70, -50, 300, 60.2))
    assert segments[0, [0, 2]] == pytest.approx([79.5, 79.5])
    assert sorted(segments[0, [1, 3]]) == pytest.approx([1.0, 60.0])


def test_window_outside_the_image_is_an_error() -> None:
    with pytest.raises(InputError, match="window: expected a window overlapping the 160 x 120 image"):
        FastLineFinder(VERTICAL).find(step_edge(), ImageWindow(200, 0, 300, 50))


def test_window_of_the_wrong_type_is_an_error() -> None:
    with pytest.raises(InputError, match="window: expected an ImageWindow or None"):
        FastLineFinder().find(step_edge(), (0, 0, 10, 10))  # type: ignore[arg-type]


@pytest.mark.parametrize(
    "image",
    [np.zeros((50, 60)), np.full((50, 60), 255, dtype=np.uint8), np.zeros((0, 0)), np.zeros((2, 2))],
    ids=["zeros", "flat-uint8", "no-pixels", "tiny"],
)
def test_empty_or_flat_image_gives_no_segments(image: np.ndarray) -> None:
    for finder in (FastLineFinder(), FastLineFinder(VERTICAL), FastLineFinder(overlap=False)):
        result = finder.find(image)
        assert result.shape == (0, 4)
        assert result.dtype == np.float64


def test_noise_gives_no_long_lines() -> None:
    rng = np.random.default_rng(3)
    noise = rng.normal(128.0, 4.0, (120, 160))
    assert FastLineFinder(VERTICAL, min_length=15).find(noise).shape == (0, 4)


def test_noisy_edge_is_still_found() -> None:
    rng = np.random.default_rng(4)
    image = step_edge(low=60, high=120) + rng.normal(0.0, 6.0, (120, 160))
    segments = FastLineFinder(VERTICAL, min_length=60, smoothing=1.0).find(image)
    assert len(segments) >= 1
    assert abs(segments[0, 0] - 79.5) < 1.0
    assert abs(segments[0, 2] - 79.5) < 1.0


@pytest.mark.parametrize(
    ("image", "message"),
    [
        (np.zeros((10, 10, 3)), r"image: expected a 2-D grayscale array \(h, w\), got shape \(10, 10, 3\)"),
        (np.zeros(10), r"expected a 2-D grayscale array \(h, w\), got shape \(10,\)"),
        (np.zeros((10, 10), dtype=bool), "expected integers or floats .*got dtype bool"),
        (np.zeros((10, 10), dtype=complex), "got dtype complex128"),
        ([["a", "b"], ["c", "d"]], "got dtype <U1"),
        (
            np.full((10, 10), 1e300),
            r"^image: expected gray levels a number in \[-1e\+12, 1e\+12\], "
            r"got 1e\+300 at pixel \(u=0, v=0\)$",
        ),
        (
            np.full((10, 10), -(2**62), dtype=np.int64),
            r"^image: expected gray levels a number in \[-1e\+12, 1e\+12\], "
            r"got -4611686018427387904 at pixel",
        ),
    ],
)
def test_bad_images_are_input_errors(image: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        FastLineFinder().find(image)  # type: ignore[arg-type]


def test_gray_levels_up_to_the_range_are_taken_without_overflow() -> None:
    image = step_edge().astype(np.float64) * (1e12 / 255.0)
    assert FastLineFinder(VERTICAL).find(image).shape[0] >= 1
    assert FastLineFinder(smoothing=2.0).find(-image).shape[0] >= 1
    wide = np.full((10, 10), 2**40, dtype=np.int64)  # 64-bit integers are checked, not refused as a type
    with pytest.raises(
        InputError, match=r"^image: expected gray levels .*, got 1099511627776 at pixel \(u=0, v=0\)$"
    ):
        FastLineFinder().find(wide)
    assert FastLineFinder().find(wide // 2**20).shape == (0, 4)


def test_nan_pixel_is_an_input_error_naming_the_pixel() -> None:
    image = step_edge()
    image[7, 12] = np.nan
    with pytest.raises(InputError, match=r"expected finite gray levels, got nan at pixel \(u=12, v=7\)"):
        FastLineFinder().find(image)
    # Outside the window (and its context) the NaN is never read.
    assert FastLineFinder(VERTICAL).find(image, ImageWindow(60, 30, 100, 70)).shape == (1, 4)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"orientation": math.nan}, "orientation: expected a finite number"),
        ({"tolerance": -0.1}, "tolerance: expected a non-negative number"),
        ({"min_length": "long"}, "min_length: expected a finite number"),
        ({"min_gradient": 0.0}, "min_gradient: expected a positive number"),
        ({"buckets": 3}, r"^buckets: expected an integer in \[4, 360\], got 3$"),
        ({"buckets": 8.0}, r"^buckets: expected an integer in \[4, 360\], got 8\.0$"),
        (
            {"buckets": 10**6},
            r"^buckets: expected an integer in \[4, 360\], got 1000000 \(about 1e\+03 GB of bucket masks per "
            r"megapixel, and as many labellings\)$",
        ),
        ({"overlap": 1}, "overlap: expected a bool"),
        ({"backend": "numpy"}, "backend: expected a LineBackend"),
    ],
)
def test_bad_parameters(kwargs: dict[str, object], message: str) -> None:
    with pytest.raises(InputError, match=message):
        FastLineFinder(**kwargs)  # type: ignore[arg-type]


def test_orientation_is_taken_modulo_pi() -> None:
    assert FastLineFinder(VERTICAL + math.pi).orientation == pytest.approx(VERTICAL)
    assert FastLineFinder(-VERTICAL).orientation == pytest.approx(VERTICAL)


def test_results_sorted_by_strength() -> None:
    image = np.full((100, 120), 50.0)
    image[:, 30:] = 90.0  # weak edge
    image[:, 80:] = 250.0  # strong edge
    lines = FastLineFinder(VERTICAL).find_detailed(image)
    assert list(lines.midpoints[:, 0]) == pytest.approx([79.5, 29.5])
    assert np.all(np.diff(lines.strength) <= 0)


@given(
    du=st.integers(-20, 20),
    dv=st.integers(-20, 20),
    degrees=st.floats(0.0, 179.0),
    tuned=st.booleans(),
)
def test_translating_the_content_translates_the_lines(du: int, dv: int, degrees: float, tuned: bool) -> None:
    angle = math.radians(degrees)
    base = np.full((140, 140), 60.0)
    base[30:110, 30:110] = tilted_edge(angle, 80, 80)
    moved = np.roll(base, (dv, du), axis=(0, 1))  # the content stays clear of the borders
    finder = FastLineFinder(angle if tuned else None, min_length=12)
    before = finder.find_detailed(base).segments + np.array([du, dv, du, dv])
    after = finder.find_detailed(moved).segments
    assert before.shape == after.shape
    for segment in after:  # endpoints in either order
        direct = np.abs(before - segment).max(axis=1)
        swapped = np.abs(before[:, [2, 3, 0, 1]] - segment).max(axis=1)
        assert min(direct.min(), swapped.min()) < 1e-6


@given(u0=st.integers(0, 60), v0=st.integers(0, 40))
def test_segments_from_a_window_lie_in_it(u0: int, v0: int) -> None:
    image = np.full((120, 160), 40.0)
    image[20:100, 30:130] = 200.0
    image[40:60, 50:52] = 90.0
    finder = FastLineFinder(min_length=5)
    in_window = finder.find(image, ImageWindow(u0, v0, u0 + 99, v0 + 79))
    assert in_window.shape[0] >= 1
    # Endpoints are on the fitted line, so they may stick out of the region by a hair.
    assert np.all(in_window[:, [0, 2]] >= u0 - 0.5)
    assert np.all(in_window[:, [0, 2]] <= u0 + 99.5)
    assert np.all(in_window[:, [1, 3]] >= v0 - 0.5)
    assert np.all(in_window[:, [1, 3]] <= v0 + 79.5)
    # Every segment of the window is part of a segment of the whole image.
    whole = finder.find_detailed(image)
    window_lines = finder.find_detailed(image, ImageWindow(u0, v0, u0 + 99, v0 + 79))
    for midpoint, angle in zip(window_lines.midpoints, window_lines.orientation, strict=True):
        near = orientation_difference(whole.orientation, angle) < math.radians(2)
        a, b = whole.segments[near, :2], whole.segments[near, 2:]
        t = np.clip(np.einsum("ij,ij->i", midpoint - a, b - a) / np.einsum("ij,ij->i", b - a, b - a), 0, 1)
        assert np.min(np.hypot(*(a + t[:, None] * (b - a) - midpoint).T)) < 1.0


def test_opencv_backend_matches_numpy() -> None:
    pytest.importorskip("cv2", reason="the opencv extra is not installed")
    rng = np.random.default_rng(8)
    image = np.full((120, 160), 40.0)
    image[20:100, 30:130] = 200.0
    image += rng.normal(0.0, 3.0, image.shape)
    for orientation in (None, VERTICAL):
        numpy_lines = FastLineFinder(orientation, backend=LineBackend.NUMPY).find(image)
        opencv_lines = FastLineFinder(orientation, backend=LineBackend.OPENCV).find(image)
        assert numpy_lines.shape == opencv_lines.shape
        order_n = np.lexsort(numpy_lines.T.round(3))
        order_o = np.lexsort(opencv_lines.T.round(3))
        assert opencv_lines[order_o] == pytest.approx(numpy_lines[order_n], abs=1e-3)


def test_missing_opencv_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "cv2", None)
    with pytest.raises(
        MissingDependencyError, match=r"optional 'opencv' extra \(pip install 'aura-ums\[opencv\]'\)"
    ):
        FastLineFinder(backend=LineBackend.OPENCV)


def test_line_segments_value_type() -> None:
    lines = LineSegments([[0.0, 0.0, 3.0, 4.0]], [2.0])
    assert lines.length.tolist() == [5.0]
    assert lines.strength.tolist() == [10.0]
    with pytest.raises(ValueError, match="read-only"):
        lines.segments[0, 0] = 1.0
    with pytest.raises(InputError, match=r"LineSegments.segments: expected shape \(n, 4\), got \(1, 3\)"):
        LineSegments([[0.0, 0.0, 3.0]], [2.0])
    with pytest.raises(InputError, match=r"LineSegments.contrast: expected shape \(1,\), got \(2,\)"):
        LineSegments([[0.0, 0.0, 3.0, 4.0]], [2.0, 1.0])
    with pytest.raises(InputError, match="LineSegments: expected finite values"):
        LineSegments([[0.0, 0.0, 3.0, np.inf]], [2.0])
