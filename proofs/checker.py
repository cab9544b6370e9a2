"""``check``: the common header of a certificate, the robot's geometry hash, then the claims."""
from __future__ import annotations

import hashlib
import json
import os
import sys
import tomllib
from decimal import Decimal
from pathlib import Path

import numpy as np

from . import container, fk, singularity, trajectory, workspace
from .numbers import canonical
from .report import Rejected, Report, Unreadable

FORMAT = "certkin-certificate"
PROBLEMS = {"singularity": singularity, "forward-kinematics": fk, "trajectory": trajectory,
            "workspace-section": workspace, "workspace-volume": workspace}


def check(source, robot=None, progress=None) -> Report:
    """Re-verify a certificate: a file path, a ``Certificate``, or any object with a ``header`` (dict)
    and ``arrays`` ({name: array}), such as certkin's in-memory documents.

    ``robot``: a robot file (TOML) whose geometry the certificate's must equal exactly.
    ``progress(done, total)`` is called as the trees are walked.  Never raises on a malformed
    certificate (the report names the failing step); an unreadable file raises ``Unreadable``.
    """
    report = Report(False, "", {"claims": 0, "undecided": 0, "leaves": 0, "pieces": 0, "witnesses": 0}, progress=progress)
    try:
        source = container.read(source) if isinstance(source, (str, Path)) else source
        cert = source if isinstance(source, container.Certificate) else container.Certificate(
            source.header, source.arrays) if hasattr(source, "header") and hasattr(source, "arrays") else container.Certificate(source)
        with np.errstate(all="ignore"):
            _check(cert, robot, report)
    except Unreadable:
        raise
    except Rejected as exc:
        report.step = exc.step
    except (RecursionError, MemoryError) as exc:
        report.step = f"certificate: {'nested too deeply' if isinstance(exc, RecursionError) else 'too large'}"
    except Exception as exc:        # any other failure a malformed certificate provokes: rejected, never accepted
        report.step = f"certificate: malformed ({type(exc).__name__}: {str(exc)[:120]})"
    else:
        report.ok = True
    return report


def _check(cert, robot_file, report):
    h = cert.header
    if not isinstance(h, dict):
        raise Rejected("certificate: expected a JSON object")
    if h.get("format") != FORMAT:
        raise Rejected(f"format: expected {json.dumps(FORMAT)}, got {json.dumps(h.get('format'), default=str):.60}")
    if h.get("version") == 1 and h["version"] is not True:
        raise Rejected("version: version 1 certificates (one JSON document) are no longer checked; "
                       "solve again with --certificate to write version 2")
    if type(h.get("version")) is not int or h["version"] != 2:
        raise Rejected(f"version: unknown version {json.dumps(h.get('version'), default=str):.60} (known: 2)")
    problem = h.get("problem")
    if not isinstance(problem, str) or problem not in PROBLEMS:
        raise Rejected(f"problem: unknown problem {json.dumps(problem, default=str):.60} (known: {', '.join(PROBLEMS)})")
    robot = h.get("robot")
    if not isinstance(robot, dict):
        raise Rejected("robot: expected an object")
    segments, names = h.get("segments", 1), h.get("arrays") if isinstance(h.get("arrays"), dict) else {}
    if type(segments) is not int or not 1 <= segments <= (1 << 20 if problem == "forward-kinematics" else 1):
        raise Rejected("segments: expected a positive integer (more than 1 only for forward-kinematics)")
    stray = [a for a in names if a.startswith("segment") and not ((k := a.split("/")[0][7:]).isascii() and k.isdigit()
                                                                  and len(k) < 8 and k == str(int(k)) and 0 < int(k) < segments)]
    if stray:
        raise Rejected(f"body: array {stray[0]} belongs to no segment (the header says {segments})")
    claims = h.get("claims")
    if not isinstance(claims, list) or not claims:
        raise Rejected("claims: expected a non-empty list")
    digest = geometry_sha256(robot)
    report.about = {"robot": robot.get("name"), "kind": robot.get("kind"), "geometry_sha256": digest,
                    "problem": problem, "version": h["version"]}
    if h.get("geometry_sha256") != digest:
        raise Rejected("geometry_sha256: differs from the SHA-256 of the stated geometry")
    cert.verify_body()
    if robot_file is not None:
        theirs = geometry_sha256(read_robot(robot_file))
        if theirs != digest:
            raise Rejected(f"robot: the certificate's geometry is not that of {robot_file} "
                           f"(SHA-256 {digest[:16]}… against {theirs[:16]}…)")
        report.about["robot_file"] = str(robot_file)
    report.checked["claims"] = len(claims)
    PROBLEMS[problem].check(cert, report)


def geometry_canonical(robot: dict) -> str:
    """The canonical text of a robot's geometry: JSON (sorted keys, no spaces) of kind, base,
    platform and limits, every decimal in its canonical form (``numbers.canonical``)."""
    def canon(v):
        if isinstance(v, dict):
            return {str(k): canon(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [canon(x) for x in v]
        if isinstance(v, bool) or v is None:
            return v
        try:
            return canonical(v)
        except (ValueError, ArithmeticError, TypeError, Rejected):
            return str(v)
    geo = {k: canon(robot[k]) for k in ("kind", "base", "platform", "limits") if k in robot}
    return json.dumps(geo, sort_keys=True, separators=(",", ":"), ensure_ascii=False)


def geometry_sha256(robot: dict) -> str:
    try:
        return hashlib.sha256(geometry_canonical(robot).encode()).hexdigest()
    except RecursionError:
        raise Rejected("robot: nested too deeply") from None


MAX_ROBOT = 16 << 20     # bytes of a robot file (a few hundred in practice)


class UnreadableRobot(Unreadable):      # the robot file given to confirm the geometry cannot be read
    pass


def read_robot(path) -> dict:
    """A robot file (TOML, decimals read exactly); raises ``UnreadableRobot``."""
    try:
        with container.open_regular(path) as fh:
            raw = fh.read(MAX_ROBOT + 1)          # /dev/zero or a huge file: never read whole
        data = tomllib.loads(raw.decode("utf-8"), parse_float=Decimal) if len(raw) <= MAX_ROBOT else {}
    except (OSError, tomllib.TOMLDecodeError, UnicodeDecodeError, RecursionError) as exc:
        raise UnreadableRobot(exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)) from None
    if not isinstance(data.get("kind"), str):
        raise UnreadableRobot(f"not a robot file (no kind, or larger than {MAX_ROBOT >> 20} MiB)")
    robot = {k: data[k] for k in ("name", "kind", "base", "platform", "limits") if k in data}
    if isinstance(limits := robot.get("limits"), dict):                  # the file's shorthands: one radius for every leg; comments
        limits = robot["limits"] = dict(limits)
        if "leg_radius" in limits and not isinstance(limits["leg_radius"], list):
            limits["leg_radius"] = [limits["leg_radius"]] * len(robot.get("base", []))
        for key in ("base_joints", "platform_joints"):
            if isinstance(limits.get(key), list):
                limits[key] = [{k: v for k, v in j.items() if k != "comment"} if isinstance(j, dict) else j
                               for j in limits[key]]
    return robot


def load(path) -> container.Certificate:
    """Open a certificate file; raises ``Unreadable`` (a ``ValueError``)."""
    return container.read(Path(path))


def check_file(path, robot=None, progress=None) -> Report:
    return check(load(path), robot, progress)


def run(path, robot=None, as_json=False, progress=False) -> int:
    """The command ``python -m proofs`` / ``certkin check``: print the account (or one JSON document);
    return the exit code: 0 valid, 1 rejected, 2 unreadable (one line on stderr)."""
    try:
        report = check(load(path), robot=robot, progress=_bar if progress else None)
    except (Unreadable, MemoryError, RecursionError) as exc:
        what = f"{robot}: cannot read the robot file" if isinstance(exc, UnreadableRobot) else f"{path}: cannot read the certificate"
        print(f"{what}: {exc or type(exc).__name__}", file=sys.stderr)
        return 2
    if progress:                                  # the bar completed (also for a certificate without trees)
        _bar(1, 1, f"\r[{'#' * 40}] checked" + " " * 20 + "\n")
        _bar.shown = -1
    try:
        print(json.dumps(report.to_json(), indent=1) if as_json else "\n".join(report.lines()), flush=True)
    except BrokenPipeError:                       # the reader of stdout went away (`| head`): quiet, exit 141
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    return 0 if report.ok else 1


def _bar(done, total, text=None):
    """The progress bar on stderr: a courtesy, so a full or closed stderr stops it, never the check."""
    k = 40 * done // max(total, 1)
    if k != _bar.shown or text:
        _bar.shown = k
        try:
            sys.stderr.write(text or f"\r[{'#' * k}{'.' * (40 - k)}] {done}/{total} tree nodes")
            sys.stderr.flush()
        except (OSError, ValueError, AttributeError):       # (AttributeError: stderr closed at start, None)
            pass


_bar.shown = -1
