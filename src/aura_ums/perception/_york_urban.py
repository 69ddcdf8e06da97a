"""Reader of the York Urban Line Segment Database as a folder of ``images/`` and ``segments.csv``.

Denis, Elder & Estrada, "Efficient Edge-Based Methods for Estimating Manhattan Frames in
Urban Imagery", ECCV 2008 (where it is published: docs/getting-real-data.md). Used by the
perception benchmark and tests; images are read without OpenCV (:func:`read_gray_image`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from aura_ums._files import describe, load_csv
from aura_ums._validate import PIXEL
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


_COLUMNS = ("image", "x1", "y1", "x2", "y2", "vp", "vertical")


def _pixel(cell: str, column: str, source: str, line: int) -> float:
    try:
        value = float(cell)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and PIXEL.contains(value)):
        raise FileFormatError(
            source, "", f"expected {PIXEL.text()} in column {column!r}, got {describe(cell)}", line=line
        )
    return value


def _choice(cell: str, column: str, allowed: tuple[str, ...], source: str, line: int) -> int:
    if cell not in allowed:
        raise FileFormatError(
            source,
            "",
            f"expected one of {', '.join(allowed)} in column {column!r}, got {describe(cell)}",
            line=line,
        )
    return int(cell)


def york_urban_names(folder: Path) -> list[str]:
    """Names (``P...``) of the images in ``folder/images``, sorted."""
    return sorted(p.stem for p in (folder / "images").glob("P*.jpg"))


def load_york_urban(folder: Path, names: list[str] | None = None) -> list[YorkUrbanImage]:
    """Read images and segments from ``folder`` (``images/P*.jpg`` and ``segments.csv``).

    ``segments.csv`` is read like every CSV of aura-ums (:func:`aura_ums._files.load_csv`:
    UTF-8 with an optional BOM, size and row limits); coordinates are pixels in
    :data:`~aura_ums._validate.PIXEL`, ``vp`` is 1, 2 or 3 and ``vertical`` 0 or 1.

    Raises
    ------
    FileFormatError
        Naming the file and the line of a malformed row, or an image that does not load.
    """
    table = load_csv(folder / "segments.csv", columns=_COLUMNS, required=_COLUMNS)
    rows: dict[str, list[tuple[float, float, float, float, int, int]]] = {}
    for line, cells in zip(table.lines, table.rows, strict=True):
        row = dict(zip(table.header, cells, strict=True))
        coordinates = tuple(_pixel(row[name], name, table.source, line) for name in ("x1", "y1", "x2", "y2"))
        vp = _choice(row["vp"], "vp", ("1", "2", "3"), table.source, line)
        vertical = _choice(row["vertical"], "vertical", ("0", "1"), table.source, line)
        if not row["image"]:
            raise FileFormatError(
                table.source, "", "expected an image name in column 'image', got ''", line=line
            )
        rows.setdefault(row["image"], []).append((*coordinates, vp, vertical))  # type: ignore[arg-type]
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
