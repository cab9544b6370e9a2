"""Reports in a real headless browser (Chromium from Debian's packages, driven by its DevTools
protocol): the page loads with no console error, every image decodes and is not blank, the verdict
and the certificate's SHA-256 are on the page, and a screenshot is kept in tests/artifacts/."""
from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
import sys

import pytest

import proofs
from certkin.cli import main

sys.path.insert(0, str(Path(__file__).parent))
from browser import Browser, executable  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
ROBOTS = ROOT / "examples" / "robots"
PLANAR = str(ROBOTS / "seed003-planar-example-2.toml")
MEL = str(ROBOTS / "seed000-mel-tsukuba.toml")
MICRO = str(ROBOTS / "seed004-micro-manipulator.toml")
ARTIFACTS = ROOT / "tests" / "artifacts"

IMAGES = """(async () => {
  const out = [];
  for (const img of document.images) {
    let decoded = true;
    try { await img.decode(); } catch (e) { decoded = false; }
    const c = document.createElement('canvas');
    c.width = img.naturalWidth; c.height = img.naturalHeight;
    let colours = 0;
    if (decoded && c.width > 0) {
      const g = c.getContext('2d'); g.drawImage(img, 0, 0);
      const d = g.getImageData(0, 0, c.width, c.height).data, seen = new Set();
      for (let i = 0; i < d.length && seen.size < 50; i += 4 * 97) seen.add(d[i] << 16 | d[i + 1] << 8 | d[i + 2]);
      colours = seen.size;
    }
    out.push({alt: img.alt, decoded, width: img.naturalWidth, colours});
  }
  return out;
})()"""

REPORTS = {
    "fk": ["fk", PLANAR, "--lengths", "28.99,13.66,40.53"],
    "singular": ["singular", PLANAR, "--box", "x=-50:50,y=-50:50,phi=0:0.7853981634", "--cells", "4"],
    "trajectory": ["trajectory", MEL, "--from", "-69,-50,500,85deg,10deg,0", "--to", "84,92,500,85deg,10deg,0"],
    "plan": ["plan", MEL, "--from", "-90,140,520,0,0,0", "--to", "55,140,520,0,0,0"],
    "workspace": ["workspace", MICRO, "--orientation", "0,0,0", "--z", "20005"],
}


@pytest.fixture(scope="module")
def browser():
    path = executable()
    if path is None:
        if os.environ.get("CI"):
            pytest.fail("Chromium is missing in CI: .ci/run installs it (apt-get install chromium)")
        pytest.skip("Chromium is not installed (apt-get install chromium): the reports are not opened in a browser")
    b = Browser(path)
    yield b
    b.close()


def check_page(browser, page: Path, must_contain: list[str], name: str) -> str:
    browser.open(page.resolve().as_uri())
    assert browser.errors() == []
    images = browser.evaluate(IMAGES)
    assert images, "a report without figures"
    for img in images:
        assert img["decoded"] and img["width"] > 0 and img["colours"] > 2, img
    text = browser.evaluate("document.body.innerText")
    for s in must_contain:
        assert s in text, s
    ARTIFACTS.mkdir(exist_ok=True)
    browser.screenshot(ARTIFACTS / f"report-{name}.png")
    assert (ARTIFACTS / f"report-{name}.png").stat().st_size > 10_000
    return text


@pytest.mark.parametrize("name", list(REPORTS))
def test_a_report_in_the_browser(name, browser, tmp_path, capsys):
    cert, report = tmp_path / f"{name}.cert", tmp_path / f"{name}.html"
    assert main(REPORTS[name] + ["--json", "--certificate", str(cert), "--report", str(report)]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert proofs.check_file(cert).ok
    sha = hashlib.sha256(cert.read_bytes()).hexdigest()
    text = check_page(browser, report, [sha, f"certkin check {cert.name}", "certkin 0.1"], name)   # (from its directory)
    verdict = browser.evaluate("document.getElementById('verdict').innerText")
    status = doc.get("status") or ("complete" if doc.get("complete") else None) or \
        ("singular" if doc["counts"]["singular"] else "singularity-free")
    assert status.split("-")[0].lower() in verdict.lower()
    assert text.index(verdict) < text.index("Robot")          # the verdict comes first


def test_a_report_without_a_certificate_says_so(browser, tmp_path, capsys):
    report = tmp_path / "t.html"
    assert main(REPORTS["trajectory"] + ["--report", str(report)]) == 0
    text = check_page(browser, report, ["No certificate was written"], "no-certificate")
    assert "certkin check" not in text


def test_a_batch_report_in_the_browser(browser, tmp_path, capsys):
    jobs = tmp_path / "jobs.jsonl"
    jobs.write_text("".join(json.dumps(j) + "\n" for j in [
        {"id": "a", "command": "fk", "robot": PLANAR, "lengths": "28.99,13.66,40.53"},
        {"id": "b", "command": "trajectory", "robot": MEL, "from": "-69,-50,500,85deg,10deg,0",
         "to": "84,92,500,85deg,10deg,0"},
        {"id": "c", "command": "fk", "robot": PLANAR, "lengths": "1,2"}]))
    out, report = tmp_path / "out", tmp_path / "campaign.html"
    assert main(["batch", str(jobs), "--out", str(out), "--workers", "1", "--report", str(report)]) == 0
    shas = [hashlib.sha256((out / f"{i}.cert").read_bytes()).hexdigest() for i in "ab"]
    text = check_page(browser, report, shas + ["3 jobs", "1 with bad input"], "batch")
    assert "--lengths: expected 3 leg lengths per instance" in text
