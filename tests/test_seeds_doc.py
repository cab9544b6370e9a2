"""docs/seeds.md maps each seed example to its test: every test it names exists."""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_every_test_named_in_docs_seeds_exists():
    text = (ROOT / "docs" / "seeds.md").read_text()
    listed = re.findall(r"`(test_\w+\.py)` \(([^)]*)\)", text)      # `file.py` (`test_a`, `test_b`)
    named = re.findall(r"(test_\w+\.py)::(test_\w+)", text) + [
        (f, t) for f, names in listed for t in re.findall(r"test_\w+", names)]
    robots = re.findall(r"`(seed\d{3}-[\w.-]+\.toml)`", text)
    assert len(named) > 30 and len(robots) >= 7
    for f, t in named:
        assert re.search(rf"^def {t}\(", (ROOT / "tests" / f).read_text(), re.M), f"{f}::{t}"
    for r in robots:
        assert (ROOT / "examples" / "robots" / r).exists(), r
