from __future__ import annotations

import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_library_example_runs() -> None:
    text = README.read_text(encoding="utf-8")
    match = re.search(r"## Library in 15 lines\n\n```python\n(.*?)```", text, re.S)
    assert match is not None, "README lost its library example"
    code = match.group(1)
    assert len(code.strip().splitlines()) <= 15
    namespace: dict[str, object] = {"print": lambda *args: None}
    exec(compile(code, str(README), "exec"), namespace)
    assert "m" in namespace


def test_readme_gives_the_two_command_quick_start() -> None:
    text = README.read_text(encoding="utf-8")
    assert "make demo" in text
    assert "make test" in text
