"""The docs pages of the file formats list every physical range exactly as the readers check it."""

from __future__ import annotations

from pathlib import Path

import pytest

from aura_ums._validate import Range
from aura_ums.camera import _io as camera_io
from aura_ums.logs import _calibrate, _io, _mrclam
from aura_ums.sim import _scenario
from aura_ums.uncertainty import TerrainStats

DOCS = Path(__file__).resolve().parents[1] / "docs"


def _rows(ranges: dict[str, Range]) -> list[str]:
    return [f"| `{key}` | {bounds.interval()} |" for key, bounds in ranges.items()]


def _meta_rows() -> list[str]:
    return [
        f"| `{f'[{table}] ' if table else ''}{key}` | {bounds.interval()} |"
        for table, keys in _io._META_KEYS.items()
        for key, (_, _, bounds) in keys.items()
        if bounds is not None
    ]


def _camera_rows() -> list[str]:
    return [
        f"| `[{table}]` | `{key}` | {bounds.interval()} |"
        for table, keys in camera_io.KEY_RANGES.items()
        for key, bounds in keys.items()
    ]


@pytest.mark.parametrize(
    ("page", "rows"),
    [
        ("formats.md", _rows(TerrainStats.field_ranges())),
        ("formats.md", _rows(_calibrate.KEY_RANGES)),
        ("formats.md", _camera_rows()),
        ("formats.md", _rows(_scenario.KEY_RANGES)),
        ("log-format.md", _meta_rows()),
        ("log-format.md", _rows(_io.COLUMN_RANGES)),
        ("log-format.md", _rows(_mrclam.COLUMN_RANGES)),
    ],
)
def test_every_range_is_documented(page: str, rows: list[str]) -> None:
    text = (DOCS / page).read_text(encoding="utf-8")
    missing = [row for row in rows if row not in text]
    assert not missing, f"docs/{page} lacks the rows {missing}"
