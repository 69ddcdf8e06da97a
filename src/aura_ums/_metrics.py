"""One shape for the figures that ``simulate``, ``replay`` and ``compare`` report.

:class:`Metrics` is a read-only mapping whose keys all come from one table, the only place
where a key's unit and meaning are written (``docs/metrics.md`` shows it and a test keeps
the two equal). It checks each value against its key's type once, when it is built, and
stores an undefined number (no frames, no ground truth) as ``None``: written as JSON, it
is ``null``, never ``NaN`` or ``Infinity``.
"""

from __future__ import annotations

import enum
import json
import math
import numbers
import os
import types
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import InitVar, dataclass, field
from pathlib import Path
from typing import TypeAlias

from aura_ums.errors import InputError

__all__ = ["MetricKey", "MetricValue", "Metrics"]


class _Kind(enum.Enum):
    """What a key holds; the JSON type follows from it."""

    TEXT = "text"
    FLAG = "true/false"
    INTEGER = "integer"
    COUNT = "count"
    FRACTION = "fraction"
    NUMBER = "number"
    BY_REASON = "count by reason"
    ROWS = "list of metrics"


# Who writes a key; also the column "written by" of docs/metrics.md.
SIMULATE = "simulate"
REPLAY = "replay"
REPLAY_LOGS = "replay (several logs)"
COMPARE = "compare"
COMPARE_ROW = "compare (per method)"
STEPS_CSV = "replay --steps-csv"
CAMERA = "replay --camera"
CAMERA_ROW = "replay --camera (per baseline)"
WINDOWS_CSV = "replay --windows-csv"


@dataclass(frozen=True, slots=True)
class MetricKey:
    """One row of the metrics table: a key, its unit and its meaning.

    Attributes
    ----------
    name : str
        The key, as written in JSON and printed.
    unit : str
        ``"m²"``, ``"rad"``, ``"µs"``, ``"ms"``, ``"s"``, ``"m"``; ``"fraction"`` for a
        number in [0, 1]; ``"count"``; ``""`` for text and flags.
    kind : str
        The value's type: ``"text"``, ``"true/false"``, ``"integer"``, ``"count"``
        (integer >= 0), ``"fraction"`` (number in [0, 1]), ``"number"``,
        ``"count by reason"`` (an object of counts) or ``"list of metrics"``.
    written_by : tuple of str
        The outputs that hold the key: ``"simulate"``, ``"replay"``, ``"compare"``,
        ``"compare (per method)"``, ``"replay --steps-csv"`` (a column of the per-step CSV),
        ``"replay --camera"``, ``"replay --camera (per baseline)"`` (an entry of
        ``window_baselines``), ``"replay --windows-csv"`` (a column of the per-window CSV),
        ``"replay (several logs)"`` (a replay of several LOG_DIRs at once).
    meaning : str
        One sentence, with what ``null`` means when the value can be undefined.
    """

    name: str
    unit: str
    kind: str
    written_by: tuple[str, ...]
    meaning: str


def _key(name: str, unit: str, kind: _Kind, written_by: tuple[str, ...], meaning: str) -> MetricKey:
    return MetricKey(name, unit, kind.value, written_by, meaning)


_K = _Kind
# The one table. Order: what was run, then the figures; each output prints in its own order.
_TABLE: tuple[MetricKey, ...] = (
    _key("scenario", "", _K.TEXT, (SIMULATE,), "Name of the scenario simulated."),
    _key("runs", "count", _K.COUNT, (SIMULATE,), "Monte Carlo runs."),
    _key("seed", "", _K.INTEGER, (SIMULATE,), "Seed of the whole Monte Carlo."),
    _key("prune", "", _K.FLAG, (SIMULATE,), "Whether landmarks reduced the map (false: growth only)."),
    _key(
        "perception",
        "",
        _K.TEXT,
        (SIMULATE,),
        "Where the find-landmark schemas looked: windows, full_frame or focus_first (simulate --perception).",
    ),
    _key(
        "replays",
        "",
        _K.ROWS,
        (REPLAY_LOGS,),
        "One entry per log, in the order given, with the keys replay writes for one log.",
    ),
    _key(
        "runs_retried",
        "count",
        _K.COUNT,
        (SIMULATE, REPLAY_LOGS),
        "Runs (or logs) submitted again because their Dask worker died or they timed out, each counted "
        "once; always 0 in one process.",
    ),
    _key("log", "", _K.TEXT, (REPLAY, COMPARE), "Name of the log (its meta.toml)."),
    _key(
        "landmark_class",
        "",
        _K.TEXT,
        (REPLAY, COMPARE, WINDOWS_CSV),
        "I (bearings only) or II (range and bearing).",
    ),
    _key("sigmas", "sd", _K.NUMBER, (REPLAY,), "Standard deviations of the motion bounded by the growth."),
    _key("robust", "", _K.FLAG, (REPLAY,), "Whether an envelope map re-localized the working map."),
    _key(
        "joint_above_rad",
        "rad",
        _K.NUMBER,
        (REPLAY,),
        "Wedge width above which a frame's observations reduce the map together; null: one by one.",
    ),
    _key(
        "max_vertices",
        "count",
        _K.COUNT,
        (REPLAY,),
        "Cap on the map polygon's vertices (a sliced map's: each slice's).",
    ),
    _key(
        "envelope_max_vertices",
        "count",
        _K.COUNT,
        (REPLAY,),
        "Cap on the envelope map polygon's vertices; null: max_vertices.",
    ),
    _key(
        "bearing_sd_rad",
        "rad",
        _K.NUMBER,
        (COMPARE,),
        "Bearing noise of the filters: standard deviation of the logs' bearing errors.",
    ),
    _key(
        "range_sd_fraction",
        "fraction",
        _K.NUMBER,
        (COMPARE,),
        "Range noise of the filters: standard deviation of the logs' range errors, a fraction of the range.",
    ),
    _key("methods", "", _K.ROWS, (COMPARE,), "One entry per method: ours, the EKF, the particle filter."),
    _key(
        "method",
        "",
        _K.TEXT,
        (COMPARE_ROW, CAMERA_ROW, WINDOWS_CSV),
        "aura-ums, EKF, PF (particles), codac, or a method of yours; for windows: aura-ums, "
        "aura-ums focus, EKF 3-sigma box or disk model.",
    ),
    _key("frames", "count", _K.COUNT, (SIMULATE,), "Frames of all runs (one command and one image each)."),
    _key(
        "steps",
        "count",
        _K.COUNT,
        (REPLAY,),
        "Steps replayed: the log's frames (time stamps with observations).",
    ),
    _key(
        "steps_with_truth", "count", _K.COUNT, (REPLAY,), "Steps with a ground-truth pose to judge against."
    ),
    _key("runs_lost", "count", _K.COUNT, (SIMULATE,), "Runs in which the manager declared itself lost."),
    _key("runs_completed", "count", _K.COUNT, (SIMULATE,), "Runs that reached the end of their route."),
    _key(
        "containment_rate",
        "fraction",
        _K.FRACTION,
        (SIMULATE, REPLAY, COMPARE_ROW),
        "Fraction of the judged frames or steps whose true pose is inside the region "
        "(our map; a filter's confidence region); null: none judged.",
    ),
    _key(
        "envelope_containment_rate",
        "fraction",
        _K.FRACTION,
        (REPLAY,),
        "The same for the envelope map; null: no envelope (gate only) or no ground truth.",
    ),
    _key(
        "median_area_m2",
        "m²",
        _K.NUMBER,
        (SIMULATE, REPLAY, COMPARE_ROW),
        "Median area of the position region after each frame or step; null: none.",
    ),
    _key(
        "median_wedge_width_rad",
        "rad",
        _K.NUMBER,
        (SIMULATE, REPLAY, COMPARE_ROW),
        "Median width of the heading region (our wedge; a filter's confidence interval); null: none.",
    ),
    _key(
        "position_rmse_m",
        "m",
        _K.NUMBER,
        (COMPARE_ROW,),
        "Root mean square distance from the map's centre, its most probable position (ours; not the "
        "polygon's centroid), or the mean (a filter) to the true position; null: no ground truth.",
    ),
    _key(
        "landmark_detection_rate",
        "fraction",
        _K.FRACTION,
        (SIMULATE,),
        "Landmarks found per window searched; null: no window searched.",
    ),
    _key(
        "accepted_observations",
        "count",
        _K.COUNT,
        (SIMULATE, REPLAY),
        "Observations that reduced the map.",
    ),
    _key(
        "inconsistent_observations",
        "count",
        _K.COUNT,
        (SIMULATE, REPLAY, COMPARE_ROW),
        "Observations rejected, all reasons together (ours: the manager; a filter: its gate; "
        "codac: its re-initialisations).",
    ),
    _key(
        "rejected_by_reason",
        "count",
        _K.BY_REASON,
        (REPLAY,),
        "Rejected observations by reason; the counts add up to inconsistent_observations.",
    ),
    _key("relocalizations", "count", _K.COUNT, (REPLAY,), "Times the envelope re-seeded the working map."),
    _key(
        "observations_before_start",
        "count",
        _K.COUNT,
        (REPLAY,),
        "Observations at or before the replay's start (the later of the first motion and the first "
        "ground truth, or meta.toml's start): not replayed.",
    ),
    _key(
        "slice_width_rad",
        "rad",
        _K.NUMBER,
        (SIMULATE, REPLAY),
        "Width of the heading cells of the sliced map; null: the product map (one polygon x one wedge).",
    ),
    _key(
        "relaxed_q",
        "count",
        _K.COUNT,
        (SIMULATE, REPLAY),
        "Wrong observations the relaxed intersection tolerates among any relaxed_window consecutive ones.",
    ),
    _key(
        "relaxed_window",
        "count",
        _K.COUNT,
        (SIMULATE, REPLAY),
        "Consecutive observations (N) over which relaxed_q wrong ones are tolerated.",
    ),
    _key(
        "excluded_observations",
        "count",
        _K.COUNT,
        (SIMULATE, REPLAY),
        "Observations the relaxed intersection excluded: every branch it kept counted them as wrong "
        "(always 0 with relaxed_q = 0).",
    ),
    _key(
        "injected_observations",
        "count",
        _K.COUNT,
        (SIMULATE,),
        "Wrong observations the simulator injected (the scenario's inject_wrong_rate).",
    ),
    _key(
        "ambiguous_identifications",
        "count",
        _K.COUNT,
        (SIMULATE,),
        "Landmarks found but not posted: each lay where another mapped landmark of the same kind may "
        "appear, so which one it was could not be told.",
    ),
    _key(
        "median_update_us",
        "µs",
        _K.NUMBER,
        (REPLAY, COMPARE_ROW),
        "Median time of one step's update: growth since the previous step and the step's "
        "observations; null: no steps.",
    ),
    _key(
        "median_frame_ms",
        "ms",
        _K.NUMBER,
        (SIMULATE,),
        "Median time of one frame of the loop: schemas, perception and manager, not the rendering.",
    ),
    _key(
        "window_margin_px",
        "px",
        _K.NUMBER,
        (CAMERA,),
        "Pixels added on every side of every image window before clipping it to the image.",
    ),
    _key(
        "window_observations",
        "count",
        _K.COUNT,
        (CAMERA,),
        "Real observations the windows are judged on: those whose measured pixel "
        "(Class I: column) lies in the camera's image.",
    ),
    _key(
        "window_containment",
        "fraction",
        _K.FRACTION,
        (CAMERA, CAMERA_ROW),
        "Fraction of the judged observations whose measured pixel (Class I: column; Class II: "
        "column and row) is one the window asked for before the observation was applied meets "
        "(the window as whole pixels); null: none judged.",
    ),
    _key(
        "window_truth_containment",
        "fraction",
        _K.FRACTION,
        (CAMERA, CAMERA_ROW),
        "The same for the landmark projected from the true pose (the Expecter's guarantee), over "
        "the judged observations whose true projection is in the image; null: none, or no ground truth.",
    ),
    _key(
        "median_window_width_frac",
        "fraction",
        _K.FRACTION,
        (CAMERA, CAMERA_ROW),
        "Median over the judged observations of the window's width over the image's "
        "(0 without a window); null: none judged.",
    ),
    _key(
        "median_window_area_frac",
        "fraction",
        _K.FRACTION,
        (CAMERA, CAMERA_ROW),
        "Median over the judged observations of the window's area over the image's; null: none judged.",
    ),
    _key(
        "focus_window_containment",
        "fraction",
        _K.FRACTION,
        (CAMERA,),
        "window_containment of the windows from the focus map (UncertaintyMapManager.focus_map: "
        "with the relaxed intersection, the poses that agree with every recent sighting; "
        "without it, the map itself, so the same figure).",
    ),
    _key(
        "focus_window_truth_containment",
        "fraction",
        _K.FRACTION,
        (CAMERA,),
        "window_truth_containment of the windows from the focus map (not guaranteed: the focus map "
        "may leave the truth out while a wrong sighting is in the relaxed window).",
    ),
    _key(
        "median_focus_window_width_frac",
        "fraction",
        _K.FRACTION,
        (CAMERA,),
        "median_window_width_frac of the windows from the focus map.",
    ),
    _key(
        "median_searched_width_frac",
        "fraction",
        _K.FRACTION,
        (CAMERA,),
        "Median over the judged observations of the width a focus-first search scans, over the "
        "image's: the focus window's when the measured pixel is in it, else the (guaranteed) "
        "window's; null: none judged.",
    ),
    _key(
        "window_baselines",
        "",
        _K.ROWS,
        (CAMERA,),
        "One entry per baseline judged on the same observations at the same moments: the EKF's "
        "3-sigma box, the disk model.",
    ),
    _key(
        "time",
        "s",
        _K.NUMBER,
        (STEPS_CSV, WINDOWS_CSV),
        "Time stamp of the step (windows: of the observation's step).",
    ),
    _key(
        "inside",
        "",
        _K.FLAG,
        (STEPS_CSV,),
        "1 if the true pose is inside the map, 0 if not; empty: no truth.",
    ),
    _key("area_m2", "m²", _K.NUMBER, (STEPS_CSV,), "Area of the map after the step."),
    _key("wedge_width_rad", "rad", _K.NUMBER, (STEPS_CSV,), "Width of the heading wedge after the step."),
    _key("accepted", "count", _K.COUNT, (STEPS_CSV,), "Observations of the step that reduced the map."),
    _key("rejected", "count", _K.COUNT, (STEPS_CSV,), "Observations of the step that were rejected."),
    _key("update_us", "µs", _K.NUMBER, (STEPS_CSV,), "Time of the step's update."),
    _key("state", "", _K.TEXT, (STEPS_CSV,), "The manager's state after the step (nominal, lost, ...)."),
    _key("relocalized", "", _K.FLAG, (STEPS_CSV,), "1 if the envelope re-seeded the map at this step."),
    _key("landmark_id", "", _K.TEXT, (WINDOWS_CSV,), "Id of the landmark observed."),
    _key("u_min_px", "px", _K.NUMBER, (WINDOWS_CSV,), "Left bound of the window; empty: no window."),
    _key("v_min_px", "px", _K.NUMBER, (WINDOWS_CSV,), "Top bound of the window; empty: no window."),
    _key("u_max_px", "px", _K.NUMBER, (WINDOWS_CSV,), "Right bound of the window; empty: no window."),
    _key("v_max_px", "px", _K.NUMBER, (WINDOWS_CSV,), "Bottom bound of the window; empty: no window."),
    _key(
        "measured_u_px",
        "px",
        _K.NUMBER,
        (WINDOWS_CSV,),
        "Column of the measured bearing (at the measured range); empty: behind the camera.",
    ),
    _key(
        "measured_v_px",
        "px",
        _K.NUMBER,
        (WINDOWS_CSV,),
        "Row from the measured range and the landmark's height (Class II); empty: Class I, or no range.",
    ),
    _key(
        "in_view", "", _K.FLAG, (WINDOWS_CSV,), "1 if the measured pixel is in the image (judged), 0 if not."
    ),
    _key(
        "in_window",
        "",
        _K.FLAG,
        (WINDOWS_CSV,),
        "1 if the measured pixel is inside the window, 0 if not; empty: not judged.",
    ),
    _key(
        "truth_in_window",
        "",
        _K.FLAG,
        (WINDOWS_CSV,),
        "1 if the landmark projected from the true pose is inside the window, 0 if not; empty: "
        "not judged, no truth, or that projection is out of the image.",
    ),
    _key(
        "window_width_frac",
        "fraction",
        _K.FRACTION,
        (WINDOWS_CSV,),
        "The window's width over the image's (0 without a window).",
    ),
    _key(
        "window_area_frac",
        "fraction",
        _K.FRACTION,
        (WINDOWS_CSV,),
        "The window's area over the image's (0 without a window).",
    ),
)
_BY_NAME: Mapping[str, MetricKey] = types.MappingProxyType({key.name: key for key in _TABLE})

#: A value of :class:`Metrics`: ``None`` is undefined (``null`` in JSON).
MetricValue: TypeAlias = "str | bool | int | float | Mapping[str, int] | tuple[Metrics, ...] | None"


def _check_count(value: object, where: str, minimum: int | None) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise InputError(f"{where}: expected an integer, got {value!r}")
    number = int(value)
    if minimum is not None and number < minimum:
        raise InputError(f"{where}: expected an integer >= {minimum}, got {number}")
    return number


def _check_number(value: object, where: str) -> float | None:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise InputError(f"{where}: expected a number or None, got {value!r}")
    number = float(value)
    # One undefined value: NaN and the infinities become None, written as null.
    return number if math.isfinite(number) else None


def _checked(key: MetricKey, value: object) -> MetricValue:
    """Return ``value`` in the one form :class:`Metrics` keeps for ``key``'s kind."""
    where = f"Metrics[{key.name!r}]"
    kind = _Kind(key.kind)
    if value is None:
        return None
    if kind is _Kind.TEXT:
        if not isinstance(value, str):
            raise InputError(f"{where}: expected text, got {value!r}")
        return str(value)
    if kind is _Kind.FLAG:
        if not isinstance(value, bool):
            raise InputError(f"{where}: expected True or False, got {value!r}")
        return value
    if kind is _Kind.INTEGER:
        return _check_count(value, where, None)
    if kind is _Kind.COUNT:
        return _check_count(value, where, 0)
    if kind is _Kind.FRACTION:
        fraction = _check_number(value, where)
        if fraction is not None and not 0.0 <= fraction <= 1.0:
            raise InputError(f"{where}: expected a fraction in [0, 1] or None, got {fraction!r}")
        return fraction
    if kind is _Kind.NUMBER:
        return _check_number(value, where)
    if kind is _Kind.BY_REASON:
        if not isinstance(value, Mapping):
            raise InputError(f"{where}: expected a mapping of reasons to counts, got {value!r}")
        counts: dict[str, int] = {}
        for reason, count in value.items():
            if not isinstance(reason, str):
                raise InputError(f"{where}: expected reasons as text, got {reason!r}")
            counts[str(reason)] = _check_count(count, f"{where}[{reason!r}]", 0)
        return types.MappingProxyType(counts)
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence):
        raise InputError(f"{where}: expected a sequence of Metrics, got {value!r}")
    rows = tuple(value)
    for row in rows:
        if not isinstance(row, Metrics):
            raise InputError(f"{where}: expected a sequence of Metrics, got an item {row!r}")
    return rows


def _shown(value: MetricValue) -> str:
    """Return ``value`` as a terminal shows it: six significant digits, ``n/a`` for undefined."""
    if value is None:
        return "n/a"
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, Mapping):
        return ", ".join(f"{reason} {count}" for reason, count in value.items()) or "none"
    if isinstance(value, tuple):
        return f"{len(value)} entries"
    return str(value)


def _plain(value: MetricValue) -> object:
    """Return ``value`` as plain JSON data (dicts, lists, numbers, text, None)."""
    if isinstance(value, Mapping):
        return dict(value)
    if isinstance(value, tuple):
        return [row.to_dict() for row in value]
    return value


@dataclass(frozen=True, slots=True, eq=False)
class Metrics(Mapping[str, "MetricValue"]):
    """The figures of one simulation, replay or comparison: a read-only mapping.

    Every key is one of the metrics table (:meth:`table`, shown in ``docs/metrics.md``),
    so ``simulate``, ``replay`` and ``compare`` name and measure the same thing the same
    way: ``containment_rate`` is a fraction, ``median_area_m2`` square metres,
    ``median_wedge_width_rad`` radians, ``median_update_us`` microseconds. Each value is
    checked against its key's type when the metrics are built; an undefined number (NaN
    or an infinity: no frame judged, no step timed) is kept as ``None``. The order of the
    keys is the order given.

    Parameters
    ----------
    figures : Mapping[str, object]
        Key -> value. Numbers may be numpy scalars; they are kept as ``int`` or ``float``.

    Raises
    ------
    InputError
        For a key outside the table or a value of the wrong type (a fraction outside
        [0, 1], a negative count, text for a number).

    Examples
    --------
    >>> metrics = Metrics({"containment_rate": 1.0, "median_area_m2": float("nan"), "steps": 0})
    >>> metrics["containment_rate"], metrics["median_area_m2"]
    (1.0, None)
    >>> print(metrics.to_json(), end="")
    {
      "containment_rate": 1.0,
      "median_area_m2": null,
      "steps": 0
    }
    >>> Metrics({"containment_rate": 1.5})
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: Metrics['containment_rate']: expected a fraction in [0, 1] or None, got 1.5
    >>> Metrics({"area": 1.0})
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: Metrics: expected a key of the metrics table (docs/metrics.md), got 'area'
    """

    figures: InitVar[Mapping[str, object]]
    _values: Mapping[str, MetricValue] = field(init=False)

    def __post_init__(self, figures: Mapping[str, object]) -> None:
        if not isinstance(figures, Mapping):
            raise InputError(f"Metrics: expected a mapping of keys to values, got {type(figures).__name__}")
        checked: dict[str, MetricValue] = {}
        for name, value in figures.items():
            key = _BY_NAME.get(name) if isinstance(name, str) else None
            if key is None:
                raise InputError(
                    f"Metrics: expected a key of the metrics table (docs/metrics.md), got {name!r}"
                )
            checked[name] = _checked(key, value)
        # Validated once, here; frozen afterwards.
        object.__setattr__(self, "_values", types.MappingProxyType(checked))

    @staticmethod
    def table() -> tuple[MetricKey, ...]:
        """Return the metrics table: every key any output may hold, with unit and meaning.

        Examples
        --------
        >>> row = {key.name: key for key in Metrics.table()}["median_update_us"]
        >>> row.unit, row.written_by
        ('µs', ('replay', 'compare (per method)'))
        """
        return _TABLE

    def __getitem__(self, name: str) -> MetricValue:
        return self._values[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._values)

    def __len__(self) -> int:
        return len(self._values)

    def __repr__(self) -> str:
        return f"Metrics({dict(self._values)!r})"

    def number(self, name: str) -> float:
        """Return a numeric value as a float; NaN when it is undefined.

        Raises
        ------
        KeyError
            When ``name`` is not in these metrics.
        InputError
            When ``name`` does not hold a number (text, a flag, counts by reason).

        Examples
        --------
        >>> metrics = Metrics({"frames": 8, "landmark_detection_rate": None})
        >>> metrics.number("frames"), metrics.number("landmark_detection_rate")
        (8.0, nan)
        """
        value = self._values[name]
        if _Kind(_BY_NAME[name].kind) not in (_Kind.INTEGER, _Kind.COUNT, _Kind.FRACTION, _Kind.NUMBER):
            raise InputError(f"Metrics.number: expected a numeric key, got {name!r} ({_BY_NAME[name].kind})")
        return float(value) if isinstance(value, (int, float)) else math.nan

    def to_dict(self) -> dict[str, object]:
        """Return the metrics as plain JSON data: dicts, lists, numbers, text and None.

        Examples
        --------
        >>> Metrics({"rejected_by_reason": {"stale": 2}}).to_dict()
        {'rejected_by_reason': {'stale': 2}}
        """
        return {name: _plain(value) for name, value in self._values.items()}

    def to_json(self) -> str:
        """Return the metrics as strict JSON (undefined values are ``null``), indented, one final newline."""
        return json.dumps(self.to_dict(), indent=2, allow_nan=False, ensure_ascii=False) + "\n"

    def write_json(self, path: str | os.PathLike[str]) -> Path:
        """Write :meth:`to_json` to ``path`` atomically and return the path.

        The text goes to a temporary file in the target folder (created when missing),
        which then replaces ``path``: a reader sees the old file or the whole new one, and
        a failed write leaves neither a temporary file nor a folder made for it.

        Raises
        ------
        OSError
            When the folder cannot be created or written.
        """
        # Imported here: reading metrics (the CLI's start-up) does not need the file layer's numpy.
        from aura_ums._files import write_text_atomic

        target = Path(path)
        write_text_atomic(target, self.to_json())
        return target

    def lines(self) -> tuple[str, ...]:
        """Return one readable line per key, ``key  value``, for a terminal.

        Numbers show six significant digits and an undefined value ``n/a``; the entries of
        a list of metrics follow, indented.

        Examples
        --------
        >>> for line in Metrics({"steps": 3, "containment_rate": None}).lines():
        ...     print(line)
        steps                        3
        containment_rate             n/a
        """
        out: list[str] = []
        width = max([28, *(len(name) for name in self._values)])
        for name, value in self._values.items():
            out.append(f"{name:{width}s} {_shown(value)}")
            if isinstance(value, tuple):
                for row in value:
                    out.extend(f"  {line}" for line in row.lines())
        return tuple(out)
