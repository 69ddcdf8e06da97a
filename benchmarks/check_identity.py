"""Record, then check, that a change leaves replays and simulations bit-identical.

Runs the ``aura-ums`` command of this environment over the real logs in the data folder
beside the clone (docs/getting-real-data.md; MRCLAM Dataset 6 robots 1-2 and Dataset 7
robots 1-5, Class I and II, all calibrated on Dataset 6 robot 1) and over
``scenarios/paper_sidewalk.toml`` (20 runs, seed 1), and keeps every metrics JSON and per-step
CSV. Timings (``update_us``, ``median_update_us``, ``median_frame_ms``: any key ending in
``_us`` or ``_ms``) are dropped; ``NaN`` and ``null`` are the same undefined value. Everything
else must match to the last digit, or, with ``--rtol``, within that relative tolerance (for
the numpy reference against the C kernels: ``AURA_UMS_NATIVE=0``).

    .venv/bin/python benchmarks/check_identity.py record /tmp/identity-before
    .venv/bin/python benchmarks/check_identity.py check /tmp/identity-before
    AURA_UMS_NATIVE=0 .venv/bin/python benchmarks/check_identity.py check /tmp/identity-before --rtol 1e-9
    .venv/bin/python benchmarks/check_identity.py check /tmp/identity-before --sim-args="--gate-only"
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"
LOGS = [("mrclam6", 1), ("mrclam6", 2)] + [("mrclam7", robot) for robot in range(1, 6)]
CLASSES = ("I", "II")
SCENARIO = ROOT / "scenarios" / "paper_sidewalk.toml"


def _cli() -> str:
    return str(Path(sys.executable).with_name("aura-ums"))


def _run(*args: str | Path) -> None:
    done = subprocess.run([_cli(), *map(str, args)], capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise SystemExit(f"aura-ums {' '.join(map(str, args))} exited {done.returncode}:\n{done.stderr}")


def produce(out: Path, extra: list[str], sim_extra: list[str]) -> list[str]:
    """Run every replay and the simulation into ``out``; return the files written."""
    out.mkdir(parents=True, exist_ok=True)
    names: list[str] = []
    with tempfile.TemporaryDirectory() as scratch:
        work = Path(scratch)
        if DATA.is_dir():
            logs = {}
            for dataset, robot in LOGS:
                folder = work / f"{dataset}-r{robot}"
                _run("import", "mrclam", DATA / dataset, "--robot", str(robot), folder)
                logs[(dataset, robot)] = folder
            terrain = work / "cal" / "terrain.toml"
            _run("calibrate", logs[LOGS[0]], "--out", terrain)
            sensors = terrain.with_suffix(".sensors.toml")
            for (dataset, robot), folder in logs.items():
                for classes in CLASSES:
                    name = f"{dataset}-r{robot}-{classes}"
                    _run(
                        "replay", folder, "--terrain", terrain, "--sensors", sensors, "--classes", classes,
                        "--metrics-json", out / f"{name}.json", "--steps-csv", out / f"{name}.csv",
                        "--overwrite", *extra,
                    )  # fmt: skip
                    names += [f"{name}.json", f"{name}.csv"]
        else:
            print(f"no data at {DATA}: simulation only")
        _run(
            "simulate",
            SCENARIO,
            "--runs",
            "20",
            "--seed",
            "1",
            "--metrics-json",
            out / "simulate.json",
            "--overwrite",
            *sim_extra,
        )
        names.append("simulate.json")
    return names


def _is_timing(key: str) -> bool:
    return key.endswith(("_us", "_ms"))


def _flatten(value: Any, prefix: str = "") -> Iterator[tuple[str, Any]]:
    if isinstance(value, dict):
        for key, item in value.items():
            if not _is_timing(str(key)):
                yield from _flatten(item, f"{prefix}.{key}" if prefix else str(key))
    elif isinstance(value, list):
        for index, item in enumerate(value):
            yield from _flatten(item, f"{prefix}[{index}]")
    else:
        yield prefix, value


def _load_json(path: Path) -> dict[str, Any]:
    # Older versions wrote NaN; it is the same undefined value as null.
    return dict(_flatten(json.loads(path.read_text(), parse_constant=lambda _: None)))


def _load_csv(path: Path) -> dict[str, Any]:
    with path.open(newline="") as stream:
        rows = list(csv.DictReader(stream))
    return {f"{i}.{k}": v for i, row in enumerate(rows) for k, v in row.items() if not _is_timing(k)}


def _same(a: Any, b: Any, rtol: float) -> bool:
    if a == b:
        return True
    try:
        x, y = float(a), float(b)
    except (TypeError, ValueError):
        return False
    if math.isnan(x) and math.isnan(y):
        return True
    return rtol > 0 and math.isclose(x, y, rel_tol=rtol, abs_tol=rtol)


def compare(before: Path, after: Path, names: list[str], rtol: float) -> int:
    """Print each difference; return how many files differ."""
    differing = 0
    for name in names:
        load = _load_json if name.endswith(".json") else _load_csv
        old, new = load(before / name), load(after / name)
        diffs = [k for k in sorted(old.keys() | new.keys()) if not _same(old.get(k), new.get(k), rtol)]
        if diffs:
            differing += 1
            print(f"DIFFERS {name}: {len(diffs)} values, first: ", end="")
            print("; ".join(f"{k}: {old.get(k)!r} -> {new.get(k)!r}" for k in diffs[:3]))
        else:
            print(f"same    {name}")
    return differing


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("mode", choices=["record", "check"])
    parser.add_argument("folder", type=Path, help="where the reference outputs are (record: written)")
    parser.add_argument("--rtol", type=float, default=0.0, help="relative tolerance (default: exact)")
    parser.add_argument("--sim-args", default="", help="extra arguments for the simulation, one string")
    parser.add_argument("extra", nargs="*", help="extra arguments for every replay (after --)")
    args = parser.parse_args()
    if args.mode == "record":
        if args.folder.exists():
            shutil.rmtree(args.folder)
        names = produce(args.folder, args.extra, args.sim_args.split())
        (args.folder / "index.json").write_text(json.dumps(names))
        print(f"recorded {len(names)} files in {args.folder}")
        return
    names = json.loads((args.folder / "index.json").read_text())
    with tempfile.TemporaryDirectory() as scratch:
        produce(Path(scratch), args.extra, args.sim_args.split())
        differing = compare(args.folder, Path(scratch), names, args.rtol)
    tolerance = f" (rtol {args.rtol})" if args.rtol else ""
    print(f"{len(names) - differing} of {len(names)} files identical{tolerance}")
    sys.exit(1 if differing else 0)


if __name__ == "__main__":
    main()
