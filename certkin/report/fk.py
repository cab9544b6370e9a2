"""The report of a forward-kinematics result: every assembly mode with its proved box, drawn."""
from __future__ import annotations

from ..display import counted
from .page import enclosure, esc, evidence_section, robot_section, table, tree_evidence, write_report


def fk_verdict(result) -> str:
    """The verdict in one line; never "the rest holds none" while a cluster may hold postures."""
    n, c, u = len(result.solutions), len(result.clusters), len(result.unresolved)
    if result.tracked:
        return "Tracked: exactly one posture in the box around the previous pose (proved unique there)."
    modes = f"{counted(n, 'assembly mode')} proved unique in {'its box' if n == 1 else 'their boxes'}"
    clusters = (f", {counted(c, 'cluster')} that may hold postures (not resolved: a singular pose, "
                "postures closer than the resolution, or a continuum)") if c else ""
    if result.complete:
        where = f" {result.domain_text}" if result.domain_text else ""
        return f"{modes}{clusters}; the rest of the domain{where} is proved to hold none (complete)."
    why = f" ({result.message})" if result.message else " (a budget ran out, or the search was interrupted)"
    return f"INCOMPLETE: {modes}{clusters}, and {counted(u, 'region')} left unresolved{why}."


def fk_report(robot, result, path, certificate=None, budget=None) -> None:
    """Verdict, robot drawn in each assembly mode, the question, the evidence, every mode's box."""
    names = list(result.solutions[0]["pose"]) if result.solutions else list(robot.pose_names)
    mids = [[0.5 * (float(v.lo) + float(v.hi)) for v in s["pose"].values()] for s in result.solutions]
    poses = [(f"mode {k + 1}", m) for k, m in enumerate(mids)] if names == list(robot.pose_names) else []
    sections = [("Robot", robot_section(robot, poses, "Drawn in each assembly mode (at the midpoint of its proved box)."
                                        if poses else "No assembly mode to draw."))]
    if result.tracked:
        domain = ("a box around the previous pose (--track): only the posture there is proved; the other "
                  "assembly modes were not searched")
    elif result.user_domain:
        given = f"<code>{esc(result.domain_text)}</code> given with --domain" if result.domain_text else "a box"
        domain = (f"the domain {given} (positions narrow the search, angles filter the modes): the postures "
                  "outside it are not listed")
    else:
        domain = "every real posture (the full rotation range): every real posture for these lengths is listed"
    sections.append(("Question and assumptions", (
        f"<p>Which postures of the platform give the leg lengths <code>{esc(', '.join(result.lengths))}</code> "
        f"(exact decimals, enclosed outward)? Domain searched: {domain}. The limits of the robot file are not "
        "applied.</p>")))
    used = {"boxes decided": result.boxes, "seconds": f"{result.seconds:.3f}"}
    evidence = tree_evidence(result.tree, [result.node]) if result.tree is not None else None
    sections.append(("Evidence", evidence_section(evidence, budget, used) + (
        "<p>Each mode's box is proved to hold exactly one posture by a Krawczyk test (docs/soundness.md); "
        "the boxes are enclosures, printed outward.</p>")))
    rows = [[k + 1] + [enclosure((float(s["pose"][n].lo), float(s["pose"][n].hi))) for n in names]
            for k, s in enumerate(result.solutions)]
    rows += [[f"{kind} {k + 1}"] + [enclosure((float(s["pose"][n].lo), float(s["pose"][n].hi))) for n in names]
             for kind, regions in (("cluster", result.clusters), ("unresolved", result.unresolved))
             for k, s in enumerate(regions)]
    sections.append(("Assembly modes", table(["mode"] + names, rows) if rows else "<p>No posture.</p>"))
    write_report(path, f"Forward kinematics: {robot.name}", fk_verdict(result), sections, certificate)
