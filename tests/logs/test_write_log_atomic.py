"""``write_log`` (what ``aura-ums import`` writes with) killed half-way leaves no partial file.

A new log folder is written under a hidden scratch name and renamed when whole; into a
folder with other files, each file is renamed onto its name when whole. The kill is
deterministic: the writing process kills itself from its own progress callback.
"""

from __future__ import annotations

import errno
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from aura_ums.errors import FileFormatError
from aura_ums.logs import load_log, log_files_in, synthetic_log, write_log

WRITE = textwrap.dedent(
    """
    import os, signal, sys
    import numpy as np
    from aura_ums.logs import synthetic_log, write_log

    def progress(done, total):
        if done == 2:
            os.kill(os.getpid(), signal.SIGKILL)

    log = synthetic_log(np.random.default_rng(int(sys.argv[2])), duration=30.0)
    write_log(log, sys.argv[1], overwrite=True, progress=progress)
    """
)


def killed_write(folder: Path, seed: int) -> None:
    done = subprocess.run(
        [sys.executable, "-c", WRITE, str(folder), str(seed)], capture_output=True, check=False
    )
    assert done.returncode == -signal.SIGKILL, done.stderr


def test_a_killed_import_leaves_no_log_folder(tmp_path: Path) -> None:
    killed_write(tmp_path / "log", seed=1)
    assert not (tmp_path / "log").exists()
    (scratch,) = tmp_path.iterdir()
    assert scratch.name.startswith(".log.")
    assert scratch.name.endswith(".tmp")


def test_a_killed_overwrite_leaves_every_file_whole(tmp_path: Path) -> None:
    folder = tmp_path / "log"
    old = synthetic_log(np.random.default_rng(2), duration=30.0)
    write_log(old, folder)
    (folder / "notes.txt").write_text("mine")
    before = {name: (folder / name).read_bytes() for name in log_files_in(folder)}
    killed_write(folder, seed=3)
    assert {name: (folder / name).read_bytes() for name in log_files_in(folder)} == before
    assert len(load_log(folder).observations) == len(old.observations)  # still the whole old log
    assert (folder / "notes.txt").read_text() == "mine"


def test_progress_counts_the_files_and_an_interrupt_leaves_nothing(tmp_path: Path) -> None:
    log = synthetic_log(np.random.default_rng(2), duration=10.0)
    seen: list[tuple[int, int]] = []
    write_log(log, tmp_path / "a", progress=lambda done, total: seen.append((done, total)))
    assert seen == [(1, 5), (2, 5), (3, 5), (4, 5), (5, 5)]

    def stop(done: int, total: int) -> None:
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        write_log(log, tmp_path / "b", progress=stop)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a"]
    with pytest.raises(KeyboardInterrupt):
        write_log(log, tmp_path / "a", overwrite=True, progress=stop)
    assert len(load_log(tmp_path / "a").observations) == len(log.observations)
    assert sorted(p.name for p in (tmp_path / "a").iterdir()) == sorted(log_files_in(tmp_path / "a"))


def test_a_full_disk_leaves_no_folder_made_for_the_log(tmp_path: Path) -> None:
    log = synthetic_log(np.random.default_rng(2), duration=10.0)

    def full(done: int, total: int) -> None:  # as a write of the next file would fail
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    target = tmp_path / "new" / "deeper" / "log"
    with pytest.raises(FileFormatError, match=r"log: expected a writable folder, got No space left"):
        write_log(log, target, progress=full)
    assert list(tmp_path.iterdir()) == []
