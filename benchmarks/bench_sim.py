"""Benchmark the synthetic camera: median milliseconds to render a 512 x 480 paper frame.

Run: ``.venv/bin/python benchmarks/bench_sim.py [repeats]``.

The scene is the paper's sidewalk (``scenarios/paper_sidewalk.toml``: its camera, ground
texture, 40 clutter strips, poles, building, painted edges, sensor noise), rendered from
poses along the walk. Target: at most 5 ms per frame. Speed depends on the machine and
its load; nothing here is asserted.
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import numpy as np

from aura_ums.sim import Scenario
from aura_ums.uncertainty import Pose

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "paper_sidewalk.toml"
TARGET_MS = 5.0


def main() -> None:
    repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 200
    scenario = Scenario.from_toml(SCENARIO)
    camera = scenario.synthetic_camera(np.random.default_rng(0))
    k = scenario.camera.intrinsics
    poses = [Pose(x, 0.05 * np.sin(x), 0.02 * np.cos(x)) for x in np.linspace(0.0, 12.2, 16)]
    for pose in poses:
        camera.render(pose)
    times = []
    for i in range(repeats):
        pose = poses[i % len(poses)]
        start = time.perf_counter()
        camera.render(pose)
        times.append(time.perf_counter() - start)
    median = 1e3 * statistics.median(times)
    verdict = "within" if median <= TARGET_MS else "over"
    print(
        f"render {k.width} x {k.height}, paper sidewalk scene: median {median:.2f} ms over {repeats} frames"
    )
    print(f"target {TARGET_MS:.1f} ms: {verdict}")


if __name__ == "__main__":
    main()
