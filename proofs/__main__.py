"""python -m proofs CERT [--robot ROBOT.toml] [--json] [--progress]: the same as ``certkin check`` (docs/certificates.md).

Exit code 0 valid, 1 rejected (``REJECTED: <the failing step>``), 2 unreadable (one line on stderr, no traceback)."""
from __future__ import annotations

import argparse
import sys

from .checker import run


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        print(f"{self.prog}: {message}", file=sys.stderr)
        raise SystemExit(2)


def main(argv=None) -> int:
    p = _Parser(prog="python -m proofs", description="Re-verify a certkin certificate with the independent checker.")
    p.add_argument("certificate", help="certificate file")
    p.add_argument("--robot", metavar="ROBOT.toml", help="also confirm that the geometry is this robot file's, exactly")
    p.add_argument("--json", action="store_true", help="print one JSON document")
    p.add_argument("--progress", action="store_true", help="show a progress bar on stderr")
    args = p.parse_args(argv)
    return run(args.certificate, args.robot, args.json, args.progress)


if __name__ == "__main__":
    sys.exit(main())
