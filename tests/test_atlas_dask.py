"""`fivebar atlas` on Dask (issue 13): the same `atlas.csv` bytes in this process, on a local cluster
of 2 workers and on an external cluster (a real `dask scheduler` and `dask worker` started here on
127.0.0.1); killed runs (SIGKILL, Ctrl-C to the whole process group) leave whole parts and no
`atlas.csv`, and their reruns compute only the missing batches and give the same bytes.

Dask runs are `python -m fivebar_cli` subprocesses (cli_helpers.run_process): a local cluster starts
worker processes, and signals need a process of their own. The client of the external cluster runs
in this process (its workers are processes already).
"""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import psutil
import pytest
from cli_helpers import ENV, CliResult, check_whole, command, default_ctrl_c, ok, one_line, run_cli, run_process

DASK = Path(sys.executable).with_name("dask")


@pytest.fixture(scope="module")
def reference(spec_file, tmp_path_factory) -> bytes:
    """atlas.csv of the in-process run (`--workers 0`)."""
    root = tmp_path_factory.mktemp("reference")
    ok(run_cli("atlas", spec_file, "--workers", "0", "-o", "out", "--no-plot", "-q", cwd=root))
    return (root / "out" / "atlas.csv").read_bytes()


def done_before(stdout: str) -> int:
    return int(re.search(r"(\d+) done before", stdout).group(1))


def test_local_cluster_of_two_workers_writes_the_same_bytes(spec_file, reference, tmp_path):
    """Also with Dask's default dashboard port taken (another cluster on the machine): no warning."""
    with socket.socket() as taken:
        try:
            taken.bind(("", 8787))
            taken.listen()
        except OSError:  # already in use: by another cluster, which is the case under test
            pass
        r = ok(run_process("atlas", spec_file, "--workers", "2", "-o", "out", "--no-plot", cwd=tmp_path))
    assert "on a local cluster of 2 worker processes (2 workers connected)" in r.stdout
    assert r.stderr == ""  # Dask's log lines and warnings are silenced
    assert (tmp_path / "out" / "atlas.csv").read_bytes() == reference


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _stop(proc: subprocess.Popen) -> None:
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=15)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def test_external_scheduler_writes_the_same_bytes(spec_file, reference, tmp_path):
    """A `dask scheduler` and one `dask worker` on 127.0.0.1, started and stopped here. The worker
    runs without a nanny (in the `dask worker` process, not in one more it would spawn), and the
    run is in this process (a client needs no process of its own): the batches still cross to
    another process over TCP."""
    address = f"tcp://127.0.0.1:{_free_port()}"
    log = tmp_path / "scheduler.log"
    procs = []
    try:
        with open(log, "wb") as fh:
            procs.append(subprocess.Popen([DASK, "scheduler", "--host", "127.0.0.1", "--port", address.rsplit(":", 1)[1],
                                           "--no-dashboard"], stdout=fh, stderr=fh, env=ENV, cwd=tmp_path))
        procs.append(subprocess.Popen([DASK, "worker", address, "--nthreads", "1", "--no-nanny", "--no-dashboard",
                                       "--host", "127.0.0.1"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                      env=ENV, cwd=tmp_path))
        deadline = time.monotonic() + 60
        while "Register worker" not in log.read_text(errors="replace"):
            assert time.monotonic() < deadline and all(p.poll() is None for p in procs), log.read_text()[-2000:]
            time.sleep(0.1)
        r = ok(run_cli("atlas", spec_file, "--scheduler", address, "-o", "out", "--no-plot", cwd=tmp_path))
        assert f"on the cluster at {address} (1 worker connected)" in r.stdout
        assert r.stderr == ""
        assert (tmp_path / "out" / "atlas.csv").read_bytes() == reference
    finally:
        for proc in reversed(procs):
            _stop(proc)


def _run_until_parts(args, cwd: Path, parts: Path, sig: int, group: bool) -> tuple[CliResult, int]:
    """Start `fivebar ARGS` in its own session; send `sig` (to its whole process group when `group`,
    as Ctrl-C in a terminal does) once it has written a part. Returns its result and process group."""
    proc = subprocess.Popen(command(args), cwd=cwd, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True, preexec_fn=default_ctrl_c)
    before = set(parts.glob("part-*.csv")) if parts.exists() else set()
    try:
        deadline = time.monotonic() + 120
        while proc.poll() is None and time.monotonic() < deadline:
            if parts.exists() and set(parts.glob("part-*.csv")) - before:
                break
            time.sleep(0.002)
        assert proc.poll() is None, ("the run ended before the signal", proc.communicate())
        os.killpg(proc.pid, sig) if group else proc.send_signal(sig)
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate()
    return CliResult(proc.returncode, out, err), proc.pid


def _group_gone(pgid: int) -> bool:
    deadline = time.monotonic() + 15
    while time.monotonic() < deadline:
        try:
            os.killpg(pgid, 0)
        except ProcessLookupError:
            return True
        time.sleep(0.1)
    return False


def test_killed_runs_resume_to_the_same_bytes(spec_file, reference, tmp_path):
    """SIGKILL and SIGTERM (in process), then Ctrl-C to the process group (local cluster), then a
    finishing rerun: each leaves whole parts and no atlas.csv; each rerun computes only the missing
    batches; the last one writes the bytes of an uninterrupted run."""
    folder, parts = tmp_path / "out", tmp_path / "out" / "atlas.parts"
    args = ["atlas", spec_file, "-o", folder, "--no-plot"]

    killed, _ = _run_until_parts([*args, "--workers", "0"], tmp_path, parts, signal.SIGKILL, group=False)
    assert killed.status == -signal.SIGKILL
    assert not (folder / "atlas.csv").exists()
    check_whole(folder, {}, allow_tmp=True)  # whole parts, perhaps a temporary file
    first = len(list(parts.glob("part-*.csv")))
    assert 1 <= first < 12

    tmp_before = {p.name for p in parts.glob(".*.tmp")}
    terminated, _ = _run_until_parts([*args, "--workers", "0"], tmp_path, parts, signal.SIGTERM, group=False)
    one_line(terminated, 143, "fivebar: error: terminated")
    assert done_before(terminated.stdout) == first and not (folder / "atlas.csv").exists()
    assert {p.name for p in parts.glob(".*.tmp")} == tmp_before  # SIGTERM leaves no temporary file
    check_whole(folder, {}, allow_tmp=True)
    first = len(list(parts.glob("part-*.csv")))

    interrupted, group = _run_until_parts([*args, "--workers", "2"], tmp_path, parts, signal.SIGINT, group=True)
    one_line(interrupted, 130, "fivebar: error: interrupted")
    assert done_before(interrupted.stdout) == first
    assert not (folder / "atlas.csv").exists()
    check_whole(folder, {}, allow_tmp=True)
    second = len(list(parts.glob("part-*.csv")))
    assert first < second <= 12
    assert _group_gone(group), "worker processes of the local cluster outlived the run"

    final = ok(run_cli(*args, "--workers", "0", cwd=tmp_path))
    assert done_before(final.stdout) == second
    assert (folder / "atlas.csv").read_bytes() == reference


def _workers(proc: subprocess.Popen) -> list:
    """The worker processes a local cluster has started for `proc` (multiprocessing spawns them)."""
    try:
        children = psutil.Process(proc.pid).children(recursive=True)
        return [c for c in children if any("spawn_main" in a for a in c.cmdline())]
    except psutil.Error:  # a process that has just ended
        return []


def test_ctrl_c_during_the_start_up_of_a_local_cluster(spec_file, tmp_path):
    """Ctrl-C to the whole process group at 0.3 s (the imports), and once the cluster's worker processes
    exist (they are starting: no batch done yet): exit 130 with one line, no traceback from this process
    or a worker, no atlas.csv, no process of the group left (issue 20). The second moment is a phase of
    the run, not a time: the workers appear after ~0.8 s here idle, ~1.3 s when loaded."""
    for moment in ("0.3 s", "workers"):
        folder = tmp_path / f"out-{moment}"
        proc = subprocess.Popen(command(["atlas", spec_file, "--workers", "2", "-o", folder, "--no-plot"]), cwd=tmp_path,
                                env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                start_new_session=True, preexec_fn=default_ctrl_c)
        try:
            if moment == "workers":
                deadline = time.monotonic() + 120
                while proc.poll() is None and not _workers(proc) and time.monotonic() < deadline:
                    time.sleep(0.02)  # a look scans /proc (~2 ms); a worker imports for ~1 s before a batch
                assert not (folder / "atlas.parts").exists() or not list((folder / "atlas.parts").glob("part-*.csv"))
            else:
                time.sleep(0.3)
            assert proc.poll() is None, proc.communicate()
            os.killpg(proc.pid, signal.SIGINT)
            out, err = proc.communicate(timeout=60)
        finally:
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.communicate()
        one_line(CliResult(proc.returncode, out, err), 130, "fivebar: error: interrupted")
        assert not (folder / "atlas.csv").exists()
        assert _group_gone(proc.pid), "worker processes of the local cluster outlived the run"


# A script as users write them, analyses at its top level (no `if __name__ == "__main__":`), with
# fivebar's own workers spawned as on macOS and Windows, and a local cluster (whose workers Dask spawns)
UNGUARDED = """\
import logging, multiprocessing, sys
print("top of the script", flush=True)
multiprocessing.get_all_start_methods = lambda: ["spawn"]
import fivebar_cli as fb
print(repr(fb.aspects(fb.load(sys.argv[1]), 6, jobs=2).rows()), flush=True)
logging.getLogger("fivebar_cli").addHandler(logging.StreamHandler(sys.stdout))
logging.getLogger("fivebar_cli").setLevel(logging.INFO)
fb.atlas(sys.argv[2], "out", workers=2).save("out")
"""


def test_a_script_without_a_main_guard_runs_once(spec_file, reference, tmp_path):
    """Spawned workers import the main module again, which runs a script's top level in each (the
    script's analyses started again there failed with a wall of tracebacks): fivebar's workers leave
    it out. The script runs once, and its results are those of this process; the cluster the atlas
    runs on is told through `logging`, to the script's handler."""
    import fivebar_cli as fb
    from conftest import M1_YAML

    script = tmp_path / "sweep.py"
    script.write_text(UNGUARDED)
    r = subprocess.run([sys.executable, str(script), str(M1_YAML), str(spec_file)], cwd=tmp_path, env=ENV,
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-3000:]
    assert r.stderr == ""
    assert r.stdout.splitlines() == ["top of the script", repr(fb.aspects(fb.load(M1_YAML), 6, jobs=1).rows()),
                                     "on a local cluster of 2 worker processes (2 workers connected)"]  # (logged)
    assert (tmp_path / "out" / "atlas.csv").read_bytes() == reference


@pytest.mark.parametrize("address, status, needle", [
    ("not an address", 2, "fivebar: error: --scheduler: bad address 'not an address'"),
    ("nonsense://127.0.0.1:1", 2, "unknown address scheme"),
    ("tcp://127.0.0.1:99999", 2, "port '99999' is not a number from 1 to 65535"),
    ("tcp://:8786", 2, "no host name"),
    ("tcp://127.0.0.1:http", 2, "port 'http'"),
])
def test_bad_scheduler_address_is_one_line(spec_file, tmp_path, address, status, needle):
    one_line(run_cli("atlas", spec_file, "--scheduler", address, "-o", "o", cwd=tmp_path), status, needle)
