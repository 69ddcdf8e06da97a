"""A figure of a log's replay: the maps along the true path, and area, wedge and containment over time."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

from aura_ums._validate import integer_at_least
from aura_ums.errors import InputError
from aura_ums.plot._draw import draw_map

if TYPE_CHECKING:
    from aura_ums.logs import ReplayResult


def draw_replay(result: ReplayResult, folder: str | Path, *, maps_drawn: int = 12) -> Path:
    """Draw a replay into ``folder/<log name>_replay.png`` and return the path.

    Left: the landmarks, the true path, and ``maps_drawn`` maps spread over the replay.
    Right: the map's area (log scale) and wedge width over time, with the steps whose
    truth fell outside marked in red.

    Parameters
    ----------
    result : ReplayResult
        From :func:`aura_ums.logs.replay_log`.
    folder : str or Path
        Created when missing.
    maps_drawn : int
        Maps drawn on the left, >= 0.

    Returns
    -------
    Path
        The PNG written.

    Examples
    --------
    >>> import tempfile
    >>> from aura_ums.logs import replay_log, synthetic_log
    >>> from aura_ums.uncertainty import TerrainTable
    >>> log = synthetic_log(np.random.default_rng(3), duration=3.0)     # ten frames
    >>> result = replay_log(log, TerrainTable({"floor": TerrainTable.default()["tile"]}))
    >>> folder = Path(tempfile.mkdtemp()) / "replay"                    # created when missing
    >>> draw_replay(result, folder, maps_drawn=0).name    # no map on the left: landmarks and truth
    'synthetic_replay.png'
    >>> sorted(path.name for path in folder.iterdir())
    ['synthetic_replay.png']
    >>> draw_replay(result, folder, maps_drawn=-3)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: maps_drawn: expected an integer >= 0, got -3
    """
    from aura_ums.logs import ReplayResult

    if not isinstance(result, ReplayResult):
        raise InputError(f"result: expected a ReplayResult, got {type(result).__name__}")
    maps_drawn = integer_at_least(maps_drawn, "maps_drawn", 0)
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    figure = Figure(figsize=(12, 5.5))
    ax_map, ax_area = figure.subplots(1, 2)
    log = result.log
    ax_map.scatter(
        [lm.x for lm in log.landmarks], [lm.y for lm in log.landmarks], marker="s", color="k", s=16
    )
    truth = [s.truth for s in result.steps if s.truth is not None]
    if truth:
        ax_map.plot([p.x for p in truth], [p.y for p in truth], color="0.6", lw=0.8, label="ground truth")
    steps = result.steps
    if steps and maps_drawn > 0:
        for index in np.linspace(0, len(steps) - 1, min(maps_drawn, len(steps))).astype(int):
            draw_map(ax_map, steps[int(index)].map, color="tab:blue")
    ax_map.set_aspect("equal")
    ax_map.set_xlabel("x [m]")
    ax_map.set_ylabel("y [m]")
    ax_map.set_title(f"{log.meta.name}: maps along the run")
    if steps:
        times = np.array([s.time for s in steps]) - steps[0].time
        ax_area.semilogy(times, [s.map.area for s in steps], color="tab:blue", lw=0.8, label="area [m^2]")
        ax_wedge = ax_area.twinx()
        ax_wedge.plot(times, [s.map.wedge.width for s in steps], color="tab:orange", lw=0.8)
        ax_wedge.set_ylabel("wedge width [rad]", color="tab:orange")
        outside = [t for t, s in zip(times, steps, strict=True) if s.inside is False]
        if outside:
            ax_area.plot(outside, [steps[0].map.area] * len(outside), "|", color="red", label="truth outside")
        ax_area.legend(loc="upper left")
    ax_area.set_xlabel("time [s]")
    ax_area.set_ylabel("area [m^2]", color="tab:blue")
    ax_area.set_title(
        f"containment {result.containment_rate:.4f}, {result.inconsistent_observations} rejected"
    )
    figure.tight_layout()
    path = out / f"{log.meta.name}_replay.png"
    figure.savefig(path, dpi=110)
    return path
