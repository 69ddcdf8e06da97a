"""Benchmark perception: milliseconds on a full York Urban frame and on a 160 x 120 window.

Run: ``.venv/bin/python benchmarks/bench_perception.py [path/to/york_urban]``. Without the
argument it reads ``../shared/data/york_urban`` beside the repository, and skips (saying so)
when that folder is not there.

For each detector, the median time of ``find`` on a full 640 x 480 frame and on a
160 x 120 window (the centre of the frame), over the first 5 images, each repeated;
and the ratio full frame / window (the pixel ratio is 16). Target: the line finder tuned
to an orientation (what a Class I or III find-landmark schema runs) at most 2 ms per
160 x 120 window. Speed depends on the machine and its load; nothing here is asserted.
"""

from __future__ import annotations

import math
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from aura_ums.expecter import ImageWindow
from aura_ums.perception import (
    FastLineFinder,
    LineBackend,
    MoravecOperator,
    OpenCvLineFinder,
    RegionSegmenter,
)
from aura_ums.perception._york_urban import load_york_urban, york_urban_names

DEFAULT_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "york_urban"
WINDOW = ImageWindow(240.0, 180.0, 399.0, 299.0)  # 160 x 120 pixels at the centre
VERTICAL = math.pi / 2

Finder = Callable[[NDArray[np.uint8], ImageWindow | None], object]


def median_ms(
    find: Finder, images: list[NDArray[np.uint8]], window: ImageWindow | None, repeats: int
) -> float:
    for image in images:
        find(image, window)
    times = []
    for _ in range(repeats):
        for image in images:
            start = time.perf_counter()
            find(image, window)
            times.append(time.perf_counter() - start)
    return 1e3 * statistics.median(times)


def main() -> None:
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT_DATA
    if len(sys.argv) == 1 and not folder.is_dir():
        # make bench runs every benchmark: one whose data is elsewhere says so and lets the rest run.
        print(f"York Urban images not found at {folder}: skipped (pass their folder as the argument)")
        return
    images = [item.image for item in load_york_urban(folder, york_urban_names(folder)[:5])]
    detectors: dict[str, Finder] = {
        "FLF tuned pi/2, numpy": FastLineFinder(VERTICAL).find,
        "FLF untuned, overlap, numpy": FastLineFinder().find,
        "FLF untuned, no overlap, numpy": FastLineFinder(overlap=False).find,
        "Moravec 5x5": MoravecOperator().find,
        "region segmenter (Otsu)": RegionSegmenter().find,
    }
    try:
        import cv2  # noqa: F401
    except ImportError:
        print("OpenCV not installed: OpenCV rows skipped (pip install 'aura-ums[opencv]')")
    else:
        detectors["FLF tuned pi/2, opencv"] = FastLineFinder(VERTICAL, backend=LineBackend.OPENCV).find
        detectors["FLF untuned, overlap, opencv"] = FastLineFinder(backend=LineBackend.OPENCV).find
        detectors["LSD (OpenCV), filtered pi/2"] = OpenCvLineFinder(VERTICAL).find
        detectors["LSD (OpenCV), all"] = OpenCvLineFinder().find
    print(f"median ms per call over {len(images)} York Urban frames (target: FLF tuned <= 2 ms per window)")
    print()
    print(f"{'detector':<32}{'640x480 ms':>12}{'160x120 ms':>12}{'full/window':>13}")
    for name, find in detectors.items():
        full = median_ms(find, images, None, 4)
        window = median_ms(find, images, WINDOW, 60)
        print(f"{name:<32}{full:>12.2f}{window:>12.3f}{full / window:>13.1f}")


if __name__ == "__main__":
    main()
