"""``certkin workspace``: a constant-orientation section (exact arcs, area) or a volume bracket."""
from __future__ import annotations

import sys

from ..engine import budgets
from ..errors import InputError
from ..plots import plot_section, plot_volume
from ..report import workspace_report
from ..robots import load_robot
from ..workspace import VolumeResult, workspace_section, workspace_volume
from ..workspace.annuli import ORIENTATION, check_robot
from ..workspace.section import ignored_limits
from ..workspace.volume import DEFAULT_SLABS
from .common import Answer, options, progress, run_answer

OPTIONS = {"orientation": "--orientation", "z": "--z", "z_range": "--z-range", "slabs": "--slabs",
           "max_boxes": "--max-boxes", "min_width": "--min-width", "max_seconds": "--max-seconds", "plot": "--plot"}
DEFAULT = budgets.WORKSPACE


def add_arguments(parser) -> None:
    """The options of ``certkin workspace``."""
    parser.add_argument("robot", help="robot file (TOML): gough-stewart or planar-3rpr, with limits.leg_length")
    parser.add_argument("--orientation", metavar="PSI,THETA,PHI", default=None,
                        help="fixed orientation (radians, or with a 'deg' suffix); planar robots: PHI; default 0")
    parser.add_argument("--z", metavar="Z", help="height of the section (exact decimal)")
    parser.add_argument("--z-range", metavar="LO:HI", help="volume bracket of the workspace between two heights")
    parser.add_argument("--slabs", metavar="N", help=f"number of z slabs for --z-range (default {DEFAULT_SLABS})")
    parser.add_argument("--json", action="store_true", help="print one JSON document")
    parser.add_argument("--certificate", metavar="FILE", help="write the certificate to FILE")
    parser.add_argument("--plot", metavar="FILE.png", help="picture of the paving and arcs")
    parser.add_argument("--report", metavar="FILE.html", help="write a self-contained HTML report")
    parser.add_argument("--progress", action="store_true", help="show progress on stderr")
    parser.add_argument("--max-boxes", type=int, default=DEFAULT['max_boxes'],
                        help=f"box budget (default {DEFAULT['max_boxes']})")
    parser.add_argument("--max-seconds", type=float, default=DEFAULT['max_seconds'],
                        help=f"time budget (default {DEFAULT['max_seconds']})")
    parser.add_argument("--min-width", type=float, default=None,
                        help=f"smallest box side still split, relative to the size of the section "
                             f"(default {DEFAULT['min_width']})")


def compute(args, robot=None) -> Answer:
    """The answer of ``certkin workspace`` (``robot``: the robot file already loaded, else ``args.robot``).

    Bad input raises ``InputError`` (the CLI prints it on one line and exits 2).
    """
    with options(OPTIONS):
        result = _solve(args, robot)
    plot = plot_volume if isinstance(result, VolumeResult) else plot_section
    return Answer(result.robot, result, result.to_json(), lambda: describe(result), result.certificate,
                  lambda path, cert: workspace_report(result.robot, result, path, cert), lambda path: plot(result, path))


def run(args, out=None) -> int:
    """``certkin workspace``: prints a summary (or ``--json``), writes ``--certificate``/``--plot``; returns 0."""
    return run_answer(args, compute, OPTIONS, out)


def _solve(args, robot=None):
    """The section or the volume the options ask for."""
    robot = robot or load_robot(args.robot)
    check_robot(robot)
    if args.z is not None and args.z_range is not None:
        raise InputError("--z-range", "", "give either --z (a section) or --z-range (a volume), not both")
    budget = {"max_boxes": args.max_boxes, "max_seconds": args.max_seconds}
    if args.z_range is not None:
        slabs = DEFAULT_SLABS
        if args.slabs is not None:
            try:
                slabs = int(str(args.slabs).strip())
            except ValueError:
                raise InputError("--slabs", "", f"expected an integer, got {args.slabs!r}") from None
        result = workspace_volume(robot, args.orientation, args.z_range, slabs,
                                  min_width=args.min_width if args.min_width is not None else DEFAULT['min_width'],
                                  progress=progress(args.progress), **budget)
    else:
        if args.slabs is not None:
            raise InputError("--slabs", "", "only with --z-range")
        if args.z is None and robot.kind != "planar-3rpr":
            raise InputError("--z", "z", "give --z Z (a section) or --z-range LO:HI (a volume)")
        result = workspace_section(robot, args.orientation, args.z,
                                   min_width=args.min_width if args.min_width is not None else DEFAULT['min_width'],
                                   progress=progress(args.progress), **budget)
    return result


def describe(result) -> str:
    """A few lines for the command line."""
    names = ORIENTATION[result.robot.kind]
    orient = ",".join(names) + " = " + ",".join(result.orientation)
    ignored = ignored_limits(result.robot)
    note = f"\n  (leg-length limits only; ignored: {', '.join(ignored)})" if ignored else ""
    if isinstance(result, VolumeResult):
        vin, vout = result.volume()
        c = result.counts()
        return (f"{result.robot.name}: workspace volume for z in [{result.z_range[0]}, {result.z_range[1]}] "
                f"at {orient}: {result.status}\n"
                f"  volume in [{vin:.10g}, {vout:.10g}] ({len(result.pavings)} slabs; {c['inner_boxes']} inside, "
                f"{c['boundary_boxes']} boundary, {c['outside_boxes']} outside boxes) "
                f"[{result.stats['boxes']} boxes, {result.stats['seconds']:.3f} s]" + note)
    where = "" if result.z is None else f"z = {result.z}, "
    lines = [f"{result.robot.name}: section {where}{orient}: {result.status}"]
    b = result.boundary
    if b.decided and b.perimeter is not None:
        lines.append(f"  exact area in [{float(b.area.lo):.15g}, {float(b.area.hi):.15g}], perimeter in "
                     f"[{float(b.perimeter.lo):.15g}, {float(b.perimeter.hi):.15g}] ({len(b.arcs)} arcs, "
                     f"{b.loops} loop{'s' if b.loops != 1 else ''})")
    elif b.decided:
        lines.append(f"  exact area in [{float(b.area.lo):.15g}, {float(b.area.hi):.15g}] ({b.reason})")
    else:
        lines.append(f"  exact boundary undecided: {b.reason}")
    c = result.counts()
    lines.append(f"  paving: area in [{result.inner:.10g}, {result.outer:.10g}] ({c['inner_boxes']} inside, "
                 f"{c['boundary_boxes']} boundary, {c['outside_boxes']} outside boxes) "
                 f"[{result.stats['boxes']} boxes, {result.stats['seconds']:.3f} s]")
    return "\n".join(lines) + note
