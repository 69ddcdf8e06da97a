from __future__ import annotations

import re
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_library_examples_run(monkeypatch: pytest.MonkeyPatch) -> None:
    text = README.read_text(encoding="utf-8")
    match = re.search(r"## Library in 15 lines\n\n```python\n(.*?)```", text, re.S)
    assert match is not None, "README lost its library example"
    code = match.group(1)
    assert len(code.strip().splitlines()) <= 15
    namespace: dict[str, object] = {"print": lambda *args: None}
    exec(compile(code, str(README), "exec"), namespace)
    assert "m" in namespace
    # The landmark example continues from the first, with paths relative to the repository.
    landmarks = re.search(r"## Recognizing landmarks.*?```python\n(.*?)```", text, re.S)
    assert landmarks is not None, "README lost its landmark example"
    monkeypatch.chdir(README.parent)
    exec(compile(landmarks.group(1), str(README), "exec"), namespace)
    assert namespace["window"] is not None
    reduction = namespace["reduction"]
    assert reduction.consistent  # type: ignore[attr-defined]
    assert reduction.area_after <= reduction.area_before  # type: ignore[attr-defined]


def test_readme_gives_the_two_command_quick_start() -> None:
    text = README.read_text(encoding="utf-8")
    assert "make demo" in text
    assert "make test" in text
