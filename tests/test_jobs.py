"""`--jobs N`: the independent pavings of a command on worker processes give the same bytes as in
process (`analyses/jobs.py`). `aspects` and `rpr3 pave` are compared in their own tests' fixtures
(tests/test_aspects_cli.py, tests/test_rpr3_octree.py); here the task runner itself, `tolerance`
and the 3-RPR's aspects, at small depths."""

from __future__ import annotations

import os
import signal
import sys
import time
from multiprocessing.reduction import ForkingPickler

import numpy as np
import psutil
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from cli_helpers import ENV, REPO, CliResult, command, default_ctrl_c, ok, one_line, run_cli

from fivebar_cli.analyses.jobs import Workers, WorkerLost, default_jobs, run_tasks, workers
from fivebar_cli.paving.engine import Paving
from fivebar_cli.paving.grid import Grid
from fivebar_cli.paving.tree import Tree

CONFIGS = REPO / "configs"


def _square_and_pid(x: int) -> tuple[int, int]:
    return x * x, os.getpid()


def _fails(x: int) -> int:
    if x == 3:
        raise ValueError(f"task {x} fails")
    return x


def test_results_come_back_in_task_order_from_other_processes():
    seen = []
    out = run_tasks(_square_and_pid, range(7), jobs=2, advance=seen.append)
    assert [v for v, _ in out] == [x * x for x in range(7)]
    assert seen == [1] * 7
    assert os.getpid() not in {pid for _, pid in out}
    assert {pid for _, pid in run_tasks(_square_and_pid, range(3), jobs=1)} == {os.getpid()}


def test_a_failing_task_raises_in_the_caller():
    with pytest.raises(ValueError, match="task 3 fails"):
        run_tasks(_fails, range(5), jobs=2)


CALLED = []


def _recorded(x: int) -> int:
    CALLED.append(x)
    return x


@pytest.mark.parametrize("jobs", [1, 2])
def test_tasks_started_when_those_they_need_finish(jobs):
    """Each second-round task is submitted when the first-round task it needs is done; every
    first-round index comes once; results taken in a fixed order are the same for any N."""
    with Workers(jobs, 4) as pool:
        first = [pool.submit(_square_and_pid, x) for x in (2, 3, 5)]
        then, order = {}, []
        for k in pool.completed(first):
            order.append(k)
            then[k] = pool.submit(_square_and_pid, first[k].get()[0])
        assert sorted(order) == [0, 1, 2]
        assert [then[k].get()[0] for k in range(3)] == [16, 81, 625]
        assert ({pid for _, pid in (t.get() for t in first)} == {os.getpid()}) == (jobs == 1)
        assert list(pool.map(_square_and_pid, [4]))[0][0] == 16  # the same workers, another round


@pytest.mark.parametrize("jobs", [1, 2])
def test_costliest_first_results_still_in_task_order(jobs):
    seen = []
    with Workers(jobs, 5) as pool:
        out = list(pool.map(_square_and_pid, range(5), seen.append, cost=lambda x: (x * 7) % 5))
    assert [v for v, _ in out] == [0, 1, 4, 9, 16] and seen == [1] * 5


def test_a_failing_submitted_task_raises_when_its_result_is_taken():
    with Workers(2, 2) as pool:
        tasks = [pool.submit(_fails, x) for x in (2, 3)]
        assert sorted(pool.completed(tasks)) == [0, 1]
        assert tasks[0].get() == 2
        with pytest.raises(ValueError, match="task 3 fails"):
            tasks[1].get()


def _dies(x: int) -> int:
    if x == 3:
        os.kill(os.getpid(), signal.SIGKILL)  # as the out-of-memory killer would
    time.sleep(0.05)
    return x


@pytest.mark.timeout(60)
@pytest.mark.parametrize("wait", ["get", "completed", "map", "map by cost"])
def test_a_killed_worker_fails_the_wait_instead_of_hanging(wait):
    """multiprocessing's pool replaces a dead worker and its task never finishes: every way of
    waiting for a result fails with WorkerLost (one line for the CLI), at once, not forever."""
    start = time.monotonic()
    with pytest.raises(WorkerLost, match=r"a worker process ended before its task was done \(killed by SIGKILL"):
        with Workers(2, 4) as pool:
            if wait == "get":
                [pool.submit(_dies, x) for x in (1, 2, 3, 4)][2].get()
            elif wait == "completed":
                list(pool.completed([pool.submit(_dies, x) for x in (1, 2, 3, 4)]))
            else:
                list(pool.map(_dies, [1, 2, 3, 4], cost=(lambda x: -x) if wait == "map by cost" else None))
    assert time.monotonic() - start < 20


def _worker_pipe():
    """In a worker: its pipe to the parent (`analyses.pool._serve`'s)."""
    import sys

    frame = sys._getframe()
    while "pipe" not in frame.f_locals:
        frame = frame.f_back
    return frame.f_locals["pipe"]


def _writes_half_a_result_and_dies(_) -> None:
    """A result message cut short: its length (1000 bytes) and 10 bytes of it, as a worker killed in
    the middle of a long write leaves it."""
    import struct

    os.write(_worker_pipe().fileno(), struct.pack("!i", 1000) + b"0123456789")
    time.sleep(0.2)
    os.kill(os.getpid(), signal.SIGKILL)


def _ends_in_time(body) -> bool:
    """Whether body() returned within 30 s (run in a thread: a hang fails the test, not the run)."""
    import threading

    done = threading.Thread(target=body, daemon=True)
    done.start()
    done.join(30)
    return not done.is_alive()


@pytest.mark.timeout(60)
@pytest.mark.parametrize("left", ["a result half written", "a task running, then an error",
                                  "every worker killed, one waiting for a task"])
def test_a_pool_whose_workers_were_killed_or_busy_still_ends(left):
    """Ending a pool kills its workers, whatever they do: multiprocessing's own pool could wait
    forever there (a queue's lock held or a message half written by a killed worker,
    python/cpython#96995; this suite hung on it once). Each case, deterministically: the `with`
    ends within seconds, with the error that ended it."""
    def body():
        expected = ValueError if left == "a task running, then an error" else WorkerLost
        with pytest.raises(expected):
            with Workers(2, 2) as pool:
                if left == "a result half written":
                    pool.submit(_writes_half_a_result_and_dies, None).get()
                task = pool.submit(time.sleep, 60)
                time.sleep(0.5)  # one worker in the task, the other waiting for the next one
                if left == "a task running, then an error":
                    raise ValueError("an error while a worker runs")
                for p in pool._pool.processes:
                    os.kill(p.pid, signal.SIGKILL)
                task.get()

    start = time.monotonic()
    assert _ends_in_time(body)
    assert time.monotonic() - start < 10


def _never_starts(*_) -> None:
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    time.sleep(600)


@pytest.mark.timeout(60)
def test_ending_a_pool_ends_workers_stuck_before_their_first_task():
    """Workers stuck in their set-up (here ignoring SIGTERM too) are killed when the pool ends."""
    import multiprocessing

    from fivebar_cli.analyses.pool import Pool

    pool = Pool(2, multiprocessing.get_context(), _never_starts)
    start = time.monotonic()
    pool.end()
    assert time.monotonic() - start < 10
    assert all(p.exitcode == -signal.SIGKILL for p in pool.processes)


def _signalled_before_its_set_up(previous_setup) -> None:
    """A worker's set-up that first receives SIGTERM (as from a `kill` of the process group at the
    moment it was forked), then sets its handlers."""
    os.kill(os.getpid(), signal.SIGTERM)
    previous_setup()


def _own_handlers(_) -> tuple:
    blocked = signal.pthread_sigmask(signal.SIG_BLOCK, [])
    return (sorted(int(s) for s in blocked if s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)),
            signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM))


@pytest.mark.timeout(60)
def test_signals_reach_a_worker_only_once_its_handlers_are_set():
    """A worker starts with the parent's handlers (the CLI's raise: a traceback in the worker):
    Ctrl-C, SIGTERM and SIGHUP are held back from its start until its set-up has run. A SIGTERM
    sent before then ends it as its own handler says (killed, no traceback); the others then run
    with the signals let through, and the parent's mask is as before."""
    import multiprocessing

    from fivebar_cli.analyses import jobs
    from fivebar_cli.analyses.pool import Pool

    def raising(signum, frame):
        raise RuntimeError("the parent's handler ran in a worker")

    previous = signal.signal(signal.SIGTERM, raising)
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, [])
    try:
        doomed = Pool(1, multiprocessing.get_context("fork"), _signalled_before_its_set_up,
                      (lambda: jobs._start_worker(None),))
        deadline = time.monotonic() + 10
        while doomed.lost is None and time.monotonic() < deadline:  # (the pool reaps it: not joined here too)
            time.sleep(0.01)
        doomed.end()
        assert "(killed by SIGTERM;" in str(doomed.lost)
        with Workers(2, 2) as pool:
            reports = [task.get() for task in [pool.submit(_own_handlers, k) for k in range(2)]]
        assert reports == [([], signal.SIG_IGN, signal.SIG_DFL)] * 2
        assert signal.pthread_sigmask(signal.SIG_BLOCK, []) == mask
    finally:
        signal.signal(signal.SIGTERM, previous)


def _large(x: int) -> np.ndarray:
    return np.full(100_000, x)  # 800 kB: through /dev/shm while a pool runs


@pytest.mark.timeout(120)
def test_spawned_workers_as_where_fork_is_missing(monkeypatch):
    """Where the platform cannot fork (macOS's default, Windows), workers are spawned: fresh
    interpreters that import the task's module. The same results in order, large arrays through
    the pool's folder, a task's error, the signals let through once the handlers are set."""
    from fivebar_cli.analyses import jobs

    monkeypatch.setattr(jobs.multiprocessing, "get_all_start_methods", lambda: ["spawn"])
    with Workers(2, 4) as pool:
        assert all(p._popen.method == "spawn" for p in pool._pool.processes)
        arrays = list(pool.map(_large, [1, 2, 3]))
        reports = [task.get() for task in [pool.submit(_own_handlers, k) for k in range(2)]]
        with pytest.raises(ValueError, match="task 3 fails"):
            pool.submit(_fails, 3).get()
    assert [(a.shape, int(a[0]), int(a[-1])) for a in arrays] == [((100_000,), k, k) for k in (1, 2, 3)]
    assert reports == [([], signal.SIG_IGN, signal.SIG_DFL)] * 2


def _made_or_failed(spec: tuple[int, bool]) -> np.ndarray:
    size, fails = spec
    if fails:
        raise ValueError(f"a task of {size} fails")
    return np.arange(size)  # 9,000 or more: 64 KiB or more, through the pool's folder


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.tuples(st.sampled_from([1, 100, 9_000, 20_000]), st.booleans()), min_size=1, max_size=8))
def test_any_tasks_give_on_workers_what_they_give_in_process(specs):
    """Whatever the tasks (small and large results, failures anywhere), two workers give each task
    what the task gives called here, and `completed` names each task once."""
    def outcome(get) -> list | str:
        try:
            return get().tolist()
        except ValueError as exc:
            return str(exc)

    with Workers(2, 2) as pool:  # (two workers even for one task)
        tasks = [pool.submit(_made_or_failed, spec) for spec in specs]
        assert sorted(pool.completed(tasks)) == list(range(len(specs)))
        found = [outcome(task.get) for task in tasks]
    assert found == [outcome(lambda: _made_or_failed(spec)) for spec in specs]


def _bad_input(_) -> None:
    from fivebar_cli.errors import InputError

    raise InputError("m.yaml", "lengths.L1", "must be positive, got -8")


class _Unpicklable(Exception):
    def __reduce__(self):
        raise TypeError("not for pickling")


def _raises_unpicklable(_) -> None:
    raise _Unpicklable("a lock inside")


def test_a_tasks_error_arrives_whole_with_where_it_was_raised():
    """A task's error is raised in the caller as itself (an InputError keeps its file, field and
    message: its one line is the CLI's), its worker's traceback as `__cause__`; an error that
    cannot be pickled arrives as a FivebarError naming it."""
    from fivebar_cli.errors import FivebarError, InputError

    with Workers(2, 2) as pool:
        with pytest.raises(InputError) as bad:
            pool.submit(_bad_input, None).get()
        with pytest.raises(FivebarError, match="^_Unpicklable: a lock inside$"):
            pool.submit(_raises_unpicklable, None).get()
        assert pool.submit(_square_and_pid, 4).get()[0] == 16  # the pool still works
    parts = ("m.yaml", "lengths.L1", "must be positive, got -8")
    assert (bad.value.source, bad.value.field, bad.value.message) == parts
    assert str(bad.value) == "m.yaml: lengths.L1: must be positive, got -8"
    assert "in _bad_input" in str(bad.value.__cause__) and 'raise InputError("m.yaml"' in str(bad.value.__cause__)


@pytest.mark.timeout(60)
def test_when_the_parent_is_killed_its_workers_exit():
    """A run SIGKILLed (nothing of it runs any more to end its pool) leaves no worker behind: each
    reads the end of its pipe and exits."""
    import subprocess

    script = ("import sys, time\nfrom fivebar_cli.analyses.jobs import Workers\nwith Workers(2, 2) as pool:\n"
              "    print(*[p.pid for p in pool._pool.processes], flush=True)\n    time.sleep(60)\n")
    run = subprocess.Popen([sys.executable, "-c", script], env=ENV, stdout=subprocess.PIPE, text=True)
    with run.stdout:
        children = [psutil.Process(int(pid)) for pid in run.stdout.readline().split()]
    run.kill()
    run.wait(10)
    _, alive = psutil.wait_procs(children, timeout=10)
    for child in alive:  # (not to outlive the test)
        child.kill()
    assert len(children) == 2 and not alive


def _children(pid: int) -> list:
    """The processes `pid` started (psutil's, as tests/test_atlas_dask.py reads them)."""
    try:
        return psutil.Process(pid).children()
    except psutil.Error:  # a process that has just ended
        return []


def _running(processes: list) -> list:
    """Those of `processes` still running (a zombie has ended)."""
    def runs(p) -> bool:
        try:
            return p.status() != psutil.STATUS_ZOMBIE
        except psutil.NoSuchProcess:
            return False

    return [p for p in processes if runs(p)]


@pytest.mark.timeout(120)
@pytest.mark.parametrize("signum, status, what",
                         [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")])
def test_ctrl_c_or_sigterm_while_workers_run_ends_the_run_and_its_workers(tmp_path, signum, status, what):
    """`aspects --jobs 2` stopped while its pool runs the pavings: one line, the signal's status, at
    once, no worker left running and nothing written (the suite's other interruption tests run
    without workers)."""
    import subprocess

    run = subprocess.Popen(command(["aspects", CONFIGS / "m1.yaml", "--depth", "14", "--jobs", "2", "-o",
                                    tmp_path / "out", "-q", "--no-plot"]), env=ENV, stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True, preexec_fn=default_ctrl_c)
    deadline = time.monotonic() + 60
    while len(workers := _children(run.pid)) < 2 and run.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    assert len(workers) >= 2, "the run started no workers"
    time.sleep(0.2)  # the workers in their first tasks
    sent = time.monotonic()
    run.send_signal(signum)
    out, err = run.communicate(timeout=60)
    assert time.monotonic() - sent < 10
    one_line(CliResult(run.returncode, out, err), status, what)
    assert not _running(workers)
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").rglob("*.qt"))


def test_in_process_results_are_made_as_they_are_taken():
    """With one job, `map` computes each result when the caller asks for it (the caller writes and
    drops one aspect's files before the next are made)."""
    CALLED.clear()
    with Workers(1, 3) as pool:
        results = pool.map(_recorded, [1, 2, 3])
        assert next(results) == 1 and CALLED == [1]
        assert list(results) == [2, 3] and CALLED == [1, 2, 3]


def _touch(path: str) -> str:
    open(path, "w").close()
    return path


@pytest.mark.parametrize("cost", [None, len])
def test_on_workers_map_starts_the_tasks_before_their_results_are_taken(tmp_path, cost):
    """With workers, `map` starts every task when called (the caller does other work meanwhile,
    e.g. the crossings while the shapes are measured): their files appear before any result is taken."""
    import time

    paths = [str(tmp_path / name) for name in ("a", "bb", "ccc")]
    with Workers(2, 3) as pool:
        results = pool.map(_touch, paths, cost=cost)
        deadline = time.monotonic() + 30
        while not all(os.path.exists(p) for p in paths) and time.monotonic() < deadline:
            time.sleep(0.01)
        assert all(os.path.exists(p) for p in paths)
        assert list(results) == paths


def _itself(x):
    return x


def _random_paving(dim: int, depth: int, seed: int) -> Paving:
    """Random disjoint cells of a grid as inside, outside and undetermined parts (a few per level)."""
    rng = np.random.default_rng(seed)
    grid = Grid(((-1.0, 1.0),) * dim, depth, (False,) * dim)
    n = 1 << depth
    coords = np.unique(rng.integers(0, n, (300, dim)), axis=0)
    rng.shuffle(coords)
    inside, outside, und = np.array_split(coords, 3)
    return Paving(grid, Tree.from_cells(grid, depth, inside), Tree.from_cells(grid, depth, outside),
                  und, tuple(range(depth + 1)), Tree.from_cells(grid, depth, inside[:5]))


@pytest.mark.parametrize("dim, depth", [(2, 26), (3, 17), (1, 40)])
def test_trees_and_pavings_travel_compact_and_arrive_the_same(dim, depth):
    """Between processes a tree's levels travel in a byte and a paving's undetermined cells in 32
    bits when below 2^31 (1-D at depth 40: not): what arrives equals what left, in the same dtypes,
    in another process."""
    paving = _random_paving(dim, depth, depth)
    tree = paving.inside
    assert tree.level.max() == depth and tree.code.max() >= 1 << (dim * depth - 4)  # large codes
    plain = len(ForkingPickler.dumps(tree.level)) + len(ForkingPickler.dumps(tree.code))
    assert len(ForkingPickler.dumps(tree)) < 0.7 * plain
    with Workers(2, 2) as pool:
        back_tree, back = pool.map(_itself, [tree, paving])
    assert back_tree == tree and back_tree.level.dtype == tree.level.dtype == np.int64
    for name in ("inside", "outside", "band"):
        assert getattr(back, name) == getattr(paving, name)
    assert back.undetermined.dtype == paving.undetermined.dtype == np.int64
    assert np.array_equal(back.undetermined, paving.undetermined)
    assert back.per_level == paving.per_level and back.grid == paving.grid


def test_worker_count():
    assert workers(1, 10) == 1 and workers(4, 2) == 2 and workers(3, 0) == 1
    assert workers(None, 1000) == default_jobs() >= 1


def _same_files(a, b):
    names = sorted(p.relative_to(a).as_posix() for p in a.rglob("*") if p.is_file() and ".fivebar" not in p.parts)
    assert names and names == sorted(p.relative_to(b).as_posix() for p in b.rglob("*")
                                     if p.is_file() and ".fivebar" not in p.parts)
    for name in names:
        assert (a / name).read_bytes() == (b / name).read_bytes(), name


@pytest.mark.parametrize("args", [
    ("tolerance", CONFIGS / "m1.yaml", "--tolerances", "0,0.05", "--depth", "5"),
    ("aspects", CONFIGS / "rpr3-caro.yaml", "--depth", "3"),
], ids=["tolerance", "rpr3-aspects"])
def test_same_bytes_on_one_and_two_processes(tmp_path, args):
    for jobs in ("1", "2"):
        ok(run_cli(*args, "--no-plot", "-q", "--jobs", jobs, "-o", tmp_path / jobs))
    _same_files(tmp_path / "1", tmp_path / "2")


def test_jobs_must_be_positive(tmp_path):
    one_line(run_cli("aspects", CONFIGS / "m1.yaml", "--jobs", "0", "-o", tmp_path), 2, "--jobs")


def _killed(task):
    os.kill(os.getpid(), signal.SIGKILL)


@pytest.mark.timeout(60)
def test_a_worker_killed_during_aspects_is_one_line_and_exit_1(tmp_path, monkeypatch):
    """The command fails with the failure contract (no traceback, nothing half-written) when a
    worker dies during a mode region's task (the forked workers run the patched task)."""
    monkeypatch.setattr("fivebar_cli.analyses.aspects._region_task", _killed)
    r = run_cli("aspects", CONFIGS / "m1.yaml", "--depth", "6", "--jobs", "2", "-o", tmp_path / "out", "--no-plot")
    one_line(r, 1, "a worker process ended before its task was done (killed by SIGKILL; out of memory?)")
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").rglob("*.qt"))
