"""Worker processes for `analyses.jobs`: each worker has a pipe of its own to this process, and
one thread here hands the tasks out and takes the results back.

Why not `multiprocessing.Pool`: its workers share two queues, each guarded by a lock that a
worker holds while it reads or writes. Every early end of a run (an error, Ctrl-C, a lost worker)
kills the workers, and one killed at such a moment leaves the lock held or a message half
written: the pool's `terminate()` then waits forever (python/cpython#96995), and ending it
safely meant reaching into its private threads and queues. Here nothing is shared between the
workers: a killed worker's pipe just ends (the thread reads EOF, never half a message as a
whole one), and ending the pool is to kill the workers, wake the thread and join them.

- A task's function and argument are pickled (with `ForkingPickler`: the reductions registered
  for it apply) by the caller when it submits, so a task that cannot travel fails there.
- Tasks start in the order they are submitted, each on the first worker free.
- A worker that dies, killed or out of memory, is never replaced: every task not yet done fails
  at once with `WorkerLost`, and so does every later one.
- `initializer(*initargs)` sets each worker up (its signal handlers, its folders); Ctrl-C,
  SIGTERM and SIGHUP are held back from a worker's start until that is done (`_held_back`).
- Forked workers close the ends of the pipes they inherit but do not use, so when this process
  dies (SIGKILL) each worker reads EOF and exits.
- Spawned workers do not import this process's main module again (`main_left_out`): a script
  that runs an analysis at its top level, without `if __name__ == "__main__":`, runs once.
"""

from __future__ import annotations

import collections
import pickle
import signal
import sys
import threading
import types
import traceback
from contextlib import contextmanager
from multiprocessing import connection
from multiprocessing.reduction import ForkingPickler
from typing import Callable

from fivebar_cli.errors import FivebarError

TURN = 0.25  # seconds a wait lasts before it is taken up again (signal handlers run between turns)
# held back from a worker's start until it has set its own handlers (`_serve`): before that, the
# parent's handler (the CLI's, which raises) would run in the worker and print a traceback there
HELD = {getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name)}
UNREADABLE = ("the workers' results could no longer be read (their files in /dev/shm removed?): "
              "run again, or with fewer jobs")


class WorkerLost(FivebarError):
    """A worker process ended before its task was done (the task is lost with it)."""


class RemoteTraceback(Exception):
    """Where a task failed in its worker: the traceback there, as text (the error's `__cause__`)."""

    def __str__(self) -> str:
        return self.args[0]


class Outcome:
    """A submitted task's result: `get()` waits for it (or raises the task's error)."""

    __slots__ = ("data", "done", "value", "error", "callback")

    def __init__(self, data, callback: Callable[[], None]):
        self.data, self.callback = data, callback
        self.done = threading.Event()
        self.value = self.error = None

    def get(self):
        while not self.done.wait(TURN):  # in turns: a signal's handler runs between them
            pass
        if self.error is not None:
            raise self.error
        return self.value

    def settle(self, value=None, error: BaseException | None = None) -> None:
        self.value, self.error, self.data = value, error, None
        self.done.set()
        self.callback()


class Pool:
    """`n` worker processes of `context` (a multiprocessing context: fork or spawn)."""

    def __init__(self, n: int, context, initializer: Callable, initargs: tuple = ()):
        self.processes, self._pipes = [], []
        inherit = context.get_start_method() == "fork"
        try:
            for _ in range(n):
                here, there = context.Pipe()
                self._pipes.append(here)
                process = context.Process(target=_serve, daemon=True,
                                          args=(there, self._pipes if inherit else [], initializer, initargs))
                with _held_back(), main_left_out(not inherit):
                    process.start()
                self.processes.append(process)
                there.close()  # (before the next fork: only its worker holds it, so its death ends the pipe)
        except BaseException:
            self._kill()
            for pipe in self._pipes:
                pipe.close()
            raise
        self._wake_here, self._wake_there = context.Pipe(duplex=False)  # (after the forks: no worker holds it)
        self._lock = threading.Lock()
        self._pending: collections.deque[Outcome] = collections.deque()  # submitted, not yet sent to a worker
        self._ending = False
        self.lost: WorkerLost | None = None
        self._thread = threading.Thread(target=self._hand_out, name="fivebar-pool", daemon=True)
        self._thread.start()

    def submit(self, fn: Callable, item, callback: Callable[[], None]) -> Outcome:
        """Start fn(item) on the first worker free; `callback()` (on the pool's thread) once it is done."""
        outcome = Outcome(ForkingPickler.dumps((fn, item)), callback)
        with self._lock:
            lost = self.lost
            if lost is None:
                self._pending.append(outcome)
        if lost is None:
            self._wake_there.send_bytes(b"")
        else:
            outcome.settle(error=lost)
        return outcome

    def end(self) -> None:
        """Kill the workers (what they run is not wanted any more), then end the thread."""
        self._ending = True
        self._kill()
        self._wake_there.send_bytes(b"")
        self._thread.join()
        for pipe in (*self._pipes, self._wake_here, self._wake_there):
            pipe.close()

    def _kill(self) -> None:
        for process in self.processes:
            process.kill()
        for process in self.processes:
            process.join()

    def _hand_out(self) -> None:
        """The pool's thread: send each pending task to a free worker, take the results back as
        they come; a worker that ends fails every unfinished task (`_lose`)."""
        free = list(reversed(range(len(self.processes))))
        busy: dict[int, Outcome] = {}  # worker -> the task it runs (with the pending ones: the unfinished)
        ends = {process.sentinel for process in self.processes}
        try:
            while not self._ending:
                with self._lock:
                    sends = [(free.pop(), self._pending.popleft()) for _ in range(min(len(free), len(self._pending)))]
                busy.update(sends)  # (all of them before any is sent: a send that fails loses none)
                for k, outcome in sends:
                    self._pipes[k].send_bytes(outcome.data)
                    outcome.data = None
                ready = connection.wait([self._wake_here, *(self._pipes[k] for k in busy), *ends])
                while self._wake_here.poll():
                    self._wake_here.recv_bytes()
                for k in [k for k in busy if self._pipes[k] in ready]:  # results before deaths: sent first
                    data = self._pipes[k].recv_bytes()
                    free.append(k)
                    self._finish(busy.pop(k), data)
                if any(r in ends for r in ready) and not self._ending:
                    self._lose(busy)
                    return
        except (EOFError, OSError):  # a pipe that ended (in the middle of a message): its worker died
            if not self._ending:
                self._lose(busy)
        except BaseException as exc:  # noqa: BLE001 - never leave a caller waiting
            self._lose(busy, f"the pool's thread failed ({type(exc).__name__}: {exc})")

    def _finish(self, outcome: Outcome, data: bytes) -> None:
        try:
            ok, value, where = pickle.loads(data)
        except Exception:  # noqa: BLE001 - e.g. a result's array file removed by someone else
            outcome.settle(error=WorkerLost(UNREADABLE))
            return
        if ok:
            outcome.settle(value)
        else:
            value.__cause__ = RemoteTraceback(where)
            outcome.settle(error=value)

    def _lose(self, busy: dict[int, Outcome], why: str | None = None) -> None:
        """Fail every unfinished task (those `busy` workers run, those pending), and every later
        one, with WorkerLost: a worker ended (`why` None: the first one found ended, with how it
        ended) or the thread failed (`why`)."""
        if why is None:
            ended = connection.wait([process.sentinel for process in self.processes], TURN)
            exitcode = None
            for process in self.processes:
                if process.sentinel in ended:
                    process.join()  # (reaped: its exit status)
                    exitcode = process.exitcode
                    break
            how = ("ended" if exitcode is None else f"killed by {signal.Signals(-exitcode).name}" if exitcode < 0
                   else f"exit status {exitcode}")
            why = f"a worker process ended before its task was done ({how}; out of memory?)"
        with self._lock:
            self.lost = WorkerLost(f"{why}: run again, or with fewer jobs")
            unfinished = [*busy.values(), *self._pending]
            self._pending.clear()
        busy.clear()
        for outcome in unfinished:
            outcome.settle(error=self.lost)


def _serve(pipe, inherited: list, initializer: Callable, initargs: tuple) -> None:
    """A worker: run the tasks that come through `pipe`, one at a time, and send each result (or
    error) back, until the pipe ends."""
    for other in inherited:  # this process's copies of the parent's ends (forked): its death must end them
        other.close()
    initializer(*initargs)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, HELD)  # (one sent meanwhile acts now, as the worker's handlers say)
    while True:
        try:
            data = pipe.recv_bytes()
        except (EOFError, OSError):  # the parent is gone, or ended the pool
            return
        try:
            fn, item = pickle.loads(data)
            reply = ForkingPickler.dumps((True, fn(item), None))
        except BaseException as exc:  # noqa: BLE001 - every failure goes back to the caller
            reply = _failure(exc)
        del data
        try:
            pipe.send_bytes(reply)
        except OSError:
            return


@contextmanager
def _held_back():
    """HELD signals blocked in this thread while it starts a worker (which starts with them blocked,
    forked or spawned, and lets them through once its handlers are set); here, delivered after."""
    if not hasattr(signal, "pthread_sigmask"):  # (Windows)
        yield
        return
    before = signal.pthread_sigmask(signal.SIG_BLOCK, HELD)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)


@contextmanager
def main_left_out(spawning: bool = True):
    """Worker processes started meanwhile (`spawning`: by spawn or forkserver) do not import this
    process's main module. multiprocessing has each one import it again (so that functions defined
    there can be unpickled), which runs a script's top level once more in every worker: a script
    calling `fb.aspects(..., jobs=2)` or `fb.atlas(..., workers=2)` without `if __name__ ==
    "__main__":` would start its analysis again there, and fail with a wall of tracebacks. Workers
    of fivebar run fivebar's functions only, so `__main__` is a stand-in with neither file nor
    spec meanwhile (as in a notebook, or `python -c`). Nothing changes where there is no such file."""
    main = sys.modules.get("__main__")
    if not spawning or main is None or (getattr(main, "__spec__", None) is None
                                        and getattr(main, "__file__", None) is None):
        yield
        return
    stand_in = types.ModuleType("__main__")
    sys.modules["__main__"] = stand_in
    try:
        yield
    finally:
        if sys.modules.get("__main__") is stand_in:
            sys.modules["__main__"] = main


def _failure(exc: BaseException):
    """The message of a failed task: its error (or, if that cannot travel, a FivebarError saying
    what it was) with the traceback in the worker."""
    where = "".join(traceback.format_exception(type(exc), exc, exc.__traceback__))
    try:
        return ForkingPickler.dumps((False, exc, where))
    except Exception:  # noqa: BLE001 - an error that cannot be pickled
        return ForkingPickler.dumps((False, FivebarError(f"{type(exc).__name__}: {exc}"), where))
