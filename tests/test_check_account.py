"""``certkin check`` (``proofs.run``) on every kind of certificate: the robot's name and geometry SHA-256,
the question, each verdict with its figures, ``--robot`` confirming the geometry, ``--json`` the same as
a document, ``--progress`` a bar on stderr (issue 17, item 4)."""
import json

import pytest

import proofs
from certkin import load_robot
from certkin.certificates import singularity_certificate
from certkin.fk import forward_kinematics
from certkin.singularity import certify_singularity_free, classify_cells
from certkin.trajectory import plan, verify_trajectory
from certkin.workspace import workspace_section, workspace_volume
from test_certificates_v2 import EX2, ROOT
from test_fk_modes import ISSUE_BASE, ISSUE_PLATFORM, planar, planar_lengths, singular_pose

ROBOTS = ROOT / "examples" / "robots"
MEL, MICRO = ROBOTS / "seed000-mel-tsukuba.toml", ROBOTS / "seed004-micro-manipulator.toml"
BOX = "x=-50:50,y=-50:50,phi=0:0.7853981634"


def _clusters():
    robot = planar(ISSUE_BASE, ISSUE_PLATFORM)
    return forward_kinematics(robot, planar_lengths(robot, singular_pose(robot), 17))


KINDS = {   # name: (robot file or None, solve, fragments of the question, fragments of the verdicts)
    "singular": (EX2, lambda: certify_singularity_free(load_robot(EX2), BOX),
                 ["x in [-50, 50], y in [-50, 50], phi in [0, 0.7853981634]"], ["singular: det(A) > 0 at (", "< 0 at ("]),
    "free": (EX2, lambda: certify_singularity_free(load_robot(EX2), "x=-20:-10,y=20:30,phi=0:0.3"),
             ["x in [-20, -10], y in [20, 30], phi in [0, 0.3]"], ["singularity-free: det(A) < 0 on the whole box ("]),
    "cells": (EX2, lambda: classify_cells(load_robot(EX2), BOX, 4), ["64 box(es)"], ["64 boxes of poses: "]),
    "fk": (EX2, lambda: forward_kinematics(load_robot(EX2), "28.99,13.66,40.53"),
           ["lengths 28.99, 13.66, 40.53"], ["6 unique postures in the domain", "complete: proved"]),
    "fk-ranges": (EX2, lambda: forward_kinematics(load_robot(EX2), "28.99:29.01,13.66,40.53"),
                  ["lengths in [28.99, 29.01], [13.66, 13.66], [40.53, 40.53]"], ["6 unique postures", "complete: proved"]),
    "fk-clusters": (None, _clusters, ["every assembly mode"], ["0 unique postures", "1 unresolved clusters"]),
    "fk-tracked": (EX2, lambda: forward_kinematics(load_robot(EX2), "28.99,13.66,40.53", track=(21.88, -10.2, 1.803)),
                   ["domain: the box [[", "(floats)"], ["1 unique postures in the domain"]),   # (the box it covers)
    "fk-all": (EX2, lambda: forward_kinematics(load_robot(EX2), "28.99,13.66,40.53"), ["domain: all-postures"], []),
    "trajectory": (MEL, lambda: verify_trajectory(load_robot(MEL), "-69,-50,500,85deg,10deg,0", "84,92,500,85deg,10deg,0"),
                   ["-69,-50,500,85deg,10deg,0 -> 84,92,500,85deg,10deg,0", "constraints: interference, leg-length"],
                   ["1 path infeasible", "interference (legs 1, 2) fails for s in [0.548"]),
    "plan": (MEL, lambda: plan(load_robot(MEL), "-90,140,520,0,0,0", "55,140,520,0,0,0"),
             ["path(s); first: -90,140,520,0,0,0 -> "], ["paths feasible", "path 1: feasible"]),
    "section": (MICRO, lambda: workspace_section(load_robot(MICRO), "0,0,0", "20005"),
                ["orientation psi = 0, theta = 0, phi = 0, 1 section(s)"], ["section z = 20005: area in [1"]),
    "volume": (MICRO, lambda: workspace_volume(load_robot(MICRO), "0,0,0", "20000:20010", slabs=2),
               ["z in ['20000', '20010']"], ["2 slabs covering z in [20000, 20010]: volume in ["]),
}


@pytest.fixture(scope="module")
def certificates(tmp_path_factory):
    out = tmp_path_factory.mktemp("account")
    paths = {}
    for name, (_, solve, _, _) in KINDS.items():
        result = solve()
        doc = singularity_certificate(result) if isinstance(result, list) else result.certificate()
        paths[name] = out / f"{name}.cert"
        doc.write(paths[name])
    return paths


@pytest.mark.parametrize("kind", list(KINDS))
def test_check_prints_robot_question_verdicts(certificates, kind, capsys):
    robot, _, question, verdicts = KINDS[kind]
    assert proofs.run(certificates[kind], robot=robot, progress=True) == 0
    out, err = capsys.readouterr()
    lines = out.splitlines()
    name = load_robot(robot).name if robot else "<robot>"
    assert lines[0].startswith(f"robot: {name}") and "geometry SHA-256 " in lines[0]
    digest = lines[0].rsplit(" ", 1)[1]
    assert len(digest) == 64 and digest == proofs.geometry_sha256(proofs.load(certificates[kind]).header["robot"])
    assert (lines[1] == f"robot file: {robot}: same geometry") if robot else lines[1].startswith("question: ")
    question_line = next(line for line in lines if line.startswith("question: "))
    proved = "\n".join(line for line in lines if line.startswith("proved: "))
    assert all(q in question_line for q in question), question_line
    assert all(v in proved for v in verdicts), proved
    assert lines[-1].startswith("OK: ")
    assert err.endswith("[" + "#" * 40 + "] checked" + " " * 20 + "\n")      # the bar, on stderr
    assert proofs.run(certificates[kind], as_json=True) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["ok"] and doc["geometry_sha256"] == digest and doc["question"] == question_line[len("question: "):]
    assert doc["proved"] == [line[len("proved: "):] for line in lines if line.startswith("proved: ")]
    other = MEL if robot != MEL else EX2
    assert proofs.run(certificates[kind], robot=other) == 1
    assert "REJECTED: robot: the certificate's geometry is not that of" in capsys.readouterr().out


def test_a_question_names_the_box_where_requested_leaves_a_variable_out():
    """``requested`` is optional per variable: a certificate whose requested box names x only was shown as the
    question "x in [-20, -10]", which reads as "every y and phi"; the other variables now come from the box."""
    from certfile import Doc
    doc = Doc(certify_singularity_free(load_robot(EX2), "x=-20:-10,y=20:30,phi=0:0.3").certificate())
    doc.claim()["requested"] = {"x": ["-20", "-10"]}
    report = doc.check()
    assert report.ok, report.step
    question = report.about["question"]
    assert "x in [-20, -10]" in question and "y in [" in question and "phi in [" in question


def test_a_path_s_failing_ranges_are_listed_up_to_a_count_then_counted(monkeypatch):
    """A trajectory cut by its time at the floats' resolution has thousands of ranges: the account printed
    them all on one line (700 KB).  At most ``SHOWN`` are listed, the others counted."""
    import proofs.trajectory
    r = verify_trajectory(load_robot(MEL), "-69,-50,500,85deg,10deg,0", "84,92,500,85deg,10deg,0")
    assert len(r.violations) == 2
    monkeypatch.setattr(proofs.trajectory, "SHOWN", 1)
    report = proofs.check(r.certificate())
    assert report.ok
    [line] = [ln for ln in report.lines() if ln.startswith("proved: path 1:")]
    assert line.count(" for s in [") == 1 and line.endswith("; and 1 more range")
