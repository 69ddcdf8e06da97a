"""Perception: line finder, interest operator and region segmenter, run on image windows.

Works on plain 2-D grayscale arrays ``(h, w)`` (integers or finite floats, gray levels
0-255 for the default thresholds) and an optional
:class:`~aura_ums.expecter.ImageWindow`; knows nothing of maps. Every detector processes
only the pixels its window overlaps and reports positions in full-image pixels, with
``(0, 0)`` at the centre of the top-left pixel (DESIGN §1). Evaluation functions turn
what a detector found into a value compared with a landmark's recognition threshold,
per landmark class. :func:`segment_recall_precision` measures line detection against
annotated segments (the York Urban benchmark).

Examples
--------
>>> import numpy as np
>>> from aura_ums.expecter import ImageWindow
>>> image = np.zeros((120, 160), dtype=np.uint8)
>>> image[:, 80:] = 180                                    # a vertical edge at u = 79.5
>>> finder = FastLineFinder(orientation=np.pi / 2, min_length=20)
>>> lines = finder.find_detailed(image, ImageWindow(60, 20, 100, 100))
>>> found = evaluate_vertical_line(lines)
>>> found.column, found.value >= 500.0                     # column, and over a threshold
(79.5, True)
"""

from aura_ums.perception._evaluate import RecallPrecision, sample_points, segment_recall_precision
from aura_ums.perception._image import read_gray_image
from aura_ums.perception._landmarks import (
    CornerEvidence,
    LineEvidence,
    evaluate_corner,
    evaluate_path_edge,
    evaluate_vertical_line,
    line_intersections,
    strongest_within,
)
from aura_ums.perception._lines import FastLineFinder, LineBackend
from aura_ums.perception._moravec import MoravecOperator
from aura_ums.perception._opencv import OpenCvLineFinder
from aura_ums.perception._regions import Region, RegionSegmenter, otsu_threshold
from aura_ums.perception._segments import LineSegments, orientation_difference, segment_orientation

__all__ = [
    "CornerEvidence",
    "FastLineFinder",
    "LineBackend",
    "LineEvidence",
    "LineSegments",
    "MoravecOperator",
    "OpenCvLineFinder",
    "RecallPrecision",
    "Region",
    "RegionSegmenter",
    "evaluate_corner",
    "evaluate_path_edge",
    "evaluate_vertical_line",
    "line_intersections",
    "orientation_difference",
    "otsu_threshold",
    "read_gray_image",
    "sample_points",
    "segment_orientation",
    "segment_recall_precision",
    "strongest_within",
]
