"""What the ``aura-ums`` commands share: consoles, error exit, progress bars, manager options, log summaries.

Results go to stdout (:data:`console`); errors, warnings, progress and the ``wrote``
notes go to stderr (:data:`err_console`), so a script piping the results never mixes
them with a message.
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
import math
import os
from collections import Counter
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.console import Console
from rich.markup import escape
from typer._click.exceptions import MissingParameter, NoSuchOption, UsageError
from typer.core import TyperCommand, TyperGroup

from aura_ums.manager import ManagerSettings, MapProfile, SettingInfo

if TYPE_CHECKING:
    from aura_ums.logs import RobotLog

#: Results (metrics, tables, summaries): stdout.
console = Console(soft_wrap=True)
#: Errors, warnings, progress bars and notes: stderr.
err_console = Console(soft_wrap=True, stderr=True)

#: The option that turns the progress bars off (they are off anyway when stderr is not a terminal).
Quiet = Annotated[
    bool, typer.Option("--quiet", "-q", help="No progress bars (none either when stderr is not a terminal).")
]

# The parameter name under which a flag that sets a setting to None arrives (``--one-by-one``).
_OFF = "{}__off"


#: Control characters (and the line breaks Python splits lines at) as escapes: a file name
#: holding a newline or a terminal escape still prints as one line, and prints nothing else.
_CONTROLS = {code: repr(chr(code))[1:-1] for code in (*range(0x20), *range(0x7F, 0xA0), 0x2028, 0x2029)}


def one_line(message: str) -> str:
    r"""Return ``message`` with its control characters escaped: one line on any terminal.

    Examples
    --------
    >>> name = "lo" + chr(10) + "g" + chr(27) + "[2J"   # a newline, a terminal escape
    >>> print(one_line(name + ": expected a log folder, got no such folder"))
    lo\ng\x1b[2J: expected a log folder, got no such folder
    """
    return message.translate(_CONTROLS)


def fail(message: str) -> typer.Exit:
    """Print ``error: <message>`` (markup-safe, one line) on stderr; return the exit (code 2) to raise."""
    err_console.print(f"[red]error:[/red] {escape(one_line(message))}", highlight=False)
    return typer.Exit(code=2)


def none_or_float(text: str) -> float | None:
    """Read an option's ``none`` or number (``_`` digit groups refused, as the files refuse them).

    Raises ``ValueError`` for anything else: the option's parser says what it expected.
    """
    if text.strip().lower() == "none":
        return None
    if "_" in text:
        raise ValueError(text)
    return float(text)


def warn(message: str) -> None:
    """Print ``warning: <message>`` (markup-safe, one line) on stderr: the command goes on."""
    err_console.print(f"[yellow]warning:[/yellow] {escape(one_line(message))}", highlight=False)


def refuse_alone(context: typer.Context, rules: Sequence[tuple[str, str, str, bool]]) -> None:
    """Refuse (exit 2) an option typed on the command line that would have no effect.

    Each rule is ``(parameter, what it needs, what was given instead, whether the need is
    met)``: an option the user typed meant something, so it is refused rather than ignored.
    Options left at their defaults are not checked.
    """
    for name, needed, instead, met in rules:
        source = context.get_parameter_source(name)
        if not met and source is not None and source.name == "COMMANDLINE":
            raise fail(f"--{name.replace('_', '-')}: expected {needed} too, got {instead}")


def folder_argument(name: str, what: str = "a log folder") -> Callable[[str], Path]:
    """Return the parser of a path argument or option that refuses an empty path (exit 2, naming it).

    The empty string would otherwise become ``Path("")``, the current folder: an input's
    error would name a file inside it (``meta.toml: expected ...``) instead of the argument,
    and an output would land beside whatever the user ran the command in.
    """

    def parse(text: str) -> Path:
        if not text:
            raise fail(f"{name}: expected {what}, got an empty path ''")
        return Path(text)

    return parse


def input_file(name: str, what: str) -> Callable[[str], Path]:
    """Return the parser of an input file's path that refuses one naming no file (exit 2, naming it).

    ``''``, ``.``, ``/`` and a path ending in a separator name a folder, not a file: a file
    read beside it (a terrain table's sensors file) would have no name to take its own from.
    """

    def parse(text: str) -> Path:
        path = folder_argument(name, what)(text)
        if not path.name or path.name == ".." or text.endswith(("/", os.sep)):
            raise fail(f"{name}: expected {what}, got {text!r}, which names a folder")
        return path

    return parse


def output_file(flag: str, example: str, help: str) -> Any:
    """Return the ``typer.Option`` of an output file: refuses an empty path or a folder's (exit 2).

    A path ending in a separator (``--metrics-json out/``) names a folder; as a ``Path`` it
    would lose the separator and the output would be written to a file ``out`` instead.
    The refusal suggests ``example`` (a file name) inside that folder.
    """

    def parse(text: str) -> Path:
        if not text:
            raise fail(f"{flag}: expected a file name, got an empty path ''")
        if text.endswith(("/", os.sep)):
            raise fail(
                f"{flag}: expected a file name, got {text!r}, which names a folder "
                f"(give the file's name in it, e.g. {text}{example})"
            )
        return Path(text)

    return typer.Option(flag, parser=parse, metavar="<path>", help=help)


def _new_log_folder(text: str) -> Path:
    """Parse ``OUT_DIR``, the log folder an import writes: a path that ends in the folder's own name.

    The folder is written under a scratch name beside it and renamed into place, so
    ``.``, ``..`` or ``/`` (no name of their own; the first would replace the folder the
    user works in) are refused, as is the empty path.
    """
    what = "a path ending in the new log folder's name"
    path = folder_argument("OUT_DIR", what)(text)
    if path.name in ("", ".."):
        raise fail(f"OUT_DIR: expected {what}, got {text!r}")
    return path


#: The log folder an import writes (every import command's ``OUT_DIR``).
NewLogFolder = Annotated[Path, typer.Argument(help="Log folder to write.", parser=_new_log_folder)]


def check_seed(seed: int) -> None:
    """Refuse (exit 2) a negative ``--seed``: numpy's generators take none, deep in the work."""
    if seed < 0:
        raise fail(f"--seed: expected an integer >= 0, got {seed}")


@contextmanager
def progress_bar(
    label: str, *, quiet: bool, total: int | None = None
) -> Iterator[Callable[[int, int], None] | None]:
    """Yield a ``(done, total)`` callback drawing a rich bar on stderr, or None when quiet or not a terminal.

    The library reports progress through such callbacks and never prints; the bar is
    transient (gone once the work is done).
    """
    if quiet or not err_console.is_terminal:
        yield None
        return
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn())
    with Progress(*columns, console=err_console, transient=True) as bar:
        task = bar.add_task(escape(label), total=total)

        def advance(done: int, total: int) -> None:
            # 0: not known yet (a streamed log's frames); the bar then pulses.
            bar.update(task, completed=done, total=total or None)

        yield advance


def span(first: float, last: float) -> str:
    """Describe a time span in seconds, or ``none`` when either end is missing."""
    if not (math.isfinite(first) and math.isfinite(last)):
        return "none"
    return f"{first:.3f} .. {last:.3f} s ({last - first:.1f} s)"


def print_log_summary(log: RobotLog) -> None:
    """Print where a log was written and what it holds: counts and time spans."""
    kinds = Counter(observation.kind.value for observation in log.observations)
    seen = len({observation.landmark_id for observation in log.observations})
    times = [observation.time for observation in log.observations]
    rows = [
        ("log", log.meta.name),
        ("source", log.meta.source),
        ("landmarks", f"{len(log.landmarks)} ({seen} observed)"),
        (
            "observations",
            f"{len(log.observations)} ("
            + ", ".join(f"{count} {kind}" for kind, count in sorted(kinds.items()))
            + ")",
        ),
        ("observation span", span(min(times, default=math.nan), max(times, default=math.nan))),
        ("odometry rows", str(len(log.odometry) if log.odometry is not None else 0)),
        ("odometry span", span(*log.motion_span)),
    ]
    if log.groundtruth is not None:
        truth = log.groundtruth
        rows.append(("ground truth rows", str(len(truth))))
        rows.append(("ground truth span", span(float(truth.time[0]), float(truth.time[-1]))))
    for key, value in rows:
        console.print(f"{key:18s} {value}", highlight=False, markup=False)


def setting_flag(name: str) -> str:
    """Return the option of a :class:`ManagerSettings` field: ``max_vertices`` -> ``--max-vertices``."""
    return "--" + name.replace("_", "-")


@dataclass(frozen=True, slots=True)
class SettingOptions:
    """The :class:`ManagerSettings` options given on the command line (the others were left out).

    Attributes
    ----------
    given : Mapping[str, object]
        Field name to value, for the options given only (a ``--profile``'s fields included).
    profile : MapProfile or None
        The ``--profile`` given, if any: the fields of ``given`` it set are those of its
        :attr:`~aura_ums.manager.MapProfile.fields` no option overrode.
    """

    given: Mapping[str, object]
    profile: MapProfile | None = None

    def option_of(self, name: str) -> str:
        """Return how the user gave field ``name``: its option, or ``--profile NAME`` that set it."""
        profile = self.profile
        if profile is not None and name in profile.fields and self.given.get(name) == profile.fields[name]:
            return f"--profile {profile.value}"
        flag = setting_flag(name)
        return f"{flag}/{_off_flag(name)}" if _INFOS[name].kind is bool else flag

    def over(self, base: ManagerSettings | None = None) -> ManagerSettings:
        """Return ``base`` (default: the defaults) with the options given; a bad value exits, named.

        The profile's fields go first, then the options typed: two that conflict are
        blamed on the one typed (``--profile relaxed --relaxed-window 100000`` names
        ``--relaxed-window``, not the ``relaxed_q`` the profile set).
        """
        profiled = {
            name: value for name, value in self.given.items() if self.option_of(name).startswith("--profile ")
        }
        typed = {name: value for name, value in self.given.items() if name not in profiled}
        start = ManagerSettings.from_dict(profiled, base=base, fail=_fail_setting) if profiled else base
        return ManagerSettings.from_dict(typed, base=start, fail=_fail_setting)


#: The ``settings`` parameter's placeholder default in a command's definition (see :func:`manager_options`).
NO_OPTIONS = SettingOptions({})


def _fail_setting(name: str, message: str) -> Exception:
    return fail(f"{setting_flag(name)}: {message}")


def manager_options(default_from: str = "") -> Callable[[Callable[..., None]], Callable[..., None]]:
    """Give a command one option per :class:`ManagerSettings` field, declared from its :class:`SettingInfo`.

    The command's ``settings`` parameter is replaced by the options (where it stands in
    the signature); the command receives a :class:`SettingOptions` there. The options are
    checked against the defaults before the command runs, so a bad value is named before
    any file is read. ``default_from`` says where a left-out option's value comes from
    when not from the defaults (shown in ``--help``).
    """

    def decorate(command: Callable[..., None]) -> Callable[..., None]:
        signature = inspect.signature(command, eval_str=True)
        names = [f.name for f in dataclasses.fields(ManagerSettings)]
        options = [_profile_parameter(default_from)]
        for field in dataclasses.fields(ManagerSettings):
            options += _parameters(field, default_from)
        parameters: list[inspect.Parameter] = []
        for parameter in signature.parameters.values():
            parameters += options if parameter.name == "settings" else [parameter]

        @functools.wraps(command)
        def run(**kwargs: Any) -> None:
            profile: MapProfile | None = kwargs.pop(_PROFILE)
            # A profile's fields as if given, under the options given one by one.
            given: dict[str, object] = {} if profile is None else dict(profile.fields)
            for name in names:
                value = kwargs.pop(name)
                if kwargs.pop(_OFF.format(name), False):
                    if value is not None:
                        raise fail(f"{setting_flag(name)}: expected it or {_off_flag(name)}, got both")
                    given[name] = None
                elif value is _NONE_TYPED:
                    given[name] = None
                elif value is not None:
                    given[name] = value
            chosen = SettingOptions(given, profile)
            chosen.over()  # named before any file is read
            command(**kwargs, settings=chosen)

        run.__signature__ = signature.replace(parameters=parameters)  # type: ignore[attr-defined]
        run.__annotations__ = {p.name: p.annotation for p in parameters}
        return run

    return decorate


# Each ManagerSettings field's info, by name.
_INFOS = {field.name: SettingInfo.of(field) for field in dataclasses.fields(ManagerSettings)}
# The parameter under which ``--profile`` arrives (a name no ManagerSettings field has).
_PROFILE = "settings_profile"
# What each profile is for, in a few words (MapProfile's documentation has the measurements).
_PROFILE_BLURBS = {
    MapProfile.PRODUCT: "the paper's polygon x wedge, fastest",
    MapProfile.SLICED: "windows about a quarter of the frame",
    MapProfile.RELAXED: "the truth kept despite a misread landmark, narrow focus windows, 2-8 ms a frame",
}


def _profile_parameter(default_from: str) -> inspect.Parameter:
    """Return the ``--profile`` option: a :class:`MapProfile`, under the options given one by one."""
    defaults = ManagerSettings().to_dict()

    def sets(profile: MapProfile) -> str:
        changed = [(name, value) for name, value in profile.fields.items() if defaults[name] != value]
        shown = (f"{setting_flag(name)} {_shown_setting(name, value)}" for name, value in changed)
        return " ".join(shown) or "the defaults"

    choices = "; ".join(
        f"{profile.value} = {sets(profile)}, {_PROFILE_BLURBS[profile]}" for profile in MapProfile
    )
    source = f"{default_from}, else " if default_from else ""
    option = typer.Option(
        "--profile",
        help=(
            f"Map representation, as measured on real logs (docs/real-logs.md): {choices}. "
            "The options given one by one override it"
        ),
        show_default=f"{source}{MapProfile.PRODUCT.value}",
    )
    keyword = inspect.Parameter.POSITIONAL_OR_KEYWORD
    return inspect.Parameter(_PROFILE, keyword, default=None, annotation=Annotated[MapProfile | None, option])


def _shown_setting(name: str, value: object) -> str:
    """Return a profile's value as typed on the command line (an angle in degrees)."""
    if value is None:
        return "none"
    if _INFOS[name].unit == "rad" and isinstance(value, float):
        return f"{math.degrees(value):g}deg"
    return str(value)


def _off_flag(name: str) -> str:
    return _INFOS[name].off_flag


def _parameters(field: dataclasses.Field[Any], default_from: str) -> list[inspect.Parameter]:
    """Return the typer parameters of a field: its option, and the flag that turns it off if it has one."""
    info = SettingInfo.of(field)
    flag = setting_flag(field.name)
    unit = f", in {info.unit}" if info.unit else ""
    default = f"{default_from}, else {field.default!r}" if default_from else repr(field.default)
    keyword = inspect.Parameter.POSITIONAL_OR_KEYWORD
    if info.kind is bool:
        option = typer.Option(f"{flag}/{info.off_flag}", help=f"{info.help}.", show_default=default)
        return [
            inspect.Parameter(field.name, keyword, default=None, annotation=Annotated[bool | None, option])
        ]
    angle = info.unit == "rad"
    if angle:
        unit += " (or in degrees: 2deg)"
    help_text = f"{info.help}{unit}; {info.expected}."
    option = typer.Option(
        flag,
        help=help_text,
        show_default=default,
        parser=_setting_option(flag, info),
        metavar="<angle>" if angle else None,
    )
    parameters = [
        inspect.Parameter(field.name, keyword, default=None, annotation=Annotated[info.kind | None, option])
    ]
    if info.off_flag:
        off = typer.Option(info.off_flag, help=f"Set {flag} to none (see there).")
        parameters.append(
            inspect.Parameter(
                _OFF.format(field.name), keyword, default=False, annotation=Annotated[bool, off]
            )
        )
    return parameters


# What the parser of a nullable setting's option returns for ``none``: apart from the None
# of an option not given, so that ``--profile sliced --area-limit none`` overrides the profile.
_NONE_TYPED: Any = object()


def _setting_option(flag: str, info: SettingInfo) -> Callable[[str], object]:
    """Return the parser of a setting's option: a refusal names the option and the text given.

    An angle is radians, or degrees with a suffix (``2deg``, ``2°``); a nullable setting
    also takes ``none``, as its help says. (Typer's own conversion said "Input should be a
    valid number" in a boxed usage block, without the value.)
    """
    angle = info.unit == "rad"
    also = " (radians, or degrees as 2deg)" if angle else ""

    def parse(text: str) -> object:
        if info.nullable and text.strip().lower() == "none":
            return _NONE_TYPED
        if "_" in text:  # float() reads 1_000 as 1000: a typo, not a number
            raise fail(f"{flag}: expected {info.expected}{also}, got {text!r}")
        value = info.read(text) if angle else text
        if isinstance(value, float):
            if info.problem(value) is not None:  # named as typed, not as the radians it became
                raise fail(f"{flag}: expected {info.expected}, got {text!r} ({value:.6g} rad)")
            return value
        try:
            return int(text) if info.kind is int else float(text)
        except ValueError:
            raise fail(f"{flag}: expected {info.expected}{also}, got {text!r}") from None

    return parse


# Positional arguments' types as the help shows them (typer's own: <Path>, <list[Path]>).
_ARGUMENT_TYPES = {str(Path): "<path>", str(list[Path]): "<path>..."}


def _plain_help(params: list[Any]) -> list[Any]:
    """Show flags as ``--flag/--no-flag`` without a ``<bool>`` type, and help text as written.

    Typer renders help as rich markup: a ``[foxglove]`` in a help text would vanish as an
    unknown tag, so every help text is escaped once here, where it is shown.
    """
    for param in params:
        # typer's options are not click.Option subclasses: duck-typed on what they have
        if getattr(param, "is_flag", False):
            param.metavar = ""
        if getattr(param, "param_type_name", None) == "argument" and param.metavar is None:
            # As click names them (LOG_DIRS), typed as the options are (<path>, not <list[Path]>).
            param.metavar = str(param.name).upper()
            shown = _ARGUMENT_TYPES.get(str(param.type_descriptor.annotation))
            if shown is not None:
                param.display_type_rich = lambda ctx, shown=shown: shown
        text = getattr(param, "help", None)
        if text and not getattr(param, "_escaped", False):
            setattr(param, "help", escape(text))  # noqa: B010 - an attribute of typer's options only
            setattr(param, "_escaped", True)  # noqa: B010
    return params


def unwrapped(text: str) -> str:
    r"""Join each paragraph's hard-wrapped lines into one, so rich wraps it to the terminal.

    Typer shows a docstring's paragraphs with their line breaks kept, so a paragraph
    wrapped at 90 columns in the source shows ragged at 80 ("A refused" alone on a line).
    A paragraph marked ``\b`` or holding an indented or bulleted line keeps its breaks.

    Examples
    --------
    >>> unwrapped("Summary.\n\n    First line of a\n    paragraph.\n\n    - a list\n    - kept")
    'Summary.\n\nFirst line of a paragraph.\n\n- a list\n- kept'
    >>> unwrapped("")
    ''
    """
    kept = ("\b", " ", "\t", "- ", "* ")
    paragraphs = []
    for paragraph in inspect.cleandoc(text).split("\n\n"):
        lines = paragraph.split("\n")
        paragraphs.append(paragraph if any(line.startswith(kept) for line in lines) else " ".join(lines))
    return "\n\n".join(paragraphs)


def _plain_text(text: str | None) -> str | None:
    """Return a command's help as shown: paragraphs unwrapped (see :func:`unwrapped`), markup escaped."""
    return escape(unwrapped(text)) if text else text


class PlainCommand(TyperCommand):
    """A typer command whose help shows flags and bracketed text as written (see :func:`_plain_help`).

    Its arguments' refusals read as every other error does (see :func:`_usage_error`).
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.help = _plain_text(self.help)

    def get_params(self, ctx: Any) -> list[Any]:
        return _plain_help(super().get_params(ctx))

    def parse_args(self, ctx: Any, args: list[str]) -> list[str]:
        given = list(args)
        try:
            return super().parse_args(ctx, args)
        except UsageError as exc:
            message = None if ctx.resilient_parsing else _usage_error(exc, given, ctx.command_path)
            if message is None:
                raise
            raise fail(message) from None


def _usage_error(exc: UsageError, given: Sequence[str], command: str) -> str | None:
    """Word typer's refusal of an argument as ``OPTION: expected ..., got ...``; None to leave it.

    Typer's own words come in a boxed usage block, and its conversions do not echo the
    value ("Input should be a valid integer"): the option and what was typed are named here.
    """
    if isinstance(exc, NoSuchOption):
        hint = f"; did you mean {', '.join(exc.possibilities)}?" if exc.possibilities else ""
        return f"{exc.option_name}: expected an option of {command} (see --help{hint}), got {exc.option_name}"
    flags = [
        flag for flag in getattr(getattr(exc, "param", None), "opts", None) or [] if flag.startswith("-")
    ]
    if not flags:
        return None
    if isinstance(exc, MissingParameter):
        return f"{flags[0]}: expected a value (the option is required), got none"
    typed = None
    for index, text in enumerate(given):
        flag, equals, value = text.partition("=")
        if flag in flags:
            typed = value if equals else given[index + 1] if index + 1 < len(given) else None
    reason = exc.message.removeprefix("Value error, ")
    # ("as an integer": one of more digits than Python converts, 4300)
    expected = {"valid integer": "an integer", "as an integer": "an integer", "valid number": "a number"}
    what = next((words for key, words in expected.items() if key in reason), None)
    if what is None and " is not one of " in reason:
        what = "one of " + reason.split(" is not one of ", 1)[1].rstrip(".").replace("'", "")
    if what is None or typed is None:
        return f"{flags[0]}: {reason}"
    return f"{flags[0]}: expected {what}, got {typed!r}"


class PlainGroup(TyperGroup):
    """A typer group whose help shows flags and bracketed text as written (see :func:`_plain_help`)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.help = _plain_text(self.help)

    def get_params(self, ctx: Any) -> list[Any]:
        return _plain_help(super().get_params(ctx))
