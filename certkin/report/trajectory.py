"""The report of a trajectory (and of a plan: its segments are trajectories): verdict, the robot
at the start and goal, the constraints checked and skipped, certified margins, forbidden instants,
and one panel of margins per constraint family."""
from __future__ import annotations

from ..display import outward
from ..plots import plot_margins
from .page import enclosure, esc, evidence_section, figure, robot_section, table, write_report

VERDICTS = {"feasible": "Feasible: every constraint checked holds at every instant of the motion.",
            "infeasible": "Infeasible: a constraint is proved violated on part of the motion.",
            "undecided": "UNDECIDED: some instants are not decided (budget, resolution or interrupt)."}


SHOWN = 20          # undecided ranges listed


def _legs(m) -> str:
    return "-".join(map(str, m["legs"])) + (f" {m['detail']}" if m.get("detail") else "")


def trajectory_sections(robot, result, budget=None) -> list:
    """Question, evidence, margins, forbidden instants and the plot of one trajectory."""
    j = result.to_json()
    motion = " → ".join(",".join(p.values()) for p in j["path"])
    skipped = "".join(f"<li>not checked: {esc(k)} ({esc(why)})</li>" for k, why in result.constraints.unchecked())
    segments = len(j["path"]) - 1
    shape = ("the straight-line motion", "linear in the pose variables, t from 0 to 1") if segments == 1 else \
        (f"the polyline motion of {segments} straight segments", "linear in the pose variables on each segment, "
                                                                 "t from 0 to 1 on each")
    out = [("Question and assumptions", (
        f"<p>Is {shape[0]} {esc(motion)} ({shape[1]}) feasible? "
        f"Constraints checked: {esc(', '.join(j['constraints']))}, with the limits of the "
        f"robot file shown above.</p><ul>{skipped or '<li>every constraint family was checked</li>'}</ul>"))]
    L = result.leaves
    states = {"leaves (t-intervals) of the search": len(L["tlo"]) if L else 0}
    states.update({k: v for k, v in j["stats"].items() if k != "seconds"})
    states["seconds"] = f"{j['stats'].get('seconds', 0.0):.3f}"
    out.append(("Evidence", evidence_section(None, budget, states) +
                "<p>Each constraint is bounded over each t-interval with outward-rounded enclosures "
                "(mean-value forms and Bernstein bounds, docs/soundness.md).</p>"))
    rows = [(m["constraint"], _legs(m), enclosure(m["margin"]), m.get("sign", "")) for m in j["margins"]]
    out.append(("Certified minimum margins", table(("constraint", "legs", "minimum margin over the motion (enclosure)",
                                                    "det(A) sign"), rows)))
    if j["violations"]:
        rows = [(v["constraint"], _legs(v), outward(*v["s"]), "proved" if v["certain"] else "possible")
                for v in j["violations"]]
        out.append(("Forbidden instants", "<p>Their union contains every violation (s = segment + t).</p>" +
                    table(("constraint", "legs", "s interval", "violation"), rows)))
    if j["undecided"]:
        rows = [(outward(*u["s"]),) for u in j["undecided"][:SHOWN]]
        more = f"<p>... {len(j['undecided']) - SHOWN} more (all of them in --json).</p>" if len(j["undecided"]) > SHOWN else ""
        out.append(("Undecided instants", "<p>A constraint is neither proved to hold nor proved violated there (s = segment + t).</p>" +
                    table(("s interval",), rows) + more))
    out.append(("Margins along the motion", figure(lambda p: plot_margins(result, p),
                                                    "certified margin lower bounds per constraint family")))
    return out


def trajectory_report(robot, result, path, certificate=None, budget=None) -> None:
    texts = result.path.texts
    poses = [("start", texts[0]), ("goal", texts[-1])]
    sections = [("Robot", robot_section(robot, poses, "Drawn at the start and the goal of the motion."))]
    sections += trajectory_sections(robot, result, budget)
    verdict = VERDICTS[result.status]
    if result.status == "feasible" and result.constraints.unchecked():
        verdict = "Feasible: every constraint checked holds at every instant of the motion (some constraint families " \
                  "were not checked: see below)."
    write_report(path, f"Trajectory: {robot.name}", verdict, sections, certificate)
