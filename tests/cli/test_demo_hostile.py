"""``certkin demo`` on hostile input (issue #18): its output directory and robot directory are
checked before anything runs."""
import pytest

from conftest import refused


@pytest.mark.parametrize("argv, words", [
    (["--out", ""], ["--out", "empty"]),
    (["--out", "{tmp}/no/such"], ["--out", "does not exist"]),
    (["--out", "/proc/demo"], ["--out", "cannot write"]),
    (["--robots", "{tmp}/none"], ["--robots", "not a directory"]),
    (["--robots", "{tmp}"], ["no robot files"]),
    (["--out", "a", "--out", "b"], ["--out", "twice"]),
])
def test_hostile_input_is_refused(cli, argv, words):
    refused(cli("demo", *argv), *words)


def test_an_output_directory_that_is_a_file(cli, tmp_path):
    (tmp_path / "file").write_text("")
    run = cli("demo", "--out", "{tmp}/file")
    assert run.code == 2 and "--out" in run.err and "not a directory" in run.err and run.out == ""
