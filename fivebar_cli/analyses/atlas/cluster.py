"""Running the batches of an atlas on Dask: a `LocalCluster` of single-threaded worker processes
(`--workers N`), or an existing `dask.distributed` cluster (`--scheduler ADDRESS`).

The only module that imports Dask (on first use). Batches go out with `client.map` under keys
named after the atlas, come back through `as_completed`, and are cancelled when the run stops
early. Dask reschedules the batches of a lost worker itself. Its log lines are silenced: errors
reach the user as one line, through the exception raised here.
"""

from __future__ import annotations

import logging
import shlex
import shutil
import sys
import tempfile
import warnings
from contextlib import contextmanager
from functools import partial
from pathlib import Path
from typing import Iterator

from fivebar_cli.analyses.atlas.parts import manifest
from fivebar_cli.analyses.atlas.spec import AtlasSpec
from fivebar_cli.analyses.pool import main_left_out
from fivebar_cli.errors import FivebarError, InputError, deferred_interrupts, param

CONNECT_TIMEOUT = "10s"
SCHEMES = ("tcp", "tls", "ws", "wss", "ucx", "inproc")  # dask.distributed's communication protocols
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
    trimming: `MALLOC_TRIM`), closed on the way out (a second Ctrl-C then waits until it is closed).

    Its worker processes ignore Ctrl-C from birth (`_workers_ignore_ctrl_c`); this process keeps
    its handler all along, so a Ctrl-C during start-up stops the run too. They do not import this
    process's main module (`main_left_out`, while the cluster lives: the workers Dask starts again
    too), so a script without `if __name__ == "__main__":` is not run again in each.
    """
    import dask
    from dask.distributed import Client, LocalCluster

    cluster = None
    with _quiet_dask(), main_left_out(), _workers_ignore_ctrl_c() as started:
        try:
            with dask.config.set({MALLOC_TRIM: None}):
                cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=logging.CRITICAL)
            started.append(True)
            with Client(cluster) as client:
                yield DaskRunner(client, f"a local cluster of {workers} worker processes")
        finally:
            if cluster is not None:
                with deferred_interrupts():
                    cluster.close()


@contextmanager
def _workers_ignore_ctrl_c():
    """The worker processes a local cluster spawns start through a two-line /bin/sh wrapper that
    ignores SIGINT and execs this Python, which then ignores it from its first instruction: a
    Ctrl-C in the terminal (sent to the whole process group) reaches only this process, which stops
    the run and closes the cluster; no worker prints a traceback. (Workers started by `fork` or
    `forkserver`, if Dask is configured so, are left as they are.)"""
    import multiprocessing.spawn as spawn  # the executable of every `spawn` start (Dask's default method)

    folder = Path(tempfile.mkdtemp(prefix="fivebar-atlas-"))
    wrapper = folder / "python"
    wrapper.write_text(f"#!/bin/sh\ntrap '' INT\nexec {shlex.quote(sys.executable)} \"$@\"\n")
    wrapper.chmod(0o700)
    previous = spawn.get_executable()
    spawn.set_executable(str(wrapper))
    started: list[bool] = []  # set by the caller once the cluster is up (and so closed on the way out)
    try:
        yield started
    finally:
        spawn.set_executable(previous)
        if started:  # else a Ctrl-C stopped the start-up: worker processes may still be spawned through
            shutil.rmtree(folder, ignore_errors=True)  # it (a shell error each), so the tiny folder stays


def check_address(address: str) -> str:
    """`address` when it is a scheduler address, `[PROTOCOL://]HOST[:PORT]` (PORT 1 to 65535), checked
    before connecting (a bad one would otherwise wait for the connection timeout); else InputError."""
    def bad(why: str) -> InputError:
        return InputError(param("scheduler"), "", f"bad address {address!r}: {why} (expected tcp://HOST:PORT)")

    scheme, sep, rest = address.partition("://")
    if not sep:
        scheme, rest = "tcp", address
    if scheme not in SCHEMES:
        raise bad(f"unknown address scheme {scheme!r} (one of {', '.join(SCHEMES)})")
    if scheme == "inproc":
        return address
    host, port = rest, ""
    if rest.startswith("["):  # [IPv6]:PORT
        host, _, tail = rest[1:].partition("]")
        port = tail[1:] if tail.startswith(":") else tail
    elif rest.count(":") == 1:
        host, _, port = rest.partition(":")
    if not host or any(c.isspace() or c in "/@?#" for c in host):
        raise bad("no host name")
    if port and not (port.isascii() and port.isdigit() and 1 <= int(port) <= 65535):
        raise bad(f"port {port!r} is not a number from 1 to 65535")
    return address


@contextmanager
def existing_cluster(address: str) -> Iterator[DaskRunner]:
    """A client of the scheduler at `address` (`tcp://HOST:PORT`), closed on the way out."""
    from dask.distributed import Client

    with _quiet_dask():
        try:
            client = Client(address, timeout=CONNECT_TIMEOUT)
        except (ValueError, TypeError) as exc:  # not an address
            raise InputError(param("scheduler"), "", f"bad address {address!r}: {_one_line(exc)}") from None
        except OSError as exc:  # unreachable (TimeoutError is an OSError)
            raise FivebarError(param("scheduler") + f" {address}: cannot connect: {_one_line(exc)}") from None
        try:
            yield DaskRunner(client, f"the cluster at {address}")
        finally:
            with deferred_interrupts():
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
