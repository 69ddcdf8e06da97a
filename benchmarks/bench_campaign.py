"""Benchmark a Monte Carlo campaign on Dask: wall time, speed-up and efficiency by worker count.

Run: ``.venv/bin/python benchmarks/bench_campaign.py [runs] [workers ...]``
(default: 400 runs of ``scenarios/paper_sidewalk.toml``, seed 0, on 1, 2, 4 and 8 workers).

The baseline is the serial campaign in this process (``--workers 1``). Each Dask row
starts a local cluster of that many worker processes (one thread each) and times the
whole campaign, the cluster's start and stop included, as a user of ``simulate --workers
N`` waits for it. Speed-up is serial time over the row's, efficiency the speed-up per
worker. Every row's metrics are checked against the serial ones, the timing key
(``median_frame_ms``) aside; a difference is printed, never hidden. Speed depends on the
machine's cores and load: on a 2-core machine, 4 and 8 workers cannot go faster than 2.
Nothing here is asserted.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

from aura_ums.campaign import CampaignSettings, simulate_campaign
from aura_ums.sim import Scenario, summarize_runs

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "paper_sidewalk.toml"
TIMING = {"median_frame_ms"}


def _figures(scenario: Scenario, runs: int, workers: int) -> tuple[float, dict[str, object], int]:
    start = time.perf_counter()
    campaign = simulate_campaign(scenario, runs, seed=0, settings=CampaignSettings(workers=workers))
    seconds = time.perf_counter() - start
    metrics: dict[str, object] = {k: v for k, v in summarize_runs(campaign.values).items() if k not in TIMING}
    return seconds, metrics, campaign.retried


def main() -> None:
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 400
    counts = [int(n) for n in sys.argv[2:]] or [1, 2, 4, 8]
    scenario = Scenario.from_toml(SCENARIO)
    print(f"{scenario.name}: {runs} runs, seed 0, on {os.cpu_count()} cores")
    serial_s, serial, _ = _figures(scenario, runs, 1)
    print(f"{'workers':>8} {'wall s':>9} {'speed-up':>9} {'efficiency':>11} {'retried':>8}  metrics")
    print(f"{'serial':>8} {serial_s:9.2f} {1.0:9.2f} {1.0:11.2f} {0:8d}  (reference)")
    for workers in counts:
        if workers == 1:
            continue  # the serial row above is the one-worker campaign
        seconds, metrics, retried = _figures(scenario, runs, workers)
        speedup = serial_s / seconds
        same = "identical" if metrics == serial else f"DIFFER: {metrics} vs {serial}"
        print(f"{workers:8d} {seconds:9.2f} {speedup:9.2f} {speedup / workers:11.2f} {retried:8d}  {same}")


if __name__ == "__main__":
    main()
