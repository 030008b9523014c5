"""ε L1 of a chunk of grasps, by its two routes.

The compiled expanding-polytope kernel (:mod:`drakegrasp.batch.epsilon.kernel`)
on the chunk's primitive wrenches (:mod:`drakegrasp.batch.build.wrenches`), and
:func:`drakegrasp.quality.ferrari_canny` (Qhull) for the grasps that the kernel
flags and, without numba, for all.

ε is a stage of its own, after the LP: this module takes a chunk's validated
arrays and never runs its LP, and the LP's chunk
(:mod:`drakegrasp.batch.run.chunk`) imports nothing of ε.  The module of the
public API, which chooses the stages, joins them
(:func:`drakegrasp.batch.api.force_chunk_with_epsilon`).
"""

from __future__ import annotations

import numpy as np

from drakegrasp.core.deprecation import renamed_keyword
from drakegrasp.core.tolerances import L1_MAX_POINTS
from drakegrasp.errors import InvalidOptionError

__all__ = [
    "EPSILON_METRIC",
    "epsilon_l1_batch",
    "epsilon_l1_per_grasp",
    "epsilon_l1_routes",
]

EPSILON_METRIC = "epsilon_l1"
"""The metric name of ε L1 among a batch call's ``metrics``."""


@renamed_keyword("model", "contact_model")
def epsilon_l1_per_grasp(
    P, Nrm, mu, nu, p, b, *, contact_model: str, num_generators: int
) -> np.ndarray:
    """Ferrari–Canny L1 ε of each grasp through :func:`drakegrasp.ferrari_canny`.

    One call per grasp (slow); shapes as :func:`drakegrasp.batch.run.chunk.force_chunk`.
    """
    try:
        from drakegrasp.quality import ferrari_canny
    except ImportError as exc:
        raise InvalidOptionError(
            "metric 'epsilon_l1' needs drakegrasp.quality.ferrari_canny, which "
            "this installation does not provide"
        ) from exc
    from drakegrasp.core.contact import Contact
    from drakegrasp.core.grasp import Grasp

    out = np.empty(P.shape[0])
    for k in range(P.shape[0]):
        contacts = [
            Contact(
                P[k, i],
                Nrm[k, i],
                mu=mu[k, i],
                contact_model=contact_model,
                torsional_friction=nu[k, i],
            )
            for i in range(P.shape[1])
        ]
        grasp = Grasp(contacts, reference_point=p[k], characteristic_length=b[k])
        out[k] = float(ferrari_canny(grasp, norm="L1", num_generators=num_generators))
    return out


def _check_point_count(W_counts: np.ndarray) -> None:
    if W_counts.size and int(W_counts.max()) > L1_MAX_POINTS:
        raise InvalidOptionError(
            f"the Ferrari–Canny metric of a grasp here needs the hull of "
            f"{int(W_counts.max())} primitive wrenches (more than L1_MAX_POINTS = "
            f"{L1_MAX_POINTS}); use fewer contacts or fewer generators"
        )


def _point_counts(mu, nu, *, contact_model: str, dim: int, num_generators: int):
    """Primitive wrenches of each grasp, as :func:`primitive_wrenches` counts them."""
    if contact_model == "frictionless":
        per = np.ones(mu.shape)
    elif dim == 2:
        per = np.where(mu > 0.0, 2.0, 1.0)
    else:
        per = np.where(mu > 0.0, float(num_generators), 1.0)
        if contact_model == "soft_finger":
            per = np.where(nu > 0.0, np.where(mu > 0.0, per + 2.0, 2.0), per)
    return per.sum(axis=1)


@renamed_keyword("model", "contact_model")
def epsilon_l1_routes(
    P, Nrm, mu, nu, p, b, *, contact_model: str, num_generators: int,
    kernel: str = "auto",
) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Ferrari–Canny L1 ε of each grasp and which grasps took the Qhull route.

    Parameters
    ----------
    P, Nrm, mu, nu, p, b
        Validated chunk arrays, as :func:`drakegrasp.batch.run.chunk.force_chunk`
        takes them (``b`` the characteristic lengths, not None).
    contact_model : str
        Contact model name.
    num_generators : int
    kernel : {"auto", "numba", "numpy"}, optional
        ``"numba"`` (or ``"auto"`` with numba installed): the compiled kernel,
        Qhull for the grasps it flags; ``"numpy"`` (or no numba): Qhull for all.

    Returns
    -------
    eps : (k,) float
        ε as :func:`drakegrasp.quality.ferrari_canny` defines it (moments
        divided by ``b``).
    qhull : (k,) bool
        The grasps computed per grasp by Qhull.
    """
    import drakegrasp.batch.epsilon.kernel as epsilon_kernel
    from drakegrasp.batch.build.wrenches import batched_primitive_wrenches

    _check_point_count(
        _point_counts(
            mu,
            nu,
            contact_model=contact_model,
            dim=P.shape[2],
            num_generators=num_generators,
        )
    )
    k = P.shape[0]
    compiled = kernel == "numba" or (kernel == "auto" and epsilon_kernel.AVAILABLE)
    if not compiled or k == 0:
        eps = epsilon_l1_per_grasp(
            P,
            Nrm,
            mu,
            nu,
            p,
            b,
            contact_model=contact_model,
            num_generators=num_generators,
        )
        return eps, np.ones(k, dtype=bool)
    W = batched_primitive_wrenches(
        P, Nrm, mu, nu, p, b, contact_model=contact_model, num_generators=num_generators
    )
    eps, status = epsilon_kernel.epsilon_l1_stack(W)
    qhull = status > epsilon_kernel.FLAT
    rows = np.flatnonzero(qhull)
    if rows.size:
        eps[rows] = epsilon_l1_per_grasp(
            P[rows], Nrm[rows], mu[rows], nu[rows], p[rows], b[rows],
            contact_model=contact_model, num_generators=num_generators,
        )  # fmt: skip
    return eps, qhull


@renamed_keyword("model", "contact_model")
def epsilon_l1_batch(
    P, Nrm, mu, nu, p, b, *, contact_model: str, num_generators: int,
    kernel: str = "auto",
) -> np.ndarray:  # fmt: skip
    """Ferrari–Canny L1 ε of each grasp of a chunk; see :func:`epsilon_l1_routes`."""
    return epsilon_l1_routes(
        P, Nrm, mu, nu, p, b, contact_model=contact_model,
        num_generators=num_generators, kernel=kernel,
    )[0]  # fmt: skip
