"""The report of a whole batch campaign: verdict counts, robots, the questions, every job's
certificate (name, size, SHA-256) with the command that re-checks them, and the figures."""
from __future__ import annotations

import json
from pathlib import Path

from ..batch import PENDING
from ..errors import InputError
from ..plots import plot_campaign
from ..robots import load_robot, robot_from_dict
from .page import esc, figure, from_report, robot_section, shell_path, table, write_report


def batch_verdict(summary: dict) -> str:
    parts = ", ".join(f"{n} {k}" for k, n in summary["counts"].items())
    head = "INTERRUPTED: " if summary["interrupted"] else ""
    return f"{head}{summary['jobs']} jobs: {parts}; {len(summary['undecided'])} undecided, " \
           f"{len(summary['errors'])} with bad input, {len(summary['failed'])} failed."


def _jobs(out: Path, summary: dict) -> list:
    """The job of each result document (as it was answered)."""
    jobs = []
    for r in summary["results"]:
        try:
            jobs.append(json.loads((out / r["document"]).read_text()).get("job", {}))
        except (OSError, ValueError):
            jobs.append({})
    return jobs


def _robots(jobs) -> str:
    """One table and drawing per robot of the campaign (at its reference pose when it has one)."""
    seen, html = set(), ""
    for job in jobs:
        ref = job.get("robot")
        key = json.dumps(ref, sort_keys=True)
        if ref is None or key in seen:
            continue
        seen.add(key)
        try:
            robot = load_robot(ref) if isinstance(ref, str) else robot_from_dict(ref, "robot")
        except InputError as exc:
            html += f"<p>Robot {esc(ref)}: {esc(exc)}</p>"
            continue
        poses = [("reference pose", robot.home)] if robot.home is not None else []
        html += robot_section(robot, poses, "Drawn at its reference pose." if poses else
                              "The robot file gives no reference pose: base only.")
    return html or "<p>No robot could be read.</p>"


def batch_report(summary: dict, out, path) -> None:
    out = Path(out)
    jobs = _jobs(out, summary)
    commands = sorted({r["command"] or "?" for r in summary["results"]})
    shared = {k: v for k, v in jobs[0].items() if k not in ("id", "robot") and all(j.get(k) == v for j in jobs)} \
        if jobs else {}
    sections = [("Robots", _robots(jobs))]
    sections.append(("Question and assumptions", (
        f"<p>{summary['jobs']} jobs of the command(s) {esc(', '.join(commands))}; each job asks its command's "
        "question with its own options (its document <code>DIR/&lt;id&gt;.json</code> repeats the job under "
        "<code>job</code>), answered exactly as the command line answers it, with its own budget (an exhausted "
        "budget is an undecided answer, never a missing one).</p>"
        + (f"<p>Options shared by every job: <code>{esc(json.dumps(shared))}</code></p>" if shared else ""))))
    rows = [(k, n) for k, n in summary["counts"].items()]
    rows += [("resumed (already done, certificate re-checked)", summary["resumed"]),
             ("retried after a worker died", len(summary["retried"])),
             ("wall-clock seconds", summary["seconds"]), ("seconds in jobs", summary["job_seconds"]),
             ("workers", summary["workers"])]
    problems = [(e["id"], "bad input", e["error"]) for e in summary["errors"]] + \
               [(e["id"], "failed", e["error"]) for e in summary["failed"]] + \
               [(i, "undecided", "budget exhausted or resolution reached") for i in summary["undecided"]] + \
               [(r["id"], PENDING, "not run or not re-checked: the batch was interrupted (the same command resumes it)")
                for r in summary["results"] if r["verdict"] == PENDING]
    sections.append(("Evidence", table(("jobs", "count"), rows) +
                     (table(("job", "outcome", "why"), problems) if problems else "<p>Every job was answered.</p>")))
    sections.append(("Figures", figure(lambda p: plot_campaign(summary, p), "jobs by verdict and job times")))
    certs = [(r["id"], r["command"], r["verdict"], r["certificate"]["file"], r["certificate"]["bytes"],
              r["certificate"]["sha256"]) for r in summary["results"] if r.get("certificate")]
    directory = shell_path(from_report(out, path))
    certificates = (
        f"<p>{len(certs)} certificates in <code>{esc(out)}</code>. From the directory of this report, re-check one "
        f"with <code>certkin check {esc(directory)}/&lt;id&gt;.cert</code>, all of them with <code>for f in "
        f"{esc(directory)}/*.cert; do "
        "certkin check \"$f\" || echo \"REJECTED $f\"; done</code>, or run the batch again: it re-checks every "
        "certificate and answers again any job whose certificate does not check.</p>"
        + table(("job", "command", "verdict", "certificate", "size (bytes)", "SHA-256"), certs))
    write_report(path, f"Batch campaign: {out.name}", batch_verdict(summary), sections,
                 certificates_html=certificates)
