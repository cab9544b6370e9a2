"""The report of a singularity run: one box (verdict and witnesses) or its cells (counts and the
picture of their classification); the robot drawn at the centre of the box."""
from __future__ import annotations

import numpy as np

from ..display import inward, lower, outward, point
from ..plots import plot_cells
from .page import esc, evidence_section, figure, robot_section, table, tree_evidence, write_report


SHOWN = 20          # undecided boxes listed


def singularity_verdict(results) -> str:
    if len(results) == 1:
        r = results[0]
        if r.status == "singularity-free":
            g, cut = r.bisection, ""
            if g and g["stopped"]:          # --around, cut short: the box is proved, its size is not the largest
                cause = "the time budget ran out" if g["stopped"] == "time budget" else "Ctrl-C came"
                cut = (f" The box was still being grown when {cause} (s = {lower(g['proved'], 9)} proved, rounded down, after "
                       f"{g['tried']} boxes tried): a larger box may be proved with more time.")
            elif g and g.get("not_proved_status") == "undecided":      # a budget, not a singularity, stopped it
                cut = (f" The next box tried (s = {point(g['not_proved'])}) was left undecided by its box budget or the "
                       "resolution: a larger box may be proved with a larger budget.")
            return f"Singularity-free: det(A) {'>' if r.sign > 0 else '<'} 0 on the whole box.{cut}"
        if r.status == "singular":
            return "Singular: det(A) changes sign in the box (two poses of certified opposite signs)."
        if r.around is not None and not r.scale_factor:
            return ("UNDECIDED: det(A) is not proved non-zero at the pose itself (it may be singular there): "
                    "no box around it is claimed free.")
        return "UNDECIDED: part of the box was not decided (the budget ran out, or boxes reached the resolution)."
    counts = {s: sum(r.status == s for r in results) for s in ("singularity-free", "singular", "undecided")}
    whole = "singular" if counts["singular"] else "undecided" if counts["undecided"] else "singularity-free"
    return (f"The box is {whole}: {len(results)} cells, {counts['singularity-free']} singularity-free, "
            f"{counts['singular']} singular, {counts['undecided']} undecided.")


def _box_text(robot, lo, hi, claim: bool) -> str:
    show = inward if claim else outward
    return ", ".join(f"{n} ∈ {show(a, b)}" for n, a, b in zip(robot.pose_names, lo, hi))


def singularity_report(robot, results, path, certificate=None, budget=None) -> None:
    lo = np.min([r.lo for r in results], axis=0)
    hi = np.max([r.hi for r in results], axis=0)
    centre = list(0.5 * (lo + hi))
    sections = [("Robot", robot_section(robot, [("centre of the box", centre)], "Drawn at the centre of the box."))]
    cells = "" if len(results) == 1 else f", cut into {len(results)} cells"
    if len(results) == 1 and results[0].around is not None:      # --around: the box is the answer
        a = results[0].around
        pose = ", ".join(f"{n}={v}" for n, v in zip(robot.pose_names, a["pose"]))
        question = (f"How large a box around the pose {pose} (the pose ± s times the scale "
                    f"{', '.join(point(v).removesuffix('.0') for v in a['scale'])}, s found by bisection) can be proved free of "
                    "singularities, det(A) (the parallel Jacobian A of A ṫ + B ρ̇ = 0) never 0 on it? The box found "
                    "is in the answer below")
    elif len(results) == 1 and results[0].texts is not None:     # the decimals given, exactly
        box = ", ".join(f"{n} = {a}" if a == b else f"{n} ∈ [{a}, {b}]" for n, (a, b) in results[0].box.items())
        question = (f"Does det(A) (the parallel Jacobian A of A ṫ + B ρ̇ = 0) vanish on the box {box}? "
                    "The box as searched (floats) encloses these decimals")
    else:                       # a claim about every cell (all free) is shown on a box inside the cells' hull
        free = all(r.status == "singularity-free" for r in results)
        question = (f"Does det(A) (the parallel Jacobian A of A ṫ + B ρ̇ = 0) vanish on the box "
                    f"{_box_text(robot, lo, hi, free)}{cells}? (The cells' floats, rounded "
                    f"{'inward' if free else 'outward'} to the digits shown)")
    sections.append(("Question and assumptions", (
        f"<p>{esc(question)}; limits of the robot file are not used (the question is about det(A) only).</p>")))
    tree = results[0].tree
    evidence = tree_evidence(tree) if tree is not None else None
    decided = results[0].search_boxes if len(results) > 1 else results[0].boxes   # (a cell's boxes: tree nodes)
    used = {"boxes decided": decided, "seconds": f"{sum(r.seconds for r in results):.3f}"}
    sections.append(("Evidence", evidence_section(evidence, budget, used)))
    if len(results) == 1:
        r = results[0]
        rows = [("box", _box_text(robot, r.lo, r.hi, r.status == "singularity-free"))]
        if r.witnesses:
            rows += [(f"det(A) {'>' if k == 'positive' else '<'} 0 at",
                      ", ".join(x if isinstance(x, str) else point(x) for x in r.witness(k, text=True)))
                     for k in r.witnesses]
        if r.undecided:
            rows += [(f"undecided box {k + 1}", _box_text(robot, a, b, False)) for k, (a, b) in enumerate(r.undecided[:SHOWN])]
            if len(r.undecided) > SHOWN:
                rows.append(("", f"... {len(r.undecided) - SHOWN} more undecided boxes (the first 100 in --json, "
                                 "all of them in the certificate)"))
        sections.append(("Answer", table(("", ""), rows)))
    else:
        sections.append(("Cell classification", figure(lambda p: plot_cells(robot, results, p),
                                                        "certified classification of the cells")))
    write_report(path, f"Singularity analysis: {robot.name}", singularity_verdict(results), sections, certificate)
