"""Named pipes that no test can hang on, and that tell whether a reader opened them.

A reader that opens a FIFO blocks until a writer comes.  :func:`watched_fifo`
makes the pipe and a thread that keeps trying to open its write end without
blocking: that succeeds only while a reader waits, and the writer, closed at
once, hands the reader an end of file.  So a reader that wrongly opens the pipe
finishes (whatever it then says) instead of hanging, and the test sees that it
opened it: ``pipe.opened`` counts the openings.
"""

from __future__ import annotations

import contextlib
import errno
import os
import threading
from pathlib import Path

import pytest

needs_mkfifo = pytest.mark.skipif(
    not hasattr(os, "mkfifo"), reason="no named pipes on this platform"
)


class _Watch:
    def __init__(self, path: Path):
        self.path, self.opened = path, 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _run(self) -> None:
        while not self._stop.wait(0.05):
            try:
                fd = os.open(self.path, os.O_WRONLY | os.O_NONBLOCK)
            except OSError as err:  # ENXIO: no reader waits (or the pipe is gone)
                if err.errno not in (errno.ENXIO, errno.ENOENT):
                    raise
                continue
            os.close(fd)
            self.opened += 1


@contextlib.contextmanager
def watched_fifo(path: str | os.PathLike):
    """A named pipe at ``path`` for the ``with`` block; yields its watch."""
    watch = _Watch(Path(path))
    os.mkfifo(watch.path)
    watch._thread.start()
    try:
        yield watch
    finally:
        watch._stop.set()
        watch._thread.join()
