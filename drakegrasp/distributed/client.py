"""The Dask client the distributed drivers run on (needs the ``dask`` extra)."""

from __future__ import annotations

import asyncio
import contextlib
import gc
import logging
import math
import numbers
import threading
import traceback
from collections.abc import Iterator, Sequence

from drakegrasp.core.validation import describe
from drakegrasp.errors import InvalidOptionError

__all__ = ["HANDSHAKE_GRACE", "client_for", "connected", "results_or_cancel"]

HANDSHAKE_GRACE = 2.0
"""Seconds the handshake may take beyond the connection timeout.

Dask's own connect gives up on an unreachable address after the timeout; an
address still silent this much later has accepted the connection but not
answered Dask's handshake (a web server, say), which Dask alone would wait on
forever.
"""

_CONNECT_SETTING = "distributed.comm.timeouts.connect"


class _NoHandshake(Exception):
    """The address accepted a connection but did not answer Dask's handshake."""


def client_for(client_or_address, *, timeout: float | None = None):
    """A ``distributed.Client``: the one given, or one connected to an address.

    Parameters
    ----------
    client_or_address : distributed.Client or str
        A client, returned as it is, or a scheduler address such as
        ``"tcp://host:8786"``.
    timeout : float, optional
        Seconds to wait for a scheduler at the address: Dask's connection
        timeout (the setting ``distributed.comm.timeouts.connect``, 30 s by
        default) when not given.  An address that accepts the connection but
        does not complete Dask's handshake is given :data:`HANDSHAKE_GRACE`
        seconds more, so a connection is given up after about the timeout.

    Raises
    ------
    InvalidOptionError
        Neither a client nor an address, an address with a port outside
        1..65535, a TLS address (``tls://``, ``wss://``) when Dask's
        configuration holds no TLS settings, a timeout that is not a positive
        number of seconds, a scheduler that cannot be reached within the
        timeout, or an address that answers but is not a Dask scheduler (no
        reply to Dask's handshake, a reply that is no Dask message, or one that
        is not the handshake of this Dask version), naming the address.
        Whatever Dask raised is the error's ``__cause__``; Dask's own log
        records of the failed handshake are kept off its handlers.
    """
    try:
        from distributed import Client
    except ImportError as exc:
        raise InvalidOptionError(
            "drakegrasp.distributed needs the optional packages dask and "
            "distributed (pip install drakegrasp[dask])"
        ) from exc
    if isinstance(client_or_address, str):
        if not client_or_address.strip():
            # Client("") starts a local cluster instead of connecting anywhere.
            raise InvalidOptionError(
                "the scheduler address is empty; give one such as 'tcp://host:8786' "
                "or a distributed.Client"
            )
        port = client_or_address.rpartition(":")[2]
        if port.isdigit() and not 0 < int(port) < 65536:  # Dask waited 30 s
            raise InvalidOptionError(
                f"the scheduler address {describe(client_or_address)} has port {port}; "
                "a port is in 1..65535"
            )
        seconds = _connect_timeout(timeout)
        _check_encryption(client_or_address)
        shook_hands = False
        try:
            _check_handshake(client_or_address, seconds)
            shook_hands = True
            return Client(client_or_address, timeout=seconds)
        except (KeyboardInterrupt, SystemExit):
            raise
        except BaseException as e:  # any failure to connect, kept as the cause
            error = e
        reply = _reply_failure(error)
        # A half-made Client is cyclic garbage, held until now by the locals of
        # the error's traceback (cleared here; the traceback itself is kept).
        # Left to a later collection, its __del__ may run inside another
        # Client's start, where its close waits on the loop lock that start
        # holds: a deadlock (seen in the test suite).  Finalise it here, with
        # the comm a foreign reply left open (Dask warns of it when finalised).
        with _quiet(threading.get_ident()):
            _clear_frames(error)
            gc.collect()
        raise InvalidOptionError(
            "could not connect to the Dask scheduler at "
            f"{describe(client_or_address)}: "
            f"{_failure(error, seconds, shook_hands, reply)}"
        ) from error
    if not isinstance(client_or_address, Client):
        raise InvalidOptionError(
            "client must be a distributed.Client or a scheduler address such as "
            f"'tcp://host:8786', got {describe(client_or_address)}"
        )
    return client_or_address


@contextlib.contextmanager
def connected(client_or_address, *, timeout: float | None = None) -> Iterator:
    """:func:`client_for` as a context: a client made from an address is closed.

    A client the caller passed stays open; one this call connected is closed on
    exit, so a command line run leaves no client reconnecting to a scheduler.
    ``timeout`` is :func:`client_for`'s.
    """
    client = client_for(client_or_address, timeout=timeout)
    try:
        yield client
    finally:
        if client is not client_or_address:
            client.close()


def results_or_cancel(client, futures: Sequence) -> list:
    """The results of ``futures`` in order; on any failure, every one cancelled.

    A task that raised re-raises here (its error, as the worker raised it),
    and so does an interruption (``KeyboardInterrupt``).  Dask keeps a failed
    future's error, and that error's traceback holds the frame that waited on
    it, hence every other future of the call: without the cancel they were
    never released, so the tasks still queued went on computing and the
    finished ones held their results in the workers' memory until the client
    closed (a notebook's client: until the kernel stopped).

    Parameters
    ----------
    client : distributed.Client
        The client that submitted ``futures``.
    futures : sequence of distributed.Future

    Returns
    -------
    list
        ``[f.result() for f in futures]``: waited for in order, so of
        several failures the first future's is raised, whichever failed
        first.
    """
    try:
        return [f.result() for f in futures]
    except BaseException:
        with contextlib.suppress(Exception):  # a closed client has none left
            client.cancel(list(futures))
        raise


def _connect_timeout(timeout) -> float:
    """The connection timeout in seconds: the one given, or Dask's setting."""
    name = "timeout"
    if timeout is None:
        import dask
        from dask.utils import parse_timedelta

        timeout = dask.config.get(_CONNECT_SETTING)
        name = f"Dask's setting {_CONNECT_SETTING}"
        with contextlib.suppress(TypeError, ValueError, KeyError):
            timeout = parse_timedelta(timeout, "s")
    if (
        isinstance(timeout, bool)
        or not isinstance(timeout, numbers.Real)
        or not 0 < timeout < math.inf
    ):
        raise InvalidOptionError(
            f"{name} must be a positive number of seconds, got {describe(timeout)}"
        )
    return float(timeout)


def _check_encryption(address: str) -> None:
    """Refuse a TLS address when Dask's configuration holds no TLS settings.

    Dask would otherwise fail inside its connector, before any connection, with
    a ``TypeError`` about a missing ``ssl_context``.
    """
    from distributed import Security

    scheme = address.partition("://")[0] if "://" in address else "tcp"
    if scheme not in ("tls", "wss"):
        return
    if Security().get_connection_args("client").get("ssl_context") is None:
        raise InvalidOptionError(
            f"the scheduler address {address!r} asks for TLS, but Dask's "
            "configuration has no TLS settings (distributed.comm.tls.*): set them, "
            "or connect a distributed.Client with your Security and pass it"
        )


def _reply_failure(error: BaseException) -> str:
    """What of the reply ``error`` was raised on: ``""`` if not on a reply.

    ``"decoding"``: it passed through Dask's ``distributed.protocol``, which
    decodes what arrived, so the address answered with bytes that are not a
    Dask message.  ``"handshake"``: the reply decoded but Dask could not match
    it with its own handshake (``handshake_configuration``: no Dask, or another
    version of it).
    """
    frames = [frame for frame, _ in traceback.walk_tb(error.__traceback__)]
    if any(
        str(frame.f_globals.get("__name__", "")).startswith("distributed.protocol")
        for frame in frames
    ):
        return "decoding"
    if any(frame.f_code.co_name == "handshake_configuration" for frame in frames):
        return "handshake"
    return ""


class _ThreadFilter(logging.Filter):
    """Drops the log records of the given threads."""

    def __init__(self, *threads: int) -> None:
        super().__init__()
        self.threads = set(threads)

    def filter(self, record: logging.LogRecord) -> bool:
        return record.thread not in self.threads


@contextlib.contextmanager
def _quiet(*threads: int) -> Iterator[_ThreadFilter]:
    """Keep Dask's log records of ``threads`` off its handlers for the block.

    A foreign reply makes Dask log its decoding failure (CRITICAL, with a
    traceback) and, when the comm it left open is collected, a dangling-stream
    warning: the failure is reported once, by the error this module raises.
    Records of other threads pass.
    """
    keep = _ThreadFilter(*threads)
    handlers, logger = [], logging.getLogger("distributed")
    while logger is not None:
        handlers += logger.handlers
        logger = logger.parent if logger.propagate else None
    for handler in handlers:
        handler.addFilter(keep)
    try:
        yield keep
    finally:
        for handler in handlers:
            handler.removeFilter(keep)


def _check_handshake(address: str, seconds: float) -> None:
    """Connect to ``address`` and complete Dask's handshake, or raise.

    ``distributed.Client`` bounds only the connection by its timeout: a reply
    that never comes to its handshake is waited for forever, and a foreign
    reply is read as a Dask frame (an ``SSH-2.0-`` banner asks for an array of
    exabytes).  So the handshake is tried first, under an overall deadline, by
    Dask's own ``connect`` with the connection arguments a Client would use.
    It runs on an event loop in a thread of its own, as the caller may be on a
    running loop (a notebook's).  Raises :class:`_NoHandshake` when no
    handshake came within the timeout and :data:`HANDSHAKE_GRACE`, and
    whatever ``connect`` raised otherwise.
    """
    from distributed import Security
    from distributed.comm import connect

    deadline = seconds + HANDSHAKE_GRACE
    connection_args = Security().get_connection_args("client")

    async def handshake():
        attempt = asyncio.ensure_future(
            connect(address, timeout=seconds, **connection_args)
        )
        done, _ = await asyncio.wait({attempt}, timeout=deadline)
        if not done:
            attempt.cancel()  # aborts the connection Dask was reading from
            with contextlib.suppress(asyncio.CancelledError, Exception):
                await attempt
            raise _NoHandshake(f"no reply to Dask's handshake in {deadline:g} s")
        await attempt.result().close()

    outcome: list[BaseException] = []

    def run():
        quiet.threads.add(threading.get_ident())
        try:
            asyncio.run(handshake())
        except BaseException as e:  # handed to the caller's thread
            outcome.append(e)

    thread = threading.Thread(target=run, name="drakegrasp-dask-handshake",
                              daemon=True)  # fmt: skip
    with _quiet() as quiet:
        thread.start()
        thread.join(deadline + HANDSHAKE_GRACE)  # the loop keeps the deadline
    if thread.is_alive():
        raise _NoHandshake(f"no reply to Dask's handshake in {deadline:g} s")
    if outcome:
        raise outcome[0]


def _failure(
    error: BaseException, seconds: float, shook_hands: bool, reply: str = ""
) -> str:
    """Why a connection failed, for the error naming the address.

    ``shook_hands``: the address completed Dask's handshake, and the Client
    failed after it.  ``reply``: what of a reply the error was raised on
    (:func:`_reply_failure`).
    """
    from distributed.comm import CommClosedError
    from distributed.comm.core import FatalCommClosedError

    if isinstance(error, _NoHandshake):
        return (
            "the address accepted the connection but did not complete Dask's "
            f"handshake within {seconds + HANDSHAKE_GRACE:g} s: it is not a Dask "
            "scheduler (a scheduler listens on port 8786 unless told otherwise)"
        )
    reason = " ".join(str(error).split())
    # connect retries every error of the connection itself until the timeout
    # and raises OSError then; a closed comm comes from the handshake.
    closed = isinstance(error, CommClosedError) and not isinstance(
        error, FatalCommClosedError
    )
    if isinstance(error, (OSError, ValueError)) and not (closed or reply):
        return _short(reason) or type(error).__name__  # unreachable, malformed
    typed = type(error).__name__ + (f": {_short(reason)}" if reason else "")
    if reply == "handshake":
        return (
            "the address answered, but its reply is not the handshake of this "
            f"Dask version: it is not a Dask scheduler, or one of another version "
            f"({typed})"
        )
    if shook_hands:  # a worker's address, say
        return (
            "the address completed Dask's handshake but did not take a client "
            f"as a scheduler does ({typed})"
        )
    if closed:
        return (
            "the address accepted the connection but closed it during Dask's "
            f"handshake: it is not a Dask scheduler ({typed})"
        )
    return (
        "the address answered but is not a Dask scheduler: its reply is not "
        f"Dask's handshake ({typed})"
    )


def _short(reason: str) -> str:
    return reason if len(reason) <= 160 else reason[:157] + "..."


def _clear_frames(error: BaseException) -> None:
    """Drop the locals of the tracebacks of ``error`` and of its chained errors.

    The tracebacks stay (file, line and code for the report); only the objects
    their frames held, such as a half-made Client, are let go.
    """
    seen, pending = set(), [error]
    while pending:
        error = pending.pop()
        if error is None or id(error) in seen:
            continue
        seen.add(id(error))
        traceback.clear_frames(error.__traceback__)
        pending += [error.__cause__, error.__context__]
