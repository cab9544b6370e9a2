"""``certkin workspace``: a constant-orientation section (exact arcs, area) or a volume bracket."""
from __future__ import annotations

from .. import display
from ..engine import budgets
from ..errors import InputError
from ..plots import plot_section, plot_volume
from ..robots import load_robot
from ..workspace import VolumeResult, workspace_section, workspace_volume
from ..workspace.annuli import ORIENTATION, check_robot
from ..workspace.section import ignored_limits
from ..workspace.volume import DEFAULT_SLABS, MAX_SLABS
from .common import (Answer, add_budget, add_outputs, budget, check_outputs, count, options, progress, refuse,
                     report_writer, run_answer)

OPTIONS = {"orientation": "--orientation", "z": "--z", "z_range": "--z-range", "slabs": "--slabs", "plot": "--plot"}
DEFAULT = budgets.WORKSPACE


def add_arguments(parser) -> None:
    """The options of ``certkin workspace``."""
    parser.add_argument("robot", help="robot file (TOML): gough-stewart or planar-3rpr, with limits.leg_length")
    parser.add_argument("--orientation", metavar="PSI,THETA,PHI", default=None,
                        help="fixed orientation (radians, or with a 'deg' suffix); planar robots: PHI; default 0")
    parser.add_argument("--z", metavar="Z", help="height of the section (exact decimal)")
    parser.add_argument("--z-range", metavar="LO:HI", help="volume bracket of the workspace between two heights")
    parser.add_argument("--slabs", metavar="N", type=count(MAX_SLABS),
                        help=f"number of z slabs for --z-range, 1 to {MAX_SLABS} (default {DEFAULT_SLABS})")
    parser.add_argument("--plot", metavar="FILE.png", help="picture of the paving and arcs (PNG, SVG, PDF, or another type matplotlib writes)")
    add_outputs(parser)
    add_budget(parser, DEFAULT, width_help="smallest box side still split, relative to the size of the section")


def _check(args):
    """Conflicting or ignored options, before anything is read or solved."""
    if args.z_range is not None:
        refuse(args, "--z-range", "give either --z (a section) or --z-range (a volume), not both", "z")
    else:
        refuse(args, "--slabs", "only with --z-range", "slabs")


def compute(args, robot=None) -> Answer:
    """The answer of ``certkin workspace`` (``robot``: the robot file already loaded, else ``args.robot``).

    Bad input raises ``InputError`` (the CLI prints it on one line and exits 2).
    """
    _check(args)
    with options(OPTIONS):
        result = _solve(args, robot)
    plot = plot_volume if isinstance(result, VolumeResult) else plot_section
    return Answer(result.robot, result, result.to_json(), lambda: describe(result), result.certificate,
                  lambda path, cert: report_writer("workspace_report")(result.robot, result, path, cert, budget(args)),
                  lambda path: plot(result, path))


def run(args, out=None) -> int:
    """``certkin workspace``: prints a summary (or ``--json``), writes ``--certificate``/``--report``/
    ``--plot``; returns 0."""
    _check(args)
    check_outputs(args)
    return run_answer(args, compute, OPTIONS, out)


def _solve(args, robot=None):
    """The section or the volume the options ask for."""
    robot = robot or load_robot(args.robot)
    check_robot(robot)
    if args.z_range is not None:
        return workspace_volume(robot, args.orientation, args.z_range, args.slabs or DEFAULT_SLABS,
                                budget=budget(args), progress=progress(args.progress))
    if args.z is None and robot.kind != "planar-3rpr":
        raise InputError("--z", "z", "give --z Z (a section) or --z-range LO:HI (a volume)")
    return workspace_section(robot, args.orientation, args.z, budget=budget(args), progress=progress(args.progress))


def describe(result) -> str:
    """A few lines for the command line: exact areas outward, paving brackets with the inner bound
    rounded down (an area is never below 0: a sum rounded down to -5e-324 is shown as 0) and the
    outer one up."""
    names = ORIENTATION[result.robot.kind]
    orient = ",".join(names) + " = " + ",".join(result.orientation)
    ignored = ignored_limits(result.robot)
    note = f"\n  (leg-length limits only; ignored: {', '.join(ignored)})" if ignored else ""
    if isinstance(result, VolumeResult):
        vin, vout = result.volume()
        c = result.counts()
        return (f"{result.robot.name}: workspace volume for z in [{result.z_range[0]}, {result.z_range[1]}] "
                f"at {orient}: {result.status}\n"
                f"  volume in [{display.lower(max(vin, 0.0))}, {display.upper(vout)}] ({len(result.pavings)} slabs; "
                f"{c['inner_boxes']} inside, {c['boundary_boxes']} boundary, {c['outside_boxes']} outside boxes) "
                f"[{result.stats['boxes']} boxes, {result.stats['seconds']:.3f} s{_stopped(result)}]" + note)
    where = "" if result.z is None else f"z = {result.z}, "
    lines = [f"{result.robot.name}: section {where}{orient}: {result.status}"]
    b = result.boundary
    if b.decided and b.perimeter is not None:
        lines.append(f"  exact area in {display.interval(b.area, 15)}, perimeter in "
                     f"{display.interval(b.perimeter, 15)} ({len(b.arcs)} arcs, "
                     f"{display.counted(b.loops, 'loop')})")
    elif b.decided:
        lines.append(f"  exact area in {display.interval(b.area, 15)} ({b.reason})")
    else:
        lines.append(f"  exact boundary undecided: {b.reason}")
    c = result.counts()
    lines.append(f"  paving: area in [{display.lower(max(result.inner, 0.0))}, {display.upper(result.outer)}] "
                 f"({c['inner_boxes']} inside, {c['boundary_boxes']} boundary, {c['outside_boxes']} outside boxes) "
                 f"[{result.stats['boxes']} boxes, {result.stats['seconds']:.3f} s{_stopped(result)}]")
    return "\n".join(lines) + note


def _stopped(result) -> str:
    """Said when a budget (boxes, seconds, memory) stopped the paving before --min-width: its
    bracket is true but wider than that resolution would give."""
    return "; budget exhausted before --min-width" if result.stats.get("exhausted") else ""
