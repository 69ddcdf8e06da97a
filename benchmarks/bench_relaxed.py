"""The q-relaxed intersection on real logs: containment, median area and update time per (q, N).

Calibrates on MRCLAM Dataset 6 robot 1 (``aura-ums calibrate``), then replays Dataset 6
robot 2 and Dataset 7 robots 1-5, Class I and II, once per (q, N) given, through the
``aura-ums`` command of this environment, and prints one Markdown row per run and a
summary per (q, N, class): the lowest containment, the median of the median areas and of
the median update times over the six held-out robots.

    .venv/bin/python benchmarks/bench_relaxed.py /tmp/relaxed 0:1 1:5 1:10 2:5
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"
CALIBRATION = ("mrclam6", 1)
HELD_OUT = [("mrclam6", 2)] + [("mrclam7", robot) for robot in range(1, 6)]


def _run(*args: str | Path) -> None:
    cli = str(Path(sys.executable).with_name("aura-ums"))
    done = subprocess.run([cli, *map(str, args)], capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise SystemExit(f"aura-ums {' '.join(map(str, args))} exited {done.returncode}:\n{done.stderr}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="folder for the logs, calibration and metrics")
    parser.add_argument("configs", nargs="+", help="q:N pairs, e.g. 0:1 1:10")
    args = parser.parse_args()
    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)
    if not DATA.is_dir():
        raise SystemExit(f"no data at {DATA}")
    logs = {}
    for dataset, robot in [CALIBRATION, *HELD_OUT]:
        folder = out / f"{dataset}-r{robot}"
        if not folder.is_dir():
            _run("import", "mrclam", DATA / dataset, "--robot", str(robot), folder)
        logs[(dataset, robot)] = folder
    terrain = out / "cal" / "terrain.toml"
    if not terrain.is_file():
        _run("calibrate", logs[CALIBRATION], "--out", terrain)
    sensors = terrain.with_suffix(".sensors.toml")
    print("| q | N | log | class | containment | median area m² | median µs/frame | excluded |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    summary: dict[tuple[int, int, str], list[dict[str, float]]] = {}
    for config in args.configs:
        q, window = (int(part) for part in config.split(":"))
        for classes in ("I", "II"):
            for dataset, robot in HELD_OUT:
                name = f"{dataset}-r{robot}-{classes}-q{q}-n{window}"
                metrics_path = out / f"{name}.json"
                if not metrics_path.is_file():
                    _run(
                        "replay", logs[(dataset, robot)], "--terrain", terrain, "--sensors", sensors,
                        "--classes", classes, "--relaxed-q", str(q), "--relaxed-window", str(window),
                        "--metrics-json", metrics_path,
                    )  # fmt: skip
                figures = json.loads(metrics_path.read_text())
                summary.setdefault((q, window, classes), []).append(figures)
                print(
                    f"| {q} | {window} | {dataset} r{robot} | {classes} | {figures['containment_rate']:.4f} "
                    f"| {figures['median_area_m2']:.3g} | {figures['median_update_us']:.0f} "
                    f"| {figures['excluded_observations']} |",
                    flush=True,
                )
    print()
    print("| q | N | class | lowest containment | median of median areas m² | median µs/frame |")
    print("| --- | --- | --- | --- | --- | --- |")
    for (q, window, classes), rows in summary.items():
        lowest = min(row["containment_rate"] for row in rows)
        area = statistics.median(row["median_area_m2"] for row in rows)
        speed = statistics.median(row["median_update_us"] for row in rows)
        print(f"| {q} | {window} | {classes} | {lowest:.4f} | {area:.3g} | {speed:.0f} |")


if __name__ == "__main__":
    main()
