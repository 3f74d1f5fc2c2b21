"""Output files: refuse to overwrite without force, write atomically, hash inputs.

Every file hrgtc writes (recordings, model files, reports, C sources) goes
through here: :func:`refuse_existing` is the one "output exists, pass --force"
check, :func:`temporary_beside` and :func:`publish` the temporary file that is
synced and renamed into place (so a reader never sees half a file), and
:func:`write_text_atomic` both for a small text file.
"""

from __future__ import annotations

import ctypes
import errno
import hashlib
import os
import re
import shutil
import signal
import tempfile
import threading
import warnings
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from hrgtc.errors import HrgtcWarning, InputError, OutputExistsError

PathLike = str | os.PathLike[str]


def refuse_existing(paths: PathLike | Iterable[PathLike], force: bool,
                    note: str = "") -> None:
    """Raise :class:`OutputExistsError` if any of ``paths`` exists and ``force`` is False.

    Parameters
    ----------
    paths
        One output path or several.
    force
        Overwriting was allowed (``--force``): nothing is checked.
    note
        Said after the file names (e.g. ``"nothing was written"``).
    """
    if force:
        return
    extra = f"; {note}" if note else ""
    if isinstance(paths, str | os.PathLike):
        if Path(paths).exists():
            raise OutputExistsError(
                f"{paths} exists{extra}; pass --force (force=True) to overwrite it")
        return
    existing = [str(p) for p in paths if Path(p).exists()]
    if existing:
        names = existing[0] if len(existing) == 1 else (
            ", ".join(existing[:-1]) + " and " + existing[-1])
        raise OutputExistsError(f"{len(existing)} output file(s) exist: {names}{extra}; "
                                "pass --force (force=True) to overwrite")


def current_umask() -> int:
    """The process's file-creation mask (read by setting and restoring it)."""
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _pid_alive(pid: int) -> bool:
    """True if a process ``pid`` exists (or may exist: it belongs to another user)."""
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def clean_stale_temporaries(target: PathLike) -> list[Path]:
    """Remove the temporary files an earlier, dead writer of ``target`` left behind.

    A temporary file ``.<name>.<pid>.<random>.tmp`` whose process no longer runs is
    removed. Those of a running process are left alone; those without a PID in their
    name (older hrgtc) are only reported, with a :class:`StaleTemporaryWarning`.

    Returns
    -------
    list of Path
        The files removed.
    """
    target = Path(target)
    pattern = re.compile(re.escape(f".{target.name}.") + r"(?:(\d+)\.)?[^/]*\.tmp$")
    removed: list[Path] = []
    unknown: list[str] = []
    try:
        entries = list(target.parent.iterdir())
    except OSError:
        return removed
    for entry in entries:
        match = pattern.fullmatch(entry.name)
        if match is None or str(entry) in _ACTIVE:
            continue
        pid = match.group(1)
        if pid is None:
            unknown.append(entry.name)
        elif int(pid) != os.getpid() and not _pid_alive(int(pid)):
            try:
                entry.unlink()
            except OSError:
                unknown.append(entry.name)
            else:
                removed.append(entry)
    if unknown:
        warnings.warn(
            f"{target.parent}: {len(unknown)} temporary file(s) of an interrupted earlier "
            f"write of {target.name} remain ({', '.join(unknown[:3])}); remove them if no "
            "other program is writing that file",
            StaleTemporaryWarning, stacklevel=2)
    return removed


class StaleTemporaryWarning(HrgtcWarning):
    """Temporary files of an earlier, interrupted write remain next to an output."""


def temporary_beside(target: Path) -> str:
    """An empty hidden temporary file next to ``target``, with ordinary permissions.

    ``mkstemp`` makes 0600 files; the file gets ``0666 & ~umask`` like any other
    file the user creates. Its name carries this process's PID, and stale ones
    of dead processes are removed first (:func:`clean_stale_temporaries`). Until
    the caller removes it (or :func:`publish` renames it), a SIGTERM or SIGINT
    removes it (:func:`removed_on_signal`).
    """
    clean_stale_temporaries(target)
    fd, temporary = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.{os.getpid()}.",
                                     suffix=".tmp")
    os.close(fd)
    try:
        os.chmod(temporary, 0o666 & ~current_umask())
    except BaseException:
        os.unlink(temporary)
        raise
    _register(temporary)
    return temporary


# -- temporary files removed on SIGTERM / SIGINT -------------------------------------------
_ACTIVE: set[str] = set()
_LOCK = threading.Lock()
_PREVIOUS: dict[int, Any] = {}
_SIGNALS = (signal.SIGTERM, signal.SIGINT)


def _on_signal(signum: int, frame: Any) -> None:
    """Remove every registered temporary file, then do what the previous handler did."""
    for path in list(_ACTIVE):
        try:
            os.unlink(path)
        except OSError:
            pass
    _ACTIVE.clear()
    previous = _PREVIOUS.get(signum, signal.SIG_DFL)
    _restore_handlers()
    if callable(previous):
        previous(signum, frame)  # e.g. Python's SIGINT handler: KeyboardInterrupt
    elif previous == signal.SIG_DFL:
        os.kill(os.getpid(), signum)  # die of the signal, as without us


def _install_handlers() -> None:
    if _PREVIOUS or threading.current_thread() is not threading.main_thread():
        return
    for signum in _SIGNALS:
        previous = signal.getsignal(signum)
        if previous == signal.SIG_IGN or previous is None:
            continue  # ignored (e.g. nohup) or set outside Python: leave it
        _PREVIOUS[signum] = previous
        signal.signal(signum, _on_signal)


def _restore_handlers() -> None:
    if threading.current_thread() is not threading.main_thread():
        return
    for signum, previous in list(_PREVIOUS.items()):
        if signal.getsignal(signum) is _on_signal:
            signal.signal(signum, previous)
    _PREVIOUS.clear()


def _register(path: str) -> None:
    with _LOCK:
        _ACTIVE.add(str(path))
        _install_handlers()


def forget_temporary(path: PathLike) -> None:
    """The temporary file ``path`` was renamed or removed: stop watching it."""
    with _LOCK:
        _ACTIVE.discard(str(path))
        if not _ACTIVE:
            _restore_handlers()


@contextmanager
def removed_on_signal(path: PathLike) -> Iterator[None]:
    """Remove ``path`` if a SIGTERM or SIGINT arrives inside the block.

    The handlers are installed in the main thread only (Python delivers signals
    there) and the previous ones are restored when no watched file remains; after
    removing the file the previous handler runs (SIGINT raises KeyboardInterrupt,
    a default SIGTERM ends the process).
    """
    _register(str(path))
    try:
        yield
    finally:
        forget_temporary(path)


def check_writable(target: PathLike, expected_bytes: float = 0.0) -> None:
    """Refuse early an output that cannot be written: before the long work, not after it.

    Parameters
    ----------
    target
        Output file.
    expected_bytes
        Estimate of its size; the free space must exceed it (with 5 % to spare). [B]

    Raises
    ------
    InputError
        The directory is missing, not writable, or has too little free space.
    """
    target = Path(target)
    directory = target.parent if str(target.parent) else Path(".")
    if target.is_dir():
        raise InputError(f"{target} is a directory; give a file name")
    if not directory.is_dir():
        raise InputError(f"{target}: directory {directory} does not exist; create it first")
    if not os.access(directory, os.W_OK | os.X_OK):
        raise InputError(f"{target}: directory {directory} is not writable; choose another "
                         "output path or fix its permissions")
    if expected_bytes > 0:
        try:
            free = shutil.disk_usage(directory).free
        except OSError:
            return
        if free < 1.05 * expected_bytes:
            raise InputError(
                f"{target}: {free / 1e6:.1f} MB free in {directory} but the output needs about "
                f"{expected_bytes / 1e6:.1f} MB; free some space or write elsewhere")


def describe_os_error(exc: OSError, what: str = "") -> str:
    """One line for an operating-system error while writing or reading ``what``."""
    name = exc.filename or what or "file"
    if exc.errno == errno.ENOSPC:
        return f"{name}: the disk is full (no space left on device); free some space"
    if exc.errno in (errno.EACCES, errno.EPERM):
        return f"{name}: permission denied; choose another path or fix its permissions"
    if exc.errno == errno.EROFS:
        return f"{name}: read-only file system; write elsewhere"
    return f"{name}: {exc.strerror or exc}"


def fsync_file(path: PathLike) -> None:
    """Flush a closed file's data to disk."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


# sync_file_range(2) flags (linux/fs.h)
_WAIT_BEFORE, _WRITE, _WAIT_AFTER = 1, 2, 4


def _sync_file_range() -> Any:
    """libc's ``sync_file_range`` (Linux), or None where it is missing."""
    try:
        function = ctypes.CDLL(None, use_errno=True).sync_file_range
    except (OSError, AttributeError):
        return None
    function.argtypes = [ctypes.c_int, ctypes.c_int64, ctypes.c_int64, ctypes.c_uint]
    function.restype = ctypes.c_int
    return function


class WriteBehind:
    """Write a growing file's finished bytes to disk while the next ones are produced.

    A file written in big pieces and fsynced at the end makes its writer wait, at the
    end, for all of it to reach the disk. Calling :meth:`advance` after each piece
    starts the disk write of that piece at once and waits (in the calling thread,
    typically a writer thread running beside the computation) for the piece before
    it, so at most two pieces are ever unwritten and the final fsync, which stays the
    guarantee of durability, has little left to do. Linux ``sync_file_range(2)``;
    where it is missing, ``posix_fadvise(DONTNEED)`` starts the write-back without
    waiting; elsewhere nothing is done.

    Parameters
    ----------
    path
        The file being written (opened read-only here; the writer keeps its own handle).
    """

    def __init__(self, path: PathLike) -> None:
        self._fd: int | None = os.open(path, os.O_RDONLY)
        self._started = 0  # bytes whose write-back has been started
        self._written = 0  # bytes known to be on disk (up to the previous piece)
        self._range = _sync_file_range()

    def advance(self) -> None:
        """Start writing the bytes added since the last call; wait for the piece before."""
        if self._fd is None:
            return
        size = os.fstat(self._fd).st_size
        if self._range is None:
            if hasattr(os, "posix_fadvise"):
                try:  # DONTNEED starts write-back of the dirty pages (and drops clean ones)
                    os.posix_fadvise(self._fd, self._started, 0, os.POSIX_FADV_DONTNEED)
                except OSError:
                    pass
            self._started = size
            return
        if size > self._started:
            self._call(self._started, size - self._started, _WRITE)
        if self._started > self._written:
            self._call(self._written, self._started - self._written,
                       _WAIT_BEFORE | _WRITE | _WAIT_AFTER)
            self._written = self._started
        self._started = size

    def _call(self, offset: int, length: int, flags: int) -> None:
        if self._range(self._fd, offset, length, flags) != 0:  # a hint: the fsync decides
            self._range = None

    def close(self) -> None:
        """Stop (the file itself is not synced: that is the caller's fsync)."""
        fd, self._fd = self._fd, None
        if fd is not None:
            os.close(fd)


def sync_directory(directory: Path) -> None:
    """Flush a directory entry (a rename) to disk where the file system allows it."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def publish(temporary: str, target: Path, force: bool) -> None:
    """Rename a synced temporary file to ``target``, atomically.

    Without ``force`` the rename refuses to replace a file that appeared in the
    meantime (a hard link is atomic and fails on an existing name); on file
    systems without hard links the check and the rename are separate steps.
    """
    if force:
        os.replace(temporary, target)
    else:
        try:
            os.link(temporary, target)
        except FileExistsError:
            raise OutputExistsError(
                f"{target} appeared while writing; pass --force (force=True) to overwrite it"
            ) from None
        except OSError:  # no hard links on this file system
            refuse_existing(target, force)
            os.replace(temporary, target)
        else:
            os.unlink(temporary)
    forget_temporary(temporary)
    sync_directory(target.parent)


def write_text_atomic(path: PathLike, text: str, force: bool = False) -> Path:
    """Write ``text`` to ``path`` via a synced temporary file and a rename; never half-written.

    Raises
    ------
    OutputExistsError
        When ``path`` exists and ``force`` is False.
    """
    target = Path(path)
    refuse_existing(target, force)
    target.parent.mkdir(parents=True, exist_ok=True)
    temporary = temporary_beside(target)
    try:
        with open(temporary, "w", encoding="utf-8") as stream:
            stream.write(text)
            stream.flush()
            os.fsync(stream.fileno())
        publish(temporary, target, force)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        forget_temporary(temporary)
        raise
    return target


def file_sha256(path: PathLike, block_bytes: int = 1 << 20) -> str:
    """SHA-256 of a file, read in blocks."""
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        while block := handle.read(block_bytes):
            digest.update(block)
    return digest.hexdigest()
