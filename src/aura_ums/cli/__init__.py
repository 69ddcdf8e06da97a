"""The ``aura-ums`` command line."""

from aura_ums.cli._app import app, main

__all__ = ["app", "main"]
