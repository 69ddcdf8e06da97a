"""The runs of aura-ums' campaigns: a seeded simulation, a log loaded, a log replayed.

Each is a frozen value with ``__call__(item)``, so that Dask can pickle it to a worker
with everything it needs, and its value depends on its item alone: the campaign on any
number of workers equals the serial one.
"""

from __future__ import annotations

import dataclasses
import numbers
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TypeVar

import numpy as np

from aura_ums._metrics import Metrics
from aura_ums._validate import gap_seconds, integer_at_least, items_of
from aura_ums.camera import CalibrationBounds, Camera
from aura_ums.campaign._engine import Campaign, run_campaign, settings_or_serial
from aura_ums.campaign._settings import CampaignSettings
from aura_ums.errors import InputError
from aura_ums.logs import ReplayOptions, ReplayResult, RobotLog, load_log, replay_log, replay_windows
from aura_ums.sim import PerceptionMode, RunResult, Scenario, run_scenario
from aura_ums.uncertainty import TerrainTable

_Item = TypeVar("_Item")

#: Tasks per worker of a local cluster when a Monte Carlo is batched, and tasks on an
#: existing scheduler (whose size is not known here): enough to balance the load, few
#: enough that Dask's cost per task (tens of ms, about one short run's) stays small.
BATCHES_PER_WORKER = 4
BATCHES_ON_A_SCHEDULER = 64
#: What spawning one run's seed costs (``SeedSequence.spawn``: 100,000 seeds in 1.0 s, 38 MB).
_SEED_SECONDS = 1e-5
_SEED_BYTES = 400


def run_seeds(seed: int, runs: int) -> tuple[np.random.SeedSequence, ...]:
    """Return the seed of each run of a Monte Carlo: ``SeedSequence(seed).spawn(runs)``.

    The same seeds as ``numpy.random.default_rng(seed).spawn(runs)`` (the generators'
    seed sequences), so a run's draws depend on ``seed`` and its index only.

    Parameters
    ----------
    seed : int
        Seed of the whole Monte Carlo, >= 0.
    runs : int
        Number of runs, in [0, 100000] (:attr:`Scenario.max_runs <aura_ums.sim.Scenario.max_runs>`,
        a Monte Carlo's limit).

    Examples
    --------
    >>> first, second = run_seeds(7, 2)
    >>> first.spawn_key, second.spawn_key
    ((0,), (1,))
    >>> run_seeds(7, 0)
    ()
    >>> run_seeds(7, 10**12)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: runs: expected an integer in [0, 100000], got 1000000000000 (about 1e+07 s \
and 4e+05 GB of seeds)
    """
    for value, name in ((seed, "seed"), (runs, "runs")):
        if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < 0:
            raise InputError(f"{name}: expected an integer >= 0, got {value!r}")
    if runs > Scenario.max_runs:
        count = int(runs)
        raise InputError(
            f"runs: expected an integer in [0, {Scenario.max_runs}], got {runs!r} (about "
            f"{count * _SEED_SECONDS:.3g} s and {count * _SEED_BYTES / 1e9:.3g} GB of seeds)"
        )
    return tuple(np.random.SeedSequence(int(seed)).spawn(int(runs)))


@dataclass(frozen=True, slots=True)
class SimulationRun:
    """One Monte Carlo run of a scenario: ``SimulationRun(scenario)(seed) -> RunResult``.

    Parameters
    ----------
    scenario : Scenario
        The scenario, settings included.
    prune : bool
        Reduce the map by landmarks (False: growth only).
    perception : PerceptionMode
        Where perception runs (:func:`~aura_ums.sim.run_scenario`'s ``perception``).

    Examples
    --------
    >>> import pathlib
    >>> run = SimulationRun(Scenario.from_toml(pathlib.Path("scenarios/paper_sidewalk.toml")))
    >>> (seed,) = run_seeds(1, 1)
    >>> result = run(seed)
    >>> len(result.records), run(seed).final_map.area == result.final_map.area   # the same seed, the same run
    (4, True)
    >>> run(1)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: seed: expected a numpy.random.SeedSequence, got int
    """

    scenario: Scenario
    prune: bool = True
    perception: PerceptionMode = PerceptionMode.WINDOWS

    def __call__(self, seed: np.random.SeedSequence) -> RunResult:
        """Run the scenario once with the generator of ``seed``.

        A fresh copy of ``seed`` is used: a seed sequence counts the children it spawned,
        and the run spawns from it, so a second call with the same seed would otherwise
        draw differently.
        """
        if not isinstance(seed, np.random.SeedSequence):
            raise InputError(f"seed: expected a numpy.random.SeedSequence, got {type(seed).__name__}")
        fresh = np.random.SeedSequence(seed.entropy, spawn_key=seed.spawn_key, pool_size=seed.pool_size)
        return run_scenario(
            self.scenario, np.random.default_rng(fresh), prune=self.prune, perception=self.perception
        )


@dataclass(frozen=True, slots=True)
class SimulationBatch:
    """Consecutive Monte Carlo runs in one task: ``SimulationBatch(run)(seeds) -> tuple of RunResult``.

    Each run is ``run(seed)`` as alone, so a batched campaign equals the per-run one.

    Parameters
    ----------
    run : SimulationRun
        One run of the scenario.

    Examples
    --------
    >>> import pathlib
    >>> run = SimulationRun(Scenario.from_toml(pathlib.Path("scenarios/paper_sidewalk.toml")))
    >>> (seed,) = run_seeds(1, 1)
    >>> first, second = SimulationBatch(run)((seed, seed))     # each run as alone: the same run twice
    >>> len(first.records), first.final_map.area == second.final_map.area
    (4, True)
    >>> SimulationBatch(run)(())                   # an empty batch: no run
    ()
    """

    run: SimulationRun

    def __call__(self, seeds: tuple[np.random.SeedSequence, ...]) -> tuple[RunResult, ...]:
        """Run the scenario once per seed, in order."""
        return tuple(self.run(seed) for seed in seeds)


def batches(items: tuple[_Item, ...], count: int) -> list[tuple[_Item, ...]]:
    """Split ``items`` into ``count`` consecutive batches whose sizes differ by at most one.

    Examples
    --------
    >>> batches((1, 2, 3, 4, 5), 2)
    [(1, 2), (3, 4, 5)]
    >>> batches((1, 2), 5)          # never an empty batch
    [(1,), (2,)]
    >>> batches((1, 2), 0)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: count: expected an integer >= 1, got 0
    """
    items = tuple(items_of(items, "items", "a sequence of items"))
    count = integer_at_least(count, "count", 1)
    parts = max(1, min(count, len(items)))
    ends = [len(items) * k // parts for k in range(parts + 1)]
    return [items[ends[k] : ends[k + 1]] for k in range(parts)]


def simulate_campaign(
    scenario: Scenario,
    runs: int,
    seed: int,
    *,
    prune: bool = True,
    perception: PerceptionMode = PerceptionMode.WINDOWS,
    settings: CampaignSettings | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> Campaign[RunResult]:
    """Run a scenario's Monte Carlo: ``runs`` runs seeded by :func:`run_seeds` (``seed``, ``runs``).

    The runs come back in their order, the same on any number of workers; summarize them
    with :func:`aura_ums.sim.summarize_runs`.

    Parameters
    ----------
    scenario : Scenario
    runs : int
        In [1, 100000] (:meth:`Scenario.check_runs <aura_ums.sim.Scenario.check_runs>`).
    seed : int
        >= 0.
    prune : bool
        Reduce the map by landmarks (False: growth only).
    perception : PerceptionMode
        Where perception runs: the Expecter's windows (the default), the full frame, or the
        focus map's windows first (:class:`~aura_ums.sim.PerceptionMode`).
    settings : CampaignSettings or None
        Where to run (default: serially, in this process).
    progress : callable or None
        ``progress(done, total)`` after each finished run.

    Examples
    --------
    >>> import pathlib
    >>> from aura_ums.sim import summarize_runs
    >>> scenario = Scenario.from_toml(pathlib.Path("scenarios/paper_sidewalk.toml"))
    >>> campaign = simulate_campaign(scenario, 2, seed=1)
    >>> summarize_runs(campaign.values)["frames"], campaign.retried
    (8, 0)
    >>> simulate_campaign(scenario, 0, seed=1)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: runs: expected an integer in [1, 100000], got 0
    """
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario: expected a Scenario, got {type(scenario).__name__}")
    count = scenario.check_runs(runs)  # before a seed is spawned per run
    if not isinstance(perception, PerceptionMode):
        raise InputError(f"perception: expected a PerceptionMode, got {perception!r}")
    run, seeds = SimulationRun(scenario, prune, perception), run_seeds(seed, count)
    chosen = settings_or_serial(settings)
    if not chosen.distributed:
        return run_campaign(run, seeds, chosen, progress=progress)
    # A run takes tens of ms, about Dask's own cost per task: runs go to workers in batches.
    tasks = BATCHES_PER_WORKER * chosen.workers if chosen.scheduler is None else BATCHES_ON_A_SCHEDULER
    parts = batches(seeds, tasks)
    longest = max(len(part) for part in parts)
    if chosen.timeout_s is not None:  # a run's limit, so a batch's is its longest's sum
        chosen = dataclasses.replace(chosen, timeout_s=chosen.timeout_s * longest)

    def advance(done: int, total: int) -> None:
        if progress is not None:
            progress(count * done // total, count)

    batched = run_campaign(SimulationBatch(run), parts, chosen, progress=advance)
    starts = np.cumsum([0] + [len(part) for part in parts]).tolist()
    retried = tuple(i for b in batched.retried_items for i in range(starts[b], starts[b + 1]))
    values = tuple(result for part in batched.values for result in part)
    return Campaign(values, len(retried), retried)


@dataclass(frozen=True, slots=True)
class LoadLog:
    """Read a log folder: ``LoadLog()(folder) -> RobotLog`` (:func:`~aura_ums.logs.load_log`).

    Parameters
    ----------
    max_truth_gap : float or None
        Longest interval, s, between ground-truth rows interpolated across
        (:meth:`GroundTruth.with_max_gap <aura_ums.logs.GroundTruth.with_max_gap>`);
        None: the log's own.

    Examples
    --------
    >>> import tempfile
    >>> from aura_ums.logs import synthetic_log, write_log
    >>> folder = write_log(synthetic_log(np.random.default_rng(0), duration=5.0), tempfile.mkdtemp() + "/log")
    >>> log = LoadLog()(folder)
    >>> log.meta.name, log.groundtruth.max_gap, LoadLog(max_truth_gap=2.0)(folder).groundtruth.max_gap
    ('synthetic', 0.5, 2.0)
    >>> LoadLog()(folder / "missing")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.FileFormatError: .../missing: expected a log folder, got no such folder
    >>> LoadLog(max_truth_gap=-1.0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: LoadLog.max_truth_gap: expected a positive number of seconds ..., got -1.0
    """

    max_truth_gap: float | None = None

    def __post_init__(self) -> None:
        # Checked here, not on the worker: a campaign learns of a bad gap before it starts.
        if self.max_truth_gap is not None:
            gap = gap_seconds(self.max_truth_gap, "LoadLog.max_truth_gap")
            object.__setattr__(self, "max_truth_gap", gap)

    def __call__(self, folder: str | os.PathLike[str]) -> RobotLog:
        """Read ``folder`` (on the worker: the path must be readable there)."""
        log = load_log(Path(folder))
        if self.max_truth_gap is None or log.groundtruth is None:
            return log
        return dataclasses.replace(log, groundtruth=log.groundtruth.with_max_gap(self.max_truth_gap))


@dataclass(frozen=True, slots=True)
class LogReplay:
    """Replay a log folder and return its metrics: ``LogReplay(table, options)(folder) -> Metrics``.

    The replay of ``aura-ums replay`` (:func:`~aura_ums.logs.replay_log`, or with a camera
    :func:`~aura_ums.logs.replay_windows`), without maps kept: a worker returns only the
    figures.

    Parameters
    ----------
    table : TerrainTable
        Terrain statistics holding the logs' terrains.
    options : ReplayOptions
        The replay's settings and bounds.
    camera : Camera or None
        Judge each observation's image window through this camera too.
    window_margin : float
        Pixels added on every side of each window (with a camera), >= 0.
    load : LoadLog
        How the folder is read.
    until : float or None
        Stop after the last frame at or before this log time, s.
    table_file : str
        Where ``table`` was read (the terrain TOML), named when it lacks a log's terrain.
    calibration_bounds : CalibrationBounds or None
        How far the true camera may be from ``camera`` (windows for every camera within them).

    Examples
    --------
    >>> from aura_ums.logs import ReplayOptions, synthetic_log, write_log
    >>> import numpy as np, tempfile
    >>> folder = write_log(synthetic_log(np.random.default_rng(0), duration=5.0), tempfile.mkdtemp() + "/log")
    >>> LogReplay(TerrainTable({}), ReplayOptions(), table_file="none.toml")(folder)  # the edge: no terrain
    Traceback (most recent call last):
    ...
    aura_ums.errors.UnknownTerrainError: none.toml: expected the terrain 'floor' of the log in ...), got none
    """

    table: TerrainTable
    options: ReplayOptions
    camera: Camera | None = None
    window_margin: float = 0.0
    load: LoadLog = LoadLog()
    until: float | None = None
    table_file: str = "table"
    calibration_bounds: CalibrationBounds | None = None

    def __call__(self, folder: str | os.PathLike[str]) -> Metrics:
        """Replay the log in ``folder`` and return its metrics (with the windows', given a camera).

        The metrics are :meth:`ReplayResult.metrics <aura_ums.logs.ReplayResult.metrics>`. A log
        that replays no step (:meth:`~aura_ums.logs.ReplayResult.require_steps`) is refused.
        """
        log = self.load(folder)
        # Checked here, where the log's terrain is first known: the replay's own check
        # names neither the table's file nor the log among the campaign's many.
        self.table.require(
            log.meta.terrain, where=str(self.table_file), whose=f"the log in {folder} (its meta.toml)"
        )
        if self.camera is None:
            result = replay_log(log, self.table, self.options, keep_maps=False, until=self.until)
            _require_steps(result, self.until, folder)
            return result.metrics()
        result, windows = replay_windows(
            log,
            self.table,
            self.camera,
            self.options,
            margin=self.window_margin,
            keep_maps=False,
            until=self.until,
            calibration_bounds=self.calibration_bounds,
        )
        _require_steps(result, self.until, folder)
        return Metrics({**result.metrics(), **windows.metrics()})


def _require_steps(result: ReplayResult, until: float | None, folder: str | os.PathLike[str]) -> None:
    """Refuse a log of the campaign that replayed no step, naming its folder among the many."""
    try:
        result.require_steps(until)
    except InputError as exc:
        raise InputError(f"{os.fspath(folder)}: {exc}") from None
