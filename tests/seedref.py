"""Independent references for the seed tests: the seed models at high precision with mpmath, from the
exact decimals of a robot (never from certkin's arithmetic), and the reading of printed decimals.

det(A) rows (seed 003 §1.2-1.3, same column order as certkin):
  planar 3-RPR, pose (x, y, phi):  [(y - a_y) q_x - (x - a_x) q_y, x + q_x - a_x, y + q_y - a_y], q = R(phi) b
  spherical, Euler ZYZ (phi1, phi2, phi3) or tilt-and-torsion (phi1, phi2, sigma = phi1 + phi3):
                                   a_i x (Q b_i),  Q = Rz(phi1) Ry(phi2) Rz(phi3)
Gough-Stewart (seed 000 §1.1): B_i = C + Rz(psi) Rx(theta) Rz(phi) b_i, leg i = B_i - A_i.
"""
from fractions import Fraction

import mpmath as mp

from test_proofs import _cross, _rx, _ry, _rz

DPS = 40


def exact(text) -> mp.mpf:
    """The decimal (or integer, or "<v>deg") text as an mpf at the working precision."""
    text = str(text)
    if text.endswith("deg"):
        return exact(text[:-3]) * mp.pi / 180
    q = Fraction(text)
    return mp.mpf(q.numerator) / q.denominator


def printed(text) -> tuple[Fraction, Fraction]:
    """The reals that print as ``text``: ± half a unit of its last digit."""
    decimals = len(text.split(".")[1]) if "." in text else 0
    half = Fraction(1, 2 * 10 ** decimals)
    return Fraction(text) - half, Fraction(text) + half


def prints_as(value, text) -> bool:
    """Does the high-precision ``value`` round to the printed decimal ``text``?"""
    lo, hi = printed(text)
    with mp.workdps(DPS):
        return exact(lo) <= value <= exact(hi)


def encloses(interval, value, k=None) -> bool:
    """Does a certkin Interval (component k) contain the high-precision ``value``?"""
    lo, hi = (interval.lo, interval.hi) if k is None else (interval.lo[k], interval.hi[k])
    return mp.mpf(float(lo)) <= value <= mp.mpf(float(hi))


def points(robot, which):
    return [mp.matrix([exact(c) for c in p]) for p in getattr(robot, which)]


def planar_det(robot, pose):
    with mp.workdps(DPS):
        x, y, phi = (exact(v) for v in pose)
        R = mp.matrix([[mp.cos(phi), -mp.sin(phi)], [mp.sin(phi), mp.cos(phi)]])
        rows = []
        for a, b in zip(points(robot, "base"), points(robot, "platform")):
            q = R * b
            rows.append([(y - a[1]) * q[0] - (x - a[0]) * q[1], x + q[0] - a[0], y + q[1] - a[1]])
        return mp.det(mp.matrix(rows))


def spherical_det(robot, pose, tilt_torsion=False):
    with mp.workdps(DPS):
        p1, p2, p3 = (exact(v) for v in pose)
        Q = _rz(p1) * _ry(p2) * _rz(p3 - p1 if tilt_torsion else p3)
        rows = [_cross(a, Q * b) for a, b in zip(points(robot, "base"), points(robot, "platform"))]
        return mp.det(mp.matrix(rows))


def planar_legs(robot, pose):
    with mp.workdps(DPS):
        x, y, phi = (exact(v) for v in pose)
        R = mp.matrix([[mp.cos(phi), -mp.sin(phi)], [mp.sin(phi), mp.cos(phi)]])
        C = mp.matrix([x, y])
        return [mp.norm(C + R * b - a) for a, b in zip(points(robot, "base"), points(robot, "platform"))]


def gough_legs(robot, pose):
    with mp.workdps(DPS):
        x, y, z, psi, theta, phi = (exact(v) for v in pose)
        R = _rz(psi) * _rx(theta) * _rz(phi)
        C = mp.matrix([x, y, z])
        return [mp.norm(C + R * b - a) for a, b in zip(points(robot, "base"), points(robot, "platform"))]
