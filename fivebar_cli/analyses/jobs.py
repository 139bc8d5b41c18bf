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
the workers cost the parent. Arrays of 64 KiB or more (and the texts a task gives back,
`Texts`) do not go through the pipes at all while a pool runs: the sender writes their bytes to
a file in memory (/dev/shm, in a folder of the pool's) and the pipe carries its name; the
receiver reads and removes it (`_array_travels`). Through a pipe of 64 KiB, megabytes go in
hundreds of turns between two processes, each waiting for the other's GIL; through a file, in
one copy each way. The folder goes with the pool; one left by a killed run (its lock gone with
its processes) is removed by the next pool (`_clear_stale`). Without /dev/shm (or when it is
full) arrays go through the pipes as before. The processes themselves are `analyses.pool`'s (a
pipe of its own to each worker, no lock shared between them): workers ignore Ctrl-C and SIGHUP
and die on SIGTERM, so the parent alone reacts to signals; when it stops (an interruption, an
error) it kills its workers and the run ends at once. A worker that dies (killed, out of memory)
fails every unfinished task with one line (`WorkerLost`) instead of a wait forever.
"""

from __future__ import annotations

import itertools
import multiprocessing
import os
import queue
import shutil
import signal
import tempfile
import time
from multiprocessing.reduction import ForkingPickler
from typing import Callable, Iterable, Iterator, TypeVar

import numpy as np

from fivebar_cli.analyses.limits import check_count
from fivebar_cli.analyses.pool import TURN, Pool, WorkerLost
from fivebar_cli.paving.engine import Paving
from fivebar_cli.paving.tree import Tree

T = TypeVar("T")
R = TypeVar("R")
__all__ = ["Texts", "WorkerLost", "Workers", "default_jobs", "run_tasks", "workers"]


def default_jobs() -> int:
    """One worker per core this process may run on."""
    try:
        return max(len(os.sched_getaffinity(0)), 1)
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def workers(jobs: int | None, tasks: int) -> int:
    """How many processes `jobs` gives for this many tasks (1: run them in this process); `jobs`
    is None (one per core) or at least 1 (InputError: 0 or -1, "every core" in some libraries,
    would otherwise run in one process without a word)."""
    check_count(jobs, "jobs", 1, none="None: one per core")
    return max(1, min(default_jobs() if jobs is None else int(jobs), tasks))


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
        self._pool: Pool | None = None
        self._finished: queue.SimpleQueue = queue.SimpleQueue()  # ids of tasks done, as they finish
        self._seen: set[int] = set()  # those taken from the queue
        self._ids = itertools.count()

    def __enter__(self) -> "Workers":
        if self.n > 1:
            method = "fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn"
            self._spill, self._lock = _spill_folder() or (None, None)
            self._outer, _spill[0] = _spill[0], self._spill
            try:
                self._pool = Pool(self.n, multiprocessing.get_context(method), _start_worker, (self._spill,))
            except BaseException:
                self._release()
                raise
        return self

    def __exit__(self, *exc) -> None:
        if self._pool is not None:
            self._pool.end()  # what is left to run is not wanted (an error, an interruption)
            self._release()

    def _release(self) -> None:
        """Remove the pool's folder, with the arrays of tasks never run or results never taken."""
        _spill[0] = self._outer
        if self._spill is not None:
            shutil.rmtree(self._spill, ignore_errors=True)
            os.close(self._lock)

    def map(self, fn: Callable[[T], R], items: Iterable[T], advance: Callable[[int], None] = lambda n=1: None,
            cost: Callable[[T], float] | None = None) -> Iterator[R]:
        """fn(item) for each item, in order, as each is ready. On workers the tasks start at once
        (the caller may do other work meanwhile); in this process each is computed when asked, so
        that the caller may drop each result before the next is made. With `cost`, the workers
        take the costliest tasks first (the last ones to finish are then small)."""
        if self._pool is None:
            results = (fn(item) for item in items)
        else:
            items = list(items)
            order = range(len(items)) if cost is None else sorted(range(len(items)), key=lambda k: -cost(items[k]))
            tasks = [None] * len(items)
            for k in order:
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
            task._result = self._pool.submit(fn, item, lambda: self._finished.put(task.id))
        return task

    def completed(self, tasks: list["Task"]) -> Iterator[int]:
        """The indices in `tasks` of submitted tasks, each once, in the order they finish
        (WorkerLost once a worker died: the others may never finish)."""
        waiting = {t.id: k for k, t in enumerate(tasks)}
        while waiting:
            for done in [i for i in waiting if i in self._seen]:
                yield waiting.pop(done)
            while waiting and not self._seen.intersection(waiting):
                if self._pool is not None and self._pool.lost is not None:
                    raise self._pool.lost
                try:
                    self._seen.add(self._finished.get(timeout=TURN))  # (in turns: signals are handled)
                except queue.Empty:
                    pass


def _advancing(results: Iterable[R], advance: Callable[[int], None]) -> Iterator[R]:
    for result in results:
        yield result
        advance(1)


class Task:
    """A submitted task: `get()` waits for its result (or raises its error)."""

    def __init__(self, key: int):
        self.id = key
        self._result = None  # the pool's `Outcome`, or `_Done` for a task run here

    def get(self):
        return self._result.get()


class _Done:
    """The result of a task run in this process (what a pool's `Outcome` gives)."""

    def __init__(self, value):
        self.value = value

    def get(self):
        return self.value


def _start_worker(spill: str | None) -> None:
    """A worker: its pool's folder for large arrays in transit; signals left to the parent."""
    _spill[0] = spill
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


# ---------------------------------------------------------------- large arrays through memory files

SPILL_BYTES = 1 << 16  # arrays from this size travel through a file in memory: one pipe's buffer
SPILL_ROOT = "/dev/shm"
SPILL_PREFIX = "fivebar-pool-"
MAKING_SECONDS = 60.0  # a folder still being made after this long was left by a killed run
_spill: list[str | None] = [None]  # the folder of the pool this process runs or works in
_names = itertools.count()


def _spill_folder() -> tuple[str, int] | None:
    """A new folder in memory for a pool's arrays in transit, and an open descriptor of it that
    holds a lock on it while the pool lives (None: none can be made here)."""
    if not os.path.isdir(SPILL_ROOT):  # (Linux: not on macOS or Windows)
        return None
    import fcntl

    _clear_stale()
    try:  # made under another name, locked, then named: `_clear_stale` never sees it unlocked
        making = tempfile.mkdtemp(prefix=f"making-{SPILL_PREFIX}", dir=SPILL_ROOT)
    except OSError:
        return None
    fd = None
    try:
        fd = os.open(making, os.O_RDONLY)
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        folder = os.path.join(SPILL_ROOT, os.path.basename(making).removeprefix("making-"))
        os.rename(making, folder)
    except OSError:
        if fd is not None:
            os.close(fd)
        shutil.rmtree(making, ignore_errors=True)
        return None
    return folder, fd


def _clear_stale() -> None:
    """Remove the folders of pools that are gone (a SIGKILL leaves its folder behind): those whose
    lock nothing holds any more (a lock goes with the processes that held it), and those still
    being made a minute after (a run killed in the microseconds between making and naming one)."""
    import fcntl

    try:
        entries = list(os.scandir(SPILL_ROOT))
    except OSError:
        return
    for entry in entries:
        made = entry.name.startswith(SPILL_PREFIX)
        left_half_made = entry.name.startswith("making-" + SPILL_PREFIX) and _age(entry) > MAKING_SECONDS
        if not (made or left_half_made):
            continue
        try:
            fd = os.open(entry.path, os.O_RDONLY)
        except OSError:  # gone meanwhile, or another user's
            continue
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            shutil.rmtree(entry.path, ignore_errors=True)
        except OSError:  # locked: its pool runs
            pass
        finally:
            os.close(fd)


def _age(entry: os.DirEntry) -> float:
    try:
        return time.time() - entry.stat().st_mtime
    except OSError:  # gone meanwhile
        return 0.0


def _array_travels(a: np.ndarray):
    """How an array is pickled between processes: a large one, while a pool runs, as the name of
    a file holding its bytes (in its memory order: C, or F for a Fortran-ordered array, as numpy's
    own pickling keeps it); others, and any the file cannot take, as numpy pickles them."""
    folder = _spill[0]
    if folder is None or a.nbytes < SPILL_BYTES or a.dtype.hasobject:
        return a.__reduce__()
    transposed = a.flags.f_contiguous and not a.flags.c_contiguous
    data = a.T if transposed else np.ascontiguousarray(a)
    path = os.path.join(folder, f"{os.getpid()}-{next(_names)}")
    try:
        with open(path, "xb") as fh:
            fh.write(data.reshape(-1).view(np.uint8))
    except OSError:  # full, or the folder went with its pool: through the pipe after all
        try:
            os.unlink(path)
        except OSError:
            pass
        return a.__reduce__()
    return _array_arrives, (path, data.dtype, data.shape, transposed)


def _array_arrives(path: str, dtype: np.dtype, shape: tuple, transposed: bool) -> np.ndarray:
    a = np.fromfile(path, dtype).reshape(shape)
    os.unlink(path)
    return a.T if transposed else a


class Texts(tuple):
    """Texts a task gives back (a tuple of str), which travel between processes as one array of
    their UTF-8 bytes, so large ones through a file in memory (`_array_travels`); a plain tuple
    arrives."""


def _texts_travel(texts: Texts):
    data = [t.encode() for t in texts]
    return _texts_arrive, (np.frombuffer(b"".join(data), np.uint8), [len(d) for d in data])


def _texts_arrive(data: np.ndarray, lengths: list[int]) -> tuple[str, ...]:
    raw, out, start = data.tobytes(), [], 0
    for length in lengths:
        out.append(raw[start:start + length].decode())
        start += length
    return tuple(out)


ForkingPickler.register(np.ndarray, _array_travels)
ForkingPickler.register(Texts, _texts_travel)
