"""``check``: the header of a certificate, then its claims, at a chosen precision."""
from __future__ import annotations

import json

from mpmath import iv

from . import fk, singularity, trajectory, workspace
from .models import MODELS, Robot
from .report import Rejected, Report

FORMAT = "certkin-certificate"
VERSION = 1
PROBLEMS = ("singularity", "forward-kinematics", "trajectory") + workspace.PROBLEMS


def check(cert, prec: int = 80) -> Report:
    """Re-verify a certificate (a parsed JSON document) with ``iv.prec = prec``.

    Never raises on a malformed certificate: the report names the step.
    ``iv.prec`` is restored afterwards (mpmath's iv context is global, so do
    not run two checks at once in one process).
    """
    if isinstance(prec, bool) or not isinstance(prec, int) or not 53 <= prec <= 100_000:
        raise ValueError(f"prec must be an int in [53, 100000], got {prec!r}")
    counts = {"claims": 0, "undecided": 0, "leaves": 0, "pieces": 0, "witnesses": 0}
    saved = iv.prec
    iv.prec = prec
    try:
        _check(cert, counts)
    except Rejected as exc:
        return Report(False, exc.step, counts)
    except RecursionError:
        return Report(False, "certificate: nested too deeply", counts)
    finally:
        iv.prec = saved
    return Report(True, "", counts)


def _check(cert, counts):
    if not isinstance(cert, dict):
        raise Rejected("certificate: expected a JSON object")
    if cert.get("format") != FORMAT:
        raise Rejected(f"format: expected {FORMAT!r}, got {cert.get('format')!r}")
    version = cert.get("version")
    if type(version) is not int or version != VERSION:
        raise Rejected(f"version: unknown version {version!r} (known: {VERSION})")
    problem = cert.get("problem")
    if problem not in PROBLEMS:
        raise Rejected(f"problem: unknown problem {problem!r} (known: {', '.join(PROBLEMS)})")
    robot = cert.get("robot")
    if not isinstance(robot, dict):
        raise Rejected("robot: expected an object")
    claims = cert.get("claims")
    if not isinstance(claims, list) or not claims:
        raise Rejected("claims: expected a non-empty list")
    counts["claims"] = len(claims)
    if problem in workspace.PROBLEMS:
        workspace.check_claims(cert, counts)
        return
    if problem == "forward-kinematics":
        model = cert.get("model")
        if not isinstance(model, str) or model not in fk.MODELS:
            raise Rejected(f"model: unknown model {model!r} (known: {', '.join(fk.MODELS)})")
        if cert.get("unknowns") != list(fk.MODELS[model][1]):
            raise Rejected(f"unknowns: expected {list(fk.MODELS[model][1])} for model {model}")
        fk.check_claims(model, robot, claims, counts)
        return
    model = MODELS.get(cert.get("model")) if isinstance(cert.get("model"), str) else None
    if model is None:
        raise Rejected(f"model: unknown model {cert.get('model')!r} (known: {', '.join(MODELS)})")
    if robot.get("kind") != model.kind:
        raise Rejected(f"robot.kind: {robot.get('kind')!r} does not fit model {model.name}")
    if cert.get("pose") != list(model.pose):
        raise Rejected(f"pose: expected {list(model.pose)} for model {model.name}")
    if problem == "trajectory":
        trajectory.check_claims(model, robot, claims, counts)
        return
    singularity.check_claims(Robot(model, robot), claims, counts)


def _no_constants(name):
    raise ValueError(f"invalid JSON constant {name}")


def load(path):
    """Parse a certificate file; raises ``OSError`` or ``ValueError`` (invalid JSON, NaN/Infinity)."""
    with open(path, encoding="utf-8") as fh:
        return json.load(fh, parse_constant=_no_constants)


def check_file(path, prec: int = 80) -> Report:
    """``check(load(path), prec)``; an unreadable file or invalid JSON raises ``OSError``/``ValueError``."""
    return check(load(path), prec)
