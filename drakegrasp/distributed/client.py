"""The Dask client the distributed drivers run on (needs the ``dask`` extra)."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

from drakegrasp.errors import InvalidOptionError

__all__ = ["client_for", "connected"]


def client_for(client_or_address):
    """A ``distributed.Client``: the one given, or one connected to an address."""
    try:
        from distributed import Client
    except ImportError as exc:
        raise InvalidOptionError(
            "drakegrasp.distributed needs the optional packages dask and "
            "distributed (pip install drakegrasp[dask])"
        ) from exc
    if isinstance(client_or_address, str):
        return Client(client_or_address)
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
