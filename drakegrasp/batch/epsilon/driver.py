r"""Ferrari–Canny L1 ε of many grasps at once: arrays in, one array out.

:func:`batch_epsilon_l1` is :func:`drakegrasp.quality.ferrari_canny`
(``norm="L1"``) for ``K`` grasps given as stacked arrays, with the same
definition, generators and torque scaling.  It takes the inputs, chunking and
workers of :func:`~drakegrasp.batch.batch_force_closure`, and is what
``metrics=["epsilon_l1"]`` computes there.

**Algorithm.**  ε is the distance from the origin to the nearest facet of the
convex hull ``P`` of the primitive wrenches.  Qhull builds all of ``P``: hundreds to
thousands of facets in 6-D for 3 to 8 contacts.  Only the facets near the
origin matter, so each grasp runs an expanding polytope
(:mod:`drakegrasp.batch.epsilon.kernel`, compiled with numba; Zheng's
incremental algorithm for the Q1 measure, IEEE T-RO 2013, is of this family):

1. a simplex of ``D + 1`` primitive wrenches, each chosen farthest from the
   affine hull of those before (a flat set has ε = 0);
2. repeatedly, the facet of the current polytope ``Q ⊂ P`` nearest to the
   origin (smallest signed offset ``b``): if no wrench lies beyond its
   hyperplane, that hyperplane supports ``P`` and ``ε = max(b, 0)``
   (``ε(Q) = b <= ε(P) <= b``); otherwise the farthest wrench beyond it is
   added (beneath–beyond: the facets it sees are replaced by its cone over
   their horizon).

Three spatial hard fingers need about 5 insertions and 90 facets, eight about
10 and 500, against Qhull's whole hull.  Degenerate inputs are common (a
contact's cone wrenches lie in one 2-flat, symmetric grasps have many coplanar
wrenches) and are handled by the visibility tolerance; what round-off could
still spoil — nearly dependent facet edges, a thin but not flat wrench set (a
cone of ``μ = 1e-12``, a torsion generator of ``ν = 1e12``), an inconsistent
horizon — is detected, and that grasp is computed by
:func:`~drakegrasp.quality.ferrari_canny` (Qhull on whitened wrenches)
instead.  Without numba every grasp takes that route.
"""

from __future__ import annotations

import numpy as np

from drakegrasp.batch.build.construction import batched_characteristic_lengths
from drakegrasp.batch.epsilon.routes import epsilon_l1_batch
from drakegrasp.batch.metrics import check_moment_arms, moment_arms_in_input_order
from drakegrasp.batch.options import takes_batch_options
from drakegrasp.batch.ragged import accepts_ragged
from drakegrasp.batch.run.chunk import force_task
from drakegrasp.batch.run.stream import DEFAULT_CHUNK_SIZE, stream
from drakegrasp.core.calls import checked_call
from drakegrasp.core.contact import ContactModel
from drakegrasp.core.deprecation import keyword_only, renamed_keyword
from drakegrasp.core.tolerances import (
    DEFAULT_NUM_GENERATORS,
    DEFAULT_RANK_TOL,
    DEFAULT_TOL,
)

__all__ = ["batch_epsilon_l1", "epsilon_chunk"]


@renamed_keyword("model", "contact_model")
def epsilon_chunk(P, Nrm, mu_c, nu_c, p, b, *, contact_model, num_generators, kernel):
    """ε L1 of one validated chunk (a worker task); ``b`` None: the default."""
    if b is None:
        b = batched_characteristic_lengths(P, p)
    eps = epsilon_l1_batch(
        P, Nrm, mu_c, nu_c, p, b, contact_model=contact_model,
        num_generators=num_generators, kernel=kernel,
    )  # fmt: skip
    return {"epsilon_l1": eps}


def _merge_epsilon(K: int, _dim: int, parts) -> np.ndarray:
    """ε of a ragged batch's groups, in input order (read-only)."""
    out = np.zeros(K)
    for idx, eps in parts:
        out[idx] = eps
    out.flags.writeable = False
    return out


@checked_call
@renamed_keyword("model", "contact_model")
@keyword_only("mu", after=2)
@accepts_ragged(_merge_epsilon, check=moment_arms_in_input_order)
@takes_batch_options
def batch_epsilon_l1(
    positions: np.ndarray,
    normals: np.ndarray,
    *,
    mu: float | np.ndarray,
    contact_model: ContactModel | str = "hard_finger",
    num_generators: int = DEFAULT_NUM_GENERATORS,
    torsional_friction: float | np.ndarray | None = None,
    reference_points: np.ndarray | None = None,
    characteristic_lengths: float | np.ndarray | None = None,
    chunk_size: int | None = DEFAULT_CHUNK_SIZE,
    progress: bool = False,
    workers: int | None = None,
    kernel: str = "auto",
) -> np.ndarray:
    r"""Ferrari–Canny L1 ε of ``K`` grasps at once.

    Parameters
    ----------
    positions, normals, mu, contact_model, num_generators, torsional_friction
        The contacts, as in :func:`~drakegrasp.batch.batch_force_closure`:
        (K, N, 3) or (K, N, 2) points (metres) and inward normals, ``μ`` and
        ``ν`` as scalars, (K,), (1, N) or (K, N); or ragged, as lists of
        per-grasp arrays.
    reference_points : (d,) or (K, d) float, optional
        Point ``p`` about which moments are taken; default the origin.
    characteristic_lengths : float or (K,) float, optional
        ``b > 0`` metres: moments are divided by it and a soft finger's
        torsion bound is ``b ν``; default the largest ``‖c_i - p‖`` of each
        grasp, as :class:`~drakegrasp.Grasp` does.  A grasp's extent over
        its ``b`` must lie in :data:`~drakegrasp.core.tolerances.MOMENT_ARMS`,
        as in :func:`~drakegrasp.quality.ferrari_canny`.
    chunk_size, progress, workers : optional
        As in :func:`~drakegrasp.batch.batch_force_closure`.
    kernel : {"auto", "numba", "numpy"}, optional
        ``"numba"``: the compiled expanding polytope (see the module notes),
        Qhull for the grasps it flags; ``"numpy"``: Qhull for every grasp (the
        reference); ``"auto"`` takes numba when installed.

    Returns
    -------
    eps : (K,) float
        ε ≥ 0 of each grasp, as :func:`drakegrasp.quality.ferrari_canny` with
        ``norm="L1"`` and ``torque_scale = b`` gives it (0 when the origin is
        not strictly inside the primitive wrenches' hull).  Read-only.

    Notes
    -----
    .. math::

        \varepsilon = \min_{\text{facets } F \text{ of } P} \operatorname{dist}(0, F),
        \qquad P = \operatorname{conv}\{\operatorname{diag}(I, I/b)\, G_i s_k\}
    """
    task, options = force_task(
        positions, mu, contact_model, num_generators, torsional_friction,
        reference_points, characteristic_lengths, DEFAULT_TOL, DEFAULT_RANK_TOL, (),
        kernel,
    )  # fmt: skip
    eps_options = {
        "contact_model": options["contact_model"],
        "num_generators": options["num_generators"],
        "kernel": options["kernel"],
    }

    def eps_task(P, Nrm, sl):
        _, args, _ = task(P, Nrm, sl)
        P_c, _, _, _, p, b = args
        if b is not None:
            check_moment_arms(P_c, p, b, sl.start)
        return epsilon_chunk, args, eps_options

    out = np.zeros(np.shape(positions)[0])
    chunks = stream(
        positions, normals, kind="epsilon", task=eps_task, chunk_size=chunk_size,
        progress=progress, workers=workers, n_g=options["num_generators"],
        contact_model=options["contact_model"],
    )  # fmt: skip
    for sl, arrays in chunks:
        out[sl] = arrays["epsilon_l1"]
    out.flags.writeable = False
    return out
