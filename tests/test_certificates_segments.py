"""Streamed FK certificates (docs/certificates.md, "Segments"): a search past its record limit writes
its tree in segments whose continued leaves are the next segment's roots.  The segmented certificate
re-checks with the same verdicts as the one kept whole, and a removed, swapped, dangling or damaged
segment, or a continued leaf that no following root matches, is rejected with what failed named."""
from pathlib import Path

import numpy as np
import pytest

import proofs
from certfile import Doc
from certkin import load_robot
from certkin.certificates import fk_certificate
from certkin.engine import PROVED
from certkin.fk import forward_kinematics

ROOT = Path(__file__).resolve().parents[1]
SPHERICAL = ROOT / "examples" / "robots" / "seed003-spherical-example-1.toml"
LIMIT = 500                                    # tree nodes: the search hands over several segments


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    robot = load_robot(SPHERICAL)
    lengths = [repr(float(v)) for v in robot.leg_lengths(robot.home_box()).mid()]
    out = tmp_path_factory.mktemp("segments")
    streamed = forward_kinematics(robot, lengths, record=True, record_limit=LIMIT)
    whole = forward_kinematics(robot, lengths, record="whole")
    assert streamed.tree.segment_roots is not None and whole.tree.segment_roots is None
    assert len(streamed.tree.kind) < len(whole.tree.kind)
    for r, only_proved in ((streamed, True), (whole, False)):    # streamed: no C that the certificate does not write
        has_C = r.tree.evidence_rows["C"] >= 0
        assert np.all(r.tree.kind[has_C] == PROVED) == only_proved and np.any(r.tree.kind[has_C] == PROVED)
    streamed.certificate().write(out / "streamed.cert")
    whole.certificate().write(out / "whole.cert")
    return out / "streamed.cert", out / "whole.cert"


def renamed(doc, mapping):
    """The arrays of segment k renamed to segment mapping[k] (None: removed)."""
    arrays = {}
    for name, a in doc.arrays.items():
        k = int(name.split("/")[0][7:]) if name.startswith("segment") else 0
        if mapping.get(k, k) is not None:
            arrays[name.replace(f"segment{k}/", f"segment{mapping.get(k, k)}/") if k else name] = a
    doc.arrays = arrays
    return doc


def rejected(doc, tmp_path, *fragments):
    report = proofs.check(doc.write(tmp_path / "forged.cert"))
    assert not report.ok
    for f in fragments:
        assert f in report.step, report.step
    return report.step


def test_segmented_certificate_checks_with_the_verdicts_of_the_whole_tree(files):
    streamed, whole = (Doc(f) for f in files)
    k = streamed.header["segments"]
    assert k >= 4 and "segments" not in whole.header
    assert not np.any(streamed.arrays["tree.kind"] != 4)          # segment 0: the claim's root, continued
    for s in range(1, k):                                          # every segment but the last continues
        assert np.any(streamed.arrays[f"segment{s}/tree.kind"] == 4) == (s < k - 1)
    a, b = proofs.check(files[0]), proofs.check(files[1])
    assert a.ok and b.ok, (a.step, b.step)
    assert a.proved == b.proved and a.checked == b.checked
    assert streamed.claim()["figures"] == whole.claim()["figures"]
    assert streamed.claim()["solutions"] == whole.claim()["solutions"]
    assert sum(len(streamed.arrays[n]) for n in streamed.arrays if n.endswith("tree.kind")) == \
        len(whole.arrays["tree.kind"]) + sum(int(np.sum(streamed.arrays[n] == 4))
                                             for n in streamed.arrays if n.endswith("tree.kind"))


def test_removed_segment(files, tmp_path):
    doc = Doc(files[0])
    k = doc.header["segments"]
    rejected(renamed(doc.copy(), {2: None}), tmp_path, "array segment2/tree.kind is missing")
    shifted = renamed(doc.copy(), {2: None, **{s: s - 1 for s in range(3, k)}})
    shifted.header["segments"] = k - 1
    rejected(shifted, tmp_path, "segment2/tree.roots: root", "of segment 1")
    last = renamed(doc.copy(), {k - 1: None})
    last.header["segments"] = k - 1
    rejected(last, tmp_path, f"segment {k - 2}: ", "continued leaves, 0 segments follow")


def test_swapped_segments(files, tmp_path):
    rejected(renamed(Doc(files[0]), {1: 2, 2: 1}), tmp_path, "segment1/tree.roots: root 0 is not continued leaf 0 of segment 0")


def test_continued_leaf_and_next_root_differ(files, tmp_path):
    doc = Doc(files[0])
    roots = doc.arrays["segment2/tree.roots"]
    assert len(roots) > 3
    roots[3, 0, 1] = np.nextafter(roots[3, 0, 1], np.inf)          # one bound of root 3 one float wider
    rejected(doc, tmp_path, "segment2/tree.roots: root 3 is not continued leaf 3 of segment 1")


def test_continued_leaf_without_following_segment(files, tmp_path):
    doc = Doc(files[0])
    k = doc.header["segments"]
    kind = doc.arrays[f"segment{k - 1}/tree.kind"]
    kind[np.nonzero((kind == 3) & (doc.arrays[f"segment{k - 1}/tree.code"] == 1))[0][0]] = 4   # an hc4-empty leaf
    doc.arrays[f"segment{k - 1}/tree.code"][kind == 4] = 0
    rejected(doc, tmp_path, f"segment {k - 1}: 1 continued leaves, 0 segments follow")
    dangling = renamed(Doc(files[0]), {})
    dangling.arrays.update({f"segment{k}/{n.split('/')[1]}": a for n, a in dangling.arrays.items() if n.startswith("segment1/")})
    rejected(dangling, tmp_path, f"body: array segment{k}/", "belongs to no segment")
    dangling.header["segments"] = k + 1
    rejected(dangling, tmp_path, f"segment {k - 1}: 0 continued leaves, 1 segments follow")


def test_flipped_bit_in_a_segment_array(files, tmp_path):
    doc = Doc(files[0])
    raw = bytearray(doc.arrays["segment2/tree.box"].tobytes())
    raw[len(raw) // 2] ^= 0x10
    doc.arrays["segment2/tree.box"] = np.frombuffer(bytes(raw), np.uint64).reshape(doc.arrays["segment2/tree.box"].shape)
    path = doc.write(tmp_path / "flipped.cert", rehash=False)
    report = proofs.check(path)
    assert not report.ok and report.step == "body: array segment2/tree.box: SHA-256 differs from the header's"


def test_segments_only_for_forward_kinematics(files, tmp_path):
    doc = Doc(files[1])
    doc.header["segments"] = 0
    rejected(doc, tmp_path, "segments: expected a positive integer")


def test_a_result_of_a_streamed_batch_alone_is_searched_again_whole():
    robot = load_robot(SPHERICAL)
    home = [float(v) for v in robot.leg_lengths(robot.home_box()).mid()]
    rows = [[repr(v) for v in home], [repr(v * 1.01) for v in home]]
    both = forward_kinematics(robot, rows, record=True, record_limit=LIMIT)
    assert both[0].tree is both[1].tree and both[0].tree.segment_roots is not None
    together = proofs.check(fk_certificate(both))
    alone = proofs.check(both[1].certificate())       # segment 1 would hold both roots: the search runs again whole
    assert together.ok and alone.ok, (together.step, alone.step)
    assert together.proved[1] == alone.proved[0] and together.checked["claims"] == 2 and alone.checked["claims"] == 1
    assert fk_certificate(both).header["segments"] >= 3 and "segments" not in both[1].certificate().header
