"""File output: checked before the work starts, written atomically, always UTF-8.

``check_output`` is called by every command on its output paths before any
computation, so that an unwritable output costs nothing (``check_report_output``
for a report, where ``-`` is standard output); ``write_atomic`` leaves the old file or
nothing, never half a file.  Both raise ``FileAccessError`` (exit
status 2) naming the path and the operating system's reason.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from pendverify.errors import FileAccessError


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _reason(exc: OSError) -> str:
    return exc.strerror or str(exc)


def _existing_ancestor(path: Path) -> Path:
    """The nearest ancestor of ``path`` (itself excluded) that exists."""
    parent = path.parent
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent
    return parent


def check_output(path: str | Path | None, folder: bool = False) -> None:
    """Refuse an output path that cannot be written, before any work is done.

    ``path`` is a file to write (or, with ``folder``, a folder to write files into);
    None is accepted (no output asked).  Missing parent folders are created when the
    file is written, so the nearest existing ancestor must be a writable folder.
    Raises ``FileAccessError`` naming the path and the reason.
    """
    if path is None:
        return
    path = Path(path)  # "" is "."
    if path.is_dir() and not folder:
        raise FileAccessError(str(path), "write", "it is a directory, not a file")
    if path.exists() and folder and not path.is_dir():
        raise FileAccessError(str(path), "write", "it is a file, not a folder")
    base = path if folder and path.is_dir() else _existing_ancestor(path)
    if not base.is_dir():
        raise FileAccessError(str(path), "write", f"{base} is a file, not a folder")
    try:  # the only faithful test (permissions, read-only mounts, root): create and delete a file
        fd, probe = tempfile.mkstemp(prefix=".pendverify-probe.", dir=base)
    except OSError as exc:
        raise FileAccessError(str(path), "write", f"{base}: {_reason(exc)}") from None
    os.close(fd)
    os.unlink(probe)


#: the path that names standard output (``--json -``)
STDOUT = "-"


def check_report_output(path: str | None) -> None:
    """``check_output`` for a report path that may be ``-`` (standard output: nothing to check)."""
    if path != STDOUT:
        check_output(path)


def utf8_bytes(text: str) -> bytes:
    """``text`` as UTF-8, always valid UTF-8.

    A path the OS gave in bytes the locale could not decode holds lone surrogates: they
    become the original bytes again when those are UTF-8 (``θ.urdf`` under
    ``LC_ALL=POSIX``), else a visible ``\\udcXX`` escape — never a silent '?'.
    """
    try:
        return text.encode("utf-8")
    except UnicodeEncodeError:
        raw = text.encode("utf-8", "surrogateescape")
        try:
            raw.decode("utf-8")
        except UnicodeDecodeError:
            return text.encode("utf-8", "backslashreplace")
        return raw


def write_atomic(path: str | Path, data: str | bytes) -> Path:
    """Write ``data`` (text as UTF-8) to a temporary file beside ``path``, fsync it, rename it into place."""
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as exc:
        raise FileAccessError(str(path), "write", _reason(exc)) from None
    payload = data if isinstance(data, bytes) else utf8_bytes(data)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(payload)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the usual permissions
        os.replace(tmp, path)
    except OSError as exc:
        Path(tmp).unlink(missing_ok=True)
        raise FileAccessError(str(path), "write", _reason(exc)) from None
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path
