"""Certificates of batch verdicts: why each failing grasp of a batch fails.

:func:`batch_certificates` takes the arrays a batch was run on and its
:class:`~drakegrasp.batch.BatchClosureResult`, and returns, for every grasp
whose verdict is "no", the same witness as the single-grasp path
(:mod:`drakegrasp.certificates.certificate`): an escape twist for form closure, an
unresisted wrench (polyhedral cones) for force closure.  The witnesses are
computed per failing grasp with the core's witness programs, which take a
fraction of a verdict's time (``benchmarks/bench_core.py``); a "yes" carries
no witness here, because the batched interior-point method does not keep the
optimal forces.

Every twist and wrench is in the grasp's frame about its reference point, with
the orders and scalings of :class:`~drakegrasp.certificates.certificate.Certificate`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drakegrasp.batch.build.construction import (
    batched_characteristic_lengths,
    batched_grasp_matrix,
    batched_normal_grasp_matrix,
    contact_kinds,
)
from drakegrasp.certificates.certificate import Certificate, CertificateCheck
from drakegrasp.certificates.witness import (
    GraspFrame,
    escape_twist,
    null_space_certificate,
    unresisted_wrench,
)
from drakegrasp.closure.programs import balance_matrix, balance_rank
from drakegrasp.core.contact import Contact, ContactModel
from drakegrasp.core.deprecation import renamed_keyword
from drakegrasp.core.friction_cone import ConeLayout
from drakegrasp.core.grasp import Grasp
from drakegrasp.core.linalg import equilibrated
from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS, DEFAULT_RANK_TOL
from drakegrasp.errors import InvalidOptionError

__all__ = ["BatchCertificates", "batch_certificates", "grasp_at"]


@dataclass(frozen=True)
class BatchCertificates:
    """Witnesses of the "no" verdicts of a batch, as arrays.

    Attributes
    ----------
    kind : str
        ``"escape twist"`` (form closure) or ``"unresisted wrench"``.
    has_witness : (K,) bool
        True where the verdict is "no" and a witness was found (a "no" within
        ``tol`` of the boundary has none, as in the single path).
    direction : (K, w) float
        Escape twist ``[v_p; ω]`` or unresisted wrench ``[f; m]`` per grasp
        (NaN rows where ``has_witness`` is False).
    separating_twist : (K, w) float
        Force closure: the hyperplane normal ``y`` with ``yᵀ G f <= 0``
        (NaN for form closure and where there is no witness).
    two_sided : (K,) bool
        Rank-deficient grasps: both signs of ``direction`` are witnesses.
    null_dim : (K,) int
        Dimension of the left null space the witness was taken from (0 for a
        full-rank "no").
    contact_rates : (K, N) float
        ``Certificate.contact_rates`` per grasp.
    certificates : tuple of Certificate or None
        The full witness of each grasp (None for a "yes").
    """

    kind: str
    has_witness: np.ndarray
    direction: np.ndarray
    separating_twist: np.ndarray
    two_sided: np.ndarray
    null_dim: np.ndarray
    contact_rates: np.ndarray
    certificates: tuple[Certificate | None, ...]

    def __len__(self) -> int:
        return len(self.certificates)

    def check(self, grasps) -> list[CertificateCheck | None]:
        """Re-verify every witness on its grasp (a sequence of ``Grasp``)."""
        return [
            None if c is None else c.check(g)
            for c, g in zip(self.certificates, grasps, strict=True)
        ]


def per_contact_getter(value, K: int, N: int, name: str) -> np.ndarray:
    a = np.asarray(value, dtype=float)
    if a.ndim == 1 and a.shape == (K,):
        a = a[:, None]
    try:
        return np.broadcast_to(a, (K, N))
    except ValueError:
        raise InvalidOptionError(
            f"{name} must be a scalar or of shape (K,), (K, 1), (1, N) or (K, N) "
            f"= ({K}, {N}); got shape {a.shape}"
        ) from None


def _null_space_witnesses(
    positions, normals, result, rows, form, num_generators, **options
) -> dict[int, Certificate]:
    """Vectorised witnesses of the rank-deficient "no"s (no Grasp, no solver).

    The normalised balance matrices of the rows are built at once (moments
    about each grasp's contacts' centroid over their spread, as
    :func:`~drakegrasp.core.grasp.invariant_grasp_matrix`), and each row's left
    null space at the batch's rank is the witness.  A row whose trailing
    singular values are not numerically zero (the ranks disagree) is left to
    the per-grasp path.
    """
    if rows.size == 0:
        return {}
    P = np.asarray(positions[rows], dtype=float)
    n = np.asarray(normals[rows], dtype=float)
    n = n / np.linalg.norm(n, axis=2, keepdims=True)
    K_all, N, d = len(positions), P.shape[1], P.shape[2]
    p = _reference(options["reference_points"], K_all, d)[rows]
    b = _lengths(options["characteristic_lengths"], P, p, rows)
    centroid = P.mean(axis=1)
    spread = np.max(np.linalg.norm(P - centroid[:, None], axis=2), axis=1)
    spread = np.where(np.isfinite(spread) & (spread > 0.0), spread, 1.0)
    if form:
        A = batched_normal_grasp_matrix(P, n, centroid)
        G_n = batched_normal_grasp_matrix(P, n, p)
        layouts = np.zeros((len(rows), 1), dtype=int)
    else:
        mus = per_contact_getter(options["mu"], K_all, N, "mu")[rows]
        nus = per_contact_getter(options["torsional_friction"], K_all, N, "nu")[rows]
        contact_model = ContactModel.parse(options["contact_model"]).value
        layouts = contact_kinds(mus, nus, contact_model=contact_model, dim=d)
    out: dict[int, Certificate] = {}
    for layout in np.unique(layouts, axis=0):
        group = np.flatnonzero((layouts == layout).all(axis=1))
        if not form:
            Ag = batched_grasp_matrix(
                P[group], n[group], centroid[group], tuple(layout)
            )[0]
        else:
            Ag = A[group]
        Ag = Ag.copy()
        Ag[:, d:, :] /= spread[group, None, None]
        sv = np.linalg.svd(equilibrated(Ag)[0], compute_uv=False)
        for j, row in zip(group, rows[group], strict=True):
            rank = int(result.rank[row])
            tail = sv[j, rank:] if rank < sv.shape[1] else np.zeros(0)
            if tail.size and tail.max() > DEFAULT_RANK_TOL * sv[j, 0]:
                continue  # the batch's rank is not this matrix's: per grasp
            frame = GraspFrame(P[j], p[j], float(b[j]))
            out[int(row)] = null_space_certificate(
                frame,
                Ag[j],
                rank,
                G_n=G_n[j] if form else None,
                cones="polyhedral",
                num_generators=num_generators,
            )
    return out


def _reference(value, K: int, d: int) -> np.ndarray:
    if value is None:
        return np.zeros((K, d))
    r = np.asarray(value, dtype=float)
    return np.broadcast_to(r, (K, d)) if r.shape == (d,) else r


def _lengths(value, P, p, rows) -> np.ndarray:
    if value is None:
        return batched_characteristic_lengths(P, p)
    c = np.asarray(value, dtype=float)
    return np.full(len(rows), float(c)) if c.shape == () else c[rows]


def _witness(grasp: Grasp, rank: int, form: bool, num_generators: int):
    if form:
        return escape_twist(grasp, rank)
    return unresisted_wrench(
        grasp, rank, cones="polyhedral", num_generators=num_generators
    )


def _core_rank(grasp: Grasp, form: bool, num_generators: int) -> int:
    if form:
        cols = grasp.normal_indices()
    else:
        cols = ConeLayout.of(grasp, num_generators).columns
    return balance_rank(balance_matrix(grasp, cols), DEFAULT_RANK_TOL)


@renamed_keyword("model", "contact_model")
def grasp_at(
    positions,
    normals,
    k: int,
    *,
    mu=0.0,
    contact_model: ContactModel | str = "hard_finger",
    torsional_friction=0.0,
    reference_points=None,
    characteristic_lengths=None,
) -> Grasp:
    """The single-path :class:`~drakegrasp.Grasp` of grasp ``k`` of a batch.

    Parameters are those of :func:`drakegrasp.batch_force_closure`.
    """
    P = np.asarray(positions[k], dtype=float)
    n = np.asarray(normals[k], dtype=float)
    N, d = P.shape
    K = len(positions)
    mus = per_contact_getter(mu, K, N, "mu")[k]
    nus = per_contact_getter(torsional_friction, K, N, "torsional_friction")[k]
    contact_model = ContactModel.parse(contact_model)
    contacts = [
        Contact(
            P[i],
            n[i],
            mu=mus[i],
            contact_model=contact_model,
            torsional_friction=nus[i],
        )
        for i in range(N)
    ]
    p = None
    if reference_points is not None:
        r = np.asarray(reference_points, dtype=float)
        p = r if r.shape == (d,) else r[k]
    b = None
    if characteristic_lengths is not None:
        c = np.asarray(characteristic_lengths, dtype=float)
        b = float(c) if c.shape == () else float(c[k])
    return Grasp(contacts, reference_point=p, characteristic_length=b)


@renamed_keyword("model", "contact_model")
def batch_certificates(
    positions,
    normals,
    result,
    *,
    mu=0.0,
    contact_model: ContactModel | str = "hard_finger",
    num_generators: int = DEFAULT_NUM_GENERATORS,
    torsional_friction=0.0,
    reference_points=None,
    characteristic_lengths=None,
) -> BatchCertificates:
    """Witnesses of every "no" of a batch result.

    Parameters
    ----------
    positions, normals : (K, N, d) float
        The arrays the batch was run on (metres; normals into the object).
    result : BatchClosureResult
        Of :func:`~drakegrasp.batch_form_closure` (``kind="form"``) or
        :func:`~drakegrasp.batch_force_closure` (``kind="force"``).
    mu, contact_model, num_generators, torsional_friction, reference_points,
    characteristic_lengths
        As given to the batch call (form closure ignores the friction ones).

    Returns
    -------
    BatchCertificates
    """
    K = len(positions)
    if len(result) != K:
        raise InvalidOptionError(
            f"result has {len(result)} grasps but positions has {K}"
        )
    N, d = np.shape(positions[0])
    w = 3 if d == 2 else 6
    direction = np.full((K, w), np.nan)
    separating = np.full((K, w), np.nan)
    rates = np.full((K, N), np.nan)
    two_sided = np.zeros(K, dtype=bool)
    null_dim = np.zeros(K, dtype=int)
    certs: list[Certificate | None] = [None] * K
    form = result.kind == "form"
    options = {
        "mu": mu,
        "contact_model": contact_model,
        "torsional_friction": torsional_friction,
        "reference_points": reference_points,
        "characteristic_lengths": characteristic_lengths,
    }
    fails = np.flatnonzero(~np.asarray(result.is_closure))
    deficient = fails[np.asarray(result.rank)[fails] < w]
    for k, cert in _null_space_witnesses(
        positions, normals, result, deficient, form, num_generators, **options
    ).items():
        certs[k] = cert
    for k in fails:
        if certs[k] is not None:
            continue
        g = grasp_at(
            positions,
            normals,
            int(k),
            mu=mu,
            contact_model="frictionless" if form else contact_model,
            torsional_friction=torsional_friction,
            reference_points=reference_points,
            characteristic_lengths=characteristic_lengths,
        )
        # The batch's rank decided the verdict; it agrees with the core's on
        # the normalised G in the agreement tests.  A witness that does not
        # check out at that rank is recomputed at the core's rank.
        cert = _witness(g, int(result.rank[k]), form, num_generators)
        if cert is None or not cert.check(g).holds:
            cert = _witness(
                g, _core_rank(g, form, num_generators), form, num_generators
            )
        certs[k] = cert
    for k in fails:
        cert = certs[k]
        if cert is None:
            continue
        direction[k] = cert.direction
        if cert.separating_twist is not None:
            separating[k] = cert.separating_twist
        rates[k] = cert.contact_rates
        two_sided[k] = cert.two_sided
        null_dim[k] = cert.null_basis.shape[1] if cert.two_sided else 0
    return BatchCertificates(
        kind="escape twist" if form else "unresisted wrench",
        has_witness=np.array([c is not None for c in certs]),
        direction=direction,
        separating_twist=separating,
        two_sided=two_sided,
        null_dim=null_dim,
        contact_rates=rates,
        certificates=tuple(certs),
    )
