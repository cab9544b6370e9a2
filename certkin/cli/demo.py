"""``certkin demo``: the seed examples on the bundled robots.

Loads every robot file of ``examples/robots``, prints a summary of each
(kind, legs, reference pose, certified leg lengths and det(A) there), then
runs the certified seed examples: seed 003 planar example 2 (the full box
is singular: its vertex signs differ, Annex C.1) and its 10×10×10 cell
classification; the 6 assembly modes of that robot for one set of leg
lengths; the seed 000 Fig. 1.8 trajectory of the MEL robot (legs 1-2 and
2-5 collide).  Each certificate is re-checked by the independent checker.  Last, a small batch:
50 forward-kinematics jobs of that robot on 2 workers, with the campaign's report.
"""
from __future__ import annotations

from pathlib import Path
import sys
import time

import proofs

from .. import display
from ..batch import run_batch
from ..batch.grid import fk_jobs
from ..certificates import singularity_certificate
from ..errors import InputError
from ..fk import forward_kinematics
from ..robots import load_robot
from ..singularity import certify_singularity_free, classify_cells
from ..report import batch_report
from ..trajectory import verify_trajectory
from .batch import run_job, table
from .common import check_output_directory, options, writing_in


SOURCE_TREE = Path(__file__).resolve().parent.parent.parent


def bundled_robots_dir(source: Path = SOURCE_TREE, prefix: str | None = None) -> Path:
    """``examples/robots`` of the source tree (an editable install), else the copy an install from a
    wheel puts in ``<prefix>/share/certkin/robots`` (pyproject's data-files)."""
    here = Path(source) / "examples" / "robots"
    installed = Path(sys.prefix if prefix is None else prefix) / "share" / "certkin" / "robots"
    return here if here.is_dir() or not installed.is_dir() else installed


def summarise(robot) -> list[str]:
    lines = [f"{robot.name}  ({robot.kind}, {robot.n_legs} legs)  <- {Path(robot.source).name}"]
    if robot.home is None:
        lines.append("  no reference pose in the file")
        return lines
    box = robot.home_box()
    pose = ", ".join(f"{n}={t}" for n, t in zip(robot.pose_names, robot.home))
    lines.append(f"  pose: {pose}")
    legs = robot.leg_lengths(box)
    lines.append("  leg lengths: " + ", ".join(display.interval(legs[i], 8) for i in range(robot.n_legs)))
    det = robot.det_enclosure(box)
    sign = "> 0" if det.lo > 0 else "< 0" if det.hi < 0 else "sign not decided"
    lines.append(f"  det(A) in {display.interval(det, 8)}  ({sign})")
    return lines


def run_demo(directory=None, out=print, results="certkin-demo") -> int:
    given = bool(directory)
    directory = Path(directory) if directory else bundled_robots_dir()
    files = sorted(directory.glob("*.toml"))
    if not files:
        raise InputError(str(directory), "", "no robot files (*.toml) found")
    out(f"== {'Robots' if given else 'Bundled robots'} ({directory})")
    robots = {}
    for f in files:
        robot = load_robot(f)
        robots[f.stem] = robot
        for line in summarise(robot):
            out(line)
    _singularity_demo(robots, out)
    _fk_demo(robots, out)
    _trajectory_demo(robots, out)
    _batch_demo(robots, out, Path(results))
    if _pick(robots, "planar-example-2", "planar-3rpr") is None and _pick(robots, "seed000", "gough-stewart") is None:
        out("")
        out("(the demo's questions are those of the seed 000 and seed 003 planar example 2 robots: no file of "
            "this directory is one of them)")
    return 0


def _pick(robots, part: str, kind: str):
    """The first robot file whose name holds ``part`` and whose robot is of ``kind`` (a directory given
    with --robots may name its files anyhow: a step runs only on a robot its question fits)."""
    return next((k for k, r in robots.items() if part in k and r.kind == kind), None)


def _batch_demo(robots, out, results: Path):
    """50 planar FK jobs (a grid of leg lengths) on 2 workers, and the report of the campaign."""
    name = _pick(robots, "planar-example-2", "planar-3rpr")
    if name is None:
        return
    robot = robots[name]
    jobs = fk_jobs(robot.source, robot, "L1=28:30:5,L2=13:14:5,L3=40:41:2", "demo-fk")
    out("")
    out(f"== A batch: {len(jobs)} forward-kinematics jobs of {name} on 2 workers, into {results}/")
    with options({"out": "--out"}), writing_in("--out", results):
        summary = run_batch(jobs, results, run_job, workers=2)
    for line in table(summary, results).splitlines():
        out("  " + line)
    with writing_in("--out", results):
        batch_report(summary, results, results / "report.html")
    out(f"  report of the campaign: {results / 'report.html'}")


def _check(out, result, what):
    t = time.perf_counter()
    report = proofs.check(result.certificate())
    out(f"  certificate of {what} re-checked by proofs: {'OK' if report.ok else 'REJECTED: ' + report.step} "
        f"({time.perf_counter() - t:.1f} s)")


def _fk_demo(robots, out):
    """Seed 003 planar example 2 geometry: 6 real assembly modes (each proved unique, complete)."""
    robot = robots.get(_pick(robots, "planar-example-2", "planar-3rpr"))
    if robot is None:
        return
    out("")
    out("== Forward kinematics: seed 003 planar example 2, leg lengths 28.99, 13.66, 40.53")
    t = time.perf_counter()
    r = forward_kinematics(robot, "28.99,13.66,40.53")
    out(f"  {len(r.solutions)} assembly modes, each proved unique; complete: {'yes' if r.complete else 'no'} "
        f"({time.perf_counter() - t:.3f} s)")
    for k, sol in enumerate(r.solutions):
        out(f"    {k + 1}: " + ", ".join(f"{n}={display.interval(v, 12)}" for n, v in sol["pose"].items()))
    _check(out, r, f"the {display.counted(len(r.solutions), 'mode')}")


def _trajectory_demo(robots, out):
    """Seed 000 Fig. 1.8 on the MEL robot: legs 1-2 and 2-5 collide before the goal."""
    robot = robots.get(_pick(robots, "seed000", "gough-stewart"))
    if robot is None:
        return
    start, goal = "-69,-50,500,85deg,10deg,0", "84,92,500,85deg,10deg,0"
    out("")
    out(f"== Trajectory: seed 000 Fig. 1.8, MEL robot, {start} -> {goal} (leg radius 2 mm)")
    t = time.perf_counter()
    r = verify_trajectory(robot, start, goal)
    out(f"  {r.status} ({time.perf_counter() - t:.2f} s)")
    for v in r.violations:
        if v["certain"]:
            out(f"    {v['constraint']} legs {'-'.join(map(str, v['legs']))}: proved violated, failing instants "
                f"within t in {display.pair(v['t'])}")
    legs = [m for m in r.margins if m["constraint"] == "leg-length"]
    worst = min(legs, key=lambda m: m["margin"][0])
    out(f"    smallest leg-length margin: leg {worst['legs'][0]}, in {display.pair(worst['margin'], 8)} mm")
    _check(out, r, "the trajectory")


def _singularity_demo(robots, out):
    robot = robots.get(_pick(robots, "planar-example-2", "planar-3rpr"))
    if robot is None:
        return
    out("")
    out("== Seed 003, planar example 2: singularity-free regions")
    box = "x=-50:50,y=-50:50,phi=0:0.7853981634"
    t = time.perf_counter()
    r = certify_singularity_free(robot, box)
    out(f"  full box {box}: {r.status} ({time.perf_counter() - t:.3f} s)")
    if r.witnesses:
        for k, v in r.witnesses.items():
            out(f"    det(A) {'>' if k == 'positive' else '<'} 0 at " + ", ".join(display.point(x) for x in v))
    t = time.perf_counter()
    cells = classify_cells(robot, box, 10)
    dt = time.perf_counter() - t
    counts = {s: sum(c.status == s for c in cells) for s in ("singularity-free", "singular", "undecided")}
    out(f"  10x10x10 cells: {counts['singularity-free']} singularity-free, {counts['singular']} singular, "
        f"{counts['undecided']} undecided ({dt:.2f} s)")
    t = time.perf_counter()
    report = proofs.check(singularity_certificate(cells))
    out(f"  certificate of the 1000 cells re-checked by proofs: {'OK' if report.ok else 'REJECTED'} "
        f"({time.perf_counter() - t:.1f} s)")


def add_arguments(d):
    d.add_argument("--robots", help="directory of robot files (default: the bundled examples)")
    d.add_argument("--out", default="certkin-demo", metavar="DIR",
                   help="directory of the demo batch's results and report (default certkin-demo)")


def run(args):
    check_output_directory(args.out, "--out")
    if args.robots is not None and not args.robots.strip():
        raise InputError("--robots", "", "empty directory name (leave it out for the bundled examples)")
    if args.robots is not None and not Path(args.robots).is_dir():
        raise InputError("--robots", args.robots, "not a directory")
    if args.robots is not None and not any(Path(args.robots).glob("*.toml")):
        raise InputError("--robots", args.robots, "no robot files (*.toml) in this directory")
    return run_demo(args.robots, results=args.out)
