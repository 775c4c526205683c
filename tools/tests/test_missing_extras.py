"""servoctl's command line without its extra (rich): --version and --help
still answer, and a command says which extra to install, in one line."""

from .lerobot.test_core_dependencies import core_modules, run_alone


def test_the_version_and_help_need_no_rich(tmp_path):
    """pyserial alone: --version and --help answer; a command says which extra, one line."""
    script = "import sys; from servoctl.cli import main; sys.exit(main(sys.argv[1].split()))"

    def run(argv):
        (tmp_path / argv.split()[-1].strip("-")).mkdir()

        class Line:
            url = argv  # run_alone's argument to the script
        return run_alone(tmp_path / argv.split()[-1].strip("-"), script, Line, core_modules())

    version, helped, scan = run("--version"), run("--help"), run("--port socket://127.0.0.1:9 scan")
    assert version.returncode == 0 and version.stdout.startswith("servoctl 0."), version.stdout + version.stderr
    assert helped.returncode == 0 and "Exit codes" in helped.stdout, helped.stderr
    assert scan.returncode == 2 and scan.stderr.count("\n") == 1, scan.stderr
    assert scan.stderr.endswith("pip install 'servoctl[cli]' (in a clone: pip install -e './tools[cli]')\n")
