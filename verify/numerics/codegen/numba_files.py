"""numba's cache of a generated module: only files this user's processes wrote are ever loaded.

A generated module's functions are ``@njit(cache=True)``: numba writes their machine code
into ``__pycache__`` beside the module, an index ``<stem>.<function>-<line>.pyXY.nbi`` and
data files ``….N.nbc``, and loads them itself on the first call of the function.  Both are
pickles, so a planted one would run code as it is loaded.  The cache therefore records
the SHA-256 of each such file in the module's signed record (``codegen.signed``) when
the process that compiled has written them (``digests``), and before the module is
imported deletes every one of its numba files that is not recorded with that digest
(``prune``): a garbage, truncated or planted file is never unpickled; numba compiles
again and writes a good one.

numba raises when it cannot write its cache (a full disk) or read what it wrote; so
``guard`` wraps each function's cache object: a file numba cannot write is skipped with
one line on stderr (the code runs, uncached), one it cannot read is compiled again.
The wrapping uses numba's ``Dispatcher._cache`` (numba 0.5x–0.6x keeps the per-function
cache there); a numba without it simply goes unwrapped.
"""

from __future__ import annotations

import hashlib
import pickle
import sys
import types
from pathlib import Path

SUFFIXES = (".nbi", ".nbc")


def files(module_path: Path) -> list[Path]:
    """numba's cache files of the module at ``module_path``."""
    folder = module_path.parent / "__pycache__"
    if not folder.is_dir():
        return []
    prefix = f"{module_path.stem}."
    return sorted(
        p
        for p in folder.iterdir()
        if p.name.startswith(prefix) and p.suffix in SUFFIXES and ".tmp." not in p.name
    )


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def digests(module_path: Path) -> dict[str, str]:
    """{file name: SHA-256} of the module's numba files as they are now."""
    found = {}
    for path in files(module_path):
        try:
            found[path.name] = _sha256(path)
        except OSError:  # removed meanwhile by another process's prune
            continue
    return found


def prune(module_path: Path, recorded: dict) -> dict[str, str]:
    """Delete the module's numba files that ``recorded`` ({name: SHA-256}) does not list with their
    digest; the ones kept, {name: SHA-256}."""
    kept = {}
    for path in files(module_path):
        try:
            if recorded.get(path.name) == _sha256(path):
                kept[path.name] = recorded[path.name]
                continue
            path.unlink()
        except OSError:
            continue
    return kept


def dispatchers(module: types.ModuleType) -> list:
    """The module's numba functions (found once per module)."""
    found = module.__dict__.get("__pendverify_dispatchers__")
    if found is None:
        from numba.core.dispatcher import Dispatcher

        found = [obj for obj in vars(module).values() if isinstance(obj, Dispatcher)]
        module.__pendverify_dispatchers__ = found
    return found


def compilations(module: types.ModuleType) -> int:
    """How many compilations this process ran for the module's functions (numba's cache misses)."""
    return sum(len(d.stats.cache_misses) for d in dispatchers(module))


_WARNED: set[str] = set()

#: what numba raises reading a file that is not what it wrote (a truncated or garbage pickle)
UNREADABLE = (OSError, EOFError, pickle.UnpicklingError, ValueError, TypeError, AttributeError, IndexError)


def guard(module: types.ModuleType) -> None:
    """Make numba's cache of ``module`` skip a file it cannot write, and recompile one it cannot read."""
    for dispatcher in dispatchers(module):
        cache = getattr(dispatcher, "_cache", None)
        if not hasattr(cache, "save_overload") or getattr(cache, "_pendverify_guarded", False):
            continue
        save, load = cache.save_overload, cache.load_overload
        where = str(getattr(cache, "cache_path", "?"))

        def guarded_save(sig, data, save=save, where=where):
            try:
                save(sig, data)
            except OSError as exc:
                if where not in _WARNED:
                    _WARNED.add(where)
                    print(
                        f"pendverify: note: numba cannot write its cache in {where} "
                        f"({exc.strerror or exc}); the compiled code is not cached",
                        file=sys.stderr,
                        flush=True,
                    )

        def guarded_load(sig, target_context, load=load):
            try:
                return load(sig, target_context)
            except UNREADABLE:
                return None

        cache.save_overload, cache.load_overload = guarded_save, guarded_load
        cache._pendverify_guarded = True
