"""Angle ranges of a user domain (``--domain``) as a filter of proved postures: is a posture's
rotation inside the ranges, outside them, or cannot it tell?

An angle names a rotation only modulo 2π, and a rotation has two triples of proper Euler angles
(Gough-Stewart: Rz(psi) Rx(theta) Rz(phi); spherical: Rz(phi1) Ry(phi2) Rz(phi3)): (a, b, c) and
(a + π, −b, c + π), since Rz(π) Rx(−b) Rz(π) = Rx(b) (and likewise about y).  With tilt and
torsion (phi1, phi2, sigma = phi1 + phi3) the second triple is (phi1 + π, −phi2, sigma + 2π).  So a
posture is *inside* the ranges when one of its triples, each angle shifted by some multiple of 2π,
lies in them, and *outside* when no triple and no shift meets them.  At theta = 0 (phi2 = 0) the
triples form a continuum; the pose enclosures (``FKSystem.pose``) are then as wide as 2π there
and the answer is "cannot tell".  Each comparison keeps a relative slack of ``SLACK`` on the side
that weakens the verdict (float π and 2πk are off by a few units in the last place), so "inside"
and "outside" are never claimed on rounding alone; "cannot tell" leaves the posture in a cluster.
"""
from __future__ import annotations

import math

TWO_PI = 2.0 * math.pi
SLACK = 2.0 ** -40          # relative to the magnitudes compared


def in_ranges(pose: dict, ranges: dict):
    """True (inside every angle range, for one of the rotation's angle triples), False (outside,
    for every triple), None (cannot tell).  ``pose``: name -> Interval (the enclosures of a proved
    posture); ``ranges``: name -> (lo, hi) floats enclosing the user's range."""
    if not ranges:
        return True
    verdicts = [_triple_in(triple, ranges) for triple in _triples(pose)]
    if True in verdicts:
        return True
    return False if all(v is False for v in verdicts) else None


def _triples(pose: dict) -> list[dict]:
    """The angle triples naming the posture's rotation, as (lo, hi) float pairs: the pose's own and,
    for three Euler angles, the other one."""
    own = {k: (float(v.lo), float(v.hi)) for k, v in pose.items()}
    names = [k for k in pose if k in ("psi", "theta", "phi", "phi1", "phi2", "phi3", "sigma")]
    if len(names) != 3:                                     # the planar robot's phi: one triple
        return [own]
    a, b, c = names
    other = dict(own)
    other[a] = (own[a][0] + math.pi, own[a][1] + math.pi)
    other[b] = (-own[b][1], -own[b][0])
    if c != "sigma":                                        # sigma + 2π names the same angle
        other[c] = (own[c][0] + math.pi, own[c][1] + math.pi)
    return [own, other]


def _triple_in(triple: dict, ranges: dict):
    verdict = True
    for name, (a, b) in ranges.items():
        lo, hi = triple[name]
        v = _angle_in(lo, hi, a, b)
        if v is False:
            return False
        if v is None:
            verdict = None
    return verdict


def _angle_in(lo: float, hi: float, a: float, b: float):
    """Is every angle of [lo, hi] + 2πk inside [a, b] for one integer k (True), is no angle of it in
    [a, b] for any k (False), or neither (None)?"""
    if not all(math.isfinite(t) for t in (lo, hi, a, b)):
        return None
    slack = SLACK * (1.0 + abs(lo) + abs(hi) + abs(a) + abs(b))
    if b - a >= TWO_PI + slack:                             # the range holds every angle
        return True
    if slack > 1.0:
        return None
    if hi - lo >= TWO_PI - slack:                           # the enclosure may hold every angle
        return None
    inside, meets = False, False
    for k in range(math.floor((a - hi) / TWO_PI) - 1, math.ceil((b - lo) / TWO_PI) + 2):
        l, h = lo + k * TWO_PI, hi + k * TWO_PI
        inside |= l >= a + slack and h <= b - slack
        meets |= l <= b + slack and h >= a - slack
    return True if inside else (None if meets else False)
