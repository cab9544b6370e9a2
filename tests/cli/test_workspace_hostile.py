"""``certkin workspace`` on hostile input (issue #18)."""
import pytest

from conftest import MICRO, R2, answered, refused

W = ["workspace", MICRO]
Z = W + ["--z", "20005"]

HOSTILE = [
    (Z + ["--max-boxes", "0"], ["--max-boxes"]),
    (Z + ["--max-seconds", "0"], ["--max-seconds"]),
    (Z + ["--max-seconds", "nan"], ["--max-seconds"]),
    (Z + ["--min-width", "-1"], ["--min-width"]),
    (Z + ["--max-memory", "x"], ["--max-memory"]),
    (Z + ["--z-range", "1:2"], ["--z-range", "not both"]),
    (Z + ["--slabs", "10"], ["--slabs", "--z-range"]),
    (W + ["--z-range", "20000:20010", "--slabs", "0"], ["--slabs"]),
    (W + ["--z-range", "20000:20010", "--slabs", "100000"], ["--slabs"]),
    (W + ["--z-range", "20000:20010", "--slabs", "ten"], ["--slabs"]),
    (W + ["--z-range", "20010:20000"], ["--z-range"]),
    (W + ["--z-range", "-1e300:0"], ["--z-range", "out of range"]),
    (W + ["--z", "1e300"], ["--z", "out of range"]),
    (W + ["--z", "nan"], ["--z"]),
    (W, ["--z"]),
    (Z + ["--orientation", "0,0"], ["--orientation"]),
    (Z + ["--orientation", "0,1e13,0"], ["--orientation", "theta"]),
    (Z + ["--z", "1"], ["--z", "twice"]),
    (["workspace", R2, "--z", "1"], ["limits.leg_length"]),          # no leg-length limits in this file
    (Z + ["--plot", "{tmp}/w.xyz"], ["--plot", ".xyz"]),
    (Z + ["--plot", "{tmp}"], ["--plot", "directory"]),
    (Z + ["--report", "{tmp}/w.txt"], ["--report"]),
    (Z + ["--certificate", "{tmp}/no/w.json"], ["--certificate"]),
]


@pytest.mark.parametrize("argv, words", HOSTILE, ids=[" ".join(a[2:])[:60] for a, _ in HOSTILE])
def test_hostile_input_is_refused(cli, argv, words):
    refused(cli(*argv), *words)


def test_negative_values_are_values(cli):
    """``--orientation -30deg,0,0`` and ``--z-range -20010:-20000`` once failed with 'expected one argument'."""
    answered(cli(*Z, "--orientation", "-30deg,0,0", "--min-width", "0.05"), "section z = 20005")
    answered(cli(*W, "--z-range", "-20010:-20000", "--slabs", "20", "--min-width", "0.05"), "volume in [")


def test_report_and_plot(cli):
    pytest.importorskip("matplotlib")
    run = cli(*Z, "--min-width", "0.02", "--report", "{tmp}/w.html", "--plot", "{tmp}/w.png")
    answered(run, "exact area in [")
    assert run.left == ["w.html", "w.png"]


def test_many_slabs_stay_within_the_time_budget(cli):
    run = cli(*W, "--z-range", "20000:20010", "--slabs", "10000", "--max-seconds", "1")
    answered(run)
    assert run.seconds < 1 + 6


def test_a_fine_paving_stays_under_the_memory_ceiling(tmp_path):
    from conftest import limited
    run = limited(Z + ["--min-width", "1e-12", "--max-boxes", "1e9", "--max-seconds", "3"], tmp_path)
    answered(run, "paving: area in [")


def test_a_paving_stopped_by_its_budget_says_so(cli):
    """A box budget that runs out leaves a true but coarse bracket: the text says the budget stopped
    it (the JSON's ``stats.exhausted``), and a paving that reached --min-width does not."""
    answered(cli(*Z, "--max-boxes", "200"), "budget exhausted before --min-width")
    answered(cli(*W, "--z-range", "20000:20010", "--slabs", "4", "--max-boxes", "200"), "budget exhausted before --min-width")
    run = cli(*Z, "--min-width", "0.05")
    answered(run, "paving: area in [")
    assert "budget exhausted" not in run.out


def test_the_report_says_when_a_budget_stopped_the_paving(tmp_path):
    from certkin import load_robot
    from certkin.report.workspace import workspace_verdict
    from certkin.workspace import workspace_section
    robot = load_robot(MICRO)
    cut = workspace_section(robot, "0,0,0", "20005", max_boxes=200)
    assert workspace_verdict(cut).endswith("(certified bracket; a budget or Ctrl-C stopped the paving before its resolution).")
    assert "budget" not in workspace_verdict(workspace_section(robot, "0,0,0", "20005", min_width=0.05))


def test_a_large_box_budget_leaves_the_volume_search_its_time():
    """With 10 000 slabs and max_boxes=1e9 the first search (which only sets the resolution) ran until
    the time budget was out, leaving the answer's search one batch: undecided, volume in [0, 3816],
    where the default box budget gives a bracket [11.4, 3601]."""
    from certkin.workspace import workspace_volume
    v = workspace_volume(MICRO, "0,0,0", "20000:20010", slabs=10000, max_boxes=10 ** 9, max_seconds=3)
    assert v.status == "non-empty" and v.to_json()["volume"]["inner"] > 5, v.to_json()["volume"]
