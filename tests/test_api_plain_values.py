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
MICRO = str(ROBOTS / "seed004-micro-manipulator.toml")
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
    assert functions - {"load_robot", "robot_from_dict", "keep_freed_memory"} == set(calls)   # (no robot, no budget)
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


def test_floats_and_numpy_scalars_stand_for_their_repr_and_their_certificates_check():
    """A float (numpy's too) stands for its shortest repr, enclosed: the text recorded is the one
    searched (a float32 path printed "20.1" while the search used 20.100000381...; a box of 0.1 and
    np.float64 values gave certificates the checker rejected; np.float64 became 'np.float64(20.1)')."""
    import proofs
    from certkin import certify_singularity_free, load_robot, verify_trajectory
    examples = Path(__file__).resolve().parents[1] / "examples" / "robots"
    planar, planning = (load_robot(examples / f) for f in ("seed003-planar-example-2.toml", "seed001-3rpr-planning.toml"))
    r = verify_trajectory(planning, np.array([20.1, 0.1, 3.0], np.float32), np.array([60.3, -50.7, 3.0], np.float32))
    assert r.to_json()["path"][0] == {"x": repr(float(np.float32(20.1))), "y": repr(float(np.float32(0.1))), "phi": "3.0"}
    assert proofs.check(r.certificate()).ok
    r = verify_trajectory(planning, np.array([20.1, 0.1, 3.0]), np.array([60.3, -50.7, 3.0]))
    assert r.to_json()["path"][0] == {"x": "20.1", "y": "0.1", "phi": "3.0"} and proofs.check(r.certificate()).ok
    for box in ({"x": (-20, -10), "y": (20, 30), "phi": (0.1, 0.3)}, {"x": (np.float64(-20), -10), "y": (20, 30), "phi": 0.3}):
        r = certify_singularity_free(planar, box)
        assert r.status == "singularity-free" and proofs.check(r.certificate()).ok


def test_decimals_no_float_can_hold_are_refused_at_once():
    import time
    from certkin import forward_kinematics, robot_from_dict
    t0 = time.perf_counter()
    with pytest.raises(certkin.InputError, match="below 1e-400"):
        forward_kinematics(Path(__file__).resolve().parents[1] / "examples" / "robots" / "seed003-planar-example-2.toml",
                           "1e-999999999,1,1")
    robot = {"kind": "planar-3rpr", "base": [["1e-99999999", 4.34], [34.47, -3.78], [16.233, 34.76]],
             "platform": [[-4.83, -3.19], [12.04, -3.19], [8.23, 12.09]]}
    with pytest.raises(certkin.InputError, match="below 1e-400"):              # (it hung in the degeneracy check)
        robot_from_dict(robot)
    robot["base"][0][0] = 10 ** 5000                                    # (int to text: a ValueError)
    with pytest.raises(certkin.InputError, match="out of range"):
        robot_from_dict(robot)
    assert time.perf_counter() - t0 < 30


def test_a_budget_is_checked_when_made_and_fixed_afterwards():
    """Budget(max_seconds="5") was accepted (the docs refuse text), and b.max_boxes = -5 was then used."""
    import dataclasses
    for field in ("max_seconds", "min_width", "max_boxes", "max_memory"):
        with pytest.raises(certkin.InputError) as exc:
            certkin.Budget(**{field: "5"})
        assert exc.value.source == field
    for field in ("max_boxes", "max_memory"):          # (np.array([5]) raised "only 0-dimensional arrays ...")
        with pytest.raises(certkin.InputError, match=f"^{field}: expected a positive integer"):
            certkin.Budget(**{field: np.array([5])})
    assert certkin.Budget(max_boxes=np.int64(5), max_memory=np.array(2 ** 20)).max_boxes == 5
    b = certkin.Budget(max_boxes=10)
    with pytest.raises(dataclasses.FrozenInstanceError):
        b.max_boxes = -5
    assert dataclasses.replace(b, max_boxes=20).max_boxes == 20


def test_a_memory_budget_past_the_machine_is_refused_as_on_the_command_line():
    """max_memory=2**50 was taken by the API (the command line refused it): a search could then grow
    until the system killed the process instead of answering ``undecided``."""
    from certkin.engine.budgets import PHYSICAL
    if PHYSICAL is None:
        pytest.skip("this system does not say how much memory it has")
    with pytest.raises(certkin.InputError, match="^max_memory: .* more than this machine's memory"):
        certkin.forward_kinematics(R2, L, max_memory=PHYSICAL + 1)
    with pytest.raises(certkin.InputError, match="^max_memory: "):
        certkin.Budget(max_memory=2 ** 50)
    assert certkin.Budget().max_memory == min(2 ** 31, PHYSICAL)
    assert certkin.Budget(max_memory=PHYSICAL).max_memory == PHYSICAL


def test_an_incomplete_spatial_answer_describes_its_open_boxes_within_the_time_budget(monkeypatch):
    """Cut by its time budget, a spatial FK search then described up to 2000 unresolved regions (their
    poses and platform points), 0.3 to 0.5 s past max_seconds on a slow machine.  A share of the seconds
    is now kept for them, and with little time left they are fewer and larger; every open leaf of the
    search still lies in one of them."""
    import time
    import certkin.fk.api as api
    robot = certkin.load_robot(ROBOTS / "dietmaier-6-6-40.toml")
    lengths = "1,0.645275,1.086284,1.503439,1.281933,0.771071"
    certkin.forward_kinematics(robot, lengths, max_boxes=1000)             # (the kernels loaded first)
    t0 = time.perf_counter()
    r = certkin.forward_kinematics(robot, lengths, max_seconds=0.5)          # (the whole search: 2.5 s)
    assert not r.complete and r.message.startswith("the time budget ran out")
    assert time.perf_counter() - t0 < 0.75 and 16 <= len(r.unresolved) <= 2000
    monkeypatch.setattr(api, "UNRESOLVED_SECONDS", 1e6)                    # as if no time were left for them
    r = certkin.forward_kinematics(robot, lengths, max_boxes=8000, record="whole")
    assert len(r.unresolved) == api.MIN_UNRESOLVED
    tree = r.tree
    open_ = tree.leaves(kind=certkin.engine.UNDECIDED)
    assert len(open_) > 1000
    lo = np.stack([u["box"].lo for u in r.unresolved])
    hi = np.stack([u["box"].hi for u in r.unresolved])
    inside = np.all((lo[None] <= tree.lo[open_][:, None]) & (tree.hi[open_][:, None] <= hi[None]), axis=2)
    assert inside.any(axis=1).all()


def test_a_spatial_search_in_a_fresh_process_keeps_its_seconds_apart_from_loading_its_kernels():
    """The first spatial search of a process spent 0.7 s (1.4 s on a slower machine) of a 0.05 s budget
    loading numba and its machine code in its first batch; that start-up is no longer counted, and
    the search itself stops near its budget."""
    import subprocess
    import sys
    code = ("import sys, certkin; r = certkin.forward_kinematics(certkin.load_robot(sys.argv[1]), "
            "'1,0.645275,1.086284,1.503439,1.281933,0.771071', max_seconds=float(sys.argv[2])); "
            "print(r.complete, r.seconds)")
    robot = str(ROBOTS / "dietmaier-6-6-40.toml")
    subprocess.run([sys.executable, "-c", code, robot, "0.5"], check=True, capture_output=True)   # kernels cached
    out = subprocess.run([sys.executable, "-c", code, robot, "0.1"], check=True, capture_output=True, text=True)
    complete, seconds = out.stdout.split()
    assert complete == "False" and float(seconds) < 0.6


def test_a_box_budget_past_int64_is_no_limit_in_every_solver():
    """max_boxes=10**20 crashed every search (OverflowError: the engine counts boxes in int64)."""
    assert certkin.Budget(max_boxes=10 ** 20).max_boxes == 2 ** 53
    r = certkin.forward_kinematics(R2, L, max_boxes=10 ** 20)
    assert r.complete and len(r.solutions) == 6
    assert proofs.check(r.certificate()).ok
    cell = certkin.certify_singularity_free(R2, "x=0:1,y=0:1,phi=0:0.1", max_boxes=1e20)
    assert cell.status == "singularity-free" and proofs.check(cell.certificate()).ok
    path = certkin.verify_trajectory(MEL, "-69,-50,500,85deg,10deg,0", "84,92,500,85deg,10deg,0", max_boxes=1e20)
    assert path.status == "infeasible"
    assert proofs.check(path.certificate()).ok


def test_budgets_and_tolerances_past_the_floats_are_read_not_crashed():
    """max_seconds=10**400, min_width=10**400, rtol=10**400 and max_memory=10**400 raised OverflowError
    (float() of an int past the floats); rtol=b"1" was read as 1.0.  (A memory budget past this machine's
    memory is refused.)"""
    from fractions import Fraction
    assert certkin.Budget(max_seconds=10 ** 400).max_seconds == float("inf")
    assert certkin.Budget(max_seconds=Fraction(10 ** 400, 3)).max_seconds == float("inf")
    with pytest.raises(certkin.InputError, match="^max_memory: .* more than this machine's memory"):
        certkin.Budget(max_memory=10 ** 400)
    for keyword, bad in (("min_width", 10 ** 400), ("max_seconds", -10 ** 400), ("min_width", -10 ** 400)):
        with pytest.raises(certkin.InputError, match=f"^{keyword}: expected a positive"):
            certkin.Budget(**{keyword: bad})
    path = certkin.verify_trajectory(MEL, "-69,-50,500,85deg,10deg,0", "84,92,500,85deg,10deg,0",
                                     max_seconds=10 ** 400)
    assert path.status == "infeasible"
    for bad in (10 ** 400, b"1"):
        with pytest.raises(certkin.InputError, match="^rtol: expected a positive"):
            certkin.verify_trajectories(MEL, [("-69,-50,500,85deg,10deg,0", "84,92,500,85deg,10deg,0")], rtol=bad)


def test_a_box_as_a_tuple_is_an_input_error():
    """A box given as a tuple of ranges raised ValueError or AttributeError (it was taken for the
    solver's own (enclosure, texts) pair)."""
    for box in (((-20, -10), (20, 30), (0, 0.3)), ((-20, -10), (20, 30)), ("x=-20:-10", "y=20:30,phi=0:0.3")):
        with pytest.raises(certkin.InputError, match="^box: expected"):
            certkin.certify_singularity_free(R2, box)


def test_a_number_given_as_a_list_of_three_huge_ints_is_an_input_error():
    """A height or a pose value given as a list of three huge ints raised OverflowError (Decimal reads
    a 3-tuple as sign, digits, exponent)."""
    from certkin.workspace import workspace_section
    with pytest.raises(certkin.InputError, match="^z: expected a number"):
        workspace_section(MICRO, "0,0,0", [10 ** 400] * 3)
    with pytest.raises(certkin.InputError, match="^start: x: expected a number"):
        certkin.verify_trajectory(MEL, [[10 ** 400] * 3] * 6, "84,92,500,85deg,10deg,0")


def test_a_scale_past_the_floats_is_an_input_error():
    """largest_free_box(scale=[10**400] * 3) raised OverflowError."""
    from certkin.singularity import largest_free_box
    with pytest.raises(certkin.InputError, match="^scale: x: expected a positive number"):
        largest_free_box(R2, "10,10,0.4", scale=[10 ** 400] * 3)


def test_the_flags_of_trajectories_and_sections_are_true_or_false():
    """indices="no" and exact="no" were taken as true; an array raised "truth value ... ambiguous"."""
    from certkin.workspace import workspace_section
    for bad in ("no", 0, np.array([1.0, 2.0]), None):
        with pytest.raises(certkin.InputError, match="^indices: expected True or False"):
            certkin.verify_trajectory(MEL, "-69,-50,500,85deg,10deg,0", "84,92,500,85deg,10deg,0", indices=bad)
        with pytest.raises(certkin.InputError, match="^exact: expected True or False"):
            workspace_section(MICRO, "0,0,0", "20005", exact=bad)
    assert workspace_section(MICRO, "0,0,0", "20005", exact=np.bool_(False), min_width=0.05).area is None


def test_many_rows_whose_answers_alone_exceed_the_time_budget_are_refused():
    """20 000 rows with max_seconds=3 ran 37 s: the rows' answers are built after the search, about 1 ms
    each.  Now that time is kept from the search's, and more rows than the budget can answer are refused."""
    rows = np.tile([28.99, 13.66, 40.53], (2000, 1))
    with pytest.raises(certkin.InputError, match="^max_seconds: 2000 rows of leg lengths take about 3 s"):
        certkin.forward_kinematics(R2, rows, max_seconds=1)
    done = certkin.forward_kinematics(R2, rows[:20], max_seconds=0.05)      # within the budget: answered
    assert len(done) == 20 and all(not r.complete or len(r.solutions) == 6 for r in done)
    one = certkin.forward_kinematics(R2, L, max_seconds=1e-9)               # one row: incomplete, never refused
    assert not one.complete and proofs.check(one.certificate()).ok


def test_a_0_d_array_as_a_pose_or_a_height_range_is_an_input_error():
    """np.array(1.0) as a pose raised TypeError (iteration over a 0-d array), as a z range too."""
    from certkin.singularity import largest_free_box
    from certkin.workspace.volume import workspace_volume
    z0 = np.array(1.0)
    for call, parameter in ((lambda: certkin.verify_trajectory(R2, z0, [2, 3, 0.1]), "start"),
                            (lambda: certkin.forward_kinematics(R2, L, track=z0), "track"),
                            (lambda: certkin.plan(R2, z0, [2, 3, 0.1]), "start"),
                            (lambda: largest_free_box(R2, z0), "pose"),
                            (lambda: certkin.verify_trajectory(R2, np.zeros((1, 3)), [2, 3, 0.1]), "start"),
                            (lambda: workspace_volume(MICRO, "0,0,0", z0, 5), "z_range"),
                            (lambda: workspace_volume(MICRO, "0,0,0", 5, 5), "z_range")):
        with pytest.raises(certkin.InputError) as exc:
            call()
        assert exc.value.source == parameter
    from certkin.workspace.section import workspace_section      # a 0-d array as a number is its value
    assert workspace_section(MICRO, "0,0,0", np.array(20005.0), max_seconds=5).status == "non-empty"
    with pytest.raises(certkin.InputError, match="^z: not a plain decimal") as exc:     # (was "z: z: ...")
        workspace_section(MICRO, "0,0,0", "abc")
    assert exc.value.field == "z"


def test_a_robot_changed_after_it_was_read_to_hold_nan_is_an_input_error():
    """A loaded robot's point set to NaN raised a bare ValueError naming nothing."""
    robot = certkin.load_robot(R2)
    robot.base[0] = ("nan", "4.34")
    with pytest.raises(certkin.InputError, match=r"^robot: base\[0\]: not a finite number"):
        certkin.forward_kinematics(robot, L)


def test_a_record_limit_is_a_positive_integer_and_record_and_independent_are_flags():
    """record_limit=0, -1 or 2.5 were taken as they came (a limit the search compared node counts with);
    record="banana" and independent="yes" too."""
    for bad in (0, -1, 2.5, "5", True):
        with pytest.raises(certkin.InputError, match="^record_limit: expected a positive integer"):
            certkin.forward_kinematics(R2, L, record=True, record_limit=bad)
    for keyword, bad in (("record", "banana"), ("record", 1), ("independent", "yes"), ("independent", 1)):
        with pytest.raises(certkin.InputError, match=f"^{keyword}: expected True"):
            certkin.forward_kinematics(R2, L, **{keyword: bad})
    r = certkin.forward_kinematics(R2, L, record=True, record_limit=3)     # (a tiny limit: its tree in segments)
    assert r.complete and proofs.check(r.certificate()).ok


def test_wrong_types_are_input_errors_naming_the_parameter():
    """Each of these raised TypeError, ValueError or numpy's errors (the README: bad values raise
    certkin.InputError naming the parameter)."""
    planning = str(ROBOTS / "seed001-3rpr-planning.toml")
    fk = certkin.forward_kinematics(str(ROBOTS / "seed003-planar-example-2.toml"), L)
    calls = {"constraints": lambda: certkin.verify_trajectory(planning, "20,0,3.0", "60,-50,6.0", constraints=5),
             "start": lambda: certkin.verify_trajectory(planning, None, "60,-50,6.0"),
             "rtol": lambda: certkin.verify_trajectories(planning, [("20,0,3.0", "60,-50,6.0")], rtol="x"),
             "path": lambda: fk.certificate().write(None),
             "max_memory": lambda: certkin.certify_singularity_free(str(ROBOTS / "seed003-planar-example-2.toml"),
                                                                  "x=-20:-10,y=20:30,phi=0:0.3", max_memory=1)}
    for source, call in calls.items():
        with pytest.raises(certkin.InputError) as exc:
            call()
        assert exc.value.source == source, (source, str(exc.value))
    for bad in (5, None):
        with pytest.raises(certkin.RobotFileError, match="expected a file's path"):
            certkin.load_robot(bad)
    with pytest.raises(certkin.RobotFileError, match="kind"):
        certkin.robot_from_dict({"kind": ["planar-3rpr"], "base": [[0, 0], [1, 0], [0, 1]],
                                 "platform": [[0, 0], [1, 0], [0, 1]]})


def test_numpy_floating_point_warnings_do_not_reach_the_caller():
    """min_width=1e300 printed numpy's "overflow encountered in accumulate" twice through the API."""
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = certkin.verify_trajectories(str(ROBOTS / "seed001-3rpr-planning.toml"), [("20,0,3.0", "60,-50,6.0")],
                                        min_width=1e300)
    assert r[0].status in ("infeasible", "undecided", "feasible")


def test_a_pose_may_be_a_mapping_of_its_variables():
    """A dict pose gave "x: not a finite number: 'x'" (its keys were read as the values)."""
    planning = str(ROBOTS / "seed001-3rpr-planning.toml")
    a = certkin.verify_trajectory(planning, {"x": 20, "y": 0, "phi": "3.0"}, {"phi": 6.0, "x": 60, "y": -50})
    b = certkin.verify_trajectory(planning, "20,0,3.0", "60,-50,6.0")
    assert a.to_json()["path"] == b.to_json()["path"] and a.status == b.status
    with pytest.raises(certkin.InputError, match="phi: missing"):
        certkin.verify_trajectory(planning, {"x": 20, "y": 0}, "60,-50,6.0")


def test_robot_points_may_be_tuples_or_arrays_and_a_volume_is_never_below_zero():
    """Tuples and numpy arrays of points were refused ("got no list"); a one-slab volume showed an inner
    bound of -4.94066e-324 (a volume's lower bound is at least 0)."""
    d = {"kind": "planar-3rpr", "base": ((3.78, 4.34), (34.47, -3.78), (16.233, 34.76)),
         "platform": np.array([[-4.83, -3.19], [12.04, -3.19], [8.23, 12.09]])}
    assert certkin.robot_from_dict(d).base[0] == ("3.78", "4.34")
    from certkin.workspace import workspace_volume
    r = workspace_volume(str(ROBOTS / "seed004-micro-manipulator.toml"), z_range="20000:20010", slabs=1)
    assert r.to_json()["volume"]["inner"] == 0.0 and "1 slab," in repr(r)
    assert proofs.check(r.certificate()).ok


def test_a_single_waypoint_text_and_a_text_fallback_are_refused():
    """waypoints="40,-20,4.0" was read letter by letter; fallback="no" was taken as true."""
    from certkin.fk import track_sequence
    planning = str(ROBOTS / "seed001-3rpr-planning.toml")
    with pytest.raises(certkin.InputError) as exc:
        certkin.verify_trajectory(planning, "20,0,3.0", "60,-50,6.0", waypoints="40,-20,4.0")
    assert exc.value.source == "waypoints"
    with pytest.raises(certkin.InputError) as exc:
        track_sequence(str(ROBOTS / "seed003-planar-example-2.toml"), [L.split(",")], "13.3,-17,1.13", fallback="no")
    assert exc.value.source == "fallback"


def test_angles_are_refused_beyond_where_a_certificate_can_be_checked():
    """phi = 1e9 rad gave a singularity answer whose certificate the checker could not verify (its sine
    reduces arguments below 2^22 pi/2 only): angles above 1e6 rad are refused; 1e5 rad checks."""
    planar = str(ROBOTS / "seed003-planar-example-2.toml")
    with pytest.raises(certkin.InputError, match="out of range for an angle"):
        certkin.certify_singularity_free(planar, "x=-50:50,y=-50:50,phi=1e9:1000000001")
    r = certkin.certify_singularity_free(planar, "x=-50:50,y=-50:50,phi=1e5:100001")
    assert proofs.check(r.certificate()).ok


def test_a_long_double_stands_for_its_shortest_text_enclosed():
    """np.longdouble values were enclosed as the nearest float64, a point: a box from 0.1 (the text
    recorded) was searched from 0.1000000000000000055 and called singularity-free, and its
    certificate was rejected ("'0.1' is not inside the box")."""
    ld = np.longdouble
    box = {"x": (ld(-20), ld(-10)), "y": (ld(20), ld(30)), "phi": (ld("0.1"), ld(1) / 3)}
    r = certkin.certify_singularity_free(R2, box)
    assert r.box["phi"][0] == "0.1" and r.lo[2] < 0.1
    assert r.status == "singularity-free" and proofs.check(r.certificate()).ok
    planning = str(ROBOTS / "seed001-3rpr-planning.toml")
    r = certkin.verify_trajectory(planning, [ld(20), 0, ld(1) / 3], "30,10,3.5")
    assert r.to_json()["path"][0]["phi"] == str(ld(1) / 3) and proofs.check(r.certificate()).ok


def test_a_fraction_is_its_exact_decimal_or_refused():
    """Fractions were taken and written as "2899/100": the lengths of an FK answer, a pose of a path,
    whose certificates the checker rejects (not an exact decimal), and a robot whose first use raised
    a bare ValueError.  A fraction with a decimal is that decimal; 1/3 has none and is refused."""
    from fractions import Fraction
    r = certkin.forward_kinematics(R2, [Fraction(2899, 100), Fraction(683, 50), "40.53"])
    assert r.lengths == ["28.99", "13.66", "40.53"] and len(r.solutions) == 6 and proofs.check(r.certificate()).ok
    with pytest.raises(certkin.InputError, match=r"^lengths: leg 1: not an exact decimal: 1/3"):
        certkin.forward_kinematics(R2, [Fraction(1, 3), 13.66, 40.53])
    planning = str(ROBOTS / "seed001-3rpr-planning.toml")
    with pytest.raises(certkin.InputError, match=r"^start: phi: not an exact decimal"):
        certkin.verify_trajectory(planning, [20, 0, Fraction(1, 3)], "30,10,3.5")
    robot = {"kind": "planar-3rpr", "base": [[Fraction(189, 50), 4.34], [34.47, -3.78], [16.233, 34.76]],
             "platform": [[-4.83, -3.19], [12.04, -3.19], [8.23, 12.09]]}
    assert certkin.robot_from_dict(robot).base[0] == ("3.78", "4.34")
    robot["base"][0][0] = Fraction(1, 3)
    with pytest.raises(certkin.RobotFileError, match=r"base\[0\]\[0\]: not an exact decimal"):
        certkin.robot_from_dict(robot)
    with pytest.raises(certkin.InputError, match="below 1e-400"):
        certkin.forward_kinematics(R2, [Fraction(1, 10 ** 500), 1, 1])


def test_waypoints_may_be_an_array_of_poses():
    """waypoints=np.array([[...]]) (and a path's "via" given so) raised numpy's "truth value of an array
    is ambiguous"; waypoints=5 a TypeError."""
    planning = str(ROBOTS / "seed001-3rpr-planning.toml")
    expected = certkin.verify_trajectory(planning, "20,0,3.0", "30,10,3.0", waypoints=[[25.0, 5.0, 3.0]]).to_json()["path"]
    r = certkin.verify_trajectory(planning, "20,0,3.0", "30,10,3.0", waypoints=np.array([[25, 5, 3.0]]))
    assert r.to_json()["path"] == expected and r.status == "feasible"
    [r] = certkin.verify_trajectories(planning, [{"start": "20,0,3.0", "goal": "30,10,3.0", "via": np.array([[25, 5, 3.0]])}])
    assert r.to_json()["path"] == expected
    with pytest.raises(certkin.InputError, match="^waypoints: expected a list of poses, got int"):
        certkin.verify_trajectory(planning, "20,0,3.0", "30,10,3.0", waypoints=5)


def test_many_paths_are_refused_when_their_answers_alone_exceed_the_time_budget():
    """2000 paths with max_seconds=0.1 took 2 s (the MEL robot: 10 s), all undecided: each path's answer
    is concluded after the search, about a millisecond a path, which no budget bounded."""
    import time
    planning = str(ROBOTS / "seed001-3rpr-planning.toml")
    t0 = time.perf_counter()
    with pytest.raises(certkin.InputError, match="^max_seconds: 2000 paths of 4 constraints take about"):
        certkin.verify_trajectories(planning, [("20,0,3.0", "30,10,3.0")] * 2000, max_seconds=0.1)
    assert time.perf_counter() - t0 < 2.0
    t0 = time.perf_counter()
    rs = certkin.verify_trajectories(planning, [("20,0,3.0", "30,10,3.0")] * 200, max_seconds=0.5)
    assert time.perf_counter() - t0 < 2.0 and {r.status for r in rs} <= {"feasible", "undecided"}


def test_a_progress_that_is_not_callable_is_refused_up_front():
    """``progress=5`` raised TypeError ("'int' object is not callable") from inside the search, after
    the robot was loaded and work had started, and ``progress=0`` was silently ignored: now any value
    neither None nor callable is an InputError naming progress, before the robot is even read (a
    missing robot file is not reached)."""
    from certkin.singularity import largest_free_box
    from certkin.workspace import workspace_section, workspace_volume
    missing = str(ROBOTS / "no-such-robot.toml")
    calls = [
        lambda p: certkin.certify_singularity_free(missing, "x=-20:-10,y=20:30,phi=0:0.3", progress=p),
        lambda p: largest_free_box(missing, "-15,25,0.1", progress=p),
        lambda p: certkin.forward_kinematics(missing, L, progress=p),
        lambda p: certkin.verify_trajectory(missing, "-69,-50,500,0,0,0", (0, 0, 500, 0, 0, 0), progress=p),
        lambda p: certkin.verify_trajectories(missing, [("-69,-50,500,0,0,0", "0,0,500,0,0,0")], progress=p),
        lambda p: certkin.plan(missing, "-90,140,520,0,0,0", "55,140,520,0,0,0", progress=p),
        lambda p: workspace_section(missing, "0,0,0", 500, progress=p),
        lambda p: workspace_volume(missing, "0,0,0", "500:510", progress=p),
    ]
    for call in calls:
        for bad in (5, 0, "bar", True):
            with pytest.raises(certkin.InputError, match="^progress: expected None or a callable"):
                call(bad)
        with pytest.raises(certkin.RobotFileError):       # None and a callable pass on to the robot
            call(lambda *a: None)
    seen = []
    certkin.forward_kinematics(R2, L, progress=lambda *a: seen.append(a))
    assert seen


def test_a_masked_array_is_refused_when_an_entry_is_masked_and_read_when_none_is():
    """A numpy masked array of lengths was read as its data, the masked entry's hidden value
    included (forward_kinematics answered for lengths the caller had masked out): an array with a
    masked entry is now an InputError naming the parameter; one with nothing masked is its data."""
    from numpy import ma
    cases = [
        (lambda: certkin.forward_kinematics(R2, ma.array([28.99, 13.66, 40.53], mask=[0, 1, 0])),
         r"lengths: .*1 masked entry \(the first at index 1\)"),
        (lambda: certkin.forward_kinematics(R2, ma.array([[28.99, 13.66, 40.53]], mask=[[0, 0, 1]])),
         r"lengths: .*index \[0, 2\]"),
        (lambda: certkin.track_sequence(R2, ma.array([[28.99, 13.66, 40.53], [29, 13.66, 40.53]],
                                                     mask=[[0, 0, 0], [1, 0, 0]]), "30,13,-1.9"), r"lengths: .*\[1, 0\]"),
        (lambda: certkin.forward_kinematics(R2, L, track=ma.array([30, 13, -1.9], mask=[0, 1, 0])), "track: "),
        (lambda: certkin.verify_trajectory(MEL, ma.array([-69, -50, 500, 0, 0, 0], mask=[1, 0, 0, 0, 0, 0]),
                                           "0,0,500,0,0,0"), "start: "),
        (lambda: certkin.verify_trajectory(MEL, "-69,-50,500,0,0,0", "0,0,500,0,0,0",
                                           waypoints=ma.array([[-30, -20, 500, 0, 0, 0]], mask=[[0, 1, 0, 0, 0, 0]])),
         "waypoints: "),
        (lambda: certkin.verify_trajectories(MEL, ma.array([[[-69, -50, 500, 0, 0, 0], [0, 0, 500, 0, 0, 0]]],
                                                           mask=[[[0] * 6, [0, 0, 1, 0, 0, 0]]])), "paths: "),
        (lambda: certkin.plan(MEL, ma.array([-90, 140, 520, 0, 0, 0], mask=[0, 0, 1, 0, 0, 0]), "55,140,520,0,0,0"),
         "start: "),
        (lambda: certkin.forward_kinematics(R2, [28.99, ma.masked, 40.53]), "lengths: leg 2: a masked entry"),
    ]
    for call, message in cases:
        with pytest.raises(certkin.InputError, match="^" + message):
            call()
    whole = certkin.forward_kinematics(R2, ma.array([28.99, 13.66, 40.53], mask=False))
    assert whole.lengths == ["28.99", "13.66", "40.53"] and len(whole.solutions) == 6
