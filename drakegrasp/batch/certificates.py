"""Certificates of batch verdicts: why each failing grasp of a batch fails.

:func:`batch_certificates` takes the arrays a batch was run on and its
:class:`~drakegrasp.batch.BatchClosureResult`, and returns, for every grasp
whose verdict is "no", the same witness as the single-grasp path
(:mod:`drakegrasp.certificates`): an escape twist for form closure, an
unresisted wrench (polyhedral cones) for force closure.  The witnesses are
computed per failing grasp with the core's witness programs, which take a
fraction of a verdict's time (``benchmarks/bench_core.py``); a "yes" carries
no witness here, because the batched interior-point method does not keep the
optimal forces.

Every twist and wrench is in the grasp's frame about its reference point, with
the orders and scalings of :class:`~drakegrasp.certificates.Certificate`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drakegrasp.certificates import Certificate, CertificateCheck
from drakegrasp.closure import DEFAULT_RANK_TOL, _balance_matrix, _balance_rank
from drakegrasp.contact import Contact, ContactModel
from drakegrasp.errors import InvalidOptionError
from drakegrasp.friction_cone import ConeLayout
from drakegrasp.grasp import Grasp
from drakegrasp.witness import escape_twist, unresisted_wrench

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
        ``contact_rates`` of :class:`~drakegrasp.certificates.Certificate`, per grasp.
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


def _per_contact(value, K: int, N: int, name: str) -> np.ndarray:
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


def _core_rank(grasp: Grasp, form: bool, num_generators: int) -> int:
    if form:
        cols = grasp.normal_indices()
    else:
        cols = ConeLayout.of(grasp, num_generators).columns
    return _balance_rank(_balance_matrix(grasp, cols), DEFAULT_RANK_TOL)


def grasp_at(
    positions,
    normals,
    k: int,
    *,
    mu=0.0,
    model: ContactModel | str = "hard_finger",
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
    mus = _per_contact(mu, K, N, "mu")[k]
    nus = _per_contact(torsional_friction, K, N, "torsional_friction")[k]
    model = ContactModel.parse(model)
    contacts = [
        Contact(P[i], n[i], mu=mus[i], model=model, torsional_friction=nus[i])
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


def batch_certificates(
    positions,
    normals,
    result,
    *,
    mu=0.0,
    model: ContactModel | str = "hard_finger",
    num_generators: int = 8,
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
    mu, model, num_generators, torsional_friction, reference_points,
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
    for k in np.flatnonzero(~np.asarray(result.is_closure)):
        g = grasp_at(
            positions,
            normals,
            int(k),
            mu=mu,
            model="frictionless" if form else model,
            torsional_friction=torsional_friction,
            reference_points=reference_points,
            characteristic_lengths=characteristic_lengths,
        )
        # the witness's rank is the core's, on the normalised G (the batch's
        # own rank decided the verdict; they agree in the agreement tests)
        rank = _core_rank(g, form, num_generators)
        if form:
            cert = escape_twist(g, rank)
        else:
            cert = unresisted_wrench(
                g, rank, cones="polyhedral", num_generators=num_generators
            )
        certs[k] = cert
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
