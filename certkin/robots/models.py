"""The compiled models of each robot kind, kept on disk between processes.

Compiling a kind's model (``robots.symbolic``: sympy's common subexpressions, then
``intervals.compiler``) costs about a second of CPU per process, and importing sympy half a second
more: a batch pays it in every worker, a command line in every call.  ``compiled(cls, what)``,
``parts(cls)`` and ``rigid_legs(cls)`` answer from this process's memory, else from a disk cache
entry, else from ``robots.symbolic`` (then writing the entry).

An entry (one JSON file per kind and question) holds the evaluator's generated code and the bounds
of its constant enclosures bit for bit (``float.hex``), so the evaluator rebuilt from it
(``intervals.evaluator``) is the one the compiler made.  An entry is used only when

- its key is this process's: the SHA-256 of everything the answer depends on (``FORMAT``, the sympy
  version, the source files of ``robots.symbolic``, ``robots.base``, the kind's module and
  ``intervals.compiler``, and the kind's names), in its file name and recorded inside;
- the SHA-256 recorded in it matches its content, and that content has the expected shape.

Anything else (a truncated, altered or stale file, code that does not compile) is ignored, then
rebuilt and overwritten: an entry is never used without both checks.  (The checksum detects
accidents, not forgery: whoever can write the cache directory can also write Python's own
``__pycache__``.)  Entries are written atomically (a temporary file
renamed into place), so concurrent workers never read half an entry; two writers of one key write
the same content.  Directory: ``$CERTKIN_CACHE_DIR`` (empty: no disk cache), else
``$XDG_CACHE_HOME/certkin``, else ``~/.cache/certkin``; a directory that cannot be written only
means no caching.
"""
from __future__ import annotations

from functools import lru_cache
import hashlib
import importlib
import importlib.metadata
import importlib.util
import inspect
import json
import os
from pathlib import Path
import re

import numpy as np

from intervals import Interval
from intervals.evaluator import Evaluator

from ..certificates.writing import write_text

FORMAT = "certkin-model-cache/1"
DEPENDS = ("certkin.robots.symbolic", "certkin.robots.base", "intervals.compiler")
_MEMORY: dict = {}          # (class name, question) -> answer, for this process
_CONSTANT = re.compile(r"_c[0-9]+")


def cache_dir() -> Path | None:
    """The directory of the disk cache (None: no disk cache)."""
    if "CERTKIN_CACHE_DIR" in os.environ:
        return Path(os.environ["CERTKIN_CACHE_DIR"]) if os.environ["CERTKIN_CACHE_DIR"] else None
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "certkin"


def symbolic():
    """The module of symbolic models (``robots.symbolic``), imported on first use: it imports sympy
    (about half a second), which only det(A), trajectories and workspaces need."""
    return importlib.import_module("certkin.robots.symbolic")


@lru_cache(maxsize=None)
def key(cls) -> str:
    """SHA-256 of everything a compiled model of ``cls`` depends on."""
    h = hashlib.sha256(FORMAT.encode())
    h.update(importlib.metadata.version("sympy").encode())
    for path in [importlib.util.find_spec(m).origin for m in DEPENDS] + [inspect.getfile(cls)]:
        h.update(Path(path).read_bytes())
    names = [cls.__name__, cls.kind, cls.pose_names, cls.geometry_names(), sorted(cls.angle_names), cls.dim, cls.n_legs]
    h.update(json.dumps(names).encode())
    return h.hexdigest()


def compiled(cls, what: str) -> Evaluator:
    """The compiled interval evaluator of ``what`` (det, A, legs_sq, R, points, leg_vectors)."""
    return _answer(cls, what, lambda: symbolic().compiled(cls, what), _encode, lambda v: _decode(cls, v))


def parts(cls) -> frozenset:
    """The names of the parts of the kind's symbolic model (``legs``, ``A``, ``det``, ``R``, ...)."""
    return _answer(cls, "parts", lambda: frozenset(symbolic().model(cls)), sorted, _names)


def rigid_legs(cls) -> bool:
    """Whether the model's leg vectors are l_i = C + R b_i − a_i (``robots.symbolic.rigid_legs``)."""
    return _answer(cls, "rigid_legs", lambda: symbolic().rigid_legs(cls), bool, _flag)


def forget() -> None:
    """Forget this process's answers (the disk cache stays): the next question reads the disk again."""
    _MEMORY.clear()
    key.cache_clear()


def entry_path(cls, question: str) -> Path | None:
    directory = cache_dir()
    return None if directory is None else directory / f"{cls.kind}.{question}.{key(cls)}.json"


def _answer(cls, question, build, encode, decode):
    """From memory, else a valid disk entry, else ``build()`` (its entry written)."""
    memo = (cls.__name__, question)
    if memo not in _MEMORY:
        path = entry_path(cls, question)
        value = _read(path, cls, question, decode) if path is not None else None
        if value is None:
            value = build()
            if path is not None:
                _write(path, cls, question, encode(value))
        _MEMORY[memo] = value
    return _MEMORY[memo]


def _digest(value) -> str:
    return hashlib.sha256(json.dumps(value, sort_keys=True).encode()).hexdigest()


def _read(path: Path, cls, question: str, decode):
    """The decoded answer of a valid entry, else None (missing, unreadable, stale, altered, malformed)."""
    try:
        entry = json.loads(path.read_text())
        if not (isinstance(entry, dict) and entry.get("format") == FORMAT and entry.get("key") == key(cls)
                and entry.get("question") == question and entry.get("sha256") == _digest(entry.get("value"))):
            return None
        return decode(entry["value"])
    except (OSError, ValueError, TypeError, KeyError, SyntaxError):
        return None


def _write(path: Path, cls, question: str, value) -> None:
    if value is None:
        return
    entry = {"format": FORMAT, "key": key(cls), "kind": cls.kind, "question": question, "value": value,
             "sha256": _digest(value)}
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        write_text(path, json.dumps(entry, sort_keys=True))
    except OSError:
        pass                    # no disk cache: every process compiles


def _encode(ev: Evaluator):
    """An evaluator's code and constants (each bound's exact float), or None if a constant is not scalar."""
    constants = {}
    for name, c in ev.constants.items():
        if not isinstance(c, Interval) or np.shape(c.lo) != () or np.shape(c.hi) != ():
            return None
        constants[name] = [float(c.lo).hex(), float(c.hi).hex()]
    return {"source": ev.source, "constants": constants, "variables": ev.n_variables, "parameters": ev.n_parameters}


def _decode(cls, value) -> Evaluator:
    """The evaluator of an entry; ValueError when the entry does not have the expected shape."""
    source, constants = value["source"], value["constants"]
    if not (isinstance(source, str) and source.startswith("def _f(v, p):\n") and isinstance(constants, dict)
            and value["variables"] == len(cls.pose_names) and value["parameters"] == len(cls.geometry_names())):
        raise ValueError("not a compiled model")
    enclosures = {}
    for name, (lo, hi) in constants.items():
        lo, hi = float.fromhex(lo), float.fromhex(hi)
        if not (_CONSTANT.fullmatch(name) and lo <= hi):
            raise ValueError("not a constant enclosure")
        enclosures[name] = Interval.from_bounds(np.array(lo), np.array(hi))
    return Evaluator(source, enclosures, value["variables"], value["parameters"])


def _names(value) -> frozenset:
    if not (isinstance(value, list) and all(isinstance(v, str) for v in value)):
        raise ValueError("not a list of names")
    return frozenset(value)


def _flag(value) -> bool:
    if not isinstance(value, bool):
        raise ValueError("not a boolean")
    return value
