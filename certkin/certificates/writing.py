"""Writing certificates, format version 2 (``docs/certificates.md``): a ZIP archive whose first member is
the JSON header (stored, readable with ``unzip -p FILE header.json``), then one member per
body array (raw little-endian bytes; deflated, or stored when it is small, a sample of it does not
compress, or the whole body is small), each listed in the header with its dtype, shape and SHA-256.

A ``Document`` holds the header and the body arrays as *producers*: functions that yield an array
chunk by chunk from the engine's own arrays.  ``Document.write`` streams them twice, once to hash
them (the header, which lists the hashes, comes first in the file) and once to compress them into a
temporary file renamed into place, so no second copy of a search tree is ever held in memory and
nothing half-written is left behind.  A small body (at most ``KEEP`` bytes) is produced once and its
archive assembled in memory, then written at once (a batch writes many small certificates).
``Document.arrays`` gives the arrays whole (in memory, for tests and for ``proofs.check(document)``).
"""
from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass
from decimal import Decimal
import errno
from fractions import Fraction
from functools import lru_cache
import hashlib
import io
import json
import os
from pathlib import Path
import secrets
import stat
import zipfile
import zlib

import numpy as np

from ..display import size_bound
from ..errors import InputError

FORMAT = "certkin-certificate"
VERSION = 2
CHUNK = 1 << 16          # rows per chunk when streaming the engine's arrays
LEVEL = 1                # deflate level: the body is mostly floats; level 1 is fast and nearly as small
SAMPLE = 1 << 12         # bytes at the start of an array compressed to decide whether to deflate it
KEEP = 1 << 22           # bytes of a body kept in memory between hashing and writing (larger ones are produced twice)
SMALL = 1 << 10          # an array of fewer bytes is stored: deflating it would save little and cost a compressor
SAMPLED = 1 << 16        # an array of more bytes is stored when its SAMPLE does not deflate; a smaller one is deflated
SMALL_BODY = 1 << 16     # a body of at most this many bytes is stored whole: deflating it would save a few KB and
                         # cost as much as the rest of writing it (a batch writes many such certificates)


@dataclass
class Array:
    """A body array: its name, dtype, shape after the first axis, and ``chunks()``, a function that
    yields its rows in order (callable more than once)."""

    name: str
    dtype: str
    tail: tuple
    chunks: object

    def _raw(self):
        dt = np.dtype(self.dtype).newbyteorder("<")
        for chunk in self.chunks():
            chunk = np.asarray(chunk)
            if chunk.size:
                yield len(chunk), np.ascontiguousarray(chunk.reshape((-1,) + tuple(self.tail)), dtype=dt).tobytes()


class Document:
    """A certificate: ``header`` (a dict without the body entries) and ``body``, a list of ``Array``."""

    def __init__(self, header: dict, body: list):
        self.header_fields, self.body = header, [a for a in body if a is not None]
        self._arrays = None

    def _entries(self):
        """The header; the chunks of a small body are kept (``self._kept``) for ``write``, which
        then does not produce them twice."""
        entries, total, self._stored, kept, size = {}, hashlib.sha256(), set(), {}, 0
        for a in self.body:
            h, rows, nbytes, sample, kept[a.name] = hashlib.sha256(), 0, 0, [], []
            for n, raw in a._raw():
                if nbytes < SAMPLE:
                    sample.append(raw[:SAMPLE - nbytes])
                h.update(raw)
                total.update(raw)
                rows += n
                nbytes += len(raw)
                size += len(raw)
                if size <= KEEP:
                    kept[a.name].append(raw)
            sample = b"".join(sample)
            if nbytes < SMALL or nbytes > SAMPLED and len(zlib.compress(sample, LEVEL)) > 0.9 * len(sample):
                self._stored.add(a.name)            # small, or large and nearly incompressible (floats): stored
            entries[a.name] = {"dtype": np.dtype(a.dtype).newbyteorder("<").str, "shape": [rows, *a.tail],
                               "sha256": h.hexdigest()}
        self._kept = kept if size <= KEEP else None
        if size <= SMALL_BODY:
            self._stored = set(entries)
        robot = self.header_fields["robot"]
        return {**self.header_fields, "geometry_sha256": _geometry_sha256(json.dumps(robot, sort_keys=True, default=str)),
                "arrays": entries, "body_sha256": total.hexdigest()}

    @property
    def header(self) -> dict:
        return self._entries()

    @property
    def arrays(self) -> dict:
        """The body arrays, whole (in memory)."""
        if self._arrays is None:
            self._arrays = {}
            for a in self.body:
                parts = [np.frombuffer(raw, dtype=np.dtype(a.dtype).newbyteorder("<")) for _, raw in a._raw()]
                flat = np.concatenate(parts) if parts else np.zeros(0, np.dtype(a.dtype))
                self._arrays[a.name] = flat.reshape((-1,) + tuple(a.tail))
        return self._arrays

    def write(self, path) -> tuple[int, str] | None:
        """Write the archive atomically (a temporary file renamed into place).  (size, SHA-256) of the
        file written when it was assembled in memory (a small body), else None."""
        header = self._entries()
        text = json.dumps(header, separators=(",", ":"), ensure_ascii=False, allow_nan=False)
        if (size := len(text.encode())) > MAX_HEADER:      # (a claim per cell: more than about 100 000 cells)
            raise InputError("certificate", str(path), f"its header would hold {size_bound(size)} "
                             f"of claims, more than the {MAX_HEADER >> 20} MiB a checker reads (proofs/container.py): "
                             "ask for fewer cells, or split the box")
        with atomic_file(path) as fh:
            if self._kept is None:                     # a large body: streamed to the file, produced again
                self._zip(fh, text)
                return None
            buffer = io.BytesIO()                      # a small one: assembled in memory, written at once
            self._zip(buffer, text)
            fh.write(buffer.getbuffer())
        return buffer.getbuffer().nbytes, hashlib.sha256(buffer.getbuffer()).hexdigest()

    def _zip(self, target, header: str) -> None:
        with zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED, allowZip64=True, compresslevel=LEVEL) as z:
            z.writestr(zipfile.ZipInfo("header.json"), header, compress_type=zipfile.ZIP_STORED)
            for a in self.body:
                info = a.name + ".bin"                 # deflated at LEVEL (the archive's default)
                if a.name in self._stored:
                    info = zipfile.ZipInfo(info)
                    info.compress_type = zipfile.ZIP_STORED
                with z.open(info, "w", force_zip64=True) as fh:
                    for raw in self._kept[a.name] if self._kept is not None else (r for _, r in a._raw()):
                        fh.write(raw)


def write_text(path, text: str) -> None:
    """Write a text file (UTF-8) atomically (a temporary file renamed into place)."""
    with atomic_file(path) as fh:
        fh.write(text.encode())


@contextmanager
def atomic_path(path):
    """A temporary file name beside ``path`` (with its suffix, so a writer that reads the type from
    the name still can), renamed onto ``path`` when the block ends without error and removed
    otherwise: nothing half-written is left.  The file is created as a file created normally is (0666
    less the umask, or the directory's default ACL); a missing directory is an error, never created;
    a name that is not a regular file is refused and a symbolic link replaced (``replaced_file``)."""
    path = replaced_file(path)
    fd, tmp = _temporary(path)
    os.close(fd)
    with _renamed(tmp, path):
        yield tmp


@contextmanager
def atomic_file(path):
    """``atomic_path``'s file, open for writing bytes (the block writes to it; it is closed, then
    renamed onto ``path``)."""
    path = replaced_file(path)
    fd, tmp = _temporary(path)
    with _renamed(tmp, path):
        with open(fd, "wb") as fh:
            yield fh


class NotRegularFile(OSError):
    """An output path that names a device, a pipe or a socket."""


def replaced_file(path) -> Path:
    """``path``, the name an atomic write renames its new file onto, once checked: refused
    (``NotRegularFile``) when it exists and is not a regular file, since renaming onto /dev/null would
    replace the device itself.  A symbolic link is replaced by the new file and its target left as it
    is (as ``sed -i`` or git do: a link planted in an output directory cannot redirect a write), unless
    it leads to something that is not a regular file: ``/dev/stdout`` is a link to the process's
    output, and replacing it would break every later ``> /dev/stdout`` on the machine."""
    if not isinstance(path, (str, os.PathLike)) or not str(path).strip():
        raise InputError("path", "", f"expected a file name, got {path!r:.60}")
    target = Path(path)
    try:
        mode = os.lstat(target).st_mode
    except FileNotFoundError:
        return target
    if stat.S_ISLNK(mode):
        try:
            mode = os.stat(target).st_mode
        except OSError:                     # a dangling link (or a loop): replaced
            return target
        if stat.S_ISREG(mode) and not _stream_link(target):
            return target
        mode = 0 if stat.S_ISREG(mode) else mode  # (a link to a process's stream: /dev/stdout > a file)
    if not stat.S_ISREG(mode):
        kind = "a directory" if stat.S_ISDIR(mode) else "a device, a pipe or a socket" if mode else \
            "a link to a stream of a process, through /dev or /proc"
        raise NotRegularFile(errno.EINVAL, f"not a regular file ({kind}): certkin writes a new file and renames "
                                           "it onto the name")
    return target


def _stream_link(path, hops: int = 40) -> bool:
    """Whether a link, or a link it leads to, lies in or points into /dev or /proc: /dev/stdout leads to
    /proc/self/fd/1, a regular file when the output is redirected to one, and is still not ours to replace."""
    path = os.path.abspath(path)
    for _ in range(hops):
        if path.startswith(("/dev/", "/proc/")) and not path.startswith("/dev/shm/"):
            return True
        if not os.path.islink(path):
            return False
        path = os.path.normpath(os.path.join(os.path.dirname(path), os.readlink(path)))
    return True


def _temporary(path):
    """(descriptor, name) of a new file ``.NAME.XXXXXXXX.tmp`` + NAME's suffix beside ``path``, created
    exclusively with the mode of a normal file (so no chmod follows: one metadata update less per file)."""
    path = Path(path)
    for _ in range(TRIES):
        tmp = os.path.join(path.parent, f".{path.name}.{secrets.token_hex(4)}.tmp{path.suffix}")
        try:
            return os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC, 0o666), tmp
        except FileExistsError:
            continue
        except FileNotFoundError:        # named after the file asked for, not the temporary one
            raise FileNotFoundError(errno.ENOENT, f"no such directory: {path.parent}", str(path)) from None
    raise FileExistsError(errno.EEXIST, f"no free temporary name beside {path}")


TRIES = 100     # random temporary names tried (as tempfile.mkstemp)
MAX_HEADER = 64 << 20   # bytes of header.json the checker reads (proofs.container.MAX_HEADER)


def temporary_of(name: str) -> str | None:
    """The name of the file whose atomic write made the temporary file ``name`` (``.NAME.XXXXXXXX.tmp``
    + NAME's suffix, beside it), or None if ``name`` is not such a file: what a process killed while
    writing leaves behind (a finished write renames its temporary file, a failed one removes it)."""
    if not name.startswith("."):
        return None
    head, sep, suffix = name.rpartition(".tmp")
    target, dot, rand = head[1:].rpartition(".")
    if not sep or not dot or len(rand) != 8 or not target.endswith(suffix):
        return None
    return target


@contextmanager
def _renamed(tmp, path):
    """Rename ``tmp`` onto ``path`` when the block ends, remove it if it fails.  An ``OSError`` that names
    no file, or the temporary one (a full disk met by a writer), is raised naming ``path``."""
    try:
        yield
        os.replace(tmp, path)
    except BaseException as exc:
        if os.path.exists(tmp):
            os.unlink(tmp)
        if isinstance(exc, OSError) and exc.filename in (None, tmp):
            raise OSError(exc.errno, exc.strerror or str(exc), str(path)) from exc
        raise


def header(robot, problem: str, model: str | None = None, **fields) -> dict:
    """The first fields of every certificate: format, version, problem, robot and model."""
    return {"format": FORMAT, "version": VERSION, "problem": problem, "robot": robot.to_dict(),
            "model": f"{robot.model_name}/1" if model is None else model, **fields}


def canonical_decimal(value) -> str:
    """The canonical text of an exact decimal: no exponent, no trailing zeros (``3.780`` → ``3.78``)."""
    text = str(value).strip()
    suffix = "deg" if text.lower().endswith("deg") else ""
    q = Fraction(text[:-3] if suffix else text)
    sign, q = ("-" if q < 0 else ""), abs(q)
    whole, rest = divmod(q.numerator, q.denominator)
    digits = ""
    while rest:
        rest *= 10
        d, rest = divmod(rest, q.denominator)
        digits += str(d)
    return sign + str(whole) + ("." + digits if digits else "") + suffix


@lru_cache(maxsize=64)
def _geometry_sha256(robot_json: str) -> str:
    """``geometry_sha256`` of a robot given as JSON (computed once per robot: a batch writes many
    certificates of one robot)."""
    return geometry_sha256(json.loads(robot_json))


def geometry_sha256(robot: dict) -> str:
    """SHA-256 of the canonical geometry text: JSON (sorted keys, no spaces) of kind, base, platform and
    limits with every decimal in its canonical form (``docs/certificates.md``)."""
    def canon(v):
        if isinstance(v, dict):
            return {str(k): canon(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [canon(x) for x in v]
        if isinstance(v, bool) or v is None:
            return v
        try:
            return canonical_decimal(v)
        except (ValueError, ArithmeticError, TypeError):
            return str(v)
    geo = {k: canon(robot[k]) for k in ("kind", "base", "platform", "limits") if k in robot}
    return hashlib.sha256(json.dumps(geo, sort_keys=True, separators=(",", ":"), ensure_ascii=False).encode()).hexdigest()


def outward_boxes(lo, hi) -> list:
    """Boxes (lo, hi: arrays (k, d)) as [[[lo', hi'], ...], ...]: each bound the next float outward, so that
    its JSON text (the shortest decimal that rounds to it) lies outside the box too: for people."""
    return np.stack([np.nextafter(lo, -np.inf), np.nextafter(hi, np.inf)], -1).tolist()


@lru_cache(maxsize=1 << 16)
def float_text(v: float) -> str:
    """The exact decimal value of a float (cells of a grid share their faces: each is converted once)."""
    return str(Decimal(v))


def box_json(lo, hi) -> list:
    """[[lo, hi], ...] of a float box (JSON floats: exact binary values)."""
    return [[float(a), float(b)] for a, b in zip(lo, hi)]


def one(array) -> object:
    """A producer of one whole array (for small arrays the writer has anyway)."""
    return lambda: [array]
