"""The files of a batch: ``DIR/<id>.json`` (the command's ``--json`` document, with the job it
answers under ``"job"``), ``DIR/<id>.cert`` (its certificate) and ``DIR/summary.json``.

Every file is written atomically (a temporary file renamed into place), the certificate before the
document: a document on disk means its job finished.  A job is *done* when its document answers
the same job (same canonical text), is not an error, names (``"sources"``) the robot file's bytes as
they are now and the certificate beside it, that certificate re-checks with the independent
checker ``proofs``, and its claims state what the document states (``agrees``): only such jobs are
skipped when a batch is run again.
"""
from __future__ import annotations

from contextlib import contextmanager
from datetime import datetime, timezone
import fcntl
from fractions import Fraction
import hashlib
import json
import math
import os
from pathlib import Path


from .. import __version__
from ..certificates import temporary_of, write_text
from ..display import json_text
from ..errors import InputError
from ..robots.poses import decimal_text, exact_value, exceeds
from ..workspace.volume import DEFAULT_SLABS
from .jobs import canonical

SUMMARY = "summary.json"
LOCK = ".certkin-batch.lock"                 # held by the batch that writes in the directory
ERROR, FAILED = "error", "failed"            # verdicts of jobs without an answer
SLOWEST = 5
TIMING_FIELDS = {"seconds", "cpu_seconds", "paving_seconds", "job_seconds", "job_cpu_seconds", "batch_cpu_seconds",
                 "slowest", "date", "workers", "attempts", "resumed", "retried"}   # what differs between runs of the same jobs


def untimed(doc):
    """A document (or summary) without its timing fields and the batch's bookkeeping of attempts: what
    two runs of the same jobs must have in common, whatever the workers."""
    if isinstance(doc, dict):
        return {k: untimed(v) for k, v in doc.items() if k not in TIMING_FIELDS}
    if isinstance(doc, list):
        return [untimed(v) for v in doc]
    return doc


@contextmanager
def locked(out):
    """Hold ``DIR/.certkin-batch.lock`` (an advisory lock) while a batch writes in ``out``: a second batch
    on the same directory is refused (``InputError``) instead of removing the first one's temporary
    files or writing the same jobs at once.  The lock file stays (empty); the lock ends with the process.
    Where the file system cannot lock (some network file systems), the batch runs unlocked."""
    try:
        fd = os.open(Path(out) / LOCK, os.O_RDONLY | os.O_CREAT | os.O_CLOEXEC, 0o666)
    except OSError:
        fd = None
    try:
        if fd is not None:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                raise InputError("out", str(out), "another certkin batch is writing in this directory "
                                                  "(wait for it, or give another --out)") from None
            except OSError:
                pass
        yield
    finally:
        if fd is not None:
            os.close(fd)


def document_path(out, jid: str) -> Path:
    return Path(out) / f"{jid}.json"


def certificate_path(out, jid: str) -> Path:
    return Path(out) / f"{jid}.cert"


def file_facts(path, known: tuple[int, str] | None = None) -> dict:
    """Name, size and SHA-256 of a file (what a report shows of a certificate); ``known``: (size,
    SHA-256) of the bytes just written there, else the file is read."""
    if known is None:
        data = Path(path).read_bytes()
        known = len(data), hashlib.sha256(data).hexdigest()
    return {"file": Path(path).name, "bytes": known[0], "sha256": known[1]}


def remove_leftovers(out, ids) -> int:
    """Remove the temporary files of these jobs' documents and certificates (and of the summary) that a
    process killed while writing them left in ``out``; how many.  Only the batch's own files are
    touched, and only when none of its workers is writing."""
    names = {f"{i}{suffix}" for i in ids for suffix in (".json", ".cert")} | {SUMMARY}
    removed = 0
    for entry in os.scandir(out):
        if temporary_of(entry.name) in names and entry.is_file(follow_symlinks=False):
            try:
                os.unlink(entry.path)
                removed += 1
            except FileNotFoundError:
                pass
    return removed


def write_json(path, document: dict) -> None:
    """A JSON document, written atomically, strict JSON (``display.json_text``: never a bare NaN)."""
    write_text(path, json_text(document))


def write_document(out, job: dict, document: dict, sources: dict | None = None) -> None:
    """``DIR/<id>.json``: the document with the job it answers (and ``provenance``'s ``sources``)."""
    head = {"job": json.loads(canonical(job))}
    if sources is not None:
        head["sources"] = sources
    write_json(document_path(out, job["id"]), {**head, **document})


def answer_sha256(document: dict) -> str:
    """The SHA-256 of a job's answer: its document without the job, its ``sources`` and its timing fields,
    as canonical JSON.  The batch writes it in the certificate's header (``document_sha256``), and ``done``
    takes a document as the job's answer only while it is still that: margins, areas, postures and every
    other field, not only those a claim holds."""
    body = untimed({k: v for k, v in document.items() if k not in ("job", "sources")})
    return hashlib.sha256(json.dumps(body, sort_keys=True).encode()).hexdigest()


def provenance(robot_sha256: str | None, certificate: dict | None) -> dict:
    """What a document's answer was computed from and written with (its ``"sources"``): the SHA-256 of
    the robot file (None for an inline robot, which the job holds) and of the certificate written
    beside it: a later run skips the job only if both are still those (``done``)."""
    return {"robot_sha256": robot_sha256, "certificate_sha256": certificate["sha256"] if certificate else None}


def write_error(out, job: dict, verdict: str, message: str, seconds: float = 0.0, attempts: int = 1) -> dict:
    """The result of a job without an answer (``error``: bad input; ``failed``: its worker died):
    its document, a stale certificate removed, and its summary row."""
    try:
        certificate_path(out, job["id"]).unlink(missing_ok=True)
    except OSError:                     # (a directory, say, in its place: left there; the error says why)
        pass
    write_document(out, job, {"status": verdict, "error": message})
    return row(job, verdict, seconds, attempts, error=message)


def row(job: dict, verdict: str, seconds: float, attempts: int = 1, certificate: dict | None = None,
        error: str | None = None, resumed: bool = False, cpu_seconds: float = 0.0) -> dict:
    """One job's line of ``summary.json`` (``seconds``: wall clock, ``cpu_seconds``: CPU of its worker)."""
    command = job.get("command")
    out = {"id": job["id"], "command": command if isinstance(command, str) else None, "verdict": verdict,
           "seconds": round(seconds, 6), "cpu_seconds": round(cpu_seconds, 6), "attempts": attempts, "document": f"{job['id']}.json",
           "certificate": certificate}
    if error is not None:
        out["error"] = error
    if resumed:
        out["resumed"] = True
    return out


def done(out, job: dict, verdict, robot_sha256, robot=None, instances=None) -> dict | None:
    """The summary row of a job already answered in ``out``, else None: its document answers this very
    job, from the robot file as it is now (``robot_sha256()``: its SHA-256, as ``provenance``), with
    the certificate that is beside it now (the same SHA-256: not another job's), that certificate
    re-checks, is about the job's robot (``robot()``: its ``to_dict()``; the same geometry SHA-256), holds
    the document's ``answer_sha256`` (no field edited since) and ``agrees`` with the document and the job (``instances()``: a path's constraint instances for the
    job's ``constraints``, which every claim of a path must list).  ``verdict(command,
    document)`` names the answer.  The row's times are 0: the job was not run again (the caller times
    this check), and the times of the run that answered it are in its document."""
    path, cert = document_path(out, job["id"]), certificate_path(out, job["id"])
    try:
        document = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(document, dict) or document.get("status") in (ERROR, FAILED) or \
            json.dumps(document.get("job"), sort_keys=True) != canonical(job) or not cert.exists():
        return None
    sources = document.get("sources")
    try:
        facts = file_facts(cert)
    except OSError:
        return None
    if not isinstance(sources, dict) or sources.get("certificate_sha256") != facts["sha256"] or \
            sources.get("robot_sha256") != robot_sha256():
        return None
    import proofs           # the checker, imported by the runs that resume only
    try:
        certificate = proofs.load(cert)
        if certificate.header.get("document_sha256") != answer_sha256(document) or \
                not proofs.check(certificate).ok or not agrees(document, certificate.header, job, instances) or \
                robot is not None and certificate.header.get("geometry_sha256") != proofs.geometry_sha256(robot()):
            return None
        document.pop("job")
        return row(job, verdict(job.get("command"), document), 0.0, 0, facts, resumed=True)
    except (OSError, ValueError, LookupError, TypeError, AttributeError, InputError):   # (edited out of shape: run again)
        return None


def agrees(document: dict, header: dict, job: dict | None = None, instances=None) -> bool:
    """Whether a document states what its certificate's claims (re-checked) prove, about the question they
    answer: an FK document its lengths and ``complete``; a singularity document its status and box (one
    claim) or its counts (cells); a trajectory document its status and path; a plan its waypoints and
    segments; a workspace document its orientation, height(s), areas or volume and a status they imply;
    and the certificate answers the question of ``job`` (its lengths over every posture, box, cells,
    ``around`` pose, poses, start and goal, orientation, ``z``, ``z_range`` or ``slabs``, compared
    exactly; ``instances()``: the constraint instances its ``constraints`` select).  A job with another
    option, or written in a form not compared (``_bound_options``, the ``None`` of the readers), is not
    taken as done: it runs again.
    A document edited after the fact, or a certificate of another job put beside it (its hash edited in),
    is then not taken as done."""
    claims = header.get("claims")
    if not isinstance(claims, list) or not claims or not all(isinstance(c, dict) for c in claims):
        return False
    one = claims[0] if len(claims) == 1 else None
    same = lambda key: key not in document or one is None or key not in one or document[key] == one[key]  # noqa: E731
    problem = header.get("problem")
    if job is not None and not (_same_kind(job, problem, header, document) and _bound_options(job)):
        return False
    if problem == "trajectory" and instances is not None and any(c.get("instances") != instances() for c in claims):
        return False                             # (another selection of constraints)
    if problem == "forward-kinematics":
        asked = _lengths_asked(job)
        if job is not None and (asked is None or one is None or one.get("covers") != "all-postures"):
            return False                         # (lengths as v+-t, another form, a domain or a track: run again)
        if one is not None and isinstance(document.get("solutions"), list) and \
                sum(s.get("status") == "unique" for s in document["solutions"] if isinstance(s, dict)) != \
                len(one.get("solutions", [])):
            return False
        proved = [(Fraction(t), Fraction(t)) for t in one["lengths"]] if one and "lengths" in one else \
            [(Fraction(a), Fraction(b)) for a, b in one["length_ranges"]] if one and "length_ranges" in one else None
        return one is not None and same("lengths") and same("length_ranges") and \
            (document.get("tracked") or same("complete")) and (asked is None or asked == proved)
    if problem == "singularity" and one is not None and "counts" not in document:
        box, asked = document.get("box"), _box_asked(job)
        if job is not None and asked is None and not job.get("around"):
            return False                         # (a box in another form: not compared, run again)
        return same("status") and (not isinstance(box, dict) or [list(v) for v in box.values()] == one.get("box")) and \
            (asked is None or not isinstance(one.get("requested"), dict) or
             asked == {k: [exact_value(t) for t in v] for k, v in one["requested"].items()}) and \
            _around_inside(job, one.get("box"))
    if problem == "singularity":
        counts, tally = document.get("counts"), {}
        for c in claims:
            tally[c.get("status")] = tally.get(c.get("status"), 0) + 1
        results = document.get("results")
        return isinstance(counts, dict) and all(counts.get(k, 0) == n for k, n in tally.items()) and \
            sum(counts.values()) == len(claims) and _cells_cover(job, claims) and isinstance(results, list) and \
            [r.get("status") for r in results] == [c.get("status") for c in claims] and \
            [[list(v) for v in r.get("box", {}).values()] for r in results] == [c.get("box") for c in claims]
    if document.get("problem") == "plan" and "route" not in header:
        return False                              # (a plan without a path: its answer is not a claim; run again)
    if problem == "trajectory" and "route" not in header:
        path, asked = document.get("path"), _path_asked(job)
        if job is not None and asked is None:
            return False                         # (poses by name, or another form: not compared, run again)
        return one is not None and same("status") and \
            (not isinstance(path, list) or [list(p.values()) if isinstance(p, dict) else p for p in path] == one.get("path")) and \
            (asked is None or asked == [[exact_value(t) for t in pose] for pose in one.get("path", [])])
    if problem == "trajectory":                  # a plan found: its route, its segments, the job's start and goal
        route, asked, waypoints = header["route"], _path_asked(job), document.get("waypoints")
        if job is not None and asked is None:
            return False
        chain = [c["path"][0] for c in claims] + [claims[-1]["path"][-1]]
        return document.get("status") == "found" and [list(w.values()) for w in waypoints] == chain and \
            [s.get("status") for s in document.get("segments")] == [c.get("status") for c in claims] and \
            chain[0] == route.get("from") and chain[-1] == route.get("to") and \
            (job is None or asked == [[exact_value(t) for t in route[k]] for k in ("from", "to")])
    if problem in ("workspace-section", "workspace-volume"):
        return _workspace_agrees(document, header, claims, job)
    return False


def summarise(rows: list, wall_seconds: float, interrupted: bool, workers: str, cpu_seconds: float | None = None) -> dict:
    """``summary.json``: counts by command and verdict, the undecided, failed and broken jobs, the
    times, and every job's row (in the order of the jobs file).  ``cpu_seconds``: the CPU of the whole
    batch (this process and its local workers; None on a Dask cluster or after an interrupt)."""
    counts: dict = {}
    for r in rows:
        key = f"{r['command'] or '?'} {r['verdict']}"
        counts[key] = counts.get(key, 0) + 1
    finished = [r for r in rows if r["verdict"] not in (ERROR, FAILED)]
    return {"format": "certkin-batch", "version": 1, "certkin": __version__,
            "date": datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC"), "workers": workers,
            "jobs": len(rows), "interrupted": interrupted, "counts": dict(sorted(counts.items())),
            "undecided": [r["id"] for r in finished if r["verdict"] in UNDECIDED],
            "errors": [{"id": r["id"], "error": r["error"]} for r in rows if r["verdict"] == ERROR],
            "failed": [{"id": r["id"], "error": r["error"]} for r in rows if r["verdict"] == FAILED],
            "retried": [r["id"] for r in rows if r["attempts"] > 1],
            "resumed": sum(bool(r.get("resumed")) for r in rows),
            "seconds": round(wall_seconds, 3), "job_seconds": round(sum(r["seconds"] for r in rows), 3),
            "job_cpu_seconds": round(sum(r["cpu_seconds"] for r in rows), 3),
            "batch_cpu_seconds": None if cpu_seconds is None else round(cpu_seconds, 3),
            "slowest": [{"id": r["id"], "seconds": r["seconds"]}
                        for r in sorted(rows, key=lambda r: -r["seconds"])[:SLOWEST] if r["seconds"] > 0],
            "results": rows}


def _lengths_asked(job) -> list | None:
    """A job's leg lengths as exact (lo, hi) pairs, or None when they are not plain decimals or ``lo:hi``
    ranges (``v+-t``: not compared)."""
    value = (job or {}).get("lengths")
    texts = value.split(",") if isinstance(value, str) else value if isinstance(value, list) else None
    try:
        parts = [[Fraction(p.strip()) for p in str(t).split(":")] for t in texts]
    except (TypeError, ValueError, ZeroDivisionError):
        return None
    return [(p[0], p[-1]) for p in parts] if all(len(p) in (1, 2) for p in parts) else None


def _path_asked(job) -> list | None:
    """A trajectory job's poses (from, via..., to) as exact values, or None when one is not a plain list of
    decimals (``x=...`` names, a named pose: not compared)."""
    try:
        via = job.get("via") or []
        poses = [job["from"], *(via if isinstance(via, list) else [via]), job["to"]]
        return [[exact_value(t) for t in (p.split(",") if isinstance(p, str) else p)] for p in poses]
    except (KeyError, TypeError, ValueError, ZeroDivisionError, AttributeError):
        return None


def _box_texts(job) -> dict | None:
    """A singularity job's ``box`` ("x=a:b,y=c,...") as [lo, hi] texts per variable, or None (not compared:
    cells, ``around``, another form)."""
    box = (job or {}).get("box")
    if not isinstance(box, str) or job.get("cells") or job.get("around"):
        return None
    try:
        parts = [p.split("=") for p in box.split(",")]
        texts = {k.strip(): [t.strip() for t in (v.split(":") if ":" in v else [v, v])] for k, v in parts}
        [exact_value(t) for pair in texts.values() for t in pair]
        return texts
    except (TypeError, ValueError, ZeroDivisionError):
        return None


def _box_asked(job) -> dict | None:
    """``_box_texts`` as exact values."""
    texts = _box_texts(job)
    return None if texts is None else {k: [exact_value(t) for t in v] for k, v in texts.items()}


BOUND = {"fk": {"lengths"}, "singular": {"box", "cells", "around"}, "trajectory": {"from", "to", "via", "constraints"},
         "plan": {"from", "to", "divisions", "margin", "max_edges", "constraints"},
         "workspace": {"orientation", "z", "z_range", "slabs"}}
FREE = {"id", "command", "robot", "max_boxes", "max_seconds", "min_width", "max_memory"}   # (budgets: answers as true)


def _bound_options(job) -> bool:
    """Whether every option of the job is one ``agrees`` compares with the certificate (``BOUND``), or a
    budget: a job with any other (``domain``, ``track``, ``angles``, ``scale``) runs
    again, since its certificate is not compared with it; so does a cell or slab count that is not a
    plain integer (which the command refuses)."""
    command = job.get("command")
    if not {k for k, v in job.items() if v is not None and v is not False} <= FREE | BOUND.get(command, set()):
        return False                             # (null and false leave an option out: its default)
    return all(_integer(job[k]) for k in ("cells", "slabs") if job.get(k) is not None)


def _integer(value) -> bool:
    return (isinstance(value, int) and not isinstance(value, bool)) or (isinstance(value, str) and value.strip().isdigit())


def _same_kind(job, problem, header, document) -> bool:
    """The certificate and document answer the kind of question the job asks: its command's problem, a
    volume for a ``z_range``, cells for ``cells``, a plan's route for ``plan``."""
    command = job.get("command")
    cells = command == "singular" and bool(job.get("cells"))
    return {"fk": problem == "forward-kinematics",
            "singular": problem == "singularity" and cells == ("counts" in document),
            "trajectory": problem == "trajectory" and "route" not in header,
            "plan": problem == "trajectory" and "route" in header,
            "workspace": problem == ("workspace-volume" if job.get("z_range") is not None else "workspace-section"),
            }.get(command, False)


def _around_inside(job, box) -> bool:
    """A largest-free-box job (``around``): the proved box is centred on its pose (each side's ends
    within a few float steps of the same distance from it; compared exactly that the pose is inside);
    other jobs pass, and a pose that is not plain decimals (a named pose) fails: it runs again."""
    around = (job or {}).get("around")
    texts = around.split(",") if isinstance(around, str) else around if isinstance(around, list) else None
    if around is None:
        return True
    try:
        [exact_value(t) for t in texts]
    except (TypeError, ValueError, ZeroDivisionError):
        return False                    # (a named pose, or another form: not compared, run again)
    if not isinstance(box, list) or len(box) != len(texts):
        return False
    for t, (lo, hi) in zip(texts, box):
        centre = _radians(t)
        if exceeds(_exact(lo), str(t)) or exceeds(str(t), _exact(hi)) or \
                abs((hi - centre) - (centre - lo)) > 8 * math.ulp(max(abs(lo), abs(hi), abs(centre))) + 1e-300:
            return False
    return True


def _exact(value) -> str:
    """The exact decimal of a float (every digit)."""
    return decimal_text(float(value))


def _radians(text) -> float:
    """A decimal text (``deg`` allowed) as a float of its value in radians (to within rounding)."""
    q, deg = exact_value(text)
    return float(q) * (math.pi / 180 if deg else 1)


def _cells_cover(job, claims) -> bool:
    """A cells job: its claims' requested boxes span the job's box enclosed in floats (each bound the
    exact one, or one float step outside it; a few for degrees), with ``cells`` per side of every variable of
    nonzero width: no other job's cells are taken for this one's.  (A cell's bound is a float's exact
    decimal, or the job's own text when there is one cell.)"""
    texts = _box_texts({**(job or {}), "cells": None})
    if texts is None:
        return False
    try:
        cells = int((job or {}).get("cells"))
        lo = {k: min((c["requested"][k][0] for c in claims), key=_radians) for k in texts}
        hi = {k: max((c["requested"][k][1] for c in claims), key=_radians) for k in texts}
    except (TypeError, ValueError, KeyError, AttributeError, OverflowError, ZeroDivisionError):
        return False
    steps = lambda u: 16 if exact_value(u)[1] else 1          # noqa: E731  (deg: a product enclosed; else one float)
    near = lambda t, u: abs(_radians(t) - _radians(u)) <= steps(u) * math.ulp(_radians(u)) + 1e-300   # noqa: E731
    wide = sum(exact_value(a) != exact_value(b) for a, b in texts.values())
    return len(claims) == cells ** wide and len(lo) == len(claims[0]["requested"]) and all(
        not exceeds(lo[k], a) and not exceeds(b, hi[k]) and near(lo[k], a) and near(hi[k], b)
        for k, (a, b) in texts.items())


def _workspace_agrees(document, header, claims, job) -> bool:
    """A workspace document states its certificate's orientation, heights and areas (or volume), its
    status follows from them (``non-empty``: an inner area; ``empty``: no outer one), and they answer
    the job's orientation and ``z`` or ``z_range`` (and ``slabs``), compared exactly."""
    section = header.get("problem") == "workspace-section"
    orientation = header.get("orientation")
    if document.get("orientation") != orientation or not isinstance(orientation, dict):
        return False
    if section:
        (one,) = claims
        areas = [one["area"]]
        if document.get("area", {}).get("inner") != one["area"]["inner"] or \
                document.get("area", {}).get("outer") != one["area"]["outer"] or document.get("z") != one.get("z"):
            return False
    else:
        areas = [c["area"] for c in claims]
        if document.get("volume", {}).get("inner") != header["volume"]["inner"] or \
                document.get("volume", {}).get("outer") != header["volume"]["outer"] or \
                [[a.get("inner"), a.get("outer")] for a in document.get("sections", [])] != \
                [[a["inner"], a["outer"]] for a in areas]:
            return False
    status = document.get("status")
    if status == "non-empty" and not any(a["inner"] > 0 for a in areas) or \
            status == "empty" and any(a["outer"] > 0 for a in areas):
        return False
    job = job or {}
    asked = job.get("orientation", ",".join(["0"] * len(orientation)))
    texts = asked.split(",") if isinstance(asked, str) else asked if isinstance(asked, list) else [asked]
    try:
        if [exact_value(t) for t in texts] != [exact_value(t) for t in orientation.values()]:
            return False
        if section:
            return ("z" in job) == ("z" in claims[0]) and ("z" not in job or exact_value(job["z"]) == exact_value(claims[0]["z"]))
        z = job.get("z_range")
        lo, hi = (z.split(":") if isinstance(z, str) else z) if z is not None else (None, None)
        return (z is None or [exact_value(lo), exact_value(hi)] == [exact_value(t) for t in header["requested"]["z"]]) \
            and int(job.get("slabs") or DEFAULT_SLABS) == len(claims)
    except (TypeError, ValueError, ZeroDivisionError):
        return False         # (a job in another form: run again)


UNDECIDED = ("undecided", "incomplete")      # verdicts of answers a budget cut short


def write_summary(out, summary: dict) -> None:
    write_json(Path(out) / SUMMARY, summary)
