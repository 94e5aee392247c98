"""Files and folders written all or nothing, shared by images, projects, bundles and tile sets.

A file is written to a hidden temporary sibling and renamed over the target only when complete;
a folder (an export bundle, a tile set) is filled as a hidden temporary sibling folder and
swapped in by two renames. A full disk, a crash, a cancel or a ``kill -9`` therefore never leaves
a half-written file or a folder mixing two runs.

Temporaries carry the writing process's id in their names (``.NAME.PID-XXXXXXXX.tmp``,
``.NAME.tmp-PID-XXXXXXXX``, ``.NAME.old-PID-XXXXXXXX``): the next write to the same target
removes those whose process is gone (or that are older than a day), and puts back a previous
folder that a killed swap had moved aside. Nothing else is ever deleted: a folder is replaced
only when every file in it is one the program wrote itself (the caller says which).
"""

from __future__ import annotations

import errno
import os
import re
import shutil
import stat
import tempfile
import time
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager, suppress
from pathlib import Path
from typing import BinaryIO

STALE_AGE = 24 * 3600.0
"""Seconds after which a temporary is stale even if a process with its id is running (ids are
reused)."""

__all__ = [
    "InputError",
    "OutputError",
    "atomic_path",
    "check_folder",
    "check_writable",
    "clean_stale",
    "open_input",
    "replace_folder",
    "umask",
    "write_bytes_atomically",
    "write_problem",
]


class OutputError(OSError):
    """An output could not be written; the message names it and says why. ``errno`` holds the
    underlying error number (e.g. ``ENOSPC``) when there is one."""

    def __init__(self, code: int | None, message: str, reason: str | None = None):
        super().__init__(message)
        self.errno = code
        self.reason = reason or message

    def __str__(self) -> str:
        return self.args[0]


class InputError(ValueError):
    """An input file cannot be read; the message is the reason (callers add the file name)."""


_OPEN_REASONS = {
    errno.ELOOP: "is a symbolic link loop (or too many links), not a file",
    errno.ENOTDIR: "a part of the path is a file, not a folder",
    errno.ENAMETOOLONG: "the path is too long",
    errno.ENXIO: "is a socket, not a regular file",
    errno.EACCES: "permission denied",
    errno.EPERM: "permission denied",
}
_KINDS = (
    (stat.S_ISFIFO, "is a named pipe (FIFO), not a regular file"),
    (stat.S_ISCHR, "is a device, not a regular file"),
    (stat.S_ISBLK, "is a device, not a regular file"),
    (stat.S_ISSOCK, "is a socket, not a regular file"),
)


def open_input(path, *, max_bytes: int, what: str = "a file") -> BinaryIO:
    """Open a regular file of at most ``max_bytes`` bytes for reading, after checking what it
    is from its inode: a folder, a FIFO (never waited on), a device such as ``/dev/zero``, a
    socket, an empty or too-large file, a broken link or a link loop raise :class:`InputError`
    before a byte is read. ``what`` names the expected kind ("an image")."""
    name = os.fspath(path)
    try:
        fd = os.open(name, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        if os.path.islink(name):
            raise InputError(f"is a broken symbolic link (to {os.readlink(name)})") from None
        raise InputError("no such file") from None
    except OSError as exc:
        raise InputError(_OPEN_REASONS.get(exc.errno, exc.strerror or str(exc))) from None
    try:
        st = os.fstat(fd)
        if stat.S_ISDIR(st.st_mode):
            raise InputError(f"is a folder, not {what}")
        for test, why in _KINDS:
            if test(st.st_mode):
                raise InputError(why)
        if not stat.S_ISREG(st.st_mode):
            raise InputError("is not a regular file")
        if st.st_size == 0:
            raise InputError("the file is empty")
        if st.st_size > max_bytes:
            raise InputError(
                f"the file is {st.st_size:,} bytes, over the limit of {max_bytes:,} for {what}"
            )
        os.set_blocking(fd, True)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def umask() -> int:
    """The process umask, read without changing it (os.umask would race other threads)."""
    try:
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    return 0o022


def reason(exc: BaseException) -> str:
    """A short human reason for an error while writing."""
    if isinstance(exc, OSError):
        if exc.errno == errno.ENOSPC:
            return "the disk is full"
        if exc.errno in (errno.EACCES, errno.EPERM):
            return "permission denied (read-only folder?)"
        if exc.errno == errno.EROFS:
            return "read-only file system"
        if exc.errno == errno.EDQUOT:
            return "the disk quota is exceeded"
        return exc.strerror or str(exc)
    return str(exc) or type(exc).__name__


def write_problem(folder: Path, exc: OSError) -> str:
    """Why ``folder`` cannot take a new file: a file in the way of its path, else the OS's
    reason."""
    for q in (folder, *folder.parents):
        if q.exists():
            if not q.is_dir():
                return f"{q} is a file, not a folder"
            break
    return reason(exc)


def check_writable(folder, *, name: str | None = None) -> None:
    """Make sure a file can be created in ``folder`` (or, if it is missing, that it can be made
    in its nearest existing ancestor), before any long work and without leaving anything
    behind. Raises :class:`OutputError` "{name}: cannot write there (why)"; ``name`` defaults
    to the folder."""
    p = Path(os.fspath(folder) or ".")
    shown = name or str(p)
    q = p
    while not q.exists() and q != q.parent:
        q = q.parent
    try:
        if not q.is_dir():
            raise NotADirectoryError(errno.ENOTDIR, "not a folder")
        if q == p:
            with tempfile.TemporaryFile(dir=p):
                pass
        elif not os.access(q, os.W_OK | os.X_OK):
            code = errno.EROFS if _read_only(q) else errno.EACCES
            raise OSError(code, os.strerror(code))
    except OSError as exc:
        why = write_problem(p, exc)
        raise OutputError(exc.errno, f"{shown}: cannot write there ({why})", why) from None


def _read_only(path: Path) -> bool:
    try:
        return bool(os.statvfs(path).f_flag & os.ST_RDONLY)
    except OSError:
        return False


# ---------------------------------------------------------------- stale temporaries


def _process_gone(pid: int) -> bool:
    if pid == os.getpid():
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except (PermissionError, OverflowError):  # someone else's live process / not a pid
        return False
    return _zombie(pid)


def _zombie(pid: int) -> bool:
    """True when ``pid`` has exited but is not yet reaped (Linux; False elsewhere): a worker
    killed with its parent stays a zombie until init collects it."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            return f.read().rsplit(b")", 1)[1].split()[0] == b"Z"
    except (OSError, IndexError):
        return False


def _is_stale(path: Path, pid: int) -> bool:
    try:
        age = time.time() - path.lstat().st_mtime
    except OSError:
        return False
    return _process_gone(pid) or age > STALE_AGE


def clean_stale(parent, name: str) -> list[Path]:
    """Remove the temporaries that killed runs left beside ``parent / name``; a folder a
    killed swap had moved aside comes back if ``name`` is missing. Returns what was removed."""
    parent = Path(os.fspath(parent))
    pattern = re.compile(
        rf"^\.{re.escape(name)}\.(?:(?P<pid>\d+)-[a-z0-9_]+(?:\.\w+)?"
        rf"|(?P<kind>tmp|old)-(?P<dpid>\d+)-[a-z0-9_]+)$"
    )
    removed = []
    try:
        entries = list(os.scandir(parent))
    except OSError:
        return removed
    target = parent / name
    for entry in entries:
        m = pattern.match(entry.name)
        if m is None:
            continue
        path = Path(entry.path)
        if not _is_stale(path, int(m["pid"] or m["dpid"])):
            continue
        with suppress(OSError):
            if m["kind"] == "old" and (path / "bundle").is_dir() and not target.exists():
                os.replace(path / "bundle", target)  # killed between the two renames
            if entry.is_dir(follow_symlinks=False):
                shutil.rmtree(path)
            else:
                path.unlink()
            removed.append(path)
    return removed


# ---------------------------------------------------------------- files


@contextmanager
def atomic_path(path, *, suffix: str = ".tmp") -> Iterator[Path]:
    """Yield a temporary sibling of ``path`` to write; on success it replaces ``path`` with the
    usual permissions (0666 minus the umask), on any error it is removed.

    ``mkstemp`` errors (missing or unwritable folder) propagate as ``OSError``.
    """
    p = Path(os.fspath(path))
    parent = p.parent if str(p.parent) else Path(".")
    clean_stale(parent, p.name)
    fd, tmp = tempfile.mkstemp(dir=parent, prefix=f".{p.name}.{os.getpid()}-", suffix=suffix)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~umask())
        os.replace(tmp, p)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_bytes_atomically(path, data: bytes) -> None:
    """Write ``data`` to ``path`` all or nothing (see :func:`atomic_path`)."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)


# ---------------------------------------------------------------- folders


def _holds(folder: Path, path: Path) -> bool:
    return folder == path or folder in path.parents


def check_folder(
    out,
    *,
    owned: Callable[[Path], Iterable[str]] = lambda folder: (),
    inputs: Iterable = (),
    overwrite: bool = True,
    action: str = "export to",
    overwrite_word: str = "overwrite=True",
) -> list[str]:
    """Refuse, before any work, an ``out`` that :func:`replace_folder` would refuse; returns the
    names in it (empty if it does not exist). Also removes stale temporaries of ``out``.
    ``overwrite_word`` is the caller's name of ``overwrite`` (the CLI's ``--overwrite``)."""
    shown = os.fspath(out)
    out = Path(os.path.abspath(shown))

    def fail(code: int, why: str):
        raise OutputError(code, f"cannot {action} {shown}: {why}")

    try:
        real = out.resolve()
    except (RuntimeError, OSError):  # Python reports a symbolic link loop as RuntimeError
        fail(errno.ELOOP, "it is a symbolic link loop")
    if real.exists() and _holds(real, Path.cwd().resolve()):
        fail(
            errno.EINVAL,
            "it is the current folder (or holds it), which cannot be replaced as a "
            "whole; choose another folder, or run from its parent folder",
        )
    for p in inputs:
        try:
            folder = Path(os.path.abspath(os.fspath(p))).resolve().parent if p else None
        except (RuntimeError, OSError):  # an input that is a link loop is refused when read
            folder = None
        if folder is not None and _holds(real, folder):
            fail(
                errno.EINVAL,
                f"it holds the input {os.fspath(p)}, which must never be "
                "replaced; choose another folder",
            )
    if out.exists() and not out.is_dir():
        fail(errno.EEXIST, "it exists and is not a folder")
    clean_stale(out.parent, out.name)
    existing = sorted(e.name for e in os.scandir(out)) if out.is_dir() else []
    if existing and not overwrite:
        fail(
            errno.EEXIST,
            f"the folder is not empty (pass {overwrite_word} to replace it)",
        )
    if existing:
        mine = set(owned(out))
        unknown = [n for n in existing if n not in mine]
        if unknown:
            more = f" and {len(unknown) - 3} more" if len(unknown) > 3 else ""
            fail(
                errno.EEXIST,
                f"it holds {', '.join(unknown[:3])}{more}, not written by Quilt "
                "Studio, which are never replaced or deleted; choose a new or empty folder",
            )
    return existing


def replace_folder(
    out,
    fill: Callable[[Path], None],
    *,
    owned: Callable[[Path], Iterable[str]] = lambda folder: (),
    inputs: Iterable = (),
    overwrite: bool = True,
    action: str = "export to",
) -> None:
    """Create or replace the folder ``out`` as a whole with what ``fill(tmp)`` writes into an
    empty temporary folder.

    An existing non-empty ``out`` is replaced only with ``overwrite`` and only if every entry in
    it is named by ``owned(out)`` (the files an earlier run wrote, from its manifest); a folder
    holding one of the ``inputs``, the current folder and any folder holding another file are
    refused before ``fill`` runs (:func:`check_folder`). Every failure raises
    :class:`OutputError` ("cannot {action} {out}: why"), after which ``out`` is as it was and
    no temporary is left.
    """
    existing = check_folder(out, owned=owned, inputs=inputs, overwrite=overwrite, action=action)
    shown = os.fspath(out)
    out = Path(os.path.abspath(shown))
    parent = out.parent

    def fail(code: int, why: str):
        raise OutputError(code, f"cannot {action} {shown}: {why}")

    try:
        parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(dir=parent, prefix=f".{out.name}.tmp-{os.getpid()}-"))
    except OSError as exc:
        fail(exc.errno or errno.EIO, f"{reason(exc)}; nothing was written")
    old = None
    try:
        fill(tmp)
        os.chmod(tmp, 0o777 & ~umask())
        if out.is_dir():
            if existing:
                old = Path(tempfile.mkdtemp(dir=parent, prefix=f".{out.name}.old-{os.getpid()}-"))
                os.replace(out, old / "bundle")
            else:
                out.rmdir()
        os.replace(tmp, out)
    except BaseException as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        if old is not None and (old / "bundle").exists() and not out.exists():
            os.replace(old / "bundle", out)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
        if not isinstance(exc, OSError) or isinstance(exc, OutputError):
            raise
        why = f"{reason(exc)}; nothing was written"
        raise OutputError(exc.errno or errno.EIO, f"cannot {action} {shown}: {why}") from exc
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)
