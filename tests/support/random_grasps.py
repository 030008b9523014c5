"""Seeded random grasps shared by the core, closure and certificate tests.

:func:`random_inward_contacts` is imported by hypothesis tests (which cannot
take function-scoped fixtures); the other tests get it through the
``make_contacts`` fixture of ``tests/conftest.py``.
"""

from __future__ import annotations

import numpy as np

import drakegrasp as dg


def random_inward_contacts(
    rng, num, dim=3, *, mu=0.5, model="hard_finger", tilt=0.6, nu=0.0
):
    """Contacts on the unit sphere/circle, normals tilted from the inward radial.

    Normal ``-p + tilt * z`` with ``z`` standard normal.
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
