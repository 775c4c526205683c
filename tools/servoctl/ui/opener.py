"""Opens the page in the user's browser without the token on the browser's
command line: a browser started with the address as an argument keeps it in
/proc/PID/cmdline, which every user of the computer can read (`ps`). The
browser is handed a local file instead, readable by this user alone (0600 in
a 0700 folder), that forwards to the address; the folder goes when ui stops."""
import html
import json
import os
import shutil
import tempfile
import webbrowser
from pathlib import Path


class PageOpener:
    def __init__(self, opener=webbrowser.open):
        self.opener, self.folder = opener, None

    def open(self, url: str) -> bool:
        """The browser on a file that forwards to url; False: no browser."""
        self.folder = Path(tempfile.mkdtemp(prefix="servoctl-ui-"))  # 0700
        page = self.folder / "open.html"
        fd = os.open(page, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "w") as f:
            f.write(f'<!doctype html><meta charset="utf-8"><meta name="referrer" content="no-referrer">'
                    f'<meta http-equiv="refresh" content="0;url={html.escape(url)}">'
                    f'<script>location.replace({json.dumps(url)})</script>servoctl ui: opening the page\n')
        return bool(self.opener(page.as_uri()))

    def close(self):
        if self.folder is not None:
            shutil.rmtree(self.folder, ignore_errors=True)
            self.folder = None
