"""Reader of the York Urban Line Segment Database as a folder of ``images/`` and ``segments.csv``.

Denis, Elder & Estrada, "Efficient Edge-Based Methods for Estimating Manhattan Frames in
Urban Imagery", ECCV 2008 (where it is published: docs/getting-real-data.md). Used by the
perception benchmark and tests; images are read without OpenCV (:func:`read_gray_image`).
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from aura_ums.errors import FileFormatError
from aura_ums.perception._image import read_gray_image


@dataclass(frozen=True, slots=True)
class YorkUrbanImage:
    """One annotated image: its name, gray levels and segments.

    ``segments`` is ``(n, 4)`` ``x1, y1, x2, y2`` pixels ((0, 0) = centre of the top-left
    pixel), ``vp`` the Manhattan direction (1-3) of each and ``vertical`` whether that
    direction is the world vertical.
    """

    name: str
    image: NDArray[np.uint8]
    segments: NDArray[np.float64]
    vp: NDArray[np.int64]
    vertical: NDArray[np.bool_]


def york_urban_names(folder: Path) -> list[str]:
    """Names (``P...``) of the images in ``folder/images``, sorted."""
    return sorted(p.stem for p in (folder / "images").glob("P*.jpg"))


def load_york_urban(folder: Path, names: list[str] | None = None) -> list[YorkUrbanImage]:
    """Read images and segments from ``folder`` (``images/P*.jpg`` and ``segments.csv``)."""
    table = folder / "segments.csv"
    rows: dict[str, list[tuple[float, float, float, float, int, int]]] = {}
    try:
        with table.open(newline="") as handle:
            for line, row in enumerate(csv.DictReader(handle), start=2):
                try:
                    rows.setdefault(row["image"], []).append(
                        (
                            float(row["x1"]),
                            float(row["y1"]),
                            float(row["x2"]),
                            float(row["y2"]),
                            int(row["vp"]),
                            int(row["vertical"]),
                        )
                    )
                except (KeyError, TypeError, ValueError) as exc:
                    raise FileFormatError(str(table), "", f"expected numbers, got {row}", line=line) from exc
    except OSError as exc:
        raise FileFormatError(str(table), "", f"expected a readable file, got {exc}") from exc
    result = []
    for name in york_urban_names(folder) if names is None else names:
        data = np.array(rows.get(name, []), dtype=np.float64).reshape(-1, 6)
        result.append(
            YorkUrbanImage(
                name,
                read_gray_image(folder / "images" / f"{name}.jpg"),
                data[:, :4],
                data[:, 4].astype(np.int64),
                data[:, 5] == 1,
            )
        )
    return result
