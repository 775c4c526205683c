"""rich's console for servoctl's output. A reader that stops reading
(`servoctl scan | head -1`) ends a command the same way whatever printed
last: app.main meets the closed pipe and exits 0, quietly, as a Unix
filter does; rich's own console would exit 1 without a word. A command
that changes servos is not cut short by it: its output goes nowhere from
then on, it finishes, and its exit code is its own (pipe_guard)."""
import contextlib
import os
import sys

# Commands that only read and print: a closed pipe ends them (exit 0).
READERS = {"scan", "ping", "info", "faults", "store", "monitor", "bench", "record",
           ("config", "get"), ("config", "dump"), ("config", "diff")}


class _Silenced:
    """stdout that, once its reader is gone, writes to /dev/null instead."""

    def __init__(self, out):
        self._out, self._gone = out, False

    def _close(self):
        if not self._gone:  # what is still buffered goes there too, at exit
            os.dup2(os.open(os.devnull, os.O_WRONLY), self._out.fileno())
        self._gone = True

    def write(self, text):
        try:
            return len(text) if self._gone else self._out.write(text)
        except BrokenPipeError:
            self._close()
            return len(text)

    def flush(self):
        try:
            None if self._gone else self._out.flush()
        except BrokenPipeError:
            self._close()

    def __getattr__(self, name):
        return getattr(self._out, name)


@contextlib.contextmanager
def pipe_guard(args):
    """Around a command: one that changes servos outlives a closed stdout."""
    if args.command in READERS or (args.command, getattr(args, "action", None)) in READERS:
        yield
        return
    out = sys.stdout
    sys.stdout = _Silenced(out)
    try:
        yield
    finally:
        sys.stdout = out


def stdout():
    """A rich Console on stdout that leaves a closed pipe to app.main."""
    from rich.console import Console  # rich loads only where a command uses it

    class PipeConsole(Console):
        def on_broken_pipe(self) -> None:
            raise BrokenPipeError("the reader closed the pipe")  # met by app.main

    return PipeConsole()


def progress(*columns, **options):
    """rich's Progress, its console stdout()."""
    from rich.progress import Progress

    return Progress(*columns, console=stdout(), **options)
