"""Tests of hrgtc.core.files.WriteBehind: the bytes reach the file unchanged, the thread syncs
what the file grows by, and a failed sync is raised, never lost.

Truth: the bytes written, read back; the synced offset against the file's size; an
injected EIO.
"""

from __future__ import annotations

import errno
import os
import time

import numpy as np
import pytest

from hrgtc.core.files import WriteBehind
from hrgtc.recording import Metadata, RecordingWriter


def _wait_for(condition, seconds: float = 10.0) -> bool:
    deadline = time.monotonic() + seconds
    while not condition():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.005)
    return True


def test_write_behind_keeps_every_byte_and_syncs_what_the_file_grows_by(tmp_path):
    path = tmp_path / "out.bin"
    pieces = [np.random.default_rng(k).bytes(100_000 + 4096 * k) for k in range(4)]
    with open(path, "wb") as stream:
        behind = WriteBehind(path, poll_s=60.0)  # only advance() wakes it
        for piece in pieces:
            stream.write(piece)
            stream.flush()
            behind.advance()
            size = stream.tell()
            assert _wait_for(lambda size=size: behind.synced == size)
        syncs = behind.syncs
        behind.advance()  # nothing new: no sync, no error
        time.sleep(0.05)
        assert behind.syncs == syncs and 1 <= syncs <= len(pieces)
        behind.close()
        behind.close()  # closed: a no-op
        behind.advance()
        os.fsync(stream.fileno())
    assert path.read_bytes() == b"".join(pieces)


def test_write_behind_finds_new_bytes_without_being_woken(tmp_path):
    path = tmp_path / "out.bin"
    with open(path, "wb") as stream:
        behind = WriteBehind(path, poll_s=0.01)
        stream.write(b"x" * 50_000)
        stream.flush()
        assert _wait_for(lambda: behind.synced == 50_000)
        behind.close()


def test_a_failed_sync_is_raised_by_close(tmp_path, monkeypatch):
    def failing(fd):
        raise OSError(errno.EIO, "Input/output error")

    monkeypatch.setattr(os, "fdatasync", failing, raising=False)
    monkeypatch.setattr(os, "fsync", failing)
    path = tmp_path / "out.bin"
    path.write_bytes(b"y" * 1000)
    behind = WriteBehind(path, poll_s=0.01)
    assert _wait_for(lambda: behind._error is not None)
    with pytest.raises(OSError, match=r"out\.bin: writing to disk failed: Input/output error$") \
            as caught:
        behind.close()
    assert caught.value.errno == errno.EIO
    discarded = WriteBehind(path, poll_s=0.01)
    assert _wait_for(lambda: discarded._error is not None)
    discarded.close(discard=True)  # the file is being thrown away: nothing raised


def test_a_recording_writer_whose_sync_fails_leaves_nothing(tmp_path, monkeypatch):
    def failing(fd):
        raise OSError(errno.EIO, "Input/output error")

    monkeypatch.setattr(os, "fdatasync", failing, raising=False)
    out = tmp_path / "run.parquet"
    writer = RecordingWriter(out, Metadata(sample_rate_hz=10.0), ["time_s", "rate_dph"])
    writer.write({"time_s": np.arange(100.0) / 10, "rate_dph": np.zeros(100)})
    writer.start_writeback()
    assert _wait_for(lambda: writer._behind._error is not None)
    with pytest.raises(OSError, match="writing to disk failed"):
        writer.close()
    assert list(tmp_path.iterdir()) == []  # no output, no temporary file


# -- the checks before a write (issue 21: tests that catch plausible bugs, found by mutmut) --
def test_check_writable_names_what_is_wrong(tmp_path, monkeypatch):
    from collections import namedtuple

    from hrgtc.core.errors import InputError
    from hrgtc.core.files import check_writable

    with pytest.raises(InputError, match=rf"^{tmp_path} is a directory; give a file name$"):
        check_writable(tmp_path)
    missing = tmp_path / "no" / "out.parquet"
    with pytest.raises(InputError, match=rf"^{missing}: directory {missing.parent} does not "
                       "exist; create it first$"):
        check_writable(missing)
    check_writable(tmp_path / "out.parquet", expected_bytes=1e3)  # room enough: no error
    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr("shutil.disk_usage", lambda path: usage(0, 0, 2_500_000))
    check_writable(tmp_path / "out.parquet")  # no estimate: free space not asked
    check_writable(tmp_path / "out.parquet", expected_bytes=2_000_000)
    with pytest.raises(InputError, match=rf"^{tmp_path}/out.parquet: 2.5 MB free in {tmp_path} "
                       r"but the output needs about 3.0 MB; free some space or write elsewhere$"):
        check_writable(tmp_path / "out.parquet", expected_bytes=3e6)
    with pytest.raises(InputError, match="MB free"):
        check_writable(tmp_path / "out.parquet", expected_bytes=2_400_000)  # 5 % to spare
    monkeypatch.chdir(tmp_path)
    check_writable("relative.parquet")  # the current directory: writable
    monkeypatch.setattr(os, "access", lambda path, mode: False)
    with pytest.raises(InputError, match=r"^out.parquet: directory . is not writable; choose "
                       "another output path or fix its permissions$"):
        check_writable("out.parquet")


@pytest.mark.parametrize("code, text", [
    (errno.ENOSPC, "the disk is full (no space left on device); free some space"),
    (errno.EACCES, "permission denied; choose another path or fix its permissions"),
    (errno.EPERM, "permission denied; choose another path or fix its permissions"),
    (errno.EROFS, "read-only file system; write elsewhere"),
    (errno.EIO, "Input/output error"),
])
def test_describe_os_error_names_the_file_and_the_fix(code, text):
    from hrgtc.core.files import describe_os_error

    named = OSError(code, os.strerror(code), "/data/out.parquet")
    assert describe_os_error(named) == f"/data/out.parquet: {text}"
    anonymous = OSError(code, os.strerror(code))
    assert describe_os_error(anonymous, "model.json") == f"model.json: {text}"
    assert describe_os_error(anonymous).startswith("file: ")


def test_a_write_error_without_a_file_name_gets_the_outputs(tmp_path):
    from hrgtc.core.files import naming_os_errors

    target = tmp_path / "out.parquet"
    for raised in (OSError(errno.ENOSPC, "No space left on device"),
                   OSError("Error writing bytes to file. Detail: [errno 28] No space left on "
                           "device"),
                   OSError(errno.ENOSPC, "No space left", str(tmp_path / ".out.parquet.1.x.tmp"))):
        with pytest.raises(OSError) as caught, naming_os_errors(target):
            raise raised
        assert (caught.value.errno, caught.value.filename) == (errno.ENOSPC, str(target))
    other = OSError(errno.EACCES, "Permission denied", "/elsewhere/file")
    with pytest.raises(OSError) as caught, naming_os_errors(target):
        raise other
    assert caught.value is other  # names its own file: left alone


def test_pid_alive(monkeypatch):
    from hrgtc.core import files

    assert files._pid_alive(os.getpid())
    assert not files._pid_alive(0) and not files._pid_alive(-5)
    child = os.fork()
    if child == 0:
        os._exit(0)
    os.waitpid(child, 0)
    assert not files._pid_alive(child)  # reaped: no such process

    def denied(pid, sig):
        raise PermissionError(errno.EPERM, "Operation not permitted")

    monkeypatch.setattr(os, "kill", denied)
    assert files._pid_alive(1)  # another user's process: it may exist


def test_a_signal_removes_the_temporary_files_then_runs_the_previous_handler(tmp_path):
    import signal

    from hrgtc.core import files

    seen = []
    previous = signal.signal(signal.SIGTERM, lambda signum, frame: seen.append(signum))
    try:
        temporary = tmp_path / ".out.tmp"
        temporary.write_text("half")
        with files.removed_on_signal(temporary):
            assert signal.getsignal(signal.SIGTERM) is files._on_signal
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(0.01)
        assert seen == [signal.SIGTERM] and not temporary.exists()
        assert files._ACTIVE == set()
        assert signal.getsignal(signal.SIGTERM) is not files._on_signal
    finally:
        signal.signal(signal.SIGTERM, previous)


def test_file_sha256_reads_in_blocks(tmp_path):
    import hashlib

    from hrgtc.core.files import file_sha256

    data = bytes(range(256)) * 40
    path = tmp_path / "f.bin"
    path.write_bytes(data)
    assert file_sha256(path) == hashlib.sha256(data).hexdigest()
    assert file_sha256(path, block_bytes=7) == hashlib.sha256(data).hexdigest()


def test_a_sigterm_with_the_default_handler_removes_the_file_and_ends_the_process(tmp_path):
    import signal
    import subprocess
    import sys
    from pathlib import Path

    import hrgtc

    temporary = tmp_path / ".out.parquet.tmp"
    code = (
        "import os, signal, time\n"
        "from hrgtc.core.files import removed_on_signal\n"
        f"path = {str(temporary)!r}\n"
        "open(path, 'w').write('half')\n"
        "with removed_on_signal(path):\n"
        "    os.kill(os.getpid(), signal.SIGTERM)\n"
        "    time.sleep(5)\n"
        "print('survived')\n")
    env = {**os.environ, "PYTHONPATH": str(Path(hrgtc.__file__).parents[1])}
    result = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                            text=True, timeout=60)
    assert result.returncode == -signal.SIGTERM, result.stderr  # died of the signal
    assert "survived" not in result.stdout and not temporary.exists()


def test_write_behind_starts_from_nothing_synced_in_a_named_daemon_thread(tmp_path):
    path = tmp_path / "one.bin"
    with open(path, "wb") as stream:
        behind = WriteBehind(path, poll_s=0.01)
        assert (behind.synced, behind.syncs) == (0, 0)
        assert behind._thread.name == "hrgtc-write-behind" and behind._thread.daemon
        stream.write(b"z")  # one byte: synced goes from 0 to 1
        stream.flush()
        assert _wait_for(lambda: behind.syncs == 1 and behind.synced == 1)
        behind.close()


def test_check_writable_asks_for_free_space_only_with_an_estimate(tmp_path, monkeypatch):
    from collections import namedtuple

    from hrgtc.core.errors import InputError
    from hrgtc.core.files import check_writable

    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr("shutil.disk_usage", lambda path: usage(0, 0, 0))
    check_writable(tmp_path / "out.parquet")  # default: no estimate, a full disk passes
    with pytest.raises(InputError, match=r"0.0 MB free .* needs about 0.0 MB"):
        check_writable(tmp_path / "out.parquet", expected_bytes=1.0)


# -- outputs never inputs, atomic text files (issue 21) --------------------------------------
def test_refuse_input_names_the_output_and_the_input_it_is(tmp_path, monkeypatch):
    from hrgtc.core.errors import InputError
    from hrgtc.core.files import refuse_input

    run = tmp_path / "run.csv"
    run.write_text("time_s\n0\n")
    link = tmp_path / "link.csv"
    link.symlink_to(run)
    fix = ("the output is an input of this command{}; writing it would replace the input, "
           "so it is refused even with --force: give -o another file name")
    with pytest.raises(InputError) as caught:
        refuse_input(run, [None, tmp_path / "model.json", run])
    assert str(caught.value) == f"{run}: " + fix.format("")
    with pytest.raises(InputError) as caught:
        refuse_input([tmp_path / "new.csv", link], [run])
    assert str(caught.value) == f"{link}: " + fix.format(f" (the same file as {run})")
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError, match=r"^run.csv: the output is an input .* \(the same "):
        refuse_input("run.csv", [str(run)])
    refuse_input(tmp_path / "new.csv", [run, None])  # not written yet: not an input
    refuse_input(run, [None])  # no inputs


def test_write_text_atomic_refuses_creates_folders_and_falls_back_without_hard_links(
        tmp_path, monkeypatch):
    from hrgtc.core import files
    from hrgtc.core.errors import OutputExistsError

    target = tmp_path / "a" / "b" / "prior.json"
    files.write_text_atomic(target, "é first\n")  # missing folders are created
    assert target.read_text(encoding="utf-8") == "é first\n"
    with pytest.raises(OutputExistsError, match=r"prior.json exists; pass --force"):
        files.write_text_atomic(target, "second\n")  # no force by default

    def raced(source, destination):  # another writer created the target meanwhile
        raise FileExistsError(errno.EEXIST, "File exists")

    monkeypatch.setattr(os, "link", raced)
    fresh = tmp_path / "fresh.txt"
    with pytest.raises(OutputExistsError, match=rf"^{fresh} appeared while writing; pass --force"):
        files.write_text_atomic(fresh, "x\n")
    assert files._ACTIVE == set() and sorted(p.name for p in tmp_path.iterdir()) == ["a"]

    def no_links(source, destination):  # a file system without hard links
        raise PermissionError(errno.EPERM, "Operation not permitted")

    monkeypatch.setattr(os, "link", no_links)
    files.write_text_atomic(fresh, "no links\n")
    assert fresh.read_text() == "no links\n"
    with pytest.raises(OutputExistsError):
        files.write_text_atomic(fresh, "again\n")
    assert fresh.read_text() == "no links\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a", "fresh.txt"]


# -- mutants of files.py that no test killed (make mutation, issue 21) -------------------------
@pytest.fixture
def no_kill(monkeypatch):
    """os.kill recorded instead of sent; the SIGTERM handler restored afterwards."""
    import signal

    from hrgtc.core import files

    calls = []
    monkeypatch.setattr(files.os, "kill", lambda pid, signum: calls.append((pid, signum)))
    handler = signal.getsignal(signal.SIGTERM)
    yield calls
    signal.signal(signal.SIGTERM, handler)
    files._PREVIOUS.clear()


def test_on_signal_calls_a_previous_handler_with_the_signal_and_frame(no_kill, monkeypatch):
    import signal

    from hrgtc.core import files

    seen = []
    monkeypatch.setitem(files._PREVIOUS, signal.SIGTERM, lambda *args: seen.append(args))
    files._on_signal(signal.SIGTERM, "the frame")
    assert seen == [(signal.SIGTERM, "the frame")] and no_kill == []


@pytest.mark.parametrize("registered", [True, False])
def test_on_signal_without_a_previous_handler_dies_of_the_signal(no_kill, monkeypatch,
                                                                  registered):
    """The default action (or no handler recorded) re-sends the same signal to itself."""
    import signal

    from hrgtc.core import files

    if registered:
        monkeypatch.setitem(files._PREVIOUS, signal.SIGTERM, signal.SIG_DFL)
    files._on_signal(signal.SIGTERM, None)
    assert no_kill == [(os.getpid(), signal.SIGTERM)]


def test_check_writable_asks_for_write_and_search_permission(tmp_path, monkeypatch):
    """As root, os.access always says yes: the mode asked for is checked by a stand-in."""
    from hrgtc.core import files
    from hrgtc.core.errors import InputError

    monkeypatch.setattr(files.os, "access", lambda path, mode: not mode & os.W_OK)
    with pytest.raises(InputError, match="is not writable"):
        files.check_writable(tmp_path / "out.parquet")


def test_check_writable_free_space_edge_and_figures(tmp_path, monkeypatch):
    """Exactly 5 % to spare is enough; less is refused, the figures in MB (1e6 bytes)."""
    import shutil
    from collections import namedtuple

    from hrgtc.core import files
    from hrgtc.core.errors import InputError

    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr(shutil, "disk_usage", lambda path: usage(0, 0, 105))
    files.check_writable(tmp_path / "out.parquet", 100.0)  # 105 free, 1.05 × 100: enough
    monkeypatch.setattr(shutil, "disk_usage", lambda path: usage(0, 0, 1_050_000))
    with pytest.raises(InputError, match=r"1\.1 MB free in .* needs about 1\.1 MB"):
        files.check_writable(tmp_path / "out.parquet", 1_050_000.0)


def test_write_text_atomic_writes_utf8_whatever_the_locale(tmp_path, monkeypatch):
    """Model files and notes are UTF-8 on every machine: a text ``open`` without an
    encoding would follow the locale (simulated here as Latin-1)."""
    import builtins

    from hrgtc.core import files

    def latin1_locale_open(file, mode="r", *args, encoding=None, **kwargs):
        if "b" not in mode and encoding is None:
            encoding = "latin-1"
        return builtins.open(file, mode, *args, encoding=encoding, **kwargs)

    monkeypatch.setattr(files, "open", latin1_locale_open, raising=False)
    target = files.write_text_atomic(tmp_path / "note.txt", "± 0.5 °C/h\n")
    assert target.read_bytes() == "± 0.5 °C/h\n".encode()


def test_write_text_atomic_a_failed_open_names_the_output_and_keeps_its_error(
        tmp_path, monkeypatch):
    """A disk full before the temporary file exists: the error is the disk's, naming the
    output (not a FileNotFoundError from removing a temporary file that was never made)."""
    from hrgtc.core import files

    def full_disk(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(files, "open", full_disk, raising=False)
    target = tmp_path / "model.json"
    with pytest.raises(OSError) as caught:
        files.write_text_atomic(target, "{}\n")
    assert caught.value.errno == errno.ENOSPC
    assert caught.value.filename == str(target)
    assert files._ACTIVE == set() and list(tmp_path.iterdir()) == []


def test_refuse_existing_names_every_existing_output_and_the_note(tmp_path):
    from hrgtc.core.errors import OutputExistsError
    from hrgtc.core.files import refuse_existing

    a, b, c, free = (tmp_path / n for n in ("a.csv", "b.csv", "c.csv", "free.csv"))
    for path in (a, b, c):
        path.write_text("x")
    refuse_existing([a, b, free], force=True)  # --force: nothing is checked
    refuse_existing(free, force=False)
    refuse_existing([free, str(free)], force=False)
    with pytest.raises(OutputExistsError) as one:
        refuse_existing(str(a), force=False, note="nothing was written")
    assert str(one.value) == (f"{a} exists; nothing was written; pass --force (force=True) "
                              "to overwrite it")
    with pytest.raises(OutputExistsError) as single:
        refuse_existing([free, a], force=False)
    assert str(single.value) == (f"1 output file(s) exist: {a}; pass --force (force=True) "
                                 "to overwrite")
    with pytest.raises(OutputExistsError) as two:
        refuse_existing([free, a, b], force=False)
    assert str(two.value) == (f"2 output file(s) exist: {a} and {b}; pass --force "
                              "(force=True) to overwrite")
    with pytest.raises(OutputExistsError) as three:
        refuse_existing((p for p in (a, b, c)), force=False, note="nothing was written")
    assert str(three.value) == (f"3 output file(s) exist: {a}, {b} and {c}; nothing was "
                                "written; pass --force (force=True) to overwrite")


def _dead_pid() -> int:
    child = os.fork()
    if child == 0:
        os._exit(0)
    os.waitpid(child, 0)
    return child


def test_clean_stale_temporaries_removes_only_those_of_dead_writers(tmp_path):
    from hrgtc.core import files

    target = tmp_path / "out.csv"
    dead, alive, mine = _dead_pid(), os.getppid(), os.getpid()
    names = {
        "dead": f".out.csv.{dead}.k3j_x.tmp",  # removed
        "alive": f".out.csv.{alive}.a8f2.tmp",  # another process still writes it
        "mine": f".out.csv.{mine}.zz.tmp",  # this process's own
        "old": ".out.csv.q1w2e3.tmp",  # older hrgtc: no PID, reported
        "other": f".other.csv.{dead}.k3j_x.tmp",  # another output's
        "plain": f"out.csv.{dead}.tmp",  # not hidden: not ours
        "active": f".out.csv.{dead}.active.tmp",  # registered in this process
    }
    for name in names.values():
        (tmp_path / name).write_text("half")
    files._ACTIVE.add(str(tmp_path / names["active"]))
    try:
        with pytest.warns(files.StaleTemporaryWarning) as caught:
            removed = files.clean_stale_temporaries(target)
    finally:
        files._ACTIVE.discard(str(tmp_path / names["active"]))
    assert removed == [tmp_path / names["dead"]]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        n for k, n in names.items() if k != "dead")
    assert len(caught) == 1
    assert str(caught[0].message) == (
        f"{tmp_path}: 1 temporary file(s) of an interrupted earlier write of out.csv remain "
        f"({names['old']}); remove them if no other program is writing that file")
    assert files.clean_stale_temporaries(tmp_path / "missing" / "out.csv") == []


def test_temporary_beside_has_the_permissions_of_an_ordinary_file(tmp_path, monkeypatch):
    from hrgtc.core import files

    for umask, mode in ((0o022, 0o644), (0o077, 0o600), (0o002, 0o664)):
        old = os.umask(umask)
        try:
            temporary = files.temporary_beside(tmp_path / "out.csv")
        finally:
            os.umask(old)
        assert os.stat(temporary).st_mode & 0o777 == mode
        os.unlink(temporary)
        files.forget_temporary(temporary)

    def refused(path, mode):
        raise PermissionError(errno.EPERM, "Operation not permitted", path)

    monkeypatch.setattr(os, "chmod", refused)
    with pytest.raises(PermissionError):
        files.temporary_beside(tmp_path / "out.csv")
    assert list(tmp_path.iterdir()) == []


def test_signal_handlers_are_installed_once_in_the_main_thread_and_leave_ignored_ones(
        tmp_path):
    import signal
    import threading

    from hrgtc.core import files

    saved = {s: signal.getsignal(s) for s in (signal.SIGTERM, signal.SIGINT)}
    signal.signal(signal.SIGTERM, signal.SIG_IGN)  # e.g. started by nohup
    made: list[str] = []
    try:
        made.append(files.temporary_beside(tmp_path / "a.csv"))
        made.append(files.temporary_beside(tmp_path / "b.csv"))  # installed already
        assert signal.getsignal(signal.SIGTERM) == signal.SIG_IGN  # left alone
        assert signal.getsignal(signal.SIGINT) is files._on_signal
        assert files._PREVIOUS == {signal.SIGINT: saved[signal.SIGINT]}
        for path in made:
            files.forget_temporary(path)
        assert signal.getsignal(signal.SIGINT) == saved[signal.SIGINT]

        errors: list[BaseException] = []

        def worker() -> None:  # a fleet worker thread cannot set signal handlers
            try:
                made.append(files.temporary_beside(tmp_path / "c.csv"))
            except BaseException as exc:
                errors.append(exc)

        thread = threading.Thread(target=worker)
        thread.start()
        thread.join()
        assert errors == [] and files._PREVIOUS == {}
        assert signal.getsignal(signal.SIGINT) == saved[signal.SIGINT]
    finally:
        for path in made:
            files.forget_temporary(path)
        for signum, handler in saved.items():
            signal.signal(signum, handler)
        files._PREVIOUS.clear()


def test_pid_alive_sends_no_signal(monkeypatch):
    """Signal 0 only asks whether the process exists; any other would hit it."""
    from hrgtc.core import files

    sent = []
    monkeypatch.setattr(os, "kill", lambda pid, signum: sent.append((pid, signum)))
    assert files._pid_alive(12345)
    assert sent == [(12345, 0)]


def test_file_sha256_never_reads_a_whole_file_at_once(tmp_path, monkeypatch):
    import builtins

    from hrgtc.core import files

    sizes = []

    class Recorded:
        def __init__(self, handle):
            self.handle = handle

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.handle.close()

        def read(self, size=-1):
            sizes.append(size)
            return self.handle.read(size)

    monkeypatch.setattr(files, "open", lambda *a, **k: Recorded(builtins.open(*a, **k)),
                        raising=False)
    path = tmp_path / "f.bin"
    path.write_bytes(b"x" * 100)
    files.file_sha256(path, block_bytes=40)
    assert sizes == [40, 40, 40, 40]


def test_a_stale_temporary_that_cannot_be_removed_is_reported_by_name(tmp_path, monkeypatch):
    from pathlib import Path

    from hrgtc.core import files

    name = f".out.csv.{_dead_pid()}.k3j_x.tmp"
    (tmp_path / name).write_text("half")

    def refused(self, missing_ok=False):
        raise PermissionError(errno.EACCES, "Permission denied", str(self))

    monkeypatch.setattr(Path, "unlink", refused)
    with pytest.warns(files.StaleTemporaryWarning, match=rf"1 temporary file\(s\) .* \({name}\)"):
        assert files.clean_stale_temporaries(tmp_path / "out.csv") == []


def test_stale_temporaries_of_older_versions_are_counted_and_three_named(tmp_path):
    import re

    from hrgtc.core import files

    names = [f".out.csv.old{i}.tmp" for i in range(4)]  # no PID: older hrgtc
    for name in names:
        (tmp_path / name).write_text("half")
    with pytest.warns(files.StaleTemporaryWarning) as caught:
        files.clean_stale_temporaries(tmp_path / "out.csv")
    assert caught[0].filename == __file__  # said where the caller is
    message = str(caught[0].message)
    listed = re.search(r"4 temporary file\(s\) of an interrupted earlier write of out\.csv "
                       r"remain \((.*)\); remove them", message).group(1).split(", ")
    assert len(listed) == 3 and set(listed) < set(names)


def test_a_file_hashed_ahead_gives_its_digest_without_being_read_again(tmp_path, monkeypatch):
    import hashlib

    from hrgtc.core import files

    path = tmp_path / "soak.bin"
    data = bytes(range(256)) * 5000
    path.write_bytes(data)
    files.hash_ahead([path, str(path)])  # the same file twice: hashed once
    entry = files._AHEAD[os.path.realpath(path)]
    assert entry.done.wait(10)
    opened = []
    monkeypatch.setattr(files, "open", lambda *a, **k: opened.append(a) or open(*a, **k),
                        raising=False)
    assert files.file_sha256(path) == hashlib.sha256(data).hexdigest()
    assert opened == []


def test_a_file_changed_after_it_was_hashed_ahead_is_hashed_again(tmp_path):
    import hashlib

    from hrgtc.core import files

    path = tmp_path / "drift.bin"
    path.write_bytes(b"before" * 1000)
    files.hash_ahead([path])
    assert files._AHEAD[os.path.realpath(path)].done.wait(10)
    path.write_bytes(b"after, longer" * 1000)
    assert files.file_sha256(path) == hashlib.sha256(b"after, longer" * 1000).hexdigest()


def test_a_missing_file_hashed_ahead_is_refused_as_before(tmp_path):
    from hrgtc.core import files

    path = tmp_path / "missing.bin"
    files.hash_ahead([path])
    with pytest.raises(FileNotFoundError):
        files.file_sha256(path)
