"""Per-grasp quality metrics of a chunk of grasps (singular values of G, ε L1)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from drakegrasp.errors import InvalidOptionError

__all__ = ["epsilon_l1_per_grasp", "singular_value_metrics"]

SINGULAR_VALUE_METRICS = ("sigma_min", "isotropy", "ellipsoid_volume")


def singular_value_metrics(
    G: np.ndarray, b: np.ndarray, names: Sequence[str]
) -> dict[str, np.ndarray]:
    """σ_min, σ_min/σ_max and ∏σ of ``G`` with moment rows divided by ``b``.

    Parameters
    ----------
    G : (k, w, M) float
        Grasp matrices about the grasps' reference points.
    b : (k,) float
        Characteristic lengths, metres.
    names : sequence of str
        The metrics wanted (others are ignored).

    Returns
    -------
    dict of str to (k,) float
    """
    wanted = [n for n in names if n in SINGULAR_VALUE_METRICS]
    if not wanted:
        return {}
    w = G.shape[1]
    f = 2 if w == 3 else 3
    Gs = G.copy()
    Gs[:, f:, :] /= b[:, None, None]
    sv = np.linalg.svd(Gs, compute_uv=False)
    if sv.shape[1] < w:  # fewer columns than wrench rows: the rest are zero
        sv = np.concatenate([sv, np.zeros((sv.shape[0], w - sv.shape[1]))], axis=1)
    out = {}
    if "sigma_min" in wanted:
        out["sigma_min"] = sv[:, -1]
    if "isotropy" in wanted:
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = sv[:, -1] / sv[:, 0]
        out["isotropy"] = np.where(sv[:, 0] > 0.0, ratio, 0.0)
    if "ellipsoid_volume" in wanted:
        out["ellipsoid_volume"] = np.prod(sv, axis=1)
    return out


def epsilon_l1_per_grasp(
    P, Nrm, mu, nu, p, b, *, model: str, num_generators: int
) -> np.ndarray:
    """Ferrari–Canny L1 ε of each grasp through :func:`drakegrasp.ferrari_canny`.

    One call per grasp (slow); shapes as :func:`drakegrasp.batch.chunks.force_chunk`.
    """
    try:
        from drakegrasp.quality import ferrari_canny
    except ImportError as exc:
        raise InvalidOptionError(
            "metric 'epsilon_l1' needs drakegrasp.quality.ferrari_canny, which "
            "this installation does not provide"
        ) from exc
    from drakegrasp.contact import Contact
    from drakegrasp.grasp import Grasp

    out = np.empty(P.shape[0])
    for k in range(P.shape[0]):
        contacts = [
            Contact(
                P[k, i],
                Nrm[k, i],
                mu=mu[k, i],
                model=model,
                torsional_friction=nu[k, i],
            )
            for i in range(P.shape[1])
        ]
        grasp = Grasp(contacts, reference_point=p[k], characteristic_length=b[k])
        out[k] = float(ferrari_canny(grasp, norm="L1", num_generators=num_generators))
    return out
