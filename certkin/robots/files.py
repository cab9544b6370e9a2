"""Robot files: reading, validating and building a robot model.

``load_robot(path)`` reads a TOML robot file with exact decimals
(``tomllib.load(..., parse_float=Decimal)``), validates every field and
returns a model of the right kind.  Any problem raises ``RobotFileError``
whose message names the file and the field.
"""
from __future__ import annotations

from decimal import Decimal
from fractions import Fraction
from pathlib import Path
import itertools
import os
import select
import stat
import sys
import tomllib

import numpy as np

from ..engine import interrupt
from ..errors import InputError, RobotFileError, clip, shown
from .base import Robot
from .gough import GoughStewart
from .planar import Planar3RPR
from .poses import parse_number
from .spherical import Spherical3DOF, rotation_float

KINDS = {cls.kind: cls for cls in (Planar3RPR, Spherical3DOF, GoughStewart)}

MAX_FILE_BYTES = 16 * 2 ** 20       # a robot file is a few hundred bytes
READ_CHUNK = 1 << 16
MAX_NAME = 200                      # characters of a robot's name


WAIT_SLICE = 0.1                    # seconds between two looks at Ctrl-C while a pipe's writer is silent


def robot_file_bytes(path) -> bytes:
    """The first ``MAX_FILE_BYTES`` + 1 bytes of a file (more means refused: /dev/zero or a huge file
    is never read whole), read a chunk at a time so that a small file costs a small buffer.

    A file that is not a regular one (a pipe: ``<(cat robot.toml)``, a named pipe, a device) is opened
    without waiting for a writer: a named pipe that no program writes to is refused (``RobotFileError``:
    its open would wait forever), and while a writer is silent a Ctrl-C ends the wait at once
    (``KeyboardInterrupt``, also under ``engine.interrupt.interruptible``)."""
    try:
        regular = stat.S_ISREG(os.stat(path).st_mode)
    except (OSError, ValueError):
        regular = True                      # (open says why)
    if not regular:
        return _stream_bytes(path)
    chunks, left = [], MAX_FILE_BYTES + 1
    with open(path, "rb") as fh:
        while left > 0:
            chunk = fh.read(min(left, READ_CHUNK))
            if not chunk:
                break
            chunks.append(chunk)
            left -= len(chunk)
    return b"".join(chunks)


def _stream_bytes(path) -> bytes:
    """``robot_file_bytes`` of a pipe or a device: opened non-blocking, read as its writer writes."""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    try:
        chunks, left = [], MAX_FILE_BYTES + 1
        while left > 0:
            try:
                chunk = os.read(fd, min(left, READ_CHUNK))
            except BlockingIOError:         # a writer, silent so far
                _wait_readable(fd)
                continue
            if not chunk:
                break
            chunks.append(chunk)
            left -= len(chunk)
        if not chunks and stat.S_ISFIFO(os.fstat(fd).st_mode):
            raise RobotFileError(str(path), "", "a named pipe with no writer (nothing to read): start the program "
                                                "that writes the robot into it first, or give a file")
        return b"".join(chunks)
    finally:
        os.close(fd)


def _wait_readable(fd) -> None:
    """Until ``fd`` has data or its writer closed; a Ctrl-C (even one ``interrupt`` only notes) ends it."""
    poller = select.poll()
    poller.register(fd, select.POLLIN | select.POLLHUP)
    while not poller.poll(WAIT_SLICE * 1000):
        if interrupt.requested():
            raise KeyboardInterrupt


def load_robot(path) -> Robot:
    """Load and validate a robot file (see the format in ``docs/index.md``)."""
    if not isinstance(path, (str, os.PathLike)):
        raise RobotFileError("robot file", "", f"expected a file's path, got {type(path).__name__}")
    if not str(path).strip():
        raise RobotFileError("robot file", "", "empty file name")
    path = Path(path)
    source = str(path)
    try:
        raw = robot_file_bytes(path)
        if len(raw) > MAX_FILE_BYTES:
            raise RobotFileError(source, "", f"larger than {MAX_FILE_BYTES // 2 ** 20} MiB: not a robot file")
        data = tomllib.loads(raw.decode("utf-8-sig"), parse_float=Decimal)   # (a BOM: a Windows editor)
    except RobotFileError:
        raise
    except FileNotFoundError:
        raise RobotFileError(source, "", "no such file") from None
    except IsADirectoryError:
        raise RobotFileError(source, "", "is a directory, not a robot file") from None
    except tomllib.TOMLDecodeError as exc:
        raise RobotFileError(source, "", f"not valid TOML ({exc})") from None
    except RecursionError:              # tomllib recurses once per level of nested arrays or tables
        raise RobotFileError(source, "", "not a robot file (arrays or tables nested too deeply)") from None
    except UnicodeDecodeError:
        raise RobotFileError(source, "", "not a text file") from None
    except ValueError:                  # int() of an integer of more than sys.get_int_max_str_digits() digits
        raise RobotFileError(source, "", f"not a robot file (an integer of more than {sys.get_int_max_str_digits()} "
                                         "digits)") from None
    except OSError as exc:
        raise RobotFileError(source, "", f"cannot read ({exc.strerror or exc})") from None
    return robot_from_dict(data, source)


def as_robot(robot, parameter: str = "robot") -> Robot:
    """A robot given as a model, a path to a robot file (``str`` or ``Path``), or a robot file's
    content (a mapping): what every API function accepts as its ``robot``."""
    if isinstance(robot, Robot):
        return robot
    if isinstance(robot, (str, Path)):
        return load_robot(robot)
    if isinstance(robot, dict):
        return robot_from_dict(robot)
    raise InputError(parameter, "", f"expected a robot, a robot file's path or its content, got {type(robot).__name__}")


def robot_from_dict(data: dict, source: str = "<robot>") -> Robot:
    """Build a robot from the content of a robot file (exact values as Decimal, int or str)."""
    if not isinstance(data, dict):
        raise RobotFileError(source, "", "expected a table of fields")
    kind = data.get("kind")
    if kind is None:
        raise RobotFileError(source, "kind", f"missing field (one of {', '.join(KINDS)})")
    if not isinstance(kind, str) or kind not in KINDS:
        raise RobotFileError(source, "kind", f"unknown kind {shown(kind)} (one of {', '.join(KINDS)})")
    cls = KINDS[kind]
    name = data.get("name", Path(source).stem)
    if not isinstance(name, str):
        raise RobotFileError(source, "name", "expected a string")
    if not name.strip():                                  # every answer starts with it
        raise RobotFileError(source, "name", "empty (leave it out to use the file's name)")
    if not name.isprintable() or len(name) > MAX_NAME:     # printed in every answer and certificate check
        raise RobotFileError(source, "name", f"expected one line of at most {MAX_NAME} printable characters (no "
                                             f"newline, terminal escape or bidi control), got {shown(name)}")
    base = parse_points(data, "base", cls.n_legs, cls.dim, source)
    platform = parse_points(data, "platform", cls.n_legs, cls.dim, source)
    limits = _parse_limits(data.get("limits", {}), cls, source)
    home = data.get("home")
    if home is not None:
        if not isinstance(home, list) or len(home) != len(cls.pose_names):
            raise RobotFileError(source, "home", f"expected {len(cls.pose_names)} values {list(cls.pose_names)}")
        home = [parse_number(v, source, f"home[{i}]", angle=cls.pose_names[i] in cls.angle_names)[1]
                for i, v in enumerate(home)]
    known = {"name", "kind", "base", "platform", "limits", "home"}
    extra = sorted(set(data) - known)
    if extra:
        raise RobotFileError(source, extra[0], f"unknown field (known: {', '.join(sorted(known))})")
    robot = cls(name, base, platform, limits, home, source)
    _check_degenerate(robot, source)
    return robot


def parse_points(data, key: str, count: int, dim: int, source: str):
    """A list of ``count`` points of ``dim`` exact coordinates."""
    if key not in data:
        raise RobotFileError(source, key, "missing field")
    pts = data[key]
    if isinstance(pts, (tuple, np.ndarray)):           # a Python caller's tuples or array: as lists
        pts = [list(p) if isinstance(p, (tuple, list, np.ndarray)) else p for p in pts]
    if not isinstance(pts, list) or len(pts) != count:
        n = len(pts) if isinstance(pts, list) else "no list"
        raise RobotFileError(source, key, f"expected {count} points, got {n}")
    out = []
    for i, p in enumerate(pts):
        if isinstance(p, (tuple, np.ndarray)):
            p = list(p)
        if not isinstance(p, list) or len(p) != dim:
            raise RobotFileError(source, f"{key}[{i}]", f"expected {dim} coordinates, got {shown(p)}")
        row = []
        for j, c in enumerate(p):
            iv, text = parse_number(c, source, f"{key}[{i}][{j}]")
            row.append(text)
        out.append(tuple(row))
    return out


def _pairs(value, count, source, field):
    if not isinstance(value, list) or len(value) != count:
        raise RobotFileError(source, field, f"expected {count} [min, max] pairs")
    out = []
    for i, pair in enumerate(value):
        f = f"{field}[{i}]"
        if not isinstance(pair, list) or len(pair) != 2:
            raise RobotFileError(source, f, f"expected [min, max], got {shown(pair)}")
        lo, lo_t = parse_number(pair[0], source, f)
        hi, hi_t = parse_number(pair[1], source, f)
        if Fraction(lo_t) > Fraction(hi_t):
            raise RobotFileError(source, f, f"min {clip(lo_t)} exceeds max {clip(hi_t)}")
        if Fraction(lo_t) < 0:
            raise RobotFileError(source, f, f"a leg length cannot be negative ({clip(lo_t)})")
        out.append([lo_t, hi_t])
    return out


def _parse_joints(value, cls, source, field):
    if not isinstance(value, list) or len(value) != cls.n_legs:
        raise RobotFileError(source, field, f"expected {cls.n_legs} joint tables, one per leg")
    out = []
    for i, table in enumerate(value):
        f = f"{field}[{i}]"
        if not isinstance(table, dict):
            raise RobotFileError(source, f, "expected a table with 'normals' or 'axis' and 'half_angle'")
        entry = {}
        if "normals" in table:
            normals = table["normals"]
            if not isinstance(normals, list) or not normals:
                raise RobotFileError(source, f + ".normals", "expected a non-empty list of vectors")
            rows = []
            for k, n in enumerate(normals):
                if not isinstance(n, list) or len(n) != 3:
                    raise RobotFileError(source, f"{f}.normals[{k}]", "expected 3 coordinates")
                rows.append([parse_number(c, source, f"{f}.normals[{k}]")[1] for c in n])
                if all(Fraction(c) == 0 for c in rows[-1]):
                    raise RobotFileError(source, f"{f}.normals[{k}]", "a facet normal cannot be zero")
            entry["normals"] = rows
        if "axis" in table or "half_angle" in table:
            if "axis" not in table or "half_angle" not in table:
                raise RobotFileError(source, f, "a cone needs both 'axis' and 'half_angle'")
            axis = table["axis"]
            if not isinstance(axis, list) or len(axis) != 3:
                raise RobotFileError(source, f + ".axis", "expected 3 coordinates")
            entry["axis"] = [parse_number(c, source, f + ".axis")[1] for c in axis]
            if all(Fraction(c) == 0 for c in entry["axis"]):
                raise RobotFileError(source, f + ".axis", "the cone axis cannot be zero")
            half, entry["half_angle"] = parse_number(table["half_angle"], source, f + ".half_angle", angle=True)
            if not (half.lo >= 0 and half.hi < 1.5707963267948966):
                raise RobotFileError(source, f + ".half_angle", "a cone half-angle must lie in [0, 90deg)")
        if not entry:
            raise RobotFileError(source, f, "expected 'normals' or 'axis' and 'half_angle'")
        for key in table:
            if key not in ("normals", "axis", "half_angle", "comment"):
                raise RobotFileError(source, f"{f}.{key}", "unknown field")
        out.append(entry)
    return out


def _parse_limits(limits, cls, source):
    if not isinstance(limits, dict):
        raise RobotFileError(source, "limits", "expected a table")
    out = {}
    for key, value in limits.items():
        field = f"limits.{key}"
        if key == "leg_length":
            out[key] = _pairs(value, cls.n_legs, source, field)
        elif key == "leg_radius":
            values = value if isinstance(value, list) else [value] * cls.n_legs
            if len(values) != cls.n_legs:
                raise RobotFileError(source, field, f"expected one radius or {cls.n_legs}")
            texts = [parse_number(v, source, field)[1] for v in values]
            if any(Fraction(t) < 0 for t in texts):
                raise RobotFileError(source, field, "a radius cannot be negative")
            out[key] = texts
        elif key in ("base_joints", "platform_joints"):
            out[key] = _parse_joints(value, cls, source, field)
        else:
            raise RobotFileError(source, field, "unknown limit (known: leg_length, leg_radius, base_joints, platform_joints)")
    return out


def _matrix_A(robot, base, plat, poses) -> np.ndarray:
    """The matrix A of the robot's model (``symbolic_model``) at float poses, in plain numpy (the
    same rows: planar [(y − a_y) q_x − (x − a_x) q_y, l_x, l_y], spherical a_i × Q b_i, Gough
    [l_i, (R b_i) × l_i], with q_i, Q b_i, R b_i the rotated platform points and l_i the legs);
    floats for an input check, without building the symbolic model."""
    a, b = np.array(base, dtype=np.float64), np.array(plat, dtype=np.float64)
    if robot.kind == "planar-3rpr":
        x, y, phi = poses[:, 0, None], poses[:, 1, None], poses[:, 2, None]
        qx = np.cos(phi) * b[:, 0] - np.sin(phi) * b[:, 1]
        qy = np.sin(phi) * b[:, 0] + np.cos(phi) * b[:, 1]
        return np.stack([(y - a[:, 1]) * qx - (x - a[:, 0]) * qy, x + qx - a[:, 0], y + qy - a[:, 1]], axis=-1)
    R = rotation_float(robot.kind, poses if robot.kind == "gough-stewart" else poses[:, :3])
    rb = np.einsum("nkj,ij->nik", R, b)
    if robot.kind == "spherical-3dof":
        return np.cross(a[None], rb)
    legs = poses[:, None, :3] + rb - a[None]
    return np.concatenate([legs, np.cross(rb, legs)], axis=-1)


def _check_degenerate(robot: Robot, source: str) -> None:
    """Reject geometries for which det(A) vanishes at every pose."""
    base = [tuple(Fraction(c) for c in p) for p in robot.base]
    plat = [tuple(Fraction(c) for c in p) for p in robot.platform]
    for i, j in itertools.combinations(range(robot.n_legs), 2):
        if base[i] == base[j] and plat[i] == plat[j]:
            raise RobotFileError(source, f"base[{j}]", f"legs {i + 1} and {j + 1} coincide (same base and platform joints)")
    if all(p == base[0] for p in base):
        raise RobotFileError(source, "base", "all base joints coincide: every pose is singular")
    if all(p == plat[0] for p in plat):
        raise RobotFileError(source, "platform", "all platform joints coincide: every pose is singular")
    if robot.kind == "spherical-3dof":
        for i in range(3):
            if all(c == 0 for c in base[i]):
                raise RobotFileError(source, f"base[{i}]", "a base joint at the centre O makes every pose singular")
            if all(c == 0 for c in plat[i]):
                raise RobotFileError(source, f"platform[{i}]", "a platform joint at the centre O makes every pose singular")
    # generic check: det(A) at random poses (plain floats: an input check, not a proof).  Its ratio to
    # the Hadamard bound depends on the shape only (a move of either frame's origin changes A by a
    # unimodular factor, a change of unit scales both alike): planar and Gough-Stewart joints are taken
    # about their centroids, in units of the robot's size, so that a small or far robot is tried alike
    a, b = np.array(base, dtype=np.float64), np.array(plat, dtype=np.float64)
    scale = max(1.0, float(np.max(np.abs(np.concatenate([a, b])))))
    if robot.kind != "spherical-3dof":                     # (a spherical robot turns about O: kept)
        a, b = a - a.mean(axis=0), b - b.mean(axis=0)
        scale = float(np.max(np.abs(np.concatenate([a, b]))))
        a, b, scale = a / scale, b / scale, 1.0
    rng = np.random.default_rng(0)
    d = len(robot.pose_names)
    poses = rng.uniform(-1, 1, size=(8, d))
    for k, name in enumerate(robot.pose_names):
        if name not in robot.angle_names:
            poses[:, k] *= scale
    if robot.kind == "gough-stewart":
        poses[:, 2] = np.abs(poses[:, 2]) + scale
    A = _matrix_A(robot, a, b, poses)
    hadamard = np.prod(np.linalg.norm(A, axis=-2), axis=-1)  # |det A| <= product of the column norms
    if np.all(np.abs(np.linalg.det(A)) <= 1e-9 * hadamard):
        raise RobotFileError(source, "platform", "det(A) is below 1e-9 of its Hadamard bound at every pose tried: a degenerate "
                                                 "geometry (collinear or coincident joints, base and platform similar) or one "
                                                 "within about that of it")
