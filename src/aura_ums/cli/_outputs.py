"""Where the commands write: checked before any work, written whole, never onto an input.

Every command declares its inputs (:class:`Source`) and its outputs (:class:`Target`)
and calls :func:`check_outputs` before it computes anything. Paths are compared after
resolving symlinks. An output may not be an input file, lie inside an input folder, be
a folder holding an input, or share its path with another output; an existing output is
replaced only with ``--overwrite``; the folder an output goes into must be writable.
Each refusal exits with code 2 and names the option and both paths on stderr.

Files are then written through :func:`aura_ums._files.atomic_path` (a scratch name
beside the target, renamed onto it when whole), and folders of figures are drawn into a
scratch folder and moved in file by file: a failure, a Ctrl-C or a kill leaves the old
file or none, never a part of one under its final name. :func:`interruptible` turns a
Ctrl-C into exit code 130 and says what was (not) written.
"""

from __future__ import annotations

import functools
import os
import re
import shutil
import stat
import unicodedata
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

import typer

from aura_ums._files import (
    NAME_MAX,
    atomic_path,
    is_scratch,
    make_folders,
    place_new,
    remove_made,
    scratch_path,
    write_text_atomic,
)
from aura_ums.cli._common import err_console, fail
from aura_ums.cli._interrupt import announce, exit_code, nothing_written, stopped
from aura_ums.errors import FileFormatError

#: The option every command that writes takes, with the same help everywhere.
Overwrite = Annotated[
    bool,
    typer.Option(
        "--overwrite", help="Replace outputs that exist already (without it, an existing output is refused)."
    ),
]


# What the running command has written so far, for the message after a Ctrl-C.
_written: list[Path] = []
# Whether the running command was given --overwrite (set by check_outputs): without it, an
# output that appears while the command computes is not replaced either.
_replacing: list[bool] = [False]

_UNSAFE = re.compile(r"[^A-Za-z0-9._-]+")
_SAFE_NAME_LENGTH = 100


@dataclass(frozen=True, slots=True)
class Source:
    """An input of a command.

    Attributes
    ----------
    option : str
        How the user gave it (``"LOG_DIR"``, ``"--terrain"``).
    path : Path
        As given.
    folder : bool
        A folder (a log folder, a dataset): nothing may be written inside it.
    """

    option: str
    path: Path
    folder: bool = False


@dataclass(frozen=True, slots=True)
class Target:
    """An output of a command: a file, or a folder the command fills.

    Attributes
    ----------
    option : str
        How the user gave it (``"--metrics-json"``, ``"OUT_DIR"``).
    path : Path
        As given (or derived, e.g. ``--out`` with ``.sensors.toml``).
    folder : bool
        A folder of outputs: it must be new or empty unless ``--overwrite``.
    """

    option: str
    path: Path
    folder: bool = False


def resolved(path: Path) -> Path:
    """Return ``path`` absolute with every symlink resolved (the missing tail kept as is).

    A relative path in a current folder that was deleted (the shell still in it) exits 2
    saying so, where ``os.getcwd`` raised FileNotFoundError through a traceback.
    """
    try:
        return Path(os.path.realpath(path.expanduser()))
    except FileNotFoundError:
        raise fail(f"{path}: expected a path from an existing current folder, got {CWD_GONE}") from None


#: Why a relative path cannot be found when the current folder is gone.
CWD_GONE = "a current folder that was deleted; cd to an existing folder, or give absolute paths"


def safe_name(text: str, default: str = "log") -> str:
    """Return ``text`` as one file name: no folder, no leading dot, only ``A-Z a-z 0-9 . _ -``.

    For output names taken from data (a log's name), so that no name reaches outside
    the output folder.

    Examples
    --------
    >>> safe_name("../x"), safe_name("/abs/x"), safe_name("Robot 1: café*?"), safe_name("..")
    ('x', 'abs_x', 'Robot_1_cafe', 'log')
    """
    ascii_text = unicodedata.normalize("NFKD", text).encode("ascii", "ignore").decode("ascii")
    name = _UNSAFE.sub("_", ascii_text).strip("._-")[:_SAFE_NAME_LENGTH].strip("._-")
    return name or default


def check_outputs(
    targets: Sequence[Target | None], sources: Sequence[Source | None], *, overwrite: bool
) -> None:
    """Refuse (exit 2) outputs that would touch an input, collide, exist, or cannot be written.

    Called before any computation, so a refusal costs nothing. ``None`` entries (options
    not given) are skipped.
    """
    _replacing[0] = overwrite
    inputs = [(source, resolved(source.path)) for source in sources if source is not None]
    seen: list[tuple[Target, Path]] = []
    for target in (t for t in targets if t is not None):
        _named(target)
        where = resolved(target.path)
        if target.folder:
            refuse_root(target.option, target.path)
        for source, origin in inputs:
            _apart(target, where, source, origin)
        for other, taken in seen:
            if taken == where:
                raise fail(
                    f"{target.option}: expected a path of its own, got {target.path}, which is also "
                    f"the output of {other.option} ({other.path})"
                )
            # A file output cannot also be the folder of another: one of the two would fail
            # after the computation, with the other written.
            nested = (taken in where.parents and not other.folder) or (
                where in taken.parents and not target.folder
            )
            if nested:
                raise fail(
                    f"{target.option}: expected a path of its own, got {target.path}, which nests with "
                    f"the output file of {other.option} ({other.path})"
                )
        seen.append((target, where))
        try:
            _replaceable(target, where, overwrite)
            _writable(target, where)
        except OSError as exc:  # e.g. a folder of the path that cannot be looked into
            raise _unwritable(target, target.path, exc) from None


def refuse_root(option: str, folder: Path) -> None:
    """Refuse (exit 2) the file system's root as an output folder: none is written beside it.

    An output folder is written in a scratch folder beside it and moved in whole; the root
    has no place beside it.
    """
    where = resolved(folder)
    if where.parent == where:
        raise fail(f"{option}: expected a folder other than the file system's root, got {folder}")


def _named(target: Target) -> None:
    """Refuse a path with a name longer than a file system takes: it would fail after the work."""
    for part in target.path.parts:
        size = len(os.fsencode(part))
        if size > NAME_MAX:
            raise fail(
                f"{target.option}: expected names of at most {NAME_MAX} bytes in the path, got one of "
                f"{size} bytes ({part[:24]}...)"
            )


def _apart(target: Target, where: Path, source: Source, origin: Path) -> None:
    what = f"the input {source.option} ({_shown(source.path, origin)})"
    given, option = _shown(target.path, where), target.option
    if where == origin:
        raise fail(f"{option}: expected an output apart from the inputs, got {given}, which is {what}")
    if _same_file(where, origin):
        # a hard link: another name of the input's bytes (replaced atomically, the input would
        # survive, but the name given is the input)
        raise fail(f"{option}: expected an output apart from the inputs, got {given}, a hard link to {what}")
    if source.folder and _linked_into(where, origin):
        raise fail(
            f"{option}: expected an output apart from the inputs, got {given}, "
            f"a hard link to a file of {what}"
        )
    if source.folder and where.is_relative_to(origin):
        raise fail(f"{option}: expected an output outside the input folders, got {given}, inside {what}")
    if target.folder and origin.is_relative_to(where):
        raise fail(
            f"{option}: expected an output folder apart from the inputs, got {given}, which holds {what}"
        )


def _linked_into(where: Path, folder: Path) -> bool:
    """Whether ``where`` is an existing file hard-linked to a file of ``folder`` (its top level)."""
    try:
        info = os.stat(where)
        if not stat.S_ISREG(info.st_mode) or info.st_nlink < 2:  # no other name anywhere
            return False
        with os.scandir(folder) as entries:
            for entry in entries:
                if entry.is_file() and os.path.samestat(entry.stat(), info):
                    return True
    except OSError:
        return False
    return False


def _same_file(one: Path, other: Path) -> bool:
    """Whether two existing paths are one file (a hard link); False when either is missing."""
    try:
        return one.is_file() and other.is_file() and one.samefile(other)
    except OSError:
        return False


def _shown(path: Path, where: Path) -> str:
    """``path`` as given, with where it leads when a symlink takes it elsewhere."""
    plain = Path(os.path.abspath(path.expanduser()))
    return str(path) if plain == where else f"{path} (a link to {where})"


def _replaceable(target: Target, where: Path, overwrite: bool) -> None:
    if target.folder:
        if where.exists() and not where.is_dir():
            raise fail(f"{target.option}: expected a folder, got {target.path}, which is a file")
        leftovers: list[str] = []
        for path in where.iterdir() if where.is_dir() and not overwrite else ():
            if not is_scratch(path):
                raise fail(
                    f"{target.option}: expected a new or empty folder, got {target.path}, which holds files "
                    "(pass --overwrite to replace what is written there)"
                )
            leftovers.append(path.name)
        if leftovers:
            # Not outputs, but not ours to delete either: a command writing there may still run.
            shown = ", ".join(sorted(leftovers)[:3]) + (", ..." if len(leftovers) > 3 else "")
            raise fail(
                f"{target.option}: expected a new or empty folder, got {target.path}, which holds only the "
                f"scratch files of unfinished writes ({shown}: a killed command's leftovers can be deleted; "
                "or pass --overwrite)"
            )
        return
    if where.is_dir():
        raise fail(f"{target.option}: expected a file, got {target.path}, which is a folder")
    # The path as given, followed through its links (/dev/stdout on a pipe resolves to a
    # /proc name that is no file, so `where` cannot tell).
    given = _followed(target.path)
    stream = "" if given is None else _stream_of(given)
    if stream:
        raise fail(
            f"{target.option}: expected a file apart from the command's own {stream}, got {target.path} "
            "(results are printed on stdout, errors on stderr, anyway)"
        )
    if given is not None and not stat.S_ISREG(given.st_mode):
        # The atomic rename would put a regular file in its place (as root, /dev/null's).
        raise fail(
            f"{target.option}: expected a regular file, got {target.path}, which is a device, pipe or "
            "socket (it would be replaced, not written to)"
        )
    if where.exists() and not overwrite:
        raise fail(
            f"{target.option}: expected a new file, got {target.path}, which exists "
            "(pass --overwrite to replace it)"
        )
    if os.path.lexists(where) and not where.exists() and not overwrite:
        # Resolved as far as it goes, a link that loops is still a name that is taken: the
        # final rename would refuse it, after the computation, as if it had just appeared.
        raise fail(
            f"{target.option}: expected a new file, got {target.path}, a symbolic link that loops "
            "(pass --overwrite to replace the link with the file)"
        )


def _followed(path: Path) -> os.stat_result | None:
    """``os.stat`` of ``path`` through its links; None when there is no such file (the usual case)."""
    try:
        return os.stat(path)
    except (OSError, ValueError):  # no such file, or a name the system refuses
        return None


def _stream_of(given: os.stat_result) -> str:
    """Name the stream of this process that a file is, ``"stdout"`` or ``"stderr"``, else ``""``.

    ``/dev/stdout``, or the file the stream is redirected to.
    """
    for name, descriptor in (("stdout", 1), ("stderr", 2)):
        try:
            stream = os.fstat(descriptor)
        except OSError:  # closed
            continue
        if (given.st_dev, given.st_ino) == (stream.st_dev, stream.st_ino):
            return name
    return ""


def _writable(target: Target, where: Path) -> None:
    """Probe the deepest existing folder the output goes into with a file of our own."""
    folder = where if target.folder else where.parent
    while not folder.exists():
        folder = folder.parent
    if not folder.is_dir():
        raise fail(
            f"{target.option}: expected a path in a folder, got {target.path}, where {folder} is a file"
        )
    probe = scratch_path(folder / "write-probe")
    try:
        try:
            probe.open("x").close()
        finally:  # also when a Ctrl-C or SIGTERM lands between making the probe and removing it
            probe.unlink(missing_ok=True)
    except OSError as exc:
        raise _unwritable(target, folder, exc) from None


def _unwritable(target: Target, path: Path, exc: OSError) -> typer.Exit:
    return fail(f"{target.option}: expected a writable place, got {path}: {exc.strerror or exc}")


def wrote(path: Path, note: str = "") -> None:
    """Record that ``path`` is written whole, and say so on stderr."""
    _written.append(path)
    err_console.print(f"wrote {path}{note}", highlight=False, markup=False)


def write_text(target: Target, text: str) -> Path:
    """Write ``text`` to the target file atomically; a system error exits 2 naming the option."""
    try:
        # through a symlink to its file (the link stays), as the checks resolved it
        write_text_atomic(resolved(target.path), text, replace=_replacing[0])
    except FileExistsError:
        raise appeared(target, target.path) from None
    except OSError as exc:
        raise _unwritable(target, target.path, exc) from None
    wrote(target.path)
    return target.path


def appeared(target: Target, path: Path) -> typer.Exit:
    """Return the refusal of an output that appeared while the command computed (no --overwrite)."""
    return fail(
        f"{target.option}: expected a new file, got {path}, which appeared while this command ran "
        "(kept; pass --overwrite to replace it)"
    )


@contextmanager
def placed(target: Target) -> Iterator[Path]:
    """Yield a scratch path for the target file; when the block ends, move it onto the target.

    For outputs a library function writes itself (an MCAP file, the per-step CSV): the
    final move keeps an output that appeared meanwhile unless ``--overwrite`` was given.
    """
    final = resolved(target.path)
    scratch = final
    try:
        # The one scratch file: the library's writers, which write atomically themselves,
        # write into it as it is (see atomic_path).
        with atomic_path(final, replace=_replacing[0]) as scratch:
            yield scratch
    except FileExistsError:
        raise appeared(target, target.path) from None
    except OSError as exc:
        raise _unwritable(target, target.path, exc) from None
    except FileFormatError as exc:
        if exc.path != str(scratch):
            raise
        # The library could not write the scratch file (a full disk): the user named the output.
        reason = exc.message.removeprefix(FileFormatError.UNWRITABLE)
        if reason == exc.message:
            raise fail(f"{target.option}: {target.path}: {reason}") from None
        raise fail(f"{target.option}: expected a writable place, got {target.path}: {reason}") from None


@contextmanager
def staged(target: Target) -> Iterator[Path]:
    """Yield a scratch folder beside the target folder; when the block ends, move its files in.

    Each file is moved onto its place in the target folder with one ``os.replace``
    (sub-folders kept): every file there is an old one or a whole new one. On an error
    or a Ctrl-C the scratch folder is removed and the target folder left as it was.
    """
    final = resolved(target.path)
    try:
        made = make_folders(final)
    except OSError as exc:
        raise _unwritable(target, final, exc) from None
    stage = scratch_path(final)
    try:
        try:
            stage.mkdir()
            yield stage
            for path in sorted(p for p in stage.rglob("*") if p.is_file()):
                place = final / path.relative_to(stage)
                place.parent.mkdir(parents=True, exist_ok=True)
                if _replacing[0]:
                    os.replace(path, place)
                else:
                    place_new(path, place)
                wrote(target.path / path.relative_to(stage))
        finally:
            shutil.rmtree(stage, ignore_errors=True)
    except BaseException as exc:
        # A folder made for this output and still empty goes too: no empty folder under its name.
        remove_made(made)
        if isinstance(exc, FileExistsError):
            raise appeared(target, Path(exc.filename or final)) from None
        if isinstance(exc, OSError):
            raise _unwritable(target, final, exc) from None
        raise


def interruptible(command: Callable[..., None]) -> Callable[..., None]:
    """Turn a Ctrl-C inside ``command`` into exit code 130 and a message on stderr of what was written."""

    @functools.wraps(command)
    def run(*args: Any, **kwargs: Any) -> None:
        _written.clear()
        _replacing[0] = False
        try:
            command(*args, **kwargs)
        except KeyboardInterrupt as stop:  # a Ctrl-C, or a Terminated (SIGTERM, SIGHUP)
            if _written:
                done = ", ".join(str(path) for path in _written)
                message = f"{stopped(stop)}: only {done} written whole; nothing else was written"
            else:
                message = nothing_written(stop)
            err_console.print(f"[red]error:[/red] {_escape(message)}", highlight=False)
            announce()
            raise typer.Exit(code=exit_code(stop)) from None

    return run


def _escape(text: str) -> str:
    from rich.markup import escape

    return escape(text)
