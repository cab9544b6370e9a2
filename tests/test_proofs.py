"""The independent checker ``proofs`` on certificates written by hand (format version 2, not by certkin).

The sign of det(A) at the centre of every box is computed here independently
with sympy (exact rationals, 30-digit evaluation) from the formulas of
docs/certificates.md, and the checker must accept the honest certificates
and reject every tampered variant with the step named.
"""
import copy
import json
import math
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from mpmath import mp

import proofs
from certfile import document, tree_arrays

ROOT = Path(__file__).resolve().parents[1]

PLANAR = {"name": "toy", "kind": "planar-3rpr",
          "base": [["0", "0"], ["10", "0"], ["3", "10"]], "platform": [["0", "0"], ["4", "0"], ["2", "2"]]}
# seed 003 spherical Example 1 (Tab. 4.13): a_i = [w_i, u_i, -h], b_i = [x_i, y_i, 0]
SPHERICAL = {"name": "seed003-ex1", "kind": "spherical-3dof",
             "base": [["1.6", "0", "-1.2"], ["-1.1", "1.2", "-1.2"], ["-0.9", "-1", "-1.2"]],
             "platform": [["1", "0", "0"], ["-0.6", "1", "0"], ["-0.2", "-0.5", "0"]]}
# seed 000 Annex Table 3.1 (MEL Tsukuba prototype)
_XA, _YA = ["112.5", "-225", "-112.5", "67.5", "-135", "67.5"], ["-194.856", "0", "194.856", "-116.913", "0", "116.913"]
_XB, _YB = ["95.263", "0", "-95.263", "-69.282", "0", "69.282"], ["55", "-110", "55", "-40", "80", "-40"]
GOUGH = {"name": "mel", "kind": "gough-stewart",
         "base": [[_XA[i], _YA[i], "-25"] for i in range(6)],
         "platform": [[_XB[i], _YB[i], "-20"] for i in range(6)]}


# ----- independent reference: mpmath at 40 digits, exact geometry -------------
def _rz(a):
    return mp.matrix([[mp.cos(a), -mp.sin(a), 0], [mp.sin(a), mp.cos(a), 0], [0, 0, 1]])


def _ry(a):
    return mp.matrix([[mp.cos(a), 0, mp.sin(a)], [0, 1, 0], [-mp.sin(a), 0, mp.cos(a)]])


def _rx(a):
    return mp.matrix([[1, 0, 0], [0, mp.cos(a), -mp.sin(a)], [0, mp.sin(a), mp.cos(a)]])


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def reference_det(model, robot, pose):
    """det(A) at a float pose, from the formulas of docs/certificates.md, at 40 digits."""
    with mp.workdps(40):
        P = [mp.mpf(v) for v in pose]  # the exact binary values of the floats
        base = [mp.matrix([mp.mpf(c) for c in p]) for p in robot["base"]]
        plat = [mp.matrix([mp.mpf(c) for c in p]) for p in robot["platform"]]
        rows = []
        if model == "planar-3rpr/1":
            x, y, phi = P
            R = mp.matrix([[mp.cos(phi), -mp.sin(phi)], [mp.sin(phi), mp.cos(phi)]])
            for b, p in zip(base, plat):
                q = R * p
                rows.append([(y - b[1]) * q[0] - (x - b[0]) * q[1], x + q[0] - b[0], y + q[1] - b[1]])
        elif model.startswith("spherical"):
            third = P[2] - P[0] if model == "spherical-3dof-tt/1" else P[2]
            Q = _rz(P[0]) * _ry(P[1]) * _rz(third)
            rows = [_cross(a, Q * b) for a, b in zip(base, plat)]
        else:
            R = _rz(P[3]) * _rx(P[4]) * _rz(P[5])
            C = mp.matrix(P[:3])
            for a, b in zip(base, plat):
                rb = R * b
                l = C + rb - a
                rows.append(list(l) + _cross(rb, l))
        return float(mp.det(mp.matrix(rows)))


def cert(model, robot, pose, claims, trees=(), d=3):
    """A singularity certificate: the header and the arrays of the hand-written ``trees`` (one per
    claim with ``"tree": true``, as ``certfile.tree_arrays`` nodes)."""
    header = {"format": "certkin-certificate", "version": 2, "problem": "singularity",
              "robot": copy.deepcopy(robot), "model": model, "pose": pose, "claims": claims}
    return document(header, tree_arrays(trees, d))


def leaf(rule=0, flags=None):
    return ("leaf", rule, {} if flags is None else {"tree.flags": [flags]})


# float bounds enclosing the requested decimals (the float 4.9 is above 4.9, 5.1 below 5.1)
BOX = [[4.89, 5.11], [4.89, 5.11], [0.289, 0.32]]


@pytest.fixture
def planar():
    assert reference_det("planar-3rpr/1", PLANAR, [5.0, 5.0, 0.3]) > 100
    claim = {"requested": {"x": ["4.9", "5.1"], "y": ["4.9", "5.1"], "phi": ["0.29", "0.31"]},
             "box": copy.deepcopy(BOX), "status": "singularity-free", "sign": 1, "tree": True}
    return cert("planar-3rpr/1", PLANAR, ["x", "y", "phi"], [claim], [("cut", 0, 5.0, leaf(), leaf())])


def rejected(c, *fragments):
    report = c.check()
    assert not report.ok
    for f in fragments:
        assert f in report.step, report.step
    return report.step


# ----- acceptance ---------------------------------------------------------------
def test_planar_certificate_accepted(planar):
    report = planar.check()
    assert report.ok, report.step
    assert report.checked["leaves"] == 2 and report.checked["claims"] == 1
    assert str(report) == "OK: 1 claim, 2 leaves re-verified"
    assert report.proved == [f"singularity-free: det(A) {'> 0' if planar.claim()['sign'] > 0 else '< 0'} on the whole box (2 leaves)"]


def test_models_match_seed_reference_values():
    """Seed 003 digest values (planar Example 2 spot values, spherical Example 1 vertices)."""
    from proofs.models import MODELS, Robot
    ex2 = {"kind": "planar-3rpr", "base": [["3.78", "4.34"], ["34.47", "-3.78"], ["16.233", "34.76"]],
           "platform": [["-4.83", "-3.19"], ["12.04", "-3.19"], ["8.23", "12.09"]]}

    def at(robot, p):
        x = np.array([p], dtype=float)
        d = robot.det(x, x)
        assert d.hi[0] - d.lo[0] < 1e-9 * max(1.0, abs(d.lo[0]))
        return 0.5 * (d.lo[0] + d.hi[0])

    r = Robot(MODELS["planar-3rpr/1"], ex2)
    assert at(r, [0.0, 0.0, 0.0]) == pytest.approx(28891.66058, abs=1e-5)
    assert at(r, [10.0, 10.0, math.pi / 8]) == pytest.approx(8868.48667784, abs=1e-7)
    tt = Robot(MODELS["spherical-3dof-tt/1"], SPHERICAL)
    zyz = Robot(MODELS["spherical-3dof/1"], SPHERICAL)
    assert at(tt, [0.0, math.pi / 4, 0.0]) == pytest.approx(-0.025258874503, abs=1e-11)
    h = math.pi / 2
    got = [at(zyz, [a, b, c]) for a in (-h, h) for b in (0.0, h) for c in (-h, h)]
    assert got == pytest.approx([-0.0864, 0.0864, 0.72, -0.72, 0.0864, -0.0864, 0.72, -0.72], abs=1e-12)
    x = np.array([[1.0, 2.0, 0.3]])
    D, grad = r.det_gradient(x, x)
    eps = 1e-6
    fd = (at(r, [1.0 + eps, 2.0, 0.3]) - at(r, [1.0 - eps, 2.0, 0.3])) / (2 * eps)
    assert 0.5 * (grad.lo[0, 0] + grad.hi[0, 0]) == pytest.approx(fd, rel=1e-6)


def test_spherical_and_gough_certificates_accepted():
    for model, pose_names, centre in (("spherical-3dof-tt/1", ["phi1", "phi2", "sigma"], [0.52, 1.05, 1.05]),
                                      ("spherical-3dof/1", ["phi1", "phi2", "phi3"], [0.3, 0.6, -0.4])):
        s = 1 if reference_det(model, SPHERICAL, centre) > 0 else -1
        assert abs(reference_det(model, SPHERICAL, centre)) > 0.05
        box = [[c - 0.01, c + 0.01] for c in centre]
        c = cert(model, SPHERICAL, pose_names, [{"box": box, "status": "singularity-free", "sign": s, "tree": True}],
                 [leaf()])
        assert c.check().ok, c.check().step
        c.claim()["sign"] = -s
        rejected(c, "claims[0].tree: node 0 (leaf): natural rule: det(A) has sign")

    centre = [10.0, -5.0, 600.0, 0.1, 0.2, 0.3]
    s = 1 if reference_det("gough-stewart/1", GOUGH, centre) > 0 else -1
    box = [[c - 0.01, c + 0.01] if i < 3 else [c - 1e-4, c + 1e-4] for i, c in enumerate(centre)]
    c = cert("gough-stewart/1", GOUGH, ["x", "y", "z", "psi", "theta", "phi"],
             [{"box": box, "status": "singularity-free", "sign": s, "tree": True}], [leaf()], d=6)
    assert c.check().ok, c.check().step
    c.claim()["sign"] = -s
    rejected(c, "det(A) has sign")


# ----- tampering ---------------------------------------------------------------
def test_widened_claim_box_rejected(planar):
    planar.claim()["box"][0][1] = 100.0          # the cut at 5 still splits it; the upper part holds a singularity
    rejected(planar, "claims[0].tree: node 2 (leaf): natural rule:")


def test_flipped_sign_rejected(planar):
    planar.claim()["sign"] = -1
    rejected(planar, "claims[0].tree: node 1 (leaf): natural rule: det(A) has sign 1")


def test_removed_leaf_rejected(planar):
    for name in ("tree.kind", "tree.code"):
        planar.arrays[name] = planar.arrays[name][:-1]
    assert rejected(planar) == "tree: 2 nodes, but 1 roots and the splits and contractions make 3"


def test_changed_geometry_rejected(planar):
    assert reference_det("planar-3rpr/1", {**PLANAR, "base": [["0", "7"], ["10", "0"], ["3", "10"]]},
                         [5.0, 5.0, 0.3]) < 0
    planar.header["robot"]["base"][0][1] = "7"
    assert rejected(planar) == "geometry_sha256: differs from the SHA-256 of the stated geometry"
    planar.header["geometry_sha256"] = proofs.geometry_sha256(planar.header["robot"])
    rejected(planar, "node 1 (leaf): natural rule: det(A) has sign -1")


def test_split_outside_box_rejected(planar):
    planar.arrays["tree.cut"][0] = 5.3
    rejected(planar, "claims[0].tree: node 0: split point 5.3 not strictly inside")
    planar.arrays["tree.cut"][0] = 4.89            # lo < at is strict
    rejected(planar, "not strictly inside")
    planar.arrays["tree.cut"][0] = 5.0
    planar.arrays["tree.code"][0] = 3
    rejected(planar, "claims[0].tree: node 0: split dimension 3 (the boxes have 3)")
    planar.arrays["tree.code"][0] = 1               # a swapped dimension: y cut at 5.0 instead of x
    assert planar.check().ok                        # still a proof (det > 0 on both halves): of the same box


def test_requested_must_lie_in_box(planar):
    planar.claim()["requested"]["x"] = ["4.9", "5.1100000000000004"]  # > the float 5.11 = 5.1100000000000003...
    rejected(planar, "claims[0].requested.x: '5.1100000000000004' is not inside the box")
    planar.claim()["requested"]["x"] = ["4.9", "5.11000000000000031974423109204508364200592041015625"]
    assert planar.check().ok
    planar.claim()["requested"]["phi"] = ["17deg", "17.5deg"]  # 0.2967..., 0.3054...
    assert planar.check().ok
    planar.claim()["requested"]["phi"] = ["16deg", "17.5deg"]
    rejected(planar, "requested.phi: '16deg' is not inside")
    planar.claim()["requested"] = {"z": ["0", "1"]}
    rejected(planar, "unknown pose variable 'z'")


def test_unknown_header_fields_rejected(planar):
    for key, value, step in (("format", "other", "format:"), ("version", 3, "version:"),
                             ("model", "planar-3rpr/2", "model:"), ("problem", "fk", "problem:"),
                             ("pose", ["x", "phi", "y"], "pose:")):
        c = planar.copy()
        c.header[key] = value
        assert rejected(c).startswith(step)
    c = planar.copy()
    c.header["version"] = 1
    assert rejected(c).startswith("version: version 1 certificates (one JSON document) are no longer checked")
    c = planar.copy()
    c.arrays["tree.code"][1] = 7
    rejected(c, "tree: node 1: unknown leaf rule code 7")
    c = planar.copy()
    c.claim()["status"] = "free"
    rejected(c, "claims[0].status: unknown status")
    c = planar.copy()
    c.header["robot"]["base"][0][0] = 0.1
    c.header["geometry_sha256"] = proofs.geometry_sha256(c.header["robot"])
    rejected(c, "robot.base[0][0]: expected an exact decimal string")
    assert proofs.check([]).step == "certificate: expected a JSON object"


def test_undecided_claim_claims_nothing(planar):
    planar.header["claims"].append({"box": [[0, 1]], "status": "undecided"})
    report = planar.check()
    assert report.ok and report.checked["undecided"] == 1
    assert "1 undecided" in str(report)


# ----- singular claims ----------------------------------------------------------
@pytest.fixture
def singular():
    pos, neg = [5.0, 5.0, 1.0], [10.0, 10.0, 1.0]
    assert reference_det("planar-3rpr/1", PLANAR, pos) > 100 and reference_det("planar-3rpr/1", PLANAR, neg) < -100
    claim = {"box": [[0.0, 10.0], [0.0, 10.0], [0.9, 1.1]], "status": "singular",
             "witnesses": {"positive": pos, "negative": neg}}
    return cert("planar-3rpr/1", PLANAR, ["x", "y", "phi"], [claim])


def test_singular_witnesses(singular):
    assert singular.check().ok
    same = singular.copy()
    same.claim()["witnesses"]["negative"] = [5.0, 5.0, 1.0]
    assert rejected(same) == "claims[0].witnesses.negative: det(A) not proved < 0"
    swapped = singular.copy()
    w = swapped.claim()["witnesses"]
    w["positive"], w["negative"] = w["negative"], w["positive"]
    assert rejected(swapped) == "claims[0].witnesses.positive: det(A) not proved > 0"
    outside = singular.copy()
    outside.claim()["witnesses"]["negative"] = [10.0, 10.5, 1.0]
    assert rejected(outside) == "claims[0].witnesses.negative: pose outside the box"


def test_witnesses_lie_in_the_exact_requested_box(singular):
    """Issue item 5: a singular claim is about its requested box; its witnesses must lie in it, compared
    exactly with the decimal bounds; an exact coordinate may be a decimal string (enclosed)."""
    singular.claim()["requested"] = {"x": ["0", "10"], "y": ["0", "10"], "phi": ["0.95", "1.05"]}
    assert singular.check().ok
    singular.claim()["requested"]["x"] = ["5.0000000000000001", "10"]     # above the float 5.0
    rejected(singular, "claims[0].witnesses.positive: x = 5.0 is outside the requested [5.0000000000000001, 10]")
    singular.claim()["requested"] = {"x": ["0", "10"], "y": ["0", "10"], "phi": ["1", "1"]}
    assert singular.check().ok
    singular.claim()["requested"]["phi"] = ["57.29577951308232deg", "57.29577951308232deg"]   # ≈ 1 rad, not 1
    rejected(singular, "is outside the requested")
    for w in singular.claim()["witnesses"].values():
        w[2] = "57.29577951308232deg"                # the exact value, enclosed: det keeps its sign there
    assert singular.check().ok


# ----- the other rules and the checker's own bisection --------------------------
MONO_BOX = [[1.8, 2.2], [7.8, 8.2], [0.29, 0.31]]


def _single(box, node, sign=1):
    return cert("planar-3rpr/1", PLANAR, ["x", "y", "phi"],
                [{"box": box, "status": "singularity-free", "sign": sign, "tree": True}], [node])


def test_monotone_leaf():
    from proofs.models import MODELS, Robot
    from proofs.singularity import _rule
    assert reference_det("planar-3rpr/1", PLANAR, [2.0, 8.0, 0.3]) > 0
    lo, hi = np.array([[b[0] for b in MONO_BOX]]), np.array([[b[1] for b in MONO_BOX]])
    robot = Robot(MODELS["planar-3rpr/1"], PLANAR)
    one = np.array([1])
    assert _rule(robot, 0, lo, hi, one, None)[0] == 0     # the natural rule alone does not decide this box
    assert _rule(robot, 2, lo, hi, one, np.array([[1, 0, -1]]))[0] == 1
    report = _single(MONO_BOX, leaf(2, [1, 0, -1])).check()
    assert report.ok and report.checked["pieces"] == 0, report
    wrong = _single(MONO_BOX, leaf(2, [-1, 0, -1]))
    rejected(wrong, "claims[0].tree: node 0 (leaf): monotone rule: sign 1 not proved", "after bisecting 6 levels")
    bad = _single(MONO_BOX, leaf(2, [1, 0, 2]))
    rejected(bad, "tree.flags: monotonicity flags must be -1, 0 or 1")


def test_centred_leaf():
    box = [[7.5, 8.5], [7.5, 8.5], [0.275, 0.325]]
    report = _single(box, leaf(1)).check()
    assert report.ok and report.checked["pieces"] == 0, report


def test_checker_bisects_a_leaf_its_enclosure_does_not_decide():
    box = [[4.0, 6.0], [4.0, 6.0], [0.2, 0.4]]
    report = _single(box, leaf()).check()
    assert report.ok and report.checked["pieces"] > 0, report
    singular_box = [[0.0, 10.0], [0.0, 10.0], [0.9, 1.1]]
    rejected(_single(singular_box, leaf()), "claims[0].tree: node 0 (leaf): natural rule:")


# ----- files and the command line ----------------------------------------------
def _run(*args):
    return subprocess.run([sys.executable, "-m", "proofs", *map(str, args)], cwd=ROOT,
                          capture_output=True, text=True, timeout=60)


def test_cli_exit_codes(planar, tmp_path):
    good = planar.write(tmp_path / "good.cert")
    assert proofs.check(good).ok
    r = _run(good)
    assert r.returncode == 0 and r.stdout.endswith("\nOK: 1 claim, 2 leaves re-verified\n")
    assert r.stdout.startswith("robot: toy (planar-3rpr), geometry SHA-256 ") and "proved: singularity-free: det(A) " in r.stdout

    planar.claim()["sign"] = -1
    bad = planar.write(tmp_path / "bad.cert")
    r = _run(bad)
    assert r.returncode == 1 and r.stdout.splitlines()[-1].startswith("REJECTED: claims[0].tree") and not r.stderr

    old = tmp_path / "old.json"                       # version 1: refused with one clear line
    old.write_text(json.dumps({"format": "certkin-certificate", "version": 1, "problem": "singularity",
                               "robot": PLANAR, "claims": [{}]}))
    r = _run(old)
    assert r.returncode == 1 and "REJECTED: version: version 1 certificates" in r.stdout

    header = tmp_path / "header.json"                 # a version 2 header outside its archive: no certificate
    header.write_text(json.dumps({"format": "certkin-certificate", "version": 2, "problem": "singularity"}))
    r = _run(header)
    assert r.returncode == 2 and r.stdout == "" and "not a ZIP archive" in r.stderr and r.stderr.count("\n") == 1, r

    broken = tmp_path / "broken.json"
    broken.write_text('{"format": ')
    nan = tmp_path / "nan.json"
    nan.write_text('{"x": NaN}')
    for path in (broken, nan, tmp_path / "missing.cert"):
        r = _run(path)
        assert r.returncode == 2 and r.stdout == "" and r.stderr.count("\n") == 1, r
    with pytest.raises(ValueError):
        proofs.check_file(nan)


# ----- hostile files: rejected at once, with little memory, never a traceback ------------------
def test_members_compressed_otherwise_than_deflate_are_rejected(planar, tmp_path):
    """bzip2 or LZMA expand a few bytes into gigabytes: only stored and deflated members are read."""
    path = planar.write(tmp_path / "ok.cert")
    assert proofs.check(path).ok
    with zipfile.ZipFile(path) as z, zipfile.ZipFile(tmp_path / "bz2.cert", "w") as out:
        for info in z.infolist():
            out.writestr(info.filename, z.read(info), compress_type=zipfile.ZIP_STORED if info.filename == "header.json"
                         else zipfile.ZIP_BZIP2)
    assert "neither stored nor deflated" in proofs.check(tmp_path / "bz2.cert").step


def test_trees_that_do_not_add_up_or_outgrow_their_file_are_rejected_before_they_are_walked(planar, monkeypatch):
    bomb = planar.copy()            # a million splits: their 2 million children would be walked level by level
    bomb.arrays["tree.kind"] = np.zeros(1 << 20, np.uint8)
    bomb.arrays["tree.code"] = np.zeros(1 << 20, np.uint8)
    bomb.arrays.pop("tree.cut")
    assert rejected(bomb) == "tree: 1048576 nodes, but 1 roots and the splits and contractions make 2097153"
    monkeypatch.setattr(proofs.tree, "MAX_DEPTH", 0)       # a chain of contractions deeper than allowed
    assert "level 1 of 2 boxes: deeper or wider than" in rejected(planar.copy())
    monkeypatch.setattr(proofs.tree, "MAX_DEPTH", 1 << 16)
    big = planar.copy()             # more nodes than 16 a byte of the file (in memory: of its arrays)
    big.arrays["tree.kind"] = np.full((1 << 22) + 1, 3, np.uint8)
    big.arrays["tree.code"] = np.zeros((1 << 22) + 1, np.uint8)
    monkeypatch.setattr(proofs.container.Certificate, "size", property(lambda self: 1000))
    assert rejected(big) == "tree: 4194305 nodes in a certificate of 1000 bytes"


def test_malformed_values_are_rejections_not_tracebacks_nor_hangs(planar):
    import time
    t = time.perf_counter()
    huge = planar.copy()            # canonical form of 1e100000000: never built (it took minutes)
    huge.header["robot"]["base"][0][0] = "1e100000000"
    huge.robot_edited()
    assert not huge.check().ok
    far = planar.copy()             # beyond the float range: compared exactly, no OverflowError
    far.claim()["requested"]["x"][1] = "1e400"
    assert not far.check().ok
    listed = planar.copy()
    listed.header["problem"] = ["singularity"]
    assert rejected(listed).startswith("problem: unknown problem")
    stray = planar.copy()           # many array names against a million segments: no loop over the segments
    stray.header.update(segments=1, arrays={f"segment{i}x/t": {} for i in range(2000)})
    assert rejected(stray).startswith("body: array segment0x/t belongs to no segment")
    odd = planar.copy()             # arrays that are not arrays, given in memory
    odd.arrays["tree.kind"] = [3, 3]
    assert not odd.check().ok and odd.check().step.startswith("certificate: malformed")
    assert time.perf_counter() - t < 20


def test_a_wide_level_is_visited_in_batches_and_a_misdeclared_array_is_never_read(planar, tmp_path, monkeypatch):
    """A level of a million leaves of one rule went to the rule in one call (a 26 KB file: 10 GiB);
    an array declared with other rows than the nodes use was read whole before being refused."""
    calls = []
    parts = [(np.arange(20000), np.zeros((20000, 3)), np.ones((20000, 3)), np.zeros(20000, int))]
    proofs.tree.Forest._flush({(proofs.tree.LEAF, 0): parts}, lambda kind, code, ids, *rest: calls.append(len(ids)))
    assert calls == [8192, 8192, 3616]
    big = planar.copy()
    big.arrays["tree.cut"] = np.zeros(1 << 20)             # 8 MiB of zeros: the tree uses one cut
    path = big.write(tmp_path / "cut.cert")
    read = []
    real = proofs.container.Certificate.array
    monkeypatch.setattr(proofs.container.Certificate, "array", lambda self, name, *a: (read.append(name), real(self, name, *a))[1])
    assert "tree: tree.cut has 1048576 rows, the nodes use 1" in proofs.check(path).step
    assert "tree.cut" not in read


def test_decimals_in_other_scripts_than_ascii_are_not_decimals(planar):
    """'৪0.53' (a Bengali 4, like an 8) was read as 40.53 and printed as it was written."""
    odd = planar.copy()
    odd.claim()["requested"]["x"][0] = "৪.9"
    assert "not an exact decimal" in rejected(odd)
