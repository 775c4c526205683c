"""Every process the suite starts is stopped, whatever the test did.

The run marks itself in its environment (SERVO_TEST_RUN), which every
process it starts inherits: servo_sim, a virtual board, QEMU, a servoctl
child and what they start in turn, also one whose parent is gone. After
each test, any such process still alive is killed; if the test had passed,
that is a leak, and the run fails at its end naming the test and the
process. At the end of the run any that escaped is killed and fails the run
too.

Under pytest-xdist (scripts/test.sh runs the suite on several workers) each
worker marks its own processes (the run's mark, a dash and the worker's
name) and has its own temporary folder, so that one worker's test never
counts another's simulator as its own; a worker's leaks are reported by the
run, which at its end looks for any worker's process that escaped."""
import os
import shutil
import signal
import tempfile
import time
import uuid

import pytest

MARK = "SERVO_TEST_RUN"
os.environ.setdefault(MARK, uuid.uuid4().hex)
_RUN = os.environ[MARK]
_WORKER = None  # this process's xdist worker name, if it is one
_TMP = None
_leaks = []


def pytest_configure(config):
    global _RUN, _WORKER, _TMP
    if not hasattr(config, "workerinput"):
        return
    # The worker itself keeps the run's mark (its /proc environ); what it
    # starts carries the worker's.
    _WORKER = config.workerinput["workerid"]
    _RUN = os.environ[MARK] = f"{_RUN.split('-')[0]}-{_WORKER}"
    _TMP = os.path.join(tempfile.gettempdir(), f"servo-tests-{_RUN}")
    os.makedirs(_TMP, exist_ok=True)
    os.environ["TMPDIR"] = _TMP
    tempfile.tempdir = None


def _marked(workers: bool = False) -> dict:
    """{pid: command line} of this run's processes, this one excepted;
    with workers, of every xdist worker's (not the workers themselves)."""
    found = {}
    needle = f"{MARK}={_RUN}".encode()
    for name in os.listdir("/proc"):
        if not name.isdigit() or int(name) == os.getpid():
            continue
        try:
            with open(f"/proc/{name}/environ", "rb") as f:
                env = f.read().split(b"\0")
            if not any(v.startswith(needle + b"-") if workers else v == needle for v in env):
                continue
            with open(f"/proc/{name}/cmdline", "rb") as f:
                cmd = f.read().replace(b"\0", b" ").decode(errors="replace").strip()
            with open(f"/proc/{name}/stat") as f:
                if f.read().rsplit(")", 1)[1].split()[0] == "Z":
                    continue  # a zombie: gone, waiting for its parent
        except OSError:
            continue  # gone meanwhile, or not ours to read
        found[int(name)] = cmd
    return found


def _kill(pids) -> None:
    for pid in pids:
        try:
            os.kill(pid, signal.SIGKILL)
        except OSError:
            pass
    deadline = time.monotonic() + 5.0
    while time.monotonic() < deadline and any(os.path.exists(f"/proc/{p}") for p in pids):
        for pid in pids:
            try:
                os.waitpid(pid, os.WNOHANG)  # our own children: reaped here
            except ChildProcessError:
                pass
        time.sleep(0.02)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    if report.when == "call":
        item.passed_call = report.passed


def _parent(pid: int) -> int:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return int(f.read().rsplit(")", 1)[1].split()[1])
    except (OSError, ValueError, IndexError):
        return 0


def _owned_by(pid: int, before: set) -> bool:
    """Whether pid descends from a process that was up before the test (a
    module's browser starting a helper while a test runs): that process's
    fixture stops it, not the test."""
    for _ in range(64):
        pid = _parent(pid)
        if pid <= 1 or pid == os.getpid():
            return False
        if pid in before:
            return True
    return False


@pytest.fixture(autouse=True)
def _no_process_outlives_its_test(request):
    """Torn down after every other fixture of the test (autouse fixtures
    are set up first)."""
    before = set(_marked())
    yield
    left = {pid: cmd for pid, cmd in _marked().items() if pid not in before and not _owned_by(pid, before)}
    if left:
        _kill(left)
        if getattr(request.node, "passed_call", False):
            _leaks.append((request.node.nodeid, sorted(left.values())))


def pytest_sessionfinish(session, exitstatus):
    # The xdist controller runs this while its workers (which carry the
    # run's mark) are still up, each having looked for its own leaks.
    escaped = _marked(workers=session.config.pluginmanager.has_plugin("dsession"))
    if escaped:
        _kill(escaped)
        _leaks.append(("the run", sorted(escaped.values())))
    if _WORKER:
        session.config.workeroutput["servo_leaks"] = list(_leaks)
        shutil.rmtree(_TMP, ignore_errors=True)
        return
    if _leaks:
        for where, cmds in _leaks:
            print(f"\nprocess guard: {where} left running: {'; '.join(cmds)}")
        session.exitstatus = pytest.ExitCode.TESTS_FAILED


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error):
    """An xdist worker finished: its leaks are the run's."""
    _leaks.extend(tuple(leak) for leak in getattr(node, "workeroutput", {}).get("servo_leaks", []))


def pytest_terminal_summary(terminalreporter):
    if _leaks:
        terminalreporter.write_line(f"process guard: {len(_leaks)} leak(s), listed above", red=True)
