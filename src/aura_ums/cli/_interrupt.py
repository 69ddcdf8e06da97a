"""What a Ctrl-C (or a request to stop) ends the command line with: defined once, loaded first."""

from __future__ import annotations

import sys

#: Exit code after a Ctrl-C (128 + SIGINT), as shells report it.
INTERRUPTED = 130

#: The message when a Ctrl-C comes before anything was written.
NOTHING_WRITTEN = "interrupted: nothing was written"

#: The signals that ask the command line to stop as a Ctrl-C does (see :class:`Terminated`).
TERMINATION_SIGNALS = ("SIGTERM", "SIGHUP")

# Whether the running command has said what a Ctrl-C left (see announce).
_announced = [False]


class Terminated(KeyboardInterrupt):
    """A request to stop (SIGTERM from ``kill`` or ``timeout``, SIGHUP from a closed terminal).

    Raised by the handler the command line installs, and met where a Ctrl-C is: every
    output is then whole or not written, the scratch files go, and the command says what
    was written. Only the exit code differs: 128 + the signal's number, as a shell
    reports a process the signal ended.
    """

    def __init__(self, signum: int, name: str) -> None:
        super().__init__(name)
        self.signum = signum
        self.name = name


#: The last request to stop the handler raised (see :func:`received`).
_received: list[Terminated | None] = [None]


def received(stop: Terminated | None = None) -> Terminated | None:
    """Record ``stop`` (the handler raises it), or return the last one recorded.

    Typer turns any KeyboardInterrupt it meets while it reads the arguments into the exit
    status of a Ctrl-C, 130; a SIGTERM there must still end the command with 143.
    """
    if stop is not None:
        _received[0] = stop
    return _received[0]


def exit_code(stop: KeyboardInterrupt) -> int:
    """Return the exit code a Ctrl-C or a :class:`Terminated` ends the command with."""
    return 128 + stop.signum if isinstance(stop, Terminated) else INTERRUPTED


def stopped(stop: KeyboardInterrupt) -> str:
    """Return how the message names what stopped the command: ``interrupted`` or ``terminated (SIGTERM)``."""
    return f"terminated ({stop.name})" if isinstance(stop, Terminated) else "interrupted"


def nothing_written(stop: KeyboardInterrupt | None = None) -> str:
    """Return the message when a Ctrl-C (or ``stop``) came before anything was written."""
    return NOTHING_WRITTEN if stop is None else NOTHING_WRITTEN.replace("interrupted", stopped(stop), 1)


def announce() -> None:
    """Record that the command said on stderr what a Ctrl-C left written."""
    _announced[0] = True


def say_interrupted(stop: KeyboardInterrupt | None = None) -> None:
    """Say, once, that a Ctrl-C (or ``stop``) ended the command before anything was written."""
    if not _announced[0]:
        sys.stderr.write(f"error: {nothing_written(stop)}\n")
        _announced[0] = True
