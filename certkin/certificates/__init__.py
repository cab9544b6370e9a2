"""Certificates: every certified answer as a file the independent checker ``proofs`` re-verifies.

``writing`` holds the version-2 container (a ZIP archive: JSON header, hashed body arrays, streamed
and written atomically), ``forest`` the search trees as breadth-first arrays; one module per
capability builds its header and body (``singularity``, ``fk``, ``trajectory``, ``workspace``).  The
format is ``docs/certificates.md``.
"""
from .fk import fk_certificate
from .singularity import singularity_claim, singularity_certificate
from .trajectory import trajectory_certificate
from .workspace import section_certificate, volume_certificate
from .writing import FORMAT, VERSION, Document, geometry_sha256, header, temporary_of, write_text

__all__ = ["FORMAT", "VERSION", "Document", "header", "geometry_sha256", "temporary_of", "write_text", "fk_certificate",
           "singularity_claim",
           "singularity_certificate", "trajectory_certificate", "section_certificate", "volume_certificate"]
