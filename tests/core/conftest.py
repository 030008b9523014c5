"""Shared generators of random grasps for the core tests (seeded)."""

import numpy as np
import pytest

import drakegrasp as dg


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q @ np.diag(np.sign(np.diag(r)))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


def random_inward_contacts(
    rng, num, dim=3, *, mu=0.5, model="hard_finger", tilt=0.6, nu=0.0
):
    """Contacts on the unit sphere/circle, normals tilted from the inward radial.

    Normal ``-p + tilt * z`` with ``z`` standard normal.  Test modules import it
    (``from .conftest import random_inward_contacts``) for hypothesis tests,
    which cannot take function-scoped fixtures.
    """
    contacts = []
    for _ in range(num):
        p = rng.normal(size=dim)
        p /= np.linalg.norm(p)
        n = -p + tilt * rng.normal(size=dim)
        contacts.append(
            dg.Contact(p, n, mu=mu, contact_model=model, torsional_friction=nu)
        )
    return contacts


@pytest.fixture
def rng():
    return np.random.default_rng(20261122)


@pytest.fixture
def make_contacts():
    """The function ``random_inward_contacts`` (fixtures are how tests share it)."""
    return random_inward_contacts
