"""Campaigns: many runs at once, on the cores of this machine or on a Dask cluster.

:func:`run_campaign` applies a task to a sequence of items, in this process or on Dask
workers (:class:`CampaignSettings`: a local cluster of ``workers`` processes, or a running
scheduler's), and returns a :class:`Campaign`: the values in the items' order and how many
runs were retried after their worker died or timed out. The tasks of aura-ums'
campaigns: :class:`SimulationRun` (one seeded Monte Carlo run; :func:`simulate_campaign`
seeds them from :func:`run_seeds`), :class:`LoadLog` and :class:`LogReplay`. Dask is the
optional extra ``aura-ums[dask]``; a serial campaign needs nothing more.
"""

from aura_ums.campaign._engine import Campaign, run_campaign
from aura_ums.campaign._jobs import (
    LoadLog,
    LogReplay,
    SimulationBatch,
    SimulationRun,
    batches,
    run_seeds,
    simulate_campaign,
)
from aura_ums.campaign._settings import CampaignSettings

__all__ = [
    "Campaign",
    "CampaignSettings",
    "LoadLog",
    "LogReplay",
    "SimulationBatch",
    "SimulationRun",
    "batches",
    "run_campaign",
    "run_seeds",
    "simulate_campaign",
]
