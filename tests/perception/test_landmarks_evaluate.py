"""Evaluation functions per landmark class, the recall/precision metric, and image reading."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import matplotlib.image
import numpy as np
import pytest

from aura_ums.errors import FileFormatError, InputError
from aura_ums.expecter import ImageWindow
from aura_ums.perception import (
    FastLineFinder,
    LineSegments,
    MoravecOperator,
    OpenCvLineFinder,
    RecallPrecision,
    evaluate_corner,
    evaluate_path_edge,
    evaluate_vertical_line,
    line_intersections,
    read_gray_image,
    sample_points,
    segment_recall_precision,
    strongest_within,
)


def test_class_one_picks_the_strongest_vertical_line() -> None:
    image = np.full((120, 160), 60.0)
    image[:, 50:] = 90.0  # weak vertical edge at 49.5
    image[:, 110:] = 230.0  # strong vertical edge at 109.5
    image[100:, :] = 250.0  # a strong horizontal edge: wrong direction
    lines = FastLineFinder().find_detailed(image)
    found = evaluate_vertical_line(lines)
    assert found.found
    assert found.column == pytest.approx(109.5, abs=0.05)
    assert found.point is not None
    assert found.segment is not None
    assert found.value == pytest.approx(lines.within(math.pi / 2, 0.1).strength.max())


def test_class_one_nothing_found() -> None:
    found = evaluate_vertical_line(LineSegments([[0, 0, 50, 1]], [40.0]))
    assert not found.found
    assert found.value == 0.0
    assert found.column is None


def test_class_three_path_edge() -> None:
    image = np.full((120, 160), 80.0)
    v, u = np.mgrid[0:120, 0:160]
    image[v > 119 - 0.5 * u] = 160.0  # an edge rising to the right
    image[10:14, 10:20] = 250.0  # a short strong blob
    lines = FastLineFinder().find_detailed(image)
    angle = math.atan2(-0.5, 1.0) % math.pi
    edge = evaluate_path_edge(lines, angle, min_length=60)
    assert edge.found
    assert edge.segment is not None
    x1, y1, x2, y2 = edge.segment
    assert math.hypot(x2 - x1, y2 - y1) > 100
    assert evaluate_path_edge(lines, angle + 0.5).found is False


def test_class_two_corner_from_points_and_lines() -> None:
    image = np.full((80, 80), 40.0)
    image[30:, 30:] = 200.0  # a building corner at (29.5, 29.5)
    image[60:64, 5:9] = 120.0  # a small blob: another interest point
    points = MoravecOperator().find(image)
    lines = FastLineFinder(min_length=15).find_detailed(image)
    corner = evaluate_corner(points, lines)
    assert corner.supported
    assert corner.point is not None
    assert corner.intersection is not None
    assert math.dist(corner.point, (29.5, 29.5)) <= 3.0
    assert math.dist(corner.intersection, (29.5, 29.5)) <= 1.0
    alone = evaluate_corner(points)
    assert not alone.supported
    assert alone.value == pytest.approx(points[:, 2].max())


def test_class_two_bad_input() -> None:
    with pytest.raises(InputError, match=r"points: expected a finite \(n, 3\) array"):
        evaluate_corner([[1.0, 2.0]])
    with pytest.raises(InputError, match="lines: expected LineSegments, got list"):
        evaluate_corner([[1.0, 2.0, 3.0]], [[0, 0, 1, 1]])  # type: ignore[arg-type]
    with pytest.raises(InputError, match="lines: expected LineSegments, got list"):
        evaluate_vertical_line([[0, 0, 1, 1]])  # type: ignore[arg-type]


def test_intersections_need_different_directions_and_nearness() -> None:
    parallel = LineSegments([[0, 0, 0, 10], [2, 0, 2, 10]], [1.0, 1.0])
    assert line_intersections(parallel, radius=5, min_angle=0.3).shape == (0, 2)
    far = LineSegments([[0, 0, 0, 10], [20, 30, 40, 30]], [1.0, 1.0])  # meet at (0, 30): far away
    assert line_intersections(far, radius=5, min_angle=0.3).shape == (0, 2)


def test_recall_precision_metric() -> None:
    truth = np.array([[10.0, 0.0, 10.0, 100.0]])
    assert segment_recall_precision(truth, truth).recall == 1.0
    assert segment_recall_precision(truth + np.array([1.5, 0, 1.5, 0]), truth).recall == 1.0
    assert segment_recall_precision(truth + np.array([2.5, 0, 2.5, 0]), truth).recall == 0.0
    tilted = np.array([[10.0, 0.0, 14.0, 100.0]])  # 2.3 degrees off
    assert segment_recall_precision(tilted, truth).recall > 0.5
    assert segment_recall_precision(tilted, truth, angle_tolerance=math.radians(1)).recall == 0.0
    half = segment_recall_precision([[10.0, 0.0, 10.0, 50.0], [60.0, 0.0, 60.0, 50.0]], truth)
    assert half.recall == pytest.approx(53 / 101)
    assert half.precision == pytest.approx(0.5)
    nothing = segment_recall_precision(np.zeros((0, 4)), truth)
    assert nothing.recall == 0.0
    assert math.isnan(nothing.precision)
    other = segment_recall_precision(
        truth + np.array([30, 0, 30, 0]),
        truth,
        reference=np.vstack([truth, truth + np.array([30, 0, 30, 0])]),
    )
    assert other.recall == 0.0
    assert other.precision == 1.0


def test_recall_precision_pooling_and_bad_input() -> None:
    assert RecallPrecision(1, 2, 3, 4) + RecallPrecision(1, 2, 1, 4) == RecallPrecision(2, 4, 4, 8)
    with pytest.raises(InputError, match=r"detected: expected shape \(n, 4\), got \(2,\)"):
        segment_recall_precision([1.0, 2.0], np.zeros((0, 4)))
    with pytest.raises(InputError, match="step: expected a positive number"):
        segment_recall_precision(np.zeros((0, 4)), np.zeros((0, 4)), step=0.0)
    with pytest.raises(InputError, match="ground_truth: expected finite coordinates"):
        segment_recall_precision(np.zeros((0, 4)), [[0, 0, np.nan, 1]])


def test_read_gray_image_png_and_jpeg(tmp_path: Path) -> None:
    rgb = np.zeros((8, 10, 3), dtype=np.uint8)
    rgb[..., 0] = 200
    rgb[:, 5:, 1] = 100
    png = tmp_path / "a.png"
    matplotlib.image.imsave(png, rgb)
    gray = read_gray_image(png)
    assert gray.dtype == np.uint8
    assert gray.shape == (8, 10)
    assert gray[0, 0] == round(0.299 * 200)
    assert gray[0, 9] == round(0.299 * 200 + 0.587 * 100)
    jpeg = tmp_path / "a.jpg"
    matplotlib.image.imsave(jpeg, rgb)  # JPEG through Pillow
    assert read_gray_image(jpeg).shape == (8, 10)


LINES = LineSegments([[0.0, 0.0, 10.0, 0.0], [0.0, 0.0, 0.0, 10.0]], [10.0, 10.0])
SEGMENTS = np.array([[0.0, 0.0, 10.0, 0.0], [0.0, 0.0, 0.0, 10.0]])
NONE: Any = None


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (
            lambda: line_intersections(LINES, radius=NONE, min_angle=0.5),
            "^radius: expected a finite number, got None$",
        ),
        (
            lambda: line_intersections(LINES, radius=math.nan, min_angle=0.5),
            "^radius: expected a finite number, got nan$",
        ),
        (
            lambda: line_intersections(LINES, radius=4.0, min_angle=[1.0, 2.0]),  # type: ignore[arg-type]
            r"^min_angle: expected a finite number, got \[1\.0, 2\.0\]$",
        ),
        (
            lambda: line_intersections(NONE, radius=4.0, min_angle=0.5),
            "^lines: expected LineSegments, got NoneType$",
        ),
        (lambda: strongest_within(NONE, 0.0, 0.1), "^lines: expected LineSegments, got NoneType$"),
        (lambda: strongest_within(LINES, 0.0, math.nan), "^tolerance: expected a finite number, got nan$"),
        (lambda: strongest_within(LINES, "abc", 0.1), "^orientation: expected a finite number, got 'abc'$"),  # type: ignore[arg-type]
        (lambda: sample_points(SEGMENTS, 0.0), "^step: expected a positive number, got 0.0$"),
        (lambda: sample_points(SEGMENTS, math.nan), "^step: expected a finite number, got nan$"),
        (lambda: sample_points([1.0, 2.0]), r"^segments: expected shape \(n, 4\), got \(2,\)$"),
        (
            lambda: sample_points(SEGMENTS, 1e-300),
            r"^step: expected a step that makes at most 10000000 sample points \(about 0\.48 GB\), "
            r"got 1e-300, which makes 2e\+301 \(about 9\.6e\+293 GB\)$",
        ),
        (
            lambda: segment_recall_precision(SEGMENTS, SEGMENTS, step=1e-7),
            "^step: expected a step that makes at most 10000000 sample points",
        ),
        (lambda: read_gray_image(NONE), "^path: expected a str or PathLike, got NoneType$"),
    ],
)
def test_segment_tools_refuse_bad_input(call: object, match: str) -> None:
    assert callable(call)
    with pytest.raises(InputError, match=match):
        call()


def test_segment_tools_give_what_they_gave() -> None:
    points, owner = sample_points([[0, 0, 1, 1]])
    assert points.tolist() == [[0.0, 0.0], [0.5, 0.5], [1.0, 1.0]]
    assert owner.tolist() == [0, 0, 0]
    assert strongest_within(LINES, math.pi / 2, 0.1).segment == (0.0, 0.0, 0.0, 10.0)
    assert line_intersections(LINES, radius=1.0, min_angle=0.5).tolist() == [[0.0, 0.0]]


def test_read_gray_image_errors(tmp_path: Path) -> None:
    with pytest.raises(FileFormatError, match=r"missing\.jpg: expected a readable image file"):
        read_gray_image(tmp_path / "missing.jpg")
    junk = tmp_path / "junk.jpg"
    junk.write_text("not an image")
    with pytest.raises(FileFormatError, match=r"junk\.jpg: expected a readable image file"):
        read_gray_image(junk)


def test_opencv_lsd_baseline_interface() -> None:
    pytest.importorskip("cv2", reason="the opencv extra is not installed")
    image = np.full((120, 160), 40, dtype=np.uint8)
    image[20:100, 30:130] = 200
    vertical = OpenCvLineFinder(math.pi / 2).find_detailed(image)
    assert len(vertical) == 2
    assert sorted(vertical.midpoints[:, 0]) == pytest.approx([29.5, 129.5], abs=0.5)
    assert np.all(vertical.contrast > 30.0)
    in_window = OpenCvLineFinder(math.pi / 2).find(image, ImageWindow(100, 0, 159, 119))
    assert in_window.shape == (1, 4)
    assert in_window[0, 0] == pytest.approx(129.5, abs=0.5)
    assert OpenCvLineFinder().find(np.zeros((30, 30))).shape == (0, 4)
    assert OpenCvLineFinder().find(np.zeros((1, 30))).shape == (0, 4)
