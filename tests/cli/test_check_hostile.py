"""``certkin check`` on hostile input: exit 0 valid, 1 checked and rejected, 2 unreadable (issue #18)."""
from certfile import Doc
from conftest import R2


def unreadable(run, name):
    """Exit 2, one line on stderr naming the file, nothing on stdout, no traceback."""
    assert run.code == 2, (run.code, run.err, run.out[:300])
    lines = run.err.strip().splitlines()
    assert len(lines) == 1 and name in lines[0] and "cannot read" in lines[0], run.err
    assert run.out == "" and "Traceback" not in run.err


def test_exit_codes(cli, tmp_path):
    (tmp_path / "bad.json").write_text("{not json")
    unreadable(cli("check", "{tmp}/none.cert"), "none.cert")
    unreadable(cli("check", "{tmp}/bad.json"), "bad.json")
    assert cli("singular", R2, "--box", "x=-20:-10,y=20:30,phi=0:0.3", "--certificate", "{tmp}/c.cert").code == 0
    run = cli("check", "{tmp}/c.cert")
    assert run.code == 0 and "OK" in run.out
    cert = Doc(tmp_path / "c.cert")
    cert.claim()["sign"] = -cert.claim()["sign"]
    cert.write(tmp_path / "t.cert")
    run = cli("check", "{tmp}/t.cert")
    assert run.code == 1 and "REJECTED" in run.out and "Traceback" not in run.err


def test_deeply_nested_json_is_unreadable(cli, tmp_path):
    (tmp_path / "deep.json").write_text("[" * 100000)
    unreadable(cli("check", "{tmp}/deep.json"), "deep.json")


def test_a_huge_robot_coordinate_gives_no_warning(cli, tmp_path):
    assert cli("singular", R2, "--box", "x=-20:-10,y=20:30,phi=0:0.3", "--certificate", "{tmp}/c.cert").code == 0
    cert = Doc(tmp_path / "c.cert")
    cert.header["robot"]["base"][0][0] = "1e308"
    cert.robot_edited().write(tmp_path / "h.cert")
    run = cli("check", "{tmp}/h.cert")
    assert run.code == 1 and "Warning" not in run.err and "Traceback" not in run.err
    assert len(run.err.strip().splitlines()) <= 1


def test_empty_names_are_bad_input(cli):
    for argv, word in ((["check", ""], "CERT"), (["check", "{tmp}/c.cert", "--robot", ""], "--robot")):
        run = cli(*argv)
        assert run.code == 2 and word in run.err and "empty" in run.err and run.out == ""


def test_robot_files_that_are_not_robots_and_endless_files_are_unreadable(cli, tmp_path):
    """``--robot`` an empty file, not TOML, or endless (/dev/zero): exit 2 naming the robot file, never a
    'rejected' certificate nor a read without end; a certificate that is an endless stream: exit 2 after
    reading a bounded prefix."""
    assert cli("singular", R2, "--box", "x=-20:-10,y=20:30,phi=0:0.3", "--certificate", "{tmp}/c.cert").code == 0
    (tmp_path / "empty.toml").write_text("")
    (tmp_path / "text.toml").write_text("not = [toml")
    for robot in ("{tmp}/empty.toml", "{tmp}/text.toml", "/dev/zero"):
        run = cli("check", "{tmp}/c.cert", "--robot", robot)
        unreadable(run, robot.replace("{tmp}", str(tmp_path)))
        assert "robot file" in run.err
    unreadable(cli("check", "/dev/zero"), "/dev/zero")
    assert cli("check", "{tmp}/c.cert", "--robot", R2).code == 0


def test_a_pipe_is_unreadable_at_once(cli, tmp_path):
    """A named pipe given as the certificate (a ZIP archive cannot be read from one): the check waited
    for a writer forever; it is refused at once, as a device is."""
    import os
    import signal

    def hung(*_):
        raise AssertionError("the check waits for a writer of the pipe")
    os.mkfifo(tmp_path / "pipe.cert")
    previous = signal.signal(signal.SIGALRM, hung)
    signal.alarm(30)
    try:
        unreadable(cli("check", "{tmp}/pipe.cert"), "pipe.cert")
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    assert "not a regular file" in cli("check", "/dev/null").err


def test_text_of_a_certificate_cannot_forge_lines_of_the_account(cli, tmp_path):
    """A robot name in a (tampered) certificate with a newline, a terminal escape or a bidi control is
    printed escaped: the account keeps one line per item and its verdict cannot be overwritten."""
    assert cli("singular", R2, "--box", "x=-20:-10,y=20:30,phi=0:0.3", "--certificate", "{tmp}/c.cert").code == 0
    cert = Doc(tmp_path / "c.cert")
    cert.header["robot"]["name"] = "x\nOK: forged\x1b[2K\u202eevil"
    cert.write(tmp_path / "forged.cert")
    run = cli("check", "{tmp}/forged.cert")
    first = run.out.splitlines()[0]
    assert first.startswith("robot: x\\nOK: forged\\x1b[2K\\u202eevil (planar-3rpr)")
    assert not any(line.startswith("OK: forged") for line in run.out.splitlines())
    assert all(c.isprintable() for c in run.out.replace("\n", ""))


def test_messages_speak_json_and_plain_words(cli, tmp_path):
    """A missing header field is shown as JSON writes it (``null``, never Python's ``None``); a missing
    robot file as the system's words, without Python's ``[Errno 2]``."""
    assert cli("singular", R2, "--box", "x=-20:-10,y=20:30,phi=0:0.3", "--certificate", "{tmp}/c.cert").code == 0
    for field, words in (("version", "unknown version null"), ("problem", "unknown problem null"),
                         ("format", "got null")):
        cert = Doc(tmp_path / "c.cert")
        del cert.header[field]
        cert.write(tmp_path / "t.cert")
        run = cli("check", "{tmp}/t.cert")
        assert run.code == 1 and words in run.out and "None" not in run.out, run.out
    run = cli("check", "{tmp}/c.cert", "--robot", "{tmp}/none.toml")
    unreadable(run, "none.toml")
    assert "No such file or directory" in run.err and "Errno" not in run.err


def test_a_pipe_given_as_the_robot_file_is_unreadable_at_once(cli, tmp_path):
    """``--robot`` a named pipe: the checker waited for a writer forever (the certificate was refused at once)."""
    import os
    import signal

    def hung(*_):
        raise AssertionError("the check waits for a writer of the pipe")
    assert cli("singular", R2, "--box", "x=-20:-10,y=20:30,phi=0:0.3", "--certificate", "{tmp}/c.cert").code == 0
    os.mkfifo(tmp_path / "pipe.toml")
    previous = signal.signal(signal.SIGALRM, hung)
    signal.alarm(30)
    try:
        run = cli("check", "{tmp}/c.cert", "--robot", "{tmp}/pipe.toml")
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    unreadable(run, "pipe.toml")
    assert "robot file" in run.err and "not a regular file" in run.err


def test_bytes_after_the_archive_and_repeated_keys_are_unreadable(cli, tmp_path):
    """A certificate with bytes appended after its archive checked OK (its file hash then covered bytes
    nobody checked); a header with a key given twice checked OK too (Python keeps the last value, another
    reader may keep the first): both are not certificates, exit 2."""
    import zipfile
    assert cli("singular", R2, "--box", "x=-20:-10,y=20:30,phi=0:0.3", "--certificate", "{tmp}/c.cert").code == 0
    raw = (tmp_path / "c.cert").read_bytes()
    (tmp_path / "tail.cert").write_bytes(raw + b"garbage")
    run = cli("check", "{tmp}/tail.cert")
    unreadable(run, "tail.cert")
    assert "after the archive's end" in run.err
    with zipfile.ZipFile(tmp_path / "c.cert") as z, zipfile.ZipFile(tmp_path / "twice.cert", "w") as out:
        for info in z.infolist():
            data = z.read(info)
            if info.filename == "header.json":
                data = b'{"problem": "forward-kinematics", ' + data[1:]      # (the header's own problem comes later)
            out.writestr(info, data)
    run = cli("check", "{tmp}/twice.cert")
    unreadable(run, "twice.cert")
    assert "'problem' is repeated" in run.err


def test_a_number_is_not_a_claim_of_completeness(cli, tmp_path):
    """``"complete": 1`` in an FK claim was taken for true (and shown "complete: proved"); ``"version":
    true`` was answered as a version 1 certificate."""
    assert cli("fk", R2, "--lengths", "28.99,13.66,40.53", "--certificate", "{tmp}/f.cert").code == 0
    for field, value, words in (("complete", 1, "complete: expected true or false"),
                                ("version", True, "unknown version true")):
        cert = Doc(tmp_path / "f.cert")
        (cert.claim() if field == "complete" else cert.header)[field] = value
        cert.write(tmp_path / "t.cert")
        run = cli("check", "{tmp}/t.cert")
        assert run.code == 1 and words in run.out and "Traceback" not in run.err, (run.out, run.err)


def test_python_m_proofs_exits_quietly_when_its_reader_goes_away(tmp_path):
    """``python -m proofs CERT | head -c 10`` with a long account: a BrokenPipeError traceback; now exit
    141 (as ``certkin check``), nothing on stderr."""
    import subprocess
    import sys
    from certkin import forward_kinematics
    cert = Doc(forward_kinematics(R2, "28.99,13.66,40.53").certificate())
    cert.header["robot"]["name"] = "x" * 1_000_000
    cert.robot_edited().write(tmp_path / "long.cert")
    p = subprocess.Popen([sys.executable, "-m", "proofs", str(tmp_path / "long.cert")], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE)
    assert p.stdout.read(10) == b"robot: xxx"
    p.stdout.close()
    err = p.stderr.read().decode()
    assert p.wait(timeout=120) == 141 and err == "", err
