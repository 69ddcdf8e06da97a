"""The line finder's and Class I evaluation's unchecked fast paths against their public references."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from aura_ums.expecter import ImageWindow
from aura_ums.perception import (
    FastLineFinder,
    LineSegments,
    evaluate_vertical_line,
    orientation_difference,
    strongest_within,
)


def clutter(seed: int, height: int = 90, width: int = 120) -> np.ndarray:
    """Random bars and boxes of random gray levels: lines of many directions and contrasts."""
    rng = np.random.default_rng(seed)
    image = np.full((height, width), rng.uniform(20, 60))
    v, u = np.mgrid[0:height, 0:width]
    for _ in range(8):
        angle, offset = rng.uniform(0, math.pi), rng.uniform(-40, 40)
        signed = (u - width / 2) * math.sin(angle) - (v - height / 2) * math.cos(angle) - offset
        image[np.abs(signed) < rng.uniform(1, 6)] = rng.uniform(0, 255)
    return image + rng.normal(0.0, 2.0, image.shape)


@settings(max_examples=40, deadline=None)
@given(
    st.integers(0, 10_000),
    st.floats(0.0, math.pi),
    st.floats(0.02, 0.5),
    st.sampled_from([0.0, 3.0, 12.0]),
    st.booleans(),
)
def test_tuned_filter_equals_orientation_difference_on_all_lines(
    seed: int, orientation: float, tolerance: float, min_contrast: float, windowed: bool
) -> None:
    image = clutter(seed)
    window = ImageWindow(10.3, 7.8, 101.2, 70.6) if windowed else None
    tuned = FastLineFinder(
        orientation, tolerance=tolerance, min_length=8.0, min_contrast=min_contrast
    ).find_detailed(image, window)
    every = FastLineFinder(orientation, tolerance=math.pi / 2, min_length=8.0).find_detailed(image, window)
    near = orientation_difference(every.orientation, orientation) <= tolerance
    keep = near & (every.contrast >= min_contrast)
    assert tuned.segments.tobytes() == every.segments[keep].tobytes()
    assert tuned.contrast.tobytes() == every.contrast[keep].tobytes()


@pytest.mark.parametrize("seed", range(6))
def test_strongest_within_equals_evaluate_vertical_line(seed: int) -> None:
    lines = FastLineFinder(orientation=None, min_length=5.0).find_detailed(clutter(seed))
    assert len(lines) > 0
    for orientation, tolerance in ((math.pi / 2, 0.2), (0.3, 0.05), (1.0, 0.0)):
        assert strongest_within(lines, orientation, tolerance) == evaluate_vertical_line(
            lines, orientation=orientation, tolerance=tolerance
        )
    assert strongest_within(LineSegments.empty(), 1.0, 0.1).segment is None
