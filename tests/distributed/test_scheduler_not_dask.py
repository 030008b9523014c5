"""A scheduler address that answers but is not a Dask scheduler.

A web server at the address never answers Dask's handshake, and the Client
waited on it forever (``drakegrasp batch --scheduler`` hung with no output); an
SSH banner read as a Dask frame asked numpy for exabytes, and a raw
``MemoryError`` came out.  Both are now the library's error naming the address,
given within about the connection timeout, with Dask's error as the cause.
The fake servers run in threads of this process, on ephemeral ports.
"""

from __future__ import annotations

import gc
import http.server
import logging
import socket
import struct
import threading
import time

import numpy as np
import pytest

distributed = pytest.importorskip("distributed", reason="dask is an optional extra")
dask = pytest.importorskip("dask", reason="dask is an optional extra")

from drakegrasp import GraspError, InvalidOptionError  # noqa: E402
from drakegrasp.distributed.client import (  # noqa: E402
    HANDSHAKE_GRACE,
    client_for,
    connected,
)

BOUND = 60.0  # seconds: every failure below is reported well within this
TIMEOUT = 1.0  # seconds: the connection timeout the slow cases are given


class _QuietHandler(http.server.BaseHTTPRequestHandler):
    def log_message(self, *args):
        pass


@pytest.fixture
def web_server():
    """``python -m http.server``: it waits for a request line Dask never sends."""
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), _QuietHandler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"127.0.0.1:{server.server_address[1]}"
    server.shutdown()
    server.server_close()


def _socket_server(reply: bytes, *, hang_up: bool):
    """A listener that sends ``reply`` to every connection, then hangs up or not."""
    listener = socket.create_server(("127.0.0.1", 0))
    listener.settimeout(0.1)
    stop = threading.Event()
    kept: list[socket.socket] = []

    def serve():
        while not stop.is_set():
            try:
                conn, _ = listener.accept()
            except TimeoutError:
                continue
            except OSError:
                return
            conn.sendall(reply)
            if hang_up:
                conn.close()
            else:
                kept.append(conn)  # the connection stays open, as sshd's does

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    try:
        yield f"127.0.0.1:{listener.getsockname()[1]}"
    finally:
        stop.set()
        thread.join(5)
        listener.close()
        for conn in kept:
            conn.close()


@pytest.fixture
def ssh_server():
    yield from _socket_server(b"SSH-2.0-OpenSSH_8.9\r\n", hang_up=False)


@pytest.fixture
def hanging_up_server():
    yield from _socket_server(b"", hang_up=True)


def _refusal(address, **kwargs) -> tuple[InvalidOptionError, float]:
    start = time.monotonic()
    with pytest.raises(InvalidOptionError) as info:
        client_for(address, **kwargs)
    elapsed = time.monotonic() - start
    assert elapsed < BOUND
    error = info.value
    assert isinstance(error, GraspError)
    assert f"could not connect to the Dask scheduler at {address!r}" in str(error)
    assert error.__cause__ is not None  # what Dask raised is kept
    return error, elapsed


def test_a_web_server_did_not_complete_the_handshake(web_server):
    error, _ = _refusal(web_server, timeout=TIMEOUT)
    message = str(error)
    assert "accepted the connection but did not complete Dask's handshake" in message
    assert f"within {TIMEOUT + HANDSHAKE_GRACE:g} s" in message
    assert "it is not a Dask scheduler" in message


def test_the_default_timeout_is_dasks_setting(web_server):
    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):
        error, _ = _refusal(web_server)
    assert f"within {1 + HANDSHAKE_GRACE:g} s" in str(error)


def test_a_foreign_banner_is_not_read_as_a_dask_frame(ssh_server):
    # The default timeout: the banner comes at once, nothing is waited for.
    error, _ = _refusal(ssh_server)
    message = str(error)
    assert "the address answered but is not a Dask scheduler" in message
    assert "its reply is not Dask's handshake" in message
    assert not isinstance(error, MemoryError)
    cause = error.__cause__
    assert type(cause).__name__ in message
    assert cause.__traceback__ is not None  # the report keeps where it failed


def test_a_hang_up_during_the_handshake(hanging_up_server):
    error, _ = _refusal(hanging_up_server, timeout=TIMEOUT)
    message = str(error)
    assert "accepted the connection but closed it during Dask's handshake" in message
    assert "it is not a Dask scheduler" in message


def test_connected_passes_the_timeout_on(web_server):
    start = time.monotonic()
    with pytest.raises(InvalidOptionError, match="did not complete Dask's handshake"):
        with connected(web_server, timeout=TIMEOUT):
            raise AssertionError("connected to a web server")
    assert time.monotonic() - start < BOUND


def test_a_failure_leaves_no_client_and_no_thread(ssh_server, web_server):
    def clients():
        return sum(isinstance(o, distributed.Client) for o in gc.get_objects())

    gc.collect()
    before = clients()
    _refusal(ssh_server)
    _refusal(web_server, timeout=TIMEOUT)
    assert clients() == before
    names = [t.name for t in threading.enumerate()]
    assert "drakegrasp-dask-handshake" not in names


@pytest.mark.parametrize("timeout", [0, -1.0, float("nan"), float("inf"), "30", True])
def test_a_timeout_is_a_positive_number_of_seconds(timeout):
    # Refused before any connection is tried (port 1 would take the timeout).
    start = time.monotonic()
    with pytest.raises(InvalidOptionError, match="timeout must be a positive"):
        client_for("127.0.0.1:1", timeout=timeout)
    assert time.monotonic() - start < BOUND


@pytest.mark.parametrize("server", ["web_server", "ssh_server"])
def test_the_command_line_says_it_is_not_a_scheduler(server, request, tmp_path, capsys):
    pytest.importorskip("pyarrow", reason="pyarrow is an optional extra")
    from drakegrasp.cli import main
    from drakegrasp.core.examples import equator_fingers

    address = request.getfixturevalue(server)
    grasp = equator_fingers(0.5)
    P = np.stack([np.stack([c.position for c in grasp.contacts])] * 4)
    N = np.stack([np.stack([c.normal for c in grasp.contacts])] * 4)
    good = tmp_path / "good.npz"
    np.savez(good, positions=P, normals=N, mu=np.full(P.shape[:2], 0.5))
    out = tmp_path / "out"
    start = time.monotonic()
    # Dask's setting, as a user would give it (DASK_DISTRIBUTED__COMM__TIMEOUTS__
    # CONNECT=1s): the web server is given up after 1 s and the grace.
    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):
        code = main(["batch", str(good), str(out), "--scheduler", address])
    assert time.monotonic() - start < BOUND
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.strip()]
    assert code == 1, err
    assert len(lines) == 1, err
    assert lines[0].startswith("drakegrasp: error: could not connect to the Dask")
    assert address in lines[0] and "not a Dask scheduler" in lines[0]
    assert not out.exists()


def _dask_message(*frames: bytes) -> bytes:
    """``frames`` in Dask's TCP framing: sizes as little-endian uint64."""
    sizes = struct.pack(f"<{1 + len(frames)}Q", len(frames), *map(len, frames))
    body = sizes + b"".join(frames)
    return struct.pack("<Q", len(body)) + body


@pytest.fixture
def garbage_server():
    """A framed Dask message whose only frame is not msgpack (0xc1 is unused)."""
    yield from _socket_server(_dask_message(b"\xc1"), hang_up=False)


@pytest.fixture
def foreign_handshake_server():
    """A framed message that decodes (an empty map) but is no Dask handshake."""
    yield from _socket_server(_dask_message(b"\x80"), hang_up=False)


def test_a_reply_that_does_not_decode_is_not_a_scheduler(garbage_server):
    # It raised a ValueError (msgpack's FormatError), which read as a malformed
    # address: "could not connect ...: FormatError".
    error, _ = _refusal(garbage_server, timeout=TIMEOUT)
    message = str(error)
    assert "the address answered but is not a Dask scheduler" in message
    assert "its reply is not Dask's handshake (FormatError)" in message


def test_a_reply_that_decodes_but_is_no_handshake(foreign_handshake_server):
    error, _ = _refusal(foreign_handshake_server, timeout=TIMEOUT)
    message = str(error)
    assert "its reply is not the handshake of this Dask version" in message
    assert "it is not a Dask scheduler, or one of another version" in message
    assert "ValueError: Your Dask versions may not be in sync" in message


class _Recorder(logging.Handler):
    """A handler beside Dask's own on the ``distributed`` logger."""

    def __init__(self):
        super().__init__()
        self.messages: list[str] = []

    def emit(self, record):
        self.messages.append(f"{record.name}: {record.getMessage()}")


@pytest.fixture
def dask_log():
    recorder = _Recorder()
    logging.getLogger("distributed").addHandler(recorder)
    yield recorder.messages
    logging.getLogger("distributed").removeHandler(recorder)


@pytest.mark.parametrize("server", ["garbage_server", "foreign_handshake_server"])
def test_dask_logs_nothing_of_a_foreign_reply(server, request, dask_log):
    # Dask logged "Failed to deserialize" (CRITICAL, with a traceback) and a
    # dangling-stream warning to stderr, beside the one-line error.
    address = request.getfixturevalue(server)
    _refusal(address, timeout=TIMEOUT)
    gc.collect()
    assert dask_log == []


def test_other_threads_still_log_during_a_refusal(garbage_server, dask_log):
    # The filter drops the records of the threads given only, and is gone
    # afterwards.
    from drakegrasp.distributed.client import _quiet

    logger = logging.getLogger("distributed.drakegrasp_test")
    with _quiet(threading.get_ident()):
        logger.warning("own thread")  # dropped
        other = threading.Thread(target=logger.warning, args=("other thread",))
        other.start()
        other.join()
    logger.warning("after")
    assert dask_log == [f"{logger.name}: other thread", f"{logger.name}: after"]
    _refusal(garbage_server, timeout=TIMEOUT)
    assert not any(h.filters for h in logging.getLogger("distributed").handlers)


def test_a_tls_address_without_tls_settings_is_refused_at_once():
    # Dask failed inside its connector with "TLS expects a `ssl_context`",
    # which read as "the address answered but is not a Dask scheduler".
    start = time.monotonic()
    for address in ("tls://127.0.0.1:1", "wss://127.0.0.1:1"):
        with pytest.raises(InvalidOptionError) as info:
            client_for(address, timeout=TIMEOUT)
        message = str(info.value)
        assert f"{address!r} asks for TLS" in message
        assert "no TLS settings (distributed.comm.tls.*)" in message
        assert "answered" not in message
    assert time.monotonic() - start < 5 * TIMEOUT
