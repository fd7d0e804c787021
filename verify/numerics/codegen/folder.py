"""The folder generated code is cached in: private to its user, or a temporary one for this process.

A folder may hold code pendverify imports only when nobody else can write it: the cache
folder (``$PENDVERIFY_CACHE/generated`` or ``~/.cache/pendverify/generated``) and the
folder above it must be folders owned by the user running pendverify and not writable
by group or others; missing ones are created with mode 0700.  A folder that breaks the
rule, or cannot be written (read-only, ``XDG_CACHE_HOME`` naming a file, a full disk),
is not used: the code is generated into a private temporary folder (``mkdtemp``, mode
0700) removed when the process ends, with one line on stderr naming the folder and why,
so that the run's verdict does not depend on the cache (every engine runs as it would).
"""

from __future__ import annotations

import atexit
import os
import shutil
import stat
import sys
import tempfile
from pathlib import Path

from pendverify.errors import FileAccessError

#: the cache folder asked for → the folder used (itself, or a temporary one)
_USED: dict[str, Path] = {}
_TEMPORARY: set[Path] = set()  # the temporary folders this process made


def create_private(folder: Path) -> None:
    """Create ``folder`` and its missing parents with mode 0700 (existing ones are left alone)."""
    missing = []
    path = folder
    while not path.exists() and path != path.parent:
        missing.append(path)
        path = path.parent
    for path in reversed(missing):
        try:
            os.mkdir(path, 0o700)
        except FileExistsError:
            pass


def _ownership_problem(path: Path) -> str | None:
    info = path.stat()
    if not stat.S_ISDIR(info.st_mode):
        return f"{path} is not a folder"
    if info.st_uid != os.geteuid():
        return f"{path} is owned by user id {info.st_uid}, not by you (user id {os.geteuid()})"
    if info.st_mode & 0o022:
        mode = f"{stat.S_IMODE(info.st_mode):04o}"
        return f"{path} is writable by group or others (mode {mode}); run chmod 700 on it"
    return None


def problem(folder: Path) -> str | None:
    """Why ``folder`` cannot hold generated code (after creating it, mode 0700), or None."""
    try:
        create_private(folder)
        for path in (folder.parent, folder):
            why = _ownership_problem(path)
            if why is not None:
                return f"{why}: a code cache must be private to its user"
        fd, probe = tempfile.mkstemp(prefix=".pendverify-probe.", dir=folder)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        return f"{exc.filename or folder}: {exc.strerror or exc}"
    return None


def used(folder: Path) -> Path:
    """The folder to cache generated code in: ``folder`` if it may (``problem``), else a temporary one."""
    asked = str(folder)
    if asked not in _USED:
        why = problem(folder)
        _USED[asked] = folder if why is None else _temporary(folder, why)
    return _USED[asked]


def give_up(folder: Path, why: str) -> Path | None:
    """A write into ``folder`` failed (``why``): the temporary folder to use from now on, or None
    when ``folder`` is already this process's temporary folder (the caller reports the failure)."""
    if folder in _TEMPORARY:
        return None
    for asked, path in list(_USED.items()):
        if path == folder:
            _USED[asked] = _temporary(folder, why)
            return _USED[asked]
    return _temporary(folder, why)


def _temporary(folder: Path, why: str) -> Path:
    try:
        temporary = Path(tempfile.mkdtemp(prefix="pendverify-code-"))
    except OSError as exc:
        why = f"{why}; no temporary folder either: {exc.strerror}"
        raise FileAccessError(str(folder), "write", why) from None
    _TEMPORARY.add(temporary)
    atexit.register(_remove, temporary, os.getpid())
    print(
        f"pendverify: note: the code cache {folder} is not used ({why}); "
        f"generating into the temporary folder {temporary}, removed at exit",
        file=sys.stderr,
        flush=True,
    )
    return temporary


def _remove(folder: Path, pid: int) -> None:
    if os.getpid() == pid:  # not in a forked child that inherited the handler
        shutil.rmtree(folder, ignore_errors=True)


def forget() -> None:
    """Decide again on the next call (tests change ``PENDVERIFY_CACHE``)."""
    _USED.clear()
