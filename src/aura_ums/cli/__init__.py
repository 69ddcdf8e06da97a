"""The ``aura-ums`` command line.

Importing this package loads nothing else (``app`` is imported on first use): the console
script's :func:`main` answers a Ctrl-C from its first moment, while numpy, the kernels and
the command line itself are still loading.
"""

from __future__ import annotations

from aura_ums import TYPE_CHECKING
from aura_ums.cli._interrupt import INTERRUPTED, TERMINATION_SIGNALS, exit_code, received, say_interrupted

if TYPE_CHECKING:
    from types import FrameType
    from typing import Any

    from aura_ums.cli._app import app

__all__ = ["app", "main"]


def main() -> None:
    r"""Run the ``aura-ums`` command line (the console script's entry point).

    A Ctrl-C before a command starts (while the libraries load, or while the arguments
    are read) exits with code 130 and says so on stderr, as one during a command does,
    instead of a traceback or nothing. It runs the command line of ``sys.argv`` in this
    process and exits with its status (:doc:`/cli`: 0, or 2 for a refusal named on stderr).

    Examples
    --------
    >>> import subprocess, sys
    >>> run = [sys.executable, "-c", "from aura_ums.cli import main; main()"]
    >>> subprocess.run([*run, "--version"], capture_output=True, text=True).stdout.startswith("aura-ums ")
    True
    >>> refused = subprocess.run([*run, "replay", "no/log", "--terrain", "t"], capture_output=True, text=True)
    >>> refused.returncode, refused.stderr
    (2, 'error: no/log: expected a log folder, got no such folder\n')
    """
    try:
        from aura_ums.cli._app import main as run

        run()
    except KeyboardInterrupt as stop:  # a Ctrl-C, or a Terminated (SIGTERM, SIGHUP)
        code = exit_code(stop)
        _finish_on_interrupt(code)
        say_interrupted(stop)
        raise SystemExit(code) from None
    except SystemExit as exc:
        request = received() if exc.code == INTERRUPTED else None
        if request is not None:  # typer's answer to a SIGTERM or SIGHUP while it reads the arguments
            code = exit_code(request)
            _finish_on_interrupt(code)
            say_interrupted(request)
            raise SystemExit(code) from None
        _finish_on_interrupt(_status(exc.code))
        if exc.code == INTERRUPTED:  # typer's own answer to a Ctrl-C while it reads the arguments
            say_interrupted()
        raise
    _finish_on_interrupt(0)


def _status(code: object) -> int:
    """Return the exit status ``SystemExit(code)`` gives: None is 0, a message 1."""
    if code is None:
        return 0
    return code if isinstance(code, int) else 1


def _finish_on_interrupt(status: int) -> None:
    """From now on, let a Ctrl-C end the process at once with ``status``, not by the signal.

    The command is over: its outputs are written whole (or it was interrupted and said
    so). A Ctrl-C while Python shuts down (joining threads, closing a Dask client) would
    otherwise be a KeyboardInterrupt nothing catches, and Python then ends the process by
    SIGINT itself, which a caller reads as a crash rather than as the command's status.
    """
    # Imported here, not at the top, where they would delay main()'s Ctrl-C handler (the
    # enum of signal alone by a millisecond).
    import atexit
    import contextlib
    import os
    import signal
    import sys

    def finish(signum: int, frame: FrameType | None) -> None:
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):  # a closed pipe: nothing left to say
                stream.flush()
        os._exit(status)

    with contextlib.suppress(ValueError):  # not the main thread: an embedding caller's signals
        signal.signal(signal.SIGINT, finish)
        # Python puts back the default action of every signal it handles after the exit
        # functions, before it tears the modules down, unless it is ignored: a Ctrl-C or a
        # SIGTERM in that last stretch would end the process by the signal (helper-64: a
        # SIGTERM 50 ms after calibrate's last line, 8 of 8 times). By then nothing is left
        # that a request to stop could stop.
        atexit.register(signal.signal, signal.SIGINT, signal.SIG_IGN)
        for name in TERMINATION_SIGNALS:  # a request to stop, now: the same
            number = getattr(signal, name, None)
            if number is not None and getattr(signal.getsignal(number), "stops_the_command", False):
                signal.signal(number, finish)
                atexit.register(signal.signal, number, signal.SIG_IGN)


def __getattr__(name: str) -> Any:
    if name == "app":
        from aura_ums.cli._app import app

        return app
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
