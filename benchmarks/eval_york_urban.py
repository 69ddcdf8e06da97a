"""Accuracy of the fast line finder on the York Urban Line Segment Database, next to OpenCV's LSD.

Run: ``.venv/bin/python benchmarks/eval_york_urban.py [path/to/york_urban]``.

Data: Denis, Elder & Estrada, ECCV 2008 (51 images, 640 x 480), read from
the folder given, by default ``york_urban`` in the data folder beside the clone
(docs/getting-real-data.md). Task: the Class I landmark's, vertical lines.

- Ground truth for recall: the segments annotated ``vertical == 1`` (world verticals).
- Detectors tuned to the image vertical (orientation pi/2) with a tolerance of 10
  degrees: in these photographs world verticals are not exactly vertical in the image
  (camera tilt and roll); all 2802 annotated verticals lie within 9.6 degrees of it
  (95% within 4.3). LSD's segments are filtered to the same tolerance.
- Metric (:func:`aura_ums.perception.segment_recall_precision`): points every 1 px along
  ground-truth segments are recalled when within 2 px of a detected segment whose
  direction is within 5 degrees; precision is the same with roles swapped, against
  *all* annotated segments (any Manhattan direction). Only Manhattan-aligned segments are
  annotated, so precision is a lower bound. Counts are pooled over images.
- Tuning: the line finder's parameters (``min_gradient`` 4, ``min_length`` 10 px,
  8 buckets, no smoothing, no contrast filter) were chosen on the odd-indexed images of
  the sorted list (25 images) over a small grid (min_gradient 2-6, min_length 6-15,
  smoothing 0/0.8, buckets 8/12/16, min_contrast 0-10); the even-indexed images (26)
  are held out. Nothing is tuned per image. LSD runs with OpenCV's defaults. A second
  operating point (``min_contrast`` 8, from the same grid) trades recall for precision.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from aura_ums.perception import FastLineFinder, OpenCvLineFinder, RecallPrecision, segment_recall_precision
from aura_ums.perception._york_urban import YorkUrbanImage, load_york_urban

DEFAULT_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "york_urban"
VERTICAL = math.pi / 2
TOLERANCE = math.radians(10.0)

#: The line finder as tuned (on the odd-indexed images) for vertical lines.
TUNED_FINDER = FastLineFinder(VERTICAL, TOLERANCE, 10.0, min_gradient=4.0)


def evaluate(
    find: Callable[[NDArray[np.uint8]], NDArray[np.float64]], images: list[YorkUrbanImage]
) -> tuple[RecallPrecision, float]:
    """Pooled counts over ``images`` and the mean number of segments per image."""
    total = RecallPrecision(0, 0, 0, 0)
    segments = 0
    for item in images:
        found = find(item.image)
        segments += found.shape[0]
        total = total + segment_recall_precision(found, item.segments[item.vertical], reference=item.segments)
    return total, segments / max(len(images), 1)


def main() -> None:
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT_DATA
    start = time.perf_counter()
    images = load_york_urban(folder)
    splits = {
        "tuning (odd, 25)": images[1::2],
        "held out (even, 26)": images[0::2],
        f"all ({len(images)})": images,
    }
    detectors: dict[str, Callable[[NDArray[np.uint8]], NDArray[np.float64]]] = {
        "fast line finder": TUNED_FINDER.find,
        "FLF min_contrast 8": FastLineFinder(
            VERTICAL, TOLERANCE, 10.0, min_gradient=4.0, min_contrast=8.0
        ).find,
    }
    try:
        import cv2  # noqa: F401
    except ImportError:
        print("OpenCV not installed: LSD rows skipped (pip install 'aura-ums[opencv]')")
    else:
        detectors["LSD (all lengths)"] = OpenCvLineFinder(VERTICAL, TOLERANCE, 0.0).find
        detectors["LSD (>= 10 px)"] = OpenCvLineFinder(VERTICAL, TOLERANCE, 10.0).find
    print("York Urban, vertical lines: recall of vertical==1 segments, precision against all annotated")
    print("(points every 1 px, matched within 2 px and 5 deg; detectors tuned to pi/2 +- 10 deg)")
    print()
    print(f"{'split':<22}{'detector':<20}{'recall':>8}{'precision':>11}{'segments/image':>16}")
    for split, subset in splits.items():
        for name, find in detectors.items():
            counts, per_image = evaluate(find, subset)
            print(f"{split:<22}{name:<20}{counts.recall:>8.3f}{counts.precision:>11.3f}{per_image:>16.1f}")
    print(f"\n({time.perf_counter() - start:.0f} s)")


if __name__ == "__main__":
    main()
