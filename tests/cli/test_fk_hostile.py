"""``certkin fk`` on hostile input (issue #18)."""
import json
import os
import stat
import zipfile

import pytest

import certkin
import certkin.cli.fk
from certkin.certificates.writing import NotRegularFile, write_text
from conftest import MEL, R2, answered, refused

L = "28.99,13.66,40.53"
F = ["fk", R2, "--lengths", L]

HOSTILE = [
    (F + ["--certificate", "-"], ["--certificate", "a file name is needed"]),      # once: a file named '-'
    (["fk", R2, "--lengths", "28.99,13.66,1e999999999"], ["--lengths", "leg 3", "out of range"]),  # once: hung
    (["fk", R2, "--lengths", "28.99,13.66,1e9999"], ["--lengths", "out of range"]),    # once: "not a finite number"
    (["fk", R2, "--lengths", "29+-1e-999999999,13.66,40.53"], ["--lengths", "below 1e-400"]),
    (["fk", R2, "--lengths", "28.99" + "0" * 4400 + ",13.66,40.53"], ["--lengths", "leg 1", "more than 1000 digits"]),
    (["fk", R2, "--lengths", "28:28.99" + "0" * 4400 + ",13.66,40.53"], ["--lengths", "more than 1000 digits"]),
    (F + ["--max-boxes", "0"], ["--max-boxes"]),
    (F + ["--max-boxes", "-1"], ["--max-boxes"]),
    (F + ["--max-seconds", "0"], ["--max-seconds"]),
    (F + ["--max-seconds", "nan"], ["--max-seconds"]),
    (F + ["--min-width", "0"], ["--min-width"]),
    (F + ["--min-width", "nan"], ["--min-width"]),
    (F + ["--max-memory", "0"], ["--max-memory"]),
    (F + ["--max-memory", "1000TiB"], ["--max-memory", "this machine's memory"]),
    (F + ["--max-memory", "1PiB"], ["--max-memory", "this machine's memory"]),     # once: "a size such as 2GiB"
    (F + ["--max-boxes", "１０"], ["--max-boxes", "positive integer"]),             # once: full-width digits read as 10
    (F + ["--max-seconds", "１"], ["--max-seconds", "positive number"]),
    (F + ["--min-width", "１e-9"], ["--min-width", "positive number"]),
    (F + ["--lengths", "1,2,3"], ["--lengths", "twice"]),
    (["fk", R2, "--lengths", "-28.99,13.66,40.53"], ["--lengths", "negative"]),
    (["fk", R2, "--lengths", "1e300,13.66,40.53"], ["--lengths", "out of range"]),
    (["fk", R2, "--lengths", "nan,13.66,40.53"], ["--lengths"]),
    (["fk", R2, "--lengths", "28.99,13.66"], ["--lengths"]),
    (["fk", R2, "--lengths", ""], ["--lengths"]),
    (["fk", R2], ["--lengths"]),
    (F + ["--track", "30,13,-1.9", "--domain", "x=0:50,y=-10:20,phi=-3:3"], ["--domain", "--track"]),
    (F + ["--track", "30,13"], ["--track"]),
    (F + ["--track", "1e300,0,0"], ["--track", "x", "out of range"]),        # once: ignored, full search
    (F + ["--track", "0,0,1e300"], ["--track", "phi", "out of range for an angle", "1e+06 rad"]),  # (it named 1e+12)
    (F + ["--track", "0,0,1e400"], ["--track", "phi", "out of range", "1e+06 rad"]),
    (["fk", R2, "--lengths", "29+-1e300,13.66,40.53"], ["--lengths", "out of range"]),   # once: 300 digits
    (F + ["--max-seconds", "-inf"], ["--max-seconds"]),
    (F + ["--domain", "x=0:50,q=-10:20"], ["--domain", "q"]),          # (a domain names only what it narrows)
    (F + ["--domain", ""], ["--domain", "empty"]),
    (F + ["--domain", "x=0:1e300,y=-10:20,phi=0:1"], ["--domain", "x"]),
    (F + ["--angles", "zyz"], ["--angles"]),
    (F + ["--certificate", "{tmp}"], ["--certificate", "directory"]),
    (F + ["--report", "{tmp}/f.json"], ["--report"]),
    (F + ["--certificate", "{tmp}/no/f.json"], ["--certificate", "does not exist"]),
]


@pytest.mark.parametrize("argv, words", HOSTILE, ids=[" ".join(a[2:])[:60] for a, _ in HOSTILE])
def test_hostile_input_is_refused(cli, argv, words):
    refused(cli(*argv), *words)


def test_boxes_are_printed_outward(cli):
    """Each mode is printed as an enclosure of its proved box."""
    import json
    doc = json.loads(cli(*F, "--json").out)
    text = cli(*F).out.splitlines()[1:]
    for line, s in zip(text, doc["solutions"]):
        x = line.split("x=[")[1].split("]")[0].split(", ")
        assert float(x[0]) <= s["pose"]["x"][0] and s["pose"]["x"][1] <= float(x[1])


def test_first_compilation_is_announced(cli, monkeypatch):
    monkeypatch.setattr(certkin.cli.fk, "kernels_cached", lambda: False)
    run = cli(*F)
    answered(run)
    assert "compiling" not in run.err                     # planar robots use no compiled kernels
    run = cli("fk", MEL, "--lengths", "500,500,500,500,500,500", "--max-boxes", "200")
    answered(run)
    assert "compiling kernels, once" in run.err


def test_max_seconds_is_respected(cli):
    """The budget bounds the search; the first run on a fresh checkout also compiles the kernels (about
    15 s, more on a loaded machine), so that run comes first and the second is timed."""
    argv = ("fk", MEL, "--lengths", "520,530,540,550,560,570", "--min-width", "1e-14", "--max-seconds", "1")
    answered(cli(*argv))
    run = cli(*argv)
    answered(run)
    assert run.seconds < 1 + 8                            # the budget, the process's start and its answer


def test_a_long_spatial_search_stays_under_the_memory_ceiling(tmp_path):
    """Dietmaier's robot at its published lengths ±1e-6 (the Cayley-Menger rule is off with length ranges:
    a long search; its exact lengths now take 63 000 boxes, 2.5 s), finest width: cut by the time budget,
    within 3 GiB of address space (a subprocess under ``resource.setrlimit``), its regions listed briefly."""
    from conftest import ROBOTS, limited
    lengths = ",".join(f"{v}+-0.000001" for v in ("1", "0.645275", "1.086284", "1.503439", "1.281933", "0.771071"))
    run = limited(["fk", str(ROBOTS / "dietmaier-6-6-40.toml"), "--lengths", lengths,
                   "--min-width", "1e-14",
                   "--max-seconds", "3", "--certificate", "{tmp}/f.cert"], tmp_path)
    answered(run, "INCOMPLETE")
    lines = run.out.splitlines()
    regions = [ln for ln in lines if ln.startswith("  unresolved ")]
    modes = [ln for ln in lines if ln[2:].split(":")[0].strip().isdigit()]
    assert 0 < len(regions) <= 20 and run.left == ["f.cert"]           # at most 20 regions, then one line
    more = [ln for ln in lines if "more unresolved regions" in ln]
    assert lines[-1] == "  note: the time budget ran out before every region was decided"
    assert len(lines) == 1 + len(modes) + len(regions) + len(more) + 1


def test_an_answer_cut_by_its_budget_says_so(cli):
    """'INCOMPLETE' alone did not say why: a budget that ran out is named (text and JSON), a complete
    answer carries no such note, and one region or one mode is counted in the singular."""
    run = cli(*F, "--max-boxes", "10")
    answered(run, "0 assembly modes; INCOMPLETE, 1 unresolved region [10 boxes",
             "note: the box budget ran out before every region was decided")
    assert certkin.forward_kinematics(R2, L, max_boxes=10).to_json()["message"].startswith("the box budget ran out")
    assert certkin.forward_kinematics(R2, L, max_seconds=1e-9).to_json()["message"].startswith("the time budget ran out")
    assert certkin.forward_kinematics(R2, L, max_memory=1).to_json()["message"].startswith("the memory budget ran out")
    full = certkin.forward_kinematics(R2, L)
    assert full.complete and "message" not in full.to_json()
    assert "note:" not in cli(*F).out


def test_outputs_onto_a_pipe_are_refused_and_a_link_to_a_file_is_replaced(cli, tmp_path):
    """An output path naming a pipe (or /dev/null, a device) is refused before solving and left as
    it is (renaming the new file onto it would replace it); a symbolic link to a regular file is
    replaced by the new file, its target left as it is (a planted link cannot redirect a write); a
    link to a pipe or a device is refused like them.  The library's writer refuses the pipe too."""
    pipe = tmp_path / "pipe.cert"
    os.mkfifo(pipe)
    for option in ("--certificate", "--report"):
        target = pipe if option == "--certificate" else tmp_path / "pipe.html"
        if option == "--report":
            os.mkfifo(target)
        refused(cli(*F, option, str(target)), option, "not a regular file")
        assert stat.S_ISFIFO(os.lstat(target).st_mode)
    with pytest.raises(NotRegularFile):
        write_text(pipe, "x")
    assert stat.S_ISFIFO(os.lstat(pipe).st_mode) and sorted(p.name for p in tmp_path.iterdir()) == ["pipe.cert",
                                                                                                    "pipe.html"]
    link, real = tmp_path / "link.cert", tmp_path / "real.cert"
    real.write_text("kept")
    link.symlink_to(real)
    answered(cli(*F, "--certificate", str(link)))
    assert not link.is_symlink() and zipfile.is_zipfile(link) and real.read_text() == "kept"
    for target in (pipe, os.devnull):   # (--certificate /dev/stdout replaced the system's link with a file)
        device_link = tmp_path / "device.cert"
        device_link.symlink_to(target)
        refused(cli(*F, "--certificate", str(device_link)), "--certificate", "not a regular file")
        assert device_link.is_symlink() and os.readlink(device_link) == str(target)
        device_link.unlink()
    assert stat.S_ISFIFO(os.lstat(pipe).st_mode)


def test_a_link_to_the_process_output_is_refused_when_the_output_is_a_file(tmp_path):
    """``--certificate /dev/stdout`` with the output redirected to a file: /dev/stdout leads to
    /proc/self/fd/1, a regular file then, and the system's link was replaced by the certificate."""
    import subprocess
    import sys
    link = tmp_path / "stdout.cert"
    link.symlink_to("/proc/self/fd/1")
    with open(tmp_path / "out.txt", "w") as out:
        run = subprocess.run([sys.executable, "-m", "certkin", *F, "--certificate", str(link)], stdout=out,
                             stderr=subprocess.PIPE, text=True)
    assert run.returncode == 2 and "not a regular file" in run.stderr and "Traceback" not in run.stderr
    assert link.is_symlink() and os.readlink(link) == "/proc/self/fd/1"


def test_angle_ranges_of_a_domain_are_read_modulo_two_pi_and_the_rest_is_counted(cli):
    """phi = 100:101 holds the modes whose phi is within -0.531 and 0.469 (modulo 2 pi): 3 of the 6;
    the text counts the others, which the certificate lists."""
    run = cli("fk", R2, "--lengths", "28.99,13.66,40.53", "--domain", "x=-50:50,y=-50:50,phi=100:101")
    answered(run)
    assert "3 assembly modes, each proved unique; complete" in run.out
    assert "note: 3 more assembly modes outside the angle ranges of --domain" in run.out


def test_a_tiny_tolerance_is_kept_exactly(cli):
    """29+-1e-30 is the range 29 - 1e-30 : 29 + 1e-30, exactly (once rounded to 29:29)."""
    run = cli("fk", R2, "--lengths", "29+-1e-30,13.66,40.53", "--json")
    answered(run)
    assert json.loads(run.out)["lengths"][0] == "28.999999999999999999999999999999:29.000000000000000000000000000001"


def test_an_output_that_names_the_robot_file_is_refused(cli, tmp_path):
    """``--certificate robot.toml`` replaced the robot file with a certificate: refused, file intact."""
    robot = tmp_path / "robot.toml"
    robot.write_bytes(open(R2, "rb").read())
    before = robot.read_bytes()
    for argv in (["fk", str(robot), "--lengths", L, "--certificate", str(robot)],
                 ["singular", str(robot), "--box", "x=-20:-10,y=20:30,phi=0:0.3", "--certificate", str(robot)]):
        refused(cli(*argv), "--certificate", "the robot file itself")
    assert robot.read_bytes() == before



@pytest.mark.parametrize("lengths", ["5.5,5.5,5_5", "２９,13.66,40.53"])
def test_numbers_are_plain_ascii_decimals(cli, lengths):
    """Python's Decimal reads '5_5' as 55 and full-width digits as digits: a typo answered another question."""
    refused(cli("fk", R2, "--lengths", lengths), "--lengths", "not a plain decimal number")


def test_a_robot_file_nested_too_deeply_is_refused(cli, tmp_path):
    """A robot file of 100 000 nested arrays: one line naming the file (it was a RecursionError traceback)."""
    (tmp_path / "deep.toml").write_text('kind = "planar-3rpr"\nbase = ' + "[" * 100000 + "]" * 100000 + "\n")
    refused(cli("fk", "deep.toml", "--lengths", L), "deep.toml", "nested too deeply")


@pytest.mark.parametrize("size", ["0", "-1", "1e30", "512KiB", "2 GiBs", "inf"])
def test_a_refused_memory_size_always_gets_the_same_message(cli, size):
    """0 said "positive finite number", -1 "a size such as 2GiB", 1e30 "1MiB to 1PiB": one message now."""
    run = cli(*F, "--max-memory", size)
    refused(run, "--max-memory")
    assert run.err.strip() == ("certkin: error: argument --max-memory: expected a size from 1MiB to 1PiB, a number "
                               f"of bytes or with a unit (2GiB, 512MiB, 1.5G), got '{size}'")


def test_a_long_value_is_echoed_by_its_start_and_end(cli):
    """A 100 000-character value was echoed whole in the error line."""
    run = cli(*F, "--max-boxes", "7" * 50000 + "x" + "8" * 50000)
    refused(run, "--max-boxes", "'" + "7" * 28 + "..." + "8" * 27 + "'")
    assert len(run.err) < 200
    run = cli("fk", R2, "--lengths", L, "--domain", "q" * 100000)
    refused(run, "--domain: " + "q" * 29 + "..." + "q" * 28 + ": expected name=lo:hi")


def test_a_decimal_written_with_an_exponent_the_checker_refuses_is_refused(cli, tmp_path):
    """2899000e-405 is about 2.9e-399, in range, but written with an exponent beyond ±400, which the
    checker does not read: its certificate was rejected.  Refused (exit 2); 2.899e-399 is answered and
    its certificate checks, as is a robot file's 378e-402 (TOML's number, written 3.78E-400)."""
    refused(cli("fk", R2, "--lengths", "2899000e-405,13.66,40.53"), "--lengths", "exponent beyond ±400")
    robot = tmp_path / "r.toml"
    robot.write_text(open(R2).read().replace("[3.78, 4.34]", "[378e-402, 4.34]", 1))
    assert "378e-402" in robot.read_text()
    answered(cli("fk", str(robot), "--lengths", L, "--certificate", str(tmp_path / "r.cert")))
    assert cli("check", str(tmp_path / "r.cert")).code == 0
    run = cli("fk", R2, "--lengths", "2.899e-399,13.66,40.53", "--certificate", str(tmp_path / "c.cert"))
    answered(run)
    assert cli("check", str(tmp_path / "c.cert")).code == 0
@pytest.fixture
def no_hang():
    """Fails a test whose command waits for a pipe's writer for more than 20 s (it once waited forever)."""
    import signal

    def hung(*_):
        raise AssertionError("the command waits for the writer of a pipe")
    previous = signal.signal(signal.SIGALRM, hung)
    signal.alarm(20)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)


def test_a_robot_file_from_a_pipe_is_read_as_its_writer_writes_and_ctrl_c_ends_the_wait(cli, tmp_path, no_hang):
    """A named pipe with no writer (``mkfifo f; certkin fk f``) waited forever and ignored the first
    Ctrl-C: it is refused at once.  A pipe whose writer is slow (``<(sleep 1; cat robot.toml)``) is read
    once it writes; while it is silent, a Ctrl-C ends the command at once (exit 130, no traceback)."""
    import signal
    import threading
    os.mkfifo(tmp_path / "f")
    refused(cli("fk", "{tmp}/f", "--lengths", L), "f: a named pipe with no writer")
    text = open(R2, "rb").read()
    r, w = os.pipe()                       # as a shell's <(...): /dev/fd/N, a writer that writes later

    def write():
        os.write(w, text)
        os.close(w)
    writer = threading.Timer(0.3, write)
    writer.start()
    try:
        answered(cli("fk", f"/dev/fd/{r}", "--lengths", L), "6 assembly modes")
    finally:
        writer.join()
        os.close(r)
    r, w = os.pipe()                       # a writer that never writes
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    try:
        run = cli("fk", f"/dev/fd/{r}", "--lengths", L)
    finally:
        timer.cancel()
        os.close(r)
        os.close(w)
    assert run.code == 130 and run.err == "certkin: interrupted\n" and run.out == "" and run.seconds < 1.5
