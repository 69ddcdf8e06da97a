"""Benchmark the closed loop: median milliseconds per frame, windows vs full-frame perception.

Run: ``.venv/bin/python benchmarks/bench_loop.py [runs]``.

The paper's sidewalk (``scenarios/paper_sidewalk.toml``: 512 x 480 frames, three Class I
landmarks active) driven through :func:`aura_ums.sim.run_scenario`; a frame's time covers
the map manager's growth, the schemas (Expecter windows, line finder, evaluation,
observation) and the reductions, not the synthetic rendering. Only frames in which all
three landmarks were searched count. The same seeded runs are timed with perception in
the Expecter's windows and on the full frame, interleaved seed by seed (windows, then
full frame) so that a change in the machine's load weighs on both alike. Targets: <= 10
ms per frame and >= 5x faster than full frame. Speed depends on the machine and its
load; nothing is asserted.
"""

from __future__ import annotations

import statistics
import sys
from pathlib import Path

import numpy as np

from aura_ums.sim import PerceptionMode, Scenario, run_scenario

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "paper_sidewalk.toml"
TARGET_MS = 10.0
TARGET_RATIO = 5.0


MODES = (PerceptionMode.WINDOWS, PerceptionMode.FULL_FRAME)


def frame_times(scenario: Scenario, runs: int) -> dict[PerceptionMode, list[float]]:
    """Milliseconds of the frames with three landmarks searched, per mode, over ``runs`` seeded runs."""
    times: dict[PerceptionMode, list[float]] = {mode: [] for mode in MODES}
    for seed in range(runs):
        for mode in MODES:
            result = run_scenario(scenario, np.random.default_rng(seed), perception=mode)
            times[mode].extend(r.frame_ms for r in result.records if len(r.windows) >= 3)
    return times


def main() -> None:
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 30
    scenario = Scenario.from_toml(SCENARIO)
    frame_times(scenario, 2)  # warm up
    times = frame_times(scenario, runs)
    windows = statistics.median(times[PerceptionMode.WINDOWS])
    full = statistics.median(times[PerceptionMode.FULL_FRAME])
    k = scenario.camera.intrinsics
    print(f"closed loop, {k.width}x{k.height}, three active landmarks, {runs} runs")
    print(f"{'perception':<12} {'median ms/frame':>16}")
    print(f"{'windows':<12} {windows:>16.2f}   (target <= {TARGET_MS:g})")
    print(f"{'full frame':<12} {full:>16.2f}")
    print(f"{'speed-up':<12} {full / windows:>16.1f}x  (target >= {TARGET_RATIO:g}x)")


if __name__ == "__main__":
    main()
