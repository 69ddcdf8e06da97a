"""The public API stays small: what ``import aura_ums`` offers, and the constants it shows."""

from __future__ import annotations

import ast
import importlib
import inspect
import json
import pkgutil
import subprocess
import sys
from pathlib import Path
from types import ModuleType

import pytest

import aura_ums

#: Every public module of the package (subpackages and ``errors``), found, not listed, so
#: that a new one is checked too.
PUBLIC = sorted(
    f"aura_ums.{info.name}" for info in pkgutil.iter_modules(aura_ums.__path__) if info.name[0] != "_"
)

#: Most names the top level may export, and most ALL-CAPS names all public modules together.
TOP_LEVEL_LIMIT = 60
CONSTANT_LIMIT = 5


def public_all(name: str) -> list[str]:
    module = importlib.import_module(name)
    names = getattr(module, "__all__", None)
    assert isinstance(names, list), f"{name}: expected an __all__ list"
    return names


def test_the_public_modules_are_found() -> None:
    assert {"aura_ums.geometry", "aura_ums.uncertainty", "aura_ums.manager", "aura_ums.errors"} <= set(PUBLIC)
    assert all(not part.startswith("_") for name in PUBLIC for part in name.split("."))


def test_the_top_level_is_small_and_every_name_resolves() -> None:
    names = public_all("aura_ums")
    assert len(names) <= TOP_LEVEL_LIMIT, f"expected at most {TOP_LEVEL_LIMIT} names, got {len(names)}"
    assert len(set(names)) == len(names)
    missing = [name for name in names if not hasattr(aura_ums, name)]
    assert not missing, f"aura_ums.__all__ names what the package lacks: {missing}"
    # What a user of `import aura_ums as ums` reaches first.
    for name in ("FOOT", "SpatialUncertaintyMap", "UncertaintyMapManager", "ManagerSettings", "Expecter"):
        assert name in names, name


@pytest.mark.parametrize("name", PUBLIC)
def test_every_name_of_a_public_module_resolves(name: str) -> None:
    module: ModuleType = importlib.import_module(name)
    names = public_all(name)
    assert len(set(names)) == len(names), f"{name}.__all__ repeats a name"
    missing = [item for item in names if not hasattr(module, item)]
    assert not missing, f"{name}.__all__ names what the module lacks: {missing}"


def test_few_constants_are_public_and_foot_is_one() -> None:
    # Each (module, name) counts: a constant re-exported elsewhere counts again, except
    # FOOT, the unit of the paper's figures, which the top level re-exports.
    shown = [(name, item) for name in ("aura_ums", *PUBLIC) for item in public_all(name) if item.isupper()]
    constants = [pair for pair in shown if pair[1] != "FOOT"]
    count = len(constants) + any(item == "FOOT" for _, item in shown)
    assert ("aura_ums", "FOOT") in shown
    assert ("aura_ums.uncertainty", "FOOT") in shown
    assert count <= CONSTANT_LIMIT, f"expected at most {CONSTANT_LIMIT} constants, got {count}: {shown}"


def test_the_lazy_top_level_takes_each_name_from_where_the_type_checkers_see_it() -> None:
    """``aura_ums._HOMES`` (imported on first use) matches the imports under ``TYPE_CHECKING``."""
    tree = ast.parse(Path(aura_ums.__file__).read_text(encoding="utf-8"))
    (guard,) = [
        node
        for node in tree.body
        if isinstance(node, ast.If) and isinstance(node.test, ast.Name) and node.test.id == "TYPE_CHECKING"
    ]
    seen = {
        alias.name: node.module
        for node in guard.body
        if isinstance(node, ast.ImportFrom) and node.module != "typing"  # typing.Any, for __getattr__
        for alias in node.names
    }
    assert seen == aura_ums._HOMES
    assert set(seen) == set(public_all("aura_ums")) - {"__version__"}
    assert {"numpy", "aura_ums.uncertainty"} & set(
        json.loads(
            subprocess.run(
                [sys.executable, "-c", "import json, sys, aura_ums; print(json.dumps(sorted(sys.modules)))"],
                capture_output=True,
                text=True,
                check=True,
            ).stdout
        )
    ) == set()


def test_a_subpackage_is_an_attribute_of_the_top_level_and_an_unknown_name_is_not() -> None:
    assert aura_ums.geometry is importlib.import_module("aura_ums.geometry")
    with pytest.raises(AttributeError, match="has no attribute 'no_such_name'"):
        _ = aura_ums.no_such_name  # type: ignore[attr-defined]


def _public_objects() -> list[tuple[str, object]]:
    """Every class and function a public module exports (``__all__``), by its public name."""
    found: list[tuple[str, object]] = []
    for name in PUBLIC:
        module = importlib.import_module(name)
        for attr in public_all(name):
            value = getattr(module, attr)
            if inspect.isclass(value) or inspect.isfunction(value):
                found.append((f"{name}.{attr}", value))
    return found


def test_every_public_class_and_function_shows_an_example() -> None:
    """Style rule 8: a runnable Examples section (run by pytest's doctests) on each public name."""
    bare = [name for name, value in _public_objects() if ">>>" not in (inspect.getdoc(value) or "")]
    assert not bare, f"no example in the docstrings of {bare}"
