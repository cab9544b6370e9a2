"""Version-2 certificate files (ZIP: JSON header, hashed arrays): re-checked, and every kind of damage or
tampering rejected with the failing step named (issue items 4-6)."""
import json
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

import proofs
from certfile import Doc
from certkin import load_robot, robot_from_dict
from certkin.fk import forward_kinematics
from certkin.singularity import certify_singularity_free
from certkin.trajectory import verify_trajectory

ROOT = Path(__file__).resolve().parents[1]
EX2 = ROOT / "examples" / "robots" / "seed003-planar-example-2.toml"
PLANAR = {"name": "planar benchmark", "kind": "planar-3rpr", "base": [["0", "0"], ["15.91", "0"], ["0", "10"]],
          "platform": [["0", "0"], ["17.04", "0"], ["13.236", "16.097"]]}


@pytest.fixture(scope="module")
def fk_file(tmp_path_factory):
    result = forward_kinematics(robot_from_dict(PLANAR), ["14.98", "15.38", "12"])
    assert result.complete and len(result.solutions) == 6
    path = tmp_path_factory.mktemp("v2") / "fk.cert"
    result.certificate().write(path)
    return path


@pytest.fixture(scope="module")
def singular_file(tmp_path_factory):
    r = certify_singularity_free(load_robot(EX2), "x=-50:50,y=-50:50,phi=0:0.7853981634")
    assert r.status == "singular"
    path = tmp_path_factory.mktemp("v2") / "singular.cert"
    r.certificate().write(path)
    return path


def forged(path, tmp_path, edit_header=None, edit_arrays=None, rehash=True):
    """A copy of ``path`` with its header and arrays edited (hashes recomputed unless ``rehash`` is false)."""
    doc = Doc(path)
    if edit_header:
        edit_header(doc.header)
    if edit_arrays:
        edit_arrays(doc.arrays)
    return doc.write(tmp_path / "forged.cert", rehash=rehash)


def rejected(path, *fragments, robot=None):
    report = proofs.check(path, robot=robot)
    assert not report.ok
    for f in fragments:
        assert f in report.step, report.step
    return report.step


def test_v2_files_check_and_say_what_was_proved(fk_file, singular_file, tmp_path):
    report = proofs.check(fk_file)
    assert report.ok, report.step
    assert report.proved == ["lengths 14.98, 15.38, 12: 6 unique postures in the domain, "
                             f"{report.checked['leaves'] - 6} boxes excluded, complete: proved"]
    assert report.about["geometry_sha256"] == proofs.geometry_sha256(PLANAR) and report.about["version"] == 2
    assert proofs.check(singular_file).ok
    with zipfile.ZipFile(fk_file) as z:                   # the header is the first member, stored, readable
        first = z.infolist()[0]
        assert first.filename == "header.json" and first.compress_type == zipfile.ZIP_STORED
        assert json.loads(z.read(first))["claims"][0]["complete"] is True
    traj = verify_trajectory(load_robot(ROOT / "examples" / "robots" / "seed000-mel-tsukuba.toml"),
                             "-69,-50,500,85deg,10deg,0", "84,92,500,85deg,10deg,0").certificate()
    traj.write(tmp_path / "traj.cert")
    assert proofs.check(tmp_path / "traj.cert").ok


def test_flipped_bit_in_a_packed_array(fk_file, tmp_path):
    def flip(arrays):
        raw = bytearray(arrays["tree.box"].tobytes())
        raw[100] ^= 0x10
        arrays["tree.box"] = np.frombuffer(bytes(raw), dtype=arrays["tree.box"].dtype).reshape(arrays["tree.box"].shape)
    rejected(forged(fk_file, tmp_path, edit_arrays=flip, rehash=False), "body: array tree.box: SHA-256 differs")
    data = bytearray(Path(fk_file).read_bytes())          # a flipped bit in the compressed stream itself
    with zipfile.ZipFile(fk_file) as z:
        info = z.getinfo("tree.kind.bin")
    local = data[info.header_offset:info.header_offset + 30]          # the member's local header
    start = info.header_offset + 30 + int.from_bytes(local[26:28], "little") + int.from_bytes(local[28:30], "little")
    data[start + info.compress_size // 2] ^= 0x01
    damaged = tmp_path / "damaged.cert"
    damaged.write_bytes(bytes(data))
    rejected(damaged, "tree.kind")


def test_truncated_body_and_file(fk_file, tmp_path):
    def cut(arrays):
        arrays["tree.code"] = arrays["tree.code"][:-7]
    rejected(forged(fk_file, tmp_path, edit_arrays=cut, rehash=False), "body: member tree.code.bin has",
             "its header entry says")
    short = tmp_path / "short.cert"
    short.write_bytes(Path(fk_file).read_bytes()[:-200])
    r = subprocess.run([sys.executable, "-m", "proofs", str(short)], capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "Traceback" not in r.stderr and not r.stdout


def test_wrong_hashes(fk_file, tmp_path):
    rejected(forged(fk_file, tmp_path, lambda h: h.update(body_sha256="0" * 64), rehash=False),
             "header.body_sha256: differs")
    rejected(forged(fk_file, tmp_path, lambda h: h["arrays"]["tree.kind"].update(sha256="1" * 64), rehash=False),
             "body: array tree.kind: SHA-256 differs")
    rejected(forged(fk_file, tmp_path, lambda h: h.update(geometry_sha256="2" * 64), rehash=False),
             "geometry_sha256: differs")


def test_removed_node(fk_file, tmp_path):
    doc = Doc(fk_file)
    i = int(doc.nodes(3, 1)[-1])                          # an hc4-empty leaf (no evidence rows)
    for name in ("tree.kind", "tree.code"):
        doc.arrays[name] = np.delete(doc.arrays[name], i)
    rejected(doc.write(tmp_path / "removed.cert"), "tree: ")


def test_swapped_split_dimension(fk_file, tmp_path):
    """A swapped dimension changes every box below the split: the root's is rejected, the node named.
    (Lower down, a swap may leave boxes that the same rules still exclude: then it is another proof of
    the same claim, and it is accepted.)"""
    doc = Doc(fk_file)
    assert doc.arrays["tree.kind"][0] == 0
    rejected_steps = 0
    for i in doc.nodes(0)[:8]:
        bad = doc.copy()
        bad.arrays["tree.code"][i] = (bad.arrays["tree.code"][i] + 1) % 4
        report = proofs.check(bad.write(tmp_path / "swapped.cert"))
        assert report.ok or report.step.startswith("claims[0].tree: node "), report.step
        rejected_steps += not report.ok
        if i == 0:
            assert not report.ok
    assert rejected_steps >= 1


def test_reused_preconditioner(fk_file, tmp_path):
    doc = Doc(fk_file)
    unique = doc.nodes(3, 6)                              # krawczyk-unique leaves: their C is stored
    assert len(unique) >= 2
    bad = doc.copy()
    bad.arrays["tree.C"][bad.row("tree.C", unique[1])] = bad.arrays["tree.C"][bad.row("tree.C", unique[0])]
    rejected(bad.write(tmp_path / "reused.cert"), "krawczyk-unique", "not proved")
    bad = doc.copy()
    bad.arrays["fk.region.box_C"][1] = bad.arrays["fk.region.box_C"][0]       # another root's matrix
    rejected(bad.write(tmp_path / "reused.cert"), "claims[0].regions[1]", "not all proved")
    bad = doc.copy()                                      # a contraction whose C the checker rebuilds: set
    k = bad.nodes(2, 3 + 64)[0]                           # one instead, that of a unique leaf elsewhere
    bad.arrays["tree.code"][k] = 3
    rows = bad.row("tree.C", k)
    bad.arrays["tree.C"] = np.insert(bad.arrays["tree.C"], rows, bad.arrays["tree.C"][0], axis=0)
    rejected(bad.write(tmp_path / "reused.cert"), "claims[0].tree: node ", "krawczyk")


def test_edited_requested_box(singular_file, tmp_path):
    def free_region(h):                          # a region of poses where det(A) keeps one sign (issue item 5)
        h["claims"][0]["requested"] = {"x": ["10", "10.001"], "y": ["10", "10.001"], "phi": ["0.39", "0.3901"]}
    rejected(forged(singular_file, tmp_path, free_region), "claims[0].witnesses", "outside the requested")
    def outside(h):
        h["claims"][0]["requested"]["x"] = ["-50", "60"]
    rejected(forged(singular_file, tmp_path, outside), "claims[0].requested.x: '60' is not inside the box")


def test_edited_geometry_and_the_robot_file(singular_file, tmp_path):
    def moved(h):
        h["robot"]["base"][0][0] = "30"          # 3.78 → 30, name unchanged
    path = forged(singular_file, tmp_path, moved)
    step = rejected(path, "robot: the certificate's geometry is not that of", robot=EX2)
    assert str(EX2) in step
    assert proofs.check(singular_file, robot=EX2).ok
    assert proofs.check(singular_file, robot=EX2).about["robot_file"] == str(EX2)


def test_command_line_on_version_2(fk_file, tmp_path):
    run = lambda *a: subprocess.run([sys.executable, "-m", "proofs", *map(str, a)], capture_output=True,  # noqa: E731
                                    text=True, timeout=120)
    r = run(fk_file, "--json")
    doc = json.loads(r.stdout)
    assert r.returncode == 0 and doc["ok"] and doc["checked"]["solutions"] == 6 and doc["version"] == 2
    r = run(fk_file)
    lines = r.stdout.splitlines()
    assert lines[0].startswith("robot: planar benchmark (planar-3rpr), geometry SHA-256 ")
    assert lines[1].startswith("question: ") and lines[2].startswith("proved: ") and lines[-1].startswith("OK: ")
    doc = Doc(fk_file)
    deep = tmp_path / "deep.cert"
    with zipfile.ZipFile(deep, "w") as z:
        z.writestr("header.json", "[" * 100000)
    huge = doc.copy()
    huge.claim()["domain"][0] = [-1e308, 1e308]
    for path, code in ((deep, 2), (huge.write(tmp_path / "huge.cert"), 1)):
        r = run(path)
        assert r.returncode == code and "Traceback" not in r.stderr and "Warning" not in r.stderr, r.stderr


def test_certificate_option_writes_atomically_or_says_why(tmp_path):
    run = lambda *a: subprocess.run([sys.executable, "-m", "certkin", *map(str, a)], capture_output=True,  # noqa: E731
                                    text=True, timeout=300, cwd=ROOT)
    fk = ("fk", EX2, "--lengths", "28.99,13.66,40.53")
    for target in (tmp_path, tmp_path / "missing" / "fk.cert"):       # a directory; a path that cannot be made
        r = run(*fk, "--certificate", target)
        assert r.returncode == 2 and r.stderr.startswith("certkin: error: --certificate") and r.stderr.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == []           # nothing half-written left behind
    good = tmp_path / "fk.cert"
    r = run(*fk, "--certificate", good)
    assert r.returncode == 0 and zipfile.is_zipfile(good)
    r = run("check", good, "--robot", EX2, "--json")
    doc = json.loads(r.stdout)
    assert r.returncode == 0 and doc["ok"] and doc["robot_file"] == str(EX2) and doc["checked"]["solutions"] == 6
    r = run("check", good, "--robot", ROOT / "examples" / "robots" / "seed003-planar-example-1.toml")
    assert r.returncode == 1 and "REJECTED: robot: the certificate's geometry is not that of" in r.stdout


def test_a_small_certificate_is_written_stored_with_its_hash_and_normal_permissions(tmp_path):
    """A body of at most 64 KiB is stored (no deflate); ``Document.write`` gives the size and SHA-256 of
    the bytes on disk; the file has the mode of a normally created file (0666 less the umask) and no
    temporary file is left."""
    import hashlib
    import os
    result = forward_kinematics(robot_from_dict(PLANAR), ["14.98", "15.38", "12"])
    document = result.certificate()
    path = tmp_path / "fk.cert"
    for umask in (0o022, 0o077):
        old = os.umask(umask)
        try:
            size, sha256 = document.write(path)
        finally:
            os.umask(old)
        data = path.read_bytes()
        assert (size, sha256) == (len(data), hashlib.sha256(data).hexdigest())
        assert path.stat().st_mode & 0o777 == 0o666 & ~umask
        with zipfile.ZipFile(path) as z:
            assert {i.compress_type for i in z.infolist()} == {zipfile.ZIP_STORED}
            assert sum(i.file_size for i in z.infolist() if i.filename != "header.json") <= 1 << 16
    assert [p.name for p in tmp_path.iterdir()] == ["fk.cert"]
    assert proofs.check(path).ok


# ----- FK regions (X* a uniqueness box around each root, R its tight box) and in-region leaves ----------
def regions_from_uniqueness_boxes(doc):
    """The planar certificate rewritten with regions X*_j = the uniqueness box of a krawczyk-unique leaf
    of root j (its C), R_j the root box as before; every such leaf becomes ``in-region j`` (code 8)."""
    out = doc.copy()
    unique = out.nodes(3, 6)
    star_rows = [out.row("tree.star", k) for k in unique]
    C_rows = [out.row("tree.C", k) for k in unique]
    index_rows = [out.row("tree.index", k) for k in unique]
    region = out.arrays["tree.index"][index_rows]
    out.arrays["fk.region.star"] = out.arrays["fk.region.box"].copy()      # X* given explicitly now
    out.arrays["fk.region.star_C"] = out.arrays["fk.region.box_C"].copy()
    twin = out.arrays["tree.index"][[r + 1 for r in index_rows]]
    assert not twin.any()                                  # planar: no twins
    for j in range(len(out.arrays["fk.region.box"])):
        k = list(region).index(j)
        out.arrays["fk.region.star"][j] = out.arrays["tree.star"][star_rows[k]]
        out.arrays["fk.region.star_C"][j] = out.arrays["tree.C"][C_rows[k]]
    out.arrays["tree.code"][unique] = 8
    out.arrays["tree.star"] = np.delete(out.arrays["tree.star"], star_rows, axis=0)
    out.arrays["tree.C"] = np.delete(out.arrays["tree.C"], C_rows, axis=0)
    out.arrays["tree.index"] = np.delete(out.arrays["tree.index"], [r + 1 for r in index_rows])
    leaves = out.claim()["figures"]["leaves"]
    leaves["in-region"] = leaves.pop("krawczyk-unique")
    return out


def test_regions_and_in_region_leaves(fk_file):
    doc = regions_from_uniqueness_boxes(Doc(fk_file))
    assert not np.array_equal(doc.arrays["fk.region.star"], doc.arrays["fk.region.box"])    # X* ⊋ R
    report = doc.check()
    assert report.ok, report.step
    assert report.checked["solutions"] == 6 and doc.claim()["figures"]["leaves"]["in-region"] == 6
    wrong = doc.copy()                                     # an in-region leaf naming another region
    wrong.arrays["tree.index"][wrong.row("tree.index", wrong.nodes(3, 8)[0])] += 1
    assert "the leaf is not inside the named box" in wrong.check().step
    small = doc.copy()                                     # X* shrunk to R: the leaves no longer lie in it
    small.arrays["fk.region.star"] = small.arrays["fk.region.box"].copy()
    small.arrays["fk.region.star_C"] = small.arrays["fk.region.box_C"].copy()
    assert "not inside the named box" in small.check().step
    loose = doc.copy()                                     # R moved out of its X*
    loose.arrays["fk.region.box"][2, 0] += 1.0
    assert "claims[0].regions[2]" in loose.check().step
    outside = doc.copy()                                   # a domain cut through a region's R: it straddles
    box = outside.arrays["fk.region.box"][0, 0]            # the boundary, so "complete" is not proved
    outside.claim()["domain"][0][1] = float(0.5 * box[0] + 0.5 * box[1])
    assert not outside.check().ok


def test_clusters_and_length_ranges(fk_file):
    doc = Doc(fk_file)
    clustered = doc.copy()                                 # an excluded leaf called "in a cluster" (the domain)
    leaf = clustered.nodes(3, 1)[0]
    clustered.arrays["tree.code"][leaf] = 9
    clustered.arrays["tree.index"] = np.insert(clustered.arrays["tree.index"], clustered.row("tree.index", leaf), 0)
    clustered.claim()["clusters"] = [clustered.claim()["domain"]]
    clustered.claim()["figures"]["leaves"]["hc4-empty"] -= 1
    clustered.claim()["figures"]["leaves"]["in-cluster"] = 1
    report = clustered.check()
    assert report.ok and "1 unresolved clusters" in report.proved[0], report.step
    clustered.claim()["clusters"] = [[[0.0, 0.0]] * 4]    # a cluster that does not hold the leaf
    assert "not inside the named box" in clustered.check().step
    ranged = doc.copy()                                    # the lengths as (degenerate) ranges
    ranged.claim()["length_ranges"] = [[v, v] for v in ranged.claim().pop("lengths")]
    report = ranged.check()
    assert report.ok and report.proved[0].startswith("lengths in [14.98, 14.98]"), report.step
    ranged.claim()["length_ranges"][0] = ["14.99", "14.97"]
    assert "leg lengths must satisfy 0 <= lo <= hi" in ranged.check().step


def test_a_contraction_result_beyond_the_child_needs_the_excess_proved_root_free(fk_file):
    """The checker accepts a contraction whose own result Z overshoots the child Y only when Z \\ Y (slabs
    beyond Y's faces) is proved root-free; a child that leaves out a root is refused (proofs.fk)."""
    from proofs import container, fk
    from proofs.fk_system import System
    cert = container.read(fk_file)
    system = System(cert.header["model"], cert.header["robot"])
    L = fk._read_claim(system, cert, cert.header["claims"][0], "claims[0]").L
    R = cert.array("fk.region.box")                      # a proved root box of each posture
    lo, hi = R[:, :, 0], R[:, :, 1]
    w = hi - lo
    Lk = type(L)(np.repeat(L.lo[None], len(R), 0), np.repeat(L.hi[None], len(R), 0))
    zlo, zhi = lo - 4 * w, hi + 4 * w                    # Z: around each root
    keeps = fk._root_free_outside(system, zlo, zhi, lo - w, hi + w, Lk, zhi - zlo)
    assert keeps.all()                                   # Y holds the root: the rest of Z is root-free
    misses = fk._root_free_outside(system, zlo, zhi, hi + w, hi + 2 * w, Lk, zhi - zlo)
    assert not misses.any()                              # Y beside the root: never accepted
    nan = zlo.copy()
    nan[:, 0] = np.nan
    assert not fk._root_free_outside(system, nan, zhi, lo - w, hi + w, Lk, zhi - zlo).any()


def node_boxes(doc):
    """(lo, hi) of every node of a one-root tree (breadth-first order), decoded as the checker does, and
    the child of each contraction node."""
    from proofs.tree import SPLIT_RATIO
    kind, code = doc.arrays["tree.kind"], doc.arrays["tree.code"]
    lo0, hi0 = (np.array(v, dtype=float) for v in zip(*doc.claim()["domain"]))
    lo, hi = np.zeros((len(kind), len(lo0))), np.zeros((len(kind), len(lo0)))
    lo[0], hi[0] = lo0, hi0
    nxt, cuts, boxes, child = 1, iter(doc.arrays["tree.cut"]), iter(doc.arrays["tree.box"]), {}
    for i in range(len(kind)):
        if kind[i] <= 1:
            d = int(code[i])
            at = lo[i, d] + SPLIT_RATIO * (hi[i, d] - lo[i, d]) if kind[i] == 0 else next(cuts)
            lo[nxt:nxt + 2], hi[nxt:nxt + 2] = lo[i], hi[i]
            hi[nxt, d], lo[nxt + 1, d] = at, at
            nxt += 2
        elif kind[i] == 2:
            box = (np.stack([lo[i], hi[i]], -1).view(np.uint64) ^ next(boxes)).view(np.float64)
            lo[nxt], hi[nxt], child[i] = box[:, 0], box[:, 1], nxt
            nxt += 1
    return lo, hi, child


def test_second_hc4_pass_rechecked():
    """A spatial search runs HC4 again on a box the first pass shrank a lot: two "hc4" contractions in
    a row, each re-checked from its own parent box.  The second one narrowed further is rejected."""
    robot = load_robot(ROOT / "examples" / "robots" / "seed003-spherical-example-1.toml")
    lengths = ",".join(repr(float(v)) for v in robot.leg_lengths(robot.home_box()).mid())
    result = forward_kinematics(robot, lengths)
    assert result.complete and len(result.solutions) == 6
    doc = Doc(result.certificate())
    assert doc.check().ok
    kind, code = doc.arrays["tree.kind"], doc.arrays["tree.code"]
    lo, hi, child = node_boxes(doc)
    hc4 = set(np.nonzero((kind == 2) & (code == 0))[0].tolist())
    second = [child[i] for i in sorted(hc4) if child[i] in hc4]
    assert second                                          # chains of two HC4 passes exist
    i = next(j for j in second if kind[child[j]] == 3)     # (its child a leaf: no box below depends on it)
    c = child[i]
    d = int(np.argmax(hi[c] - lo[c]))
    new = np.stack([lo[c], hi[c]], -1)
    new[d, 0] += 0.01 * (hi[c, d] - lo[c, d])             # the second pass's box narrowed by 1 %
    bad = doc.copy()
    bad.arrays["tree.box"][bad.row("tree.box", i)] = np.stack([lo[i], hi[i]], -1).view(np.uint64) ^ new.view(np.uint64)
    assert "not inside the child box" in bad.check().step, bad.check().step


@pytest.mark.parametrize("example, lengths", [
    (3, "2.99806464835365,2.10024948004205,2.27700767471315"),     # slope-gs-empty leaves, rebuilt C
    (1, "1.11130683860015,2.84842079860041,1.47839641688408")])    # an hc4 contraction, widened too little
def test_near_singular_certificates_check(tmp_path, example, lengths):
    """Lengths of a pose next to a singularity (a cluster of postures): the answer was right, its
    certificate was rejected.  The checker rebuilt the C of slope steps from its own slope matrices,
    but there mid(S) has condition number 8e7: the two float64 inverses rounded to different float32
    values, and C S moved by order 1 (such C are now kept in the certificate); and its HC4 pass ended
    27 units in the last place beyond a contraction widened by 2⁻²⁰ of a 6e-10 wide box (now also by
    2⁻⁴⁰ of the bounds' magnitude)."""
    robot = load_robot(ROOT / "examples" / "robots" / f"seed003-spherical-example-{example}.toml")
    result = forward_kinematics(robot, lengths)
    assert result.complete and len(result.solutions) == 2 and result.clusters
    result.certificate().write(tmp_path / "c.cert")
    report = proofs.check(tmp_path / "c.cert")
    assert report.ok, report.step
    if example == 3:                 # (its C in the certificate)
        assert "slope-gs-empty, C kept" in {result.tree.reason_name(i) for i in np.nonzero(result.tree.reason > 12)[0]}


def test_a_preconditioner_is_fragile_when_ill_conditioned():
    from certkin.fk.step import KAPPA, fragile
    from intervals import Interval
    M = np.array([[[1.0, 0.0], [0.0, 1.0]], [[1.0, 1.0], [1.0, 1.0 + 1e-6]]])
    C = np.linalg.inv(M)
    assert fragile(C, Interval.from_bounds(M, M)).tolist() == [False, True]
    assert fragile(np.full((1, 2, 2), np.nan), Interval.from_bounds(M[:1], M[:1])).tolist() == [True]
    assert 1e3 <= KAPPA <= 1e6


def test_a_preconditioner_that_is_no_inverse_is_fragile():
    """A singular midpoint's pseudo-inverse has a small norm but is no inverse: the checker's own
    inverse of a midpoint a few ulps away may be another matrix entirely, so the C is kept."""
    from certkin.fk.step import KAPPA, fragile
    from intervals import Interval
    M = np.array([[[1.0, 1.0], [1.0, 1.0]], [[2.0, 0.0], [0.0, 4.0]]])
    C = np.linalg.pinv(M)
    kappa = np.abs(C).sum(axis=2).max(axis=1) * np.abs(M).sum(axis=2).max(axis=1)
    assert np.all(kappa <= KAPPA)                      # the norm rule alone would rebuild both
    assert fragile(C, Interval.from_bounds(M, M)).tolist() == [True, False]
    assert fragile(C.astype(np.float32).astype(float), Interval.from_bounds(M, M)).tolist() == [True, False]


def test_a_widened_solution_box_is_rejected(fk_file, tmp_path):
    """A solution's box (the one people read) widened to the whole domain, where it holds all six
    postures, was accepted: it only had to enclose its region.  It may now be wider than the region
    by the next floats only (what certkin writes, so that its printed decimals lie outside too)."""
    def widen(h):
        h["claims"][0]["solutions"][0]["box"] = [list(d) for d in h["claims"][0]["domain"]]

    def one_float(h):
        box = h["claims"][0]["solutions"][0]["box"]
        box[0][0] = float(np.nextafter(box[0][0], -np.inf))
    rejected(forged(fk_file, tmp_path, widen), "solutions[0].box: wider than the box of region 0")
    rejected(forged(fk_file, tmp_path, one_float), "solutions[0].box: wider than the box of region 0")
    assert proofs.check(fk_file).ok


def test_a_reports_rules_name_a_rule_once_whether_its_c_is_kept_or_not():
    from certkin.report.page import tree_evidence
    robot = load_robot(ROOT / "examples" / "robots" / "seed003-spherical-example-3.toml")
    result = forward_kinematics(robot, "2.99806464835365,2.10024948004205,2.27700767471315", record="whole")
    rules = tree_evidence(result.tree)["rules"]
    assert "excluded: slope-gs-empty" in rules and not any("kept" in r for r in rules)
    assert sum(rules.values()) == len(result.tree.leaves())
