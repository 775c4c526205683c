"""servoctl ui's limits on the computer it runs on (docs/ui.md, "Files" and
"The token"): the page names files in one folder only, and the browser is
not handed the token on its command line. No simulator, no browser."""
import os
import stat

import pytest

from servoctl.cli import args as args_
from servoctl.cli.args import build_parser
from servoctl.errors import UsageError
from servoctl.ui.files import Folder
from servoctl.ui.opener import PageOpener


def _confined(folder, *argv):
    """The parsed command, each file it names as the page's folder shows it
    (the command itself is handed a private copy's path: files.Staging)."""
    args = build_parser().parse_args(["--port", "loop://", *argv])
    if args.command == "config":
        args_.config_operands(args)
    staging = folder.confine(args)
    for attr in ("file", "image", "mujoco", "elf", "target", "other"):
        if isinstance(getattr(args, attr, None), str):
            setattr(args, attr, staging.shown(getattr(args, attr)))
    if args.command == "update":
        args.targets = [staging.shown(t) for t in args.targets]
    staging.close()
    return args


def test_the_page_names_files_in_its_folder_only(tmp_path):
    """Anyone with the token read and wrote any file the server's user
    could (config save/load/diff, backup, restore, update)."""
    root, outside = tmp_path / "bench", tmp_path / "secret"
    root.mkdir()
    outside.mkdir()
    (root / "sub").mkdir()
    (root / "out").symlink_to(outside)
    (root / "in").symlink_to(root / "sub")
    folder = Folder(root)
    assert folder.path("servo.json") == str(root / "servo.json")
    assert folder.path(str(root / "sub" / "a.json")) == str(root / "sub" / "a.json")
    assert folder.path("in/a.json") == str(root / "sub" / "a.json")  # a symlink that stays inside
    for name, why in (("../secret/x.json", "'..' is refused"), ("sub/../../x", "'..' is refused"),
                      (str(outside / "x.json"), "outside it"), ("/etc/passwd", "outside it"),
                      ("out/x.json", f"a symlink to {outside / 'x.json'}, outside it")):
        with pytest.raises(UsageError) as refused:
            folder.path(name)
        assert f"the page names files in {root} only: {name!r}: {why}" in str(refused.value)
        assert "--files DIR" in str(refused.value)
    with pytest.raises(UsageError, match="no such folder"):
        Folder(tmp_path / "none")


def test_every_command_that_names_a_file_is_confined(tmp_path):
    folder = Folder(tmp_path)
    for argv, attr in ((["config", "save", "1", "c.json"], "file"), (["config", "load", "1", "c.json"], "file"),
                       (["backup", "c.json"], "file"), (["restore", "c.json"], "file"),
                       (["bench", "--ids", "1", "--image", "c.json"], "image"), (["identify", "1", "--mujoco", "c.json"], "mujoco"),
                       (["faults", "1", "--elf", "c.json"], "elf")):
        assert getattr(_confined(folder, *argv), attr) == str(tmp_path / "c.json"), argv
        with pytest.raises(UsageError, match="names files in"):
            _confined(folder, *argv[:-1], "/etc/passwd")
    diff = _confined(folder, "config", "diff", "3", "factory")
    assert (diff.target, diff.other) == ("3", "factory")
    assert _confined(folder, "config", "diff", "c.json", "1").target == str(tmp_path / "c.json")
    with pytest.raises(UsageError):
        _confined(folder, "config", "diff", "1", "/etc/shadow")
    assert _confined(folder, "update", "5", "f.img", "6").targets == ["5", str(tmp_path / "f.img"), "6"]
    with pytest.raises(UsageError):
        _confined(folder, "update", "5", "../f.img")
    assert _confined(folder, "move", "1", "90").id == 1  # no file: as it was


def test_the_browser_is_not_handed_the_token(tmp_path):
    """webbrowser.open(url) put the token on chromium's command line, which
    every user reads in ps (/proc/PID/cmdline)."""
    url = "http://127.0.0.1:8765/?token=s3cr3t-t0ken"
    handed = []
    opener = PageOpener(lambda arg: handed.append(arg) or True)
    assert opener.open(url)
    [arg] = handed
    assert "s3cr3t" not in arg and arg.startswith("file://")
    page = opener.folder / "open.html"
    assert stat.S_IMODE(os.stat(page).st_mode) == 0o600
    assert stat.S_IMODE(os.stat(opener.folder).st_mode) == 0o700
    assert f'location.replace("{url}")' in page.read_text()
    opener.close()
    assert not page.exists()


@pytest.mark.parametrize("swapped", ["the file", "its folder"])
def test_a_symlink_swapped_in_after_the_check_is_not_followed(tmp_path, swapped):
    """The name was checked, then the command opened it by name: a symlink
    put in its place meanwhile (by another user of a shared folder) was
    followed, and config save wrote outside the folder."""
    root, outside = tmp_path / "bench", tmp_path / "secret"
    root.mkdir()
    outside.mkdir()
    (root / "sub").mkdir()
    (outside / "servo.json").write_text("precious")
    args = build_parser().parse_args(["--port", "loop://", "config", "save", "1", "sub/servo.json"])
    args_.config_operands(args)
    staging = Folder(root).confine(args)  # checked: inside
    if swapped == "the file":
        (root / "sub" / "servo.json").symlink_to(outside / "servo.json")
    else:
        (root / "sub").rmdir()
        (root / "sub").symlink_to(outside)
    with open(args.file, "w") as f:  # what config save does with the name it is given
        f.write("written")
    try:
        if staging is not None:
            with pytest.raises(UsageError, match="a symlink now, put there after it was checked"):
                staging.write_out()
    finally:
        if staging is not None:
            staging.close()
    assert (outside / "servo.json").read_text() == "precious"


def test_a_file_the_command_reads_is_read_through_the_folder(tmp_path):
    """config load, restore, diff and update read a copy taken with no
    symlink followed; the command's words name the folder's file."""
    (tmp_path / "c.json").write_text("{}")
    args = build_parser().parse_args(["--port", "loop://", "restore", "c.json"])
    staging = Folder(tmp_path).confine(args)
    try:
        assert args.file != str(tmp_path / "c.json") and open(args.file).read() == "{}"
        assert staging.shown(f"cannot read {args.file}") == f"cannot read {tmp_path / 'c.json'}"
    finally:
        staging.close()


def test_a_fifo_in_the_folder_is_refused_not_waited_on(tmp_path):
    """A FIFO named as an update's image or a restore's file held the bus
    thread in open() until someone wrote to it."""
    os.mkfifo(tmp_path / "image.img")
    args = build_parser().parse_args(["--port", "loop://", "restore", "image.img"])
    with pytest.raises(UsageError, match="'image.img': not a regular file"):
        Folder(tmp_path).confine(args)
    # A FIFO as a file the command writes: it said "saved" (identify ran its whole experiment) first.
    args = build_parser().parse_args(["--port", "loop://", "backup", "image.img"])
    with pytest.raises(UsageError, match="'image.img': not a regular file"):
        Folder(tmp_path).confine(args)
    # faults --elf opened its path itself: outside the folder, and a FIFO held the bus thread.
    args = build_parser().parse_args(["--port", "loop://", "faults", "1", "--elf", "image.img"])
    with pytest.raises(UsageError, match="'image.img': not a regular file"):
        Folder(tmp_path).confine(args)


def test_a_file_written_into_a_folder_that_is_not_there_is_refused(tmp_path):
    """config save, backup and identify --mujoco into a missing folder:
    refused before the command runs, the folder named."""
    folder = Folder(tmp_path)
    (tmp_path / "plain").write_text("")
    for argv in (["config", "save", "1", "none/c.json"], ["backup", "none/c.json"],
                 ["identify", "1", "--mujoco", "none/c.xml"]):
        with pytest.raises(UsageError, match=f"is not written: no such folder: none in {tmp_path}"):
            _confined(folder, *argv)
    with pytest.raises(UsageError, match="not a folder: plain"):
        _confined(folder, "backup", "plain/c.json")
    with pytest.raises(UsageError, match="not a folder"):
        Folder(tmp_path / "plain")
    assert _confined(folder, "config", "load", "1", "none/c.json").file == str(tmp_path / "none" / "c.json")


def test_a_write_to_a_folders_name_is_refused_before_the_command_runs(tmp_path):
    """backup into "sub/" (a folder there) said "saved 1 servo(s)", then
    failed copying out; config save "" and "." ran before being refused."""
    (tmp_path / "sub").mkdir()
    for argv in (["backup", "sub/"], ["config", "save", "1", "."], ["config", "save", "1", ""]):
        args = build_parser().parse_args(["--port", "loop://", *argv])
        if args.command == "config":
            args_.config_operands(args)
        with pytest.raises(UsageError, match="a folder, not a file to write"):
            Folder(tmp_path).confine(args)
