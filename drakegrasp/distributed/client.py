"""The Dask client the distributed drivers run on (needs the ``dask`` extra)."""

from __future__ import annotations

from drakegrasp.errors import InvalidOptionError

__all__ = ["client_for"]


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
