"""``keep_freed_memory`` (certkin.allocator): set on glibc, the same answers, no page faults per call.

Each case runs in a fresh process: the allocator's thresholds are the whole process's and stay set."""
import json
import platform
import subprocess
import sys
from pathlib import Path

import pytest

ROBOT = Path(__file__).resolve().parent.parent / "examples" / "robots" / "seed000-mel-tsukuba.toml"

PROGRAM = r"""
import json, resource, sys
import certkin
tuned = certkin.keep_freed_memory() if sys.argv[1] == "1" else None
robot = certkin.load_robot(sys.argv[2])
paths = [("-49.722,5.477,520,85deg,10deg,0", "-10.019,57.933,520,85deg,10deg,0"),
         ("-69,-50,500,85deg,10deg,0", "84,92,500,85deg,10deg,0")] * 6
certkin.verify_trajectory(robot, *paths[0])
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
answers = [certkin.verify_trajectory(robot, *p).to_json() for p in paths]
faults = (resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before) / len(paths)
from certkin.batch.results import untimed
print(json.dumps({"tuned": tuned, "faults": faults, "answers": untimed(answers)}))
"""


def run(tuned: bool) -> dict:
    out = subprocess.run([sys.executable, "-c", PROGRAM, "1" if tuned else "0", str(ROBOT)], capture_output=True,
                         text=True, check=True)
    return json.loads(out.stdout)


@pytest.mark.skipif(platform.system() != "Linux" or platform.libc_ver()[0] != "glibc", reason="glibc's malloc only")
def test_freed_memory_is_kept_and_answers_do_not_change():
    plain, tuned = run(False), run(True)
    assert tuned["tuned"] is True
    assert tuned["answers"] == plain["answers"]
    assert tuned["faults"] < 50, tuned["faults"]     # untuned: about 1 800 a call on glibc 2.36


def test_the_command_line_and_the_batch_workers_local_or_dask_keep_freed_memory():
    from certkin.batch import cluster, local
    from certkin import cli
    for module in (cli, local, cluster):
        assert "keep_freed_memory()" in Path(module.__file__).read_text()
