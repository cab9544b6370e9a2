"""The tamper list of issue 17 (item 6) on each kind of certificate: forward kinematics (with length ranges
and in-cluster leaves), singularity (one free box, cells with monotone leaves) and trajectory.  Every edit
is rejected with a message naming the step that failed (hashes are recomputed, as a forger would, unless
the damage is to the bytes themselves)."""
import numpy as np
import pytest

import proofs
from certfile import Doc
from certkin import load_robot
from certkin.fk import forward_kinematics
from certkin.singularity import certify_singularity_free, classify_cells
from certkin.trajectory import verify_trajectory
from test_certificates_v2 import EX2, ROOT, forged, rejected

MEL = ROOT / "examples" / "robots" / "seed000-mel-tsukuba.toml"


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """One certificate file per kind, each checked OK as written."""
    out = tmp_path_factory.mktemp("tamper")
    results = {
        "fk-ranges": forward_kinematics(load_robot(EX2), ["28.99:29.01", "13.66", "40.53"]),
        "free": certify_singularity_free(load_robot(EX2), "x=-20:-10,y=20:30,phi=0:0.3"),
        "cells": classify_cells(load_robot(EX2), "x=-50:50,y=-50:50,phi=0:0.7853981634", 4),
        "trajectory": verify_trajectory(load_robot(MEL), "-69,-50,500,85deg,10deg,0", "84,92,500,85deg,10deg,0"),
    }
    paths = {}
    for name, result in results.items():
        from certkin.certificates import singularity_certificate
        doc = singularity_certificate(result) if isinstance(result, list) else result.certificate()
        paths[name] = out / f"{name}.cert"
        doc.write(paths[name])
        report = proofs.check(paths[name])
        assert report.ok, (name, report.step)
    return paths


FIRST_ARRAY = {"fk-ranges": "tree.box", "free": "tree.code", "cells": "tree.flags", "trajectory": "traj.state"}


@pytest.mark.parametrize("kind", sorted(FIRST_ARRAY))
def test_damaged_bytes_and_hashes(files, kind, tmp_path):
    name = FIRST_ARRAY[kind]

    def flip(arrays):
        raw = bytearray(arrays[name].tobytes())
        raw[len(raw) // 2] ^= 0x04
        arrays[name] = np.frombuffer(bytes(raw), dtype=arrays[name].dtype).reshape(arrays[name].shape)
    rejected(forged(files[kind], tmp_path, edit_arrays=flip, rehash=False), f"body: array {name}: SHA-256 differs")

    def cut(arrays):
        arrays[name] = arrays[name][:-1]
    rejected(forged(files[kind], tmp_path, edit_arrays=cut, rehash=False), f"body: member {name}.bin has")
    rejected(forged(files[kind], tmp_path, lambda h: h.update(body_sha256="0" * 64), rehash=False),
             "header.body_sha256: differs")


@pytest.mark.parametrize("kind", sorted(FIRST_ARRAY))
def test_edited_geometry_is_caught_by_the_robot_file(files, kind, tmp_path):
    robot = MEL if kind == "trajectory" else EX2
    assert proofs.check(files[kind], robot=robot).ok

    def moved(h):
        h["robot"]["base"][1][0] = str(float(h["robot"]["base"][1][0]) + 0.5)    # name unchanged
    rejected(forged(files[kind], tmp_path, moved), "robot: the certificate's geometry is not that of", robot=robot)
    rejected(forged(files[kind], tmp_path, moved, rehash=False), "geometry_sha256: differs")


def test_fk_length_ranges_tampered(files):
    doc = Doc(files["fk-ranges"])
    assert doc.claim()["length_ranges"][0] == ["28.99", "29.01"]
    wide = doc.copy()                                 # a wider range: some rule no longer proves its box
    wide.claim()["length_ranges"][0] = ["28.9", "29.1"]
    assert not wide.check().ok and "claims[0]" in wide.check().step
    fixed = doc.copy()                                # the range replaced by a single length outside it
    fixed.claim().pop("length_ranges")
    fixed.claim()["lengths"] = ["29.5", "13.66", "40.53"]
    assert not fixed.check().ok and "claims[0]" in fixed.check().step
    inverted = doc.copy()
    inverted.claim()["length_ranges"][0] = ["29.01", "28.99"]
    assert "leg lengths must satisfy 0 <= lo <= hi" in inverted.check().step


def test_fk_removed_node_and_swapped_split(files):
    doc = Doc(files["fk-ranges"])
    removed = doc.copy()
    i = int(removed.nodes(3, 1)[-1])
    for name in ("tree.kind", "tree.code"):
        removed.arrays[name] = np.delete(removed.arrays[name], i)
    step = removed.check().step                       # the nodes after it shift: the first misplaced one fails
    assert step.startswith("tree: ") or step.startswith("claims[0].tree: node "), step
    swapped = doc.copy()
    swapped.arrays["tree.code"][0] = (swapped.arrays["tree.code"][0] + 1) % 4
    assert swapped.check().step.startswith("claims[0].tree: node ")


def test_fk_claim_without_its_tree_is_rejected(files, tmp_path):
    """A domain with no tree (and no regions) would claim "no posture anywhere, complete"."""
    def strip(h):
        claim = h["claims"][0]
        claim.pop("tree")
        claim.pop("figures", None)
        claim.update(regions=[0, 0], solutions=[])

    def no_nodes(arrays):
        for name in list(arrays):
            if name.startswith("tree."):
                del arrays[name]
        arrays["tree.kind"], arrays["tree.code"] = np.zeros(0, np.uint8), np.zeros(0, np.uint8)
    rejected(forged(files["fk-ranges"], tmp_path, strip, no_nodes), "claims[0].tree: expected true")


def test_singularity_removed_node_swapped_split_reused_flags(files):
    free = Doc(files["free"])
    removed = free.copy()
    i = int(removed.nodes(3)[-1])
    for name in ("tree.kind", "tree.code"):
        removed.arrays[name] = np.delete(removed.arrays[name], i)
    assert removed.check().step.startswith("tree: "), removed.check().step
    swapped = free.copy()                             # the root split on y instead of x: the leaves cover
    swapped.arrays["tree.code"][0] = 1                # other boxes; det(A) keeps its sign on the whole box,
    assert swapped.check().ok                         # and the checker bisects what its enclosure leaves
    swapped.arrays["tree.code"][0] = 3                # undecided: another proof of the same claim. No dimension 3:
    step = swapped.check().step
    assert step.startswith("claims[0].tree: node 0") and "dimension" in step, step
    cells = Doc(files["cells"])
    mono = cells.nodes(3, 2)                          # monotone leaves: one row of flags each
    rows = [cells.row("tree.flags", k) for k in mono]
    flags = cells.arrays["tree.flags"][rows]
    j = next(j for j in range(1, len(rows)) if not np.array_equal(flags[j], flags[0]))
    reused = cells.copy()                             # another leaf's flags (the analogue of a reused C): the
    reused.arrays["tree.flags"][rows[j]] = flags[0]   # checker re-proves such a leaf on pieces, so the claim
    assert reused.check().ok                          # stands or falls on its own, never on the evidence
    reused.arrays["tree.flags"][rows[j]] = 2
    assert reused.check().step == "tree.flags: monotonicity flags must be -1, 0 or 1"
    flipped = cells.copy()                            # a free cell's sign flipped: its leaves refute it
    k = next(k for k, c in enumerate(flipped.header["claims"]) if c["status"] == "singularity-free")
    flipped.claim(k)["sign"] *= -1
    step = flipped.check().step
    assert step.startswith(f"claims[{k}].tree: node ") and "not proved" in step, step


def test_singularity_edited_requested_box(files):
    free = Doc(files["free"])
    grown = free.copy()                               # a requested box beyond the proved box
    grown.claim()["requested"]["x"] = ["-20", "-9.5"]
    assert "claims[0].requested.x: '-9.5' is not inside the box" in grown.check().step


def test_trajectory_tampered(files, tmp_path):
    doc = Doc(files["trajectory"])
    claim = doc.claim()
    assert claim["status"] == "infeasible" and claim["leaves"] == [0, len(doc.arrays["traj.segment"])]
    removed = doc.copy()                              # a leaf removed: [0, 1] no longer tiled
    for name in ("traj.segment", "traj.t", "traj.state"):
        removed.arrays[name] = np.delete(removed.arrays[name], 3, axis=0)
    removed.claim()["leaves"] = [0, len(removed.arrays["traj.segment"])]
    assert "claims[0].leaves" in removed.check().step, removed.check().step
    moved = doc.copy()                                # a cut moved: the leaves overlap
    moved.arrays["traj.t"][3, 1] += 0.01
    assert "claims[0].leaves" in moved.check().step, moved.check().step
    flipped = doc.copy()                              # a violated leaf said to hold
    k = [i["constraint"] for i in claim["instances"]].index("interference")
    i = int(np.nonzero(flipped.arrays["traj.state"][:, k] == 2)[0][-1])
    flipped.arrays["traj.state"][i, k] = 1
    assert not flipped.check().ok and "claims[0]" in flipped.check().step, flipped.check().step
    feasible = doc.copy()                             # the verdict changed
    feasible.claim()["status"] = "feasible"
    assert "claims[0].status" in feasible.check().step
    path = doc.copy()                                 # the requested path edited (the end pose)
    path.claim()["path"][1][0] = "90"
    step = path.check().step
    assert step.startswith("claims[0].leaves[") and "refuted" in step, step
    narrower = doc.copy()                             # a violation interval shrunk: a bad leaf uncovered
    narrower.claim()["violations"][0]["s"][1] = 0.9
    narrower.claim()["violations"][0].pop("segment", None), narrower.claim()["violations"][0].pop("t", None)
    assert "no violation interval covers it" in narrower.check().step


def test_a_certificate_behind_other_bytes_is_unreadable(files, tmp_path):
    """Another certificate (or anything) before a valid one: ZIP readers find the last archive, so the file
    a reviewer hashes and files would not be the one checked: unreadable."""
    joined = tmp_path / "joined.cert"
    joined.write_bytes(files["fk-ranges"].read_bytes() + files["free"].read_bytes())
    with pytest.raises(ValueError, match="does not begin with header.json at the file's first byte"):
        proofs.check(joined)
    joined.write_bytes(b"#!" + files["free"].read_bytes())
    with pytest.raises(ValueError):
        proofs.check(joined)


def test_fk_region_moved_to_its_twin_outside_the_domain_is_rejected():
    """A forger negates a region's quaternion (q and -q are one rotation; the equations are even in q),
    which puts R outside the domain (q0 < 0), and marks that region's leaves as holding its twin.  Every
    Krawczyk test still passes, but the posture would be counted nowhere: "3 postures, complete" for a
    robot with 4.  The checker must refuse a twin leaf of a region outside the domain in a complete claim."""
    robot = load_robot(ROOT / "examples" / "robots" / "seed003-spherical-example-2.toml")
    result = forward_kinematics(robot, robot.leg_lengths_float([0.5235987755982988, 1.0471975511965976, 0.5235987755982988]))
    doc = Doc(result.certificate())
    assert result.complete and doc.check().ok and doc.check().checked["solutions"] == 4
    leaves = doc.nodes(3, 6)
    k = int(doc.arrays["tree.index"][doc.row("tree.index", int(leaves[0]))])
    n = doc.arrays["fk.region.box"].shape[1]
    sign = np.array([1.0] * (n - 4) + [-1.0] * 4)
    for name in ("fk.region.box", "fk.region.star"):
        if name in doc.arrays:
            box = doc.arrays[name][k]
            doc.arrays[name][k] = np.where(sign[:, None] > 0, box, -box[:, ::-1])
    for name in ("fk.region.box_C", "fk.region.star_C"):
        if name in doc.arrays:
            doc.arrays[name][k] = (sign[:, None] * doc.arrays[name][k]).astype(doc.arrays[name].dtype)
    for leaf in leaves:
        j, t = doc.row("tree.index", int(leaf)), doc.row("tree.index", int(leaf), 1)
        if doc.arrays["tree.index"][j] == k:
            doc.arrays["tree.index"][t] = 1 - doc.arrays["tree.index"][t]
    claim = doc.claim()
    claim["solutions"] = [s for s in claim["solutions"] if s["region"] != k]
    if "figures" in claim:
        claim["figures"]["solutions"] -= 1
    assert doc.check().step.endswith("the twin of a region outside the domain, in a complete claim: "
                                     "that posture would be counted nowhere"), doc.check().step
