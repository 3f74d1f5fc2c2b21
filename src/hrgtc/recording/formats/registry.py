"""The one registry of file formats: built-in ones, and a lab's own through an entry point.

Every choice of a format by a file's suffix or content goes through here: reading
(:func:`open_streams`), writing (:func:`writable`), ``hrgtc info``, the simulator's
outputs and a fleet's file discovery.

The built-in formats are the modules of this package, registered below in
:data:`BUILTIN`. A package of a lab's own adds a format without touching hrgtc: it
declares a :class:`~hrgtc.recording.formats.base.Format` and names it in the entry
point group ``hrgtc.formats`` of its ``pyproject.toml``::

    [project.entry-points."hrgtc.formats"]
    mylab = "mylab_hrgtc:FORMAT"

The entry points are loaded once, when a file's suffix is not one of the formats
registered so far or when every format is listed (the scan of the installed
distributions costs some milliseconds, which reading a Parquet, CSV or HDF5 file does
not pay). A format that fails to load is left out with a
:class:`~hrgtc.core.errors.FormatPluginWarning` (reading the other formats goes on); two
formats may not claim one suffix.
"""

from __future__ import annotations

import warnings
from importlib import metadata as importlib_metadata
from pathlib import Path
from types import ModuleType

from hrgtc.core.errors import FormatPluginWarning, RecordingError
from hrgtc.recording.formats import csv, dataflash, hdf5, matlab, mdf, parquet, tdms, ulog
from hrgtc.recording.formats.base import SNIFF_BYTES, Format, Source

#: Entry point group of the file formats of other packages.
ENTRY_POINT_GROUP = "hrgtc.formats"
#: The built-in formats, in the order they are listed.
BUILTIN: tuple[Format, ...] = (parquet.FORMAT, csv.FORMAT, hdf5.FORMAT, tdms.FORMAT,
                               matlab.FORMAT, ulog.FORMAT, dataflash.FORMAT, mdf.FORMAT)

_formats: dict[str, Format] = {}
_plugins_loaded = False


def register(fmt: Format, *, replace: bool = False) -> Format:
    """Add a format to the registry (for a format defined at run time, e.g. in a test).

    Raises
    ------
    ValueError
        Another format has the same name or claims one of its suffixes (unless
        ``replace`` and it is the same name).
    """
    if not isinstance(fmt, Format):
        raise TypeError(f"register() takes a hrgtc Format, got {type(fmt).__name__}")
    if fmt.name in _formats and not replace:
        raise ValueError(f"a file format named {fmt.name!r} is already registered")
    for other in _formats.values():
        if other.name == fmt.name:
            continue
        clash = set(other.suffixes) & set(fmt.suffixes)
        if clash:
            raise ValueError(f"format {fmt.name!r}: suffix {sorted(clash)[0]!r} is already "
                             f"the format {other.name!r}'s")
        if fmt.output_name == other.output_name:
            raise ValueError(f"format {fmt.name!r}: output name {fmt.output_name!r} is "
                             f"already the format {other.name!r}'s")
    _formats[fmt.name] = fmt
    return fmt


def unregister(name: str) -> None:
    """Remove a format (a test's own); unknown names are ignored."""
    _formats.pop(name, None)


for _builtin in BUILTIN:
    register(_builtin)


def load_plugins(force: bool = False) -> list[str]:
    """Register the formats of the ``hrgtc.formats`` entry points (once); their names.

    An entry point names a :class:`Format` or a module with one as ``FORMAT``.
    """
    global _plugins_loaded
    if _plugins_loaded and not force:
        return []
    _plugins_loaded = True
    names = []
    for point in importlib_metadata.entry_points(group=ENTRY_POINT_GROUP):
        try:
            found = point.load()
            fmt = found.FORMAT if isinstance(found, ModuleType) else found
            if fmt.name in _formats and _formats[fmt.name] is fmt:
                continue
            register(fmt)
        except Exception as exc:  # a broken plugin must not stop the other formats
            warnings.warn(f"file format {point.name!r} of the entry point {point.value!r} "
                          f"({ENTRY_POINT_GROUP}) was not loaded: {exc}", FormatPluginWarning,
                          stacklevel=2)
            continue
        names.append(fmt.name)
    return names


def formats() -> tuple[Format, ...]:
    """Every registered format, built-in ones first."""
    load_plugins()
    return tuple(_formats.values())


def get(name: str) -> Format:
    """The format called ``name`` (or with that output name, ``"h5"``)."""
    for fmt in formats():
        if name in (fmt.name, fmt.output_name):
            return fmt
    raise RecordingError(f"unknown file format {name!r}; the registered formats are "
                         f"{', '.join(f.name for f in formats())}")


def suffixes() -> dict[str, str]:
    """Suffix -> format name, of every registered format."""
    return {suffix: fmt.name for fmt in formats() for suffix in fmt.suffixes}


def _by_suffix(suffix: str) -> Format | None:
    """The format of ``suffix``: of those registered so far, else after loading the plugins."""
    for fmt in _formats.values():
        if suffix in fmt.suffixes:
            return fmt
    if not _plugins_loaded:
        load_plugins()
        return _by_suffix(suffix)
    return None


def output_suffixes() -> dict[str, str]:
    """Output name (``--format``) -> the suffix written, of every format with a writer."""
    return {fmt.output_name: fmt.suffixes[0] for fmt in formats() if fmt.sink is not None}


def path_suffix(path: str | Path) -> str:
    """The suffix that names a file's format, lower case: ``.csv.gz`` for ``run.CSV.gz``.

    A compressed file's suffix is its last two (a format that reads it registers
    ``.csv.gz``); any other file's is its last.
    """
    path = Path(path)
    if path.suffix.lower() == ".gz" and len(path.suffixes) >= 2:
        return "".join(path.suffixes[-2:]).lower()
    return path.suffix.lower()


def is_recording(path: str | Path) -> bool:
    """True when the suffix of ``path`` is that of a registered format."""
    return _by_suffix(path_suffix(path)) is not None


def _listing() -> str:
    return "; ".join(f"{fmt.name} ({', '.join(fmt.suffixes)})" for fmt in formats())


def _head(path: Path) -> bytes | None:
    try:
        with open(path, "rb") as handle:
            return handle.read(SNIFF_BYTES)
    except OSError:
        return None


def format_for(path: str | Path) -> Format:
    """The format of a file: by its suffix, else by its content (each format's sniff).

    A file whose suffix names one format but whose first bytes are certainly another's
    (an HDF5 file named ``.parquet``) is refused with both named.

    Raises
    ------
    RecordingError
        Unknown suffix and no format recognises the content; the message lists the
        registered formats and their suffixes.
    """
    path = Path(path)
    suffix = path_suffix(path)
    fmt = _by_suffix(suffix)
    if fmt is not None:
        head = _head(path) if path.is_file() else None
        if head and fmt.sniff is not None and not fmt.accepts(head):
            other = next((f for f in _formats.values() if f is not fmt and f.accepts(head)),
                         None)
            if other is not None:
                raise RecordingError(
                    f"{path}: the file's content is {other.name} (its first bytes), not "
                    f"{fmt.name} as its suffix {suffix!r} says; rename it to "
                    f"{path.stem}{other.suffixes[0]}")
        return fmt
    head = _head(path) if path.is_file() else None
    if head:
        found = [fmt for fmt in formats() if fmt.accepts(head)]
        found = [f for f in found if not any(g.within == f.name for g in found)]
        if len(found) == 1:
            return found[0]
    known = ", ".join(suffixes())
    raise RecordingError(
        f"{path}: unknown file type {suffix or '(no suffix)'!r}; use one of {known} "
        f"(registered formats: {_listing()})")


def format_of(path: str | Path) -> str:
    """The name of the format of ``path`` (``"parquet"``, ``"csv"``, ``"hdf5"`` ...)."""
    return format_for(path).name


def open_streams(path: str | Path) -> list[Source]:
    """Open a file as its streams (one for most formats), the format from the registry."""
    return format_for(path).open(path)


def writable(path: str | Path) -> Format:
    """The format that writes ``path``, by its suffix alone (the file may not exist yet).

    Raises
    ------
    RecordingError
        No registered format has the suffix, or its format cannot be written.
    """
    path = Path(path)
    suffix = path_suffix(path)
    if suffix.endswith(".gz"):
        raise RecordingError(
            f"{path}: hrgtc does not write compressed files ({suffix}); write "
            f"{path.name[:-3]} and compress it afterwards (gzip {path.name[:-3]})")
    fmt = _by_suffix(suffix)
    if fmt is not None and fmt.sink is not None:
        return fmt
    can = ", ".join(f"{f.suffixes[0]} ({f.name})" for f in formats() if f.sink is not None)
    if fmt is None:
        raise RecordingError(f"{path}: unknown file type {suffix or '(no suffix)'!r}; use one "
                             f"of {', '.join(suffixes())} (formats that write: {can})")
    raise RecordingError(f"{path}: the {fmt.name} format is read only; write one of {can}")
