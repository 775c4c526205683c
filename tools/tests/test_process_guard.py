"""The suite's process guard (conftest.py) can fail: a passing test that
leaves a process running fails the run, names the test, and the process is
gone afterwards; a failing test's process is stopped too."""
from pathlib import Path

pytest_plugins = ["pytester"]

GUARD = (Path(__file__).parent / "conftest.py").read_text()


def _leaking(marker: Path) -> str:
    """A test that passes and leaves a process running, its pid in marker."""
    return f"""
import subprocess, sys

def test_passes_but_leaks():
    p = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(120)"])
    open({str(marker)!r}, "w").write(str(p.pid))
"""


def test_a_process_left_running_fails_the_run_and_is_stopped(pytester, monkeypatch, tmp_path):
    marker = tmp_path / "sleeper.pid"
    pytester.makeconftest(GUARD)
    pytester.makepyfile(test_leaks=_leaking(marker) + """
def test_fails_and_leaks():
    subprocess.Popen([sys.executable, "-c", "import time; time.sleep(120)"])
    assert False
""")
    monkeypatch.delenv("SERVO_TEST_RUN")  # the inner run marks its own processes
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider")
    assert result.ret == 1
    result.stdout.fnmatch_lines(["*process guard: test_leaks.py::test_passes_but_leaks left running*"])
    assert "test_fails_and_leaks left running" not in result.stdout.str()
    pid = int(marker.read_text())
    assert not Path(f"/proc/{pid}").exists() or "Z" in Path(f"/proc/{pid}/stat").read_text().split()[2]


def test_on_xdist_workers_a_leak_fails_the_run_and_no_worker_takes_another_s(pytester, monkeypatch,
                                                                             tmp_path):
    """scripts/test.sh runs the suite on workers: a leak on a worker still
    fails the run and names its test, and a test on one worker never sees
    (nor stops) a process another worker's test has running meanwhile."""
    marker = tmp_path / "sleeper.pid"
    pytester.makeconftest(GUARD)
    pytester.makepyfile(test_leaks=_leaking(marker), test_busy="""
import subprocess, sys, time

def test_its_process_lives_through_the_other_workers_tests():
    p = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(120)"])
    time.sleep(3)
    assert p.poll() is None
    p.kill()
    p.wait()
""")
    monkeypatch.delenv("SERVO_TEST_RUN")
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider", "-n", "2", "--dist", "loadfile")
    assert result.ret == 1
    result.stdout.fnmatch_lines(["*process guard: test_leaks.py::test_passes_but_leaks left running*"])
    result.assert_outcomes(passed=2)
    pid = int(marker.read_text())
    assert not Path(f"/proc/{pid}").exists() or "Z" in Path(f"/proc/{pid}/stat").read_text().split()[2]


def test_a_helper_that_a_modules_process_starts_during_a_test_is_not_the_tests(pytester, monkeypatch):
    """A module's long-lived process (the UI tests' browser) may start a
    helper of its own while a test runs (chromium's zygote): that helper is
    its fixture's to stop, not a leak of the test; a process the test starts
    still is (the first test above)."""
    pytester.makeconftest(GUARD)
    pytester.makepyfile(test_spawner="""
import os, signal, subprocess, sys, time
import pytest

HELPER = "import subprocess, sys, time; sys.stdin.readline(); " \\
         "c = subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(120)']); " \\
         "print(c.pid, flush=True); time.sleep(120)"

@pytest.fixture(scope="module")
def spawner():
    p = subprocess.Popen([sys.executable, "-c", HELPER], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    yield p
    os.kill(p.helper, signal.SIGKILL)
    p.kill()
    p.wait()
    for _ in range(500):  # SIGKILL is sent, not done: under load the helper ran on past the guard's look
        try:
            with open(f"/proc/{p.helper}/stat") as f:
                if f.read().rsplit(")", 1)[1].split()[0] == "Z":
                    break
        except FileNotFoundError:
            break
        time.sleep(0.01)

def test_the_module_process_starts_a_helper(spawner):
    spawner.stdin.write("\\n")
    spawner.stdin.flush()
    spawner.helper = int(spawner.stdout.readline())
    assert os.path.exists(f"/proc/{spawner.helper}")
""")
    monkeypatch.delenv("SERVO_TEST_RUN")
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider")
    assert result.ret == 0, result.stdout.str()
    assert "process guard" not in result.stdout.str()
