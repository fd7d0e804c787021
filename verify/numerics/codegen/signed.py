"""The cache's records, authenticated with a key only the user's own processes hold.

A record is a small JSON object written as one line followed by a line holding its
HMAC-SHA-256 under ``cache.key``: 32 random bytes in the cache folder, mode 0600, made
on first use (``os.link`` of a complete file: processes racing get the same key).  A
record read back is used only when its HMAC holds, so an index and module planted by
anyone who cannot read that key (copied in, unpacked from an archive, written while
the folder was open to others) is never trusted, even when the module's SHA-256 agrees
with the index; a record that does not verify reads as missing and is written anew.
"""

from __future__ import annotations

import hashlib
import hmac
import json
import os
import secrets
import stat
import tempfile
from pathlib import Path

from pendverify.atomic import write_atomic

KEY_FILE = "cache.key"
KEY_BYTES = 32

_KEYS: dict[str, bytes] = {}  # folder → its key (read once per process)


def _read_key(path: Path) -> bytes | None:
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
    except OSError:
        return None
    with os.fdopen(fd, "rb") as fh:
        info = os.fstat(fh.fileno())
        private = stat.S_ISREG(info.st_mode) and info.st_uid == os.geteuid() and not info.st_mode & 0o077
        data = fh.read(KEY_BYTES + 1)
    return data if private and len(data) == KEY_BYTES else None


def key(folder: Path) -> bytes:
    """The folder's key, made now if it has none (or one that is not a private 32-byte file)."""
    known = _KEYS.get(str(folder))
    if known is not None:
        return known
    path = folder / KEY_FILE
    value = _read_key(path)
    if value is None:
        fd, tmp = tempfile.mkstemp(prefix=".cache.key.", dir=folder)  # mode 0600
        with os.fdopen(fd, "wb") as fh:
            fh.write(secrets.token_bytes(KEY_BYTES))
            fh.flush()
            os.fsync(fh.fileno())
        try:
            if path.is_symlink() or path.exists():
                os.replace(tmp, path)  # a key that is not private: every record signed with it is void
            else:
                os.link(tmp, path)
        except FileExistsError:  # another process made it first: use that one
            pass
        finally:
            Path(tmp).unlink(missing_ok=True)
        value = _read_key(path)
        if value is None:
            raise OSError(f"{path}: the cache key cannot be made")
    _KEYS[str(folder)] = value
    return value


def _mac(secret: bytes, text: str) -> str:
    return hmac.new(secret, text.encode(), hashlib.sha256).hexdigest()


def write(path: Path, record: dict) -> None:
    """Write ``record`` signed with the key of ``path``'s folder (``FileAccessError`` if it cannot)."""
    text = json.dumps(record, sort_keys=True, separators=(",", ":"))
    write_atomic(path, f"{text}\n{_mac(key(path.parent), text)}\n")


def read(path: Path) -> dict | None:
    """The record at ``path`` if it is one this user's processes signed, else None."""
    try:
        text, mac = path.read_text(encoding="utf-8").split("\n")[:2]
        secret = key(path.parent)
    except (OSError, UnicodeDecodeError, ValueError):
        return None
    if not hmac.compare_digest(_mac(secret, text), mac.strip()):
        return None
    try:
        record = json.loads(text)
    except ValueError:
        return None
    return record if isinstance(record, dict) else None


def forget() -> None:
    """Read the keys again (tests)."""
    _KEYS.clear()
