"""``certkin check`` on hostile input: exit 0 valid, 1 checked and rejected, 2 unreadable (issue #18)."""
import json

import pytest

from conftest import R2, refused


def test_exit_codes(cli, tmp_path):
    (tmp_path / "bad.json").write_text("{not json")
    refused(cli("check", "{tmp}/none.json"), "none.json")
    refused(cli("check", "{tmp}/bad.json"), "bad.json")
    assert cli("singular", R2, "--box", "x=-20:-10,y=20:30,phi=0:0.3", "--certificate", "{tmp}/c.json").code == 0
    run = cli("check", "{tmp}/c.json")
    assert run.code == 0 and run.out.startswith("OK")
    cert = json.loads((tmp_path / "c.json").read_text())
    cert["claims"][0]["sign"] = -cert["claims"][0]["sign"]
    (tmp_path / "t.json").write_text(json.dumps(cert))
    run = cli("check", "{tmp}/t.json")
    assert run.code == 1 and run.out.startswith("REJECTED") and "Traceback" not in run.err


@pytest.mark.xfail(reason="cli/check.py: a deeply nested file is the certificates branch's (#17)", strict=False)
def test_deeply_nested_json_is_unreadable(cli, tmp_path):
    (tmp_path / "deep.json").write_text("[" * 100000)
    refused(cli("check", "{tmp}/deep.json"), "deep.json")


def test_a_huge_robot_coordinate_gives_no_warning(cli, tmp_path):
    assert cli("singular", R2, "--box", "x=-20:-10,y=20:30,phi=0:0.3", "--certificate", "{tmp}/c.json").code == 0
    cert = json.loads((tmp_path / "c.json").read_text())
    cert["robot"]["base"][0][0] = "1e308"
    (tmp_path / "h.json").write_text(json.dumps(cert))
    run = cli("check", "{tmp}/h.json")
    assert run.code in (0, 1, 2) and "Warning" not in run.err and "Traceback" not in run.err
    assert len(run.err.strip().splitlines()) <= 1
