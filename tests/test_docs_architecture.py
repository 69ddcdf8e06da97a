"""docs/architecture.md says what the code does: its layers are .importlinter's, its paths exist."""

from __future__ import annotations

import configparser
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "architecture.md"


def _contract_layers() -> list[str]:
    parser = configparser.ConfigParser()
    parser.read(ROOT / ".importlinter", encoding="utf-8")
    lines = parser["importlinter:contract:layers"]["layers"].strip().splitlines()
    return [line.strip() for line in lines if line.strip()]


def _page_layers() -> list[str]:
    block = re.search(r"## Layers\n.*?```\n(.*?)```", PAGE.read_text(encoding="utf-8"), re.S)
    assert block is not None, "docs/architecture.md has no layer diagram under '## Layers'"
    return [re.split(r"\s{3,}", line.strip())[0] for line in block.group(1).splitlines() if line.strip()]


def _names(layer: str) -> set[str]:
    return {name.strip("() ") for name in re.split(r"[|:]", layer)}


def test_the_page_draws_the_contracts_layers_in_order() -> None:
    contract = [_names(layer) for layer in _contract_layers()]
    page = [_names(layer) for layer in _page_layers()]
    assert page == contract


def test_every_path_the_page_names_exists() -> None:
    text = PAGE.read_text(encoding="utf-8")
    paths = set(re.findall(r"`((?:tests|src|benchmarks|docs)/[\w/.-]+)`", text))
    assert paths, "the page names no test or source path"
    missing = sorted(p for p in paths if not (ROOT / p.rstrip("/")).exists())
    assert missing == []
