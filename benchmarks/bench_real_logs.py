"""Side by side on real logs: the sliced map, the product map, filterpy's EKF and a particle filter.

Calibrates on one robot of the MRCLAM data beside the clone (``--calibrate``, default
Dataset 6 robot 1; docs/getting-real-data.md) and replays every other robot found there
(``--logs`` to choose), in Class I (bearings) and Class II (range and bearing). Per log and
class, one run of each method on the same position reports and observations:

- the product map (``ManagerSettings.slice_width = None``) and the heading-sliced map, each
  replayed twice: once plain (:func:`aura_ums.logs.replay_log`: containment, median area,
  median µs per frame) and once with the Expecter's windows judged through the camera
  (:func:`aura_ums.logs.replay_windows`, margin 0: window containment and width);
- filterpy's ``ExtendedKalmanFilter`` (benchmarks/filterpy_ekf.py) and aura-ums's particle
  filter, 99% regions, through :func:`aura_ums.logs.compare_on_log`, with the calibration's
  noise (``Calibration.noise``). The EKF's windows are those of its 3-sigma box, from aura-ums's
  ``ExtendedKalmanFilter`` (the same model, noise and gate as filterpy's) run inside
  ``replay_windows``; a particle filter has no window here.

The figures carry the keys of ``docs/metrics.md``. Prints Markdown tables (the ranges over
the logs, then every log); writes a JSON of every figure (``--json``) and draws window width
over time on one log (``--figure``). ``--write-docs`` writes both into docs/ (real-logs.json,
images/real_logs_windows.png) and the tables into README.md and docs/real-logs.md, between
their ``bench_real_logs`` markers. Settings of either map are
options: ``--set KEY=VALUE`` for both, ``--product KEY=VALUE`` / ``--sliced KEY=VALUE`` for one
(fields of ``ManagerSettings``; ``none``, ``true``, ``false`` or a number). ``--from-json FILE``
replays nothing: it prints (and with ``--write-docs`` writes) the tables of an earlier run.

    MPLBACKEND=Agg .venv/bin/python benchmarks/bench_real_logs.py --write-docs
    MPLBACKEND=Agg .venv/bin/python benchmarks/bench_real_logs.py --sliced relaxed_q=1 --logs mrclam7:3
    .venv/bin/python benchmarks/bench_real_logs.py --from-json docs/real-logs.json --write-docs
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime
import json
import math
import os
import platform
import re
import shlex
import subprocess
import sys
import textwrap
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from numpy.typing import NDArray

from aura_ums import Metrics
from aura_ums._native import NATIVE
from aura_ums.camera import Camera, load_camera
from aura_ums.errors import AuraUmsError
from aura_ums.logs import (
    Calibration,
    ReplayOptions,
    RobotLog,
    WindowReport,
    calibrate_logs,
    compare_on_log,
    filter_settings,
    read_mrclam,
    replay_log,
    replay_windows,
)
from aura_ums.manager import ManagerSettings, MapProfile, SettingInfo
from aura_ums.manager._settings import SettingValue
from aura_ums.uncertainty import LandmarkClass, Pose
from filterpy_ekf import FilterpyLogEkf

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"
CAMERA = ROOT / "examples" / "virtual_camera_60deg.toml"
FIGURE = ROOT / "docs" / "images" / "real_logs_windows.png"
README = ROOT / "README.md"
DOCS_PAGE = ROOT / "docs" / "real-logs.md"
FIGURES_JSON = ROOT / "docs" / "real-logs.json"

#: The slice width measured best so far (docs/real-logs.md, "The slice width": 2-degree cells
#: narrow the windows to about a quarter of the frame at under 2 ms a frame), used while
#: ManagerSettings' own default is the product map: the width of ``MapProfile.SLICED``.
BEST_SLICE_WIDTH = float(MapProfile.SLICED.settings().slice_width or math.nan)
PRODUCT = "product map"
SLICED = "sliced map"
FILTERPY = "filterpy EKF"
OURS, FOCUS, EKF_BOX, DISK_MODEL = WindowReport.methods
#: How the replays' methods are named in the rows of compare_on_log.
COMPARE_OURS, COMPARE_EKF = "aura-ums", "EKF"
# The focus map's window figures (the map's own with relaxed_q = 0), kept in each map's row.
FOCUS_KEYS = ("focus_window_containment", "median_focus_window_width_frac", "median_searched_width_frac")

#: (dataset folder, robot number), as ``mrclam7:1`` on the command line.
LogId = tuple[str, int]
#: A stage's progress callback: ``advance(done, total)``.
Advance = Callable[[int, int], None]
#: ``stage(description)``: shows a new stage and returns its callback (None: nothing shown).
Stage = Callable[[str], Advance | None]


@dataclass(frozen=True, slots=True)
class Series:
    """One method's window widths over a log: seconds since the first judged observation, fractions."""

    method: str
    time: NDArray[np.float64]
    width_frac: NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class Run:
    """One log in one class: a row of figures per method, and the window widths over time."""

    log: str
    landmark_class: LandmarkClass
    rows: tuple[Metrics, ...]
    series: tuple[Series, ...]

    def row(self, method: str) -> Metrics:
        return next(row for row in self.rows if row["method"] == method)

    def metrics(self) -> Metrics:
        return Metrics({"log": self.log, "landmark_class": self.landmark_class.value, "methods": self.rows})


def particle_label(particles: int) -> str:
    """The particle filter's name in compare_on_log's rows."""
    return f"PF ({particles})"


def table_methods(particles: int) -> tuple[str, ...]:
    """The methods of the Markdown tables, in their order."""
    return (SLICED, PRODUCT, FILTERPY, particle_label(particles))


def map_settings(
    both: Mapping[str, SettingValue], product: Mapping[str, SettingValue], sliced: Mapping[str, SettingValue]
) -> dict[str, ManagerSettings]:
    """Return the product map's and the sliced map's settings: the defaults, then the overrides.

    The product map has ``slice_width`` None whatever the defaults; the sliced map has the
    default ``slice_width``, or :data:`BEST_SLICE_WIDTH` while that default is the product map.
    """
    defaults = ManagerSettings.from_dict(both)
    width = defaults.slice_width if defaults.slice_width is not None else BEST_SLICE_WIDTH
    return {
        PRODUCT: ManagerSettings.from_dict({"slice_width": None, **product}, base=defaults),
        SLICED: ManagerSettings.from_dict({"slice_width": width, **sliced}, base=defaults),
    }


def replay_options(
    calibration: Calibration, landmark_class: LandmarkClass, settings: ManagerSettings
) -> ReplayOptions:
    """A replay of one class with the calibration's motion and sensor bounds."""
    return ReplayOptions(
        settings=settings,
        landmark_class=landmark_class,
        working=calibration.working,
        envelope=calibration.envelope,
        motion=calibration.motion,
    )


def measure(
    log: RobotLog,
    calibration: Calibration,
    camera: Camera,
    landmark_class: LandmarkClass,
    maps: Mapping[str, ManagerSettings],
    *,
    particles: int = 1000,
    seed: int = 0,
    stage: Stage | None = None,
) -> Run:
    """Run every method on one log in one class; ``stage(name)`` returns that stage's progress callback."""
    table = calibration.terrain_table()
    noise = calibration.noise

    def progress(name: str) -> Advance | None:
        return None if stage is None else stage(name)

    def options(settings: ManagerSettings) -> ReplayOptions:
        return replay_options(calibration, landmark_class, settings)

    rows: list[Metrics] = []
    series: list[Series] = []
    box: WindowReport | None = None
    for name, settings in maps.items():
        plain = replay_log(log, table, options(settings), keep_maps=False, progress=progress(name))
        _, windows = replay_windows(
            log, table, camera, options(settings), bearing_sd=noise.bearing_sd,
            range_sd_fraction=noise.range_sd_fraction, keep_maps=False, progress=progress(f"{name}, windows"),
        )  # fmt: skip
        # The EKF's box and the disk model do not depend on the map's settings: one report serves.
        box = windows if box is None else box
        figures = windows.metrics()
        rows.append(
            Metrics(
                {
                    "method": name,
                    "containment_rate": plain.containment_rate,
                    "envelope_containment_rate": plain.metrics()["envelope_containment_rate"],
                    "median_area_m2": plain.median_area_m2,
                    "median_wedge_width_rad": plain.median_wedge_width_rad,
                    **windows.figures(OURS),
                    **{key: figures[key] for key in FOCUS_KEYS},
                    "median_update_us": plain.median_update_us,
                    "inconsistent_observations": plain.inconsistent_observations,
                    "excluded_observations": int(plain.trace.excluded.sum()),
                    "relocalizations": plain.relocalizations,
                    "steps": len(plain.trace),
                }
            )
        )
        series.append(_series(name, windows, OURS))
    if box is None:
        raise AuraUmsError("maps: expected at least one map's settings, got none")
    series.append(_series(EKF_BOX, box, EKF_BOX))
    rows.append(Metrics({"method": DISK_MODEL, **box.figures(DISK_MODEL)}))

    def filterpy_ekf(start: Pose) -> FilterpyLogEkf:
        return FilterpyLogEkf(
            start,
            **filter_settings(log, bearing_sd=noise.bearing_sd, range_sd_fraction=noise.range_sd_fraction),
        )

    compared = compare_on_log(
        log,
        table,
        options(next(iter(maps.values()))),
        bearing_sd=noise.bearing_sd,
        range_sd_fraction=noise.range_sd_fraction,
        rng=np.random.default_rng(seed),
        particles=particles,
        others={FILTERPY: filterpy_ekf},
        progress=progress("filters"),
    )
    for summary in compared:
        if summary.method == COMPARE_OURS:
            continue  # replayed above, map by map
        # Both EKFs are the same model, noise and gate: the box's windows are the EKF's.
        boxed = summary.method in (COMPARE_EKF, FILTERPY)
        windows_of = box.figures(EKF_BOX) if boxed else {}
        rows.append(Metrics({**summary.metrics(), **windows_of}))
    return Run(log.meta.name, landmark_class, tuple(rows), tuple(series))


def _series(method: str, windows: WindowReport, judged: str) -> Series:
    rows = windows.judged(judged)
    times = np.array([row.time for row in rows], dtype=float)
    widths = np.array([row.width_frac for row in rows], dtype=float)
    return Series(method, times - (times[0] if times.size else 0.0), widths)


# -- Markdown ---------------------------------------------------------------------------------------

#: The tables' figures: metrics key, column title, format of one value.
COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("containment_rate", "truth inside", ".3f"),
    ("median_area_m2", "median area m²", ".3g"),
    ("median_window_width_frac", "median window width", ".2f"),
    ("window_containment", "measured in window", ".3f"),
    ("median_update_us", "median µs/frame", ",.0f"),
)


def _cell(values: Sequence[float], spec: str) -> str:
    known = [v for v in values if not math.isnan(v)]
    if not known:
        return "n/a"
    low, high = format(min(known), spec), format(max(known), spec)
    return low if low == high else f"{low}-{high}"


def _number(row: Metrics, key: str) -> float:
    """The figure, NaN when undefined or not measured for that method (a particle filter's windows)."""
    return row.number(key) if key in row else math.nan


def summary_table(runs: Sequence[Run], methods: Sequence[str]) -> str:
    """Markdown: per class and method, the range (lowest-highest) of each figure over the logs."""
    lines = [
        "| class | method | " + " | ".join(title for _, title, _ in COLUMNS) + " |",
        "|---" * (2 + len(COLUMNS)) + "|",
    ]
    for landmark_class in dict.fromkeys(run.landmark_class for run in runs):
        chosen = [run for run in runs if run.landmark_class is landmark_class]
        for method in methods:
            rows = [run.row(method) for run in chosen]
            cells = [_cell([_number(row, key) for row in rows], spec) for key, _, spec in COLUMNS]
            lines.append(f"| {landmark_class.value} | {method} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def log_table(runs: Sequence[Run], methods: Sequence[str]) -> str:
    """Markdown: every log, class and method, one row each."""
    lines = [
        "| log | class | method | " + " | ".join(title for _, title, _ in COLUMNS) + " |",
        "|---" * (3 + len(COLUMNS)) + "|",
    ]
    for run in runs:
        for method in methods:
            row = run.row(method)
            cells = [_cell([_number(row, key)], spec) for key, _, spec in COLUMNS]
            lines.append(f"| {run.log} | {run.landmark_class.value} | {method} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def replace_block(text: str, name: str, content: str) -> str:
    """Return ``text`` with what stands between ``<!-- name -->`` and ``<!-- /name -->`` replaced."""
    pattern = re.compile(rf"(<!-- {re.escape(name)} -->\n).*?(<!-- /{re.escape(name)} -->)", re.S)
    if pattern.search(text) is None:
        raise AuraUmsError(f"expected the markers <!-- {name} --> and <!-- /{name} -->, got none")
    return pattern.sub(lambda match: match.group(1) + content + match.group(2), text, count=1)


# -- Figure -----------------------------------------------------------------------------------------

COLOURS = {SLICED: "tab:blue", PRODUCT: "tab:green", EKF_BOX: "tab:orange"}


def draw(run: Run, path: Path, window: int = 51) -> None:
    """Draw window width over time on one run: a dot per observation, a running median per method."""
    figure, axes = plt.subplots(figsize=(9, 3.8), constrained_layout=True)
    for series in run.series:
        if not series.time.size:
            continue
        colour = COLOURS.get(series.method)
        axes.plot(series.time, series.width_frac, ".", markersize=1.5, alpha=0.35, color=colour)
        axes.plot(
            series.time,
            _running_median(series.width_frac, window),
            "-",
            linewidth=1.4,
            color=colour,
            label=f"{series.method} (median {np.median(series.width_frac):.2f})",
        )
    axes.set_xlabel("time since the first judged observation, s")
    axes.set_ylabel("window width / image width")
    axes.set_ylim(0.0, 1.25)
    axes.set_title(
        f"{run.log}, Class {run.landmark_class.value}: image windows through a 640x480, 60 deg camera "
        f"(lines: running median of {window})",
        fontsize=10,
    )
    axes.legend(loc="upper center", ncol=3, fontsize=9)
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=110)
    plt.close(figure)


def _running_median(values: NDArray[np.float64], window: int) -> NDArray[np.float64]:
    half = window // 2
    padded = np.pad(values, half, mode="edge")
    return np.median(np.lib.stride_tricks.sliding_window_view(padded, 2 * half + 1), axis=1)


# -- The whole run ----------------------------------------------------------------------------------


def development_logs(data: Path) -> list[LogId]:
    """Every MRCLAM robot under ``data``: dataset folders with Barcodes.dat, robots with odometry."""
    found: list[LogId] = []
    if not data.is_dir():
        return found
    for folder in sorted(p for p in data.iterdir() if (p / "Barcodes.dat").is_file()):
        for odometry in sorted(folder.glob("Robot*_Odometry.dat")):
            number = odometry.name.removeprefix("Robot").removesuffix("_Odometry.dat")
            if number.isdigit():
                found.append((folder.name, int(number)))
    return found


def machine() -> dict[str, object]:
    """What the figures were measured on."""
    cpu = platform.processor() or platform.machine()
    cpuinfo = Path("/proc/cpuinfo")
    if cpuinfo.is_file():
        names = re.findall(r"^model name\s*:\s*(.+)$", cpuinfo.read_text(encoding="utf-8"), re.M)
        cpu = names[0] if names else cpu
    commit = subprocess.run(
        ["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True, check=False
    ).stdout.strip()
    # A run from a tree with uncommitted code measures code no commit holds: say so.
    changed = subprocess.run(
        ["git", "-C", str(ROOT), "status", "--porcelain", "--", "src", "benchmarks"],
        capture_output=True, text=True, check=False,
    ).stdout.strip()  # fmt: skip
    if commit and changed:
        commit += " with uncommitted changes"
    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "load_average": os.getloadavg() if hasattr(os, "getloadavg") else None,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "native_kernels": NATIVE,
        "commit": commit or None,
    }


def document(
    runs: Sequence[Run],
    maps: Mapping[str, ManagerSettings],
    calibration: Calibration,
    *,
    calibrated_on: str,
    camera: Path,
    particles: int,
    seed: int,
    command: str,
) -> dict[str, object]:
    """The JSON of the whole benchmark: how it ran, and every run's figures (keys: docs/metrics.md)."""
    return {
        "command": command,
        "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "machine": machine(),
        "calibrated_on": calibrated_on,
        "filter_noise": Metrics(
            {
                "bearing_sd_rad": calibration.noise.bearing_sd,
                "range_sd_fraction": calibration.noise.range_sd_fraction,
            }
        ).to_dict(),
        "camera": camera.name,
        "particles": particles,
        "seed": seed,
        "settings": {name: settings.to_dict() for name, settings in maps.items()},
        "runs": [run.metrics().to_dict() for run in runs],
    }


def setting(text: str) -> tuple[str, SettingValue]:
    """Parse ``KEY=VALUE``: ``none``, ``true``, ``false``, an integer, a number or an angle (``2deg``)."""
    key, sep, value = text.partition("=")
    if not sep or not key.strip():
        raise argparse.ArgumentTypeError(f"expected KEY=VALUE, got {text!r}")
    word = value.strip().lower()
    parsed: SettingValue
    fields = {field.name: field for field in dataclasses.fields(ManagerSettings)}
    angle = SettingInfo.of(fields[key.strip()]).read(word) if key.strip() in fields else word
    if isinstance(angle, float):  # an angle setting in degrees, as on the command line
        parsed = angle
    elif word in ("none", "true", "false"):
        parsed = {"none": None, "true": True, "false": False}[word]
    elif re.fullmatch(r"[+-]?\d+", word):
        parsed = int(word)
    else:
        try:
            parsed = float(word)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"{key.strip()}: expected none, true, false or a number, got {value!r}"
            ) from None
    return key.strip(), parsed


def log_id(text: str) -> LogId:
    """Parse ``DATASET:ROBOT`` (``mrclam7:1``)."""
    name, sep, robot = text.partition(":")
    if not sep or not robot.isdigit():
        raise argparse.ArgumentTypeError(f"expected DATASET:ROBOT (mrclam7:1), got {text!r}")
    return name, int(robot)


@contextmanager
def progress_display(quiet: bool) -> Iterator[Stage]:
    """Yield ``stage(description)``, which shows a bar for that stage (on stderr) and returns its callback."""
    if quiet:
        yield lambda description: None
        return
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TaskID, TextColumn, TimeElapsedColumn

    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn())
    with Progress(*columns, console=Console(stderr=True), transient=True) as bars:
        current: list[TaskID] = []

        def stage(description: str) -> Advance:
            for task in current:
                bars.remove_task(task)
            task = bars.add_task(description, total=None)
            current[:] = [task]

            def advance(done: int, total: int) -> None:
                bars.update(task, completed=done, total=total)

            return advance

        yield stage


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--data", type=Path, default=DATA, help="folder of the MRCLAM datasets")
    parser.add_argument(
        "--calibrate", type=log_id, default=("mrclam6", 1), help="DATASET:ROBOT calibrated on"
    )
    parser.add_argument(
        "--logs", type=log_id, nargs="+", help="DATASET:ROBOT replayed (default: every other)"
    )
    parser.add_argument("--classes", nargs="+", choices=("I", "II"), default=["I", "II"])
    parser.add_argument("--camera", type=Path, default=CAMERA)
    parser.add_argument("--particles", type=int, default=1000)
    parser.add_argument("--seed", type=int, default=0, help="seed of the particle filter")
    for flag, which in (
        ("--set", "both maps"),
        ("--product", "the product map"),
        ("--sliced", "the sliced map"),
    ):
        parser.add_argument(
            flag, type=setting, action="append", default=[], metavar="KEY=VALUE",
            help=f"a ManagerSettings field of {which} (repeat for more)",
        )  # fmt: skip
    parser.add_argument("--json", type=Path, help="JSON of every figure (--write-docs: docs/real-logs.json)")
    parser.add_argument(
        "--figure", type=Path, help="PNG of window width over time (--write-docs: docs/images/)"
    )
    parser.add_argument("--figure-log", type=log_id, default=("mrclam7", 1), help="DATASET:ROBOT drawn")
    parser.add_argument("--figure-class", choices=("I", "II"), default="II")
    parser.add_argument(
        "--write-docs", action="store_true", help="write the tables, JSON and figure into README and docs/"
    )
    parser.add_argument(
        "--from-json", type=Path, help="no replay: the tables (and --write-docs) from a JSON this wrote"
    )
    parser.add_argument("--quiet", action="store_true", help="no progress display")
    args = parser.parse_args(argv)
    drawn: Run | None = None
    if args.from_json is not None:
        doc: dict[str, Any] = json.loads(args.from_json.read_text(encoding="utf-8"))
    else:
        command = "MPLBACKEND=Agg .venv/bin/python benchmarks/bench_real_logs.py " + shlex.join(
            argv if argv is not None else sys.argv[1:]
        )
        measured = measure_all(args, command.strip())
        if measured is None:
            return 0
        doc, drawn = measured
    runs = runs_of(doc)
    methods = table_methods(int(doc["particles"]))
    summary, per_log, measured_on = summary_table(runs, methods), log_table(runs, methods), provenance(doc)
    print(summary)
    print(per_log)
    print(measured_on + "\n")
    json_path = FIGURES_JSON if args.write_docs and args.json is None else args.json
    if json_path is not None and args.from_json is None:
        json_path.parent.mkdir(parents=True, exist_ok=True)
        json_path.write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8")
        print(f"wrote {json_path}", file=sys.stderr)
    figure_path = FIGURE if args.write_docs and args.figure is None else args.figure
    if figure_path is not None and drawn is not None:
        draw(drawn, figure_path)
        print(f"wrote {figure_path}", file=sys.stderr)
    elif figure_path is not None and args.from_json is None:
        print(f"no figure: {':'.join(map(str, args.figure_log))} Class {args.figure_class} was not replayed")
    if args.write_docs:
        write_docs(summary, per_log, measured_on, doc["settings"])
        print(f"wrote {README.name} and {DOCS_PAGE.relative_to(ROOT)}", file=sys.stderr)
    return 0


def measure_all(args: argparse.Namespace, command: str) -> tuple[dict[str, Any], Run | None] | None:
    """Calibrate, run every chosen log and class; return the JSON document and the run to draw.

    None (said on stdout) when the calibration log is not there.
    """
    found = development_logs(args.data)
    if args.calibrate not in found:
        print(f"development data not found ({':'.join(map(str, args.calibrate))} under {args.data}): skipped")
        return None
    chosen: list[LogId] = args.logs or [log for log in found if log != args.calibrate]
    missing = [f"{dataset}:{robot}" for dataset, robot in chosen if (dataset, robot) not in found]
    if missing:
        raise SystemExit(f"no such logs under {args.data}: {', '.join(missing)}")
    try:
        maps = map_settings(dict(args.set), dict(args.product), dict(args.sliced))
        camera = load_camera(args.camera)
        calibration = calibrate_logs([read_mrclam(args.data / args.calibrate[0], args.calibrate[1])])
    except AuraUmsError as exc:
        raise SystemExit(str(exc)) from None
    classes = [LandmarkClass.VERTICAL_LINE if c == "I" else LandmarkClass.POINT for c in args.classes]
    runs: list[Run] = []
    drawn: Run | None = None
    with progress_display(args.quiet) as stage:
        for dataset, robot in chosen:
            log = read_mrclam(args.data / dataset, robot)
            for landmark_class in classes:
                run = measure(
                    log, calibration, camera, landmark_class, maps, particles=args.particles, seed=args.seed,
                    stage=_prefixed(stage, f"{log.meta.name} {landmark_class.value}"),
                )  # fmt: skip
                runs.append(run)
                if (dataset, robot) == args.figure_log and landmark_class.value == args.figure_class:
                    drawn = run
                print(f"{run.log} Class {landmark_class.value}: done", file=sys.stderr, flush=True)
    calibrated_on = ":".join(map(str, args.calibrate))
    doc = document(
        runs, maps, calibration, calibrated_on=calibrated_on, camera=args.camera, particles=args.particles,
        seed=args.seed, command=command,
    )  # fmt: skip
    return doc, drawn


def runs_of(doc: Mapping[str, Any]) -> list[Run]:
    """The runs of a JSON document (:func:`document`), without their window series."""
    return [
        Run(
            run["log"],
            LandmarkClass(run["landmark_class"]),
            tuple(Metrics(row) for row in run["methods"]),
            (),
        )
        for run in doc["runs"]
    ]


def provenance(doc: Mapping[str, Any]) -> str:
    """One paragraph: what was calibrated on and replayed, when, by which command, on what machine."""
    info = doc["machine"]
    load = info.get("load_average")
    busy = f", load average {load[0]:.1f}" if isinstance(load, list | tuple) and load else ""
    logs = len({run["log"] for run in doc["runs"]})
    dataset, _, robot = str(doc["calibrated_on"]).partition(":")
    return textwrap.fill(
        f"Calibrated on {dataset} robot {robot}, replayed on {logs} other robots, {doc['date'][:10]}: "
        f"`{doc['command']}` at commit {info['commit']} on {info['cpu']} ({info['cores']} cores, "
        f"shared with other work{busy}; the µs are this machine's under that load).",
        width=96,
        break_on_hyphens=False,
        break_long_words=False,
    )


def write_docs(
    summary: str, per_log: str, measured: str, maps: Mapping[str, Mapping[str, SettingValue]]
) -> None:
    """Put the tables between the ``bench_real_logs`` markers of README.md and docs/real-logs.md."""
    settings = "".join(
        f"- {name}: "
        + ", ".join(f"`{key}={_shown(value)}`" for key, value in _changed(chosen).items())
        + "\n"
        for name, chosen in maps.items()
    )
    readme = replace_block(README.read_text(encoding="utf-8"), "bench_real_logs", f"{summary}\n{measured}\n")
    README.write_text(readme, encoding="utf-8")
    page = DOCS_PAGE.read_text(encoding="utf-8")
    page = replace_block(page, "bench_real_logs", f"{summary}\n{measured}\n\n{settings}")
    DOCS_PAGE.write_text(replace_block(page, "bench_real_logs per log", per_log), encoding="utf-8")


def _shown(value: SettingValue) -> str:
    """A setting as the options take it: none, true, false or a number (4 significant digits)."""
    if value is None or isinstance(value, bool):
        return str(value).lower()
    return f"{value:.4g}" if isinstance(value, float) else str(value)


def _prefixed(stage: Stage, prefix: str) -> Stage:
    return lambda name: stage(f"{prefix}: {name}")


def _changed(settings: Mapping[str, SettingValue]) -> dict[str, SettingValue]:
    """The fields that differ from ManagerSettings' defaults (slice_width always shown)."""
    defaults = ManagerSettings().to_dict()
    return {
        key: value
        for key, value in settings.items()
        if key == "slice_width" or value != defaults.get(key, value)
    }


if __name__ == "__main__":
    sys.exit(main())
