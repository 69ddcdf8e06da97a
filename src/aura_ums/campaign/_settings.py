"""Where a campaign runs and how hard it tries: one frozen type, checked once."""

from __future__ import annotations

import math
import numbers
import re
from dataclasses import dataclass

from aura_ums.errors import InputError

#: The most local worker processes a campaign starts (a typo such as 1000 should not fork 1000).
MAX_WORKERS = 256
#: The most retries of one run: a run that fails more often fails for a reason of its own.
MAX_RETRIES = 100


def _count(value: object, name: str, low: int, high: int) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not low <= int(value) <= high:
        raise InputError(f"{name}: expected an integer in [{low}, {high}], got {value!r}")
    return int(value)


#: A scheduler's address: optional tcp:// or tls://, a host (or [IPv6]) and a port.
_ADDRESS = re.compile(r"(?:(?:tcp|tls)://)?(?:[^\s:/\[\]]+|\[[0-9A-Fa-f:.]+\]):(?P<port>[0-9]{1,5})")


@dataclass(frozen=True, slots=True)
class CampaignSettings:
    """Where the runs of a campaign execute, and how a lost run is retried.

    Parameters
    ----------
    workers : int
        1 (the default): every run in this process, one after another, as without Dask.
        N > 1: a local Dask cluster of N worker processes, one thread each (needs the
        ``aura-ums[dask]`` extra). In [1, 256].
    scheduler : str or None
        Address of a running Dask scheduler (``tcp://host:8786``): the runs go to its
        workers. Exclusive with ``workers > 1``.
    retries : int
        How many times one run is submitted again after its worker died or it outlived
        ``timeout_s``; in [0, 100]. A run that fails with an error of its own (a bad
        input) is never retried: it would fail again the same way.
    timeout_s : float or None
        Seconds a run may take on a worker before it counts as lost (its worker is
        restarted and the run retried); None: no limit. Only on Dask.

    Raises
    ------
    InputError
        For a value out of range, or both ``workers > 1`` and ``scheduler``.

    Examples
    --------
    >>> CampaignSettings().distributed
    False
    >>> CampaignSettings(workers=4, timeout_s=60.0).distributed
    True
    >>> CampaignSettings(workers=2, scheduler="tcp://10.0.0.5:8786")
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: workers: expected 1 with a scheduler (its workers run the campaign), got 2
    """

    workers: int = 1
    scheduler: str | None = None
    retries: int = 2
    timeout_s: float | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "workers", _count(self.workers, "workers", 1, MAX_WORKERS))
        object.__setattr__(self, "retries", _count(self.retries, "retries", 0, MAX_RETRIES))
        if self.scheduler is not None:
            if not isinstance(self.scheduler, str) or not self.scheduler.strip():
                raise InputError(f"scheduler: expected a Dask scheduler address, got {self.scheduler!r}")
            address = _ADDRESS.fullmatch(self.scheduler)
            if address is None or not 1 <= int(address["port"]) <= 65535:
                # Checked here: distributed's Client left a thread running after refusing it,
                # and the command never exited.
                raise InputError(
                    f"scheduler: expected a Dask scheduler address [tcp:// or tls://]HOST:PORT, "
                    f"got {self.scheduler!r}"
                )
            if self.workers != 1:
                raise InputError(
                    f"workers: expected 1 with a scheduler (its workers run the campaign), got {self.workers}"
                )
        if self.timeout_s is not None:
            timeout = self.timeout_s
            if (
                isinstance(timeout, bool)
                or not isinstance(timeout, numbers.Real)
                or not (math.isfinite(float(timeout)) and float(timeout) > 0.0)
            ):
                expected = "a finite number of seconds > 0 or None"
                raise InputError(f"timeout_s: expected {expected}, got {timeout!r}")
            object.__setattr__(self, "timeout_s", float(timeout))

    @property
    def distributed(self) -> bool:
        """Whether the runs go to Dask workers (a local cluster or a scheduler's)."""
        return self.workers > 1 or self.scheduler is not None
