"""proofs: an independent checker of certkin certificates (docs/certificates.md).

It imports neither ``certkin`` nor ``intervals``: only the standard library
and mpmath's ``iv`` interval arithmetic.  It rebuilds det(A) from the exact
geometry stated in the certificate (``models``), derives every box of the
search tree from the claimed box, and re-proves each leaf's rule
(``rules``, ``singularity``).  It is the trusted kernel, so it stays small:

    numbers.py      exact reading of JSON floats and decimal strings
    ad.py           forward-mode differentiation over iv intervals
    det.py          Laplace expansion of det(A)
    models.py       the model equations
    rules.py        natural / centred / monotone, with bounded bisection
    singularity.py  claims: trees, witnesses, requested boxes
    fk.py           forward-kinematics claims: Krawczyk, Gauss-Seidel, the tree, distinct postures
    trajectory.py   trajectory claims: tiling of [0, 1], leaf states re-proved, verdict, violations
    workspace.py    workspace claims: the paving of a section or of z slabs
    checker.py      header checks, precision, check / check_file
    __main__.py     python -m proofs CERT.json [--prec N]

    >>> report = proofs.check(cert)          # or proofs.check_file(path)
    >>> report.ok, report.step, report.checked
"""
from .checker import check, check_file, load
from .report import Rejected, Report

__all__ = ["check", "check_file", "load", "Report", "Rejected"]
