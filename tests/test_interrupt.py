"""Ctrl-C: a long command prints what it proved so far, marked interrupted, and writes a partial
certificate that still checks; a batch stops, says so, and resumes."""
from __future__ import annotations

import json
import os
from pathlib import Path
import signal
import subprocess
import sys
import time

import pytest

import proofs
from certkin.cli import fk, singular, trajectory
from certkin.cli import main

ROOT = Path(__file__).resolve().parent.parent
PLANAR = str(ROOT / "examples" / "robots" / "seed003-planar-example-2.toml")
MEL = str(ROOT / "examples" / "robots" / "seed000-mel-tsukuba.toml")


@pytest.fixture
def ctrl_c_after_first_batch(monkeypatch):
    """The progress callback of the engine sends this process a real SIGINT after its first batch."""
    def progress(enabled):
        if not enabled:
            return None
        sent = []

        def update(processed, frontier):
            if not sent:
                sent.append(True)
                os.kill(os.getpid(), signal.SIGINT)
        return update
    for module in (fk, singular, trajectory):
        monkeypatch.setattr(module, "progress", progress)


@pytest.mark.parametrize("argv", [
    ["singular", PLANAR, "--box", "x=-50:50,y=-50:50,phi=0:0.7853981634", "--cells", "8"],
    ["fk", PLANAR, "--lengths", "28.99,13.66,40.53"],
    ["trajectory", MEL, "--from", "-69,-50,500,85deg,10deg,0", "--to", "84,92,500,85deg,10deg,0"],
])
def test_ctrl_c_prints_the_partial_answer_and_writes_a_checkable_certificate(argv, ctrl_c_after_first_batch,
                                                                            tmp_path, capsys):
    cert = tmp_path / "partial.cert"
    assert main(argv + ["--progress", "--certificate", str(cert)]) == 130
    assert capsys.readouterr().out.startswith("INTERRUPTED (Ctrl-C): what was proved before the interrupt")
    assert main(argv + ["--progress", "--json"]) == 130
    doc = json.loads(capsys.readouterr().out)
    assert doc["interrupted"] is True
    if argv[0] == "fk":
        assert doc["complete"] is False
    elif argv[0] == "singular":
        assert doc["counts"]["undecided"] > 0
    else:
        assert doc["status"] == "undecided" or doc["status"] == "infeasible"
    report = proofs.check_file(cert)
    assert report.ok, report.summary()
    assert main(argv) == 0                      # without Ctrl-C: the whole answer, not marked
    assert not capsys.readouterr().out.startswith("INTERRUPTED")


def test_ctrl_c_stops_a_batch_which_then_resumes(tmp_path):
    lines = subprocess.run([sys.executable, "-m", "certkin.cli", "jobs", "grid", MEL, "--command", "trajectory",
                            "--from", "x=-60:60,y=-60:60,z=520,psi=85deg,theta=10deg,phi=0",
                            "--to", "x=-60:60,y=-60:60,z=520,psi=85deg,theta=10deg,phi=0", "--count", "400"],
                           capture_output=True, text=True, check=True).stdout
    (tmp_path / "jobs.jsonl").write_text(lines)
    out = tmp_path / "out"
    argv = [sys.executable, "-m", "certkin.cli", "batch", str(tmp_path / "jobs.jsonl"), "--out", str(out),
            "--workers", "2"]
    process = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    t0 = time.time()
    while len(list(out.glob("*.json"))) < 3:
        assert process.poll() is None and time.time() - t0 < 120
        time.sleep(0.05)
    process.send_signal(signal.SIGINT)
    stdout, _ = process.communicate(timeout=60)
    summary = json.loads((out / "summary.json").read_text())
    if process.returncode == 0:
        pytest.skip("the batch finished before the interrupt arrived")
    assert process.returncode == 130 and summary["interrupted"]
    assert "INTERRUPTED" in stdout and "jobs not run" in stdout
    done = [r for r in summary["results"] if r["verdict"] != "pending"]
    assert 0 < len(done) < 400
    rerun = subprocess.run(argv, capture_output=True, text=True, timeout=600)
    assert rerun.returncode == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["resumed"] >= len(done) and not summary["interrupted"]
    assert all(r["verdict"] in ("feasible", "infeasible", "undecided") for r in summary["results"])


@pytest.mark.parametrize("at", [1, 3])
def test_ctrl_c_stops_a_plan(monkeypatch, capsys, at):
    """The plan's search over the grid stops at the first Ctrl-C (it once went on until its time budget).
    A Ctrl-C between two batches of segments (``at`` 3: after the grid's first batch, when no search runs
    to notice it) stopped the plan too, but its answer was printed as unaffected ("Ctrl-C came after the
    searches had ended"), without ``interrupted``."""
    from certkin.cli import plan

    def progress(enabled, *args):
        calls = []

        def update(done, batch):
            calls.append(True)
            if len(calls) == at:
                os.kill(os.getpid(), signal.SIGINT)
        return update
    monkeypatch.setattr(plan, "progress", progress)
    t0 = time.perf_counter()
    code = main(["plan", MEL, "--from", "-90,140,520,0,0,0", "--to", "55,140,520,0,0,0", "--divisions", "200",
                 "--max-seconds", "600", "--json"])
    assert code == 130 and time.perf_counter() - t0 < 60
    doc = json.loads(capsys.readouterr().out)
    assert doc["interrupted"] is True and doc["status"] != "found"
    import certkin          # the request ends with the command: a later search in this process runs in full
    r = certkin.certify_singularity_free(PLANAR, "x=-20:-10,y=20:30,phi=0:0.3")
    assert r.status == "singularity-free"


def test_ctrl_c_after_the_search_ended_is_not_swallowed(monkeypatch, tmp_path, capsys):
    """A Ctrl-C while the answer of a finished search was being built left no trace (exit 0, nothing
    said).  The answer, whole, is printed and written; stderr says so; the exit code is 130."""
    from certkin import singularity
    real = singularity._verdicts

    def verdicts(problem, tree):             # right after the search: a real SIGINT
        os.kill(os.getpid(), signal.SIGINT)
        return real(problem, tree)
    monkeypatch.setattr(singularity, "_verdicts", verdicts)
    cert = tmp_path / "whole.cert"
    argv = ["singular", PLANAR, "--box", "x=-50:50,y=-50:50,phi=0:0.7853981634", "--cells", "4", "--certificate", str(cert)]
    assert main(argv) == 130
    out, err = capsys.readouterr()
    assert "Ctrl-C came after the searches had ended: the answer above is theirs, unchanged" in err
    assert not out.startswith("INTERRUPTED") and "64 cells" in out
    assert proofs.check_file(cert).ok


def test_ctrl_c_while_the_answer_is_written_leaves_it_whole(monkeypatch, tmp_path, capsys):
    """Building and writing the answer of many cells took most of a run; a Ctrl-C then aborted with
    nothing written.  Now the first one there leaves the answer whole (exit 130, stderr says so)."""
    from certkin.cli import singular as singular_cli
    real = singular_cli._text

    def text(*args):                          # while the answer is shown: a real SIGINT
        os.kill(os.getpid(), signal.SIGINT)
        return real(*args)
    monkeypatch.setattr(singular_cli, "_text", text)
    cert = tmp_path / "whole.cert"
    argv = ["singular", PLANAR, "--box", "x=-50:50,y=-50:50,phi=0:0.7853981634", "--cells", "4", "--certificate", str(cert)]
    assert main(argv) == 130
    out, err = capsys.readouterr()
    assert "answer above is theirs, unchanged" in err and "64 cells" in out
    assert proofs.check_file(cert).ok


def test_ctrl_c_stops_a_trajectory_with_a_moving_orientation_at_once(capsys):
    """A Ctrl-C during a long search with a moving orientation (batches of costly pieces) ended the
    command seconds later: the leaves the search had left were then evaluated until the time budget
    ran out, and that time was reported as the search's."""
    import threading
    timer = threading.Timer(2.5, os.kill, (os.getpid(), signal.SIGINT))
    t0 = time.perf_counter()
    timer.start()
    try:
        code = main(["trajectory", MEL, "--from", "-69,-50,500,0,10deg,0", "--to", "84,92,500,10000,10deg,0",
                     "--max-seconds", "8", "--json"])
    finally:
        timer.cancel()
    elapsed = time.perf_counter() - t0
    doc = json.loads(capsys.readouterr().out)
    assert code == 130 and doc["interrupted"] is True and doc["status"] == "undecided"
    assert elapsed < 2.5 + 1.0                       # (it went on for 2 s more)
    assert doc["stats"]["seconds"] <= elapsed


def test_an_earlier_interrupted_command_does_not_cost_a_later_call_its_indices():
    """``cut_short()`` stays true once a command was cut short by Ctrl-C (the command line reads it after
    the answer is built), and a later ``verify_trajectory`` in the same process (the API, the next test of
    a worker) left out its mean margins.  Only a Ctrl-C of the call itself leaves them out now."""
    from certkin import load_robot, verify_trajectory
    from certkin.engine import interrupt
    interrupt.cut()                          # what an interrupted command leaves behind
    try:
        r = verify_trajectory(load_robot(MEL), "-69,-50,500,85deg,10deg,0", "84,92,500,85deg,10deg,0")
    finally:
        with interrupt.interruptible():     # (entering resets the state)
            pass
    assert r.indices is not None and len(r.indices) == 6 + 15
