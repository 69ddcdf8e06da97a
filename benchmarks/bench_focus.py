"""Focus-first search in the closed loop: the guaranteed windows alone against the focus map's first.

Run: ``.venv/bin/python benchmarks/bench_focus.py [--runs N] [--profile relaxed] [SCENARIO ...]``
(default: ``scenarios/indoor_corridor.toml`` and ``scenarios/four_terrains.toml``, 5 runs).

Each scenario runs with the map profile given (``relaxed`` by default: the focus map is
the relaxed intersection's primary branch, narrower than the map; with another profile the
two modes do the same work) through :func:`aura_ums.sim.run_scenario`, with
:attr:`~aura_ums.sim.PerceptionMode.WINDOWS` (the guaranteed windows) and
:attr:`~aura_ums.sim.PerceptionMode.FOCUS_FIRST` (the focus map's window first, the
guaranteed one where the landmark is not there), interleaved seed by seed so that a change
in the machine's load weighs on both alike. Per mode: the median frame time (ms: the
manager, the schemas and the reductions, not the rendering), the line finder's time summed
over the frames (``benchmarks/bench_loop.py``'s timer), the median width of the windows
the schemas report (pixels: where a match was found, or the last window searched), and
the share of frames whose truth stayed inside. The line finder's time is the one focus-first
search can save; a miss in the focus window costs a second search. Nothing is asserted:
the times depend on the machine and its load.

Measured 28 November 2026 (10 runs, the shared 2-core machine): on the indoor corridor
focus-first took 1.07 times the line finder's time of the guaranteed windows alone (median
window 90.9 against 92.2 pixels: the focus window is hardly narrower there, and each miss in
it costs a second search); on the four terrains 0.86 times (154.3 against 209.4 pixels).
The truth stayed inside every frame in both modes.
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
from pathlib import Path

import numpy as np

from aura_ums.manager import MapProfile
from aura_ums.sim import PerceptionMode, Scenario, run_scenario
from bench_loop import finder_timed

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"
DEFAULTS = (SCENARIOS / "indoor_corridor.toml", SCENARIOS / "four_terrains.toml")
MODES = (PerceptionMode.WINDOWS, PerceptionMode.FOCUS_FIRST)


@dataclasses.dataclass
class Tally:
    """What one mode did over the runs of one scenario."""

    frame_ms: list[float] = dataclasses.field(default_factory=list)
    finder_ms: list[float] = dataclasses.field(default_factory=list)
    widths: list[float] = dataclasses.field(default_factory=list)
    inside: list[bool] = dataclasses.field(default_factory=list)


def measure(scenario: Scenario, runs: int) -> dict[PerceptionMode, Tally]:
    """Run ``scenario`` ``runs`` times per mode, seed by seed, timing the line finder."""
    tallies = {mode: Tally() for mode in MODES}
    for seed in range(runs):
        for mode in MODES:
            with finder_timed() as per_frame:
                result = run_scenario(scenario, np.random.default_rng(seed), perception=mode)
            tally = tallies[mode]
            for record, finder in zip(result.records, per_frame, strict=True):
                tally.frame_ms.append(record.frame_ms)
                tally.finder_ms.append(finder)
                tally.widths += [window.width for _, window in record.windows]
                tally.inside.append(record.inside)
    return tallies


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", nargs="*", type=Path, default=list(DEFAULTS))
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--profile", type=MapProfile, default=MapProfile.RELAXED)
    args = parser.parse_args()
    print(f"profile {args.profile.value}, {args.runs} runs per scenario and mode")
    print(f"{'scenario':<18} {'perception':<12} {'median ms/frame':>15} {'finder ms, all':>15} "
          f"{'median width px':>15} {'truth inside':>12}")  # fmt: skip
    for path in args.scenarios:
        scenario = Scenario.from_toml(path)
        scenario = dataclasses.replace(scenario, settings=args.profile.settings(scenario.settings))
        measure(scenario, 1)  # warm up
        tallies = measure(scenario, args.runs)
        for mode, tally in tallies.items():
            print(
                f"{path.stem:<18} {mode.value:<12} {statistics.median(tally.frame_ms):>15.2f} "
                f"{sum(tally.finder_ms):>15.1f} {statistics.median(tally.widths):>15.1f} "
                f"{float(np.mean(tally.inside)):>12.4f}"
            )
        windows, focus = (sum(tallies[mode].finder_ms) for mode in MODES)
        print(f"{path.stem:<18} line finder time, focus first over windows: {focus / windows:.2f}")


if __name__ == "__main__":
    main()
