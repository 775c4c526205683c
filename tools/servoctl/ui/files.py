"""The one folder whose files `servoctl ui`'s page may name (docs/ui.md,
"Files"): config save/load/diff, backup, restore, update, bench --image,
identify --mujoco and faults --elf. Anyone holding the token would otherwise read and write
any file the server's user can. A name is taken inside the folder; '..',
an absolute path elsewhere and a symlink that leads out of it are refused
before the command runs.

The command never opens the name itself: a file it reads is copied in,
and one it writes copied out, through the folder's descriptor, each folder
on the way and the file opened with O_NOFOLLOW (Staging). A symlink swapped
in after the check is then refused, not followed."""
import errno
import os
import shutil
import stat
import tempfile
from pathlib import Path

from ..errors import UsageError

# O_NONBLOCK: a FIFO put in the folder does not hold the bus thread in open().
READ = os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC | os.O_NONBLOCK
WRITE = os.O_WRONLY | os.O_CREAT | os.O_TRUNC | os.O_NOFOLLOW | os.O_CLOEXEC | os.O_NONBLOCK


class Folder:
    def __init__(self, root):
        self.root = Path(root).resolve()
        if not self.root.is_dir():
            raise UsageError(f"ui: --files {root}: " + ("not a folder" if self.root.exists() else "no such folder"))
        self.fd = os.open(self.root, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)

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

    def confine(self, args) -> "Staging":
        """Every file a parsed command names checked inside the folder, and
        on args a copy's path in a private folder (Staging): read ones
        copied in now, written ones copied out by Staging.write_out."""
        staging = Staging(self)
        try:
            command = args.command
            if command == "config" and args.action in ("save", "load"):
                args.file = staging.add(args.file, writes=args.action == "save")
            elif command == "config" and args.action == "diff":
                args.target, args.other = self._side(staging, args.target), self._side(staging, args.other)
            elif command in ("backup", "restore"):
                args.file = staging.add(args.file, writes=command == "backup")
            elif command == "update":
                args.targets = [t if t.isascii() and t.isdigit() else staging.add(t) for t in args.targets]
            elif command == "bench" and args.image:
                args.image = staging.add(args.image)
            elif command == "identify" and args.mujoco:
                args.mujoco = staging.add(args.mujoco, writes=True)
            elif command == "faults" and getattr(args, "elf", None):
                args.elf = staging.add(args.elf)
        except BaseException:
            staging.close()
            raise
        return staging

    def _side(self, staging, text: str) -> str:
        """config diff's side: an ID and 'factory' as they are, a file inside."""
        return text if text == "factory" or (text.isascii() and text.isdigit()) else staging.add(text)

    def open(self, real: str, flags: int, name: str) -> int:
        """A descriptor of real (the path path(name) gave) opened from the
        folder's descriptor down, no symlink followed on the way."""
        parts = Path(real).relative_to(self.root).parts
        if not parts:
            self._refuse(name, "the folder itself, not a file")
        fd = os.dup(self.fd)
        try:
            for part in parts[:-1]:
                inner = os.open(part, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC, dir_fd=fd)
                os.close(fd)
                fd = inner
            opened = os.open(parts[-1], flags, 0o666, dir_fd=fd)
        except OSError as e:
            if e.errno in (errno.ELOOP, errno.ENOTDIR):
                self._refuse(name, "a symlink now, put there after it was checked")
            if e.errno == errno.ENXIO:  # a FIFO nobody reads
                self._refuse(name, "not a regular file")
            raise
        finally:
            os.close(fd)
        if not stat.S_ISREG(os.fstat(opened).st_mode):
            os.close(opened)
            self._refuse(name, "not a regular file")
        return opened


class Staging:
    """The copies a command reads and writes, in a folder of this
    process's own (0700), so the command opens no name in the shared one."""

    def __init__(self, folder: Folder):
        self.folder = folder
        self.dir = None
        self.writes = []  # (the name, its real path in the folder, the copy's path)

    def add(self, name: str, writes: bool = False) -> str:
        real = self.folder.path(name)
        if self.dir is None:
            self.dir = tempfile.mkdtemp(prefix="servoctl-ui-file-")
        copy = os.path.join(self.dir, os.path.relpath(real, self.folder.root))
        os.makedirs(os.path.dirname(copy), exist_ok=True)
        if writes:
            if real == str(self.folder.root) or os.path.isdir(real):  # refused now: it said "saved" first
                self.folder._refuse(name, "a folder, not a file to write")
            if os.path.exists(real) and not os.path.isfile(real):  # a FIFO: refused before the command runs
                self.folder._refuse(name, "not a regular file")
            self._folder_of(name, real)
            self.writes.append((name, real, copy))
            return copy
        try:
            fd = self.folder.open(real, READ, name)
        except FileNotFoundError:
            return copy  # none: the command says so, of the name shown()
        with os.fdopen(fd, "rb") as src, open(copy, "wb") as dst:
            shutil.copyfileobj(src, dst)
        return copy

    def _folder_of(self, name: str, real: str) -> None:
        """A file the command writes goes into a folder that exists: refused
        now, before the command runs (it said "saved" of a copy, then the
        copy out failed with a bare errno)."""
        parent = Path(real).parent
        if not parent.is_dir():
            missing = parent
            while not missing.parent.is_dir():
                missing = missing.parent
            what = "not a folder" if missing.exists() else "no such folder"
            raise UsageError(f"ui: {name!r} is not written: {what}: {missing.relative_to(self.folder.root)} "
                             f"in {self.folder.root} (make the folder first)")

    def write_out(self) -> None:
        """What the command wrote, into the folder (after it succeeded)."""
        for name, real, copy in self.writes:
            if os.path.exists(copy):
                try:
                    fd = self.folder.open(real, WRITE, name)
                except OSError as e:  # the folder removed meanwhile, a full disk
                    raise UsageError(f"ui: {name!r} is not written into {self.folder.root}: "
                                     f"{e.strerror}") from None
                with open(copy, "rb") as src, os.fdopen(fd, "wb") as dst:
                    shutil.copyfileobj(src, dst)

    def shown(self, text: str) -> str:
        """A command's words with the copies' names as the folder's."""
        return text if self.dir is None else text.replace(self.dir, str(self.folder.root))

    def close(self) -> None:
        if self.dir is not None:
            shutil.rmtree(self.dir, ignore_errors=True)
