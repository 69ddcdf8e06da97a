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

In both modes, schemas whose line finders are equal and search the same window share one
search (:meth:`aura_ums.schemas.Frame.lines`): on the full frame the telephone pole's and
the lamppost's finders are equal, so a frame runs two full-frame searches, not three.

The line finder's own time in each frame is also summed (the benchmark wraps
:meth:`FastLineFinder.find_detailed` with a timer and :meth:`SchemaManager.step`, which
runs once per frame, to close each frame's sum), so the table splits a frame into
perception and the rest (manager, Expecter, evaluation, observations), which is the same
work in both modes and bounds the closed-loop ratio.
"""

from __future__ import annotations

import statistics
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from aura_ums.perception import FastLineFinder
from aura_ums.schemas import SchemaManager
from aura_ums.sim import PerceptionMode, Scenario, run_scenario

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "paper_sidewalk.toml"
TARGET_MS = 10.0
TARGET_RATIO = 5.0

MODES = (PerceptionMode.WINDOWS, PerceptionMode.FULL_FRAME)

_spent: list[float] = []  # line-finder milliseconds of the frame being stepped
_per_frame: list[float] = []  # line-finder milliseconds of each frame stepped so far


def _timed(find: Callable[..., Any]) -> Callable[..., Any]:
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        began = time.perf_counter()
        try:
            return find(*args, **kwargs)
        finally:
            _spent.append(1000.0 * (time.perf_counter() - began))

    return wrapper


def _framed(step: Callable[..., Any]) -> Callable[..., Any]:
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        _spent.clear()
        try:
            return step(*args, **kwargs)
        finally:
            _per_frame.append(sum(_spent))

    return wrapper


@contextmanager
def finder_timed() -> Iterator[list[float]]:
    """Time the line finder while inside: yields each stepped frame's line-finder milliseconds."""
    find, step = FastLineFinder.find_detailed, SchemaManager.step
    FastLineFinder.find_detailed = _timed(find)  # type: ignore[method-assign]
    SchemaManager.step = _framed(step)  # type: ignore[method-assign]
    _per_frame.clear()
    try:
        yield _per_frame
    finally:
        FastLineFinder.find_detailed = find  # type: ignore[method-assign]
        SchemaManager.step = step  # type: ignore[method-assign]


def frame_times(scenario: Scenario, runs: int) -> dict[PerceptionMode, list[tuple[float, float]]]:
    """(frame ms, line-finder ms) of the frames with three landmarks searched, per mode."""
    times: dict[PerceptionMode, list[tuple[float, float]]] = {mode: [] for mode in MODES}
    for seed in range(runs):
        for mode in MODES:
            with finder_timed() as per_frame:
                result = run_scenario(scenario, np.random.default_rng(seed), perception=mode)
            frames = zip(result.records, per_frame, strict=True)
            times[mode].extend((r.frame_ms, p) for r, p in frames if len(r.windows) >= 3)
    return times


def main() -> None:
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 30
    scenario = Scenario.from_toml(SCENARIO)
    frame_times(scenario, 2)  # warm up
    times = frame_times(scenario, runs)
    k = scenario.camera.intrinsics
    print(f"closed loop, {k.width}x{k.height}, three active landmarks, {runs} runs")
    print(f"{'perception':<12} {'median ms/frame':>16} {'line finder ms':>15} {'rest ms':>8}")
    medians = {}
    for mode, label in ((PerceptionMode.WINDOWS, "windows"), (PerceptionMode.FULL_FRAME, "full frame")):
        frame = statistics.median(t for t, _ in times[mode])
        finder = statistics.median(p for _, p in times[mode])
        rest = statistics.median(t - p for t, p in times[mode])
        medians[mode] = (frame, finder)
        print(f"{label:<12} {frame:>16.2f} {finder:>15.2f} {rest:>8.2f}")
    (w_frame, w_find), (f_frame, f_find) = medians[PerceptionMode.WINDOWS], medians[PerceptionMode.FULL_FRAME]
    print(f"windows <= {TARGET_MS:g} ms per frame: {'yes' if w_frame <= TARGET_MS else 'no'}")
    print(f"speed-up, closed-loop frame: {f_frame / w_frame:.1f}x  (target >= {TARGET_RATIO:g}x)")
    print(f"speed-up, line finder alone: {f_find / w_find:.1f}x")


if __name__ == "__main__":
    main()
