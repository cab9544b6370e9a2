"""``certkin trajectory`` on hostile input (issue #18)."""
import json

import pytest

from conftest import MEL, R2, answered, limited, refused

A, B = "-69,-50,500,85deg,10deg,0", "84,92,500,85deg,10deg,0"
T = ["trajectory", MEL, "--from", A, "--to", B]

HOSTILE = [
    (T + ["--max-boxes", "0"], ["--max-boxes"]),
    (T + ["--max-boxes", "-1"], ["--max-boxes"]),
    (T + ["--max-seconds", "0"], ["--max-seconds"]),
    (T + ["--max-seconds", "-1"], ["--max-seconds"]),
    (T + ["--max-seconds", "nan"], ["--max-seconds"]),
    (T + ["--min-width", "0"], ["--min-width"]),
    (T + ["--min-width", "-1"], ["--min-width"]),
    (T + ["--min-width", "nan"], ["--min-width"]),
    (T + ["--max-memory", "-1GiB"], ["--max-memory"]),
    (["trajectory", MEL, "--from", "-69,-50,1e300,85deg,10deg,0", "--to", B], ["--from", "z", "out of range"]),
    (["trajectory", MEL, "--from", "-69,-50,500,85deg,10deg", "--to", B], ["--from", "6"]),
    (["trajectory", MEL, "--from", "-69,-50,nan,85deg,10deg,0", "--to", B], ["--from", "z", "not a finite number"]),
    (["trajectory", MEL, "--from", "0x10,-50,500,85deg,10deg,0", "--to", B],     # once: "not a finite number"
     ["--from", "x: not a plain decimal number: '0x10'"]),
    (["trajectory", MEL, "--from", "1/3,-50,500,85deg,10deg,0", "--to", B], ["--from", "x: not a plain decimal number"]),
    (["trajectory", MEL, "--from", "-69,-50,500,85rad,10deg,0", "--to", B], ["--from", "psi"]),
    (["trajectory", MEL, "--from", A, "--to", "84,92,500,1e13,10deg,0"], ["--to", "psi"]),
    (["trajectory", MEL, "--from", A], ["--to"]),
    (T + ["--from", A], ["--from", "twice"]),
    (T + ["--via", "1,2,3"], ["--via[0]"]),
    (T + ["--via", A, "--via", "x"], ["--via[1]"]),
    (T + ["--constraints", ""], ["--constraints", "empty"]),
    (T + ["--constraints", "leg-length,,interference"], ["--constraints"]),
    (T + ["--constraints", "leg-length,leg-length"], ["--constraints", "twice"]),
    (T + ["--constraints", "legs"], ["--constraints", "legs"]),
    (T + ["--constraints", "joints"], ["--constraints", "no constraint"]),
    (T + ["--certificate", "{tmp}"], ["--certificate", "directory"]),
    (T + ["--certificate", "{tmp}/no/c.json"], ["--certificate", "does not exist"]),
    (T + ["--report", "{tmp}/r.pdf"], ["--report", ".pdf"]),
    (T + ["--report", "/proc/r.html"], ["--report", "cannot write"]),
    (["trajectory", R2, "--from", "0,0,0", "--to", "1,1,0", "--constraints", "leg-length"], ["--constraints",
                                                                                              "no constraint"]),
]


@pytest.mark.parametrize("argv, words", HOSTILE, ids=[" ".join(a[2:])[-60:] for a, _ in HOSTILE])
def test_hostile_input_is_refused(cli, argv, words):
    refused(cli(*argv), *words)


def test_negative_values_and_outputs(cli):
    run = cli(*T, "--certificate", "{tmp}/t.json", "--report", "{tmp}/t.html", "--json")
    answered(run)
    assert json.loads(run.out)["status"] == "infeasible" and run.left == ["t.html", "t.json"]


def test_printed_violations_enclose_the_proved_ones(cli):
    """Forbidden t-ranges are enclosures: the printed interval contains the one in the JSON."""
    doc = json.loads(cli(*T, "--constraints", "interference", "--json").out)
    text = cli(*T, "--constraints", "interference").out
    for v in doc["violations"]:
        line = next(l for l in text.splitlines() if f" {'-'.join(map(str, v['legs']))} (proved), failing instants "
                    f"within t in" in l)
        lo, hi = (float(x) for x in line.split("t in [")[1].rstrip("]").split(", "))
        assert lo <= v["t"][0] and v["t"][1] <= hi


def test_ranges_past_a_count_are_counted_not_listed(cli, monkeypatch):
    """A search cut at the floats' resolution left about 6000 'may fail' lines on the terminal: each kind
    of range (violated, may fail, undecided) is listed up to ``SHOWN``, the others counted (all in --json)."""
    import certkin.cli.trajectory
    doc = json.loads(cli(*T, "--constraints", "interference", "--json").out)
    violated = [v for v in doc["violations"] if v["certain"]]
    assert len(violated) == 2
    monkeypatch.setattr(certkin.cli.trajectory, "SHOWN", 1)
    lines = cli(*T, "--constraints", "interference").out.splitlines()
    assert sum(ln.startswith("  VIOLATED: ") for ln in lines) == 1
    assert "  ... 1 more VIOLATED ranges (all of them in --json)" in lines


def test_an_absurd_height_ends_within_the_time_budget(cli):
    """A pose 1e11 mm away (issue #18: 1e300 ran 15 s under --max-seconds 5, then crashed)."""
    run = cli("trajectory", MEL, "--from", "-69,-50,1e11,85deg,10deg,0", "--to", B, "--max-seconds", "2")
    answered(run)
    assert run.seconds < 2 + 4


def test_the_absurd_pose_of_the_issue_under_a_memory_limit(tmp_path):
    run = limited(["trajectory", MEL, "--from", "-69,-50,1e300,85deg,10deg,0", "--to", B, "--max-seconds", "5"], tmp_path)
    refused(run, "--from")


def test_a_polylines_violations_are_placed_by_s_and_name_their_detail(cli):
    """On a polyline, a violation on segment 2 was printed "t in [0.549, 1]" (the segment's own t, no
    segment named); it is placed by s = segment + t, as the undecided ranges are."""
    run = cli("trajectory", MEL, "--from", "0,0,500,0,0,0", "--via", "-69,-50,500,85deg,10deg,0",
              "--via", "-69,-50,500,85deg,10deg,0", "--to", "84,92,500,85deg,10deg,0")
    answered(run)
    doc = json.loads(cli("trajectory", MEL, "--from", "0,0,500,0,0,0", "--via", "-69,-50,500,85deg,10deg,0",
                         "--via", "-69,-50,500,85deg,10deg,0", "--to", "84,92,500,85deg,10deg,0", "--json").out)
    late = [v for v in doc["violations"] if v["segment"] == 2]
    assert late and all(v["s"][0] >= 2 for v in late)
    assert " t in [" not in run.out and "failing instants within s in [2.5" in run.out
    assert "(s = k + t: instant t ∈ [0, 1] of segment k, k = 0 to 2)" in run.out


def test_a_single_segments_undecided_instants_are_placed_by_t_as_its_violations(cli):
    """One segment: violations and undecided ranges both name t (undecided ones said "s", unexplained)."""
    run = cli("trajectory", MEL, "--from", "-69,-50,500,0,10deg,0", "--to", "84,92,500,10000,10deg,0",
              "--max-boxes", "50")
    answered(run)
    assert "undecided for t in [" in run.out and " s in [" not in run.out and "s = k + t" not in run.out


def _waypoints(n):
    import random
    rng = random.Random(2)
    return [f"{rng.randint(-60, 80)},{rng.randint(-40, 90)},500,85deg,10deg,0" for _ in range(n)]


def test_many_waypoints_stay_within_the_time_budget():
    """2000 waypoints (constant orientation) with max_seconds=4 took 5.5 s: seeding the margins' targets
    used the whole budget, then the search's first batch came on top; 20 000 waypoints with
    max_seconds=1 took 19 s (their polynomials are built before the search, no clock stops them).
    The first are answered within the budget, the second refused at once, naming max_seconds."""
    import time
    import certkin
    robot = certkin.load_robot(MEL)
    certkin.verify_trajectory(robot, A, B, max_boxes=100)                         # (models built: not timed)
    c0 = time.process_time()
    r = certkin.verify_trajectory(robot, A, B, waypoints=_waypoints(2000), max_seconds=4)
    spent = time.process_time() - c0       # (CPU: on a loaded machine the work the clock cannot stop takes longer)
    assert spent < 4 * 1.25, (spent, r.stats)                                     # (was 5.5 s)
    many = _waypoints(20000)
    c0 = time.process_time()
    with pytest.raises(certkin.InputError, match="^max_seconds: 20001 segments take about .* s to prepare"):
        certkin.verify_trajectory(robot, A, B, waypoints=many, max_seconds=1)
    assert time.process_time() - c0 < 10           # (reading the 20 000 poses: about 4 s of CPU)
