"""Deterministic generators of Gough-Stewart robots and leg lengths for the FK comparison tests.

Every generator takes a seed and returns the same instance on every machine:
the robot as robot-file content (exact decimal texts, for
``certkin.robot_from_dict``, ``msolve_fk.solve`` or ``to_toml``), the leg
lengths as exact decimal texts, and the pose they were computed from.

The lengths are computed at 50 significant digits (mpmath) and rounded to
``length_digits`` decimals, so the pose they come from is only close to a
posture of the instance; which postures the instance has is decided by the
oracle (msolve), not assumed.

Families:

- ``general_robot``: base and platform points drawn uniformly in a cube
  (``size="seed002"``: base in [-2, 2]³, platform in [-1.5, 1.5]³, as the seed
  002 24-solution robot; ``size="unit"``: both in [-1, 1]³), 3 decimals, a
  random pose (uniform rotation, origin near the base);
- ``symmetric_hexapod``: planar base and platform, joints in three pairs
  about 90°, 210°, 330° (the layout of seed 002's INRIA "main gauche",
  examples/robots/seed002-main-gauche.toml): base pairs wide, platform pairs
  narrow; coordinates exactly symmetric in the plane x = 0 (3-fold symmetric
  up to the rounding of the coordinates), home pose (0, 0, h, 0, 0, 0), leg
  limits ±15 % about the home lengths; ``symmetric_at_home`` and
  ``symmetric_at_random_pose`` (a random pose whose leg lengths lie within
  the limits).
"""
from __future__ import annotations

import random
import tomllib
from dataclasses import dataclass, field
from decimal import ROUND_HALF_EVEN, Decimal

import mpmath as mp

DIGITS = 50        # working precision (decimal digits) for leg lengths


@dataclass
class Instance:
    """A robot (robot-file content), leg lengths (exact texts) and the pose they come from."""

    label: str
    robot: dict
    lengths: list
    pose: tuple                                  # (x, y, z, psi, theta, phi), radians (approximate source pose)
    notes: dict = field(default_factory=dict)

    @property
    def lengths_text(self) -> str:
        return ",".join(self.lengths)


def decimal_text(value, digits: int) -> str:
    """``value`` rounded half-even to ``digits`` decimals, as an exact decimal text ("-0" made "0")."""
    d = Decimal(mp.nstr(mp.mpf(value), DIGITS, strip_zeros=False)) if not isinstance(value, (int, str)) \
        else Decimal(value)
    out = d.quantize(Decimal(1).scaleb(-digits), rounding=ROUND_HALF_EVEN)
    text = format(out.normalize(), "f") if out != 0 else "0"
    return text


def rotation(psi, theta, phi):
    """R = Rz(psi) Rx(theta) Rz(phi) (DESIGN.md pose convention) as an mpmath matrix."""
    def rz(a):
        c, s = mp.cos(a), mp.sin(a)
        return mp.matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    c, s = mp.cos(theta), mp.sin(theta)
    rx = mp.matrix([[1, 0, 0], [0, c, -s], [0, s, c]])
    return rz(psi) * rx * rz(phi)


def leg_lengths(robot: dict, pose, digits: int) -> list:
    """Leg lengths |C + R b_i − a_i| at ``pose`` (50 digits), rounded to ``digits`` decimals."""
    with mp.workdps(DIGITS):
        x, y, z, psi, theta, phi = (mp.mpf(v) for v in pose)
        R = rotation(psi, theta, phi)
        C = mp.matrix([x, y, z])
        out = []
        for a, b in zip(robot["base"], robot["platform"]):
            leg = C + R * mp.matrix([mp.mpf(str(v)) for v in b]) - mp.matrix([mp.mpf(str(v)) for v in a])
            out.append(decimal_text(mp.sqrt(sum(leg[k] ** 2 for k in range(3))), digits))
        return out


def unit_plucker_det(robot: dict, pose) -> float:
    """det of the 6x6 matrix of unit leg lines (l_i, (R b_i) x l_i)/|l_i| at ``pose`` (floats): 0 at a
    singularity; used to keep generated source poses away from singularities."""
    x, y, z, psi, theta, phi = (float(v) for v in pose)
    R = rotation(psi, theta, phi)
    rows = []
    for a, b in zip(robot["base"], robot["platform"]):
        rb = R * mp.matrix([float(v) for v in b])
        leg = mp.matrix([x, y, z]) + rb - mp.matrix([float(v) for v in a])
        n = mp.norm(leg)
        m = [rb[1] * leg[2] - rb[2] * leg[1], rb[2] * leg[0] - rb[0] * leg[2], rb[0] * leg[1] - rb[1] * leg[0]]
        rows.append([leg[k] / n for k in range(3)] + [m[k] / n for k in range(3)])
    return float(mp.det(mp.matrix(rows)))


def random_rotation(rng: random.Random):
    """(psi, theta, phi) of a uniformly distributed rotation (Shoemake's unit quaternion)."""
    u1, u2, u3 = rng.random(), rng.random(), rng.random()
    q = (mp.sqrt(1 - u1) * mp.sin(2 * mp.pi * u2), mp.sqrt(1 - u1) * mp.cos(2 * mp.pi * u2),
         mp.sqrt(u1) * mp.sin(2 * mp.pi * u3), mp.sqrt(u1) * mp.cos(2 * mp.pi * u3))
    return euler_of_quaternion(q)


def euler_of_quaternion(q):
    """(psi, theta, phi) with Rz(psi) Rx(theta) Rz(phi) = R(q), theta in [0, pi] (floats)."""
    q0, q1, q2, q3 = (mp.mpf(v) for v in q)
    n = q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3
    R13 = 2 * (q1 * q3 + q0 * q2) / n
    R23 = 2 * (q2 * q3 - q0 * q1) / n
    R31 = 2 * (q1 * q3 - q0 * q2) / n
    R32 = 2 * (q2 * q3 + q0 * q1) / n
    R33 = 1 - 2 * (q1 * q1 + q2 * q2) / n
    theta = mp.acos(max(-1, min(1, R33)))
    return float(mp.atan2(R13, -R23)), float(theta), float(mp.atan2(R31, R32))


def _point(rng, half, digits):
    return [decimal_text(rng.uniform(-half, half), digits) for _ in range(3)]


def general_robot(seed: int, size: str = "seed002", digits: int = 3, length_digits: int = 6,
                  min_det: float = 1e-3) -> Instance:
    """A random general 6-6 robot and lengths from a random pose (module docstring).  Draws again
    (deterministically) while the source pose is within ``min_det`` of a singularity."""
    half_base, half_plat, half_pos = {"seed002": (2.0, 1.5, 0.5), "unit": (1.0, 1.0, 0.5)}[size]
    rng = random.Random(f"general-{size}-{seed}")
    while True:
        robot = {"name": f"random general 6-6 ({size}, seed {seed})", "kind": "gough-stewart",
                 "base": [_point(rng, half_base, digits) for _ in range(6)],
                 "platform": [_point(rng, half_plat, digits) for _ in range(6)]}
        pose = tuple(rng.uniform(-half_pos, half_pos) for _ in range(3)) + random_rotation(rng)
        if abs(unit_plucker_det(robot, pose)) >= min_det:
            return Instance(f"general-{size}-{seed}", robot, leg_lengths(robot, pose, length_digits), pose)


def _polar(r, degrees, digits):
    a = mp.radians(degrees)
    return decimal_text(r * mp.cos(a), digits), decimal_text(r * mp.sin(a), digits)


def _ring(r, beta, digits):
    """Six planar points in three pairs about 90°, 330°, 210° (spread ±beta), exactly symmetric in x = 0:
    the points with x > 0 are computed, the others are their mirror images."""
    right = [_polar(r, 90 - beta, digits), _polar(r, 330 + beta, digits), _polar(r, 330 - beta, digits)]
    mirror = lambda p: ("0" if p[0] == "0" else (p[0][1:] if p[0].startswith("-") else "-" + p[0]), p[1])  # noqa: E731
    # legs in order around the circle: 90+b, 90-b, 330+b, 330-b, 210+b, 210-b
    pts = [mirror(right[0]), right[0], right[1], right[2], mirror(right[2]), mirror(right[1])]
    return [[x, y, "0"] for x, y in pts]


def symmetric_hexapod(seed: int, digits: int = 2) -> dict:
    """A symmetric hexapod (module docstring) with ``home`` and leg-length ``limits``."""
    rng = random.Random(f"symmetric-{seed}")
    rb = rng.uniform(8, 15)
    rp = rng.uniform(0.35, 0.7) * rb
    beta_b, beta_p = rng.uniform(40, 52), rng.uniform(8, 25)
    h = decimal_text(rng.uniform(0.8, 1.6) * rb, 1)
    robot = {"name": f"symmetric hexapod (seed {seed})", "kind": "gough-stewart",
             "base": _ring(rb, beta_b, digits), "platform": _ring(rp, beta_p, digits),
             "home": ["0", "0", h, "0", "0", "0"]}
    home = [float(v) for v in leg_lengths(robot, (0, 0, h, 0, 0, 0), 6)]
    lo, hi = decimal_text(0.85 * min(home), 2), decimal_text(1.15 * max(home), 2)
    robot["limits"] = {"leg_length": [[lo, hi] for _ in range(6)]}
    return robot


def symmetric_at_home(seed: int, length_digits: int = 6) -> Instance:
    """A symmetric hexapod with the leg lengths of its home pose."""
    robot = symmetric_hexapod(seed)
    pose = tuple(robot["home"])
    return Instance(f"symmetric-{seed}-home", robot, leg_lengths(robot, pose, length_digits),
                    tuple(float(v) for v in pose))


def symmetric_at_random_pose(seed: int, pose_seed: int = 0, length_digits: int = 6) -> Instance:
    """A symmetric hexapod at a random pose near home whose leg lengths lie within its limits
    (origin within ±15 % of the platform radius, angles within ±15°)."""
    robot = symmetric_hexapod(seed)
    rng = random.Random(f"symmetric-{seed}-pose-{pose_seed}")
    h = float(robot["home"][2])
    reach = 0.15 * max(abs(float(c)) for p in robot["platform"] for c in p[:2])
    lo, hi = (float(v) for v in robot["limits"]["leg_length"][0])
    while True:
        ang = [float(mp.radians(rng.uniform(-15, 15))) for _ in range(3)]
        pose = (rng.uniform(-reach, reach), rng.uniform(-reach, reach), h + rng.uniform(-reach, reach), *ang)
        lengths = leg_lengths(robot, pose, length_digits)
        if all(lo <= float(v) <= hi for v in lengths) and abs(unit_plucker_det(robot, pose)) >= 1e-3:
            return Instance(f"symmetric-{seed}-pose-{pose_seed}", robot, lengths, pose)


def load_dict(path) -> dict:
    """A robot file's content with every number as its exact decimal text."""
    with open(path, "rb") as fh:
        data = tomllib.load(fh, parse_float=Decimal)

    def text(v):
        return [text(x) for x in v] if isinstance(v, list) else {k: text(x) for k, x in v.items()} \
            if isinstance(v, dict) else v if isinstance(v, str) else str(v)
    return {k: (text(v) if k in ("base", "platform", "home", "limits") else v) for k, v in data.items()}


def home_pose(robot: dict):
    """The robot's ``home`` as mpmath numbers, angles in radians (a "deg" suffix converted)."""
    return [mp.radians(mp.mpf(v[:-3])) if v.endswith("deg") else mp.mpf(v) for v in map(str, robot["home"])]


def to_toml(robot: dict) -> str:
    """Robot-file text of a generated robot (exact decimals as TOML numbers)."""
    def num(v):
        return str(v)

    def points(key):
        return f"{key} = [\n" + "".join(f"    [{', '.join(num(c) for c in p)}],\n" for p in robot[key]) + "]\n"
    out = [f'name = "{robot.get("name", "robot")}"\n', f'kind = "{robot["kind"]}"\n', points("base"), points("platform")]
    if "home" in robot:
        out.append("home = [" + ", ".join(num(v) for v in robot["home"]) + "]\n")
    if "limits" in robot:
        out.append("\n[limits]\n")
        for key, value in robot["limits"].items():
            out.append(f"{key} = [" + ", ".join(f"[{num(a)}, {num(b)}]" for a, b in value) + "]\n")
    return "".join(out)
