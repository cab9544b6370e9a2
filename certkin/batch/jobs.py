"""The jobs file of ``certkin batch``: one JSON object a line.

``{"id": "j1", "command": "fk", "robot": "robot.toml" or an inline robot table, <options of that
command by their long names>}``.  Numbers keep their exact decimal text (``parse_float=Decimal``),
so ``0.1`` in a job is the decimal 0.1, as on the command line.  A line that cannot be a job (not
JSON, ``NaN`` and ``Infinity`` included; no usable id, an id used twice, even in another letter
case, or a reserved one: ``summary``, ``line-N``) still becomes a job, with an ``error`` and an id
of its own (``line-N``), so the batch reports it and carries on.
"""
from __future__ import annotations

from contextvars import ContextVar
from decimal import Decimal
import json
import os
import re
import sys

from ..errors import InputError, clip

ID = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,127}")     # a file name on every system: no separator
RESERVED = re.compile(r"summary|line-[0-9]+", re.IGNORECASE)   # summary.json; the ids of unreadable lines
ERROR = "error"                                           # key of a job that is already broken
MAX_JOBS = 200_000          # jobs of one file at most: a batch holds each job and its summary row
                            # (200 000 jobs: about 0.5 GB in the batch process; split larger campaigns)
MAX_LINE = 1 << 20          # characters of a job line at most (an inline robot table is a few hundred)
MAX_DEPTH = 32              # nesting of a job's lists and tables at most (an inline robot table: 4)


BATCH_DIRECTORY: ContextVar[str | None] = ContextVar("certkin_batch_directory", default=None)


def located(path: str) -> str:
    """A path of a job (its robot file) as the batch process sees it: a relative one joined to the
    batch's working directory (``BATCH_DIRECTORY``) when a task runs in a process started elsewhere (a
    Dask worker; set per task, so the threads of one worker may serve different batches), else as given."""
    base = BATCH_DIRECTORY.get()
    return path if base is None or os.path.isabs(path) else os.path.join(base, path)


def read_jobs(path) -> list[dict]:
    """The jobs of a JSONL file, in file order (empty lines and lines starting with '#' skipped).

    Raises ``InputError`` only when the file itself cannot be read; a bad line becomes a job with
    an ``error`` (its id: ``line-N`` when it has no usable one)."""
    if os.path.exists(path) and not os.path.isfile(path) and not os.path.isdir(path):
        raise InputError(str(path), "", "not a regular file (a device or a pipe is not a jobs file)")
    jobs, seen, shared = [], set(), {}
    try:
        with open(path, "rb") as fh:          # decoded line by line: a line that is not UTF-8 is named
            for n, line in enumerate(_lines(fh), 1):
                try:
                    line = None if line is None else line.decode("utf-8-sig" if n == 1 else "utf-8")  # (a BOM is no text)
                except UnicodeDecodeError as exc:
                    if not jobs:        # the first line already: not a text file in UTF-8 (UTF-16, binary)
                        raise InputError(str(path), "", f"cannot read the jobs file (line {n} is not UTF-8 text, "
                                                        f"byte {exc.start + 1})") from None
                    jobs.append({"id": f"line-{n}", ERROR: f"{path}: line {n}: not UTF-8 text (byte {exc.start + 1})"})
                    continue
                if line is None:
                    jobs.append({"id": f"line-{n}", ERROR: f"{path}: line {n}: longer than {MAX_LINE >> 10} KiB: not a job"})
                elif line.strip() and not line.lstrip().startswith("#"):
                    jobs.append(_job(path, n, line, seen, shared))
                if len(jobs) > MAX_JOBS:
                    raise InputError(str(path), "", f"more than {MAX_JOBS} jobs: split the campaign")
    except FileNotFoundError:
        raise InputError(str(path), "", "no such file") from None
    except OSError as exc:
        why = exc.strerror or exc
        raise InputError(str(path), "", f"cannot read the jobs file ({why})") from None
    return jobs


def _lines(fh):
    """The lines of a text file, one at a time; None for a line longer than ``MAX_LINE`` (read past
    in pieces, never held whole)."""
    while True:
        line = fh.readline(MAX_LINE + 1)
        if not line:
            return
        if len(line) > MAX_LINE:
            while line and not line.endswith(b"\n"):
                line = fh.readline(MAX_LINE + 1)
            yield None
        else:
            yield line


def _job(path, n: int, line: str, seen: set, shared: dict) -> dict:
    where = f"{path}: line {n}"
    try:
        job = json.loads(line, parse_float=Decimal, object_pairs_hook=_without_repeats, parse_constant=_no_constant)
    except json.JSONDecodeError as exc:
        return {"id": f"line-{n}", ERROR: f"{where}: not valid JSON ({exc.msg})"}
    except NotJSONNumber as exc:
        return {"id": f"line-{n}", ERROR: f"{where}: not valid JSON ({exc.args[0]} is not a JSON number)"}
    except RepeatedKey as exc:
        return {"id": f"line-{n}", ERROR: f"{where}: {clip(repr(exc.args[0]))} given twice (one value per key)"}
    except RecursionError:
        return {"id": f"line-{n}", ERROR: f"{where}: not a job (JSON nested too deeply)"}
    except ValueError:                  # int() of an integer of more than sys.get_int_max_str_digits() digits
        return {"id": f"line-{n}", ERROR: f"{where}: not a job (an integer of more than "
                                          f"{sys.get_int_max_str_digits()} digits)"}
    if not isinstance(job, dict):
        return {"id": f"line-{n}", ERROR: f"{where}: expected a JSON object (a job)"}
    if _depth(job) > MAX_DEPTH:         # (it could not be handed to a worker: pickling recurses)
        return {"id": f"line-{n}", ERROR: f"{where}: not a job (JSON nested more than {MAX_DEPTH} deep)"}
    jid = job.get("id")
    if not isinstance(jid, str) or not ID.fullmatch(jid):
        return {**job, "id": f"line-{n}",
                ERROR: f"{where}: id: expected a name of letters, digits, '.', '_' or '-' (at most 128), "
                       f"got {shown(jid)}"}
    if RESERVED.fullmatch(jid):
        return {**job, "id": f"line-{n}", ERROR: f"{where}: id: {jid!r} is reserved (summary.json is the batch's "
                                                 "summary, line-N the id of a line that is not a job)"}
    if jid.casefold() in seen:           # a.json and A.json are one file on some systems
        return {**job, "id": f"line-{n}", ERROR: f"{where}: id: {jid!r} is used by an earlier job (letter case "
                                                 "aside)"}
    seen.add(jid.casefold())
    for key in ("command", "robot"):         # the same text in many jobs: held once
        if isinstance(job.get(key), str):
            job[key] = shared.setdefault(job[key], job[key])
    return job


class NotJSONNumber(ValueError):
    """``NaN``, ``Infinity`` or ``-Infinity`` in a job line: Python's ``json`` reads them, JSON has no such
    number (a job echoed with one in ``DIR/<id>.json`` would not be JSON either)."""


def _no_constant(name: str):
    raise NotJSONNumber(name)


class RepeatedKey(ValueError):
    """A key given twice in one JSON object (``json`` would keep the last value silently)."""


def _without_repeats(pairs) -> dict:
    out = {}
    for key, value in pairs:
        if key in out:
            raise RepeatedKey(key)
        out[key] = value
    return out


def _depth(value) -> int:
    """How deep lists and tables nest in a parsed JSON value (without recursion)."""
    deepest, todo = 0, [(value, 1)]
    while todo:
        v, d = todo.pop()
        if isinstance(v, (dict, list)):
            deepest = max(deepest, d)
            todo.extend((w, d + 1) for w in (v.values() if isinstance(v, dict) else v))
    return deepest


def shown(value, limit: int = 60) -> str:
    """A value of a job as JSON writes it (``null``, ``true``, ``["fk"]``), cut to ``limit`` characters (its
    start and end: ``errors.clip``)."""
    try:
        text = json.dumps(value, default=_exact)
    except (TypeError, ValueError):
        text = repr(value)
    return clip(text, limit)


def dumps(job: dict) -> str:
    """A job as one JSON line; exact decimals (``Decimal``) are written as strings of their exact text,
    which every option reads the same way."""
    return json.dumps(job, default=_exact, separators=(", ", ": "), allow_nan=False)


def canonical(job: dict) -> str:
    """A job in one canonical text (sorted keys, no ``error``): two jobs asking the same thing compare equal."""
    return json.dumps({k: v for k, v in job.items() if k != ERROR}, default=_exact, sort_keys=True)


def _exact(value):
    if isinstance(value, Decimal):
        return str(value)
    raise TypeError(f"not JSON: {value!r}")
