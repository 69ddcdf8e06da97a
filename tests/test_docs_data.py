"""The docs stand on the repository alone: no page points outside it for data or design."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUTSIDE = re.compile(r"\.\.[/\\]shared")


def _pages() -> list[Path]:
    built = ROOT / "docs" / "_build"
    docs = [p for p in (ROOT / "docs").rglob("*") if p.is_file() and built not in p.parents]
    text = [p for p in docs if p.suffix in {".md", ".rst", ".py", ".txt", ".toml"}]
    return [ROOT / "README.md", *sorted(ROOT.joinpath("examples").rglob("*.md")), *sorted(text)]


def test_no_doc_refers_to_a_folder_beside_the_repository() -> None:
    pages = _pages()
    assert ROOT / "docs" / "getting-real-data.md" in pages
    offenders = [
        f"{page.relative_to(ROOT)}:{number}: {line.strip()}"
        for page in pages
        for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), start=1)
        if OUTSIDE.search(line)
    ]
    assert not offenders, "docs point outside the repository:\n" + "\n".join(offenders)


def test_the_pattern_catches_both_separators() -> None:
    assert OUTSIDE.search("read `../shared/DESIGN.md`")
    assert OUTSIDE.search(r"..\shared\data")
    assert not OUTSIDE.search("shared by the whole suite")


def test_getting_real_data_is_linked_from_the_readme_and_the_index() -> None:
    assert "(docs/getting-real-data.md)" in (ROOT / "README.md").read_text(encoding="utf-8")
    index = (ROOT / "docs" / "index.md").read_text(encoding="utf-8")
    assert "\ngetting-real-data\n" in index  # in the table of contents
    page = (ROOT / "docs" / "getting-real-data.md").read_text(encoding="utf-8")
    for command in ("aura-ums import mrclam ", "aura-ums import rosbag "):
        assert command in page
    for url in ("http://asrl.utias.utoronto.ca/datasets/mrclam/", "https://www.elderlab.yorku.ca/"):
        assert url in page
