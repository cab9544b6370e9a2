"""``certkin batch`` on hostile input (issue #18): every option and output path is checked before
any job runs (exit 2, one line, nothing created); a bad job line is an error job, never a crash."""
import json
import os

import pytest

from conftest import MEL, R2, answered, limited, refused

JOB = {"id": "a", "command": "fk", "robot": R2, "lengths": "28.99,13.66,40.53"}


@pytest.fixture
def jobs(tmp_path):
    """A jobs file outside the run's directory, written from a list of lines."""
    folder = tmp_path.parent / (tmp_path.name + "-jobs")
    folder.mkdir()

    def write(*lines, name="jobs.jsonl"):
        path = folder / name
        path.write_bytes(b"\n".join(line if isinstance(line, bytes) else line.encode() for line in lines))
        return str(path)
    return write


def ok(jobs):
    return jobs(json.dumps(JOB))


HOSTILE = [
    (["--workers", "0"], ["--workers"]),
    (["--workers", "-1"], ["--workers"]),
    (["--workers", "nan"], ["--workers"]),
    (["--workers", "1e300"], ["--workers", "'1e300'"]),
    (["--workers", "100000"], ["--workers"]),
    (["--workers", str(4 * (os.cpu_count() or 1) + 1)], ["--workers", f"to {4 * (os.cpu_count() or 1)}"]),
    (["--workers", "2", "--workers", "3"], ["--workers", "twice"]),
    (["--json", "--json"], ["--json", "twice"]),
    (["--report", "{tmp}/r.txt"], ["--report", ".txt"]),
    (["--report", "{tmp}"], ["--report", "directory"]),
    (["--report", "{tmp}/no/r.html"], ["--report", "does not exist"]),
    (["--report", "/proc/r.html"], ["--report", "cannot write"]),
    (["--scheduler", ""], ["--scheduler", "empty"]),
]


@pytest.mark.parametrize("extra, words", HOSTILE, ids=[" ".join(e)[:50] for e, _ in HOSTILE])
def test_hostile_options_are_refused(cli, jobs, extra, words):
    refused(cli("batch", ok(jobs), "--out", "{tmp}/out", *extra), *words)


@pytest.mark.parametrize("out, words", [
    ("", ["--out", "empty"]),
    ("{tmp}/no/such/dir", ["--out", "does not exist"]),          # parents are not created
    ("/proc/out", ["--out", "cannot write"]),
])
def test_bad_output_directories_are_refused(cli, jobs, out, words):
    refused(cli("batch", ok(jobs), "--out", out), *words)


def test_an_output_directory_that_is_a_file(cli, jobs, tmp_path):
    (tmp_path / "file").write_text("")
    run = cli("batch", ok(jobs), "--out", "{tmp}/file")
    assert run.left == []
    run.left = []
    refused(run, "--out", "not a directory")


@pytest.mark.parametrize("content, words", [
    ([b"\xff\xfe{}"], ["jobs.jsonl", "cannot read"]),           # not UTF-8
    ([b""], ["jobs.jsonl", "no jobs"]),
    ([b"\xef\xbb\xbf"], ["jobs.jsonl", "no jobs"]),                 # a byte-order mark alone
    ([b"# only a comment", b""], ["jobs.jsonl", "no jobs"]),
])
def test_unreadable_or_empty_jobs_files(cli, jobs, content, words):
    refused(cli("batch", jobs(*content), "--out", "{tmp}/out"), *words)


@pytest.mark.parametrize("path, words", [("{tmp}", ["cannot read the jobs file (Is a directory)"]), ("{tmp}/none.jsonl", ["none.jsonl", "no such file"]),
                                         ("/dev/zero", ["not a regular file"]),
                                         ("", ["empty file name"])])
def test_missing_jobs_files(cli, path, words):
    refused(cli("batch", path, "--out", "{tmp}/out"), *words)


def test_bad_job_lines_are_error_jobs(cli, jobs, tmp_path):
    """Each bad line becomes an error job with the command line's one-line message; the good one runs."""
    lines = [json.dumps(JOB),
             "[" * 100000,                                                       # RecursionError in json
             json.dumps({**JOB, "id": "b1", "max_seconds": "nan"}),
             json.dumps({**JOB, "id": "b2", "certificate": "x.cert"}),
             json.dumps({"id": "b3", "command": "rm", "robot": R2}),
             json.dumps({"id": "b4", "command": "singular", "robot": R2, "box": "x=-1:1,y=0:1,phi=0:0.1",
                         "cells": 1000, "max_boxes": "1e10"}),
             json.dumps({"id": "b5", "command": "trajectory", "robot": MEL, "from": "-69,-50,1e300,85deg,10deg,0",
                         "to": "84,92,500,85deg,10deg,0"}),
             json.dumps({"id": "../b6", "command": "fk", "robot": R2}),
             json.dumps({**JOB, "id": "b7", "bogus": 1}),
             json.dumps({**JOB, "id": "b8", "max_seconds": True}),      # once: "--max-seconds: expected one argument"
             json.dumps({**JOB, "id": "b9", "max_boxes ": 5}),          # once: "unrecognized arguments: --max-boxes =5"
             json.dumps({**JOB, "id": "b10", "progress": True}),        # once: "the batch writes DIR/<id>.json"
             json.dumps({**JOB, "id": "b11", "help": True}),            # once: argparse's help, and the batch ended
             json.dumps({**JOB, "id": "b12", "len": "1,2,3"}),          # once: taken for --lengths
             json.dumps({**JOB, "id": "b13", "rep": "r.html"}),         # once: taken for --report, nothing written
             '{"id": "b14", "command": "fk", "robot": "%s", "lengths": %s1%s}' % (R2, "[" * 500, "]" * 500),
             json.dumps({**JOB, "id": "b15"})[:-1] + ', "lengths": "1,2,3"}',   # once: the last one won
             json.dumps({**JOB, "id": "b16", "lengths": [None, 1, 2]}),
             json.dumps({**JOB, "id": "b17", "command": ["fk"]}),
             json.dumps({**JOB, "id": None}),
             json.dumps({"id": "b18", "command": "singular", "robot": R2, "box": {"x": [-1, 1]}}),
             json.dumps({"id": "b19", "command": "singular", "robot": R2, "box": [[-1, 1], [0, 1], [0, 0.1]]})]
    run = cli("batch", jobs(*lines), "--out", "{tmp}/out", "--workers", "1", "--json")
    answered(run)
    summary = json.loads(run.out)
    errors = {e["id"]: e["error"] for e in summary["errors"]}
    assert set(errors) == {"line-2", "b1", "b2", "b3", "b4", "b5", "line-8", "b7", "b8", "b9", "b10", "b11", "b12",
                           "b13", "line-16", "line-17", "b16", "b17", "line-20", "b18", "b19"}, errors
    for word, jid in (("nested too deeply", "line-2"), ("--max-seconds", "b1"), ("certificate", "b2"),
                      ("command", "b3"), ("--cells", "b4"), ("--from", "b5"), ("id", "line-8"),
                      ("'bogus': not an option of certkin fk", "b7"),
                      ("max_seconds: expected a value, got true", "b8"), ("'max_boxes ': not an option name", "b9"),
                      ("certkin batch --progress", "b10"), ("'help': not an option of certkin fk", "b11"),
                      ("'len': not an option", "b12"), ("'rep': not an option", "b13"),
                      ("nested more than 32 deep", "line-16"), ("'lengths' given twice", "line-17"),
                      ("'null'", "b16"), ('got ["fk"]', "b17"), ("got null", "line-20"),
                      ('--box: x: a box is a text "x=a:b,..." or a list of such items ("x=a:b"), got {"x": [-1, 1]}',
                       "b18"), ("--box: item 1: a box is a text", "b19")):
        assert word in errors[jid] and "\n" not in errors[jid], (jid, errors[jid])
    assert "None" not in run.out and "True" not in run.out
    assert summary["counts"]["fk complete"] == 1 and summary["jobs"] == 22
    assert summary["counts"]["? error"] == 4     # no command, or not a text (["fk"]): line-2, 16, 17 and b17
    assert (tmp_path / "out" / "a.cert").exists()


def test_a_robot_file_nested_too_deeply_is_an_error_job(cli, jobs, tmp_path):
    """A job whose robot file nests 100 000 arrays gets the command line's error (it was "internal error:
    RecursionError"); the batch carries on."""
    deep = tmp_path.parent / (tmp_path.name + "-deep.toml")
    deep.write_text('kind = "planar-3rpr"\nbase = ' + "[" * 100000 + "]" * 100000 + "\n")
    run = cli("batch", jobs(json.dumps({**JOB, "robot": str(deep)}), json.dumps({**JOB, "id": "b"})),
              "--out", "{tmp}/out", "--workers", "1", "--json")
    answered(run)
    errors = {e["id"]: e["error"] for e in json.loads(run.out)["errors"]}
    assert list(errors) == ["a"] and errors["a"] == f"{deep}: not a robot file (arrays or tables nested too deeply)"


def test_numbers_of_thousands_of_digits_are_error_jobs(cli, jobs):
    """A 4400-digit decimal in an inline robot was "internal error: ValueError: Exceeds the limit (4300 digits)";
    a 4400-digit integer in a job line stopped the whole batch with a traceback."""
    robot = {"kind": "planar-3rpr", "base": [[0, 0], [10, 0], [3, 10]], "platform": [[0, 0], [4, 0], [2, 2]]}
    inline = json.dumps({**JOB, "robot": robot}).replace("[4, 0]", "[12." + "0" * 4400 + ", 0]")
    integer = json.dumps({**JOB, "id": "b", "lengths": [1, 2, 3]}).replace("[1, 2", "[1" + "0" * 4400 + ", 2")
    run = cli("batch", jobs(inline, integer, json.dumps({**JOB, "id": "c"})), "--out", "{tmp}/out", "--workers", "1",
              "--json")
    answered(run)
    errors = {e["id"]: e["error"] for e in json.loads(run.out)["errors"]}
    assert set(errors) == {"a", "line-2"}, errors
    assert errors["a"] == ("robot: platform[1][0]: a decimal of more than 1000 digits (no robot needs that many, and "
                           "a certificate's checker reads no more)")
    assert errors["line-2"].endswith("jobs.jsonl: line 2: not a job (an integer of more than 4300 digits)")


def test_text_of_a_jobs_file_cannot_forge_lines_of_the_table(cli, jobs):
    """A robot path with a newline and a terminal escape, echoed in a job's error, is printed escaped."""
    forged = json.dumps({"id": "a", "command": "fk", "robot": "no\nsuch\x1b[2K  fk complete 99",
                         "lengths": "28.99,13.66,40.53"})
    run = cli("batch", jobs(forged), "--out", "{tmp}/out")
    assert run.code == 0 and "error a: no\\nsuch\\x1b[2K  fk complete 99: no such file" in run.out
    assert not any(line.strip().startswith("fk complete") for line in run.out.splitlines())
    assert all(c.isprintable() for c in run.out.replace("\n", ""))


def test_a_jobs_file_the_batch_would_overwrite_is_refused(cli, tmp_path):
    """A jobs file inside --out named like one of the batch's files (summary.json, <id>.json) would be
    overwritten by the run: refused, nothing written."""
    out = tmp_path / "out"
    out.mkdir()
    for name in ("summary.json", "a.json"):
        path = out / name
        path.write_text(json.dumps(JOB) + "\n")
        run = cli("batch", str(path), "--out", str(out))
        assert run.code == 2 and "overwrite its own jobs file" in run.err
        assert path.read_text() == json.dumps(JOB) + "\n" and sorted(p.name for p in out.iterdir()) == [name]
        path.unlink()


def test_a_scheduler_nobody_answers_at_is_refused_before_anything_is_written(cli, jobs, tmp_path):
    """``--scheduler`` at an address where no Dask scheduler answers: exit 2, one line naming
    --scheduler, no output directory created (the connection is made first)."""
    pytest.importorskip("dask.distributed")      # its configuration loaded first: the set below restores it after
    import dask
    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):
        run = cli("batch", ok(jobs), "--out", "{tmp}/out", "--scheduler", "tcp://127.0.0.1:1")
    refused(run, "--scheduler", "tcp://127.0.0.1:1", "no Dask scheduler")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("greeting", [None, b"SSH-2.0-OpenSSH_9.2\r\n"], ids=["silent", "another-protocol"])
def test_a_scheduler_address_where_another_service_listens_is_refused(cli, jobs, tmp_path, greeting):
    """A service that accepts the connection and then stays silent (Dask's own timeout never ends the
    wait), or answers in another protocol (Dask read a bogus length: "out of memory"), is no Dask
    scheduler: exit 2 naming --scheduler within the connection timeout and a few seconds."""
    pytest.importorskip("dask.distributed")
    import socket
    import threading
    import time

    import dask
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen()
    accepted = []

    def serve():
        try:
            while True:
                conn, _ = server.accept()
                accepted.append(conn)
                if greeting:
                    conn.sendall(greeting)
        except OSError:
            pass
    threading.Thread(target=serve, daemon=True).start()
    address = f"tcp://127.0.0.1:{server.getsockname()[1]}"
    t0 = time.perf_counter()
    try:
        with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):
            run = cli("batch", ok(jobs), "--out", "{tmp}/out", "--scheduler", address)
    finally:
        server.close()
        for conn in accepted:
            conn.close()
    refused(run, "--scheduler", address, "no Dask scheduler")
    assert "out of memory" not in run.err and time.perf_counter() - t0 < 15
    assert not (tmp_path / "out").exists()


def test_a_byte_order_mark_before_the_first_job_is_no_error(cli, jobs):
    run = cli("batch", jobs(b"\xef\xbb\xbf" + json.dumps(JOB).encode()), "--out", "{tmp}/out", "--json")
    answered(run)
    assert json.loads(run.out)["counts"] == {"fk complete": 1}


def test_an_out_directory_the_disk_cannot_hold_is_named_with_its_file(jobs, tmp_path):
    """A full disk under --out was blamed on standard output: the error now names --out and the file."""
    job = {"id": "a", "command": "singular", "robot": R2, "box": "x=-50:0,y=-50:0,phi=0:0.3925"}
    run = limited(["batch", jobs(json.dumps(job)), "--out", "{tmp}/res", "--workers", "1"], tmp_path, file_size=100)
    assert run.code == 2, (run.code, run.err)
    assert run.err == f"certkin: error: --out: cannot write {tmp_path}/res/a.json: File too large\n", run.err
