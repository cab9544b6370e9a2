"""``certkin plan`` on hostile input (issue #18)."""
import json
from pathlib import Path

import pytest

from conftest import MEL, answered, refused

S, G = "-90,140,520,0,0,0", "55,140,520,0,0,0"
P = ["plan", MEL, "--from", S, "--to", G]

HOSTILE = [
    (P + ["--divisions", "0"], ["--divisions"]),
    (P + ["--divisions", "-3"], ["--divisions"]),
    (P + ["--divisions", "2.5"], ["--divisions"]),
    (P + ["--divisions", "1001"], ["--divisions"]),
    (P + ["--margin", "-1"], ["--margin"]),
    (P + ["--margin", "1001"], ["--margin"]),
    (P + ["--margin", "nan"], ["--margin"]),
    (P + ["--margin", "2.5"], ["--margin"]),
    (P + ["--max-edges", "1e300"], ["--max-edges", "'1e300'"]),
    (P + ["--via", "1,2,3,4,5,6"], ["--via"]),
    (P + ["--max-edges", "0"], ["--max-edges"]),
    (P + ["--max-boxes", "0"], ["--max-boxes"]),
    (P + ["--max-seconds", "-1"], ["--max-seconds"]),
    (P + ["--max-seconds", "nan"], ["--max-seconds"]),
    (P + ["--min-width", "0"], ["--min-width"]),
    (P + ["--max-memory", "0"], ["--max-memory"]),
    (["plan", MEL, "--from", "-90,140,1e300,0,0,0", "--to", G], ["--from", "z"]),
    (["plan", MEL, "--from", S, "--to", "55,140"], ["--to"]),
    (P + ["--constraints", ""], ["--constraints"]),
    (P + ["--constraints", "legs"], ["--constraints"]),
    (P + ["--to", G], ["--to", "twice"]),
    (P + ["--certificate", "{tmp}"], ["--certificate", "directory"]),
    (P + ["--report", "{tmp}/p.txt"], ["--report"]),
    (P + ["--report", "{tmp}/no/p.html"], ["--report", "does not exist"]),
]


@pytest.mark.parametrize("argv, words", HOSTILE, ids=[" ".join(a[6:])[:60] for a, _ in HOSTILE])
def test_hostile_input_is_refused(cli, argv, words):
    refused(cli(*argv), *words)


def test_plan_reports_progress_and_prints_exact_waypoints(cli):
    run = cli(*P, "--progress", "--report", "{tmp}/p.html", "--certificate", "{tmp}/p.json", "--json")
    answered(run)
    doc = json.loads(run.out)
    assert doc["status"] == "found" and "segments verified" in run.err
    assert run.left == ["p.html", "p.json"]
    for w in doc["waypoints"][1:-1]:
        for v in w.values():
            digits = v.replace("-", "").replace(".", "").lstrip("0")
            assert len(digits) <= 12 and "e" not in v


def test_no_path_writes_no_certificate_and_says_so(cli):
    run = cli("plan", MEL, "--from", S, "--to", "84,92,500,85deg,10deg,0", "--certificate", "{tmp}/p.json")
    answered(run, "infeasible-endpoint")
    assert "no certificate written" in run.err and run.left == []


def test_max_seconds_bounds_the_whole_plan(cli):
    run = cli(*P, "--divisions", "200", "--max-seconds", "2")
    answered(run)
    assert run.seconds < 2 + 4


def test_the_largest_grid_stays_under_the_memory_ceiling(tmp_path):
    from conftest import limited
    run = limited(P + ["--divisions", "1000", "--margin", "1000", "--max-edges", "1e9", "--max-seconds", "3"], tmp_path)
    answered(run)


def test_a_report_never_cites_a_certificate_left_by_an_earlier_run(cli, tmp_path):
    """No path found: no certificate is written, and the report says so, even when a file of that name
    (an earlier run's certificate) is there: it cited that file's size and SHA-256 as its own."""
    stale = tmp_path / "np.cert"
    stale.write_bytes(b"an earlier run's certificate")
    seed001 = str(Path(__file__).resolve().parents[2] / "examples" / "robots" / "seed001-3rpr-planning.toml")
    run = cli("plan", seed001, "--from", "20,0,3.0", "--to", "60,-50,6.0", "--max-seconds", "1",
              "--report", "{tmp}/np.html", "--certificate", str(stale))
    answered(run, "no-path-found")
    page = (tmp_path / "np.html").read_text()
    assert "No certificate was written for this report" in page and "np.cert" not in page
    assert "segments verified" in page and "edges_verified" not in page and "False" not in page


@pytest.mark.parametrize("n", [2, 3, 10])
def test_max_edges_is_a_maximum(cli, n):
    """--max-edges 2, 3, 5 or 10 each verified 27 segments (a whole expansion at once)."""
    run = cli(*P, "--max-edges", str(n), "--json")
    answered(run)
    assert json.loads(run.out)["stats"]["edges_verified"] == n


def test_an_infeasible_endpoint_report_names_the_constraints(cli, tmp_path):
    """The terminal named them; the report's verdict said only "the start pose is infeasible"."""
    run = cli("plan", MEL, "--from", "0,0,300,0,0,0", "--to", G, "--report", "{tmp}/ie.html")
    answered(run, "infeasible-endpoint")
    assert "No path: the start pose is infeasible (leg-length 1; " in (tmp_path / "ie.html").read_text()


@pytest.mark.parametrize("budget, stopped, words", [
    (["--max-seconds", "0.01"], "time", "the time budget ran out"),
    (["--max-edges", "3"], "max-edges", "the segment budget ran out"),
])
def test_no_path_found_says_which_budget_ended_the_search(cli, budget, stopped, words):
    """``no-path-found`` looked the same whether the grid was exhausted or a budget cut the search."""
    argv = ["plan", MEL, "--from", "-90,140,520,0,0,0", "--to", "55,140,520,0,0,0"] + budget
    run = cli(*argv)
    answered(run, "no-path-found", words)
    run = cli(*argv, "--json")
    assert json.loads(run.out)["stats"]["stopped"] == stopped


def test_end_poses_that_differ_a_little_in_a_position_get_a_note(cli):
    """z = 520.001 against 520: the grid's z step was 0.001 / 6, so it could not climb over the obstacle
    the path at z = 520 goes around, and the answer only said a larger budget "may find a path".  A
    note now names the coordinate; equal values (the usual case) get none."""
    run = cli("plan", MEL, "--from", "-90,140,520.001,0,0,0", "--to", G, "--max-edges", "300", "--json")
    doc = json.loads(run.out)
    assert doc["status"] == "no-path-found" and doc["stats"]["narrow"] == ["z"]
    run = cli("plan", MEL, "--from", "-90,140,520.001,0,0,0", "--to", G, "--max-edges", "300")
    answered(run, "no-path-found", "differ only a little in z")
    run = cli(*P, "--json")
    doc = json.loads(run.out)
    assert doc["status"] == "found" and "narrow" not in doc["stats"]
