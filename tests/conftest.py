"""``pytest --certificate-ratios``: for every test that has a certificate re-checked by ``proofs``, the CPU
seconds spent solving (the test's setup and call, less its checks), the CPU seconds of its accepted checks
and their ratio, as a table at the end of the run (target: a check within 10x its solve, issue 17).

A test that checks one certificate several times (forgeries that remain valid proofs) counts each check;
its ratio is an upper bound.  Solves under 50 ms are listed but not flagged: a check there is dominated
by fixed costs (reading the model, the first batch).
"""
import time

import pytest

import proofs

_rows = {}          # test id -> [cpu of setup + call, cpu in accepted checks, cpu in all checks, checks]


def pytest_addoption(parser):
    parser.addoption("--certificate-ratios", action="store_true",
                     help="print, per test, the CPU time of its certificate checks against its solving time")


@pytest.fixture(autouse=True)
def _certificate_ratio(request, monkeypatch):
    if not request.config.getoption("--certificate-ratios"):
        yield
        return
    row = _rows.setdefault(request.node.nodeid, [0.0, 0.0, 0.0, 0])
    check = proofs.check

    def timed(*args, **kwargs):
        t = time.process_time()
        report = check(*args, **kwargs)
        dt = time.process_time() - t
        row[2] += dt
        if report.ok:
            row[1] += dt
            row[3] += 1
        return report
    monkeypatch.setattr(proofs, "check", timed)
    yield


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    t = time.process_time()
    yield
    if item.nodeid in _rows:
        _rows[item.nodeid][0] += time.process_time() - t


def pytest_terminal_summary(terminalreporter, config):
    if not config.getoption("--certificate-ratios"):
        return
    rows = [(k, v) for k, v in _rows.items() if v[3]]
    if not rows:
        return terminalreporter.write_line("certificate ratios: no certificate was checked in this process")
    terminalreporter.section("certificate checks against solves (CPU seconds)")
    terminalreporter.write_line(f"{'solve':>8s} {'check':>8s} {'ratio':>6s} {'checks':>6s}  test")
    over = 0
    for name, (total, ok, every, n) in sorted(rows, key=lambda r: -r[1][1] / max(r[1][0] - r[1][2], 1e-3)):
        solve = max(total - every, 1e-3)
        flag = "  > 10x" if ok / solve > 10 and solve >= 0.05 else ""
        over += bool(flag)
        terminalreporter.write_line(f"{solve:8.3f} {ok:8.3f} {ok / solve:6.1f} {n:6d}  {name}{flag}")
    terminalreporter.write_line(f"{len(rows)} tests with accepted checks, {over} above 10x (solves of 50 ms or more)")
