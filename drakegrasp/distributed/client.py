"""The Dask client the distributed drivers run on (needs the ``dask`` extra)."""

from __future__ import annotations

import contextlib
import gc
from collections.abc import Iterator

from drakegrasp.errors import InvalidOptionError

__all__ = ["client_for", "connected"]


def client_for(client_or_address):
    """A ``distributed.Client``: the one given, or one connected to an address.

    Raises
    ------
    InvalidOptionError
        Neither a client nor an address, an address with a port outside
        1..65535, or a scheduler that cannot be reached (Dask's own
        connection timeout, 30 s by default), naming the address.
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
                f"the scheduler address {client_or_address!r} has port {port}; "
                "a port is in 1..65535"
            )
        try:
            return Client(client_or_address)
        except (OSError, TimeoutError, ValueError) as e:
            reason = " ".join(str(e).split())
        # The half-made Client is cyclic garbage, held until now by the error's
        # traceback.  Left to a later collection, its __del__ may run inside
        # another Client's start, where its close waits on the loop lock that
        # start holds: a deadlock (seen in the test suite).  Finalise it here,
        # and raise outside the except block so nothing keeps it alive.
        gc.collect()
        raise InvalidOptionError(
            f"could not connect to the Dask scheduler at {client_or_address!r}: "
            f"{reason}"
        )
    if not isinstance(client_or_address, Client):
        raise InvalidOptionError(
            "client must be a distributed.Client or a scheduler address such as "
            f"'tcp://host:8786', got {client_or_address!r}"
        )
    return client_or_address


@contextlib.contextmanager
def connected(client_or_address) -> Iterator:
    """:func:`client_for` as a context: a client made from an address is closed.

    A client the caller passed stays open; one this call connected is closed on
    exit, so a command line run leaves no client reconnecting to a scheduler.
    """
    client = client_for(client_or_address)
    try:
        yield client
    finally:
        if client is not client_or_address:
            client.close()
