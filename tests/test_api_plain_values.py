"""The public API takes plain values (issue #18): every function of ``certkin.__all__`` takes a robot
or a robot file's path, plain poses and lengths, the budget keywords, and refuses a bad value with
an ``InputError`` naming the parameter; results print as one short line and ``to_json()`` is a dict."""
import json
from pathlib import Path

import numpy as np
import pytest

import certkin
import proofs

ROBOTS = Path(__file__).resolve().parents[1] / "examples" / "robots"
R2 = str(ROBOTS / "seed003-planar-example-2.toml")
MEL = str(ROBOTS / "seed000-mel-tsukuba.toml")
L = "28.99,13.66,40.53"


def test_every_public_function_takes_a_path_and_budget_keywords():
    calls = {
        "certify_singularity_free": lambda **b: certkin.certify_singularity_free(R2, "x=-20:-10,y=20:30,phi=0:0.3", **b),
        "forward_kinematics": lambda **b: certkin.forward_kinematics(R2, L, **b),
        "track_sequence": lambda **b: certkin.track_sequence(R2, [L, "29,13.66,40.53"], (30, 13, -1.9), **b),
        "verify_trajectory": lambda **b: certkin.verify_trajectory(MEL, "-69,-50,500,0,0,0", (0, 0, 500, 0, 0, 0),
                                                                   constraints="leg-length", **b),
        "verify_trajectories": lambda **b: certkin.verify_trajectories(
            MEL, np.array([[[-69, -50, 500, 0, 0, 0], [0, 0, 500, 0, 0, 0]]]), constraints="leg-length", **b),
        "plan": lambda **b: certkin.plan(MEL, "-90,140,520,0,0,0", "55,140,520,0,0,0", **b),
    }
    functions = {n for n in certkin.__all__ if callable(getattr(certkin, n)) and n[0].islower()}
    assert functions - {"load_robot", "robot_from_dict"} == set(calls)
    for name, call in calls.items():
        for keyword, bad in (("max_boxes", 0), ("max_seconds", float("nan")), ("min_width", -1),
                             ("max_memory", 0)):
            with pytest.raises(certkin.InputError, match=f"^{keyword}: "):
                call(**{keyword: bad})
        out = call(max_seconds=60, max_boxes=100_000, min_width=1e-9, max_memory=2 ** 30)
        for r in out if isinstance(out, list) else [out]:
            assert len(repr(r)) < 200 and "\n" not in repr(r), (name, repr(r)[:300])
            doc = r.to_json()
            assert isinstance(doc, dict) and json.loads(json.dumps(doc)) == doc
        with pytest.raises(certkin.InputError, match="^budget: "):
            call(budget={"max_boxes": 10})
        call(budget=certkin.Budget(max_boxes=100_000))


def test_text_rows_of_lengths_are_instances():
    """A list of "l1,l2,l3" texts is one instance per text (as the rows of a 2-D array)."""
    a = certkin.forward_kinematics(R2, [L, "29,13.66,40.53"])
    b = certkin.forward_kinematics(R2, [[28.99, 13.66, 40.53], ["29", "13.66", "40.53"]])
    assert [r.lengths for r in a] == [["28.99", "13.66", "40.53"], ["29", "13.66", "40.53"]]
    assert [len(r.solutions) for r in a] == [len(r.solutions) for r in b] == [6, 6]
    tracked = certkin.track_sequence(R2, [L, "29,13.66,40.53"], "30,13,-1.9")
    assert all(r.tracked for r in tracked)
    assert proofs.check(tracked[1].certificate()).ok


def test_errors_name_the_parameter():
    cases = [
        (lambda: certkin.forward_kinematics(R2, "1,2"), "lengths"),
        (lambda: certkin.track_sequence(R2, [L], "30,13"), "start_pose"),
        (lambda: certkin.verify_trajectories(MEL, [["-69,-50,500,0,0,0"]]), r"paths\[0\]"),
        (lambda: certkin.verify_trajectory(MEL, (-69, -50, 1e300, 0, 0, 0), "0,0,500,0,0,0"), "start"),
        (lambda: certkin.verify_trajectory(MEL, "-69,-50,500,0,0,0", "0,0,500,0,0,0", constraints="legs"),
         "constraints"),
        (lambda: certkin.plan(MEL, "-90,140,520,0,0,0", "55,140,520,0,0,0", divisions=0), "divisions"),
        (lambda: certkin.certify_singularity_free(3, "x=0:1,y=0:1,phi=0:1"), "robot"),
    ]
    for call, parameter in cases:
        with pytest.raises(certkin.InputError, match=f"^{parameter}"):
            call()
