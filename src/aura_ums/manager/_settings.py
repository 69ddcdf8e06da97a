"""The map manager's settings: one frozen type, each field with its unit, range and help.

Every reader of settings -- the ``aura-ums`` options, a scenario's ``[manager]`` table,
:class:`~aura_ums.logs.ReplayOptions` and the manager's saved JSON -- is built from
:class:`ManagerSettings` and the :class:`SettingInfo` of its fields: a default, a unit, a
range or a help text is written here and nowhere else.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import textwrap
from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

from aura_ums._validate import SIGMAS, Choice
from aura_ums.errors import InputError
from aura_ums.uncertainty import MAX_SLICES, MAX_VERTICES, MIN_SECTOR, cell_count

#: What a setting holds.
SettingValue = float | int | bool | None

_INFO = "aura_ums.setting"
_TWO_PI = 2.0 * math.pi


@dataclass(frozen=True, slots=True)
class SettingInfo:
    """What one field of :class:`ManagerSettings` is: its help, unit, type and range.

    Attributes
    ----------
    help : str
        One sentence (no final period) for option help and documentation.
    unit : str
        The unit (``"rad"``, ``"m^2"``); ``""`` for counts and factors.
    kind : type
        ``float``, ``int`` or ``bool``.
    low, high : float or None
        Smallest and largest value allowed (None: unbounded).
    low_open : bool
        Whether ``low`` itself is excluded.
    nullable : bool
        Whether None is allowed (its meaning is in ``help``).
    off_flag : str
        The command-line flag that turns the setting off: for a boolean, the one that
        sets False (``"--gate-only"``); for a nullable setting whose default is not None,
        the one that sets None (``"--one-by-one"``). ``""`` when there is none.

    Examples
    --------
    >>> info = SettingInfo("Cap on the vertices", "", int, low=3)
    >>> info.expected, info.problem(2), info.problem(8)
    ('an integer >= 3', 'expected an integer >= 3, got 2', None)
    >>> SettingInfo("Scale", "", float, low=1.0, nullable=True).problem(float("nan"))
    'expected a finite number >= 1 or none, got nan'
    """

    help: str
    unit: str
    kind: type
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    nullable: bool = False
    off_flag: str = ""

    @property
    def expected(self) -> str:
        """What a valid value is, in words (``"a positive number"``, ``"an integer >= 3"``)."""
        if self.kind is bool:
            text = "true or false"
        elif self.kind is int:
            text = f"an integer >= {_shown(self.low)}" if self.low is not None else "an integer"
        elif self.high is not None:
            opening = "(" if self.low_open else "["
            text = f"a number in {opening}{_shown(self.low)}, {_shown(self.high)}]"
        elif self.low == 0.0 and self.low_open:
            text = "a positive number"
        elif self.low is not None:
            text = f"a number {'>' if self.low_open else '>='} {_shown(self.low)}"
        else:
            text = "a number"
        return f"{text} or none" if self.nullable else text

    def problem(self, value: object) -> str | None:
        """Return ``"expected ..., got ..."`` when ``value`` is not valid, else None."""
        if value is None:
            return None if self.nullable else f"expected {self.expected}, got None"
        if self.kind is bool:
            return None if isinstance(value, bool) else f"expected {self.expected}, got {value!r}"
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            return f"expected {self.expected}, got {value!r}"
        if self.kind is int:
            if not isinstance(value, numbers.Integral) or (self.low is not None and value < self.low):
                return f"expected {self.expected}, got {value!r}"
            if self.high is not None and int(value) > self.high:
                # a cap sizes arrays: 1e9 vertices allocated 7.45 GiB before any work
                return f"expected an integer in [{_shown(self.low)}, {_shown(self.high)}], got {value!r}"
            return None
        number = float(value)
        if not math.isfinite(number):
            return f"expected a finite {self.expected.removeprefix('a ')}, got {number!r}"
        low, high = self.low, self.high
        if (low is not None and (number < low or (self.low_open and number == low))) or (
            high is not None and number > high
        ):
            return f"expected {self.expected}, got {number!r}"
        return None

    def read(self, value: object) -> object:
        """Return the text of an angle in degrees, ``"2deg"`` or ``"2°"``, as radians.

        Only for a setting whose unit is ``"rad"``: on the command line its value may be
        written in degrees, since 2 degrees is 0.0349066 rad to seven figures (a scenario's
        ``[manager]`` table says ``<name>_deg`` instead). Every other value is returned as
        it is.

        Examples
        --------
        >>> info = SettingInfo("Cell width", "rad", float, low=0.0, low_open=True)
        >>> info.read("2deg") == math.radians(2.0), info.read(" 90 ° ") == math.pi / 2
        (True, True)
        >>> info.read("2 degrees"), info.read(0.5)   # not an angle in degrees: as it is
        ('2 degrees', 0.5)
        """
        if self.unit != "rad" or not isinstance(value, str):
            return value
        text = value.strip()
        for suffix in _DEGREES:
            if text.endswith(suffix):
                try:
                    return math.radians(float(text.removesuffix(suffix)))
                except ValueError:
                    return value
        return value

    def normalize(self, value: object) -> SettingValue:
        """Return a valid ``value`` (see :meth:`problem`) as the setting's type."""
        if value is None or isinstance(value, bool):
            return value
        if self.kind is int and isinstance(value, numbers.Integral):
            return int(value)
        if isinstance(value, numbers.Real):
            return float(value)
        raise InputError(f"value: expected {self.expected}, got {value!r}")

    @staticmethod
    def of(field: dataclasses.Field[Any]) -> SettingInfo:
        """Return the info of a field of :class:`ManagerSettings` (``dataclasses.fields``)."""
        info = field.metadata.get(_INFO)
        if not isinstance(info, SettingInfo):
            raise InputError(f"field: expected a field of ManagerSettings, got {field.name!r}")
        return info


#: The suffixes of an angle in degrees (``SettingInfo.read``).
_DEGREES = ("deg", "\N{DEGREE SIGN}")

#: The largest vertex and slice caps: arrays are sized by them (a cap of 1e9 is 7.45 GiB).
#: Also the largest count of frames or observations a setting counts to.
_MOST = 100_000
#: Widest factor on a window or a bound (1e300 overflowed the envelope's coordinates).
_WIDEST = 100.0


def _shown(value: float | None) -> str:
    return "2 pi" if value == _TWO_PI else f"{value:g}"


def _setting(default: Any, info: SettingInfo) -> Any:
    return dataclasses.field(default=default, metadata={_INFO: info})


def _fail(key: str, message: str) -> Exception:
    return InputError(f"ManagerSettings.{key}: {message}")


@dataclass(frozen=True, slots=True)
class ManagerSettings:
    """Every setting of the uncertainty map manager and its localizer, validated once.

    The working map is reduced by observations under their typical bounds and guarded
    by a consistency gate; with ``robust``, an envelope map under worst-case bounds
    (``envelope_factor`` wider, unless the caller gives the envelope's observations) runs
    alongside, and when ``relocalize_after`` of the last ``relocalize_window``
    observations were inconsistent, the working map is re-localized from it (see
    :class:`~aura_ums.manager.UncertaintyMapManager`).

    Each field's unit, range and help are its :class:`SettingInfo` (``SettingInfo.of``
    on ``dataclasses.fields(ManagerSettings)``): the command-line options and the
    scenario reader are built from them. Errors read ``"ManagerSettings.<field>:
    expected ..., got ..."`` (or name the option, key or file the value came from).

    Examples
    --------
    >>> settings = ManagerSettings(area_limit=25.0, robust=False)
    >>> settings.sigmas, settings.area_limit, settings.max_vertices
    (3.0, 25.0, 64)
    >>> ManagerSettings.from_dict(settings.to_dict()) == settings
    True
    >>> ManagerSettings.from_dict({"max_vertices": 24}).max_vertices   # the rest: defaults
    24
    >>> ManagerSettings(relocalize_after=2)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: ManagerSettings.relocalize_window: expected an integer >= \
relocalize_after (2), got 1
    """

    sigmas: float = _setting(
        3.0,
        SettingInfo(
            "Standard deviations of the motion and terrain model that the growth bounds",
            "",
            float,
            low=SIGMAS.low,
            high=SIGMAS.high,
        ),
    )
    area_limit: float | None = _setting(
        None,
        SettingInfo(
            "Map area above which the robot is lost (none: no limit)",
            "m^2",
            float,
            low=0.0,
            low_open=True,
            # The square of every coordinate a map may hold (COORDINATE, +-1e6 m): no map is larger.
            high=4e12,
            nullable=True,
        ),
    )
    missed_limit: int = _setting(
        3,
        SettingInfo(
            "Frames in a row with landmarks predicted and none found that make the robot lost",
            "",
            int,
            low=1,
            high=_MOST,
        ),
    )
    lost_window_scale: float = _setting(
        2.0,
        SettingInfo(
            "Factor by which the Expecter's windows widen while lost", "", float, low=1.0, high=_WIDEST
        ),
    )
    joint_above: float | None = _setting(
        math.pi / 2,
        SettingInfo(
            "Heading wedge width above which the observations of one instant reduce the map "
            "together (none: one by one)",
            "rad",
            float,
            low=0.0,
            high=_TWO_PI,  # a wedge is never wider: above it, the same as none
            nullable=True,
            off_flag="--one-by-one",
        ),
    )
    # joint_sector and max_vertices default to what reduce_jointly and the map's grow and
    # reduce take when not told (tests/manager/test_manager_settings.py holds them equal).
    joint_sector: float = _setting(
        math.radians(5.0),
        SettingInfo(
            "Widest heading sector of the joint reduction", "rad", float, low=0.0, high=_TWO_PI, low_open=True
        ),
    )
    max_vertices: int = _setting(
        64,
        SettingInfo(
            "Cap on the map polygon's vertices, a sliced map's on each slice's (at most 100000): fewer "
            "is faster and looser",
            "",
            int,
            low=3,
            high=MAX_VERTICES,
        ),
    )
    # max_slices defaults to what SpatialUncertaintyMap.with_slices takes (tests/manager/
    # test_sliced_manager.py holds them equal).
    slice_width: float | None = _setting(
        None,
        SettingInfo(
            "Width of the global heading grid's cells of a heading-sliced map, which keeps a "
            "polygon of positions per heading interval (none: the paper's product map, one "
            "polygon for every heading). The grid has a whole number of cells, each at most this "
            "wide: 0.034907 (2 degrees) gives 180 cells, 0.0349 gives 181",
            "rad",
            float,
            low=0.0,
            high=_TWO_PI,
            low_open=True,
            nullable=True,
            off_flag="--product-map",
        ),
    )
    max_slices: int = _setting(
        48,
        SettingInfo(
            "Cap on a sliced map's slice count, at most 100000: beyond it neighbours merge (fewer is "
            "faster and looser)",
            "",
            int,
            low=1,
            high=MAX_SLICES,
        ),
    )
    anchor_growth: bool = _setting(
        False,
        SettingInfo(
            "Grow the map from the last corrected map (the anchor), once by the composite of the "
            "moves since then, with the terrain statistics read at that scale, as calibrate "
            "--anchor fits them (off: the paper's growth, move by move; a map of several "
            "meadows always grows move by move)",
            "",
            bool,
            off_flag="--per-move-growth",
        ),
    )
    anchor_span: float = _setting(
        30.0,
        SettingInfo(
            "Longest time an anchor of the anchored growth is kept: the longest time without "
            "correction the terrain statistics were calibrated for",
            "s",
            float,
            low=0.0,
            low_open=True,
        ),
    )
    robust: bool = _setting(
        True,
        SettingInfo(
            "Keep an envelope map under worst-case bounds and re-localize from it (off: the "
            "consistency gate alone)",
            "",
            bool,
            off_flag="--gate-only",
        ),
    )
    envelope_factor: float = _setting(
        2.0,
        SettingInfo(
            "Factor by which the envelope map's bounds are wider than the working ones",
            "",
            float,
            low=1.0,
            high=_WIDEST,
        ),
    )
    envelope_max_vertices: int | None = _setting(
        None,
        SettingInfo(
            "Cap on the envelope map polygon's vertices, at most 100000 (none: max_vertices)",
            "",
            int,
            low=3,
            high=MAX_VERTICES,
            nullable=True,
        ),
    )
    relocalize_after: int = _setting(
        1,
        SettingInfo(
            "Inconsistent observations among the last relocalize_window that re-localize the working map",
            "",
            int,
            low=1,
            high=_MOST,
        ),
    )
    relocalize_window: int = _setting(
        1, SettingInfo("Observations remembered for relocalize_after", "", int, low=1, high=_MOST)
    )
    relaxed_q: int = _setting(
        0,
        SettingInfo(
            "Wrong observations tolerated among any relaxed_window consecutive ones (repeats of one "
            "landmark count once): the map keeps the poses consistent with all but at most this many "
            "of the latest (0: every one trusted)",
            "",
            int,
            low=0,
            high=_MOST,
        ),
    )
    relaxed_window: int = _setting(
        10,
        SettingInfo(
            "Consecutive observations over which relaxed_q wrong ones are tolerated (shorter: fewer "
            "branches, so faster, and a guarantee that holds on more logs, for somewhat larger maps)",
            "",
            int,
            low=1,
            high=_MOST,
        ),
    )

    def __post_init__(self) -> None:
        values = _checked({f.name: getattr(self, f.name) for f in _FIELDS}, _fail)
        for name, value in values.items():
            object.__setattr__(self, name, value)

    def to_dict(self) -> dict[str, SettingValue]:
        """Return the settings as a JSON-ready dictionary, field name to value (None for none)."""
        return {f.name: getattr(self, f.name) for f in _FIELDS}

    @classmethod
    def from_dict(
        cls,
        data: Mapping[str, object],
        *,
        base: ManagerSettings | None = None,
        fail: Callable[[str, str], Exception] | None = None,
    ) -> ManagerSettings:
        """Return the settings of ``data`` (field name to value); missing fields are ``base``'s.

        Parameters
        ----------
        data : Mapping[str, object]
            Field names to values, as :meth:`to_dict` writes them.
        base : ManagerSettings or None
            Where the fields ``data`` leaves out come from (default: the defaults).
        fail : callable or None
            ``fail(field, message)`` returns the exception to raise for a bad field (a
            reader names its file and key); default: an :class:`InputError` naming
            ``ManagerSettings.<field>``.

        Raises
        ------
        InputError
            (or what ``fail`` returns) for an unknown field or a bad value.

        Examples
        --------
        >>> ManagerSettings.from_dict({"sigma": 2.0})
        Traceback (most recent call last):
        ...
        aura_ums.errors.InputError: ManagerSettings.sigma: expected a field of ManagerSettings \
(sigmas, area_limit, missed_limit, lost_window_scale, joint_above, joint_sector, max_vertices, \
slice_width, max_slices, anchor_growth, anchor_span, robust, envelope_factor, envelope_max_vertices, \
relocalize_after, relocalize_window, relaxed_q, relaxed_window), got 'sigma'
        """
        report = _fail if fail is None else fail
        if not isinstance(data, Mapping):
            raise report("", f"expected a mapping of field names to values, got {type(data).__name__}")
        start = ManagerSettings() if base is None else base
        values: dict[str, object] = dict(start.to_dict())
        for key, value in data.items():
            if key not in _INFOS:
                raise report(
                    str(key), f"expected a field of ManagerSettings ({', '.join(_INFOS)}), got {key!r}"
                )
            values[key] = value
        changes: dict[str, Any] = _checked(values, report, given=frozenset(map(str, data)))
        return dataclasses.replace(start, **changes)


_FIELDS = dataclasses.fields(ManagerSettings)
_INFOS = {f.name: SettingInfo.of(f) for f in _FIELDS}


def _checked(
    values: Mapping[str, object], fail: Callable[[str, str], Exception], given: Collection[str] = ()
) -> dict[str, SettingValue]:
    """Check every field of ``values`` and the fields' relations; return them normalized.

    ``given`` names the fields the caller set (the others are defaults or a base's): when
    two fields conflict, the one set is named.
    """
    checked: dict[str, SettingValue] = {}
    for name, info in _INFOS.items():
        value = values[name]
        problem = info.problem(value)
        if problem is not None:
            raise fail(name, problem)
        checked[name] = info.normalize(value)
    width, cells = checked["slice_width"], 1
    if isinstance(width, float):
        # 2 pi / 1e-12 heading cells failed deep in the kernel, as a traceback
        try:
            cells = cell_count(width)
        except InputError as exc:
            raise fail("slice_width", str(exc).partition(": ")[2]) from None
    sector = checked["joint_sector"]
    if isinstance(sector, float) and sector < MIN_SECTOR:
        # 2 pi / 1e-300 sectors overflowed the joint reduction's kernel
        raise fail(
            "joint_sector",
            f"expected at least {MIN_SECTOR:g} rad (0.1 degree: a joint reduction costs in proportion "
            f"to its sectors), got {sector!r}",
        )
    after, window = checked["relocalize_after"], checked["relocalize_window"]
    if isinstance(after, int) and isinstance(window, int) and window < after:
        if _blames_count("relocalize_after", "relocalize_window", given):
            raise fail(
                "relocalize_after", f"expected an integer <= relocalize_window ({window}), got {after}"
            )
        raise fail("relocalize_window", f"expected an integer >= relocalize_after ({after}), got {window}")
    allowed, span = checked["relaxed_q"], checked["relaxed_window"]
    if isinstance(allowed, int) and isinstance(span, int) and allowed > 0 and span <= allowed:
        if _blames_count("relaxed_q", "relaxed_window", given):
            raise fail("relaxed_q", f"expected an integer < relaxed_window ({span}), got {allowed}")
        raise fail("relaxed_window", f"expected an integer > relaxed_q ({allowed}), got {span}")
    branches = 1
    if isinstance(allowed, int) and isinstance(span, int) and allowed > 0:
        branches = branch_bound(allowed, span)
        if branches > MAX_BRANCHES:
            name = "relaxed_window" if "relaxed_window" in given and "relaxed_q" not in given else "relaxed_q"
            raise fail(
                name,
                f"expected at most {MAX_BRANCHES} branches of the relaxed intersection (the sum of "
                f"C(relaxed_window, k) for k <= relaxed_q), got {'more than ' if branches > 10**15 else ''}"
                f"{min(branches, 10**15)} (relaxed_q {allowed}, relaxed_window {span})",
            )
    _refuse_too_many_vertices(checked, cells, branches, fail, given)
    return checked


#: Most polygon vertices a map may hold at its caps: ``max_vertices`` (or the envelope's) times
#: its slices times the relaxed intersection's branches. The relaxed profile (1,080 polygons)
#: at a cap of 1000, 3000 and 10,000 vertices replayed the 60 s sample log in 2.6, 9.8 and
#: 70 s (0.16, 0.38 and 1.8 GB); at 100,000 it passed 4 GB and ignored Ctrl-C for minutes.
MAX_VERTEX_SLOTS = 4_000_000


def _refuse_too_many_vertices(
    checked: Mapping[str, SettingValue],
    cells: int,
    branches: int,
    fail: Callable[[str, str], Exception],
    given: Collection[str],
) -> None:
    """Refuse caps whose worst case holds more than :data:`MAX_VERTEX_SLOTS` vertices, with the count.

    ``cells`` is the heading grid's (1 for a product map), ``branches`` the relaxed
    intersection's most (1 without it).
    """
    vertices, envelope = checked["max_vertices"], checked["envelope_max_vertices"]
    slices = checked["max_slices"]
    if not (isinstance(vertices, int) and isinstance(slices, int)):
        return
    cap = max(vertices, envelope if isinstance(envelope, int) else 0)
    polygons = min(cells, slices)
    slots = cap * polygons * branches
    if slots > MAX_VERTEX_SLOTS:
        wider = isinstance(envelope, int) and envelope > vertices
        name = "envelope_max_vertices" if wider else "max_vertices"
        if name not in given and "max_slices" in given:
            name = "max_slices"
        raise fail(
            name,
            f"expected at most {MAX_VERTEX_SLOTS} vertices at the caps (the vertex cap {cap} times "
            f"{polygons} slices times {branches} branches of the relaxed intersection), got {slots}",
        )


#: Most branches the relaxed intersection may keep. Each is a map grown and reduced at every
#: step: on a 90 s log, q = 1 over N = 1000 (1001 branches) replayed in 2.6 s, and q = 3 over
#: N = 100 (166,751) passed 2 GB and 100 s without finishing.
MAX_BRANCHES = 2000


def branch_bound(q: int, window: int) -> int:
    """Return the most branches of a ``q``-relaxed intersection over ``window`` observations.

    ``sum(C(window, k) for k <= q)``, counted only until it passes ``10**15``.

    Examples
    --------
    >>> branch_bound(1, 5), branch_bound(3, 100), branch_bound(0, 10)
    (6, 166751, 1)
    """
    total, term = 0, 1
    for k in range(min(q, window) + 1):
        total += term
        if total > 10**15:
            break
        term = term * (window - k) // (k + 1)
    return total


def _blames_count(count: str, window: str, given: Collection[str]) -> bool:
    """Whether a count too large for its window is the count's fault: set, while the window was not.

    A command line that sets ``--relaxed-q 100000`` alone is told about ``--relaxed-q``,
    not about the default ``--relaxed-window`` it never gave.
    """
    return count in given and window not in given


def _document() -> str:
    """Return the class docstring with a Parameters section written from the fields' infos."""
    lines = ["Parameters", "----------"]
    for field in _FIELDS:
        info = _INFOS[field.name]
        unit = f"Unit: {info.unit}. " if info.unit else ""
        text = f"{info.help}. {unit}Valid: {info.expected}. Default: {field.default!r}."
        lines.append(f"{field.name} : {info.kind.__name__}" + (" or None" if info.nullable else ""))
        lines += textwrap.wrap(text, 84, initial_indent="    ", subsequent_indent="    ")
    doc = ManagerSettings.__doc__ or ""
    head, examples = doc.split("    Examples\n", 1)
    section = "".join(f"    {line}\n" for line in lines)
    return f"{head}{section}\n    Examples\n{examples}"


ManagerSettings.__doc__ = _document()


class MapProfile(Choice):
    """How the manager represents the map: the three trade-offs measured on real logs.

    Each profile sets :attr:`fields` and leaves every other setting as it was. Measured
    on MRCLAM, calibrated on one robot and replayed on six others (``docs/real-logs.md``,
    "The three profiles"):

    - ``PRODUCT``: the paper's map, one polygon times one heading wedge (the defaults).
      The fastest, about 0.05-0.1 ms a frame; its windows cover 0.6 to all of the width
      of a 60 degree camera's frame, and a misread landmark can leave the truth outside
      (it stayed inside 0.90 to 1.00 of the time).
    - ``SLICED``: a polygon per 2 degree heading cell (``slice_width``), so position and
      heading stay coupled: windows about a quarter of the frame and a fifth to a half
      of the area, at about 0.2-0.4 ms a frame; a misread landmark or an observation beyond its
      calibrated bounds cuts deeper (the truth stayed inside 0.89 to 1.00 of the time).
    - ``RELAXED``: ``SLICED`` with the q-relaxed intersection (``relaxed_q = 1`` over
      ``relaxed_window = 5`` observations) and no slice cap (``max_slices`` 180, every cell):
      the truth stays inside whenever at most one landmark among any 5 consecutive
      observations is wrong (it stayed inside 0.998 to 1.000 of the time), for guaranteed
      windows of 0.33-0.39 of the frame with range and bearing and 0.42-0.59 with bearings
      only, and focus windows (searched first: :attr:`UncertaintyMapManager.focus_map`) of
      0.26 and 0.27-0.31, at about 2-4 ms a frame with range and bearing and 6-8 ms with
      bearings only. It shrinks only where more than ``relaxed_q`` sightings of the window
      agree: with few sightings a frame and much growth between frames it keeps the truth
      but grows until the manager is lost (the simulator's four-terrain scenario, a frame
      every 2 m: 53-55 of 60 runs lost, against 27-30 with ``PRODUCT`` and 14-18 with
      ``SLICED``).

    Examples
    --------
    >>> settings = MapProfile.RELAXED.settings(ManagerSettings(area_limit=25.0))
    >>> settings.relaxed_q, settings.relaxed_window, settings.max_slices, settings.area_limit
    (1, 5, 180, 25.0)
    >>> round(math.degrees(settings.slice_width), 6)
    2.0
    >>> MapProfile.PRODUCT.settings(settings) == ManagerSettings(area_limit=25.0)   # back to the paper's
    True
    >>> MapProfile("sliced") is MapProfile.SLICED
    True
    """

    PRODUCT = "product"
    SLICED = "sliced"
    RELAXED = "relaxed"

    @property
    def fields(self) -> Mapping[str, SettingValue]:
        """The settings this profile sets, field name to value (read-only)."""
        return _PROFILE_FIELDS[self]

    def settings(self, base: ManagerSettings | None = None) -> ManagerSettings:
        """Return ``base`` (default: the defaults) with this profile's :attr:`fields`."""
        return ManagerSettings.from_dict(self.fields, base=base)


#: Radians: the SLICED and RELAXED profiles' heading cells, the width measured best on real logs
#: (docs/real-logs.md, "The slice width"); SpatialUncertaintyMap.with_slices' default too.
_PROFILE_SLICE_WIDTH = math.radians(2.0)
#: Observations over which the RELAXED profile tolerates one wrong landmark: as sound as 10 on
#: the real logs, at about 0.6 of the time (docs/real-logs.md, "The relaxed window").
_RELAXED_WINDOW = 5
# Without the relaxed intersection its window is unused: the field's default, so that a
# profile leaves the settings as ManagerSettings() has them.
_UNUSED_WINDOW: int = ManagerSettings().relaxed_window
#: The PRODUCT and SLICED profiles' slice cap: the field's default.
_DEFAULT_MAX_SLICES: int = ManagerSettings().max_slices
#: The RELAXED profile's slice cap: every cell of its grid, so neighbours never merge. With
#: bearings only, the cap of 48 merged the wide branches' slices and widened the focus
#: windows to 0.28-0.40 of the frame; without it they are 0.27-0.31, the guaranteed ones
#: 0.43-0.60 instead of 0.44-0.83, at about the same time (docs/real-logs.md, "The focus window").
_RELAXED_MAX_SLICES = round(2.0 * math.pi / _PROFILE_SLICE_WIDTH)
_PROFILE_FIELDS = {
    MapProfile.PRODUCT: MappingProxyType(
        {
            "slice_width": None,
            "max_slices": _DEFAULT_MAX_SLICES,
            "relaxed_q": 0,
            "relaxed_window": _UNUSED_WINDOW,
        }
    ),
    MapProfile.SLICED: MappingProxyType(
        {
            "slice_width": _PROFILE_SLICE_WIDTH,
            "max_slices": _DEFAULT_MAX_SLICES,
            "relaxed_q": 0,
            "relaxed_window": _UNUSED_WINDOW,
        }
    ),
    MapProfile.RELAXED: MappingProxyType(
        {
            "slice_width": _PROFILE_SLICE_WIDTH,
            "max_slices": _RELAXED_MAX_SLICES,
            "relaxed_q": 1,
            "relaxed_window": _RELAXED_WINDOW,
        }
    ),
}
