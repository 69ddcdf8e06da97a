"""The ``aura-ums`` command line.

Importing this package loads nothing else (``app`` is imported on first use): the console
script's :func:`main` answers a Ctrl-C from its first moment, while numpy, the kernels and
the command line itself are still loading.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from aura_ums.cli._interrupt import INTERRUPTED, say_interrupted

if TYPE_CHECKING:
    from aura_ums.cli._app import app

__all__ = ["app", "main"]


def main() -> None:
    """Run the ``aura-ums`` command line (the console script's entry point).

    A Ctrl-C before a command starts (while the libraries load, or while the arguments
    are read) exits with code 130 and says so on stderr, as one during a command does,
    instead of a traceback or nothing.
    """
    try:
        from aura_ums.cli._app import main as run

        run()
    except KeyboardInterrupt:
        say_interrupted()
        raise SystemExit(INTERRUPTED) from None
    except SystemExit as exc:
        if exc.code == INTERRUPTED:  # typer's own answer to a Ctrl-C while it reads the arguments
            say_interrupted()
        raise


def __getattr__(name: str) -> Any:
    if name == "app":
        from aura_ums.cli._app import app

        return app
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
