"""A pytest plugin that records every figure the tests judge, so that two
runs (two machines, or two numerical kernels on one) can be compared figure
by figure, not only by pass/fail (scripts/figures_compare.py reads it).

Loaded by `-p tests.figure_record` with `-o enable_assertion_pass_hook=true`
(scripts/other_kernels.sh does both) and SERVO_FIGURES naming a folder: each
process appends to its own JSON-lines file there
- for every assertion that passes: the test, the line, the assertion's text
  and pytest's explanation of it, which holds the values it compared;
- for every test: its outcome, the explanation of a failed assertion, and
  what it printed (tests print the figures they judge inside a generator or
  a helper, where the explanation shows no value).
The suite's own runs do not load it, so they pay nothing for it."""
import json
import os

import pytest

_OUT = None


def _write(record: dict) -> None:
    global _OUT
    if _OUT is None:
        folder = os.environ["SERVO_FIGURES"]
        os.makedirs(folder, exist_ok=True)
        _OUT = open(os.path.join(folder, f"figures-{os.getpid()}.jsonl"), "a", encoding="utf-8")
    _OUT.write(json.dumps(record) + "\n")
    _OUT.flush()


def pytest_assertion_pass(item, lineno, orig, expl):
    _write({"test": item.nodeid, "line": lineno, "assert": orig, "explanation": expl})


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    if report.when == "call" or report.failed or report.skipped:
        _write({"test": item.nodeid, "phase": report.when, "outcome": report.outcome,
                "failure": report.longreprtext[-4000:] if report.failed else "",
                "stdout": report.capstdout[-20000:]})


def pytest_configure(config):
    if not os.environ.get("SERVO_FIGURES"):
        raise pytest.UsageError("tests.figure_record needs SERVO_FIGURES: the folder to record the figures in")
    if not config.getini("enable_assertion_pass_hook"):
        raise pytest.UsageError("tests.figure_record needs -o enable_assertion_pass_hook=true")
