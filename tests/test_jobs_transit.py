"""Large arrays and texts between the processes of `--jobs N` (`analyses/jobs.py`): while a pool
runs they cross through files in memory (/dev/shm), not the pipes, and arrive as sent (values,
dtype, shape; the memory order numpy's pickling gives); the files go once read, and the
pool's folder with the pool, also after an error or a killed run (by the next pool). Without /dev/shm, or when a
file cannot be written, they cross through the pipes as before."""

from __future__ import annotations

import os
import pickle
import time
from multiprocessing.reduction import ForkingPickler
from pathlib import Path

import numpy as np
import pytest

from fivebar_cli.analyses import jobs
from fivebar_cli.analyses.jobs import SPILL_BYTES, Texts, Workers

pytestmark = pytest.mark.skipif(not os.path.isdir(jobs.SPILL_ROOT), reason="no /dev/shm on this machine")


def _itself(x):
    return x


def _fails(x):
    raise ValueError("this task fails")


class _RemovesTheFilesSent:
    """Pickled after a large array in a task's result: removes the files the worker just wrote
    (as a cleaner of /dev/shm, such as systemd's RemoveIPC, would) before the parent reads them."""

    def __reduce__(self):
        for name in os.listdir(jobs._spill[0]):
            os.unlink(os.path.join(jobs._spill[0], name))
        return (int, ())


def _big_then_removed(x):
    return np.zeros(SPILL_BYTES), _RemovesTheFilesSent()


def _arrays():
    rng = np.random.default_rng(7)
    big = rng.normal(size=(300, 40))  # 96 000 bytes
    records = np.zeros(5000, [("level", np.uint8), ("code", np.int64), ("area", np.float64)])
    records["code"] = rng.integers(0, 1 << 40, 5000)
    return {
        "C float64": big,
        "Fortran order": np.asfortranarray(big),
        "a strided view": big[::2, ::3],
        "3-D int32": rng.integers(-9, 9, (20, 30, 40)).astype(np.int32),
        "bools": rng.random(200_000) < 0.5,
        "records": records,
        "datetimes": np.arange(10_000).astype("datetime64[s]"),
        "big-endian": big.astype(">f8"),
        "small": np.arange(5),
        "objects": np.array([{"a": 1}, "text", 3.5] * 4000, dtype=object),
    }


def _same_as_numpys_pickling(back: np.ndarray, a: np.ndarray) -> None:
    """The same dtype, shape and values as sent, in the memory order numpy's pickling gives."""
    plain = pickle.loads(pickle.dumps(a))
    assert back.dtype == a.dtype and back.shape == a.shape
    assert (back.flags.c_contiguous, back.flags.f_contiguous) == (plain.flags.c_contiguous, plain.flags.f_contiguous)
    if a.dtype.hasobject:
        assert back.tolist() == a.tolist()
    else:
        assert back.tobytes() == a.tobytes()


def test_arrays_cross_to_workers_and_back_as_numpy_pickles_them():
    arrays = _arrays()
    with Workers(2, 2) as pool:
        back = list(pool.map(_itself, list(arrays.values())))
        folder = pool._spill
        assert folder is not None and os.listdir(folder) == []  # every file read and removed
    for (name, a), b in zip(arrays.items(), back):
        _same_as_numpys_pickling(b, a)
    assert not os.path.exists(folder)


def test_a_large_array_is_a_file_name_in_the_pipe_a_small_one_its_bytes():
    big, small = np.ones(SPILL_BYTES // 8), np.ones(SPILL_BYTES // 8 - 1)
    with Workers(2, 2) as pool:
        message = ForkingPickler.dumps(big)
        assert len(message) < 1000 and len(os.listdir(pool._spill)) == 1
        assert len(ForkingPickler.dumps(small)) > small.nbytes
        assert np.array_equal(pickle.loads(message), big) and os.listdir(pool._spill) == []
    assert len(ForkingPickler.dumps(big)) > big.nbytes  # no pool: through the pipe


def test_the_folder_goes_with_its_pool_after_an_error_with_what_was_never_taken():
    with pytest.raises(ValueError, match="this task fails"):
        with Workers(2, 3) as pool:
            folder = pool._spill
            pool.submit(_itself, np.ones(100_000))  # its result never taken
            pool.submit(_fails, 1).get()
    assert not os.path.exists(folder)


def test_a_pool_that_cannot_start_leaves_no_folder(monkeypatch):
    made = []

    def no_pool(*args, **kwargs):
        made.append(jobs._spill[0])
        raise OSError("no more processes")

    monkeypatch.setattr(jobs, "Pool", no_pool)
    with pytest.raises(OSError, match="no more processes"):
        with Workers(2, 2):
            pass
    assert made[0] is not None and not os.path.exists(made[0]) and jobs._spill[0] is None


def test_a_killed_runs_folder_is_removed_by_the_next_pool_a_running_ones_kept():
    """A pool's folder is locked while the pool lives (the lock goes with its processes, however
    they end): one whose lock nothing holds is a killed run's, one locked is a running pool's."""
    import fcntl

    killed = Path(jobs.SPILL_ROOT) / f"{jobs.SPILL_PREFIX}test-killed-{os.getpid()}"
    running = Path(jobs.SPILL_ROOT) / f"{jobs.SPILL_PREFIX}test-running-{os.getpid()}"
    for folder in (killed, running):  # made whole, then named (another test's pool may look meanwhile)
        making = folder.with_name("making-" + folder.name)
        making.mkdir()
        (making / "1-0").write_bytes(b"\0" * 100)
        if folder == running:
            lock = os.open(making, os.O_RDONLY)
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        making.rename(folder)
    try:
        with Workers(2, 2) as pool:
            assert list(pool.map(_itself, [1, 2])) == [1, 2]
            with pytest.raises(BlockingIOError):  # this pool's own folder is locked too
                probe = os.open(pool._spill, os.O_RDONLY)
                try:
                    fcntl.flock(probe, fcntl.LOCK_EX | fcntl.LOCK_NB)
                finally:
                    os.close(probe)
        assert not killed.exists() and (running / "1-0").exists()
    finally:
        os.close(lock)
        for folder in (killed, running):
            if folder.exists():
                (folder / "1-0").unlink()
                folder.rmdir()


def test_a_folder_left_half_made_is_removed_after_a_minute():
    """A run killed between making its folder and naming it leaves `making-fivebar-pool-*`: the
    next pool removes it once it is a minute old (a younger one may be another pool's, being made)."""
    old, young = (Path(jobs.SPILL_ROOT) / f"making-{jobs.SPILL_PREFIX}test-{age}-{os.getpid()}"
                  for age in ("old", "young"))
    for folder in (old, young):
        folder.mkdir()
    os.utime(old, (time.time() - 2 * jobs.MAKING_SECONDS,) * 2)
    try:
        with Workers(2, 2) as pool:
            assert list(pool.map(_itself, [1, 2])) == [1, 2]
        assert not old.exists() and young.exists()
    finally:
        for folder in (old, young):
            if folder.exists():
                folder.rmdir()


def test_a_sigkilled_runs_folder_goes_with_the_next_pool():
    import fcntl
    import subprocess
    import sys

    script = ("import time\nfrom fivebar_cli.analyses.jobs import Workers\nwith Workers(2, 2) as pool:\n"
              "    list(pool.map(abs, [1, -2]))\n    print(pool._spill, flush=True)\n    time.sleep(60)\n")
    proc = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    folder = proc.stdout.readline().strip()
    proc.kill()
    proc.wait()
    proc.stdout.close()
    assert os.path.isdir(folder)  # left behind
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:  # its workers leave once their parent is gone
        try:
            probe = os.open(folder, os.O_RDONLY)
        except FileNotFoundError:  # the pool of a test running meanwhile (another xdist worker) came first
            break
        try:
            fcntl.flock(probe, fcntl.LOCK_SH | fcntl.LOCK_NB)
            break
        except BlockingIOError:
            time.sleep(0.05)
        finally:
            os.close(probe)
    with Workers(2, 2):
        pass
    assert not os.path.exists(folder)


def test_without_dev_shm_arrays_cross_through_the_pipes(monkeypatch, tmp_path):
    monkeypatch.setattr(jobs, "SPILL_ROOT", str(tmp_path / "none"))
    big = np.arange(100_000.0)
    with Workers(2, 2) as pool:
        assert pool._spill is None and len(ForkingPickler.dumps(big)) > big.nbytes
        assert np.array_equal(list(pool.map(_itself, [big, big]))[1], big)


def test_a_file_that_cannot_be_written_sends_the_bytes_through_the_pipe():
    big = np.arange(100_000.0)
    with Workers(2, 2) as pool:
        os.rmdir(pool._spill)  # as if the memory were full: no file can be made
        message = ForkingPickler.dumps(big)
        assert len(message) > big.nbytes and np.array_equal(pickle.loads(message), big)
        assert np.array_equal(list(pool.map(_itself, [big, big]))[0], big)


def test_texts_cross_as_one_array_and_arrive_as_the_same_strings():
    texts = Texts(("", "plain\n" * 30_000, "é, ∂θ, 🤖 and a NUL \0", "x"))
    with Workers(2, 2) as pool:
        assert len(ForkingPickler.dumps(texts)) < 1000  # the bytes in a file
        back = list(pool.map(_itself, [texts, Texts(())]))
    assert back == [tuple(texts), ()] and type(back[0]) is tuple
    assert pickle.loads(ForkingPickler.dumps(texts)) == tuple(texts)  # no pool: the same, in the pipe


@pytest.mark.timeout(60)
def test_a_result_whose_file_vanished_fails_instead_of_hanging():
    """The pool's thread that reads results stops on a file it cannot read (the result is lost):
    the wait fails with WorkerLost, not forever."""
    with pytest.raises(jobs.WorkerLost, match="could no longer be read"):
        with Workers(2, 2) as pool:
            pool.submit(_big_then_removed, 0).get()
