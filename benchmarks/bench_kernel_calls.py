"""The compiled kernels inside real replays: their share of each frame, and one build against another.

Calibrated on MRCLAM Dataset 6 robot 1, each chosen log is replayed (Class I and Class II,
the sliced map by default) with every compiled kernel timed where the library calls it.
Per log and class it prints the median µs per frame of the whole update, the median µs per
frame spent in the kernels, and each kernel's mean µs per frame: what a faster Python layer
could win at most, and which kernel to make faster.

With ``--against OLD.so`` (the extension module of another build, e.g. copied from a
checkout of an older commit after ``make``) it also records a sample of each kernel's calls
from those replays and times the two builds on the very same calls, alternating them over
``--rounds`` rounds in one process: on a shared machine whose speed drifts by tens of per cent
from one minute to the next, the ratio of two interleaved timings is what stays put.

    .venv/bin/python benchmarks/bench_kernel_calls.py [--logs mrclam6:2,mrclam7:2] \
        [--slice-width 2] [--against /tmp/old/_kernels.cpython-311-x86_64-linux-gnu.so]

``--slice-width 0`` replays the product map.

Measured 28 November 2026 (2-degree cells; Dataset 6 robot 2, Dataset 7 robots 2 and 5; the
shared 2-core machine, whose speed drifted by up to 1.7x within the hour): the kernels took
167-250 µs of a 316-518 µs median frame in Class II and 327-391 µs of 538-665 in Class I,
``distribute_slices`` more than half of it, then ``grow_slices`` and ``reduce_cone_slices``.
Even with no Python between the kernels, the sliced map would not meet 200 µs per frame.
``--against`` the build before cfca1c5 (each call allocated its own buffers, which grew to
the exact size at every append): ``distribute_slices`` 0.68x, ``grow_slices`` 0.66x,
``reduce_cone_slices`` 0.79x, ``reduce_cone`` 0.84x, ``merge_groups`` 0.87x; against the
build between cfca1c5 and 1b496f1: ``distribute_slices`` 0.73x, ``grow_slices`` 0.86x,
``reduce_cone_slices`` 0.84x.
"""

from __future__ import annotations

import argparse
import collections
import importlib.util
import math
import random
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Any

import aura_ums._native._kernels as kernels
from aura_ums.logs import calibrate_logs, read_mrclam, replay_log
from aura_ums.manager import ManagerSettings, UncertaintyMapManager
from aura_ums.uncertainty import LandmarkClass
from bench_real_logs import replay_options

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
SAMPLE = 300  # calls of each kernel kept for --against: a uniform sample of all its calls
NAMES = sorted(name for name in dir(kernels) if callable(getattr(kernels, name)) and not name.startswith("_"))


def _call_sites() -> list[tuple[ModuleType, str, str]]:
    """Every module attribute of aura_ums that is a compiled kernel: (module, attribute, kernel)."""
    found = []
    by_id = {id(getattr(kernels, name)): name for name in NAMES}
    for module_name, module in list(sys.modules.items()):
        if not module_name.startswith("aura_ums") or module is kernels:
            continue
        for attribute, value in list(vars(module).items()):
            if id(value) in by_id:
                found.append((module, attribute, by_id[id(value)]))
    return found


class _Timed:
    """Kernels wrapped at their call sites: time per update, and a sample of their arguments."""

    def __init__(self) -> None:
        self.spent: collections.defaultdict[str, float] = collections.defaultdict(float)
        self.calls: collections.Counter[str] = collections.Counter()
        self.sample: dict[str, list[tuple[Any, ...]]] = collections.defaultdict(list)
        self.frames: list[tuple[float, float, dict[str, float]]] = []

    def wrap(self, name: str, kernel: Callable[..., Any]) -> Callable[..., Any]:
        clock, spent, calls, sample = time.perf_counter, self.spent, self.calls, self.sample[name]
        draw = random.Random(name).randrange

        def timed(*args: Any) -> Any:
            calls[name] += 1
            # Reservoir sampling: every call so far equally likely to be kept.
            if len(sample) < SAMPLE:
                sample.append(args)
            elif (slot := draw(calls[name])) < SAMPLE:
                sample[slot] = args
            began = clock()
            try:
                return kernel(*args)
            finally:
                spent[name] += clock() - began

        return timed

    def install(self) -> None:
        wrapped: dict[str, Callable[..., Any]] = {}
        for module, attribute, name in _call_sites():
            wrapped.setdefault(name, self.wrap(name, getattr(kernels, name)))
            setattr(module, attribute, wrapped[name])
        update = UncertaintyMapManager.update

        def timed_update(manager: UncertaintyMapManager, *args: Any, **kwargs: Any) -> Any:
            self.spent.clear()
            began = time.perf_counter()
            try:
                return update(manager, *args, **kwargs)
            finally:
                total = time.perf_counter() - began
                self.frames.append((total, sum(self.spent.values()), dict(self.spent)))

        UncertaintyMapManager.update = timed_update  # type: ignore[method-assign,assignment]


def _load(path: str) -> ModuleType:
    """The extension module at ``path`` under another name (its init function is the same)."""
    spec = importlib.util.spec_from_file_location("other_build._kernels", path)
    if spec is None or spec.loader is None:
        raise SystemExit(f"--against: expected a compiled extension module, got {path!r}")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _against(other: ModuleType, sample: dict[str, list[tuple[Any, ...]]], rounds: int) -> None:
    print(f"\n{'kernel':20s} {'calls':>5s} {'other µs':>9s} {'this µs':>8s} {'this/other':>10s}")
    for name, calls in sorted(sample.items()):
        if not calls:
            continue
        times: dict[str, list[float]] = {"other": [], "this": []}
        for round_ in range(rounds):
            order = [("other", getattr(other, name)), ("this", getattr(kernels, name))]
            for label, kernel in order if round_ % 2 == 0 else order[::-1]:
                began = time.perf_counter()
                for _ in range(3):
                    for args in calls:
                        kernel(*args)
                times[label].append((time.perf_counter() - began) / (3 * len(calls)))
        before, after = statistics.median(times["other"]), statistics.median(times["this"])
        print(f"{name:20s} {len(calls):5d} {1e6 * before:9.2f} {1e6 * after:8.2f} {after / before:10.3f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--logs", default="mrclam6:2,mrclam7:2,mrclam7:5", help="dataset:robot pairs")
    parser.add_argument("--slice-width", type=float, default=2.0, help="degrees; 0 for the product map")
    parser.add_argument("--against", help="another build's extension module (.so): time the same calls")
    parser.add_argument("--rounds", type=int, default=11, help="alternations of the two builds")
    args = parser.parse_args()
    if not DATA.is_dir():
        print(f"development data not found at {DATA}: nothing to measure")
        return
    other = _load(args.against) if args.against else None
    timed = _Timed()
    timed.install()
    calibration = calibrate_logs([read_mrclam(DATA / "mrclam6", 1)])
    table = calibration.terrain_table()
    width = math.radians(args.slice_width) if args.slice_width > 0 else None
    settings = ManagerSettings(slice_width=width)
    print(f"{'log':10s} {'class':5s} {'frame µs':>8s} {'kernels µs':>10s}  mean µs per frame in each kernel")
    for item in args.logs.split(","):
        name, robot = item.split(":")
        log = read_mrclam(DATA / name, int(robot))
        for landmark_class in (LandmarkClass.VERTICAL_LINE, LandmarkClass.POINT):
            timed.frames.clear()
            replay_log(log, table, replay_options(calibration, landmark_class, settings), keep_maps=False)
            totals = [frame[0] for frame in timed.frames]
            inside = [frame[1] for frame in timed.frames]
            by_kernel: collections.defaultdict[str, float] = collections.defaultdict(float)
            for _, _, per_kernel in timed.frames:
                for kernel, seconds in per_kernel.items():
                    by_kernel[kernel] += seconds
            count = len(timed.frames)
            ranked = sorted(by_kernel.items(), key=lambda item: -item[1])
            shares = ", ".join(f"{kernel} {1e6 * seconds / count:.0f}" for kernel, seconds in ranked)
            print(
                f"{item:10s} {landmark_class.value:5s} {1e6 * statistics.median(totals):8.0f} "
                f"{1e6 * statistics.median(inside):10.0f}  {shares}",
                flush=True,
            )
    if other is not None:
        _against(other, timed.sample, args.rounds)


if __name__ == "__main__":
    main()
