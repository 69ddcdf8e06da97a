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
    .venv/bin/python benchmarks/bench_long_log.py --rows 100000 1000000 3000000 --src /tmp/main-src/src

Measured on the 2-core development machine with nothing else running (load average below
1), 27 November 2026, a camera frame every 10 rows, the three trees one after the other
(``--rows 100000 1000000 3000000``, then ``--src`` of each older tree); "load" is
``open_log`` for this branch (a pass over ``groundtruth.csv``; the other files are read
during the replay, so their parsing is in "rest"), ``load_log`` for the others:

==========  ======================  ======================  ======================  ==========
rows        f47bbb6 (issue 19):     main (2c3b04f):         streamed:               vs f47bbb6
            load, update, total s;  load, update, total s;  load, update, total s;
            peak MB                 peak MB                 peak MB
==========  ======================  ======================  ======================  ==========
10^5        1.35, 1.09, 5.59; 144   0.53, 1.13, 2.58; 120   0.13, 0.79, 1.54; 99    3.6x
10^6        17.46, 15.07, 73.08;    4.32, 14.94, 29.51;     1.29, 9.99, 19.06;      3.8x
            784                     286                     132
3 x 10^6    refused (odometry.csv   refused (over           4.23, 34.85, 65.14;
            over 64 MiB)            2,000,000 rows)         203
==========  ======================  ======================  ======================  ==========

The manager's update time varies by up to 1.7x from run to run with the same code (the
garbage collector's passes over a smaller heap are cheaper: switching it off saved a
further 10% in one run); compare the load and the rest. Earlier, on the same machine
shared with other jobs (load 2 to 3):
Two paired runs at 10^6 on one log (``--child``, branch then main, twice, 17:56-18:00 UTC):
load 2.38 / 2.65 s against 5.94 / 6.28 s (2.4x faster), rest 16.4 / 18.1 s against
17.1 / 17.7 s (the same: the judge's and the reports' savings pay for parsing odometry and
observations during the replay), peak 137 / 136 MB against 291 / 297 MB. The peak no
longer holds the log (its columns, its observation objects, its frames): it is 104, 137
and 202 MB for 10^5, 10^6 and 3 x 10^6 rows, and what still grows (33 MB per 10^6 rows)
is the replay's record: the trace (84 bytes a step) and the manager's blackboard, which
keeps every position report (about 290 bytes each). Parsing (numpy's ``loadtxt``, about
1.6 us a row) is now most of the rest at 10^6 rows: the odometry once, the ground truth
once (kept checked in a scratch file), the observations.

Since the blackboard forgets the reports its manager consumed (all but the last), the
peak is 99, 115 and 150 MB for 10^5, 10^6 and 3 x 10^6 rows (27 November, about 20:50 UTC, with
the test suite running beside it: its times are not comparable). With scipy and networkx
no longer imported by the replay too (45962a6, 21:37 UTC, load 0.9 to 1.7), it is 70, 86
and 121 MB; load / update / total 1.61 / 13.46 / 26.15 s at 10^6 rows and 4.61 / 35.22 /
69.61 s at 3 x 10^6 (the update time within the run-to-run spread above). At the end of a replay
only the trace is left of the log (``tracemalloc``: 1.57 MB for 18,679 steps, 84 bytes a
step); the peak still rises by about 17 MB per 10^6 rows, twice the trace's 8 MB. Not
from joining the trace's chunks at the end: joining them column by column, each chunk's
column let go once joined, left the peak at 87 and 119 MB (tried, not kept). The peak is
reached inside the loop, before that join (10^6 rows: VmHWM 88.0 MB before it, RSS 82.3
then 86.3 MB after). Between the 30th and the 90th chunk of 1,024 steps the resident memory
grows by about 130 bytes a step, while ``tracemalloc`` sees only the trace's chunks grow
(84 bytes a step, every other allocation flat): the rest is outside Python's allocations,
most likely the allocator's heap around the trace's 8 KB chunk columns, which sit among the
replay's short-lived arrays. One array per column that grows by doubling (large allocations,
returned to the system when replaced) would leave the trace's 84 bytes; not tried.

The gain depends on the log's shape: how many odometry rows fall between camera frames.
Reading the log and recording the steps gained the most; the manager's update per step (one
a frame) the least (15.07 against 9.99 s above, 1.5x), so the more frames a log has, the
smaller the gain. Two series of back-to-back runs, total seconds:

==============================  =======  ================  ================  =================
log                             steps    f47bbb6 / this    f47bbb6 / this    gain, 27 / 28 Nov
                                         tree, 27 Nov      tree, 28 Nov
==============================  =======  ================  ================  =================
10^6 rows, a frame every 100    9,335    80.04 / 15.40     30.69 / 8.38      5.2x / 3.7x
10^6 rows, a frame every 10     93,359   73.08 / 19.06     72.10 / 37.25     3.8x / 1.9x
10^5 rows, a frame every row    93,487   228.99 / 76.57    85.26 / 30.73     3.0x / 2.8x
==============================  =======  ================  ================  =================

The 27 November series ran about 22:35-22:45 UTC, on the machine shared with a CLI sweep
and a real-log benchmark (load average 3.5 to 5). Its frame-every-10 row was measured idle
(above). The 28 November series ran 01:03-01:10 UTC beside one test-running helper (load
average 2.5 to 3.2). Load alone moves the gain by up to 2x: at one frame every 100 rows,
the older tree took 18.10 s idle (00:56 UTC, against 4.95 s for this tree, 3.7x) and
80.04 s at load 3.5 to 5, while this tree's time varied less; the older tree holds the whole log
in memory (750 to 810 MB against 50 to 110 MB). The
command line as a user runs it, on the 10^6-row log with a frame every 10 rows, Class I (the
CLI's default), the steps CSV and metrics JSON written (``/usr/bin/time``, 28 November
01:50 UTC, load average 2): f47bbb6 61.75 s and 811 MB peak, this tree 24.40 s and 106 MB
peak, 2.5x. The issue's tenfold gain is not reached in any of these runs.

With the numeric rows read by a compiled kernel (``csv.c``, ``parse_float_rows``; numpy's
``loadtxt`` is its reference), 28 November 2026 about 21:10 UTC, idle machine, this tree
then f47bbb6 (``--src``) one after the other:

===============================  ========  =====================  =====================  =====
10^6 rows                        steps     this tree: load,       f47bbb6: load,         gain
                                           update, total s; peak  update, total s; peak
===============================  ========  =====================  =====================  =====
a frame every 100 rows           9,335     0.81, 0.71, 2.69; 80   8.78, 0.85, 11.53; 754 4.3x
a frame every 10 rows            93,359    0.57, 4.94, 10.38; 87  9.34, 5.30, 28.93; 781 2.8x
===============================  ========  =====================  =====================  =====

The command line as a user runs it (``/usr/bin/time``, ``replay LOG --terrain ... --steps-csv
... --metrics-json ...``, Class I), alternating the trees twice: a frame every 100 rows 3.41 and
2.61 s against 13.60 and 11.14 s (4.0x, 4.3x), every 10 rows 11.25 and 11.90 s against 33.76
and 29.74 s (3.0x, 2.5x); peak 99-107 MB against 770-812 MB. Where a frame every 10 rows
spends its time now (py-spy): the manager's update 47% (its compiled kernels about a third
of that), the judge 21% (the area of each step's two maps, ``polygon_area``, 10%), reading the
files 16%. Tenfold needs the update's Python (about 50 us a step around 15 us of kernels)
compiled too.

With the CSV kernel's exact fast path (Clinger: 742a91e; the ground truth's 4e6 cells in 0.14
instead of 0.48 s) and numeric blocks parsed as bytes (b1c7186), 29 November 2026 about 00:45
UTC, idle machine (load average below 1), this tree then f47bbb6 (``--src``):

===============================  ========  =====================  =====================  =====
10^6 rows                        steps     this tree: load,       f47bbb6: load,         gain
                                           update, total s; peak  update, total s; peak
===============================  ========  =====================  =====================  =====
a frame every 100 rows           9,335     0.31, 0.60, 1.62; 81   8.77, 0.63, 10.86; 755 6.7x
a frame every 10 rows            93,359    0.29, 5.00, 9.62; 88   9.63, 5.95, 31.75; 781 3.3x
===============================  ========  =====================  =====================  =====

At a frame every 10 rows the manager's update alone (5.0 s, 54 us a step) is half of this
tree's time, and is as long as the older tree's: tenfold (3.2 s) cannot be reached without
compiling the update's Python. Runs beside a fuzzing helper (load 1 to 4) gave 1.74 to 2.34 s
for a frame every 100 rows and 9.70 to 11.21 s for every 10.

(``--rows 1000000 --frame-every 100`` and ``--rows 100000 --frame-every 1``, each then with
``--src`` of f47bbb6.) The manager's update, about 100 us a step on an idle machine, two
maps a step, is most of the time once frames are frequent; its compiled kernels take
about a third of it (cProfile, 10^6 rows, a frame every 10), the Python around them the rest.

With the per-step Python trimmed (fewer objects and numpy calls per step in the manager,
the maps and the judge; 3654d2c) and the numeric CSV blocks checked by ``bytes`` methods
(ab73aa2), 29 November 2026 about 03:32 UTC, idle machine (load average below 1.0), this
tree, f47bbb6, this tree again:

===============================  ========  =====================  =====================  =====
10^6 rows                        steps     this tree: load,       f47bbb6: load,         gain
                                           update, total s; peak  update, total s; peak
===============================  ========  =====================  =====================  =====
a frame every 100 rows           9,335     0.20, 0.54, 1.28; 80   7.61, 0.62, 9.66; 746  7.5x
a frame every 10 rows            93,359    0.21, 4.11, 7.70; 86   9.11, 5.26, 28.72; 784 3.7x
===============================  ========  =====================  =====================  =====

The update is now about 44 us a step at a frame every 10 rows, of which the compiled
kernels take about 11 us; the rest is Python around them (about 3.5 us around each
growth, 3 us around each reduction, 6 us of bookkeeping an update). At a frame every 100
rows the update (0.54 s), reading the odometry (about 0.29 s) and opening the log (0.20 s)
already pass the 0.97 s that tenfold allows: the issue's target needs the update compiled,
not more small savings.
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

    The log's ``[sensor] forward`` and ``left`` are 0.0 (the default those trees assumed) and
    a replay does not read the sensors file's ``[noise]`` (compare does): both are dropped.
    """
    meta = folder / "meta.toml"
    kept = [line for line in meta.read_text().splitlines() if line not in ("forward = 0.0", "left = 0.0")]
    meta.write_text("\n".join(kept) + "\n")
    older = sensors.with_name("older.sensors.toml")
    older.write_text(re.sub(r"\n\[noise\]\n(?:[^\[\n].*\n?|\n)*", "\n", sensors.read_text()))
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
