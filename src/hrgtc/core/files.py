"""Output files: refuse to overwrite without force, write atomically, hash inputs.

Every file hrgtc writes (recordings, model files, reports, C sources) goes
through here: :func:`refuse_existing` is the one "output exists, pass --force"
check, :func:`temporary_beside` and :func:`publish` the temporary file that is
synced and renamed into place (so a reader never sees half a file), and
:func:`write_text_atomic` both for a small text file.
"""

from __future__ import annotations

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

from hrgtc.core.errors import HrgtcWarning, InputError, OutputExistsError

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


def _same_file(a: Path, b: Path) -> bool:
    """True if ``a`` and ``b`` are one file (through links and relative paths)."""
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist (yet): not the same file
        return False


def refuse_input(outputs: PathLike | Iterable[PathLike],
                 inputs: Iterable[PathLike | None]) -> None:
    """Raise :class:`InputError` if an output is one of the inputs, ``--force`` or not.

    Compared by :func:`os.path.samefile`, so a symbolic or hard link, a relative
    path or another spelling of an input is caught too. Writing the output would
    replace the input (the raw recording, the model) by the result.

    Parameters
    ----------
    outputs
        One output path or several.
    inputs
        The files the command reads (None entries are skipped).
    """
    outputs = [outputs] if isinstance(outputs, str | os.PathLike) else list(outputs)
    sources = [Path(i) for i in inputs if i is not None]
    for output in outputs:
        for source in sources:
            if _same_file(Path(output), source):
                same = "" if str(output) == str(source) else f" (the same file as {source})"
                raise InputError(
                    f"{output}: the output is an input of this command{same}; writing it "
                    "would replace the input, so it is refused even with --force: give "
                    "-o another file name")


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
    directory = target.parent  # "." for a bare file name
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


@contextmanager
def naming_os_errors(target: PathLike) -> Iterator[None]:
    """Give an :class:`OSError` raised without a file name the name of ``target``.

    Writers (pyarrow's, h5py's, a file's ``write``) report a full disk as
    ``[Errno 28] No space left on device`` without saying which file, or name the
    hidden temporary file that is removed at once; the message of
    :func:`describe_os_error` then names the output being written.
    """
    try:
        yield
    except OSError as exc:
        code = exc.errno
        if code is None and "No space left" in str(exc):
            code = errno.ENOSPC  # pyarrow's IOError carries the errno in its text only
        name = Path(str(exc.filename)).name if exc.filename is not None else None
        temporary = name is not None and name.startswith(f".{Path(target).name}.")
        if code is not None and (name is None or temporary):
            raise OSError(code, exc.strerror or os.strerror(code), str(target)) from exc
        raise


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


#: How often the write-behind thread looks for new bytes between wake-ups. [s]
WRITE_BEHIND_POLL_S = 0.05


class WriteBehind:
    """Make a growing file's bytes durable while the rest of it is produced.

    A file written in big pieces and fsynced at the end makes its writer wait, at
    the end, for all of it: the page cache's dirty pages and then the disk's own
    volatile cache, which the fsync's cache flush empties. On a virtual disk that
    flush alone took 0.5 s for a 440 MB file whose pages had already been written
    out (``sync_file_range``, the earlier way here). A thread therefore syncs
    (``fdatasync``) whatever the file has grown by, again and again, while the
    writer goes on; the final fsync, which stays the guarantee of durability, finds
    a few megabytes left (0.02 s instead of 0.5 s), and the dirty pages never pile
    up enough for the kernel to throttle the writer.

    Parameters
    ----------
    path
        The file being written (opened read-only here; the writer keeps its own handle).
    poll_s
        Seconds between looks at the file's size when :meth:`advance` is not called.

    Raises
    ------
    OSError
        From :meth:`close`: a sync failed (e.g. EIO). Linux reports a write-back
        error once, to the first sync that sees it, so it is raised here rather than
        left for a later fsync that might not see it.
    """

    def __init__(self, path: PathLike, poll_s: float = WRITE_BEHIND_POLL_S) -> None:
        self.path = str(path)
        self._fd: int | None = os.open(path, os.O_RDONLY)
        self.synced = 0  # bytes known to be on disk
        self.syncs = 0
        self._poll_s = float(poll_s)
        self._wake = threading.Event()
        self._stop = False
        self._error: OSError | None = None
        self._thread = threading.Thread(target=self._run, args=(self._fd,),
                                         name="hrgtc-write-behind", daemon=True)
        self._thread.start()

    def advance(self) -> None:
        """New bytes were written: sync them now rather than at the next look."""
        self._wake.set()

    def _run(self, fd: int) -> None:
        sync = getattr(os, "fdatasync", os.fsync)
        while True:
            self._wake.wait(self._poll_s)
            self._wake.clear()
            if self._stop:
                return
            try:
                size = os.fstat(fd).st_size
                if size > self.synced:
                    sync(fd)
                    self.synced, self.syncs = size, self.syncs + 1
            except OSError as exc:
                self._error = exc
                return

    def close(self, discard: bool = False) -> None:
        """Stop the thread (the file itself is not synced: that is the caller's fsync).

        Raises the first error of a sync, if one failed, unless ``discard`` (the
        file is being thrown away, and the error that made it so is on its way).
        """
        fd, self._fd = self._fd, None
        if fd is None:
            return
        self._stop = True
        self._wake.set()
        self._thread.join()
        os.close(fd)
        if self._error is not None and not discard:
            error, self._error = self._error, None
            raise OSError(error.errno, f"{self.path}: writing to disk failed: "
                          f"{error.strerror or error}") from error


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
    return _write_atomic(path, text, force)


def write_bytes_atomic(path: PathLike, content: bytes, force: bool = False) -> Path:
    """Write ``content`` to ``path`` exactly (no newline translation), as
    :func:`write_text_atomic` writes text."""
    return _write_atomic(path, content, force)


def _write_atomic(path: PathLike, content: str | bytes, force: bool) -> Path:
    """Write text (UTF-8) or bytes to ``path`` via a synced temporary file and a rename."""
    target = Path(path)
    refuse_existing(target, force)
    target.parent.mkdir(parents=True, exist_ok=True)
    temporary = temporary_beside(target)
    text = isinstance(content, str)
    try:
        with naming_os_errors(target), open(temporary, "w" if text else "wb",
                                            encoding="utf-8" if text else None) as stream:
            stream.write(content)
            stream.flush()
            os.fsync(stream.fileno())
        publish(temporary, target, force)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        forget_temporary(temporary)
        raise
    return target


#: Bytes read at a time when a file is hashed.
HASH_BLOCK_BYTES = 1 << 20


def file_sha256(path: PathLike, block_bytes: int = HASH_BLOCK_BYTES) -> str:
    """SHA-256 of a file, read in blocks (the digest :func:`hash_ahead` found, when the
    file is the same file, unchanged: device, inode, size and modification time)."""
    entry = _AHEAD.get(os.path.realpath(path)) if _AHEAD else None
    if entry is not None:
        digest = entry.result(path)
        if digest is not None:
            return digest
    return _sha256(path, block_bytes)


def _sha256(path: PathLike, block_bytes: int = HASH_BLOCK_BYTES) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        while block := handle.read(block_bytes):
            digest.update(block)
    return digest.hexdigest()


def _identity(path: PathLike) -> tuple[int, int, int, int] | None:
    """(device, inode, size, modification time) of a file; None when it cannot be read."""
    try:
        stat = os.stat(path)
    except (OSError, ValueError):
        return None
    return stat.st_dev, stat.st_ino, stat.st_size, stat.st_mtime_ns


class _Ahead:
    """A file's hash begun by :func:`hash_ahead`: whoever comes first (the background
    thread or :func:`file_sha256`) hashes it; the digest counts while the file keeps the
    identity it had before and after it was hashed."""

    def __init__(self) -> None:
        self.claimed = False
        self.done = threading.Event()
        self.digest: str | None = None
        self.identity: tuple[int, int, int, int] | None = None

    def run(self, path: PathLike) -> None:
        """Hash the file unless another thread began (a failure leaves no digest)."""
        with _AHEAD_LOCK:
            if self.claimed:
                return
            self.claimed = True
        try:
            before = _identity(path)
            digest = _sha256(path)
            if before is not None and before == _identity(path):
                self.identity, self.digest = before, digest
        except OSError:
            pass  # file_sha256 reads it again and says why
        finally:
            self.done.set()

    def result(self, path: PathLike) -> str | None:
        """The digest, waiting for it if it is being computed; None when it does not hold
        for the file as it is now."""
        self.run(path)
        self.done.wait()
        if self.digest is None or self.identity != _identity(path):
            return None
        return self.digest


_AHEAD_LOCK = threading.Lock()
#: The files :func:`hash_ahead` was given, by resolved path.
_AHEAD: dict[str, _Ahead] = {}


def hash_ahead(paths: Iterable[PathLike]) -> None:
    """Begin hashing ``paths`` in a background thread, for a later :func:`file_sha256`
    (a model's provenance) of the same files. The thread reads and hashes with the GIL
    released: on a second core while the caller reads the same files for their numbers
    (``calibrate``). A file already given is not hashed again."""
    todo = []
    with _AHEAD_LOCK:
        for path in paths:
            key = os.path.realpath(path)
            if key not in _AHEAD:
                _AHEAD[key] = _Ahead()
                todo.append((path, _AHEAD[key]))
    if todo:
        threading.Thread(target=_hash_each, args=(todo,), name="hrgtc-sha256",
                         daemon=True).start()


def _hash_each(todo: list[tuple[PathLike, _Ahead]]) -> None:
    for path, entry in todo:
        entry.run(path)
