"""Run fuzz calls that may hang or crash in a child process with limits.

A :class:`Sandbox` keeps one worker process (``python sandbox.py``) that reads a
call per line (``{"fn": "module:function", "args": [...]}``, the arguments in the tagged
JSON of :mod:`hostile`, so arrays keep their dtype and layout), runs it under an
address-space limit, and writes its outcome as one JSON line.  The parent waits
at most ``timeout`` seconds: a worker that overruns is killed (a hang), one that
dies is a crash; either way a fresh worker starts for the next call, so one bad
input costs one Python start-up, not one per input.

:meth:`Sandbox.call` turns the outcome back into what ``fuzz_cases.run_case``
classifies: the value, a re-raised ``GraspError`` of the same class and
message, a ``RuntimeError`` naming a raw exception or a crash, or
``SandboxTimeout`` for a hang.
"""

from __future__ import annotations

import json
import os
import resource
import select
import subprocess
import sys
import traceback
from pathlib import Path

HERE = Path(__file__).resolve().parent
MEMORY_LIMIT = 3 << 30  # bytes of address space per worker (pydrake maps ~1.5 GB)
WORKER_FOLDERS = (HERE, HERE.parent / "plant", HERE.parent / "systems")
"""Test folders on a worker's path: the fuzz helpers, and the plant and systems
tests' support modules (``drake_distances``, ``pick_support``) the workers use."""


class SandboxTimeout(Exception):
    """The call did not answer within the time limit (the worker was killed)."""


class Sandbox:
    """One worker process at a time; see the module docstring."""

    def __init__(self, *, timeout: float = 60.0, memory: int = MEMORY_LIMIT):
        self.timeout = timeout
        self.memory = memory
        self._proc: subprocess.Popen | None = None

    def _start(self) -> subprocess.Popen:
        env = dict(os.environ)
        root = str(HERE.parents[1])
        env["PYTHONPATH"] = os.pathsep.join(
            [root, *map(str, WORKER_FOLDERS), env.get("PYTHONPATH", "")]
        )
        env["DRAKEGRASP_SANDBOX_MEMORY"] = str(self.memory)
        return subprocess.Popen(
            [sys.executable, str(Path(__file__).resolve())],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
            env=env,
        )

    def close(self) -> None:
        """End the worker (by its own pid)."""
        if self._proc is not None:
            self._proc.kill()
            self._proc.wait()
            self._proc = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def raw(self, fn: str, *args) -> dict:
        """The worker's outcome dictionary for ``fn(*args)``."""
        if self._proc is None or self._proc.poll() is not None:
            self._proc = self._start()
        proc = self._proc
        from hostile import encode

        request = {"fn": fn, "args": [encode(a) for a in args]}
        proc.stdin.write(json.dumps(request) + "\n")
        proc.stdin.flush()
        ready, _, _ = select.select([proc.stdout], [], [], self.timeout)
        if not ready:
            self.close()
            return {"kind": "hang"}
        line = proc.stdout.readline()
        if not line:
            code = proc.wait()
            self._proc = None
            return {"kind": "crash", "code": code}
        return json.loads(line)

    def call(self, fn: str, *args):
        """``fn(*args)`` in the worker, its outcome as a value or an exception."""
        import drakegrasp.errors as errors

        out = self.raw(fn, *args)
        kind = out["kind"]
        if kind == "value":
            return out["value"]
        if kind == "grasp_error":
            cls = getattr(errors, out["type"], errors.GraspError)
            raise cls(out["message"])
        if kind == "hang":
            raise SandboxTimeout(f"no answer within {self.timeout:g} s")
        if kind == "crash":
            raise RuntimeError(f"the worker died with status {out['code']} (a crash)")
        raise RuntimeError(f"{out['type']}: {out['message']}")


def _serve() -> None:
    limit = int(os.environ.get("DRAKEGRASP_SANDBOX_MEMORY", MEMORY_LIMIT))
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    import importlib

    from hostile import decode

    from drakegrasp.errors import GraspError

    for line in sys.stdin:
        request = json.loads(line)
        module, _, name = request["fn"].partition(":")
        try:
            value = getattr(importlib.import_module(module), name)
            value = value(*[decode(a) for a in request["args"]])
            out = {"kind": "value", "value": value}
        except GraspError as e:
            out = {"kind": "grasp_error", "type": type(e).__name__, "message": str(e)}
        except MemoryError:
            out = {"kind": "raw", "type": "MemoryError", "message": "over the limit"}
        except BaseException as e:  # noqa: BLE001 - SystemExit included: it counts
            text = "".join(traceback.format_exception_only(type(e), e)).strip()
            out = {"kind": "raw", "type": type(e).__name__, "message": text[:500]}
        sys.stdout.write(json.dumps(out) + "\n")
        sys.stdout.flush()


if __name__ == "__main__":
    _serve()
