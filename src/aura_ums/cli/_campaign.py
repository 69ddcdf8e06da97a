"""The campaign options of ``simulate``, ``replay`` and ``calibrate`` (``--workers``, ``--scheduler``, ...).

The commands declare the options below and turn them into a
:class:`~aura_ums.campaign.CampaignSettings` with :func:`campaign_settings`; a replay of
several logs is :func:`replay_logs`.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from aura_ums.campaign import CampaignSettings
from aura_ums.cli._common import console, fail, none_or_float, progress_bar, refuse_alone
from aura_ums.cli._outputs import Target, write_text

if TYPE_CHECKING:
    from aura_ums.camera import CalibrationBounds, Camera
    from aura_ums.logs import ReplayOptions
    from aura_ums.uncertainty import TerrainTable

Workers = Annotated[
    int,
    typer.Option(
        "--workers",
        help="Worker processes of a local Dask cluster that run the campaign (needs aura-ums[dask]); "
        "1: one after another, in this process. The results are the same.",
    ),
]
Scheduler = Annotated[
    str | None,
    typer.Option(
        "--scheduler",
        help="Address of a running Dask scheduler (tcp://HOST:8786) whose workers run the campaign.",
    ),
]
Retries = Annotated[
    int,
    typer.Option("--retries", help="Times a run is submitted again after its worker died or it timed out."),
]


def _timeout(text: str) -> float | None:
    """Read ``--run-timeout``: seconds, or ``none`` (the default: no timeout)."""
    try:
        return none_or_float(text)
    except ValueError:
        raise fail(f"--run-timeout: expected a positive number of seconds or none, got {text!r}") from None


RunTimeout = Annotated[
    float | None,
    typer.Option(
        "--run-timeout",
        help="Seconds a run may take on a worker before it is retried (its worker restarted), or none.",
        parser=_timeout,
        metavar="<seconds>",
    ),
]

#: The settings a left-out option takes (CampaignSettings' defaults, written there only).
DEFAULTS = CampaignSettings()

# The settings' parameter names, as the options are spelled.
_FLAGS = {
    "workers": "--workers",
    "scheduler": "--scheduler",
    "retries": "--retries",
    "timeout_s": "--run-timeout",
}


def campaign_failure(exc: Exception) -> str:
    """Return a campaign's error message with its settings named as the options are spelled.

    A run lost to its timeout says ``no result within timeout_s = 1e-09 s``: the user typed
    ``--run-timeout``.
    """
    message = str(exc)
    name, colon, rest = message.partition(": ")
    if colon and name in _FLAGS:  # a setting refused as a whole: "scheduler: expected ..."
        message = f"{_FLAGS[name]}: {rest}"
    for name, flag in _FLAGS.items():
        message = message.replace(f"{name} = ", f"{flag} ")
    return message


def campaign_settings(
    context: typer.Context, workers: int, scheduler: str | None, retries: int, run_timeout: float | None
) -> CampaignSettings:
    """Return the campaign's settings from its options; a bad value, or one with no effect, exits named."""
    from aura_ums.errors import InputError

    try:
        settings = CampaignSettings(
            workers=workers, scheduler=scheduler, retries=retries, timeout_s=run_timeout
        )
    except InputError as exc:
        name, _, rest = str(exc).partition(": ")
        raise fail(f"{_FLAGS.get(name, name)}: {rest}") from None
    dask = workers > 1 or scheduler is not None
    neither = "neither (runs are retried on Dask workers only)"
    refuse_alone(
        context,
        [(name, "--workers above 1 or --scheduler", neither, dask) for name in ("retries", "run_timeout")],
    )
    return settings


def replay_logs(
    log_dirs: list[Path],
    table: TerrainTable,
    options: ReplayOptions,
    *,
    table_file: Path,
    camera: Camera | None,
    calibration_bounds: CalibrationBounds | None,
    window_margin: float,
    max_truth_gap: float | None,
    until: float | None,
    json_target: Target | None,
    settings: CampaignSettings,
    quiet: bool,
) -> None:
    """Replay several logs as one campaign; print their metrics and write them (``replays``) as JSON.

    ``table`` was read from ``table_file`` (``--terrain``), named when it lacks a log's terrain.
    """
    from aura_ums import Metrics
    from aura_ums.campaign import LoadLog, LogReplay, run_campaign
    from aura_ums.errors import AuraUmsError

    job = LogReplay(
        table,
        options,
        camera,
        window_margin,
        LoadLog(max_truth_gap),
        until,
        str(table_file),
        calibration_bounds,
    )
    try:
        with progress_bar("replay: logs", quiet=quiet, total=len(log_dirs)) as advance:
            campaign = run_campaign(job, log_dirs, settings, progress=advance)
    except AuraUmsError as exc:
        # The library names its argument ("until: ..."; "LOG: until: ..." from a run): the user typed --until.
        raise fail(re.sub(r"(^|: )until: ", r"\1--until: ", campaign_failure(exc), count=1)) from None
    metrics = Metrics({"replays": campaign.values, "runs_retried": campaign.retried})
    for line in metrics.lines():
        console.print(line, highlight=False, markup=False)
    if json_target is not None:
        write_text(json_target, metrics.to_json())
