"""Reading a certificate file: a ZIP archive (version 2, docs/certificates.md "Version 2: the container"); a JSON
document is read only to refuse it (version 1, no longer checked).

A body array is read only when a step needs it and then checked against its header entry (dtype, shape, SHA-256): a
flipped bit, a truncated member or an edited hash is rejected with the array named.  ``Unreadable`` (exit code 2) is
raised only when the file is not a certificate at all, ``Rejected`` (exit code 1) otherwise."""
from __future__ import annotations

import hashlib
import json
import os
import zipfile
import zlib

import numpy as np

from .report import Rejected, Unreadable

MAX_HEADER = 64 << 20            # bytes of header.json
MAX_JSON = 16 << 20              # bytes of a JSON document read to say which version it is (not more:
                                 # parsed, it takes several times that memory)
MAX_ARRAY = 2 << 30              # bytes of one array
DTYPES = ("<f8", "<f4", "<i4", "<i8", "<u8", "|i1", "|u1")


class Certificate:
    """A parsed header (``dict``) and its body arrays, read on demand (``array``)."""

    def __init__(self, header, arrays=None, archive=None):
        self.header, self._arrays, self._archive, self._read = header, dict(arrays or {}), archive, {}

    @property
    def size(self) -> int:          # bytes of the file, or of the arrays given in memory: what trees are weighed against
        return os.path.getsize(self._archive.filename) if self._archive else sum(getattr(a, "nbytes", 0) for a in self._arrays.values())

    def array(self, name: str, dtypes=None, shape_tail=None) -> np.ndarray:
        """The body array ``name`` (checked against its header entry), as stored."""
        if name not in self._read:
            self._read[name] = self._arrays[name] if name in self._arrays else self._load(name)
        a = self._read[name]
        if dtypes is not None and not any(a.dtype == np.dtype(t) for t in dtypes):
            raise Rejected(f"body: array {name}: dtype {a.dtype.str}, expected one of {', '.join(dtypes)}")
        if shape_tail is not None and tuple(a.shape[1:]) != tuple(shape_tail):
            raise Rejected(f"body: array {name}: shape {list(a.shape)}, expected [*, {', '.join(map(str, shape_tail))}]")
        return a

    def forget(self, prefixes) -> None:
        """Drop the arrays read whose names start with ``prefixes`` (one segment at a time in memory)."""
        self._read = {k: v for k, v in self._read.items() if not k.startswith(prefixes)}

    def has(self, name: str) -> bool:
        return name in self._arrays or name in self._entries()

    def _entries(self) -> dict:
        e = self.header.get("arrays", {}) if self._archive is not None else {}
        return e if isinstance(e, dict) else {}

    def _load(self, name, body=None):
        """The array ``name`` checked against its entry; with ``body`` (a hash), only streamed into it."""
        entry = self._entries().get(name)
        if not isinstance(entry, dict):
            raise Rejected(f"body: array {name} is missing (not listed in the header)")
        dtype, shape, digest = entry.get("dtype"), entry.get("shape"), entry.get("sha256")
        if dtype not in DTYPES or not isinstance(shape, list) or not all(
                type(s) is int and 0 <= s < 2 ** 40 for s in shape) or not isinstance(digest, str):
            raise Rejected(f"body: array {name}: bad entry (dtype one of {', '.join(DTYPES)}, shape, sha256)")
        size = int(np.prod(shape, dtype=object)) * np.dtype(dtype).itemsize
        if size > MAX_ARRAY:
            raise Rejected(f"body: array {name}: {size} bytes is too large")
        mine = hashlib.sha256()
        data = _member(self._archive, name + ".bin", size, body and (lambda piece: (mine.update(piece), body.update(piece))))
        mine.update(data)
        if mine.hexdigest() != digest:
            raise Rejected(f"body: array {name}: SHA-256 differs from the header's")
        return None if body else np.frombuffer(data, dtype=dtype).reshape(shape)

    def verify_body(self) -> None:
        """Every listed array matches its hash, ``body_sha256`` matches, and no member is unlisted."""
        if self._archive is None:
            return
        entries = self.header.get("arrays")
        if not isinstance(entries, dict):
            raise Rejected("header.arrays: expected an object {name: {dtype, shape, sha256}}")
        names = [i.filename for i in self._archive.infolist()[1:]]
        extra = sorted(set(names) - {n + ".bin" for n in entries})
        if extra or len(names) != len(set(names)):
            raise Rejected(f"body: unexpected or repeated member {(extra or names)[0]!r}")
        body = hashlib.sha256()
        for name in entries:                      # streamed, not kept: arrays are read when a step needs them
            self._load(name, body)
        if body.hexdigest() != self.header.get("body_sha256"):
            raise Rejected("header.body_sha256: differs from the SHA-256 of the body")


def _member(archive, member, size, each=None) -> bytes:
    """The bytes of ``member`` (``size`` of them), or b"" after handing them to ``each`` piece by piece."""
    data, n = b"", 0
    try:
        if archive.getinfo(member).compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
            raise Rejected(f"body: member {member} is neither stored nor deflated")
        with archive.open(member) as fh:
            while each and n <= size and (piece := fh.read(min(1 << 24, size + 1 - n))):
                each(piece)
                n += len(piece)
            data = b"" if each else fh.read(size + 1)
    except KeyError:
        raise Rejected(f"body: member {member} is missing") from None
    except (zipfile.BadZipFile, zlib.error, OSError, EOFError, ValueError) as exc:
        raise Rejected(f"body: member {member} cannot be read ({exc})") from None
    if max(n, len(data)) != size:
        raise Rejected(f"body: member {member} has {max(n, len(data))} bytes, its header entry says {size}")
    return data


def _json(text, where):
    try:
        value = json.loads(text, parse_constant=_no_constant, object_pairs_hook=_object)
    except RecursionError:
        raise Unreadable(f"{where}: JSON nested too deeply") from None
    except (ValueError, UnicodeDecodeError) as exc:
        raise Unreadable(f"{where}: not valid JSON ({str(exc)[:120]})") from None
    if not isinstance(value, dict):
        raise Unreadable(f"{where}: expected a JSON object")
    return value


def _no_constant(name):
    raise ValueError(f"invalid JSON constant {name}")


def _object(pairs):        # a JSON object's keys all differ (which of two values a reader keeps is not agreed)
    if len(set(keys := [k for k, _ in pairs])) < len(keys):
        raise ValueError(f"the key {next(k for k in keys if keys.count(k) > 1)!r} is repeated in one object")
    return dict(pairs)


def open_regular(path):
    """``open(path, "rb")``; an ``OSError`` for a device, a pipe or a socket (a FIFO would block)."""
    if os.path.exists(path) and not (os.path.isfile(path) or os.path.isdir(path)):
        raise OSError(0, "not a regular file (a device, a pipe or a socket)")
    return open(path, "rb")


def read(path) -> Certificate:
    """Open a certificate file (a ZIP archive; a JSON document is read for its version); raises ``Unreadable``."""
    try:
        with open_regular(path) as fh:
            magic = fh.read(4)
            text = b"" if magic.startswith(b"PK") else magic + fh.read(MAX_JSON - 3)
            end = (fh.seek(max(fh.seek(0, 2) - 22, 0)), fh.read(22))[1]     # a ZIP's end record, if nothing follows
    except OSError as exc:
        raise Unreadable(f"cannot open: {exc.strerror or exc}") from None
    if magic.startswith(b"PK"):
        try:
            archive = zipfile.ZipFile(path)
            first = archive.infolist()[0] if archive.infolist() else None
            if first is None or first.filename != "header.json" or first.header_offset:    # (nothing before it)
                raise Unreadable("the archive does not begin with header.json at the file's first byte")
            if first.file_size > MAX_HEADER:
                raise Unreadable("header.json is too large")
            with archive.open(first) as fh:
                text = fh.read(MAX_HEADER + 1)
            if end[:4] != b"PK\x05\x06" or end[20:] != b"\0\0":
                raise Unreadable("the file goes on after the archive's end record (or the archive has a comment)")
        except (zipfile.BadZipFile, zlib.error, OSError, EOFError, ValueError, RuntimeError) as exc:
            raise Unreadable(f"not a readable ZIP archive ({exc})") from None
        header = _json(text, "header.json")
        if first.compress_type != zipfile.ZIP_STORED:
            raise Unreadable("header.json must be stored uncompressed")
        return Certificate(header, archive=archive)
    if len(text) > MAX_JSON or (document := _json(text, "certificate")).get("version") != 1:
        raise Unreadable(f"not a ZIP archive (a certificate of version 2 is one; a JSON document of at most "
                         f"{MAX_JSON >> 20} MiB is read only to say that version 1 certificates are no longer checked)")
    return Certificate(document)
