"""One engine for a campaign's runs: in this process, on a local Dask cluster or on a scheduler's.

A campaign is a task applied to a sequence of items (a run's seed, a log folder). Its
results come back in the items' order whatever the order the workers finish in, so a
campaign on Dask returns exactly what the same campaign returns serially, as long as the
task depends on its item alone.

On Dask at most as many runs are in flight as the cluster has threads: a run starts on a
worker about when it is submitted, so ``timeout_s`` measures the run, not its wait in a
queue, and a long campaign holds only a window of futures. A run whose worker died
(``KilledWorker``) or that outlived ``timeout_s`` (its worker is restarted: a thread cannot
be stopped) is submitted again, at most ``retries`` times; never dropped. The local cluster
is started with ``allowed_failures=0``, so that the scheduler reports every death at once
instead of retrying silently and aura-ums counts every retry.
"""

from __future__ import annotations

import contextlib
import importlib
import logging
import os
import queue
import socket
import time
import uuid
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Generic, TypeVar

from aura_ums._validate import items_of
from aura_ums.campaign._settings import CampaignSettings
from aura_ums.errors import AuraUmsError, InputError, MissingDependencyError, RunLostError

if TYPE_CHECKING:
    from distributed import Client, Future

_T = TypeVar("_T")
_R = TypeVar("_R")

#: Seconds to connect to a scheduler, and to wait for its first worker.
_CONNECT_S = 30.0
#: Seconds a stuck worker may take to shut down, and the cluster to have a worker again,
#: after a timed-out run.
_RESTART_S = 60.0


@dataclass(frozen=True, slots=True)
class Campaign(Generic[_R]):
    """What a campaign returns: one value per item, in the items' order.

    Attributes
    ----------
    values : tuple
        The task's value for each item, in the order of the items.
    retried : int
        Items whose run was submitted again (its worker died or it timed out), each
        counted once however many retries it took; 0 for a serial campaign.
    retried_items : tuple of int
        Their indices, ascending.

    Examples
    --------
    >>> run_campaign(abs, [-1, 2, -3])
    Campaign(values=(1, 2, 3), retried=0, retried_items=())
    >>> Campaign((1, 2, 3), retried=1, retried_items=(2,)).retried_items   # item 2 ran twice on Dask
    (2,)
    >>> run_campaign(abs, [])                      # no items: no runs, nothing retried
    Campaign(values=(), retried=0, retried_items=())
    """

    values: tuple[_R, ...]
    retried: int
    retried_items: tuple[int, ...] = ()


def settings_or_serial(settings: CampaignSettings | None) -> CampaignSettings:
    """Return ``settings``, or the serial default for None; anything else is an InputError."""
    chosen = CampaignSettings() if settings is None else settings
    if not isinstance(chosen, CampaignSettings):
        raise InputError(f"settings: expected CampaignSettings or None, got {type(chosen).__name__}")
    return chosen


def run_campaign(
    task: Callable[[_T], _R],
    items: Sequence[_T],
    settings: CampaignSettings | None = None,
    *,
    progress: Callable[[int, int], None] | None = None,
) -> Campaign[_R]:
    """Apply ``task`` to every item, serially or on Dask workers, and return the values in order.

    Parameters
    ----------
    task : callable
        ``task(item) -> value``. On Dask it is pickled to the workers (with cloudpickle
        where plain pickle fails), and so are the items and values: a module-level
        function, a ``functools.partial`` of one or a frozen dataclass with
        ``__call__``. It must depend on its item alone for a Dask campaign to equal a
        serial one.
    items : sequence
        One run each.
    settings : CampaignSettings or None
        Where to run (default: serially, in this process).
    progress : callable or None
        Called as ``progress(done, total)`` after each finished run.

    Returns
    -------
    Campaign

    Raises
    ------
    MissingDependencyError
        For a Dask campaign without the ``aura-ums[dask]`` extra.
    InputError
        For a task or progress that is not callable, items that are not a sequence (a string
        neither), or when the scheduler cannot be reached or has no worker.
    RunLostError
        When a run was lost more often than ``settings.retries`` allows.
    Exception
        Whatever the task raises for an item (never retried: it would fail again).

    Examples
    --------
    >>> run_campaign(abs, [-2, 3, -5]).values
    (2, 3, 5)
    >>> run_campaign(abs, []).values
    ()
    >>> run_campaign(abs, None)
    Traceback (most recent call last):
    ...
    aura_ums.errors.InputError: items: expected a sequence of items, one a run, got NoneType
    """
    if not callable(task):
        raise InputError(f"task: expected a callable, task(item) -> value, got {type(task).__name__}")
    work = list(items_of(items, "items", "a sequence of items, one a run"))
    if progress is not None and not callable(progress):
        raise InputError(f"progress: expected a callable, progress(done, total), or None, got {progress!r}")
    chosen = settings_or_serial(settings)
    if not chosen.distributed:
        values = []
        for item in work:
            values.append(task(item))
            if progress is not None:
                progress(len(values), len(work))
        return Campaign(tuple(values), 0)
    _require_dask()
    if not work:
        return Campaign((), 0)
    with _client(chosen) as client:
        return _run_on(client, task, work, chosen, progress)


def _require_dask() -> None:
    for module in ("dask", "distributed"):
        try:
            importlib.import_module(module)
        except ImportError as exc:
            raise MissingDependencyError(
                f"a campaign on more than one worker needs the optional package {module!r} "
                f"(import failed: {exc}); install aura-ums[dask]"
            ) from exc


def _probe(address: str) -> None:
    """Refuse at once a TCP scheduler address that nothing listens at, or whose host is unknown.

    distributed's client retries a refused connection until its timeout (30 s) in case the
    scheduler is still starting; a typo in the port should not cost half a minute.
    """
    from distributed.comm.addressing import parse_address, parse_host_port

    try:
        scheme, location = parse_address(address)
        if scheme not in ("tcp", "tls"):
            return  # another transport (inproc, ucx): the client's own connection decides
        host, port = parse_host_port(location)
    except (ValueError, TypeError):
        return  # not host:port: the client says what is wrong with it
    try:
        socket.create_connection((host, port), timeout=_CONNECT_S).close()
    except (ConnectionRefusedError, socket.gaierror) as exc:
        why = f"{type(exc).__name__}: {exc}"
        raise InputError(f"scheduler: expected a Dask scheduler at {address!r}, got {why}") from None
    except OSError:
        return  # a timeout or an unreachable network: the client retries and reports it


@contextmanager
def _client(settings: CampaignSettings) -> Iterator[Client]:
    """Yield a client of the scheduler given, or of a local cluster started (and stopped) here."""
    from distributed import Client, LocalCluster

    if settings.scheduler is not None:
        _probe(settings.scheduler)
        try:
            client = Client(settings.scheduler, timeout=_CONNECT_S, set_as_default=False)
        except (OSError, ValueError) as exc:
            where, why = settings.scheduler, f"{type(exc).__name__}: {exc}"
            raise InputError(f"scheduler: expected a Dask scheduler at {where!r}, got {why}") from None
        with client:
            try:
                client.wait_for_workers(1, timeout=_CONNECT_S)
            except TimeoutError:
                where = settings.scheduler
                raise InputError(
                    f"scheduler: expected a worker at {where!r} within {_CONNECT_S:g} s, got none"
                ) from None
            yield client
        return
    import dask

    # Dask's nannies set MALLOC_TRIM_THRESHOLD_ in their workers; any fixed value switches off
    # glibc's adaptive mmap threshold, and a run's short-lived arrays then cost a system call
    # each: measured, a run took 1.65x as long. The other variables (one BLAS thread) stay.
    environ = dict(dask.config.get("distributed.nanny.pre-spawn-environ", {}))
    environ.pop("MALLOC_TRIM_THRESHOLD_", None)
    with dask.config.set({"distributed.nanny.pre-spawn-environ": environ}):
        # Loopback only; no dashboard; the workers' log lines stay out of the terminal: a task's
        # error comes back to the caller, who words it (a worker's 'Compute Failed' and a
        # traceback printed before the clean message was noise).
        held: list[int] = []
        try:
            with _stops_held(held):
                cluster = LocalCluster(
                    n_workers=settings.workers,
                    threads_per_worker=1,
                    processes=True,
                    host="127.0.0.1",
                    dashboard_address=None,
                    silence_logs=logging.CRITICAL,
                    # Its HTTP server on a free loopback port: 8787, Dask's default, may be taken.
                    scheduler_kwargs={
                        "allowed_failures": 0,
                        "dashboard": False,
                        "dashboard_address": "127.0.0.1:0",
                    },
                )
        except (RuntimeError, OSError, ValueError, TypeError, TimeoutError) as exc:
            # A stop that came meanwhile may be why (the workers met a SIGTERM sent to the whole
            # process group): it is what ends the command, not the failure it caused.
            _deliver(held)
            # "Nanny failed to start", from a worker that could not: a Dask setting it read
            # (DASK_... in the environment, a configuration file) or the machine refusing it.
            raise AuraUmsError(
                f"workers: expected {settings.workers} local Dask workers to start, got "
                f"{type(exc).__name__}: {exc} (look at Dask's settings: DASK_* variables in the "
                "environment, files in ~/.config/dask)"
            ) from None
        with cluster:
            _deliver(held)  # inside the block: the cluster is stopped before the stop goes on
            with Client(cluster, set_as_default=False) as client:
                yield client


#: The signals that stop a command line as a Ctrl-C does: Ctrl-C itself, ``kill`` and
#: ``timeout`` (SIGTERM), a closed terminal (SIGHUP).
_STOPS = ("SIGINT", "SIGTERM", "SIGHUP")
#: The ones the local workers never receive: a terminal's Ctrl-C or hangup goes to every
#: process of its group, workers too, which then printed their own KeyboardInterrupt
#: tracebacks. They are stopped by their cluster instead. SIGTERM still reaches them: Dask
#: and multiprocessing end a worker with it.
_SPARED = ("SIGINT", "SIGHUP")


@contextmanager
def _stops_held(held: list[int]) -> Iterator[None]:
    """Hold a stop (Ctrl-C, SIGTERM, SIGHUP) while a local cluster starts, and keep it from its workers.

    A KeyboardInterrupt raised inside ``LocalCluster(...)`` left a half-started cluster
    whose tasks and exit function printed Dask's tracebacks, and its workers still
    starting. Here the handlers that would raise are replaced by one that appends the
    signal's number to ``held``; the caller delivers it (:func:`_deliver`) once the cluster
    can be stopped. The signals of :data:`_SPARED` are also blocked in this thread meanwhile:
    the threads the cluster starts inherit the mask, and the worker processes they spawn
    keep it through ``exec`` (as multiprocessing's resource tracker protects its own
    process), so a Ctrl-C reaches this process alone, which stops the workers itself.
    Outside the main thread (an embedding caller's) the handlers stay as they are.
    """
    import signal

    def hold(signum: int, frame: object) -> None:
        held.append(signum)

    numbers = [getattr(signal, name) for name in _STOPS if hasattr(signal, name)]
    handlers: dict[int, Any] = {}
    with contextlib.suppress(ValueError):  # not the main thread
        for number in numbers:
            if callable(signal.getsignal(number)):  # one that raises here (the default kills, ignores)
                handlers[number] = signal.signal(number, hold)
    masks = hasattr(signal, "pthread_sigmask")  # not on Windows, which has no process groups either
    spared = {getattr(signal, name) for name in _SPARED if hasattr(signal, name)}
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, spared) if masks else set()
    try:
        if masks:
            from multiprocessing import resource_tracker

            # Started here, not by the cluster from its own thread: starting it unblocks SIGINT
            # in the thread that does (resource_tracker.py), and that thread's workers would
            # receive the Ctrl-C again. It inherits the mask too (a SIGHUP ended it).
            resource_tracker.ensure_running()
            signal.pthread_sigmask(signal.SIG_BLOCK, spared)
        yield
    finally:
        if masks:  # unblocked first: a signal pending meanwhile is handled now, by hold
            signal.pthread_sigmask(signal.SIG_SETMASK, mask)
        for number, handler in handlers.items():
            signal.signal(number, handler)


def _deliver(held: list[int]) -> None:
    """Deliver the first stop :func:`_stops_held` held: its own handler raises it here."""
    if held:
        import signal

        signal.raise_signal(held[0])


class _Runs(Generic[_T, _R]):
    """The bookkeeping of one Dask campaign: what is queued, in flight, done and retried."""

    def __init__(self, task: Callable[[_T], _R], items: list[_T], settings: CampaignSettings) -> None:
        self.task = task
        self.items = items
        self.settings = settings
        self.queue: deque[int] = deque(range(len(items)))
        self.attempts = [0] * len(items)
        self.values: dict[int, _R] = {}
        self.retried: set[int] = set()
        self.in_flight: dict[Future[Any], tuple[int, float]] = {}
        # Filled by the client's thread as runs end (finished, failed or cancelled).
        self.finished: queue.Queue[Future[Any]] = queue.Queue()
        # Keys unique to this campaign: several clients may share one scheduler.
        self.prefix = f"aura-ums-{uuid.uuid4().hex[:12]}"

    def submit(self, client: Client, slots: int) -> None:
        while self.queue and len(self.in_flight) < slots:
            index = self.queue.popleft()
            key = f"{self.prefix}-run{index}-attempt{self.attempts[index]}"
            future = client.submit(self.task, self.items[index], key=key, pure=False)
            self.in_flight[future] = (index, time.monotonic())
            future.add_done_callback(self.finished.put)

    def lost(self, index: int, why: str) -> None:
        self.attempts[index] += 1
        if self.attempts[index] > self.settings.retries:
            # A folder (a log replayed) is named: "run 3" alone left the user counting.
            item: object = self.items[index]
            named = f" ({os.fspath(item)})" if isinstance(item, str | os.PathLike) else ""
            raise RunLostError(
                f"run {index}{named}: expected it to finish within {self.settings.retries} retries, "
                f"got it lost {self.attempts[index]} times (last: {why})"
            )
        self.retried.add(index)
        # First in line again: the campaign's order of completion stays close to the items'.
        self.queue.appendleft(index)

    def next_deadline(self) -> float | None:
        if self.settings.timeout_s is None or not self.in_flight:
            return None
        first = min(started for _, started in self.in_flight.values())
        return max(0.0, first + self.settings.timeout_s - time.monotonic())


def _run_on(
    client: Client,
    task: Callable[[_T], _R],
    items: list[_T],
    settings: CampaignSettings,
    progress: Callable[[int, int], None] | None,
) -> Campaign[_R]:
    from distributed import KilledWorker

    runs = _Runs(task, items, settings)
    total = len(items)
    while runs.queue or runs.in_flight:
        runs.submit(client, max(1, sum(client.nthreads().values())))
        try:
            finished = [runs.finished.get(timeout=runs.next_deadline())]
        except queue.Empty:
            finished = []  # a run outlived the timeout: see below
        while not runs.finished.empty():
            finished.append(runs.finished.get_nowait())
        # A run timed out and cancelled here also reports; it is no longer in flight.
        for future in (f for f in finished if f in runs.in_flight):
            index, _ = runs.in_flight.pop(future)
            if future.status == "finished":
                runs.values[index] = future.result()
                if progress is not None:
                    progress(len(runs.values), total)
                continue
            error = future.exception() if future.status == "error" else None
            if error is not None and not isinstance(error, KilledWorker):
                raise error  # the run's own error: the same on any worker
            runs.lost(index, f"{type(error).__name__}: {error}" if error is not None else str(future.status))
        if settings.timeout_s is not None:
            _time_out(client, runs, settings.timeout_s)
    values = tuple(runs.values[i] for i in range(total))
    return Campaign(values, len(runs.retried), tuple(sorted(runs.retried)))


def _time_out(client: Client, runs: _Runs[_T, _R], timeout_s: float) -> None:
    """Retry the runs in flight for longer than ``timeout_s``; restart the workers stuck in them."""
    now = time.monotonic()
    late = [f for f, (_, started) in runs.in_flight.items() if now - started >= timeout_s]
    if not late:
        return
    processing = client.processing()
    stuck = sorted({worker for worker, keys in processing.items() for f in late if f.key in keys})
    for future in late:
        index, _ = runs.in_flight.pop(future)
        future.cancel()
        runs.lost(index, f"no result within timeout_s = {timeout_s:g} s")
    if stuck:
        # A thread cannot be stopped: the worker's process is, by its nanny. Not waiting for
        # the restarted workers to return: a nanny whose worker was lost before may never
        # bring it back, and the campaign would stall for _RESTART_S on the others' behalf.
        scheduler = client.scheduler
        if scheduler is None:  # the client has closed: nothing can run any more
            raise RunLostError(
                f"scheduler: expected a connected client, got one closed "
                f"(restarting {len(stuck)} stuck worker(s))"
            )
        client.sync(
            scheduler.restart_workers,
            workers=stuck,
            timeout=_RESTART_S,
            wait_for_workers=False,
            on_error="return",
            stimulus_id=f"aura-ums-timeout-{time.time()}",
        )
        try:
            client.wait_for_workers(1, timeout=_RESTART_S)
        except TimeoutError as error:  # distributed's WorkerStartTimeoutError is one
            raise RunLostError(
                f"scheduler: expected a worker within {_RESTART_S:g} s of restarting {len(stuck)} "
                f"stuck worker(s), got none"
            ) from error
        # The runs in flight waited for the restart (some were queued on that worker): their
        # time starts again now, or one stuck run would time out the runs behind it.
        restarted = time.monotonic()
        runs.in_flight.update({f: (index, restarted) for f, (index, _) in runs.in_flight.items()})
