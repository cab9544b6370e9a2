"""``certkin fk``: every real assembly mode for given leg lengths, each proved unique."""
from __future__ import annotations

from dataclasses import replace
import importlib.util
import os
from pathlib import Path
import sys

from .. import display
from ..certificates import fk_certificate
from ..engine import budgets
from ..errors import InputError
from ..fk import forward_kinematics
from ..robots import load_robot
from ..robots.poses import length_enclosures, parse_pose
from .common import (Answer, add_budget, add_outputs, budget, check_outputs, options, progress, refuse, report_writer,
                     run_answer, with_angles)

OPTIONS = {"lengths": "--lengths", "domain": "--domain", "track": "--track"}


def add_arguments(f):
    f.add_argument("robot", help="robot file (TOML)")
    f.add_argument("--lengths", required=True, metavar="L1,L2,...",
                   help="leg lengths (exact decimals); a range 'lo:hi' or 'value+-tolerance' for an uncertain leg")
    f.add_argument("--domain", help='narrow the search: "x=a:b,..." for the variables it narrows (positions narrow '
                                    'the box; angles filter the modes, modulo 2 pi and over both Euler-angle triples '
                                    'of a rotation)')
    f.add_argument("--track", metavar="POSE", help="previous pose: prove the unique posture near it first")
    f.add_argument("--angles", choices=["zyz", "tilt-torsion"], help="spherical robots: pose angles of the output")
    add_outputs(f)
    add_budget(f, budgets.FORWARD_KINEMATICS)


def compute(args, robot=None) -> Answer:
    """The answer of ``certkin fk`` (``robot``: the robot file already loaded, else ``args.robot``)."""
    if args.track is not None:
        refuse(args, "--domain", "not with --track (a tracked posture is not searched in a domain)", "domain")
    with options(OPTIONS):
        robot = with_angles(robot or load_robot(args.robot), args.angles)
        if args.track is not None:
            parse_pose(args.track, robot, "track")     # checked as every pose (the search only starts near it)
        if robot.kind != "planar-3rpr" and not kernels_cached():
            sys.stderr.write("certkin: compiling kernels, once (about 40 s; cached on disk afterwards)\n")
        result = forward_kinematics(robot, args.lengths, domain=args.domain, budget=budget(args),
                                    progress=progress(args.progress), track=args.track,
                                    record=bool(getattr(args, "certificate", None)))
    return _answer(args, robot, result)


def _answer(args, robot, result) -> Answer:
    return Answer(robot, result, result.to_json(), lambda: describe(robot, result),
                  lambda: fk_certificate(result),
                  lambda path, cert: report_writer("fk_report")(robot, result, path, cert, budget(args)))


def compute_together(args_list, robot) -> tuple[list, list]:
    """The answers of several ``certkin fk`` queries that differ only in ``--lengths`` (exact
    decimals, no ``--track``), searched together as independent instances (``forward_kinematics(...,
    independent=True)``): each answer is the one ``compute`` gives, certificate included, unless the
    seconds or memory ran out.  The search has the seconds of all the queries (their ``--max-seconds``
    each, the smallest); when they run out, the queries it did not finish are answered as they stand
    (incomplete: the seconds ran out, as alone).  A query it did not answer (its lengths refused, its
    search stopped by the memory or, alone, perhaps shortened by it, its record handed to files, alone
    or together: the search has the record room of all the queries) is
    None: the caller computes it alone.  The seconds of a query: its share of the search.  Returns
    (the answers, whether each query was searched)."""
    out, searched, rows, members = [None] * len(args_list), [False] * len(args_list), [], []
    with options(OPTIONS):
        robot = with_angles(robot, args_list[0].angles)
        for k, args in enumerate(args_list):
            try:
                _, texts, many = length_enclosures(robot, args.lengths)
            except InputError:
                continue                    # (its own computation gives the error)
            if not many and args.track is None and not any(":" in t for t in texts[0]):
                rows.append(texts[0])
                members.append(k)
        if len(members) < 2:
            return out, searched
        first = args_list[members[0]]
        group = replace(budget(first), max_seconds=len(members) * min(args_list[k].max_seconds for k in members))
        limit = len(members) * budgets.FK_RECORD_NODES      # (a query's own: ``_streamed_alone``)
        results = forward_kinematics(robot, rows, domain=first.domain, budget=group, independent=True, record=True,
                                     record_limit=limit)
    for k, r in zip(members, results):
        searched[k] = True
        if r.tree is not None and (r.tree.record_sink or not r.tree.complete_record or _out_of_memory(r)
                                   or _streamed_alone(r)):
            continue
        out[k] = _answer(args_list[k], robot, r)
    return out, searched


def _streamed_alone(result) -> bool:
    """Whether the search of this instance alone would have handed its record to files (more nodes than
    ``budgets.FK_RECORD_NODES``): its certificate is then built from those files, other bytes."""
    return bool(result.tree.nodes_per_root()[result.node] > budgets.FK_RECORD_NODES)


def _out_of_memory(result) -> bool:
    """Whether a search left boxes of this result undecided for want of memory, or the memory may have
    shortened a batch of its instance searched alone (its answer could then be another)."""
    tree = result.tree
    return tree.stopped_by == "memory" and not result.complete or tree.pressed is not None and tree.pressed[result.node]


def run(args):
    check_outputs(args)
    return run_answer(args, compute, OPTIONS)


def kernels_cached() -> bool:
    """Whether numba's disk cache holds the machine-code kernels of the spatial forward kinematics
    (``certkin/fk/kernels.py`` and ``cayley_menger.py``): in ``__pycache__`` beside them, or under
    ``NUMBA_CACHE_DIR``."""
    for module in ("certkin.fk.kernels", "certkin.fk.cayley_menger"):
        source = Path(importlib.util.find_spec(module).origin).resolve()   # not imported: numba
        places = [source.parent / "__pycache__"]
        if os.environ.get("NUMBA_CACHE_DIR"):
            root = Path(os.environ["NUMBA_CACHE_DIR"])
            places.append(root / str(source.parent).lstrip(os.sep))
            places.append(root)
        if not any(any(p.glob(f"{source.stem}.*.nbi")) for p in places if p.is_dir()):
            return False
    return True


SHOWN = 20      # clusters and unresolved regions listed on the terminal (all of them in --json)


def describe(robot, r):
    """Each assembly mode's box (an enclosure: printed outward), each cluster and unresolved region
    outward; with length ranges a mode's box holds its posture for every length in the ranges."""
    ranges = any(":" in t for t in r.lengths)
    c, twins = len(r.clusters), sum("twin_of" in x for x in r.clusters)
    clusters = (f", {display.counted(c, 'cluster')} (" + ("postures not resolved" if twins < c else
                                                          "a mode again, its quaternion negated") + ")") if c else ""
    n, u = len(r.solutions), len(r.unresolved)
    modes = {0: "0 assembly modes", 1: "1 assembly mode, proved unique"}.get(n, f"{n} assembly modes, each proved unique")
    head = (f"{robot.name}: {modes}"
            + (" for every length in the ranges" if ranges and n else "")
            + (" (tracked from the previous pose)" if r.tracked else
               f"{clusters}; complete" + (f" in the domain {r.domain_text}" if r.domain_text else "") if r.complete else
               f"{clusters}; INCOMPLETE, {display.counted(u, 'unresolved region')}"))
    lines = [head + f" [{r.boxes} boxes, {r.seconds:.3f} s]"]
    for k, s in enumerate(r.solutions):
        lines.append(f"  {k + 1}: " + ", ".join(f"{n}={display.interval(v, 12)}" for n, v in s["pose"].items()))
    for name, regions in (("cluster", r.clusters), ("unresolved", r.unresolved)):
        for k, s in enumerate(regions[:SHOWN]):
            lines.append(f"  {name} {k + 1}: " + ", ".join(f"{n}={display.interval(v, 6)}" for n, v in s["pose"].items())
                         + (f" (mode {s['twin_of'] + 1} again)" if "twin_of" in s else ""))
        if len(regions) > SHOWN:
            lines.append(f"  ... {len(regions) - SHOWN} more {name} regions (all of them in --json and the certificate)")
    if r.message:
        lines.append(f"  note: {r.message}")
    if r.filtered:
        lines.append(f"  note: {display.counted(len(r.filtered), 'more assembly mode')} outside the angle ranges of "
                     "--domain (its certificate lists every mode of the box searched)")
    return "\n".join(lines)
