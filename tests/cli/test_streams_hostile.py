"""The command line with its standard streams closed or full (``>&-``, ``2>&-``, ``2>/dev/full``)."""
import os
from pathlib import Path
import subprocess
import sys

import pytest

from conftest import MICRO, ROOT

Z = ["workspace", MICRO, "--z", "20005", "--min-width", "0.05"]


def certkin(argv, tmp_path, redirect=""):
    """``python -m certkin argv`` run by the shell with ``redirect`` (``2>&-``, ``2>/dev/full``)."""
    return subprocess.run(["sh", "-c", f'"$0" -m certkin "$@" {redirect}', sys.executable, *argv],
                          capture_output=True, text=True, cwd=tmp_path, timeout=120,
                          env={**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])})


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
def test_a_full_stderr_does_not_stop_the_answer(tmp_path):
    """With --progress and stderr on a full disk the bar's write raised OSError: exit 1, no answer."""
    run = certkin(Z + ["--progress"], tmp_path, "2>/dev/full")
    assert run.returncode == 0 and "section z = 20005" in run.stdout


def test_a_closed_stderr_does_not_stop_the_answer_nor_change_the_exit_code(tmp_path):
    """With stderr closed, --progress ended the command (exit 1, no answer), and a refusal exited 1
    (its message's write raised AttributeError), not 2."""
    run = certkin(Z + ["--progress"], tmp_path, "2>&-")
    assert run.returncode == 0 and "section z = 20005" in run.stdout
    bad = certkin(Z + ["--z", "x"], tmp_path, "2>&-")
    assert bad.returncode == 2 and bad.stdout == ""


def test_a_closed_stdout_is_refused_before_anything_is_solved_or_written(tmp_path):
    """With stdout closed the whole search ran, the certificate was written, then printing raised
    AttributeError (a traceback, exit 1)."""
    run = certkin(Z + ["--certificate", "c.cert"], tmp_path, ">&-")
    assert run.returncode == 2, run.stderr
    assert run.stderr == "certkin: error: standard output is closed: nowhere to print the answer\n"
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("redirect", ["2>/dev/full", "2>&-"])
def test_the_checker_s_progress_bar_on_a_full_or_closed_stderr_does_not_stop_the_check(tmp_path, redirect):
    """``certkin check --progress`` with stderr full or closed: the bar's write raised (exit 1, no account
    printed); a certificate that checks now gives its account and exit 0."""
    if redirect == "2>/dev/full" and not Path("/dev/full").exists():
        pytest.skip("needs /dev/full")
    made = certkin(Z + ["--certificate", "c.cert"], tmp_path)
    assert made.returncode == 0, made.stderr
    run = certkin(["check", "c.cert", "--progress"], tmp_path, redirect)
    assert run.returncode == 0 and "OK:" in run.stdout, (run.returncode, run.stdout[-300:])
    run = subprocess.run(["sh", "-c", f'"$0" -m proofs c.cert --progress {redirect}', sys.executable],
                         capture_output=True, text=True, cwd=tmp_path, timeout=120,
                         env={**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])})
    assert run.returncode == 0 and "OK:" in run.stdout
