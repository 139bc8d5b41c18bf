"""Independent tasks of one analysis (the pavings of its modes, regions or classes, each aspect's
files) run in worker processes: `--jobs N`.

Processes, not threads: the box tests are numpy code that holds the GIL for most of its time.
`jobs=1` runs every task in this process, one after another; `jobs=None` (the default of the
commands) starts one worker per core this process may use. Results come back in the tasks' order,
whatever the order they finish in, so the outputs are the same bytes for any N. A task is a
module-level function and picklable arguments; workers are forked where the platform can (no
re-import, the parent's data shared copy-on-write), spawned elsewhere. Workers ignore Ctrl-C and
SIGHUP and die on SIGTERM: the parent alone reacts to signals, and when it stops (an interruption,
an error) it terminates its pool.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
from typing import Callable, Iterable, TypeVar

T = TypeVar("T")
R = TypeVar("R")


def default_jobs() -> int:
    """One worker per core this process may run on."""
    try:
        return max(len(os.sched_getaffinity(0)), 1)
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def workers(jobs: int | None, tasks: int) -> int:
    """How many processes `jobs` gives for this many tasks (1: run them in this process)."""
    return max(1, min(default_jobs() if jobs is None else jobs, tasks))


def run_tasks(fn: Callable[[T], R], items: Iterable[T], jobs: int | None = 1,
              advance: Callable[[int], None] = lambda n=1: None) -> list[R]:
    """[fn(item) for item in items], on `jobs` worker processes; `advance(1)` as each result arrives
    (in order)."""
    items = list(items)
    n = workers(jobs, len(items))
    if n == 1:
        out = []
        for item in items:
            out.append(fn(item))
            advance(1)
        return out
    method = "fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn"
    with multiprocessing.get_context(method).Pool(n, initializer=_quiet_worker) as pool:
        out = []
        for result in pool.imap(fn, items, chunksize=1):
            out.append(result)
            advance(1)
        return out


def _quiet_worker() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # the parent's handler would raise inside a task
    if hasattr(signal, "SIGHUP"):
        signal.signal(signal.SIGHUP, signal.SIG_IGN)
