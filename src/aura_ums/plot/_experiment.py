"""The paper's localization experiment in the closed loop: Figures 12-14, the table and the report."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

from aura_ums._metrics import Metrics
from aura_ums._validate import integer_at_least
from aura_ums.errors import InputError
from aura_ums.expecter import Expecter, ImageWindow, PerceptualStrategy, disk_model_window, margin_pixels
from aura_ums.plot._draw import draw_map
from aura_ums.schemas import FindLandmarkSchema
from aura_ums.sim import FrameRecord, RunResult, Scenario, run_scenario, summarize_runs
from aura_ums.uncertainty import FOOT, GroundLineLandmark, PointLandmark

#: Scenario files of the report, relative to the scenarios folder.
PAPER = "paper_sidewalk.toml"
PAPER_CLASS2 = "paper_sidewalk_class2.toml"
OTHERS = ("indoor_corridor.toml", "four_terrains.toml")
#: Pixels a correct detection may lie beyond the image of its landmark's uncertainty disk
#: (pixel noise, the detector's localization): farther, the identification is counted wrong.
_WRONG_PIXELS = 5.0
#: Points around the uncertainty disk, and heights along a line, whose images bound the landmark's.
_WRONG_DISK_POINTS = 16
_WRONG_HEIGHTS = 9
_COLORS = ("tab:red", "tab:green", "tab:purple", "tab:orange", "tab:brown", "tab:cyan", "tab:olive")


def scenarios_folder() -> Path:
    """Return the ``scenarios/`` folder of the source tree (the report's scenario files).

    Examples
    --------
    >>> (scenarios_folder() / PAPER).is_file()
    True
    """
    here = Path(__file__).resolve()
    for parent in here.parents:
        if (parent / "scenarios" / PAPER).is_file():
            return parent / "scenarios"
    return Path("scenarios")  # pragma: no cover - run from a checkout


@dataclass(frozen=True, slots=True)
class TableRow:
    """One row of the experiment table: one frame (position along the walk)."""

    index: int
    distance_ft: float
    area_before: float
    area_after: float
    wedge_before_deg: float
    wedge_after_deg: float
    window_polygon: float
    window_disk: float
    recognized: tuple[str, ...]
    inside: bool


def experiment_table(scenario: Scenario, result: RunResult) -> list[TableRow]:
    """Return the table rows of a run: map before/after, windows of polygon vs disk model, containment.

    Examples
    --------
    The windows are computed again from each frame's map before pruning, for the landmarks
    the frame searched (only their ids are read from the record), each with the margin of
    its own strategy (the map's record), as its schema searched:

    >>> from aura_ums.manager import ManagerState
    >>> scenario = paper_scenario()
    >>> start = scenario.initial_map()
    >>> frame = FrameRecord(
    ...     0, 0.0, None, True, scenario.start.pose, True, start, start,
    ...     (("lamppost_107", ImageWindow(0, 0, 1, 1)),), ("lamppost_107",), ("lamppost_107",), 1, (),
    ...     ManagerState.NOMINAL, 3.0,
    ... )
    >>> [row] = experiment_table(scenario, RunResult(scenario.name, (frame,), start, True, None, 1, 1))
    >>> row.distance_ft, round(row.area_before, 3), round(row.wedge_before_deg, 1), row.recognized
    (0.0, 0.296, 6.0, ('lamppost_107',))
    >>> row.window_polygon < row.window_disk                  # the polygon's window is the smaller
    True
    >>> experiment_table(scenario, RunResult(scenario.name, (), start, False, None, 0, 0))   # no frame
    []
    """
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario: expected a Scenario, got {type(scenario).__name__}")
    if not isinstance(result, RunResult):
        raise InputError(f"result: expected a RunResult, got {type(result).__name__}")
    expecter = Expecter(scenario.camera)
    rows = []
    distance = 0.0
    for record in result.records:
        if record.command is not None:
            distance += record.command.run
        polygon_area = disk_area = 0.0
        for ident, _ in record.windows:
            # With the margin of the landmark's own strategy, as its schema searched.
            entry = scenario.meadow_map.landmark(ident)
            landmark, margin = entry.landmark, entry.strategy
            ours = expecter.window(record.map_before, landmark, margin=margin)
            disk = disk_model_window(expecter, record.map_before, landmark, margin=margin)
            polygon_area += 0.0 if ours is None else ours.area
            disk_area += 0.0 if disk is None else disk.area
        rows.append(
            TableRow(
                record.index,
                distance / 0.3048,
                record.area_before,
                record.area,
                math.degrees(record.wedge_width_before),
                math.degrees(record.wedge_width),
                polygon_area,
                disk_area,
                record.posted,
                record.inside,
            )
        )
    return rows


def _table_markdown(rows: list[TableRow]) -> list[str]:
    lines = [
        "| pos | ft | area before m² | area after m² | wedge before ° | wedge after ° "
        "| window px² polygon | window px² disk | recognized | true pose inside |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in rows:
        lines.append(
            f"| {r.index + 1} | {r.distance_ft:.0f} | {r.area_before:.3f} | {r.area_after:.3f} "
            f"| {r.wedge_before_deg:.2f} | {r.wedge_after_deg:.2f} | {r.window_polygon:,.0f} "
            f"| {r.window_disk:,.0f} | {', '.join(r.recognized) or '-'} | {'yes' if r.inside else 'NO'} |"
        )
    return lines


def _scenario_lines(scenario: Scenario, rows: list[TableRow], seed: int) -> list[str]:
    """Return the experiment's set-up, read from the scenario and the run's table."""
    feet = ", ".join(f"{r.distance_ft:.0f}" for r in rows)
    used = ", ".join(f"{r.symbol} (Class {r.landmark_class.value})" for r in scenario.landmarks)
    confirm = sorted({r.confirm_frames for r in scenario.landmarks})
    frames = "a single image" if confirm == [1] else f"{' or '.join(map(str, confirm))} consecutive frames"
    return [
        f"Scenario `{scenario.name}`: start known to ±{scenario.start.position_radius / FOOT:.3g} ft, "
        f"images at {feet} ft; landmarks {used}, each identified from {frames} "
        f"(`confirm_frames`). Seed {seed}.",
    ]


def figure12(path: Path, scenario: Scenario, result: RunResult) -> Path:
    """Draw the maps before (left) and after (right) pruning at each position, with the true pose."""
    n = len(result.records)
    figure = Figure(figsize=(8.0, 2.8 * n))
    for row, record in enumerate(result.records):
        for col, (m, title) in enumerate(((record.map_before, "before"), (record.map_after, "after"))):
            ax = figure.add_subplot(n, 2, 2 * row + col + 1)
            draw_map(ax, m, wedge_length=1.0)
            pose = record.true_pose
            ax.plot([pose.x], [pose.y], "k.", ms=6)
            ax.arrow(pose.x, pose.y, 0.4 * math.cos(pose.heading), 0.4 * math.sin(pose.heading), width=0.01)
            cx, cy = m.center
            ax.set_xlim(cx - 1.5, cx + 1.5)
            ax.set_ylim(cy - 1.0, cy + 1.0)
            ax.set_aspect("equal")
            by = f"\n{', '.join(record.posted) or 'nothing recognized'}" if col else ""
            ax.set_title(
                f"({chr(97 + 2 * row + col)}) position {row + 1} {title}{by}: "
                f"{m.area:.3f} m², {math.degrees(m.wedge.width):.1f}°",
                fontsize=7,
            )
            ax.tick_params(labelsize=7)
    figure.suptitle(f"{scenario.name}: spatial uncertainty map before and after pruning", fontsize=10)
    figure.tight_layout()
    figure.savefig(path, dpi=90)
    return path


def _draw_windows(ax: object, record_windows: tuple[tuple[str, ImageWindow], ...]) -> None:
    for k, (ident, w) in enumerate(record_windows):
        color = _COLORS[k % len(_COLORS)]
        ax.add_patch(  # type: ignore[attr-defined]
            Rectangle((w.u_min, w.v_min), w.width, w.height, fill=False, lw=1.5, color=color)
        )
        ax.text(w.u_min + 2, w.v_min + 12, ident, color=color, fontsize=6)  # type: ignore[attr-defined]


def figure13(path: Path, scenario: Scenario, result: RunResult) -> Path:
    """Draw the expectation windows on the image at every position."""
    n = len(result.images)
    figure = Figure(figsize=(4.0 * n, 4.0))
    for k in range(n):
        ax = figure.add_subplot(1, n, k + 1)
        ax.imshow(result.images[k], cmap="gray", vmin=0, vmax=255)
        _draw_windows(ax, result.records[k].windows)
        ax.set_title(f"position {k + 1}: {len(result.records[k].windows)} windows", fontsize=9)
        ax.set_axis_off()
    figure.suptitle(f"{scenario.name}: expectation windows (pruning on)", fontsize=10)
    figure.tight_layout()
    figure.savefig(path, dpi=90)
    return path


def figure14(path: Path, scenario: Scenario, result: RunResult, position: int = 2) -> Path:
    """Draw the line-finder (or interest-operator) results inside each window, at one position."""
    record, image = result.records[position], result.images[position]
    expecter = Expecter(scenario.camera)
    windows = record.windows or ()
    figure = Figure(figsize=(3.2 * max(1, len(windows)), 3.6))
    for k, (ident, w) in enumerate(windows):
        ax = figure.add_subplot(1, max(1, len(windows)), k + 1)
        ax.imshow(image, cmap="gray", vmin=0, vmax=255)
        ax.add_patch(Rectangle((w.u_min, w.v_min), w.width, w.height, fill=False, lw=1, color="yellow"))
        detector = FindLandmarkSchema(scenario.meadow_map.landmark(ident), expecter).detector
        found = detector.find_detailed(image, w) if hasattr(detector, "find_detailed") else None
        if found is not None:
            for u1, v1, u2, v2 in found.segments:
                ax.plot([u1, u2], [v1, v2], "r-", lw=1.2)
        else:
            points = np.array([c.point for c in detector.find(image, w)] or np.zeros((0, 2)))  # type: ignore[union-attr]
            if len(points):
                ax.plot(points[:, 0], points[:, 1], "r+")
        ax.set_xlim(w.u_min, w.u_max)
        ax.set_ylim(w.v_max, w.v_min)
        ax.set_title(f"({chr(97 + k)}) {ident}", fontsize=8)
        ax.set_axis_off()
    figure.suptitle(f"{scenario.name}: line finder in the windows, position {position + 1}", fontsize=10)
    figure.tight_layout()
    figure.savefig(path, dpi=90)
    return path


def figure_track(path: Path, scenario: Scenario, result: RunResult) -> Path:
    """Draw a whole run from above: the map after every frame and the true path."""
    figure = Figure(figsize=(10.0, 4.0))
    ax = figure.add_subplot(1, 1, 1)
    for record in result.records:
        draw_map(ax, record.map_after, wedge_length=0.5)
    xy = np.array([[r.true_pose.x, r.true_pose.y] for r in result.records])
    ax.plot(xy[:, 0], xy[:, 1], "k.-", lw=0.8, ms=4, label="true path")
    for landmark_record in scenario.landmarks:
        lm = landmark_record.landmark
        if not isinstance(lm, GroundLineLandmark):
            ax.plot([lm.x], [lm.y], "ks", ms=4)
    ax.set_aspect("equal")
    ax.legend(fontsize=8)
    inside = result.containment_rate
    ax.set_title(f"{scenario.name}: map after each frame (true pose inside at {inside:.0%} of frames)")
    figure.tight_layout()
    figure.savefig(path, dpi=90)
    return path


def _metrics_lines(title: str, metrics: Metrics) -> list[str]:
    lines = [f"| {title} | value |", "| --- | --- |"]
    for key, value in metrics.items():
        lines.append(f"| {key} | {_cell(value)} |")
    return lines


def _cell(value: object) -> str:
    """Return a metric as a report's table shows it (``n/a``: undefined, as ``Metrics.lines``)."""
    if value is None:
        return "n/a"
    return f"{value:.4g}" if isinstance(value, float) else str(value)


def paper_scenario() -> Scenario:
    """Return the paper's sidewalk experiment (``scenarios/paper_sidewalk.toml``), as the report runs it.

    Examples
    --------
    >>> paper_scenario().check_runs(40)
    40
    >>> paper_scenario().check_runs(0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: runs: expected an integer in [1, 100000], got 0
    """
    return Scenario.from_toml(scenarios_folder() / PAPER)


def write_experiment_report(out: str | Path, *, seed: int = 0, runs: int = 40) -> Path:
    """Write the report: the earlier figures and summary, then the paper's experiment in the loop.

    Adds Figures 12-14 of the sidewalk experiment, the table, the Class II variant, the
    indoor corridor and four-terrain runs and a small Monte Carlo (``runs`` per variant)
    to ``summary.md``.

    Returns
    -------
    Path
        The written ``summary.md``.

    Raises
    ------
    InputError
        When ``runs`` is not an integer in [1, 100,000] (``Scenario.check_runs``), before
        anything is written.

    Examples
    --------
    The report runs the closed loop many times (minutes; ``aura-ums demo`` writes it);
    a count of runs out of range is refused before any work:

    >>> import tempfile
    >>> out = Path(tempfile.mkdtemp()) / "report"
    >>> write_experiment_report(out, runs=0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: runs: expected an integer in [1, 100000], got 0
    >>> out.exists()
    False
    """
    from aura_ums.plot._growth import write_growth_report

    base = scenarios_folder()
    paper = paper_scenario()
    paper.check_runs(runs)  # before any work: a count out of range is refused with its estimate
    seed = integer_at_least(seed, "seed", 0)
    folder = Path(out)
    summary = write_growth_report(folder, seed=seed)
    figures = folder / "figures"
    figures.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    result = run_scenario(paper, np.random.default_rng(seed), keep_images=True)
    f12 = figure12(figures / "figure12_maps.png", paper, result)
    f13 = figure13(figures / "figure13_windows.png", paper, result)
    f14 = figure14(figures / "figure14_lines.png", paper, result)
    class2 = Scenario.from_toml(base / PAPER_CLASS2)
    result2 = run_scenario(class2, np.random.default_rng(seed), keep_images=True)
    f12b = figure12(figures / "figure12_maps_class2.png", class2, result2)
    rows, rows2 = experiment_table(paper, result), experiment_table(class2, result2)
    lines = [
        "",
        "## The localization experiment in the closed loop (Figures 12-14)",
        "",
        "Each frame: the robot executes its command (position report), the camera renders the image,",
        "the manager grows the map, the pilot's find-landmark schemas search the Expecter's windows,",
        "post identifications, and the manager prunes the map (`aura_ums.sim.run_scenario`).",
        *_scenario_lines(paper, rows, seed),
        "",
        f"![Figure 12]({f12.relative_to(folder)})",
        "",
        f"![Figure 13]({f13.relative_to(folder)})",
        "",
        f"![Figure 14]({f14.relative_to(folder)})",
        "",
        *_table_markdown(rows),
        "",
        *position_sentences(rows),
        "",
        "Window areas are summed over the landmarks predicted in the frame, both computed on the",
        "map before pruning (the disk model: the smallest disk around the polygon), each grown by",
        "the margin its landmark's strategy needs (a line finder "
        f"{margin_pixels(PerceptualStrategy.LINE_FINDER):g} px, an interest operator "
        f"{margin_pixels(PerceptualStrategy.INTEREST_OPERATOR):g} px).",
        "",
        "### Building corner as a Class II landmark",
        "",
        f"![Figure 12, Class II]({f12b.relative_to(folder)})",
        "",
        *_table_markdown(rows2),
        "",
        *position_sentences(rows2),
        "",
    ]
    variants = (
        ("paper, pruning", paper, True),
        ("paper, growth only", paper, False),
        ("class II corner, pruning", class2, True),
    )
    generators = np.random.default_rng(seed + 1).spawn(runs)
    mc: list[tuple[str, Metrics]] = []
    per_position: list[tuple[str, list[PositionCounts]]] = []
    for name, scenario, prune in variants:
        results = [run_scenario(scenario, g, prune=prune) for g in generators]
        mc.append((name, summarize_runs(results)))
        if prune:
            per_position.append((name, position_counts(scenario, results)))
    lines.extend([f"### Monte Carlo ({runs} seeded runs each)", ""])
    lines.extend(monte_carlo_markdown(mc))
    lines.append("")
    for name, counts in per_position:
        lines.extend([*position_counts_markdown(name, counts), "", *position_counts_sentences(counts), ""])
    lines.extend([*class2_paragraph(mc[0][1], mc[2][1]), ""])
    lines.extend(["### Other worlds (one seeded run each)", ""])
    for file in OTHERS:
        scenario = Scenario.from_toml(base / file)
        other = run_scenario(scenario, np.random.default_rng(seed), keep_images=True)
        track = figure_track(figures / f"track_{scenario.name}.png", scenario, other)
        middle = len(other.records) // 2
        windows = figure13(figures / f"windows_{scenario.name}.png", scenario, _slice(other, middle))
        lines.extend(
            [
                f"#### {scenario.name}",
                "",
                f"![track]({track.relative_to(folder)})",
                "",
                f"![windows]({windows.relative_to(folder)})",
                "",
                *_metrics_lines(scenario.name, summarize_runs([other])),
                "",
            ]
        )
    lines.append(f"_Experiment section computed in {time.perf_counter() - started:.1f} s._")
    with summary.open("a") as handle:
        handle.write("\n".join(lines) + "\n")
    return summary


def _slice(result: RunResult, index: int) -> RunResult:
    """Return a result holding only frame ``index`` (for drawing one image's windows)."""
    return RunResult(
        result.scenario,
        (result.records[index],),
        result.final_map,
        result.completed,
        None,
        result.predictions,
        result.hits,
        (result.images[index],),
    )


def _positions(indices: list[int]) -> str:
    """``[1, 2, 4]`` -> ``"positions 1, 2 and 4"``; ``[3]`` -> ``"position 3"``."""
    names = [str(i) for i in indices]
    if len(names) == 1:
        return f"position {names[0]}"
    return f"positions {', '.join(names[:-1])} and {names[-1]}"


def _change(what: str, before: str, after: str, *, down: str, up: str) -> str:
    """Compare two figures as the tables show them: equal shown values "stay"."""
    if float(after.replace(",", "")) == float(before.replace(",", "")):
        return f"{what} stays at {after}"
    verb = down if float(after.replace(",", "")) < float(before.replace(",", "")) else up
    return f"{what} {verb} from {before} to {after}"


def position_sentences(rows: list[TableRow]) -> list[str]:
    """Say, from a run's table (its shown values), where landmarks pruned the map and where the truth stayed.

    Every claim is decided on the numbers as :func:`_table_markdown` prints them, so no
    sentence can contradict the table above it.

    Examples
    --------
    >>> row = TableRow(0, 0.0, 0.3, 0.3, 6.0, 3.5, 100.0, 120.0, ("pole",), True)
    >>> later = TableRow(1, 10.0, 0.7, 0.7, 6.5, 6.5, 90.0, 99.0, (), False)
    >>> for sentence in position_sentences([row, later]):
    ...     print(sentence)
    Landmarks were recognized at position 1 and at no other.
    The heading wedge narrowed at position 1; the area shrank at no position.
    The true pose was inside the map after position 1 and outside it after position 2.
    >>> position_sentences([])
    []
    """
    if not rows:
        return []
    recognized = [r.index + 1 for r in rows if r.recognized]
    narrowed = [r.index + 1 for r in rows if f"{r.wedge_after_deg:.2f}" != f"{r.wedge_before_deg:.2f}"]
    shrank = [r.index + 1 for r in rows if f"{r.area_after:.3f}" != f"{r.area_before:.3f}"]
    inside = [r.index + 1 for r in rows if r.inside]
    outside = [r.index + 1 for r in rows if not r.inside]
    if len(recognized) == len(rows):
        seen = f"Landmarks were recognized at every position ({_positions(recognized)})."
    elif recognized:
        seen = f"Landmarks were recognized at {_positions(recognized)} and at no other."
    else:
        seen = "No landmark was recognized at any position."
    wedge = f"at {_positions(narrowed)}" if narrowed else "at no position"
    area = f"at {_positions(shrank)}" if shrank else "at no position"
    if not outside:
        truth = "The true pose was inside the map after every position."
    elif not inside:
        truth = "The true pose was outside the map after every position."
    else:
        truth = (
            f"The true pose was inside the map after {_positions(inside)} "
            f"and outside it after {_positions(outside)}."
        )
    return [seen, f"The heading wedge narrowed {wedge}; the area shrank {area}.", truth]


@dataclass(frozen=True, slots=True)
class PositionCounts:
    """Over a Monte Carlo, per position (frame index) of the route: how often what happened."""

    index: int
    runs: int
    pruned: int
    inside: int
    identifications: int
    wrong: int


def misidentified(scenario: Scenario, record: FrameRecord) -> tuple[str, ...]:
    """Ids of the frame's posted identifications whose detection is not where the landmark truly is.

    Seen from the true pose, a landmark lies within its ``position_uncertainty`` disk: a
    Class I line on the vertical cylinder of that radius between its heights, a Class II
    point on the disk at its height. A detection whose midpoint is more than
    ``_WRONG_PIXELS`` outside the image of that cylinder (Class I: its columns; Class II:
    its columns and rows) identified something else: another corner of a building, clutter.
    Class III identifications are not judged.
    """
    camera = scenario.camera
    wrong = []
    detections = dict(record.detections)
    around = np.linspace(0.0, 2.0 * math.pi, _WRONG_DISK_POINTS, endpoint=False)
    for ident in record.posted:
        landmark = scenario.meadow_map.landmark(ident).landmark
        if ident not in detections or isinstance(landmark, GroundLineLandmark):
            continue
        u1, v1, u2, v2 = detections[ident]
        if isinstance(landmark, PointLandmark):
            heights = np.array([landmark.z])
        else:
            heights = np.linspace(landmark.z_bottom, landmark.z_top, _WRONG_HEIGHTS)
        r = landmark.position_uncertainty
        a, z = np.meshgrid(around, heights)
        points = np.column_stack(
            [landmark.x + r * np.cos(a.ravel()), landmark.y + r * np.sin(a.ravel()), z.ravel()]
        )
        pixels = camera.project(record.true_pose, points)
        pixels = pixels[np.isfinite(pixels).all(axis=1)]
        if not len(pixels):  # behind the camera from the true pose
            wrong.append(ident)
            continue
        centre = (0.5 * (u1 + u2), 0.5 * (v1 + v2))
        axes = (0, 1) if isinstance(landmark, PointLandmark) else (0,)
        for axis in axes:
            low, high = pixels[:, axis].min() - _WRONG_PIXELS, pixels[:, axis].max() + _WRONG_PIXELS
            if not low <= centre[axis] <= high:
                wrong.append(ident)
                break
    return tuple(wrong)


def position_counts(scenario: Scenario, results: list[RunResult]) -> list[PositionCounts]:
    """Count, per position of the route, the runs that pruned there, kept the truth, misidentified."""
    positions = max((len(r.records) for r in results), default=0)
    counts = []
    for index in range(positions):
        records = [r.records[index] for r in results if len(r.records) > index]
        counts.append(
            PositionCounts(
                index,
                len(records),
                sum(r.accepted > 0 for r in records),
                sum(r.inside for r in records),
                sum(len(r.posted) for r in records),
                sum(len(misidentified(scenario, r)) for r in records),
            )
        )
    return counts


def position_counts_markdown(name: str, counts: list[PositionCounts]) -> list[str]:
    """Return the per-position table of a Monte Carlo variant."""
    lines = [
        f"| {name}: position | runs | runs pruned here | true pose inside | identifications | wrong ones |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for c in counts:
        lines.append(
            f"| {c.index + 1} | {c.runs} | {c.pruned} | {c.inside} | {c.identifications} | {c.wrong} |"
        )
    return lines


def position_counts_sentences(counts: list[PositionCounts]) -> list[str]:
    """Say, from the per-position counts, where the map was pruned and where the truth was lost.

    Examples
    --------
    >>> a = PositionCounts(0, 10, 10, 10, 12, 0)
    >>> b = PositionCounts(1, 10, 6, 9, 7, 1)
    >>> print(" ".join(position_counts_sentences([a, b])))  # doctest: +NORMALIZE_WHITESPACE
    The map was pruned at every position in some run: at position 1 in 10 of 10 runs,
    at position 2 in 6 of 10. The true pose stayed inside at position 1 in every run; at
    position 2 it was outside in 1 of 10 runs, with 1 of 7 identifications there wrong
    (detected away from the landmark's true image).
    """
    if not counts:
        return []
    pruned = [c for c in counts if c.pruned]
    where = ", ".join(
        f"at position {c.index + 1} in {c.pruned} of {c.runs}" + (" runs" if k == 0 else "")
        for k, c in enumerate(counts)
    )
    if len(pruned) == len(counts):
        first = f"The map was pruned at every position in some run: {where}."
    elif pruned:
        never = _positions([c.index + 1 for c in counts if not c.pruned])
        first = f"The map was never pruned at {never}: {where}."
    else:
        first = "The map was pruned at no position in any run."
    kept = [c.index + 1 for c in counts if c.inside == c.runs]
    lost = [c for c in counts if c.inside < c.runs]
    parts = []
    if kept:
        parts.append(f"The true pose stayed inside at {_positions(kept)} in every run")
    for c in lost:
        parts.append(
            f"at position {c.index + 1} it was outside in {c.runs - c.inside} of {c.runs} runs, "
            f"with {c.wrong} of {c.identifications} identifications there wrong "
            "(detected away from the landmark's true image)"
        )
    second = "; ".join(parts)
    return [first, second[0].upper() + second[1:] + "."]


def monte_carlo_markdown(mc: list[tuple[str, Metrics]]) -> list[str]:
    """Return the Monte Carlo table: a column per variant, a row per metric (shown by :func:`_cell`)."""
    lines = ["| metric | " + " | ".join(name for name, _ in mc) + " |"]
    lines.append("| --- | " + " | ".join("---" for _ in mc) + " |")
    for key in mc[0][1]:
        lines.append(f"| {key} | " + " | ".join(_cell(metrics[key]) for _, metrics in mc) + " |")
    return lines


def class2_paragraph(class1: Metrics, class2: Metrics) -> list[str]:
    """Say what changes with the corner as a Class II landmark, each comparison chosen from the figures.

    The figures are quoted as the Monte Carlo table shows them (:func:`_cell`), and the verb
    ("stays at", "falls from", "rises from", ...) is decided on those shown values.

    Examples
    --------
    >>> one = Metrics({"containment_rate": 1.0, "median_area_m2": 0.85, "median_wedge_width_rad": 0.16,
    ...                "inconsistent_observations": 0})
    >>> two = Metrics({"containment_rate": 0.95, "median_area_m2": 0.78, "median_wedge_width_rad": 0.16,
    ...                "inconsistent_observations": 2})
    >>> print(class2_paragraph(one, two)[-1])  # doctest: +NORMALIZE_WHITESPACE
    With the corner as Class II, the median area shrinks from 0.85 to 0.78 m², the median
    wedge stays at 0.16 rad, containment falls from 1 to 0.95, and the inconsistent
    observations rise from 0 to 2.
    """
    area = _change(
        "the median area",
        _cell(class1["median_area_m2"]),
        _cell(class2["median_area_m2"]),
        down="shrinks",
        up="grows",
    )
    wedge = _change(
        "the median wedge",
        _cell(class1["median_wedge_width_rad"]),
        _cell(class2["median_wedge_width_rad"]),
        down="narrows",
        up="widens",
    )
    containment = _change(
        "containment",
        _cell(class1["containment_rate"]),
        _cell(class2["containment_rate"]),
        down="falls",
        up="rises",
    )
    rejected = _change(
        "the inconsistent observations",
        _cell(class1["inconsistent_observations"]),
        _cell(class2["inconsistent_observations"]),
        down="fall",
        up="rise",
    ).replace(" stays at ", " stay at ")
    return [
        "What changes with the corner as a Class II landmark (a point of known height): its image",
        "row gives a range as well as a bearing, so a recognition can cut the polygon along the",
        "line of sight too, not only the heading (the paper's robot could not use it: its ground-",
        "plane assumption failed). Compared over all frames of the Monte Carlo above (Class I",
        'column "paper, pruning", Class II column "class II corner, pruning"):',
        f"With the corner as Class II, {area} m², {wedge} rad, {containment}, and {rejected}.",
    ]
