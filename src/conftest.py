"""Doctests' scratch files go under pytest's temporary folder, not the system's for good.

The examples make their scratch folders the way a user would (``tempfile.mkdtemp()``) and
do not remove them; here ``tempfile`` is pointed at a folder pytest owns and prunes.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest


@pytest.fixture(autouse=True)
def _scratch_under_pytest(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
