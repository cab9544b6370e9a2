"""``certkin demo`` on hostile input (issue #18): its output directory and robot directory are
checked before anything runs."""
import pytest

from certkin.cli.demo import SOURCE_TREE, bundled_robots_dir
from conftest import refused


@pytest.mark.parametrize("argv, words", [
    (["--out", ""], ["--out", "empty"]),
    (["--out", "{tmp}/no/such"], ["--out", "does not exist"]),
    (["--out", "/proc/demo"], ["--out", "cannot write"]),
    (["--robots", "{tmp}/none"], ["--robots", "not a directory"]),
    (["--robots", "{tmp}"], ["--robots", "no robot files"]),
    (["--robots="], ["--robots", "empty directory name"]),
    (["--out", "a", "--out", "b"], ["--out", "twice"]),
])
def test_hostile_input_is_refused(cli, argv, words):
    refused(cli("demo", *argv), *words)


def test_an_output_directory_that_is_a_file(cli, tmp_path):
    (tmp_path / "file").write_text("")
    run = cli("demo", "--out", "{tmp}/file")
    assert run.code == 2 and "--out" in run.err and "not a directory" in run.err and run.out == ""


def test_the_bundled_robots_are_found_in_a_source_tree_or_an_installed_copy(tmp_path):
    """The source tree's examples/robots when there is one (editable install); else the copy a wheel
    installs under <prefix>/share/certkin/robots (pyproject's data-files)."""
    assert bundled_robots_dir() == SOURCE_TREE / "examples" / "robots"
    assert any(bundled_robots_dir().glob("*.toml"))
    installed = tmp_path / "prefix" / "share" / "certkin" / "robots"
    installed.mkdir(parents=True)
    assert bundled_robots_dir(tmp_path / "site-packages", str(tmp_path / "prefix")) == installed
    assert bundled_robots_dir(SOURCE_TREE, str(tmp_path / "prefix")) == SOURCE_TREE / "examples" / "robots"
    assert '"share/certkin/robots" = ["examples/robots/*.toml"]' in (SOURCE_TREE / "pyproject.toml").read_text()


def test_a_robots_directory_runs_only_the_steps_its_robots_fit(cli, tmp_path):
    """A spherical robot named like the planar example, a planar one named like seed 000: the demo's
    steps matched file names and failed halfway (spherical robots have no variable 'x')."""
    folder = tmp_path / "robots"
    folder.mkdir()
    examples = SOURCE_TREE / "examples" / "robots"
    (folder / "x-planar-example-2.toml").write_bytes((examples / "seed003-spherical-example-1.toml").read_bytes())
    (folder / "seed000-x.toml").write_bytes((examples / "seed003-planar-example-1.toml").read_bytes())
    run = cli("demo", "--robots", str(folder), "--out", "{tmp}/demo")
    assert run.code == 0 and "== Robots (" in run.out and "no file of this directory is one of them" in run.out, run.err
