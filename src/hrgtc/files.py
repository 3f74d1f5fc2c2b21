"""Output files: refuse to overwrite without force, write atomically, hash inputs.

Every file hrgtc writes (recordings, model files, reports, C sources) goes
through here: :func:`refuse_existing` is the one "output exists, pass --force"
check, :func:`temporary_beside` and :func:`publish` the temporary file that is
synced and renamed into place (so a reader never sees half a file), and
:func:`write_text_atomic` both for a small text file.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from collections.abc import Iterable
from pathlib import Path

from hrgtc.errors import OutputExistsError

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


def temporary_beside(target: Path) -> str:
    """An empty hidden temporary file next to ``target``, with ordinary permissions.

    ``mkstemp`` makes 0600 files; the file gets ``0666 & ~umask`` like any other
    file the user creates. The caller removes it (or :func:`publish` renames it).
    """
    fd, temporary = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.",
                                     suffix=".tmp")
    os.close(fd)
    try:
        os.chmod(temporary, 0o666 & ~current_umask())
    except BaseException:
        os.unlink(temporary)
        raise
    return temporary


def fsync_file(path: PathLike) -> None:
    """Flush a closed file's data to disk."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
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
        raise
    return target


def file_sha256(path: PathLike, block_bytes: int = 1 << 20) -> str:
    """SHA-256 of a file, read in blocks."""
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        while block := handle.read(block_bytes):
            digest.update(block)
    return digest.hexdigest()
