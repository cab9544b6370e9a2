"""python -m proofs CERT [--robot ROBOT.toml] [--json] [--progress]

Prints the robot (name, geometry SHA-256), the question, what was proved and
``OK: ...`` — or ``REJECTED: <the failing step>``.  Exit code 0 valid,
1 checked and rejected, 2 unreadable (one line on stderr, no traceback).
``certkin check`` is this same command.
"""
from __future__ import annotations

import argparse
import json
import sys

from .checker import check, load
from .report import Unreadable


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        print(f"{self.prog}: {message}", file=sys.stderr)
        raise SystemExit(2)


def main(argv=None, prog="python -m proofs") -> int:
    p = _Parser(prog=prog, description="Re-verify a certkin certificate with the independent checker.")
    p.add_argument("certificate", help="certificate file (version 2 archive, or version 1 JSON)")
    p.add_argument("--robot", metavar="ROBOT.toml", help="also confirm that the geometry is this robot file's, exactly")
    p.add_argument("--json", action="store_true", help="print one JSON document")
    p.add_argument("--progress", action="store_true", help="show a progress bar on stderr")
    args = p.parse_args(argv)
    progress = _bar if args.progress else None
    try:
        report = check(load(args.certificate), robot=args.robot, progress=progress)
    except Unreadable as exc:
        print(f"{args.certificate}: cannot read the certificate: {exc}", file=sys.stderr)
        return 2
    except (MemoryError, RecursionError) as exc:
        print(f"{args.certificate}: cannot read the certificate: {type(exc).__name__}", file=sys.stderr)
        return 2
    if args.progress:
        print(file=sys.stderr)
    if args.json:
        print(json.dumps(report.to_json(), indent=1))
    else:
        print("\n".join(report.lines()))
    return 0 if report.ok else 1


def _bar(done, total, shown=[-1]):
    k = 40 * done // max(total, 1)
    if k != shown[0]:
        shown[0] = k
        print(f"\r[{'#' * k}{'.' * (40 - k)}] {done}/{total} tree nodes", end="", file=sys.stderr, flush=True)


if __name__ == "__main__":
    sys.exit(main())
