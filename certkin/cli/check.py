"""``certkin check``: re-verify a certificate with the independent checker ``proofs`` (the same
program as ``python -m proofs``): the robot and its geometry hash, the question, what was proved;
exit code 0 valid, 1 rejected, 2 unreadable."""
from __future__ import annotations

import proofs

from ..errors import InputError


def add_arguments(c):
    c.add_argument("certificate", help="certificate file (written by --certificate)")
    c.add_argument("--robot", metavar="ROBOT.toml", help="also confirm that the geometry is this robot file's, exactly")
    c.add_argument("--json", action="store_true", help="print one JSON document")
    c.add_argument("--progress", action="store_true", help="show a progress bar on stderr")


def run(args):
    for option, path in (("CERT", args.certificate), ("--robot", args.robot)):
        if path is not None and not path.strip():
            raise InputError(option, "", "empty file name")
    return proofs.run(args.certificate, args.robot, args.json, args.progress)
