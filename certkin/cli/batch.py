"""``certkin batch JOBS.jsonl --out DIR``: every job answered as its command answers it.

A job's options go through its command's own parser (``"max_seconds": 5`` is ``--max-seconds=5``,
``true`` a flag, a list of ``via`` poses a repeated option, any other list joined with commas), so
a bad job gets exactly the one-line message the command line prints, and its command's
``compute`` gives the same ``--json`` document.  ``run_job`` is the work done per job in a worker;
robots are loaded once per worker.  The pool, the cluster, resuming and the summary are
``certkin.batch``.
"""
from __future__ import annotations

from functools import partial
import hashlib
import importlib
import importlib.util
import json
import os
import re
import stat
import sys
import time

from ..batch import PENDING, read_jobs, run_batch
from ..batch.jobs import located, shown
from ..batch.results import ERROR, SUMMARY, answer_sha256, certificate_path, document_path, done, file_facts, \
    provenance, row, write_document, write_error
from ..display import printable
from ..errors import InputError, RobotFileError, clip
from ..robots import load_robot, robot_from_dict
from ..robots.files import robot_file_bytes
from ..trajectory.constraints import Constraints
from . import COMMANDS as CLI_COMMANDS
from .common import REPORT_SUFFIXES, Parser, check_output_directory, check_output_path, count, options, refuse, \
    report_writer, write_certificate, write_text_out, writing, writing_in

COMMANDS = ("fk", "singular", "trajectory", "plan", "workspace")
OUTPUTS = ("json", "certificate", "report", "plot", "progress")   # the batch writes a job's outputs itself
FIXED = ("id", "command", "robot")
OUTPUT_NOTES = {None: "the batch writes DIR/<id>.json and DIR/<id>.cert",
                "report": "certkin batch --report writes the campaign's report",
                "progress": "certkin batch --progress shows the batch's progress"}
OPTION_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_-]*")


class JobParser(Parser):
    """A command's parser that raises the message it would print (``InputError``) instead of exiting,
    and knows its options by their exact names only (``"len"`` is not ``lengths``)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, allow_abbrev=False, add_help=False, **kwargs)

    def error(self, message):
        raise InputError("", "", message)

    def exit(self, status=0, message=None):     # an action that would end the process (none is expected)
        raise InputError("", "", (message or "").strip() or "not an option of a job")


_PARSERS: dict = {}
_ROBOTS: dict = {}


def parse_job(job: dict):
    """The command module of a job and its options parsed by that command's own parser."""
    command = job.get("command")
    if command not in COMMANDS:
        raise InputError("command", "", f"expected one of {', '.join(COMMANDS)}, got {shown(command)}")
    module = command_module(command)
    if command not in _PARSERS:
        _PARSERS[command] = JobParser(prog=f"certkin {command}")
        module.add_arguments(_PARSERS[command])
    parser = _PARSERS[command]
    actions = getattr(parser, "_option_string_actions", None)    # argparse's own words mislead here:
    for key, value in job.items():
        if key in FIXED or key in OUTPUTS or not OPTION_NAME.fullmatch(str(key)) or actions is None:
            continue                     # (``job_argv`` explains these)
        action = actions.get("--" + key.replace("_", "-"))
        if action is None:
            raise InputError(clip(repr(key)), "", f"not an option of certkin {command} (see certkin {command} --help)")
        if value is True and action.nargs != 0:
            raise InputError(key, "", "expected a value, got true")
    return module, parser.parse_args(job_argv(job))


def command_module(command: str):
    """The module of a command, imported when a job of it runs (``certkin.cli.COMMANDS``): the batch
    process itself imports none, its workers' fork server those of the batch's jobs (``preload``)."""
    return importlib.import_module(CLI_COMMANDS[command][0])


def preload(jobs: list) -> list[str]:
    """The modules a worker needs for these jobs, to import once in the fork server."""
    return sorted({CLI_COMMANDS[j["command"]][0] for j in jobs if j.get("command") in COMMANDS})


def job_argv(job: dict) -> list[str]:
    """The command-line arguments of a job (``--name=value``, so a value may start with '-')."""
    robot = job.get("robot")
    argv = [robot if isinstance(robot, str) else "<inline robot>"]
    for key, value in job.items():
        if key in FIXED:
            continue
        if key in OUTPUTS and value is not False and value is not None:    # (false or null: left out, as any option)
            raise InputError(key, "", "not an option of a job: " + OUTPUT_NOTES.get(key, OUTPUT_NOTES[None]))
        if not OPTION_NAME.fullmatch(str(key)):
            raise InputError(clip(repr(key)), "", "not an option name (letters, digits, '_' or '-')")
        option = "--" + key.replace("_", "-")
        if value is True:
            argv.append(option)
        elif value is False or value is None:
            continue
        elif isinstance(value, list) and key == "via":
            argv += [f"{option}={_text(_flat(option, v))}" for v in value]
        else:
            argv.append(f"{option}={_text(_flat(option, value))}")
    return argv


BOX_FORMS = 'a box is a text "x=a:b,..." or a list of such items ("x=a:b")'


def _flat(option: str, value):
    """``value`` if it is a number, a text, or a list or table of those (joined by commas); a list or a
    table inside one is refused, naming the item (``{"x": [-1, 1]}`` would read as ``x=-1,1``)."""
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for k, v in items:
        if isinstance(v, (list, dict)):
            what = BOX_FORMS if option == "--box" else "expected numbers or texts, not a list or a table in one"
            field = str(k) if isinstance(value, dict) else f"item {k + 1}"
            raise InputError(option, field, f"{what}, got {shown(value)}")
    return value


def _text(value) -> str:
    if isinstance(value, list):
        return ",".join(_text(v) for v in value)
    if isinstance(value, dict):
        return ",".join(f"{k}={_text(v)}" for k, v in value.items())
    if value is None or isinstance(value, bool):    # inside a list: as the job spelled it, "null", "true"
        return json.dumps(value)
    return str(value)


def robot_of(job: dict):
    """The job's robot and its fingerprint (the SHA-256 of a robot file's bytes, None for an inline
    table, which the job's own text holds), loaded once per worker process and content: a file path
    (keyed by that SHA-256, so a worker that outlives an edit of the file loads it again), or an
    inline robot table."""
    robot = job.get("robot")
    if isinstance(robot, str) and _is_pipe(located(robot)):
        raise InputError("robot", robot, "a named pipe: every worker would wait on it (a job's robot is a regular file)")
    if isinstance(robot, str):
        key = ("file", located(robot), _content_sha256(located(robot)))
        if key[2] is None:                  # unreadable: load_robot gives the command line's message
            return _load_as_given(robot), None
    elif isinstance(robot, dict):
        key = ("table", json.dumps(robot, sort_keys=True, default=str))
    else:
        raise InputError("robot", "", "expected a robot file path or an inline robot table")
    if key not in _ROBOTS:
        try:
            _ROBOTS[key] = _load_as_given(robot) if key[0] == "file" else robot_from_dict(robot, "robot")
        except InputError as exc:
            _ROBOTS[key] = exc
    if isinstance(_ROBOTS[key], InputError):
        raise _ROBOTS[key]
    return _ROBOTS[key], (key[2] if key[0] == "file" else None)


def _load_as_given(path: str):
    """``load_robot`` of a job's robot file, its errors naming the path as the job gives it."""
    try:
        return load_robot(located(path))
    except InputError as exc:
        if exc.source != located(path) or type(exc) not in (InputError, RobotFileError):
            raise
        raise type(exc)(path, exc.field, exc.problem) from None


def robot_fingerprint(job: dict) -> str | None:
    """The fingerprint ``robot_of`` gives the job's robot now (without loading it)."""
    robot = job.get("robot")
    return _content_sha256(located(robot)) if isinstance(robot, str) else None


def _is_pipe(path: str) -> bool:
    try:
        return stat.S_ISFIFO(os.stat(path).st_mode)
    except (OSError, ValueError):
        return False


def _content_sha256(path: str) -> str | None:
    """SHA-256 of a robot file's first ``robots.files.MAX_FILE_BYTES`` + 1 bytes (what ``load_robot`` reads), or
    None when it cannot be read (a named pipe: not read, it would block)."""
    if _is_pipe(path):
        return None
    try:
        return hashlib.sha256(robot_file_bytes(path)).hexdigest()
    except (OSError, ValueError):
        return None


def verdict(command, document: dict) -> str:
    """The answer of a job in one word: fk ``complete`` (``complete-with-clusters`` when some postures
    are only enclosed in clusters)/``incomplete``/``tracked``; singular cells:
    ``singular`` if a cell is, ``singularity-free`` if all are, else ``undecided``; else its status."""
    if command == "fk":
        if document.get("tracked"):
            return "tracked"
        if not document["complete"]:
            return "incomplete"
        clusters = any(s.get("status") == "cluster" for s in document.get("solutions", ()))
        return "complete-with-clusters" if clusters else "complete"
    if command == "singular" and "counts" in document:
        c = document["counts"]
        return "singular" if c["singular"] else "undecided" if c["undecided"] else "singularity-free"
    return document.get("status", "?")


def run_job(job: dict, out: str) -> dict:
    """Answer one job into ``out`` (nothing done if it is answered there already); its summary row.

    Bad input becomes an ``error`` result with the command line's message; a budget that runs out
    is an answer (``undecided``/``incomplete``)."""
    return answer_job(job, out)()


def answer_job(job: dict, out: str, early=None):
    """``run_job`` in two phases (``run_job.phased``, see ``certkin.batch.local.run_chunk``): the job's
    answer computed now, or taken from ``early``: (answer, seconds, CPU seconds) that ``answer_together``
    computed (answer None: a search with other jobs did not answer it, its seconds come off the job's
    ``max_seconds``); returned, a function that writes its files and gives its summary row."""
    t0, c0 = time.perf_counter(), time.process_time()
    if early is not None:                   # (its share of the time of the search it was answered in)
        t0, c0 = t0 - early[1], c0 - early[2]
    try:
        module, args = parse_job(job)           # (first: a job the command refuses is never taken as done)
    except Exception as exc:
        return partial(write_error, out, job, ERROR, _message(exc), time.perf_counter() - t0)
    previous = done(out, job, verdict, partial(robot_fingerprint, job), lambda: robot_of(job)[0].to_dict(),
                    lambda: [i.to_json() for i in Constraints.of(robot_of(job)[0], job.get("constraints")).instances])
    if previous is not None:         # its times: those of this check (the answer's are in its document)
        previous.update(seconds=round(time.perf_counter() - t0, 6), cpu_seconds=round(time.process_time() - c0, 6))
        return lambda: previous
    try:
        path = certificate_path(out, job["id"])
        args.certificate = str(path)         # as ``--certificate``: a search keeps what its certificate needs
        robot, fingerprint = robot_of(job)
        if early is not None and early[0] is None:
            args.max_seconds = max(MIN_SECONDS, args.max_seconds - early[1])
        answer = early[0] if early is not None and early[0] is not None else module.compute(args, robot)
    except Exception as exc:
        return partial(write_error, out, job, ERROR, _message(exc), time.perf_counter() - t0)
    seconds, cpu = time.perf_counter() - t0, time.process_time() - c0

    def finish():
        t1, c1 = time.perf_counter(), time.process_time()
        try:
            facts = None
            if answer.certificate is not None:
                certificate = answer.certificate()
                certificate.header_fields["document_sha256"] = answer_sha256(answer.document)
                facts = file_facts(path, write_certificate(path, certificate))
            else:
                path.unlink(missing_ok=True)
            write_document(out, job, answer.document, provenance(fingerprint, facts))
            return row(job, verdict(job["command"], answer.document), seconds + time.perf_counter() - t1, 1, facts,
                       cpu_seconds=cpu + time.process_time() - c1)
        except Exception as exc:
            return write_error(out, job, ERROR, _message(exc), seconds + time.perf_counter() - t1)
    return finish


def answer_together(tasks: list) -> list:
    """Before the jobs of a chunk run one by one (``run_job.prepare``, see ``certkin.batch.local.run_chunk``):
    its ``fk`` jobs that differ only in their leg lengths are answered together
    (``certkin.cli.fk.compute_together``: each answer the one its job alone gets, certificate included,
    in a fraction of the time).  Per task, (answer, seconds, CPU seconds), None: that job is answered
    alone (and any job when anything here fails), or (None, seconds, CPU seconds): it was searched with
    others for its share of that search, without its answer (the memory ran out, its record went to
    files): it is answered alone in what is left of its ``max_seconds`` (at least ``MIN_SECONDS``)."""
    early, groups = [None] * len(tasks), {}
    for k, (job, out) in enumerate(tasks):
        if job.get("command") != "fk" or document_path(out, job["id"]).exists():
            continue                        # (a job answered before is checked, not answered again)
        try:
            module, args = parse_job(job)
            robot, _ = robot_of(job)
        except Exception:
            continue
        same = repr(sorted((name, value) for name, value in vars(args).items() if name not in ("lengths", "robot")))
        groups.setdefault((out, id(robot), same), []).append((k, args, robot, module))
    for members in groups.values():
        if len(members) < 2:
            continue
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            answers, searched = members[0][3].compute_together([args for _, args, _, _ in members], members[0][2])
        except Exception:
            continue
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        for (k, _, _, _), answer, tried in zip(members, answers, searched):
            if answer is not None:
                early[k] = (answer, wall / len(members), cpu / len(members))
            elif tried:
                early[k] = (None, wall / len(members), 0.0)
    return early


MIN_SECONDS = 0.001      # a job's seconds left after a search with others, at least (a budget is positive)
run_job.phased = answer_job
run_job.prepare = answer_together


def _message(exc: Exception) -> str:
    """The error result of a job that raised: bad input, memory, or a bug (recorded; the batch carries on)."""
    if isinstance(exc, InputError):
        return str(exc)
    if isinstance(exc, MemoryError):
        return "out of memory"
    if isinstance(exc, OSError) and exc.strerror:        # a full disk, an I/O error
        return f"{exc.filename}: {exc.strerror}" if exc.filename is not None else exc.strerror
    return f"internal error: {type(exc).__name__}: {exc}"


def add_arguments(b):
    b.add_argument("jobs", metavar="JOBS.jsonl", help="one job a line (see docs/index.md)")
    b.add_argument("--out", required=True, metavar="DIR", help="directory of the results (DIR/<id>.json, .cert)")
    b.add_argument("--workers", type=count(MAX_WORKERS), default=None,
                   help=f"local worker processes (default {os.cpu_count() or 1}, the number of cores; at most "
                        f"{MAX_WORKERS}, {PER_CORE} per core: more would share the same cores and multiply the memory)")
    b.add_argument("--scheduler", metavar="tcp://HOST:PORT", help="run on this Dask cluster (the dask extra)")
    b.add_argument("--report", metavar="FILE.html", help="write a report of the whole campaign")
    b.add_argument("--json", action="store_true", help="print summary.json instead of the table")
    b.add_argument("--progress", action="store_true", help="show progress on stderr")


PER_CORE = 4
MAX_WORKERS = PER_CORE * (os.cpu_count() or 1)     # each worker holds its own robots, models and job


def _check(args, jobs) -> None:
    """Every option and output path before any job runs (nothing is created for a refused run)."""
    check_output_directory(args.out, "--out")
    if args.report is not None:
        inside = os.path.abspath(os.path.dirname(args.report) or ".") == os.path.abspath(args.out)
        if inside and not os.path.isdir(args.out):          # DIR/report.html: DIR is created by the run
            check_output_path(args.report, "--report", REPORT_SUFFIXES, parent=False)
        else:
            check_output_path(args.report, "--report", REPORT_SUFFIXES)
    if args.scheduler is not None:
        refuse(args, "--workers", "not with --scheduler (the Dask cluster's workers run the jobs)", "workers")
        if not args.scheduler.strip():
            raise InputError("--scheduler", "", "empty address (expected tcp://HOST:PORT)")
        if importlib.util.find_spec("dask") is None or importlib.util.find_spec("distributed") is None:
            raise InputError("--scheduler", args.scheduler, "needs dask.distributed (pip install -e \".[dask]\")")
    if not jobs:
        raise InputError(str(args.jobs), "", "no jobs in the file (one JSON object a line)")
    source = os.path.realpath(args.jobs)
    name = os.path.basename(source)
    ours = os.path.dirname(source) == os.path.realpath(args.out) and (
        name == SUMMARY or any(name in (f"{j['id']}.json", f"{j['id']}.cert") for j in jobs))
    if ours or args.report is not None and os.path.realpath(args.report) == source:
        raise InputError(str(args.jobs), "", "the batch would overwrite its own jobs file (a result or the "
                                             "report has its name): move it or give another --out")
    _answers_kept(args, jobs)


def _answers_kept(args, jobs) -> None:
    """Refuse a run that would replace a job's answer in ``--out`` by an error only because the job's robot
    file is not found from here (relative paths are read from the working directory: a batch resumed
    from another directory), or is no longer a file (a directory in its place)."""
    exists = {}
    for job in jobs:
        robot = job.get("robot")
        if not isinstance(robot, str) or not robot or "id" not in job:
            continue
        if robot not in exists:
            exists[robot] = os.path.isfile(robot)
        if exists[robot]:
            continue
        try:
            document = json.loads(document_path(args.out, job["id"]).read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        if isinstance(document, dict) and document.get("status") != ERROR:
            raise InputError(str(args.jobs), f"job {job['id']}", f"robot file {robot} not found from "
                             f"{os.getcwd()} (or not a file), and {args.out} holds this job's answer: the run would replace it by "
                             "an error (relative paths are read from the working directory: run from the directory "
                             "of the first run)")


def run(args):
    if not args.jobs.strip():
        raise InputError("JOBS.jsonl", "", "empty file name")
    jobs = read_jobs(args.jobs)
    _check(args, jobs)
    bar = []                              # --progress: the bar, from the first job's end (not before a refusal)

    def tick(row):
        if not bar:
            from tqdm import tqdm         # a bar only with --progress
            bar.append(tqdm(total=len(jobs), desc="jobs", unit="job", file=sys.stderr, leave=False))
        bar[0].update(1)
    with options({"out": "--out", "scheduler": "--scheduler"}), writing_in("--out", args.out):
        workers = args.workers or os.cpu_count() or 1
        summary = run_batch(jobs, args.out, run_job, workers, args.scheduler, tick if args.progress else None,
                            preload(jobs))
    for b in bar:
        b.close()
    if args.report:
        with writing("--report", args.report):
            report_writer("batch_report")(summary, args.out, args.report)
    write_text_out(sys.stdout, (json.dumps(summary, allow_nan=False) if args.json else table(summary, args.out)) + "\n")
    return 130 if summary["interrupted"] else 0


SHOWN = 8       # ids listed per line of the table


def table(summary: dict, out) -> str:
    """The summary on one screen: counts by verdict, undecided, broken and failed jobs, times."""
    lines = [f"certkin batch: {summary['jobs']} jobs -> {out} ({summary['workers']} workers): "
             f"{summary['seconds']:.2f} s, {summary['job_seconds']:.2f} s in jobs"]
    width = max([len(k) for k in summary["counts"]] + [10])
    for key, n in summary["counts"].items():
        lines.append(f"  {key:{width}s} {n:7d}")
    lines.append(f"  resumed (already done) {summary['resumed']}, retried after a worker died "
                 f"{len(summary['retried'])}")
    for name, ids in (("undecided", summary["undecided"]), ("retried", summary["retried"])):
        if ids:
            lines.append(f"  {name}: " + ", ".join(ids[:SHOWN]) + (" ..." if len(ids) > SHOWN else ""))
    for name in ("errors", "failed"):
        for e in summary[name][:SHOWN // 2]:
            lines.append(f"  {name[:-1] if name == 'errors' else 'failed'} {e['id']}: {e['error']}")
        if len(summary[name]) > SHOWN // 2:
            lines.append(f"  ... {len(summary[name]) - SHOWN // 2} more {name} (summary.json)")
    if summary["slowest"]:
        lines.append("  slowest: " + ", ".join(f"{s['id']} {s['seconds']:.3f} s" for s in summary["slowest"]))
    pending = sum(r["verdict"] == PENDING for r in summary["results"])
    if summary["interrupted"]:
        lines.append(f"  INTERRUPTED: {pending} jobs not run or not re-checked in this run (pending; files an earlier "
                     "run wrote are kept); the same command resumes the batch")
    return "\n".join(printable(line) for line in lines)      # a jobs file's text cannot forge a line
