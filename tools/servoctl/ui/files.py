"""The one folder whose files `servoctl ui`'s page may name (docs/ui.md,
"Files"): config save/load/diff, backup, restore, update, bench --image and
identify --mujoco. Anyone holding the token would otherwise read and write
any file the server's user can. A name is taken inside the folder; '..',
an absolute path elsewhere and a symlink that leads out of it are refused
before the command runs."""
from pathlib import Path

from ..errors import UsageError


class Folder:
    def __init__(self, root):
        self.root = Path(root).resolve()
        if not self.root.is_dir():
            raise UsageError(f"ui: --files {root}: no such folder")

    def path(self, name: str) -> str:
        """name's absolute path inside the folder (symlinks followed), or UsageError."""
        given = Path(name)
        if ".." in given.parts:
            self._refuse(name, "'..' is refused")
        full = given if given.is_absolute() else self.root / given
        real = full.resolve()
        if real != self.root and self.root not in real.parents:
            linked = full.parent == self.root or self.root in full.parents  # inside by name, out by a symlink
            self._refuse(name, f"a symlink to {real}, outside it" if linked else "outside it")
        return str(real)

    def _refuse(self, name: str, why: str):
        raise UsageError(f"ui: the page names files in {self.root} only: {name!r}: {why} "
                         f"(start servoctl ui with --files DIR for another folder)")

    def confine(self, args) -> None:
        """Every file a parsed command names, put inside the folder (on args)."""
        command = args.command
        if command == "config" and args.action in ("save", "load"):
            args.file = self.path(args.file)
        elif command == "config" and args.action == "diff":
            args.target, args.other = self._side(args.target), self._side(args.other)
        elif command in ("backup", "restore"):
            args.file = self.path(args.file)
        elif command == "update":
            args.targets = [t if t.isascii() and t.isdigit() else self.path(t) for t in args.targets]
        elif command == "bench" and args.image:
            args.image = self.path(args.image)
        elif command == "identify" and args.mujoco:
            args.mujoco = self.path(args.mujoco)

    def _side(self, text: str) -> str:
        """config diff's side: an ID and 'factory' as they are, a file inside."""
        return text if text == "factory" or (text.isascii() and text.isdigit()) else self.path(text)
