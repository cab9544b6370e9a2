"""python -m proofs CERT.json [--prec N]: one line, exit 0 (OK), 1 (REJECTED), 2 (unreadable)."""
from __future__ import annotations

import argparse
import sys

from .checker import check, load


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m proofs", description="Re-verify a certkin certificate.")
    p.add_argument("certificate", help="certificate file (JSON)")
    p.add_argument("--prec", type=int, default=80, help="iv precision in bits (default 80, at least 53)")
    args = p.parse_args(argv)
    if not 53 <= args.prec <= 100_000:
        p.error("--prec must be between 53 and 100000")
    try:
        cert = load(args.certificate)
    except (OSError, ValueError) as exc:
        print(f"{args.certificate}: cannot read the certificate: {exc}", file=sys.stderr)
        return 2
    report = check(cert, args.prec)
    print(report)
    return 0 if report.ok else 1


if __name__ == "__main__":
    sys.exit(main())
