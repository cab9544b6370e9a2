"""Running the command line on hostile input: in-process for most cases (one process for a whole
table), in a subprocess under a memory limit (``resource.setrlimit``) where the ceiling or a
traceback on the real stderr is what is tested.

Every case asserts the exit code, a one-line message on stderr that names the option, no
traceback, and no file left behind in the run's directory."""
from __future__ import annotations

from dataclasses import dataclass
import os
from pathlib import Path
import subprocess
import sys
import time

import pytest

from certkin.cli import main

ROOT = Path(__file__).resolve().parents[2]
ROBOTS = ROOT / "examples" / "robots"
R2 = str(ROBOTS / "seed003-planar-example-2.toml")          # planar 3-RPR
MEL = str(ROBOTS / "seed000-mel-tsukuba.toml")              # Gough-Stewart with leg limits and radius
MICRO = str(ROBOTS / "seed004-micro-manipulator.toml")      # Gough-Stewart for the workspace
SPHERICAL = str(ROBOTS / "seed003-spherical-example-1.toml")

MEMORY_LIMIT = 3 * 2 ** 30       # address space of a limited run: the 2 GiB ceiling plus the interpreter's


@dataclass
class Run:
    code: int
    out: str
    err: str
    seconds: float
    left: list                    # files in the run's directory afterwards


def _files(directory: Path) -> list:
    return sorted(p.name for p in directory.iterdir())


@pytest.fixture
def cli(tmp_path, capsys, monkeypatch):
    """``cli(*argv)``: ``certkin.cli.main`` in this process, in ``tmp_path`` (``{tmp}`` in an argument
    is replaced by that directory); returns a ``Run``."""
    monkeypatch.chdir(tmp_path)

    def run(*argv) -> Run:
        argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
        before = set(_files(tmp_path))
        capsys.readouterr()
        t0 = time.perf_counter()
        try:
            code = main(argv)
        except SystemExit as exc:
            code = exc.code
        seconds = time.perf_counter() - t0
        out, err = capsys.readouterr()
        return Run(code, out, err, seconds, sorted(set(_files(tmp_path)) - before))
    return run


def limited(argv, tmp_path, memory=MEMORY_LIMIT, timeout=300, file_size=None) -> Run:
    """``certkin argv`` in a subprocess whose address space is limited to ``memory`` bytes (and each
    file it writes to ``file_size`` bytes, if given: a write past it fails, as on a full disk)."""
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    files = "" if file_size is None else f"resource.setrlimit(resource.RLIMIT_FSIZE, ({file_size}, {file_size}))\n"
    code = ("import resource, sys\n"
            f"resource.setrlimit(resource.RLIMIT_AS, ({memory}, {memory}))\n" + files +
            "from certkin.cli import main\n"
            f"sys.exit(main({argv!r}))\n")
    before = set(_files(tmp_path))
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, timeout=timeout,
                       env={**os.environ, "PYTHONWARNINGS": "default",        # this checkout's certkin
                            "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])})
    return Run(p.returncode, p.stdout, p.stderr, time.perf_counter() - t0, sorted(set(_files(tmp_path)) - before))


def refused(run: Run, *words: str) -> None:
    """Exit 2, one line on stderr naming ``words`` (an option, a field), nothing on stdout, no
    traceback, no file left behind."""
    assert run.code == 2, (run.code, run.err, run.out[:300])
    lines = run.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("certkin: error: "), run.err
    for w in words:
        assert w in lines[0], (w, lines[0])
    assert "Traceback" not in run.err and run.out == ""
    assert run.left == [], run.left


def answered(run: Run, *words: str) -> None:
    """Exit 0 with an answer on stdout (containing ``words``), no traceback, no warning."""
    assert run.code == 0, (run.code, run.err)
    assert "Traceback" not in run.err and "Warning" not in run.err, run.err
    for w in words:
        assert w in run.out, (w, run.out[:500])
