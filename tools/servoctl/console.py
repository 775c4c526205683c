"""rich's console for servoctl's output. A reader that stops reading
(`servoctl scan | head -1`) ends a command the same way whatever printed
last: cli.main meets the closed pipe and exits 0, quietly, as a Unix
filter does; rich's own console would exit 1 without a word."""


def stdout():
    """A rich Console on stdout that leaves a closed pipe to cli.main."""
    from rich.console import Console  # rich loads only where a command uses it

    class PipeConsole(Console):
        def on_broken_pipe(self) -> None:
            raise BrokenPipeError("the reader closed the pipe")  # met by cli.main

    return PipeConsole()


def progress(*columns, **options):
    """rich's Progress, its console stdout()."""
    from rich.progress import Progress

    return Progress(*columns, console=stdout(), **options)
