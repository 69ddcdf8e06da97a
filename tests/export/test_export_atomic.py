"""An MCAP export killed half-way (SIGKILL) or interrupted leaves the old file or none, never a part.

The kill is deterministic: the exporting process kills itself from its own progress
callback half-way through the steps (no sleep, no race with a timer).
"""

from __future__ import annotations

import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from aura_ums.export import mcap_channels, write_replay_mcap
from aura_ums.logs import replay_log, synthetic_log
from aura_ums.uncertainty import TerrainTable

pytest.importorskip("foxglove")

EXPORT = textwrap.dedent(
    """
    import os, signal, sys
    import numpy as np
    from aura_ums.export import write_replay_mcap
    from aura_ums.logs import replay_log, synthetic_log
    from aura_ums.uncertainty import TerrainTable

    log = synthetic_log(np.random.default_rng(7), duration=60.0)
    replay = replay_log(log, TerrainTable({"floor": TerrainTable.default()["tile"]}))

    def progress(done, total):
        if done == total // 2:
            os.kill(os.getpid(), signal.SIGKILL)

    write_replay_mcap(sys.argv[1], replay, progress=progress)
    """
)


def killed_export(target: Path) -> None:
    done = subprocess.run([sys.executable, "-c", EXPORT, str(target)], capture_output=True, check=False)
    assert done.returncode == -signal.SIGKILL, done.stderr


def scratch_files(folder: Path) -> list[Path]:
    return [p for p in folder.iterdir() if p.name.startswith(".") and p.name.endswith(".tmp")]


def test_a_killed_export_leaves_no_file_under_the_final_name(tmp_path: Path) -> None:
    target = tmp_path / "replay.mcap"
    killed_export(target)
    assert not target.exists()
    (scratch,) = scratch_files(tmp_path)  # the half-written file, under its hidden scratch name only
    assert scratch.stat().st_size > 0


def test_a_killed_export_leaves_the_old_file(tmp_path: Path) -> None:
    target = tmp_path / "replay.mcap"
    target.write_bytes(b"the old export")
    killed_export(target)
    assert target.read_bytes() == b"the old export"


def test_an_interrupted_export_leaves_the_old_file_and_no_scratch(tmp_path: Path) -> None:
    log = synthetic_log(np.random.default_rng(7), duration=20.0)
    replay = replay_log(log, TerrainTable({"floor": TerrainTable.default()["tile"]}))
    target = tmp_path / "replay.mcap"
    target.write_bytes(b"the old export")
    seen: list[tuple[int, int]] = []

    def progress(done: int, total: int) -> None:
        seen.append((done, total))
        if done == 5:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        write_replay_mcap(target, replay, progress=progress)
    assert target.read_bytes() == b"the old export"
    assert scratch_files(tmp_path) == []
    # uninterrupted, the progress runs to the total and the file replaces the old one whole
    seen.clear()
    write_replay_mcap(target, replay, progress=lambda done, total: seen.append((done, total)))
    assert seen[-1] == (len(replay.steps), len(replay.steps))
    assert "/map/polygon" in mcap_channels(target)
    assert scratch_files(tmp_path) == []
