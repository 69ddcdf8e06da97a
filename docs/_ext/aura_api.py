"""Sphinx directives for the aura-ums documentation.

``.. aura-package:: aura_ums.geometry``
    Documents one public subpackage from its ``__all__``: the package docstring, then its
    classes, functions and constants, each documented once at the subpackage level (the
    public name, not the private module that defines it). Names the package re-exports from
    another public subpackage are listed with a link to the place where they are documented.
    ``aura_ums`` itself, which only re-exports, gets an overview table.

``.. aura-cli::``
    The reference of the ``aura-ums`` command, read from its click command tree, so that it
    cannot drift from the code: usage, help, arguments and options of every command.
"""

from __future__ import annotations

import ast
import enum
import functools
import importlib
import inspect
import os
from pathlib import Path
from types import ModuleType
from typing import Any

from docutils import nodes
from docutils.statemachine import StringList
from sphinx import addnodes
from sphinx.application import Sphinx
from sphinx.environment import BuildEnvironment
from sphinx.pycode import ModuleAnalyzer
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective
from sphinx.util.nodes import nested_parse_with_titles

logger = logging.getLogger(__name__)

ROOT = "aura_ums"
#: Longest constant value shown next to a constant's name; longer ones are left out.
MAX_VALUE_CHARS = 60


def _is_public_module(name: str) -> bool:
    return name.split(".")[0] == ROOT and not any(part.startswith("_") for part in name.split("."))


def _import_sources(module: ModuleType) -> dict[str, str]:
    """Map each name a package's ``__init__`` imports to the module it imports it from."""
    path = getattr(module, "__file__", None)
    if path is None:
        return {}
    tree = ast.parse(Path(path).read_text(encoding="utf-8"))
    sources: dict[str, str] = {}
    for statement in tree.body:
        # The top level imports its names on first use: the imports type checkers see are
        # under ``if TYPE_CHECKING:``.
        guarded = isinstance(statement, ast.If) and ast.unparse(statement.test) == "TYPE_CHECKING"
        for node in statement.body if guarded else [statement]:
            if isinstance(node, ast.ImportFrom) and node.module is not None and node.level == 0:
                for alias in node.names:
                    sources[alias.asname or alias.name] = node.module
    return sources


def home_of(package: str, name: str) -> str:
    """Return the public package that documents ``package.name``.

    A name imported from another public package is a re-export: follow it to the package
    that imports it from a private module of its own (or defines it).
    """
    seen = set()
    while package not in seen:
        seen.add(package)
        source = _import_sources(importlib.import_module(package)).get(name)
        if source is None or not _is_public_module(source) or source.startswith(package + "._"):
            return package
        if source == package:
            return package
        package = source
    return package


def _private_source(package: str, name: str) -> str | None:
    source = _import_sources(importlib.import_module(package)).get(name)
    return source if source is not None and source.startswith(package + ".") else None


def _constant_doc(package: str, name: str) -> str:
    """Return the ``#:`` comment (or the docstring after it) that documents a constant."""
    source = _private_source(package, name)
    for module in filter(None, (source, package)):
        try:
            docs = ModuleAnalyzer.for_module(module).find_attr_docs()
        except Exception:  # a module without source: no comment to show
            continue
        lines = docs.get(("", name))
        if lines:
            return "\n".join(lines)
    return ""


def _short_value(value: object) -> str | None:
    if isinstance(value, (bool, int, float, str, tuple, frozenset)) and not isinstance(value, enum.Enum):
        text = repr(value)
        if len(text) <= MAX_VALUE_CHARS and "\n" not in text:
            return text
    return None


def _indent(text: str, prefix: str = "   ") -> list[str]:
    return [prefix + line if line.strip() else "" for line in text.splitlines()]


def package_lines(package: str) -> list[str]:
    """Return the reStructuredText that documents one public package."""
    module = importlib.import_module(package)
    names: list[str] = list(getattr(module, "__all__", ()))
    classes: list[str] = []
    functions: list[str] = []
    constants: list[str] = []
    reexports: list[tuple[str, str]] = []
    for name in names:
        if name.startswith("__"):
            continue
        home = home_of(package, name)
        if home != package:
            reexports.append((name, home))
            continue
        value = getattr(module, name)
        if inspect.isclass(value):
            classes.append(name)
        elif inspect.isroutine(value):
            functions.append(name)
        else:
            constants.append(name)

    lines = [f".. automodule:: {package}", ""]
    if classes:
        lines += [".. rubric:: Classes", ""]
        for name in classes:
            value = getattr(module, name)
            if issubclass(value, BaseException):
                lines += [f".. autoexception:: {package}.{name}", ""]
            elif issubclass(value, enum.Enum):
                lines += [f".. autoclass:: {package}.{name}", "   :members:", "   :undoc-members:", ""]
            else:
                lines += [f".. autoclass:: {package}.{name}", "   :members:", ""]
    if functions:
        lines += [".. rubric:: Functions", ""]
        for name in functions:
            lines += [f".. autofunction:: {package}.{name}", ""]
    if constants:
        lines += [".. rubric:: Constants", ""]
        for name in constants:
            lines += [f".. py:data:: {name}", f"   :module: {package}"]
            shown = _short_value(getattr(module, name))
            if shown is not None:
                lines.append(f"   :value: {shown}")
            lines.append("")
            doc = _constant_doc(package, name)
            if not doc:
                logger.info("aura-package: %s.%s has no #: comment", package, name)
            lines += [*_indent(doc), ""]
    if reexports:
        lines += [".. rubric:: Also available here", ""]
        lines += [f"- ``{name}``: the same object as :py:obj:`{home}.{name}`" for name, home in reexports]
        lines.append("")
    return lines


def overview_lines(package: str) -> list[str]:
    """Return the overview of a package that only re-exports: where each name is documented."""
    module = importlib.import_module(package)
    lines = [f".. automodule:: {package}", "", ".. list-table::", "   :header-rows: 1", ""]
    lines += ["   * - name", "     - documented in", ""]
    for name in getattr(module, "__all__", ()):
        if name.startswith("__"):
            continue
        home = home_of(package, name)
        lines += [f"   * - :py:obj:`{package}.{name} <{home}.{name}>`", f"     - :py:mod:`{home}`"]
    return [*lines, ""]


class PackageDirective(SphinxDirective):
    """``.. aura-package:: MODULE`` (add ``:overview:`` for a package that only re-exports)."""

    required_arguments = 1
    option_spec = {"overview": lambda argument: True}  # noqa: RUF012 - docutils reads a dict

    def run(self) -> list[nodes.Node]:
        """Parse the package's generated reStructuredText in place of the directive."""
        package = self.arguments[0]
        try:
            module = importlib.import_module(package)
        except ImportError as exc:
            logger.warning("aura-package: cannot import %s: %s", package, exc, location=self.get_location())
            return []
        if getattr(module, "__file__", None) is None or not hasattr(module, "__all__"):
            logger.warning(
                "aura-package: %s has no __init__.py with __all__ (yet)",
                package,
                location=self.get_location(),
            )
            return []
        lines = overview_lines(package) if "overview" in self.options else package_lines(package)
        source = self.get_source_info()[0] or ""
        content = StringList(lines, source=f"{source} (aura-package {package})")
        node = nodes.section()
        node.document = self.state.document
        nested_parse_with_titles(self.state, content, node)
        return list(node.children)


# typer vendors click (``typer._click``): its objects are read by duck typing here, and each
# parameter's name and help come from ``get_help_record``, as ``--help`` shows them.
def _param_rows(command: Any, context: Any) -> list[str]:
    rows: list[str] = []
    for param in command.get_params(context):
        record = param.get_help_record(context)
        if record is None or param.name == "help":
            continue
        name, help_text = record
        rows += [f"   * - ``{name}``", f"     - {' '.join(help_text.split())}"]
    return rows


def _usage(program: str, command: Any, context: Any) -> str:
    pieces = [program, "[OPTIONS]"]
    for param in command.get_params(context):
        if param.param_type_name == "argument":
            name = str(param.name).upper()
            pieces.append(name if param.required else f"[{name}]")
    return " ".join(pieces)


def cli_lines(group: Any, program: str) -> list[str]:
    """Return the reStructuredText reference of a click group and its commands."""
    context = group.context_class(group, info_name=program)
    lines = [".. code-block:: text", "", f"   {_usage(program, group, context)} COMMAND [ARGS]...", ""]
    lines += [" ".join((group.help or "").split()), ""]
    return lines + _command_lines(group, program, context)


def _command_lines(group: Any, program: str, context: Any) -> list[str]:
    """Return a section per command of ``group``, subcommands of a nested group included."""
    lines: list[str] = []
    for name in group.list_commands(context):
        command = group.get_command(context, name)
        if command is None or command.hidden:
            continue
        sub = command.context_class(command, info_name=name, parent=context)
        full = f"{program} {name}"
        nested = hasattr(command, "list_commands")
        title = f"``{full}``"
        lines += [title, "-" * len(title), ""]
        usage = _usage(full, command, sub) + (" COMMAND [ARGS]..." if nested else "")
        lines += [".. code-block:: text", "", f"   {usage}", ""]
        lines += [" ".join((command.help or "").split()), ""]
        rows = _param_rows(command, sub)
        if rows:
            lines += [".. list-table::", "   :header-rows: 1", "   :widths: 30 70", ""]
            lines += ["   * - argument or option", "     - meaning", *rows, ""]
        if nested:
            lines += _command_lines(command, full, sub)
    return lines


class CliDirective(SphinxDirective):
    """``.. aura-cli::``: the reference of every ``aura-ums`` command."""

    def run(self) -> list[nodes.Node]:
        """Parse the command reference in place of the directive."""
        import typer.main

        from aura_ums.cli import app

        group = typer.main.get_command(app)
        if not hasattr(group, "list_commands"):
            logger.warning("aura-cli: expected a command group", location=self.get_location())
            return []
        source = self.get_source_info()[0] or ""
        content = StringList(cli_lines(group, "aura-ums"), source=f"{source} (aura-cli)")
        node = nodes.section()
        node.document = self.state.document
        nested_parse_with_titles(self.state, content, node)
        return list(node.children)


def _lookup(dotted: str) -> object | None:
    """Return the object a dotted public name refers to, or None."""
    parts = dotted.split(".")
    for split in range(len(parts), 0, -1):
        module_name = ".".join(parts[:split])
        if not _is_public_module(module_name) or not _importable(module_name):
            continue
        value: object = importlib.import_module(module_name)
        for part in parts[split:]:
            if not hasattr(value, part):
                return None
            value = getattr(value, part)
        return value
    return None


def _documented_name(dotted: str) -> str | None:
    """Return where the public name ``dotted`` is documented, following re-exports."""
    parts = dotted.split(".")
    for split in range(len(parts) - 1, 0, -1):
        package = ".".join(parts[:split])
        if _is_public_module(package) and _importable(package):
            if not hasattr(importlib.import_module(package), parts[split]):
                return None
            return ".".join([home_of(package, parts[split]), *parts[split:]])
    return None


def _field_owner(dotted: str) -> str | None:
    """Return ``Class`` when ``dotted`` is ``Class.field``, a dataclass field or slot of a class.

    Fields are documented in their class's docstring (numpydoc Parameters or Attributes),
    not as objects of their own: a reference to one links to its class.
    """
    owner, _, field = dotted.rpartition(".")
    cls = _lookup(owner) if owner else None
    if not inspect.isclass(cls):
        return None
    fields = getattr(cls, "__dataclass_fields__", {})
    slots = getattr(cls, "__slots__", ())
    return owner if field in fields or field in slots else None


def resolve_public_name(
    app: Sphinx, env: BuildEnvironment, node: addnodes.pending_xref, contnode: nodes.TextElement
) -> nodes.Element | None:
    """Resolve a Python reference that Sphinx's own lookup missed, by three exact rules.

    1. Re-exports: ``aura_ums.expecter.ImageWindow`` and ``aura_ums.SpatialUncertaintyMap``
       are public names of objects documented once, in their home package; a reference to
       such a name (also relative to the current module or class, as Sphinx scopes them)
       goes there.
    2. Top level: a name that ``aura_ums`` exports (``TurnAndRun``, ``Expecter.bounds``) is
       looked up as ``aura_ums.<name>``.
    3. Fields: ``Class.field`` (or ``field`` inside ``Class``) links to ``Class``, whose
       docstring documents the field.

    Unknown or ambiguous names still fail the build. With ``AURA_DOCS_LIST_RESOLVED=1``
    each reference resolved here is logged, to find docstrings worth qualifying.
    """
    if node.get("refdomain") != "py":
        return None
    target = str(node.get("reftarget", "")).lstrip("~.")
    module = node.get("py:module")
    cls = node.get("py:class")
    scopes = [target]
    if module and cls:
        scopes.append(f"{module}.{cls}.{target}")
    if module:
        scopes.append(f"{module}.{target}")
    scopes.append(f"{ROOT}.{target}")
    domain = env.get_domain("py")
    for scoped in scopes:
        for candidate in (scoped, _field_owner(scoped)):
            if candidate is None:
                continue
            documented = _documented_name(candidate) or candidate
            if documented == target:
                continue
            found = domain.resolve_xref(
                env, node.get("refdoc", ""), app.builder, node["reftype"], documented, node, contnode
            )
            if found is not None:
                if os.environ.get("AURA_DOCS_LIST_RESOLVED"):
                    logger.info(
                        "aura-api: resolved %s %r as %s", node["reftype"], target, documented, location=node
                    )
                return found
    return None


@functools.cache
def _importable(name: str) -> bool:
    try:
        importlib.import_module(name)
    except ImportError:
        return False
    return True


def setup(app: Sphinx) -> dict[str, object]:
    """Register the directives and the resolution of re-exported names."""
    app.connect("missing-reference", resolve_public_name)
    app.add_directive("aura-package", PackageDirective)
    app.add_directive("aura-cli", CliDirective)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
