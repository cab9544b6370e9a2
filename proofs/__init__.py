"""proofs: an independent checker of certkin certificates (docs/certificates.md).

It imports neither ``certkin`` nor ``intervals``: numpy with its own outward rounding, the standard library (exact
rationals) and mpmath (only for a rigorous enclosure of π).  It rebuilds the model equations from the exact geometry
stated in the certificate, derives every box of the search trees from the claimed boxes, and re-proves each leaf's
rule on batches of boxes.  It is the trusted kernel, so it stays small:

    arith.py        interval arithmetic on numpy arrays (outward rounding, sums, products, sin, cos)
    numbers.py      exact reading of floats and decimal strings
    container.py    the file: a ZIP archive (JSON header, hashed body arrays), format version 2
    tree.py         search trees stored breadth-first as arrays; their boxes, level by level
    models.py       det(A) of each model, with forward-mode gradients
    singularity.py  singularity claims: tree rules, witnesses, requested boxes
    fk_system.py    forward-kinematics equations and operators: HC4, Gauss-Seidel, Krawczyk, slopes
    fk.py           forward-kinematics claims: regions, solutions, the rules of the tree
    trajectory.py   trajectory claims: tiling of [0, 1], leaf states re-proved, verdict, violations
    workspace.py    workspace claims: the paving of a section or of z slabs, area and volume bounds
    checker.py      header, geometry hash, dispatch; check / check_file
    report.py       the verdict: what was proved, or the failing step
    __main__.py     python -m proofs CERT [--robot ROBOT.toml] [--json] [--progress]

    >>> report = proofs.check("fk.cert")        # a path, or a document with .header and .arrays
    >>> report.ok, report.step, report.proved
"""
from .checker import check, check_file, geometry_sha256, load, read_robot, run
from .report import Rejected, Report, Unreadable

__all__ = ["check", "check_file", "run", "load", "read_robot", "geometry_sha256", "Report", "Rejected", "Unreadable"]
