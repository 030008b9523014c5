"""The cluster the distributed tests share: a LocalCluster of 2 worker processes."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def client():
    distributed = pytest.importorskip("distributed", reason="dask is an optional extra")
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
        memory_limit="1GiB", host="127.0.0.1",
    )  # fmt: skip
    with distributed.Client(cluster) as c:
        yield c
    cluster.close()
