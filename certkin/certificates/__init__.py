"""Certificates: every certified answer as a document the independent checker ``proofs`` re-verifies.

``writing`` holds the common header and the atomic file writing; one module per capability
builds its claims (``singularity``, ``fk``, ``trajectory``, ``workspace``).  The format is
``docs/certificates.md``.
"""
from .fk import fk_certificate, fk_claim
from .singularity import singularity_certificate, singularity_claim, singularity_tree
from .trajectory import trajectory_certificate, trajectory_claim
from .workspace import section_certificate, volume_certificate
from .writing import FORMAT, VERSION, header, write_json, write_text

__all__ = ["FORMAT", "VERSION", "header", "write_json", "write_text", "fk_certificate", "fk_claim",
           "singularity_certificate", "singularity_claim", "singularity_tree", "trajectory_certificate",
           "trajectory_claim", "section_certificate", "volume_certificate"]
