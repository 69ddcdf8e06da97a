"""The fast line finder on real photographs (York Urban): vertical recall at least LSD's.

Skips when the dataset (``york_urban`` in ``tests.conftest.SHARED_DATA``) is absent;
the comparison with LSD needs the ``opencv`` extra. The 10 images are held out from the
tuning of the finder's parameters (tuned on the odd-indexed images; see
``benchmarks/eval_york_urban.py``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from aura_ums.perception import FastLineFinder, OpenCvLineFinder, RecallPrecision, segment_recall_precision
from aura_ums.perception._york_urban import YorkUrbanImage, load_york_urban, york_urban_names
from tests.conftest import SHARED_DATA

YORK_URBAN = SHARED_DATA / "york_urban"
VERTICAL = math.pi / 2
TOLERANCE = math.radians(10.0)

pytestmark = pytest.mark.skipif(
    not (YORK_URBAN / "segments.csv").is_file(),
    reason=f"York Urban dataset not found at {YORK_URBAN} (see docs/getting-real-data.md)",
)


@pytest.fixture(scope="module")
def held_out() -> list[YorkUrbanImage]:
    names = york_urban_names(YORK_URBAN)[0::2][:10]
    return load_york_urban(YORK_URBAN, names)


def _pooled(finder: FastLineFinder | OpenCvLineFinder, images: list[YorkUrbanImage]) -> RecallPrecision:
    total = RecallPrecision(0, 0, 0, 0)
    for item in images:
        found = finder.find(item.image)
        total = total + segment_recall_precision(found, item.segments[item.vertical], reference=item.segments)
    return total


def test_images_and_segments_load(held_out: list[YorkUrbanImage]) -> None:
    assert len(held_out) == 10
    for item in held_out:
        assert item.image.shape == (480, 640)
        assert item.image.dtype == np.uint8
        assert item.segments.shape[1] == 4
        assert item.vertical.any()


def test_vertical_recall_is_high(held_out: list[YorkUrbanImage]) -> None:
    counts = _pooled(FastLineFinder(VERTICAL, TOLERANCE, 10.0, min_gradient=4.0), held_out)
    assert counts.recall > 0.75
    assert counts.precision > 0.25  # a lower bound: only Manhattan segments are annotated


def test_vertical_recall_at_least_lsd(held_out: list[YorkUrbanImage]) -> None:
    pytest.importorskip("cv2", reason="the opencv extra (LSD baseline) is not installed")
    ours = _pooled(FastLineFinder(VERTICAL, TOLERANCE, 10.0, min_gradient=4.0), held_out)
    lsd = _pooled(OpenCvLineFinder(VERTICAL, TOLERANCE, 0.0), held_out)
    assert ours.recall >= lsd.recall, (ours, lsd)
