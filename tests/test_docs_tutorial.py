"""The tutorial (docs/tutorial.md) runs: its ```python blocks, in order, in one namespace.

They run in a scratch working directory that holds a copy of ``examples/`` (the tutorial
reads ``examples/camera.toml`` from the repository root), with matplotlib on Agg.
"""

from __future__ import annotations

import re
import shutil
import tempfile
import traceback
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[1]
TUTORIAL = ROOT / "docs" / "tutorial.md"
FENCE = re.compile(r"^```python[ \t]*\n(.*?)^```[ \t]*$", re.S | re.M)
IMAGE = re.compile(r"!\[[^\]]*\]\(([^)\s]+)\)")


def python_blocks(text: str) -> list[tuple[int, str]]:
    """Return each ```python block with the line (1-based) its code starts on."""
    return [(text.count("\n", 0, match.start(1)) + 1, match.group(1)) for match in FENCE.finditer(text)]


def test_fence_pattern_finds_blocks_and_skips_other_languages() -> None:
    text = "intro\n```python\na = 1\n```\n\n```sh\nmake demo\n```\n```python\nb = a + 1\n```\n"
    assert python_blocks(text) == [(3, "a = 1\n"), (10, "b = a + 1\n")]


def test_tutorial_blocks_run_in_order(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    text = TUTORIAL.read_text(encoding="utf-8")
    blocks = python_blocks(text)
    assert len(blocks) >= 10, "the tutorial lost its code blocks"
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    monkeypatch.chdir(tmp_path)
    # The tutorial's scratch folder (tempfile.mkdtemp) goes under tmp_path, not /tmp for good.
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    monkeypatch.setenv("MPLBACKEND", "Agg")
    import matplotlib

    matplotlib.use("Agg")
    namespace: dict[str, object] = {"__name__": "__tutorial__", "print": lambda *args, **kwargs: None}
    for number, (line, code) in enumerate(blocks, start=1):
        failure = ""
        try:
            exec(compile(code, f"{TUTORIAL}:block {number} (line {line})", "exec"), namespace)
        except Exception:
            failure = traceback.format_exc()
        if failure:
            pytest.fail(
                f"docs/tutorial.md: python block {number} of {len(blocks)} (starting at line {line}) "
                f"raised:\n{failure}",
                pytrace=False,
            )
    # What the tutorial claims holds: the truth stays in every map, and reductions shrink it.
    current = namespace["current"]
    true_pose = namespace["true_pose"]
    assert current.contains(true_pose)  # type: ignore[attr-defined]
    assert current.area < namespace["grown"].area  # type: ignore[attr-defined]
    folder = namespace["folder"]
    assert isinstance(folder, Path)
    assert (folder / "maps.png").stat().st_size > 0
    # Bearing errors within their bound and 3-sigma truncated motion: the replay must keep
    # the ground truth inside the map at every check.
    result: Any = namespace["result"]
    outside = [(step.time, step.truth) for step in result.steps if not step.inside]
    assert result.containment_rate == 1.0, f"replay_log lost the ground truth at (time, truth): {outside}"
    assert result.inconsistent_observations == 0


def test_tutorial_images_exist() -> None:
    text = TUTORIAL.read_text(encoding="utf-8")
    images = IMAGE.findall(text)
    assert images, "the tutorial lost its figure"
    for image in images:
        assert (TUTORIAL.parent / image).is_file(), f"docs/tutorial.md shows a missing image: {image}"
