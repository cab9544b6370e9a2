"""``certkin jobs grid`` on hostile input (issue #18): counts, sizes, values and options checked,
nothing printed for a refused grid, never a million-line surprise."""
import json
import os
import subprocess
import sys

import pytest

from conftest import R2, ROOT, answered, refused

G = ["jobs", "grid", R2]
FK = G + ["--command", "fk", "--lengths", "L1=28:30:3,L2=13.66,L3=40.53"]
CELLS = G + ["--command", "singular", "--box", "x=-1:1,y=0:1,phi=0:0.1"]
TRAJ = G + ["--command", "trajectory", "--from", "x=0:1,y=0:1,phi=0", "--to", "x=0:1,y=0:1,phi=0"]
TRAJ_GRID = G + ["--command", "trajectory", "--from", "x=0:1:2,y=0,phi=0", "--to", "x=2,y=0,phi=0"]

HOSTILE = [
    (G + ["--command", "fk"], ["--lengths"]),
    (G + ["--command", "fk", "--lengths", ""], ["--lengths"]),
    (G + ["--command", "fk", "--lengths", "L1=1:2:0,L2=1,L3=1"], ["--lengths", "L1"]),
    (G + ["--command", "fk", "--lengths", "L1=1:2:-1,L2=1,L3=1"], ["--lengths", "L1"]),
    (G + ["--command", "fk", "--lengths", "L1=1:2:1e300,L2=1,L3=1"], ["--lengths", "L1", "'1e300'"]),
    (G + ["--command", "fk", "--lengths", "L1=nan:2:3,L2=1,L3=1"], ["--lengths", "L1"]),
    (G + ["--command", "fk", "--lengths", "L1=1:1e300:3,L2=1,L3=1"], ["--lengths", "L1", "out of range"]),
    (G + ["--command", "fk", "--lengths", "L1=1:2:1000,L2=1:2:1000,L3=1:2:1000"], ["--lengths", "jobs"]),
    (G + ["--command", "fk", "--lengths", "L1=28:30:\u0663,L2=1,L3=1"], ["--lengths", "L1"]),   # once: Arabic-Indic 3
    (G + ["--command", "fk", "--lengths", "L1=28:30:1_0,L2=1,L3=1"], ["--lengths", "L1"]),
    (G + ["--command", "fk", "--lengths", "L1=28:30:+2,L2=1,L3=1"], ["--lengths", "L1"]),
    (G + ["--command", "fk", "--lengths", "L1=28:28.0000000000000001:3,L2=1,L3=1"], ["--lengths", "L1", "repeat"]),
    (G + ["--command", "singular", "--box", "x=28:28.0000000000000001,y=0:1,phi=0", "--cells", "3"],
     ["--box", "x", "repeat"]),                                        # once: 3 cells x=28:28
    (CELLS + ["--cells", "0"], ["--cells"]),
    (CELLS + ["--cells", "-1"], ["--cells"]),
    (CELLS + ["--cells", "1e300"], ["--cells", "'1e300'"]),
    (CELLS + ["--cells", "100000"], ["--cells", "jobs"]),              # 10^15 cells (once: out of memory)
    (CELLS + ["--cells", "2", "--cells", "3"], ["--cells", "twice"]),
    (TRAJ + ["--count", "0"], ["--count"]),
    (TRAJ + ["--count", "-1"], ["--count"]),
    (TRAJ + ["--count", "1000000000000"], ["--count"]),               # once: out of memory
    (TRAJ + ["--count", "2", "--seed", "-1"], ["--seed"]),            # once: numpy's traceback
    (TRAJ + ["--count", "2", "--seed", "9223372036854775808"], ["--seed", "from 0 to 9223372036854775807,"]),
    (TRAJ + ["--count", "2", "--decimals", "99"], ["--decimals"]),
    (TRAJ + ["--count", "2", "--decimals", "nan"], ["--decimals"]),
    (FK + ["--box", "x=1"], ["--box", "fk"]),                          # an option of another command
    (FK + ["--count", "3"], ["--count", "fk"]),
    (FK + ["--set", ""], ["--set"]),
    (FK + ["--set", "max_seconds=nan"], ["--set", "--max-seconds"]),   # checked as the batch will read it
    (FK + ["--set", "bogus=1"], ["--set", "'bogus': not an option of certkin fk"]),
    (FK + ["--set", "certificate=x"], ["--set", "certificate"]),
    (FK + ["--set", "lengths=1,2,3"], ["--set", "lengths", "--lengths"]),   # once: every job the same lengths
    (FK + ["--set", "id=x"], ["--set", "id", "--prefix"]),                  # once: every job the same id
    # values the command line refuses were written into every job, each then an error in the batch
    (G + ["--command", "fk", "--lengths", "L1=２８:30:3,L2=13,L3=40"], ["--lengths", "leg 1", "in job fk-0"]),
    (G + ["--command", "fk", "--lengths", "L1=1_0:30:3,L2=13,L3=40"], ["--lengths", "leg 1", "plain decimal"]),
    (G + ["--command", "fk", "--lengths", "L1=-30:-28:2,L2=13,L3=40"], ["--lengths", "cannot be negative"]),
    (G + ["--command", "fk", "--lengths", "L1=1e-500:1:2,L2=13,L3=40"], ["--lengths", "below 1e-400"]),
    (G + ["--command", "fk", "--lengths", "L1=28:28:3,L2=13,L3=40"], ["--lengths", "L1", "identical jobs"]),
    (CELLS[:-1] + ["x=-1:1,y=0:1,phi=0:1e7", "--cells", "2"], ["--box", "phi", "out of range for an angle"]),
    (FK + ["--set", "domain=x=nan:1"], ["--domain", "x", "not a finite number"]),
    (FK + ["--set", "track=nan,0,0"], ["--track", "not a finite number"]),
    (CELLS + ["--cells", "1", "--set", "scale=1,1,1"], ["--scale", "only with --around"]),
    (FK + ["--set", "robot=other.toml"], ["--set", "robot"]),
    (FK + ["--set", "command=singular"], ["--set", "command"]),
    (CELLS + ["--cells", "2", "--set", "box=x=0:1"], ["--set", "box"]),
    (TRAJ + ["--count", "2", "--set", "from=0,0,0"], ["--set", "from", "--from"]),
    (FK + ["--set", "max_boxes=5", "--set", "max-boxes=6"], ["--set", "twice"]),   # once: the last one won
    (FK + ["--prefix", "../x"], ["--prefix"]),
    (FK + ["--prefix", "line"], ["--prefix", "reserved"]),                 # once: every job an error in the batch
    (FK + ["--prefix", "p" * 122], ["--prefix", "at most 121 characters"]),
    (TRAJ_GRID + ["--count", "5"], ["--count", "grid"]),                    # once: ignored
    (TRAJ_GRID + ["--seed", "5"], ["--seed", "grid"]),
    (TRAJ_GRID + ["--decimals", "2"], ["--decimals", "grid"]),
    (FK + ["--prefix", ""], ["--prefix"]),
    (["jobs", "grid", "{tmp}", "--command", "fk", "--lengths", "L1=1,L2=1,L3=1"], ["directory"]),
    (["jobs"], ["required: grid"]),
]


@pytest.mark.parametrize("argv, words", HOSTILE, ids=[" ".join(a[3:])[-60:] for a, _ in HOSTILE])
def test_hostile_input_is_refused(cli, argv, words):
    refused(cli(*argv), *words)


def test_a_grid_prints_checked_jobs(cli):
    run = cli(*FK, "--set", "max_seconds=5", "--prefix", "p")
    answered(run)
    lines = [json.loads(line) for line in run.out.splitlines()]
    assert [j["id"] for j in lines] == ["p-0", "p-1", "p-2"]
    assert [j["lengths"] for j in lines] == ["28,13.66,40.53", "29,13.66,40.53", "30,13.66,40.53"]
    assert all(j["max_seconds"] == "5" for j in lines)


def test_a_reader_that_closes_the_pipe_early_gets_no_traceback():
    """``certkin jobs grid ... | head -1``: exit 141 (the pipe closed), no traceback on stderr."""
    argv = [sys.executable, "-m", "certkin", *G, "--command", "fk", "--lengths", "L1=28:29:50,L2=13:14:50,L3=40:41:20"]
    p = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=ROOT,
                         env={**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])})
    first = p.stdout.readline()
    p.stdout.close()                                  # 50 000 lines: far more than a pipe holds
    err = p.stderr.read().decode()
    assert json.loads(first)["id"] == "fk-00000"
    assert p.wait(timeout=120) == 141 and err == "", err


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full on this system")
@pytest.mark.parametrize("argv", [
    [*G, "--command", "fk", "--lengths", "L1=28:29:50,L2=13:14:50,L3=40:41:2"],     # more than a buffer
    [*G, "--command", "fk", "--lengths", "L1=28:29:2,L2=13.66,L3=40.53"],          # flushed at the end
], ids=["large", "small"])
def test_a_full_disk_under_stdout_is_one_line_and_exit_2(argv):
    """Standard output on a full disk (``> /dev/full``): one line saying so, exit 2, no traceback."""
    with open("/dev/full", "w") as full:
        run = subprocess.run([sys.executable, "-m", "certkin", *argv], stdout=full, stderr=subprocess.PIPE, cwd=ROOT,
                             text=True, timeout=120, env={**os.environ, "PYTHONPATH": os.pathsep.join(
                                 [str(ROOT), os.environ.get("PYTHONPATH", "")])})
    assert run.returncode == 2 and run.stderr == "certkin: error: standard output: No space left on device\n", run.stderr


def test_a_grid_of_cell_jobs_with_cells_set_is_accepted(tmp_path):
    """``--set cells=3`` on singular jobs: the check of the first and last jobs ran them with a budget of
    one box, which refused their 27 cells; the jobs are fine (the batch answers them)."""
    out = subprocess.run([sys.executable, "-m", "certkin", *CELLS, "--cells", "2", "--set", "cells=3"],
                         capture_output=True, text=True, cwd=ROOT)
    assert out.returncode == 0, out.stderr
    jobs = [json.loads(line) for line in out.stdout.splitlines()]
    assert len(jobs) == 8 and all(j["cells"] == "3" or j["cells"] == 3 for j in jobs)
