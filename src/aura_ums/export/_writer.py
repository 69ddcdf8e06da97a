"""Write runs and replays to MCAP (needs ``foxglove-sdk``): the file sink of the shared channels.

Imported only by the public functions of :mod:`aura_ums.export`, after they have checked
that the optional dependency is installed. The messages and channels are built by
``_messages`` (the live view uses the same); this module opens the MCAP container, the
SDK's writer on a private context, and feeds it every frame or step.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

import foxglove
import numpy as np

from aura_ums import __version__
from aura_ums._files import atomic_path
from aura_ums.errors import FileFormatError, InputError
from aura_ums.export._messages import ReplayChannels, SimulationChannels
from aura_ums.export._scene import seconds_to_nanoseconds
from aura_ums.export._types import ReplayLike
from aura_ums.sim import RunResult, Scenario
from aura_ums.world import MeadowMap

if TYPE_CHECKING:
    from aura_ums.logs import WindowReport, WindowRow

#: How the SDK's errors begin (foxglove-sdk 0.30 has no exception class of its own).
_SDK_ERROR = "FoxgloveError"

#: Reports ``(done, total)`` units of work after each one (the CLI draws it as a bar).
Progress = Callable[[int, int], None]


@contextmanager
def _mcap(path: Path, kind: str, name: str) -> Iterator[foxglove.Context]:
    """Open an MCAP file on a private SDK context (nothing leaks to the global one).

    The file is written under a scratch name beside ``path`` and renamed onto it once
    closed: an error, a Ctrl-C or a kill leaves the old file (or none), never a part.
    """
    context = foxglove.Context()
    try:
        with atomic_path(path) as scratch:
            writer = foxglove.open_mcap(scratch, allow_overwrite=False, context=context)
            with writer:
                writer.write_metadata(
                    "aura_ums", {"kind": kind, "name": name, "aura_ums_version": __version__}
                )
                yield context
    except OSError as exc:
        raise FileFormatError.unwritable(str(path), exc) from exc
    except RuntimeError as exc:
        # The SDK reports its own I/O failures (a full disk while it writes or closes the
        # file) as a RuntimeError naming itself; any other RuntimeError is not ours to word.
        if not str(exc).startswith(_SDK_ERROR):
            raise
        raise FileFormatError.unwritable(str(path), str(exc)) from exc


def _report(progress: Progress | None, done: int, total: int) -> None:
    if progress is not None:
        progress(done, total)


def write_simulation(
    path: Path,
    scenario: Scenario,
    result: RunResult,
    camera_topic_images: bool,
    progress: Progress | None = None,
) -> Path:
    """Write a simulation run; see :func:`aura_ums.export.write_simulation_mcap`."""
    records = result.records
    if not records:
        raise InputError("result.records: expected at least one frame, got none")
    images = result.images
    if camera_topic_images and not images:
        raise InputError(
            "result.images: expected the frames' images (run_scenario(..., keep_images=True)), got none; "
            "pass camera_topic_images=False to export without them"
        )
    if len(images) > len(records):
        raise InputError(f"result.images: expected at most {len(records)} images, got {len(images)}")
    for index, image in enumerate(images if camera_topic_images else ()):
        if not isinstance(image, np.ndarray) or image.ndim != 2 or image.dtype != np.uint8:
            raise InputError(
                f"result.images[{index}]: expected a 2-D uint8 grayscale image, "
                f"got {getattr(image, 'shape', type(image).__name__)} of {getattr(image, 'dtype', '?')}"
            )
    # images are those of the last call of run_scenario: the last frames (after a resume)
    first_image = len(records) - len(images)
    times = [seconds_to_nanoseconds(r.time, f"records[{i}].time") for i, r in enumerate(records)]
    sliced = any(r.map_after.is_sliced for r in records)
    with _mcap(path, "simulation", scenario.name) as context:
        channels = SimulationChannels(context, scenario, images=camera_topic_images, sliced=sliced)
        channels.scene(times[0])
        for index, (record, ns) in enumerate(zip(records, times, strict=True)):
            frame_image = (
                images[index - first_image] if camera_topic_images and index >= first_image else None
            )
            channels.frame(record, frame_image, ns)
            _report(progress, index + 1, len(records))
    return path


def replay_world(replay: ReplayLike) -> MeadowMap | None:
    """Return the arena a :class:`aura_ums.logs.ReplayResult` replayed in (None for other replays)."""
    from aura_ums.logs import ReplayOptions, RobotLog, log_meadow_map

    options = getattr(replay, "options", None)
    if not isinstance(options, ReplayOptions) or not isinstance(replay.log, RobotLog):
        return None
    return log_meadow_map(replay.log, options.landmark_class, margin=options.arena_margin)


def _rows_by_time(windows: WindowReport | None) -> dict[float, list[WindowRow]]:
    rows: dict[float, list[WindowRow]] = {}
    for row in () if windows is None else windows.rows:
        rows.setdefault(row.time, []).append(row)
    return rows


def write_replay(
    path: Path, replay: ReplayLike, windows: WindowReport | None = None, progress: Progress | None = None
) -> Path:
    """Write a replay; see :func:`aura_ums.export.write_replay_mcap`."""
    steps = tuple(replay.steps)
    if not steps:
        raise InputError("replay.steps: expected at least one step, got none")
    times = [seconds_to_nanoseconds(s.time, f"replay.steps[{i}].time") for i, s in enumerate(steps)]
    size = None
    if windows is not None:
        intrinsics = windows.camera.intrinsics
        size = (intrinsics.width, intrinsics.height)
    rows = _rows_by_time(windows)
    none: Sequence[WindowRow] = ()
    with _mcap(path, "replay", str(replay.log.meta.name)) as context:
        channels = ReplayChannels(
            context,
            replay.log,
            replay_world(replay),
            truth=any(s.truth is not None for s in steps),
            sliced=any(s.map.is_sliced for s in steps),
            image_size=size,
        )
        channels.scene(times[0])
        for index, (step, ns) in enumerate(zip(steps, times, strict=True)):
            channels.step(index, step, ns, rows.get(float(step.time), none))
            _report(progress, index + 1, len(steps))
    return path
