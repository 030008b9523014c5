"""``drakegrasp batch`` under signals, full disks and hostile file names (issue 21).

Signals are sent to real subprocesses: the command must unwind (no ``.partial``
file, ``.batch-*`` scratch folder or shared-memory segment left), and its pool
workers must not outlive it, or a ``| tee`` reading its stdout would wait for
ever.  Every wait is bounded and anything left is killed at the end.
"""

from __future__ import annotations

import errno
import io
import os
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from drakegrasp.batch.files import npz as npz_module
from drakegrasp.cli import main, printable

ROOT = Path(__file__).resolve().parents[2]
linux_only = pytest.mark.skipif(
    not Path("/proc/self/task").is_dir(), reason="reads /proc to find the workers"
)


_ENV: dict = {}


@pytest.fixture(scope="module", autouse=True)
def _checkout(checkout_env):
    """Every run below: the checkout's drakegrasp, its kernels warm."""
    _ENV.update(checkout_env)


def _env() -> dict:
    return dict(_ENV)


def _children(pid: int) -> set[int]:
    found = set()
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            found.update(int(c) for c in (task / "children").read_text().split())
        except OSError:
            pass
    return found


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def _gone(pids, timeout: float) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if not any(_alive(p) for p in pids):
            return True
        time.sleep(0.1)
    return False


def _kill(pids) -> None:
    for p in pids:
        try:
            os.kill(p, signal.SIGKILL)
        except OSError:
            pass


def _shm() -> set[str]:
    return {p.name for p in Path("/dev/shm").glob("psm_*")}


@pytest.fixture(scope="module")
def slow_file(tmp_path_factory):
    """Grasps that take two workers many seconds (ε of six-contact grasps)."""
    rng = np.random.default_rng(21)
    K, N = 40000, 6
    p = rng.normal(size=(K, N, 3))
    p /= np.linalg.norm(p, axis=2, keepdims=True)
    path = tmp_path_factory.mktemp("slow") / "grasps.npz"
    np.savez(path, positions=p, normals=-p + 0.5 * rng.normal(size=p.shape), mu=0.5)
    return path


def _await_workers(proc, scratch_dir, workers: set[int]) -> None:
    """Wait (120 s at most) until ``proc`` runs two pool workers and a scratch file.

    The workers seen are added to ``workers`` as they appear, so that the
    caller can kill them whatever happens; the run must still be going.
    """
    end = time.monotonic() + 120
    while time.monotonic() < end and proc.poll() is None:
        workers |= _children(proc.pid)
        if len(workers) >= 2 and list(scratch_dir.glob(".batch-*")):
            break
        time.sleep(0.05)
    assert proc.poll() is None, "the run ended before it could be signalled"


@linux_only
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP])
def test_a_signal_leaves_no_worker_file_or_segment(slow_file, tmp_path, sig):
    out = tmp_path / "out.npz"
    before = _shm()
    cmd = [sys.executable, "-m", "drakegrasp", "batch", str(slow_file),
           str(out), "--workers", "2", "--chunk-size", "200", "--metrics",
           "epsilon_l1"]  # fmt: skip
    proc = subprocess.Popen(
        cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=_env()
    )
    workers: set[int] = set()
    try:
        _await_workers(proc, tmp_path, workers)
        assert len(workers) >= 2 and list(tmp_path.glob(".batch-*"))
        ours = _shm() - before
        proc.send_signal(sig)
        # communicate returns at EOF of stdout: only when no worker holds it
        stdout, stderr = proc.communicate(timeout=60)
        assert proc.returncode == 128 + sig, stderr
        assert (
            stderr.decode()
            .strip()
            .endswith(f"drakegrasp: terminated by {signal.Signals(sig).name}")
        )
        assert _gone(workers, 10), "a pool worker outlived the command"
        assert not out.exists()
        assert sorted(p.name for p in tmp_path.iterdir()) == []  # no scratch, partial
        assert not (ours & _shm()), "shared-memory segments were left in /dev/shm"
    finally:
        _kill([proc.pid, *workers])
        proc.wait(timeout=30)


@linux_only
@pytest.mark.parametrize("sig", [signal.SIGHUP, signal.SIGTERM, signal.SIGINT])
def test_a_signal_to_the_whole_process_group(slow_file, tmp_path, sig):
    # A closed terminal hangs up (and Ctrl-C interrupts) the whole foreground
    # group, the pool workers and Python's resource tracker included: a
    # worker killed by SIGHUP broke the pool under the cleanup (once it hung),
    # and the killed tracker was restarted and printed a page of KeyErrors.
    out = tmp_path / "out.npz"
    before = _shm()
    cmd = [sys.executable, "-m", "drakegrasp", "batch", str(slow_file),
           str(out), "--workers", "2", "--chunk-size", "200"]  # fmt: skip
    proc = subprocess.Popen(
        cmd,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=_env(),
        start_new_session=True,  # its own group: ours is never signalled
    )
    workers: set[int] = set()
    try:
        _await_workers(proc, tmp_path, workers)
        ours = _shm() - before
        os.killpg(proc.pid, sig)
        _, stderr = proc.communicate(timeout=60)
        want = (
            "drakegrasp: interrupted"
            if sig == signal.SIGINT
            else f"drakegrasp: terminated by {signal.Signals(sig).name}"
        )
        assert proc.returncode == 128 + sig, stderr
        assert stderr.decode().strip() == want  # one line, no tracker's noise
        assert _gone(workers, 10), "a pool worker outlived the command"
        assert sorted(p.name for p in tmp_path.iterdir()) == []
        assert not (ours & _shm()), "shared-memory segments were left in /dev/shm"
    finally:
        _kill([proc.pid, *workers])
        proc.wait(timeout=30)


_DEFERRED = """
import os, signal, sys, time, types
import multiprocessing
from drakegrasp.cli import Terminated, _terminable

where = sys.argv[1]
done = []
try:
    with _terminable():
        if where == "import":
            # a module whose import is signalled half-way
            sys.modules.pop("slow_module", None)
            path = os.path.join(sys.argv[2], "slow_module.py")
            with open(path, "w") as f:
                f.write("import os, signal, time\\n"
                        "os.kill(os.getpid(), signal.SIGTERM)\\n"
                        "time.sleep(0.3)\\nFINISHED = True\\n")
            sys.path.insert(0, sys.argv[2])
            import slow_module
            done.append(slow_module.FINISHED)
        else:
            os.register_at_fork(
                after_in_parent=lambda: os.kill(os.getpid(), signal.SIGTERM)
            )
            fork = multiprocessing.get_context("fork")
            p = fork.Process(target=time.sleep, args=(0,))
            p.start()  # signalled inside the fork's hooks
            done.append(p.pid is not None)
            p.join()
        time.sleep(5)  # the signal lands here, right after
        print("never terminated")
except Terminated as t:
    print(t.name, done)
"""


@linux_only
@pytest.mark.parametrize("where", ["import", "fork"])
def test_a_signal_during_an_import_or_a_fork_lands_after_it(tmp_path, where):
    # Raised inside pydrake's initialisation, SIGTERM became a 45-line CRITICAL
    # report and exit 1; raised in a fork's hooks it was printed as "Exception
    # ignored" and dropped, and the run went on.  Now it waits for the import
    # or the fork to end and unwinds the run from there.
    proc = subprocess.run(
        [sys.executable, "-c", _DEFERRED, where, str(tmp_path)],
        capture_output=True,
        text=True,
        env=_env(),
        timeout=60,
    )
    assert proc.stdout.strip() == "SIGTERM [True]", proc.stdout + proc.stderr
    assert "Exception ignored" not in proc.stderr and "Traceback" not in proc.stderr


_CHILD = """
import os, signal, sys, threading, time
import multiprocessing
from drakegrasp.cli import _terminable

sig = getattr(signal, sys.argv[1])


def target():
    time.sleep(0.3)  # a deferred signal would land here
    sys.exit(threading.active_count())  # 1: no deferral thread was started


with _terminable():
    # the signal reaches the child in the fork's hooks, before any initialiser
    os.register_at_fork(after_in_child=lambda: os.kill(os.getpid(), sig))
    p = multiprocessing.get_context("fork").Process(target=target)
    p.start()
    p.join()
    print(p.exitcode)
"""


@linux_only
@pytest.mark.parametrize(
    ("sig", "exitcode"),
    [("SIGTERM", -signal.SIGTERM), ("SIGHUP", 1), ("SIGINT", 1)],
)
def test_a_forked_child_signalled_in_its_fork_hooks_does_not_defer(sig, exitcode):
    # A group signal reached a pool worker before its initialiser reset the
    # handlers it inherited: the deferral's timer thread raced threading's
    # after-fork reset and printed a KeyError traceback into the command's
    # one-line stderr.  A child now never defers: SIGTERM ends it, as by
    # default; SIGHUP and Ctrl-C are left to the parent, as in a worker.
    proc = subprocess.run(
        [sys.executable, "-c", _CHILD, sig],
        capture_output=True,
        text=True,
        env=_env(),
        timeout=60,
    )
    assert proc.stdout.strip() == str(exitcode), proc.stdout + proc.stderr
    assert proc.stderr == ""


_ABNORMAL = """
import os, sys
import numpy as np
from drakegrasp.batch import batch_force_closure
from drakegrasp.batch.run.workers import _POOL
rng = np.random.default_rng(0)
p = rng.normal(size=(4000, 3, 3))
batch_force_closure(p, -p, 0.5, workers=2, chunk_size=200)
print(*[w.pid for w in _POOL["pool"]._processes.values()], flush=True)
{exit}
"""


@linux_only
@pytest.mark.parametrize(
    "exit", ["os._exit(3)", "os.kill(os.getpid(), 9)", "raise SystemExit(4)"]
)
def test_any_exit_of_a_program_that_used_workers_ends_them(exit):
    proc = subprocess.Popen(
        [sys.executable, "-c", _ABNORMAL.format(exit=exit)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=_env(),
    )
    workers: list[int] = []
    try:
        # the workers inherit stdout: EOF comes only when they are gone too
        stdout, stderr = proc.communicate(timeout=120)
        workers = [int(w) for w in stdout.split()]
        assert len(workers) == 2, stderr.decode()
        assert _gone(workers, 10), "a pool worker outlived its program"
    finally:
        _kill([proc.pid, *workers])
        proc.wait(timeout=30)


class _FullDisk(io.RawIOBase):
    """A file on a disk that fills after ``room`` bytes (ENOSPC after that)."""

    def __init__(self, path, room: int):
        self.f = open(path, "wb")  # noqa: SIM115
        self.room = room

    def writable(self) -> bool:
        return True

    def write(self, b) -> int:
        if len(b) > self.room:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        self.room -= len(b)
        return self.f.write(b)

    def close(self) -> None:
        self.f.close()
        super().close()


@pytest.mark.parametrize("room", [100, 20000])
def test_a_full_disk_removes_the_scratch_folder(tmp_path, monkeypatch, capsys, room):
    rng = np.random.default_rng(4)
    p = rng.normal(size=(3000, 3, 3))
    src = tmp_path / "in.npz"
    np.savez(src, positions=p, normals=-p, mu=0.5)
    out = tmp_path / "out.npz"
    out.write_bytes(b"the old results")
    monkeypatch.setattr(
        npz_module,
        "open",
        lambda path, mode: io.BufferedWriter(_FullDisk(path, room)),
        raising=False,  # the module's open is the builtin
    )
    cmd = ["batch", str(src), str(out), "--overwrite", "--chunk-size", "500"]
    assert main([*cmd, "--workers", "1"]) == 1
    assert "No space left on device" in capsys.readouterr().err
    assert out.read_bytes() == b"the old results"  # the old output is kept
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.npz", "out.npz"]


@pytest.mark.parametrize("suffix", ["npz", "parquet"])
def test_results_get_the_umasks_mode(tmp_path, suffix):
    if suffix == "parquet":
        pytest.importorskip("pyarrow", reason="pyarrow is an optional extra")
    rng = np.random.default_rng(5)
    p = rng.normal(size=(50, 3, 3))
    src = tmp_path / "in.npz"
    np.savez(src, positions=p, normals=-p, mu=0.5)
    for mask in (0o022, 0o077, 0o002):
        out = tmp_path / f"out-{mask:o}.{suffix}"
        old = os.umask(mask)
        try:
            assert main(["batch", str(src), str(out), "--workers", "1"]) == 0
        finally:
            os.umask(old)
        assert stat.S_IMODE(out.stat().st_mode) == 0o666 & ~mask


def test_file_names_with_terminal_escapes_are_printed_safely(tmp_path, capsys):
    rng = np.random.default_rng(6)
    p = rng.normal(size=(20, 3, 3))
    name = "in\x1b]0;owned\x07\u202e.npz"
    src = tmp_path / name
    np.savez(src, positions=p, normals=-p, mu=0.5)
    out = tmp_path / "out\x1b[2J.npz"
    assert main(["batch", str(src), str(out), "--workers", "1"]) == 0
    printed = capsys.readouterr().out
    assert "\x1b" not in printed and "wrote " + printable(str(out)) in printed
    assert "out\\x1b[2J.npz" in printed
    # an error naming the input: one line, no escape reaches the terminal
    assert main(["batch", str(src), str(out), "--workers", "1"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "\x1b" not in err and "\u202e" not in err
    # a scene file's name, printed by analyze before its report
    bad = tmp_path / "\x1b[31mscene.yaml"
    assert main(["analyze", str(bad)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "\x1b" not in err


_LATE = """
import atexit, os, signal, sys, time
from drakegrasp.cli import run

times, sig = int(sys.argv[1]), getattr(signal, sys.argv[2])

def signalled_while_exiting():  # the interpreter's exit, after the command
    for _ in range(times):
        os.kill(os.getpid(), sig)
        time.sleep(0.2)
    print("exited", flush=True)

atexit.register(signalled_while_exiting)
sys.argv = ["drakegrasp", "scenes"]
run()
"""


@linux_only
@pytest.mark.parametrize("sig", ["SIGTERM", "SIGHUP", "SIGINT"])
def test_a_signal_as_the_finished_command_exits_breaks_nothing(sig):
    # The command had finished and written its output, but the interpreter's
    # exit (the worker pool's stop, the modules' teardown) still ran with the
    # default handlers: SIGTERM killed it (status -15, a fragment of a
    # traceback on stderr at times), Ctrl-C printed a traceback.  The first
    # signal then is taken, and the exit ends with the command's status.
    once = subprocess.run(
        [sys.executable, "-c", _LATE, "1", sig],
        capture_output=True, text=True, env=_env(), timeout=60,
    )  # fmt: skip
    assert (once.returncode, once.stdout.split()[-1:]) == (0, ["exited"]), once
    assert once.stderr == ""
    # a second one ends the process at once, as the default does
    twice = subprocess.run(
        [sys.executable, "-c", _LATE, "2", sig],
        capture_output=True, text=True, env=_env(), timeout=60,
    )  # fmt: skip
    assert twice.returncode == -getattr(signal, sig), twice
    assert "exited" not in twice.stdout


_EARLY = """
import os, signal, sys, time
from drakegrasp import cli

real = cli.build_parser

def signalled_while_reading_arguments():
    os.kill(os.getpid(), signal.SIGTERM)
    time.sleep(0.5)
    print("went on", flush=True)
    return real()

cli.build_parser = signalled_while_reading_arguments
sys.argv = ["drakegrasp", "scenes"]
cli.run()
"""


@linux_only
def test_a_signal_before_the_command_runs_ends_it_in_one_line():
    # Before the command's handlers (its arguments being read) SIGTERM killed
    # the program silently, status -15; nothing is under way yet, so it ends
    # at once, as a signalled run does.
    proc = subprocess.run(
        [sys.executable, "-c", _EARLY],
        capture_output=True, text=True, env=_env(), timeout=60,
    )  # fmt: skip
    assert proc.returncode == 128 + signal.SIGTERM, proc
    assert proc.stderr == "drakegrasp: terminated by SIGTERM\n"
    assert "went on" not in proc.stdout
