"""``aura_ums.campaign``: serial and Dask campaigns agree; a lost run is retried, never dropped."""

from __future__ import annotations

import contextlib
import dataclasses
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from aura_ums.campaign import (
    CampaignSettings,
    LoadLog,
    LogReplay,
    SimulationBatch,
    SimulationRun,
    batches,
    run_campaign,
    run_seeds,
    simulate_campaign,
)
from aura_ums.errors import InputError, MissingDependencyError, RunLostError
from aura_ums.geometry import ImageWindow
from aura_ums.logs import ReplayOptions, calibrate_logs, synthetic_log, write_log
from aura_ums.manager import MapProfile
from aura_ums.sim import PerceptionMode, RunResult, Scenario, run_scenario, summarize_runs
from tests.campaign.campaign_helpers import FailOn, HangOnce, KillAlways, KillOnce, run_figures

SCENARIO = Path(__file__).resolve().parents[2] / "scenarios" / "paper_sidewalk.toml"
# The one timing key of simulate's metrics: measured, so never equal between two campaigns.
TIMING = {"median_frame_ms"}


@pytest.fixture(scope="module")
def scenario() -> Scenario:
    return Scenario.from_toml(SCENARIO)


@contextlib.contextmanager
def two_worker_cluster() -> Iterator[str]:
    """A two-worker cluster of processes, as the campaign starts its own: its scheduler's address."""
    distributed = pytest.importorskip("distributed", reason="the dask extra is not installed")
    cluster = distributed.LocalCluster(
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
        # Its HTTP server on a free loopback port: 8787, Dask's default, may be taken.
        scheduler_kwargs={"allowed_failures": 0, "dashboard": False, "dashboard_address": "127.0.0.1:0"},
    )
    with cluster:
        yield cluster.scheduler_address


@pytest.fixture(scope="module")
def scheduler() -> Iterator[str]:
    """One cluster shared by the Dask tests (its workers may be killed: their nannies restart them)."""
    with two_worker_cluster() as address:
        yield address


@pytest.fixture
def fresh_scheduler() -> Iterator[str]:
    """A cluster of its own, for a test that restarts workers.

    A nanny whose worker process was killed once (the shared cluster's) may not bring its
    worker back after a restart the scheduler asks for (distributed 2026.8).
    """
    with two_worker_cluster() as address:
        yield address


def test_a_serial_campaign_keeps_the_order_and_reports_progress() -> None:
    seen: list[tuple[int, int]] = []
    campaign = run_campaign(abs, [-3, 1, -2], progress=lambda done, total: seen.append((done, total)))
    assert campaign.values == (3, 1, 2)
    assert campaign.retried == 0
    assert seen == [(1, 3), (2, 3), (3, 3)]


def test_run_seeds_are_the_generators_simulate_always_spawned() -> None:
    # simulate seeded its runs with default_rng(seed).spawn(runs): the same streams.
    before = [g.integers(2**62, size=4) for g in np.random.default_rng(11).spawn(5)]
    now = [np.random.default_rng(s).integers(2**62, size=4) for s in run_seeds(11, 5)]
    for old, new in zip(before, now, strict=True):
        assert np.array_equal(old, new)


def test_run_seeds_are_bounded_by_a_monte_carlo_s_runs() -> None:
    assert len(run_seeds(0, Scenario.max_runs)) == Scenario.max_runs
    for runs in (Scenario.max_runs + 1, 10**12, 2**63):
        message = r"runs: expected an integer in \[0, 100000\], got \d+ \(about .* GB of seeds\)"
        with pytest.raises(InputError, match=message):
            run_seeds(0, runs)


@pytest.mark.parametrize(
    ("task", "items", "message"),
    [
        (None, [1, 2], "task: expected a callable, task.item. -> value, got NoneType"),
        (abs, None, "items: expected a sequence of items, one a run, got NoneType"),
        (abs, 1, "items: expected a sequence of items, one a run, got int"),
        (abs, "12", "items: expected a sequence of items, one a run, got str"),
    ],
)
def test_run_campaign_refuses_what_is_no_task_or_no_items(task: Any, items: Any, message: str) -> None:
    with pytest.raises(InputError, match=message):
        run_campaign(task, items)
    with pytest.raises(InputError, match=r"progress: expected a callable, progress\(done, total\), or None"):
        run_campaign(abs, [1], progress=1)  # type: ignore[arg-type]


def test_a_run_called_twice_with_one_seed_draws_the_same(scenario: Scenario) -> None:
    # run_scenario spawns from its generator's seed sequence, which counts its children.
    (seed,) = run_seeds(3, 1)
    run = SimulationRun(scenario)
    assert run_figures(run(seed)) == run_figures(run(seed))


def test_a_run_searches_where_its_perception_says() -> None:
    corridor = Scenario.from_toml(SCENARIO.with_name("indoor_corridor.toml"))
    relaxed = dataclasses.replace(corridor, settings=MapProfile.RELAXED.settings(corridor.settings))
    (seed,) = run_seeds(2, 1)

    def windows(result: RunResult) -> list[tuple[str, ImageWindow]]:
        return [pair for record in result.records for pair in record.windows]

    focus = windows(SimulationRun(relaxed, perception=PerceptionMode.FOCUS_FIRST)(seed))
    fresh = np.random.SeedSequence(seed.entropy, spawn_key=seed.spawn_key, pool_size=seed.pool_size)
    alone = run_scenario(relaxed, np.random.default_rng(fresh), perception=PerceptionMode.FOCUS_FIRST)
    assert focus == windows(alone)
    assert focus != windows(SimulationRun(relaxed)(seed))  # some landmark was found in a focus window
    with pytest.raises(InputError, match="perception: expected a PerceptionMode, got 'windows'"):
        simulate_campaign(relaxed, 1, 0, perception="windows")  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"workers": 0}, r"workers: expected an integer in \[1, 256\], got 0"),
        ({"workers": 2.0}, r"workers: expected an integer in \[1, 256\], got 2\.0"),
        ({"retries": -1}, r"retries: expected an integer in \[0, 100\], got -1"),
        ({"timeout_s": 0.0}, r"timeout_s: expected a finite number of seconds > 0 or None, got 0\.0"),
        ({"timeout_s": float("inf")}, r"timeout_s: expected a finite number of seconds > 0 or None"),
        ({"scheduler": " "}, r"scheduler: expected a Dask scheduler address, got ' '"),
        ({"scheduler": "tcp://127.0.0.1:8786", "workers": 3}, r"workers: expected 1 with a scheduler"),
    ],
)
def test_bad_settings_are_refused_by_name(kwargs: dict[str, object], message: str) -> None:
    with pytest.raises(InputError, match=message):
        CampaignSettings(**kwargs)  # type: ignore[arg-type]


def test_a_scheduler_nothing_listens_at_is_refused_by_name() -> None:
    with socket.socket() as probe:  # a port just free: nothing listens at it
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    settings = CampaignSettings(scheduler=f"tcp://127.0.0.1:{port}")
    with pytest.raises(InputError, match=r"scheduler: expected a Dask scheduler at .*ConnectionRefusedError"):
        run_campaign(abs, [1], settings)


def test_without_the_extra_a_dask_campaign_names_it(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "distributed", None)
    with pytest.raises(MissingDependencyError, match=r"install aura-ums\[dask\]"):
        run_campaign(abs, [1], CampaignSettings(workers=2))
    # Serially nothing more is needed.
    assert run_campaign(abs, [-1], CampaignSettings()).values == (1,)


def test_a_campaign_on_a_cluster_equals_the_serial_one(scenario: Scenario, scheduler: str) -> None:
    serial = simulate_campaign(scenario, 6, seed=4)
    seen: list[tuple[int, int]] = []
    parallel = simulate_campaign(
        scenario,
        6,
        seed=4,
        settings=CampaignSettings(scheduler=scheduler),
        progress=lambda *p: seen.append(p),
    )
    assert [run_figures(r) for r in parallel.values] == [run_figures(r) for r in serial.values]
    summary, again = summarize_runs(serial.values), summarize_runs(parallel.values)
    assert {k: v for k, v in summary.items() if k not in TIMING} == {
        k: v for k, v in again.items() if k not in TIMING
    }
    assert parallel.retried == 0
    assert seen == [(done, 6) for done in range(1, 7)]


def test_a_killed_worker_is_retried_and_the_campaign_still_equals_the_serial_one(
    scenario: Scenario, scheduler: str, tmp_path: Path
) -> None:
    seeds = run_seeds(9, 10)
    serial = run_campaign(SimulationRun(scenario), seeds)
    killer = KillOnce(SimulationRun(scenario), victim=6, marker=tmp_path / "killed", items=seeds)
    parallel = run_campaign(killer, seeds, CampaignSettings(scheduler=scheduler, retries=2))
    assert (tmp_path / "killed").exists(), "the victim's first attempt never ran"
    assert parallel.retried == 1
    assert [run_figures(r) for r in parallel.values] == [run_figures(r) for r in serial.values]


@pytest.mark.parametrize(("size", "count"), [(0, 3), (1, 3), (5, 2), (7, 3), (10, 64)])
def test_batches_keep_every_item_in_order_and_differ_by_at_most_one(size: int, count: int) -> None:
    items = tuple(range(size))
    parts = batches(items, count)
    assert tuple(i for part in parts for i in part) == items
    assert len(parts) == max(1, min(count, size))
    if size:
        assert max(map(len, parts)) - min(map(len, parts)) <= 1


def test_a_batched_campaign_with_a_killed_worker_equals_the_serial_one(
    scenario: Scenario, scheduler: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import aura_ums.campaign._jobs as jobs

    # Three batches of 3-4 runs on the test cluster, as a large campaign would have.
    monkeypatch.setattr(jobs, "BATCHES_ON_A_SCHEDULER", 3)
    seeds = run_seeds(5, 10)
    serial = simulate_campaign(scenario, 10, seed=5)
    seen: list[tuple[int, int]] = []
    batched = simulate_campaign(
        scenario,
        10,
        seed=5,
        settings=CampaignSettings(scheduler=scheduler),
        progress=lambda *p: seen.append(p),
    )
    assert [run_figures(r) for r in batched.values] == [run_figures(r) for r in serial.values]
    assert seen == sorted(seen)
    assert seen[-1] == (10, 10)
    assert len(seen) == 3
    parts = batches(seeds, 3)
    batch = SimulationBatch(SimulationRun(scenario))
    killer = KillOnce(batch, victim=1, marker=tmp_path / "killed", items=parts)
    again = run_campaign(killer, parts, CampaignSettings(scheduler=scheduler, retries=2))
    assert again.retried == 1
    assert again.retried_items == (1,)
    assert [run_figures(r) for part in again.values for r in part] == [run_figures(r) for r in serial.values]


def test_a_run_lost_more_often_than_its_retries_fails_the_campaign(scheduler: str) -> None:
    with pytest.raises(
        RunLostError, match=r"run 2: expected it to finish within 1 retries, got it lost 2 times"
    ):
        run_campaign(KillAlways(victim=2), [0, 1, 2, 3], CampaignSettings(scheduler=scheduler, retries=1))


def test_a_stuck_run_times_out_and_is_retried(fresh_scheduler: str, tmp_path: Path) -> None:
    stuck = HangOnce(victim=1, marker=tmp_path / "hung")
    # The clock of a run starts when it is handed to a worker, a restarted worker's imports
    # included: generous, for a loaded machine; the stuck run sleeps far longer.
    settings = CampaignSettings(scheduler=fresh_scheduler, retries=2, timeout_s=10.0)
    campaign = run_campaign(stuck, [0, 1, 2, 3], settings)
    assert (tmp_path / "hung").exists(), "the stuck attempt never ran"
    assert campaign.values == (0, 1, 4, 9)
    assert campaign.retried >= 1


def test_a_runs_own_error_is_raised_not_retried(scheduler: str) -> None:
    with pytest.raises(InputError, match="item: expected anything but 3, got it"):
        run_campaign(FailOn(victim=3), [1, 2, 3], CampaignSettings(scheduler=scheduler, retries=5))


def test_a_local_cluster_replays_logs_as_the_serial_campaign(tmp_path: Path) -> None:
    pytest.importorskip("distributed", reason="the dask extra is not installed")
    logs = [synthetic_log(np.random.default_rng(index), duration=30.0) for index in range(3)]
    folders = [write_log(log, tmp_path / f"l{index}") for index, log in enumerate(logs)]
    table = calibrate_logs(logs).terrain_table()  # the synthetic logs' terrain
    replay = LogReplay(table, ReplayOptions(), load=LoadLog(max_truth_gap=1.0))
    serial = run_campaign(replay, folders)
    parallel = run_campaign(replay, folders, CampaignSettings(workers=2))
    timing = {"median_update_us"}
    assert [{k: v for k, v in m.items() if k not in timing} for m in parallel.values] == [
        {k: v for k, v in m.items() if k not in timing} for m in serial.values
    ]
    assert [m["log"] for m in parallel.values] == [m["log"] for m in serial.values]


class _StuckFuture:
    key = "aura-ums-test-run0-attempt0"

    def cancel(self) -> None:
        pass


class _ClusterWithoutWorkers:
    """A client whose stuck worker's nanny never brings a worker back (nor does any other)."""

    def __init__(self) -> None:
        self.scheduler = self
        self.restarted: list[str] = []

    def processing(self) -> dict[str, tuple[str, ...]]:
        return {"tcp://stuck": (_StuckFuture.key,)}

    def restart_workers(self, *, workers: list[str], wait_for_workers: bool, **kwargs: object) -> None:
        self.restarted.extend(workers)
        assert wait_for_workers is False  # never the 60 s wait for a worker that may not return

    def sync(self, function: Any, **kwargs: object) -> None:
        function(**kwargs)

    def wait_for_workers(self, count: int, timeout: float) -> None:
        raise TimeoutError(f"Only 0/{count} workers arrived after {timeout}")


def test_a_restart_after_which_no_worker_returns_fails_the_campaign_by_name() -> None:
    import aura_ums.campaign._engine as engine

    runs = engine._Runs(abs, [1], CampaignSettings(retries=2, timeout_s=1.0))
    runs.in_flight[_StuckFuture()] = (0, time.monotonic() - 5.0)  # type: ignore[index]
    client = _ClusterWithoutWorkers()
    with pytest.raises(
        RunLostError, match=r"scheduler: expected a worker within 60 s of restarting 1 stuck worker"
    ):
        engine._time_out(client, runs, 1.0)  # type: ignore[arg-type]
    assert client.restarted == ["tcp://stuck"]
    assert runs.retried == {0}


def test_local_workers_that_cannot_start_are_named_not_a_traceback() -> None:
    # A Dask setting the workers cannot read (DASK_DISTRIBUTED__WORKER__MEMORY__TARGET=abc in
    # the environment) was "RuntimeError: Nanny failed to start." through a traceback. In a
    # process of its own: the half-started cluster Dask leaves behind broke the next cluster
    # of the same process (KeyError 'comm'), whichever test came next on that worker.
    pytest.importorskip("distributed", reason="the dask extra is not installed")
    script = (
        "import dask\n"
        "from aura_ums.campaign import CampaignSettings, run_campaign\n"
        "from aura_ums.errors import AuraUmsError\n"
        "if __name__ == '__main__':\n"
        "    with dask.config.set({'distributed.worker.memory.target': 'abc'}):\n"
        "        try:\n"
        "            run_campaign(abs, [1], CampaignSettings(workers=2))\n"
        "        except AuraUmsError as exc:\n"
        "            print(exc)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=300, check=False
    )
    assert done.stdout.startswith("workers: expected 2 local Dask workers to start, got RuntimeError"), (
        done.stderr
    )
