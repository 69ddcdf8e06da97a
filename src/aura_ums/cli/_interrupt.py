"""What a Ctrl-C ends the command line with: one definition, read before anything else loads."""

from __future__ import annotations

import sys

#: Exit code after a Ctrl-C (128 + SIGINT), as shells report it.
INTERRUPTED = 130

#: The message when a Ctrl-C comes before anything was written.
NOTHING_WRITTEN = "interrupted: nothing was written"

# Whether the running command has said what a Ctrl-C left (see announce).
_announced = [False]


def announce() -> None:
    """Record that the command said on stderr what a Ctrl-C left written."""
    _announced[0] = True


def say_interrupted() -> None:
    """Say, once, that a Ctrl-C ended the command before anything was written."""
    if not _announced[0]:
        sys.stderr.write(f"error: {NOTHING_WRITTEN}\n")
        _announced[0] = True
