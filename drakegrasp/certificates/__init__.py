"""Certificates: the witness of every closure verdict, its check and its wording.

:mod:`~drakegrasp.certificates.certificate` holds the frozen
:class:`~drakegrasp.certificates.certificate.Certificate` and its solver-free
re-check, :mod:`~drakegrasp.certificates.kinds` the four kinds and their meaning,
:mod:`~drakegrasp.certificates.text` the words a report prints,
:mod:`~drakegrasp.certificates.load` the witness that a load cannot be held
(a Farkas dual of the grasp-force system), and
:mod:`~drakegrasp.certificates.witness` the small programs that find a
witness.  The layer imports only the core (and the solver gateway): the
closure programs import it, never the reverse.
"""

from drakegrasp._lazy import lazy_exports

_SOURCES = {
    "drakegrasp.certificates.certificate": ("Certificate", "CertificateCheck"),
    "drakegrasp.certificates.load": ("LoadCertificate",),
}

_SUBMODULES = (
    "_matching",
    "certificate",
    "kinds",
    "load",
    "text",
    "witness",
)

__getattr__, __dir__ = lazy_exports(
    __name__, globals(), _SOURCES, submodules=_SUBMODULES
)

__all__ = ["Certificate", "CertificateCheck", "LoadCertificate"]
