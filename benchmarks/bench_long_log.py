"""Replay long odometry logs (10^4, 10^5, 10^6 rows): milliseconds per 1,000 rows and peak memory.

Each log comes from ``benchmarks/make_long_log.py`` (100 Hz odometry and ground truth, a
camera frame every ``--frame-every`` rows), written to a temporary folder; the terrain and
sensor bounds are calibrated on the 10^4-row log. Every replay runs in a fresh process,
which opens the log (``open_log``: read block by block as the replay goes; an older tree
without it: ``load_log``), replays it (``replay_log(keep_maps=False, steps_csv=...)``),
takes the metrics, and reports its wall time, the manager's own update time and its peak
resident memory (the memory map's high-water mark, ``VmHWM``: ``getrusage`` would report
the forked parent's). With ``--src`` the replays import aura_ums from another source tree
(e.g. ``git archive`` of an older commit with the compiled kernel copied in) and run there
as that tree's CLI did: the maps of every step kept, the per-step CSV written at the end. A
tree that refuses a log (more rows than it reads) is reported as failed.

    .venv/bin/python benchmarks/bench_long_log.py
    .venv/bin/python benchmarks/bench_long_log.py --rows 1000000 --frame-every 10 --src /tmp/old/src

Against f47bbb6, the tree issue 19 was filed against (``git archive`` of it, its compiled
kernel built from its own C sources; ``--src``), on the 2-core development machine, quiet
(load average below 0.2, nothing else running), 29 November 2026 about 19:15 UTC: one
replay of each in turn, three of each, the medians; at a frame every row, one of each
(f47bbb6's with a helper's load of about 1.3 beside it). "load" is ``open_log`` (one pass
over ``groundtruth.csv``; the other files are parsed as the replay reads them, so their
parsing is in the total):

===============================  ========  =====================  ======================  =====
10^6 rows                        steps     this tree: load,       f47bbb6: load,          gain
                                           update, total s; peak  update, total s; peak
===============================  ========  =====================  ======================  =====
a frame every 100 rows           9,335     0.10, 0.43, 0.86; 86   5.56, 0.44, 6.94; 746   8.1x
a frame every 10 rows            93,359    0.11, 3.02, 5.24; 91   6.64, 3.73, 19.52; 785  3.7x
a frame every row                932,437   0.11, 31.4, 52.1; 231  14.2, 50.5, 174.8; 2757 3.4x
===============================  ========  =====================  ======================  =====

At the command line (``aura-ums replay LOG --terrain T --metrics-json M --steps-csv S``,
bytecode compiled, the same quiet machine), a frame every 100 rows: 1.16 and 1.22 s and
101 MB against f47bbb6's 7.62 and 7.90 s and 780 MB, 6.5x; the interpreter, numpy, typer
and the library's imports take about 0.2 s of each (``aura-ums --version``: 0.20 s).

An earlier series against 2ee5097, the tree before that day's savings in reading, judging
and posting, measured on the same machine on 29 November about 09:39 UTC, shared
(load average 0.57 to 0.84): this tree and 2ee5097 (``git archive`` of it with this tree's
compiled kernel, built from the same C), one replay of each in turn, three of each, the
medians:

===============================  ========  =====================  =====================  =====
10^6 rows                        steps     this tree: load,       2ee5097: load,         gain
                                           update, total s; peak  update, total s; peak
===============================  ========  =====================  =====================  =====
a frame every 100 rows           9,335     0.19, 0.57, 1.28; 84   0.21, 0.58, 1.46; 83   1.14x
a frame every 10 rows            93,359    0.19, 4.11, 7.38; 89   0.20, 4.14, 7.66; 87   1.04x
===============================  ========  =====================  =====================  =====

How to read it:

- Times move by up to 2x with the machine's load (another process's, on these 2 cores):
  compare trees only within one series. Under a load of about 1, earlier series in this
  file's history measured 7.5x, 3.7x and 3.2x against f47bbb6.
- The gain depends on the log's shape. These savings are in reading the log (the ground
  truth's and odometry's blocks, the observations' text), cutting the odometry into
  reports, judging the truth and posting; the manager's update is as it was, so the more
  frames a log has per odometry row, the smaller the gain.
- The peak no longer holds the log. What still grows with the log (about 17 MB per 10^6
  rows) is the replay's record, the trace (84 bytes a step), and the allocator's heap
  around it.
- At a frame every 10 rows the update is about 32 us a step, most of it Python around the
  compiled kernels. At a frame every 100 rows the compiled growth alone (about 8 commands
  a step, twice: the working map and the envelope; 1.5 us a command) takes 0.22 s of the
  0.86: with the update (0.43 s), opening the log (0.10 s) and reading the odometry, it
  leaves no room under the 0.69 s that tenfold against f47bbb6 would allow. Growing a
  step's commands in one Minkowski sum (its sectors summed, then one vertex cap) would be
  cheaper, but on MRCLAM it gave larger maps, not smaller (median Class I area 17.70 m^2
  against 17.42 on Dataset 6 robot 2): one cap from many vertices cuts more than a cap
  per command.
- At a frame every row every step costs: 56 us a step in all, 34 of them the manager's
  update and 22 the rest of the replay (posting, judging, the trace and the CSV). Tenfold
  at this shape would need 19 us a step in all, so not only the update but the replay's
  whole step loop compiled.

Earlier series (27 and 28 November, before the compiled CSV reader and the per-step
trimming) are in the repository's history of this file.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def _peak_mb() -> float:
    """This process's peak resident memory, MB: the memory map's high-water mark.

    Not ``getrusage``: its ``ru_maxrss`` keeps, across ``exec``, the peak of the forked
    copy of the parent (which holds the generated log), and would report that instead.
    """
    try:
        with open("/proc/self/status") as status:
            for line in status:
                if line.startswith("VmHWM:"):
                    return float(line.split()[1]) / 1024.0
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _child(folder: str, terrain: str, sensors: str, out: str) -> None:
    """Replay one log in this process and print its figures as JSON."""
    import inspect

    import aura_ums.logs
    from aura_ums.logs import ReplayOptions, load_log, load_sensors, replay_log
    from aura_ums.uncertainty import LandmarkClass, TerrainTable

    began = time.perf_counter()
    # A tree that streams the log opens it (its files read as the replay goes); older ones load it.
    log = aura_ums.logs.open_log(folder) if hasattr(aura_ums.logs, "open_log") else load_log(folder)
    loaded = time.perf_counter()
    load_peak_mb = _peak_mb()
    table = TerrainTable.from_toml(terrain)
    motion, working, envelope = load_sensors(sensors)
    options = ReplayOptions(
        landmark_class=LandmarkClass.POINT, motion=motion, working=working, envelope=envelope
    )
    csv_path = Path(out) / "steps.csv"
    if "steps_csv" in inspect.signature(replay_log).parameters:
        result = replay_log(log, table, options, keep_maps=False, steps_csv=csv_path)
        update_us = float(result.trace.update_us.sum())
    else:  # an older tree: its CLI kept every step's map and wrote the CSV at the end
        result = replay_log(log, table, options)
        lines = ["time,inside,area_m2,wedge_width_rad,accepted,rejected,update_us,state,relocalized"]
        for s in result.steps:
            inside = "" if s.inside is None else str(int(s.inside))
            lines.append(
                f"{s.time!r},{inside},{s.map.area!r},{s.map.wedge.width!r},{s.accepted},{s.rejected},"
                f"{s.update_us:.3f},{s.state.value},{int(s.relocalized)}"
            )
        csv_path.write_text("\n".join(lines) + "\n")
        update_us = sum(s.update_us for s in result.steps)
    metrics = result.metrics()
    done = time.perf_counter()
    peak_mb = _peak_mb()
    figures = {
        "load_s": loaded - began,
        "total_s": done - began,
        "update_s": update_us / 1e6,
        "steps": metrics["steps"],
        "containment_rate": metrics["containment_rate"],
        "peak_mb": peak_mb,
        "load_peak_mb": load_peak_mb,
    }
    print(json.dumps(figures))


def _older_inputs(folder: Path, sensors: Path) -> Path:
    """Make the log and sensors file readable by a tree older than the sensor offset and the noise table.

    The log's ``[sensor] forward`` and ``left`` are 0.0 (the default those trees assumed), a
    replay does not read the sensors file's ``[noise]`` (compare does), and its ``growth = "move"``
    names the growth those trees had: all three are dropped.
    """
    meta = folder / "meta.toml"
    kept = [line for line in meta.read_text().splitlines() if line not in ("forward = 0.0", "left = 0.0")]
    meta.write_text("\n".join(kept) + "\n")
    older = sensors.with_name("older.sensors.toml")
    text = re.sub(r"\n\[noise\]\n(?:[^\[\n].*\n?|\n)*", "\n", sensors.read_text())
    older.write_text(text.replace('\ngrowth = "move"\n', "\n"))
    return older


def _replay(src: str | None, folder: Path, terrain: Path, sensors: Path, out: Path) -> dict[str, float]:
    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = src
    command = [sys.executable, __file__, "--child", str(folder), str(terrain), str(sensors), str(out)]
    done = subprocess.run(command, capture_output=True, text=True, env=env, check=True)
    figures: dict[str, float] = json.loads(done.stdout.strip().splitlines()[-1])
    return figures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--rows", type=int, nargs="+", default=[10_000, 100_000, 1_000_000])
    parser.add_argument("--frame-every", type=int, default=10, help="odometry rows per camera frame")
    parser.add_argument("--src", help="source tree to import aura_ums from (default: this environment's)")
    parser.add_argument("--child", nargs=4, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        _child(*args.child)
        return
    sys.path.insert(0, str(HERE))
    from aura_ums.logs import calibrate_logs, load_log
    from make_long_log import make_long_log

    with tempfile.TemporaryDirectory() as scratch:
        work = Path(scratch)
        calibration = calibrate_logs([load_log(make_long_log(work / "calibration", 10_000))])
        terrain, sensors = work / "terrain.toml", work / "terrain.sensors.toml"
        terrain.write_text(calibration.terrain_table().to_toml())
        sensors.write_text(calibration.sensors_toml())
        print(f"{'rows':>9} {'steps':>7} {'load s':>7} {'update s':>9} {'total s':>8} "
              f"{'ms/1000 rows':>13} {'load peak MB':>13} {'peak MB':>8} {'containment':>11}")  # fmt: skip
        for rows in args.rows:
            folder = make_long_log(work / f"log-{rows}", rows, frame_every=args.frame_every)
            read_by = sensors if args.src is None else _older_inputs(folder, sensors)
            out = work / f"out-{rows}"
            out.mkdir()
            try:
                figures = _replay(args.src, folder, terrain, read_by, out)
                print(
                    f"{rows:>9} {figures['steps']:>7} {figures['load_s']:>7.2f} {figures['update_s']:>9.2f} "
                    f"{figures['total_s']:>8.2f} {1e6 * figures['total_s'] / rows:>13.2f} "
                    f"{figures['load_peak_mb']:>13.0f} {figures['peak_mb']:>8.0f} "
                    f"{figures['containment_rate']:>11.4f}",
                    flush=True,
                )
            except subprocess.CalledProcessError as failed:  # e.g. an older tree refusing > 2e6 rows
                reason = failed.stderr.strip().splitlines()[-1] if failed.stderr.strip() else "failed"
                print(f"{rows:>9} failed: {reason}", flush=True)
            for path in (*folder.iterdir(), *out.iterdir()):
                path.unlink()
            if read_by != sensors:
                read_by.unlink()


if __name__ == "__main__":
    main()
