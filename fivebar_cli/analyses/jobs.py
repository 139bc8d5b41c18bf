"""Independent tasks of one analysis (the pavings of its modes, regions or classes, each aspect's
files) run in worker processes: `--jobs N`.

Processes, not threads: the box tests are numpy code that holds the GIL for most of its time.
`jobs=1` runs every task in this process, one after another; `jobs=None` (the default of the
commands) starts one worker per core this process may use. Results come back in the tasks' order,
whatever the order they finish in, so the outputs are the same bytes for any N; `Workers` keeps
its processes for several rounds and starts a task that needs another's result as soon as that
one is done (the order the caller takes the results in stays fixed). A task is a
module-level function and picklable arguments; workers are forked where the platform can (no
re-import, the parent's data shared copy-on-write), spawned elsewhere. Trees and pavings travel
between the processes compact (`_tree_travels`, `_paving_travels`: levels in a byte, cell
coordinates in 32 bits; the same arrays arrive): their bytes through the pipes are most of what
the workers cost the parent. Workers ignore Ctrl-C and
SIGHUP and die on SIGTERM: the parent alone reacts to signals, and when it stops (an interruption,
an error) it terminates its pool.
"""

from __future__ import annotations

import itertools
import multiprocessing
import os
import queue
import signal
from multiprocessing.reduction import ForkingPickler
from typing import Callable, Iterable, Iterator, TypeVar

import numpy as np

from fivebar_cli.paving.engine import Paving
from fivebar_cli.paving.tree import Tree

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
    with Workers(jobs, len(items)) as pool:
        return list(pool.map(fn, items, advance))


class Workers:
    """`jobs` worker processes kept for several rounds of tasks (`jobs=1`, or one task: none, every
    task runs in this process when it is submitted). `map` gives results in the tasks' order;
    `submit` and `completed` let a caller start tasks that depend on others as soon as these
    finish (the results, taken in an order of the caller's, stay the same for any N)."""

    def __init__(self, jobs: int | None, tasks: int):
        self.n = workers(jobs, tasks)
        self._pool = None
        self._finished: queue.SimpleQueue = queue.SimpleQueue()  # ids of tasks done, as they finish
        self._seen: set[int] = set()  # those taken from the queue
        self._ids = itertools.count()

    def __enter__(self) -> "Workers":
        if self.n > 1:
            method = "fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn"
            self._pool = multiprocessing.get_context(method).Pool(self.n, initializer=_quiet_worker)
        return self

    def __exit__(self, *exc) -> None:
        if self._pool is not None:
            self._pool.terminate()  # what is left to run is not wanted (an error, an interruption)
            self._pool.join()

    def map(self, fn: Callable[[T], R], items: Iterable[T], advance: Callable[[int], None] = lambda n=1: None,
            cost: Callable[[T], float] | None = None) -> Iterator[R]:
        """fn(item) for each item, in order, as each is ready. On workers the tasks start at once
        (the caller may do other work meanwhile); in this process each is computed when asked, so
        that the caller may drop each result before the next is made. With `cost`, the workers
        take the costliest tasks first (the last ones to finish are then small)."""
        if self._pool is None:
            results = (fn(item) for item in items)
        elif cost is None:
            results = self._pool.imap(fn, items, chunksize=1)
        else:
            items = list(items)
            tasks = [None] * len(items)
            for k in sorted(range(len(items)), key=lambda k: -cost(items[k])):
                tasks[k] = self.submit(fn, items[k])
            results = (task.get() for task in tasks)
        return _advancing(results, advance)

    def submit(self, fn: Callable[[T], R], item: T) -> "Task":
        """Start fn(item) (in this process: run it now)."""
        task = Task(next(self._ids))
        if self._pool is None:
            task._result = _Done(fn(item))
            self._finished.put(task.id)
        else:
            done = lambda _: self._finished.put(task.id)  # noqa: E731 (run by the pool's result thread)
            task._result = self._pool.apply_async(fn, (item,), callback=done, error_callback=done)
        return task

    def completed(self, tasks: list["Task"]) -> Iterator[int]:
        """The indices in `tasks` of submitted tasks, each once, in the order they finish."""
        waiting = {t.id: k for k, t in enumerate(tasks)}
        while waiting:
            for done in [i for i in waiting if i in self._seen]:
                yield waiting.pop(done)
            if waiting:
                self._seen.add(self._finished.get())


def _advancing(results: Iterable[R], advance: Callable[[int], None]) -> Iterator[R]:
    for result in results:
        yield result
        advance(1)


class Task:
    """A submitted task: `get()` waits for its result (or raises its error)."""

    def __init__(self, key: int):
        self.id = key
        self._result = None

    def get(self):
        return self._result.get()


class _Done:
    """The result of a task run in this process (what `get` of a pool's result gives)."""

    def __init__(self, value):
        self.value = value

    def get(self):
        return self.value


def _quiet_worker() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # the parent's handler would raise inside a task
    if hasattr(signal, "SIGHUP"):
        signal.signal(signal.SIGHUP, signal.SIG_IGN)


def _tree_travels(tree: Tree):
    """How a tree is pickled between processes: its levels (at most 62) in a byte each."""
    return _tree_arrives, (tree.grid, tree.level.astype(np.uint8), tree.code)


def _tree_arrives(grid, level: np.ndarray, code: np.ndarray) -> Tree:
    return Tree(grid, level, code, canonical=True)


def _paving_travels(paving: Paving):
    """How a paving is pickled between processes: its undetermined cells' coordinates (below
    2^depth) in 32 bits when they fit."""
    cells = paving.undetermined
    small = cells.astype(np.int32) if paving.grid.depth < 31 else cells
    return _paving_arrives, (paving.grid, paving.inside, paving.outside, small, cells.dtype.str,
                             paving.per_level, paving.band)


def _paving_arrives(grid, inside: Tree, outside: Tree, cells: np.ndarray, dtype: str, per_level, band) -> Paving:
    return Paving(grid, inside, outside, cells.astype(dtype), per_level, band)


ForkingPickler.register(Tree, _tree_travels)
ForkingPickler.register(Paving, _paving_travels)
