"""Writing certificates: the common header, boxes as JSON, and atomic files (``docs/certificates.md``).

A certificate states the robot (exact decimals), the model equations by name, the claimed boxes
and, for each, the evidence: the search tree with the rule that decided each leaf, or two witness
poses.  One module per capability builds its claims (``singularity``, ``fk``, ``trajectory``,
``workspace``); the checker in ``proofs`` re-verifies them without using certkin.
"""
from __future__ import annotations

from contextlib import contextmanager
import json
import os
from pathlib import Path
import tempfile

FORMAT = "certkin-certificate"
VERSION = 1


def floats(a) -> list:
    return [float(v) for v in a]


def box_json(lo, hi) -> list:
    """[[lo, hi], ...] of a float box."""
    return [[float(a), float(b)] for a, b in zip(lo, hi)]


def header(robot, problem: str, model: str | None = None) -> dict:
    """The first fields of every certificate: format, version, problem, robot and model."""
    return {"format": FORMAT, "version": VERSION, "problem": problem,
            "robot": robot.to_dict(), "model": f"{robot.model_name}/1" if model is None else model}


def pose_certificate(problem: str, results, claim) -> dict:
    """A certificate about poses of the robot's model (singularity, trajectory): the header, the
    pose variables and one claim per result (``results``: one result or a list of them)."""
    if not isinstance(results, (list, tuple)):
        results = [results]
    cert = header(results[0].robot, problem)
    cert["pose"] = list(results[0].robot.pose_names)
    cert["claims"] = [claim(r) for r in results]
    return cert


def write_json(path, document) -> None:
    """Write a JSON file atomically: nothing half-written is left on failure."""
    write_text(path, json.dumps(document, separators=(",", ":")) + "\n")


def write_text(path, text: str) -> None:
    """Write a text file atomically (a temporary file renamed into place)."""
    with atomic_path(path) as tmp:
        Path(tmp).write_text(text)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextmanager
def atomic_path(path):
    """A temporary file name beside ``path`` (with its suffix, so a writer that reads the type from
    the name still can), renamed onto ``path`` when the block ends without error and removed
    otherwise: nothing half-written is left.  The file gets the permissions of a file created
    normally (0666 less the umask); a missing directory is an error, never created."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp" + path.suffix)
    os.close(fd)
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
