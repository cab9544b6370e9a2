"""certkin demo: its small batch (50 planar FK jobs on 2 workers) and the report of that campaign."""
from __future__ import annotations

import json
from pathlib import Path

import proofs
from certkin.cli.demo import _batch_demo, bundled_robots_dir
from certkin.robots import load_robot


def test_the_demo_batch_answers_50_fk_jobs_and_writes_its_report(tmp_path):
    name = "seed003-planar-example-2"
    robots = {name: load_robot(bundled_robots_dir() / f"{name}.toml")}
    lines = []
    _batch_demo(robots, lines.append, tmp_path / "demo")
    summary = json.loads((tmp_path / "demo" / "summary.json").read_text())
    assert summary["jobs"] == 50 and summary["workers"] == "2 local"
    assert not summary["errors"] and not summary["failed"] and not summary["undecided"]
    assert sum(summary["counts"].values()) == 50
    for row in summary["results"][::10]:
        assert proofs.check_file(tmp_path / "demo" / row["certificate"]["file"]).ok
    report = (tmp_path / "demo" / "report.html").read_text()
    assert "50 jobs" in report and summary["results"][0]["certificate"]["sha256"] in report
    assert any("report of the campaign" in line for line in lines)
    assert Path(tmp_path / "demo" / "report.html").stat().st_size > 20_000      # its figures are embedded
