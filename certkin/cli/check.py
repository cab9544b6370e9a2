"""``certkin check``: re-verify a certificate with the independent checker ``proofs``."""
from __future__ import annotations

import proofs

from ..errors import InputError


def add_arguments(c):
    c.add_argument("certificate")


def run(args):
    try:
        report = proofs.check_file(args.certificate)
    except (OSError, ValueError) as exc:
        raise InputError(args.certificate, "", f"cannot read the certificate ({exc})") from None
    print(("OK: " if report.ok else "REJECTED: ") + report.summary())
    return 0 if report.ok else 1
