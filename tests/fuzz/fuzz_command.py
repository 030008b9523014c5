"""Generated hostile inputs for the ``drakegrasp batch`` command, and signals.

Command lines are drawn from pools of valid and hostile option values
(``--mu``, ``--num-generators``, ``--tol``, ``--chunk-size``, ``--workers``,
``--kind``, ``--contact-model``, ``--format``, ``--metrics``) over input
files drawn from pools too: a valid ``.npz``, one with NaN, a pickled object
array, a wrong shape, a missing array, random bytes, an empty file, a
missing file; outputs that exist already, equal the input, or sit in a
missing folder.  Each runs ``drakegrasp.cli.main`` in the sandbox worker.
A run must exit 0 with a right result, or non-zero with exactly one
``drakegrasp: error:`` line; the input and any earlier output never change
(``lost data`` otherwise).  The independent route for a result: each
grasp's verdict by ``fuzz_oracles.closure_verdict`` (a scipy LP).

Signal cases start ``python -m drakegrasp batch --workers 2`` on a slow file,
send SIGTERM, SIGHUP or SIGINT after a random delay (from the imports to the
pool's start and its work) to the process or its whole process group (a
terminal's Ctrl-C or hang-up), and require a non-zero
exit with one line, no process of the run left alive, no scratch file left
in the output folder, and either no output or a complete right one.
"""

from __future__ import annotations

import contextlib
import io
import math
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import fuzz_oracles as oracle
import numpy as np
from fuzz_cases import Case
from hostile import pick
from sandbox import Sandbox

import drakegrasp as dg

ROOT = Path(__file__).resolve().parents[2]


def cli_case(argv: list) -> dict:
    """Worker side: ``drakegrasp.cli.main(argv)``, its exit code and output."""
    from drakegrasp import cli

    err, out = io.StringIO(), io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
        try:
            code = cli.main([str(a) for a in argv])
        except SystemExit as e:  # argparse's own refusals exit 2
            code = e.code if isinstance(e.code, int) else 1
    return {"code": code, "stderr": err.getvalue()}


def _judged(out: dict):
    """The exit as a value (0) or a one-line refusal; anything else is raw."""
    if out["code"] == 0:
        return out
    text = out["stderr"]
    lines = [line for line in text.splitlines() if line.strip()]
    if "Traceback" in text or not lines or not lines[-1].startswith("drakegrasp"):
        raise RuntimeError(f"exit {out['code']} with stderr {text[-300:]!r}")
    # argparse's refusals too are one line (cli._Parser)
    if len(lines) != 1:
        raise RuntimeError(f"exit {out['code']} with {len(lines)} lines: {text!r}")
    raise dg.InvalidOptionError(lines[-1])


def _grasps(rng, K: int, N: int = 3):
    P = rng.normal(size=(K, N, 3))
    P /= np.linalg.norm(P, axis=2, keepdims=True)
    return P, -P + 0.6 * rng.normal(size=(K, N, 3))


def _input(kind: str, path: Path, rng, K: int):
    """Write an input of ``kind``; (positions, normals, mu) when valid."""
    P, Nrm = _grasps(rng, K)
    mu = rng.uniform(0.2, 0.9, (K, 3))
    if kind == "valid":
        np.savez(path, positions=P, normals=Nrm, mu=mu)
        return P, Nrm, mu
    if kind == "no mu":
        np.savez(path, positions=P, normals=Nrm)
        return P, Nrm, None
    if kind == "nan":
        P[int(rng.integers(K)), 0, 1] = math.nan
        np.savez(path, positions=P, normals=Nrm, mu=mu)
    elif kind == "object":
        objs = np.empty((K, 3, 3), dtype=object)
        objs[...] = 1.0
        np.savez(path, positions=objs, normals=Nrm, mu=mu)
    elif kind == "shape":
        np.savez(path, positions=P[..., :2].reshape(K, -1), normals=Nrm, mu=mu)
    elif kind == "missing":
        np.savez(path, positions=P, mu=mu)
    elif kind == "bytes":
        path.write_bytes(rng.bytes(int(rng.integers(0, 300))))
    elif kind == "empty":
        path.write_bytes(b"")
    elif kind == "complex":
        np.savez(path, positions=P + 1j, normals=Nrm, mu=mu)
    return None


_INPUTS = ("valid", "valid", "no mu", "nan", "object", "shape", "missing",
           "bytes", "empty", "complex", "absent")  # fmt: skip
_OPTIONS = {
    "--mu": (("0.5", "0", "0.9"), ("nan", "-1", "abc", "1e13", "inf")),
    "--num-generators": (("4", "8"), ("2", "x", "1e9", "-3", "8.5")),
    "--tol": (("1e-6",), ("nan", "-1", "x", "inf")),
    "--chunk-size": (("1", "7"), ("0", "-1", "x", "1.5")),
    "--workers": (("1",), ("0", "-1", "x", "1.5")),
    "--kind": (("force", "form"), ("both", "")),
    "--contact-model": (("hard_finger", "frictionless"), ("soft", "")),
    "--format": (("npz",), ("csv", "")),
}


def command_cases(
    root: Path, sandbox: Sandbox, seed: int = 219, count: int = 120
) -> Iterator[Case]:
    """Generated command lines (see the module docstring)."""
    rng = np.random.default_rng(seed)
    folder = root / "command"
    folder.mkdir(parents=True, exist_ok=True)
    for i in range(count):
        K = int(rng.integers(1, 7))
        kind = pick(rng, _INPUTS)
        src = folder / f"in{i}.npz"
        grasp = None if kind == "absent" else _input(kind, src, rng, K)
        out = folder / f"out{i}.npz"
        argv = ["batch", str(src), str(out), "--workers", "1"]
        expect = "answer" if grasp is not None else "refuse"
        mu = None if grasp is None else grasp[2]
        model, form = "hard_finger", False
        for option in rng.permutation(list(_OPTIONS))[: int(rng.integers(0, 3))]:
            good, bad = _OPTIONS[option]
            valid = rng.random() < 0.5
            value = pick(rng, good if valid else bad)
            argv += [option, value]
            if not valid:
                expect = "refuse"
            elif option == "--mu":
                mu = float(value)
            elif option == "--kind":
                form = value == "form"
            elif option == "--contact-model":
                model = value
        if grasp is not None and mu is None and not form:
            expect = "refuse"  # force closure needs a friction
        files = (src,) if src.exists() else ()
        twist = rng.random()
        if twist < 0.1:
            argv[2] = str(src)  # the output is the input: refused, input intact
            expect = "refuse"
        elif twist < 0.2:
            out.write_bytes(b"an earlier result")  # refused without --overwrite
            files += (out,)
            expect = "refuse"
        elif twist < 0.25:
            argv[2] = str(folder / "missing-folder" / "out.npz")
            expect = "refuse"

        def right(_, grasp=grasp, mu=mu, model=model, form=form, out=out):
            P, Nrm, _ = grasp
            with np.load(out) as data:
                got = data["is_closure"]
            mus = (
                np.zeros((len(P), 3))
                if form or model == "frictionless"
                else (np.broadcast_to(mu, (len(P), 3)) if mu is not None else None)
            )
            for k in range(len(P)):
                truth = oracle.closure_verdict(P[k], Nrm[k], mus[k])
                if truth is not None and truth[0] != bool(got[k]):
                    return False
            return len(got) == len(P)

        yield Case(
            "CLI",
            f"{kind} K={K} {' '.join(map(str, argv[3:]))}#{i}",
            lambda a=argv: _judged(sandbox.call("fuzz_command:cli_case", a)),
            expect,
            right if expect == "answer" else None,
            files=files,
        )


# ------------------------------------------------------------------ signals


def _descendants(pid: int) -> set[int]:
    out, todo = set(), [pid]
    while todo:
        p = todo.pop()
        try:
            kids = Path(f"/proc/{p}/task/{p}/children").read_text().split()
        except OSError:
            continue
        for k in map(int, kids):
            if k not in out:
                out.add(k)
                todo.append(k)
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().split(")")[-1].split()[0]
    except OSError:
        return False
    return state != "Z"


def signal_run(src: Path, out: Path, sig: int, delay: float, group: bool) -> dict:
    """Start the batch command, signal it after ``delay`` s; what it left.

    ``group``: signal its whole process group, as a terminal does for Ctrl-C
    and a hang-up; else the command's process alone, as ``kill`` does.
    """
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.Popen(
        [sys.executable, "-m", "drakegrasp", "batch", str(src), str(out),
         "--workers", "2", "--mu", "0.5"],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env,
        start_new_session=True,
    )  # fmt: skip
    seen: set[int] = set()
    end = time.monotonic() + delay
    while time.monotonic() < end and proc.poll() is None:
        seen |= _descendants(proc.pid)
        time.sleep(0.05)
    if proc.poll() is None:
        if group:
            os.killpg(proc.pid, sig)  # its own session: our group is not touched
        else:
            proc.send_signal(sig)
    try:
        _, err = proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.communicate()
        return {"hang": True}
    deadline = time.monotonic() + 10
    while any(_alive(p) for p in seen) and time.monotonic() < deadline:
        time.sleep(0.1)
    left = sorted(p for p in seen if _alive(p))
    for p in left:  # our own run's children only, by pid
        with contextlib.suppress(OSError):
            os.kill(p, signal.SIGKILL)
    scratch = [
        p.name for p in out.parent.iterdir() if p.name not in (out.name, src.name)
    ]
    return {"code": proc.returncode, "stderr": err, "orphans": left, "scratch": scratch}


def signal_cases(root: Path, seed: int = 220, count: int = 2) -> Iterator[Case]:
    """SIGTERM/SIGHUP/SIGINT at random moments of a two-worker batch run."""
    rng = np.random.default_rng(seed)
    folder = root / "signals"
    folder.mkdir(parents=True, exist_ok=True)
    src = folder / "slow.npz"
    P, Nrm = _grasps(rng, 6000, 4)
    np.savez(src, positions=P, normals=Nrm)
    sigs = (signal.SIGTERM, signal.SIGHUP, signal.SIGINT)
    for i in range(count):
        sig = sigs[i % 3]
        delay = float(rng.uniform(0.3, 4.0))
        group = bool(rng.random() < 0.5)
        run_dir = folder / f"run{i}"
        run_dir.mkdir()
        (run_dir / src.name).write_bytes(src.read_bytes())
        out = run_dir / "out.npz"

        def call(run_dir=run_dir, out=out, sig=sig, delay=delay, group=group):
            got = signal_run(run_dir / src.name, out, sig, delay, group)
            if got.get("hang"):
                raise TimeoutError("the run did not end within 60 s of the signal")
            if got["orphans"] or got["scratch"]:
                return got  # the check says what was left
            if got["code"] == 0:  # finished before the signal: a right result
                return got
            return _judged({"code": got["code"], "stderr": got["stderr"]})

        def right(got, out=out):
            if got["orphans"] or got["scratch"]:
                return False
            with np.load(out) as data:
                return len(data["is_closure"]) == len(P)

        yield Case(
            "CLI",
            f"{signal.Signals(sig).name} to the {'group' if group else 'process'} "
            f"after {delay:.1f} s#{i}",
            call,
            "either",
            right,
            files=(run_dir / src.name,),
        )
