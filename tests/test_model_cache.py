"""The compiled models kept on disk (``certkin.robots.models``): an entry gives the very evaluator
the compiler makes; a stale, corrupt or malformed entry is never used but rebuilt; concurrent
processes share the cache safely; a batch worker reloads a robot file that changed."""
from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from certkin import load_robot, robot_from_dict, verify_trajectory
from certkin.batch.results import untimed
from certkin.cli.batch import run_job
from certkin.robots import models
from intervals import Interval

ROOT = Path(__file__).resolve().parent.parent
PLANAR = ROOT / "examples" / "robots" / "seed003-planar-example-2.toml"
MEL = ROOT / "examples" / "robots" / "seed000-mel-tsukuba.toml"
QUESTIONS = ("det", "A", "legs_sq", "points", "leg_vectors")


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """An empty cache directory of its own; this process's answers forgotten before and after."""
    monkeypatch.setenv("CERTKIN_CACHE_DIR", str(tmp_path / "cache"))
    models.forget()
    yield tmp_path / "cache"
    models.forget()


def no_sympy(monkeypatch):
    """Fail the test if a model is compiled (sympy) instead of read from the disk."""
    def refuse():
        raise AssertionError("compiled again: the disk entry was not used")
    monkeypatch.setattr(models, "symbolic", refuse)


def boxes(robot, n=64, seed=1):
    """Random pose boxes, some of them wide."""
    rng = np.random.default_rng(seed)
    d = len(robot.pose_names)
    mid = rng.uniform(-2, 2, (n, d))
    rad = rng.uniform(0, 0.3, (n, d))
    return Interval.from_bounds(mid - rad, mid + rad)


def evaluate(robot, what):
    ev = robot.compiled(what)
    b = boxes(robot)
    v = ev(b, robot.parameters)
    val, jac = ev.jacobian(b, robot.parameters)
    return [v.lo, v.hi, val.lo, val.hi, jac.lo, jac.hi]


@pytest.mark.parametrize("path", [PLANAR, MEL, ROOT / "examples" / "robots" / "seed003-spherical-example-1.toml"])
def test_an_entry_gives_the_compilers_evaluator_bit_for_bit(cache, monkeypatch, path):
    robot = load_robot(path)
    questions = [q for q in QUESTIONS if q != "det" or robot.symbolic_det]
    questions += ["R"] if robot.kind != "planar-3rpr" else []
    fresh = {q: evaluate(robot, q) for q in questions}
    sources = {q: robot.compiled(q).source for q in questions}
    facts = (robot.model_parts(), robot.rigid_legs())
    assert facts[0] == frozenset(robot.symbolic_model())
    assert len(list(cache.glob("*.json"))) == len(questions) + 2
    models.forget()
    no_sympy(monkeypatch)
    for q in questions:
        assert robot.compiled(q).source == sources[q]
        for a, b in zip(evaluate(robot, q), fresh[q]):
            assert np.array_equal(a, b) and a.dtype == b.dtype          # the same enclosures, bit for bit
    assert (robot.model_parts(), robot.rigid_legs()) == facts


def test_the_trajectory_verdicts_are_the_same_from_the_disk(cache, monkeypatch):
    robot = load_robot(MEL)
    ends = [("1,2,520,85deg,10deg,0", "30,-20,520,85deg,10deg,0"),
            ("-60,-60,520,85deg,10deg,0", "60,60,520,85deg,10deg,0")]
    first = [verify_trajectory(robot, a, b).to_json() for a, b in ends]
    models.forget()
    no_sympy(monkeypatch)
    again = [verify_trajectory(load_robot(MEL), a, b).to_json() for a, b in ends]
    assert untimed(first) == untimed(again) and len(first) == 2


def entry(cache, question):
    (path,) = cache.glob(f"*.{question}.*.json")
    return path


@pytest.mark.parametrize("damage", ["truncated", "flipped", "not json", "empty", "other key", "no compile",
                                    "wrong shape", "bad constant"])
def test_a_corrupt_entry_is_ignored_and_rebuilt(cache, damage):
    robot = load_robot(PLANAR)
    reference = evaluate(robot, "det")
    source = robot.compiled("det").source
    path = entry(cache, "det")
    text = path.read_text()
    data = json.loads(text)

    def resealed(change):            # altered, with a checksum that matches: the shape checks refuse it
        change(data["value"])
        data["sha256"] = hashlib.sha256(json.dumps(data["value"], sort_keys=True).encode()).hexdigest()
        return json.dumps(data)
    damaged = {
        "truncated": lambda: text[:len(text) // 2],
        "flipped": lambda: text.replace("v[0]", "v[1]", 1),           # the checksum no longer matches
        "not json": lambda: "\x00\x01garbage",
        "empty": lambda: "",
        "other key": lambda: json.dumps({**data, "key": "0" * 64}),
        "no compile": lambda: resealed(lambda v: v.update(source="def _f(v, p):\n    return [(\n")),
        "wrong shape": lambda: resealed(lambda v: v.update(variables=v["variables"] + 1)),
        "bad constant": lambda: resealed(lambda v: v["constants"].update(_c0=["0x1p+0", "0x1p-1"])),
    }[damage]()
    path.write_text(damaged)
    models.forget()
    assert robot.compiled("det").source == source
    for a, b in zip(evaluate(robot, "det"), reference):
        assert np.array_equal(a, b)
    rebuilt = json.loads(path.read_text())                 # overwritten with a valid entry
    assert rebuilt["value"]["source"] == source and rebuilt["key"] == models.key(type(robot))
    assert rebuilt["sha256"] == hashlib.sha256(json.dumps(rebuilt["value"], sort_keys=True).encode()).hexdigest()


def test_a_stale_entry_is_never_used(cache, monkeypatch, tmp_path):
    """The key covers the sources the model depends on: change one, and the entry is not found."""
    robot = load_robot(PLANAR)
    assert {p.name for p in models.sources(type(robot))} == {"symbolic.py", "base.py", "compiler.py", "planar.py"}
    robot.compiled("det")
    old = entry(cache, "det")
    dependency = tmp_path / "symbolic_copy.py"
    dependency.write_text("# a model source\n")
    monkeypatch.setattr(models, "sources", lambda cls, real=models.sources: real(cls) + [dependency])
    models.forget()
    built = []
    real = models.symbolic
    monkeypatch.setattr(models, "symbolic", lambda: built.append(1) or real())
    key_1 = models.key(type(robot))
    robot.compiled("det")
    assert built and key_1 not in old.name and len(list(cache.glob("*.det.*.json"))) == 2
    dependency.write_text("# a model source, edited\n")
    models.forget()
    built.clear()
    robot.compiled("det")
    assert built and models.key(type(robot)) != key_1 and len(list(cache.glob("*.det.*.json"))) == 3


def test_concurrent_processes_share_the_cache(cache):
    """Four processes delete, rebuild, write and read the same entries at once: each always gets the
    compiler's evaluator, and no entry is ever half written."""
    script = textwrap.dedent(f"""
        import os, sys
        from certkin import load_robot
        from certkin.robots import models
        robot = load_robot({str(PLANAR)!r})
        reference = robot.compiled("det").source
        for i in range(40):
            models.forget()
            if i % 3 == int(sys.argv[1]) % 3:
                for p in models.cache_dir().glob("*.json"):
                    try:
                        os.unlink(p)
                    except FileNotFoundError:
                        pass
            assert robot.compiled("det").source == reference
            assert robot.model_parts() == {{"legs", "points", "A", "B", "det"}}
        print("ok")
    """)
    env = {**os.environ, "CERTKIN_CACHE_DIR": str(cache)}
    procs = [subprocess.Popen([sys.executable, "-c", script, str(k)], env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True) for k in range(4)]
    for p in procs:
        out, err = p.communicate(timeout=300)
        assert p.returncode == 0 and out.strip() == "ok", err
    assert not [p for p in cache.iterdir() if not p.name.endswith(".json")]      # no temporary file left
    for p in cache.glob("*.json"):
        models.forget()
        assert json.loads(p.read_text())["key"] == models.key(type(load_robot(PLANAR)))


def test_no_disk_cache_when_disabled_or_unwritable(tmp_path, monkeypatch):
    monkeypatch.setenv("CERTKIN_CACHE_DIR", "")
    models.forget()
    robot = robot_from_dict({"kind": "planar-3rpr", "base": [["0", "0"], ["10", "0"], ["0", "10"]],
                             "platform": [["0", "0"], ["5", "0"], ["0", "5"]]})
    assert models.entry_path(type(robot), "det") is None and robot.compiled("det").source
    blocked = tmp_path / "file"
    blocked.write_text("not a directory")
    monkeypatch.setenv("CERTKIN_CACHE_DIR", str(blocked / "cache"))
    models.forget()
    assert robot.compiled("det").source                  # compiled, nothing written, no error
    models.forget()


def test_a_batch_worker_reloads_a_robot_file_that_changed(tmp_path):
    """``run_job``'s robots are kept per file *content*: a worker that outlives an edit of the file
    (a Dask worker between two batches) answers with the new geometry."""
    robot_file = tmp_path / "robot.toml"
    text = PLANAR.read_text()
    robot_file.write_text(text)
    job = {"id": "a", "command": "fk", "robot": str(robot_file), "lengths": "28.99,13.66,40.53"}
    (tmp_path / "one").mkdir()
    (tmp_path / "two").mkdir()
    first = run_job(dict(job), str(tmp_path / "one"))
    robot_file.write_text(text.replace("[16.233, 34.76]", "[16.233, 35.76]"))      # the third base point moved
    second = run_job(dict(job), str(tmp_path / "two"))
    assert load_robot(robot_file).base[2] == ("16.233", "35.76")
    doc_a = json.loads((tmp_path / "one" / "a.json").read_text())
    doc_b = json.loads((tmp_path / "two" / "a.json").read_text())
    assert first["verdict"] == second["verdict"] == "complete"
    assert doc_a["solutions"] != doc_b["solutions"]       # other geometry, other postures
    assert doc_b == json.loads(json.dumps(doc_b)) and doc_b["job"]["robot"] == str(robot_file)
