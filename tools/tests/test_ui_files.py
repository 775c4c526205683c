"""servoctl ui's limits on the computer it runs on (docs/ui.md, "Files" and
"The token"): the page names files in one folder only, and the browser is
not handed the token on its command line. No simulator, no browser."""
import os
import stat

import pytest

from servoctl import args as args_
from servoctl.args import build_parser
from servoctl.errors import UsageError
from servoctl.ui.files import Folder
from servoctl.ui.opener import PageOpener


def _confined(folder, *argv):
    args = build_parser().parse_args(["--port", "loop://", *argv])
    if args.command == "config":
        args_.config_operands(args)
    folder.confine(args)
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
                       (["bench", "--ids", "1", "--image", "c.json"], "image"), (["identify", "1", "--mujoco", "c.json"], "mujoco")):
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
