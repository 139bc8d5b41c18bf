"""Running the batches of an atlas on Dask: a `LocalCluster` of single-threaded worker processes
(`--workers N`), or an existing `dask.distributed` cluster (`--scheduler ADDRESS`).

The only module that imports Dask (on first use). Batches go out with `client.map` under keys
named after the atlas, come back through `as_completed`, and are cancelled when the run stops
early. Dask reschedules the batches of a lost worker itself. Its log lines are silenced: errors
reach the user as one line, through the exception raised here.
"""

from __future__ import annotations

import logging
import signal
import threading
import warnings
from contextlib import contextmanager
from functools import partial
from typing import Iterator

from fivebar_cli.analyses.atlas.parts import manifest
from fivebar_cli.analyses.atlas.spec import AtlasSpec
from fivebar_cli.errors import FivebarError, InputError

CONNECT_TIMEOUT = "10s"
# Dask starts worker processes with MALLOC_TRIM_THRESHOLD_=65536, which makes glibc return memory to
# the system on nearly every free: the analyses (many short-lived numpy arrays) then run 2-3x slower.
# None unsets it for the workers of a local cluster (README, "Sweeping designs", for other clusters).
MALLOC_TRIM = "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_"


class DaskRunner:
    """A runner (engine.Runner) over a connected `dask.distributed.Client`."""

    def __init__(self, client, where: str):
        self.client = client
        self.where = where

    @property
    def workers(self) -> int:
        return len(self.client.scheduler_info().get("workers", {}))

    def __call__(self, task, spec: AtlasSpec, indices: list) -> Iterator[tuple[int, str]]:
        from dask.distributed import as_completed

        if not indices:
            return
        prefix = f"fivebar-atlas-{manifest(spec)['key'][:16]}"
        futures = self.client.map(partial(task, spec), indices, key=[f"{prefix}-{i}" for i in indices])
        index_of = {f.key: i for f, i in zip(futures, indices)}
        pending = {f.key: f for f in futures}  # a finished future is dropped, which releases its result
        del futures
        try:
            for batch in as_completed(pending.values(), with_results=True, raise_errors=False).batches():
                for future, text in batch:
                    index = index_of[future.key]
                    del pending[future.key]
                    if future.status != "finished":
                        _raise(future, index)
                    yield index, text
        finally:
            if pending:
                self.client.cancel(list(pending.values()))


def _raise(future, index: int) -> None:
    """The error of a failed batch, as one line (a FivebarError raised by the task passes unchanged)."""
    try:
        future.result()
    except FivebarError:
        raise
    except Exception as exc:  # KilledWorker, a lost scheduler, ...
        raise FivebarError(f"batch {index} failed on the cluster: {type(exc).__name__}: {_one_line(exc)}") from None
    raise FivebarError(f"batch {index} failed on the cluster: {future.status}")


@contextmanager
def local_cluster(workers: int) -> Iterator[DaskRunner]:
    """A `LocalCluster` of `workers` single-threaded worker processes (glibc's default memory
    trimming: `MALLOC_TRIM`), closed on the way out.

    Its worker processes ignore SIGINT (`_sigint_ignored`).
    """
    import dask
    from dask.distributed import Client, LocalCluster

    with _quiet_dask():
        with _sigint_ignored(), dask.config.set({MALLOC_TRIM: None}):
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None, silence_logs=logging.CRITICAL)
        try:
            with Client(cluster) as client:
                yield DaskRunner(client, f"a local cluster of {workers} worker processes")
        finally:
            cluster.close()


@contextmanager
def existing_cluster(address: str) -> Iterator[DaskRunner]:
    """A client of the scheduler at `address` (`tcp://HOST:PORT`), closed on the way out."""
    from dask.distributed import Client

    with _quiet_dask():
        try:
            client = Client(address, timeout=CONNECT_TIMEOUT)
        except (ValueError, TypeError) as exc:  # not an address
            raise InputError("--scheduler", "", f"bad address {address!r}: {_one_line(exc)}") from None
        except OSError as exc:  # unreachable (TimeoutError is an OSError)
            raise FivebarError(f"--scheduler {address}: cannot connect: {_one_line(exc)}") from None
        try:
            yield DaskRunner(client, f"the cluster at {address}")
        finally:
            client.close()


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split())[:300] or type(exc).__name__


@contextmanager
def _quiet_dask():
    """Dask's loggers and warnings silenced for the run (their lines would break the one-line error
    contract): e.g. "Port 8787 is already in use" when another cluster runs on this machine."""
    logger = logging.getLogger("distributed")
    level = logger.level
    logger.setLevel(logging.CRITICAL)
    try:
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", module=r"distributed\.")
            yield
    finally:
        logger.setLevel(level)


@contextmanager
def _sigint_ignored():
    """SIGINT ignored while the cluster starts its worker processes, which inherit that: a Ctrl-C in
    the terminal (sent to the whole process group) then reaches only this process, which stops the
    run and closes the cluster. A Ctrl-C during these seconds of start-up is lost."""
    previous = signal.getsignal(signal.SIGINT)
    if threading.current_thread() is not threading.main_thread() or previous is None:  # None: set outside Python
        yield
        return
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
