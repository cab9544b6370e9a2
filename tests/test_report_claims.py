"""What a report, the terminal and ``--json`` say an answer covers is what was checked: an FK answer
over ``--domain`` or ``--track`` does not say every posture is listed, and a trajectory or plan
checked for some constraint families does not say every family was checked."""
from __future__ import annotations

import json
from pathlib import Path

import proofs
from certkin import load_robot, robot_from_dict, verify_trajectory
from certkin.cli import main

ROBOTS = Path(__file__).resolve().parent.parent / "examples" / "robots"
PLANAR = str(ROBOTS / "seed003-planar-example-2.toml")
MEL = str(ROBOTS / "seed000-mel-tsukuba.toml")
LENGTHS = "28.99,13.66,40.53"        # seed 003, example 2: six assembly modes (Constantinescu 2004, Tab. 3.9)
START, GOAL = "-69,-50,500,85deg,10deg,0", "84,92,500,85deg,10deg,0"


def _run(capsys, *argv) -> str:
    assert main(list(argv)) == 0
    return capsys.readouterr().out


def test_fk_over_a_domain_says_which_domain(tmp_path, capsys):
    full = json.loads(_run(capsys, "fk", PLANAR, "--lengths", LENGTHS, "--json"))
    report, cert = tmp_path / "d.html", tmp_path / "d.cert"
    doc = json.loads(_run(capsys, "fk", PLANAR, "--lengths", LENGTHS, "--domain", "x=20:40", "--json",
                          "--report", str(report), "--certificate", str(cert)))
    assert len(full["solutions"]) == 6 and full["complete"] and "domain" not in full
    assert doc["complete"] and doc["domain"] == "x=20:40"
    outside = [s for s in full["solutions"] if not 20 <= s["pose"]["x"][0] <= 40]
    assert outside and len(doc["solutions"]) == 6 - len(outside)          # the modes left out exist
    page = report.read_text()
    assert "every real posture for these lengths is listed" not in page
    assert "x=20:40" in page and "outside it are not listed" in page
    assert "complete in the domain x=20:40" in _run(capsys, "fk", PLANAR, "--lengths", LENGTHS, "--domain", "x=20:40")
    assert proofs.check(str(cert)).ok


def test_fk_tracked_says_the_other_modes_were_not_searched(tmp_path, capsys):
    report = tmp_path / "t.html"
    doc = json.loads(_run(capsys, "fk", PLANAR, "--lengths", LENGTHS, "--track", "13.3,-17,1.13", "--json",
                          "--report", str(report)))
    assert doc["tracked"] and len(doc["solutions"]) == 1
    page = report.read_text()
    assert "every real posture for these lengths is listed" not in page and "were not searched" in page


def test_constraints_left_out_are_named(tmp_path, capsys):
    robot = load_robot(MEL)
    assert "leg_radius" in robot.limits          # the file allows the interference check
    report = tmp_path / "t.html"
    doc = json.loads(_run(capsys, "trajectory", MEL, "--from", START, "--to", GOAL, "--constraints", "leg-length",
                          "--json", "--report", str(report)))
    assert doc["constraints"] == ["leg-length"] and doc["not_asked"] == ["interference", "singularity"]
    page = report.read_text()
    assert "every constraint family was checked" not in page and "not asked: --constraints" in page
    terminal = _run(capsys, "trajectory", MEL, "--from", START, "--to", GOAL, "--constraints", "leg-length")
    assert "not checked: interference (not asked: --constraints)" in terminal
    whole = verify_trajectory(robot, START, GOAL)        # all of them: the interference family is not met
    assert whole.status != "feasible" and whole.to_json()["not_asked"] == []


def test_a_plan_checked_for_some_constraints_says_so(tmp_path, capsys):
    report = tmp_path / "p.html"
    doc = json.loads(_run(capsys, "plan", MEL, "--from", START, "--to", GOAL, "--constraints", "leg-length",
                          "--json", "--report", str(report)))
    assert doc["status"] == "found" and doc["constraints"] == ["leg-length"]
    assert doc["not_asked"] == ["interference", "singularity"]
    page = report.read_text()
    assert "all the constraints the robot file allows" not in page and "every constraint family was checked" not in page
    assert "not all the robot file allows" in page


def test_joints_checked_on_one_side_only_are_named():
    mel = load_robot(MEL)
    data = {"kind": "gough-stewart", "base": [list(p) for p in mel.base], "platform": [list(p) for p in mel.platform],
            "limits": {"base_joints": [{"axis": ["0", "0", "1"], "half_angle": "80deg"}] * 6}}
    doc = verify_trajectory(robot_from_dict(data), "0,0,500,0,0,0", "1,0,500,0,0,0", constraints="joints").to_json()
    assert doc["constraints"] == ["joints"]
    assert doc["partly_checked"] == {"joints": "the platform joints: no [limits] platform_joints in the robot file"}


PLANAR1 = str(ROBOTS / "seed003-planar-example-1.toml")


def test_around_report_states_the_pose_and_scale(tmp_path, capsys):
    report = tmp_path / "a.html"
    doc = json.loads(_run(capsys, "singular", PLANAR, "--around", "10,10,22.5deg", "--scale", "1,1,0.1", "--json",
                          "--report", str(report)))
    assert doc["around"] == {"pose": ["10", "10", "22.5deg"], "scale": [1.0, 1.0, 0.1]}
    assert doc["status"] == "singularity-free" and doc["scale_factor"] > 0
    assert "x=10, y=10, phi=22.5deg" in report.read_text() and "scale 1, 1, 0.1" in report.read_text()


def test_around_a_pose_not_proved_regular_does_not_blame_the_budget(tmp_path, capsys):
    """Seed 003 example 1 at phi = 0 with x = y = 0: the platform's joints lie on the base's (a
    simplified robot, similar triangles), det(A) = 0 there (the seed's singular configuration)."""
    report = tmp_path / "a.html"
    doc = json.loads(_run(capsys, "singular", PLANAR1, "--around", "0,0,0", "--json", "--report", str(report)))
    assert doc["status"] == "undecided" and doc["scale_factor"] == 0.0 and doc["stats"]["boxes"] <= 10
    page = report.read_text()
    assert "budget ran out" not in page and "not proved non-zero at the pose itself" in page


def test_singular_report_lists_the_undecided_boxes(tmp_path, capsys):
    report = tmp_path / "u.html"
    doc = json.loads(_run(capsys, "singular", PLANAR1, "--box", "x=0,y=0,phi=0.1:0.3", "--max-boxes", "2000", "--json",
                          "--report", str(report)))
    assert doc["status"] == "undecided" and doc["undecided_count"] > 0
    assert "undecided box 1" in report.read_text()


def test_a_cells_report_counts_the_boxes_decided_within_the_budget(tmp_path, capsys):
    """The boxes of every cell's part of the search tree (794, bisected boxes never decided included) were
    shown as the boxes decided, beside a budget of 300."""
    report = tmp_path / "c.html"
    _run(capsys, "singular", PLANAR, "--box", "x=-50:50,y=-50:50,phi=0:0.7853981634", "--cells", "4",
         "--max-boxes", "300", "--report", str(report))
    page = report.read_text()
    assert "<td>boxes decided</td><td>300</td>" in page and "<td>budget: boxes</td><td>300</td>" in page


def test_trajectory_report_lists_the_undecided_instants(tmp_path, capsys):
    report = tmp_path / "t.html"
    doc = json.loads(_run(capsys, "trajectory", MEL, "--from", START, "--to", GOAL, "--max-boxes", "40", "--json",
                          "--report", str(report)))
    assert doc["undecided"]             # (instants where a crossing is not resolved, beside proved violations)
    page = report.read_text()
    assert "Undecided instants" in page and f"{doc['undecided'][0]['s'][0]:.9f}"[:10] in page


def test_workspace_report_of_a_robot_with_unused_limits_says_only_the_outer_bound_holds(tmp_path, capsys):
    assert "leg_radius" in load_robot(MEL).limits     # interference: not a constraint of the workspace
    report = tmp_path / "w.html"
    doc = json.loads(_run(capsys, "workspace", MEL, "--orientation", "0,0,0", "--z", "600", "--min-width", "0.05",
                          "--json", "--report", str(report)))
    assert doc["ignored_limits"] == ["leg_radius"]
    page = report.read_text()
    assert "only the outer bound holds" in page and "superset of the robot's workspace" in page


def test_the_recheck_command_works_from_the_report_directory(tmp_path, capsys, monkeypatch):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    _run(capsys, "fk", PLANAR, "--lengths", LENGTHS, "--report", str(tmp_path / "a" / "r.html"),
         "--certificate", str(tmp_path / "b" / "r.cert"))
    page = (tmp_path / "a" / "r.html").read_text()
    assert "<code>certkin check ../b/r.cert</code>" in page
    monkeypatch.chdir(tmp_path / "a")
    assert main(["check", "../b/r.cert"]) == 0


def test_the_recheck_command_of_a_path_starting_with_a_dash_is_not_read_as_an_option(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    _run(capsys, "fk", PLANAR, "--lengths", LENGTHS, "--report", "r.html", "--certificate=-r.cert")
    assert "<code>certkin check ./-r.cert</code>" in Path("r.html").read_text()
    assert main(["check", "./-r.cert"]) == 0
    jobs = tmp_path / "jobs.jsonl"
    jobs.write_text(json.dumps({"id": "a", "command": "fk", "robot": PLANAR, "lengths": LENGTHS}) + "\n")
    (tmp_path / "reports").mkdir()
    _run(capsys, "batch", str(jobs), "--out=-res", "--workers", "1", "--report", "reports/b.html")
    page = (tmp_path / "reports" / "b.html").read_text()
    assert "From the directory of this report, re-check one with <code>certkin check ../-res/&lt;id&gt;.cert" in page
    assert "<code>for f in ../-res/*.cert; do" in page
    monkeypatch.chdir(tmp_path / "reports")
    assert main(["check", "../-res/a.cert"]) == 0


def test_plan_takes_a_constraints_object_as_verify_trajectories_does():
    from certkin import plan
    from certkin.trajectory.constraints import Constraints
    robot = load_robot(MEL)
    r = plan(robot, "-90,140,520,0,0,0", "-90,140,520,0,0,0", constraints=Constraints.of(robot, "leg-length"))
    assert r.to_json()["constraints"] == ["leg-length"]


def test_a_free_box_is_asked_about_in_the_decimals_given_never_a_wider_box(tmp_path, capsys):
    """The question of a singularity-free verdict names the box given, exactly; cells all proved free
    are shown on their hull rounded inward (never outward: the verdict says free "on the whole box")."""
    box = "x=-20.00000000001:-10.00000000001,y=20:30,phi=0.1234567890123:0.3234567890123"
    one, cells = tmp_path / "one.html", tmp_path / "cells.html"
    _run(capsys, "singular", PLANAR, "--box", box, "--report", str(one))
    _run(capsys, "singular", PLANAR, "--box", box, "--cells", "2", "--report", str(cells))
    page = one.read_text()
    assert "Singularity-free" in page
    assert "x ∈ [-20.00000000001, -10.00000000001], y ∈ [20, 30], phi ∈ [0.1234567890123, 0.3234567890123]?" in page
    page = cells.read_text()
    assert "8 singularity-free" in page
    assert "x ∈ [-20, -10.00000001], y ∈ [20, 30], phi ∈ [0.1234567891, 0.323456789], cut into 8 cells" in page


def test_a_trajectory_report_calls_a_via_polyline_a_polyline(tmp_path, capsys):
    """A motion through --via poses was called "the straight-line motion"."""
    straight, polyline = tmp_path / "s.html", tmp_path / "p.html"
    _run(capsys, "trajectory", MEL, "--from", START, "--to", GOAL, "--report", str(straight))
    _run(capsys, "trajectory", MEL, "--from", START, "--via", "0,0,500,85deg,10deg,0", "--to", GOAL,
         "--report", str(polyline))
    assert "Is the straight-line motion" in straight.read_text()
    page = polyline.read_text()
    assert "straight-line motion" not in page and "Is the polyline motion of 2 straight segments" in page
