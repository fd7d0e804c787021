"""The on-disk cache of generated modules, trusted only where this user's pendverify wrote it.

A generated module is written to ``$PENDVERIFY_CACHE/generated`` (or
``~/.cache/pendverify/generated``; a private temporary folder when that one is not
private or cannot be written: ``codegen.folder``) as ``rhs_<model>_<digest>.py``, the
digest the SHA-256 of its source: it depends on the model's expressions (and on the
copied templates), never on parameter values.  Its numba functions are
``@njit(cache=True)``, so their machine code lands in ``__pycache__`` beside it.  A signed
index (``codegen.signed``) maps a *model key* — the SHA-256 of the source files that
define the model class, its bases and its parameter set (and of the modules they use
from outside the standard library and site-packages), of the generator package, of the
symbolic reader, of the template modules and of the units reading (``SOURCES``), and of
pendverify's and SymPy's versions —
to that digest, so that a second process neither reads the model with SymPy nor
compiles again.  A model whose formulas depend on code the key does not see may pass
``fresh=True``.

Before anything is imported: the index's signature, key and version hold, the module's
bytes have the digest, and every numba file of the module that its signed record does
not list with its SHA-256 is deleted (``codegen.numba_files``); the module is executed
from the bytes that were hashed.  An entry that does not verify is regenerated, never
imported (``docs/code-cache.md``).
"""

from __future__ import annotations

import atexit
import functools
import hashlib
import importlib.metadata
import importlib.util
import pkgutil
import sys
import sysconfig
import time
import types
import weakref
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from pendverify.analytic.source_file import COMPANION_FILES, defining_file
from pendverify.atomic import write_atomic
from pendverify.cache_location import cache_root
from pendverify.errors import FileAccessError, PendverifyError
from pendverify.numerics.codegen import expressions as _expressions
from pendverify.numerics.codegen import folder, numba_files, signed
from pendverify.numerics.codegen import module as _module

#: the modules the generated source depends on besides the model's own
SOURCES = (
    "pendverify.analytic.symbolic_reading",
    "pendverify.symbolic.zero_test",
    "pendverify.numerics.integrators.dop853",
    "pendverify.numerics.integrators.fixedstep",
    # the units reading (family ``units``) and the notation and entry labels its messages use
    "pendverify.checks.dimensions",
    "pendverify.checks.units",
    "pendverify.diagnosis.notation",
    "pendverify.diagnosis.slots",
)


def cache_dir() -> Path:
    """Where generated modules (and numba's cache of them) live: ``generated`` in the cache folder
    if that is private and writable, else a temporary folder (``codegen.folder``)."""
    return folder.used(cache_root() / "generated")


@functools.cache
def _version() -> str:
    return importlib.metadata.version("pendverify")


#: {path: SHA-256} of model files imported from a text and deleted since (a certificate's
#: embedded source, ``pendverify.certify.model_source``): their classes keep a key
_TEXT_DIGESTS: dict[str, str] = {}


def remember_text(path: str | Path, text: str) -> None:
    """``path`` holds ``text`` while a model is imported from it, and will be gone afterwards.

    The model's key is then the one the same text has in a file of the same name, so a
    certificate's embedded model reuses the code generated when it was certified (and a
    process, or Dask worker, that imports it generates once for all processes), while an
    edited text has another key."""
    digest = hashlib.sha256(text.encode()).hexdigest()
    for name in {str(path), str(Path(path).resolve())}:
        _TEXT_DIGESTS[name] = digest


def _file_digest(path: str) -> str:
    known = _TEXT_DIGESTS.get(str(path))
    if known is not None:
        return known
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


@functools.cache
def _environment_roots() -> tuple[Path, ...]:
    return tuple(
        {Path(sysconfig.get_paths()[k]).resolve() for k in ("stdlib", "platstdlib", "purelib", "platlib")}
    )


def _outside_environment(path: str) -> bool:
    """True for a source file that is not in the standard library or site-packages."""
    return not any(Path(path).resolve().is_relative_to(root) for root in _environment_roots())


def _origin(module: str) -> str:
    """A module's source file, without importing it (dop853 would import scipy.integrate)."""
    return importlib.util.find_spec(module).origin


def _generator_files() -> set[str]:
    package = Path(__file__).parent
    names = [m.name for m in pkgutil.iter_modules([str(package)])]
    return {str(package / f"{n}.py") for n in names} | {_origin(m) for m in SOURCES}


def model_key(model_cls) -> str | None:
    """SHA-256 of everything the generated source depends on, without reading the model (docstring).

    None when a class has no source file, is not defined at top level by its module (made at
    run time), or comes from a file that is gone and whose text was not given to
    ``remember_text`` (the generator then runs once per process and class).  Computed
    once per class and process (resolving and hashing the files costs ≈ 40 ms): a source file
    edited while a process runs is seen after ``forget()``."""
    if model_cls not in _MODEL_KEYS:
        _MODEL_KEYS[model_cls] = _model_key(model_cls)
    return _MODEL_KEYS[model_cls]


def _defined_by_its_file(cls) -> bool:
    """Whether ``cls`` is the class its module defines at top level under its name: a class made at
    run time (``pendverify mutate``'s mutants, a class inside a function) is not known by its file."""
    module = sys.modules.get(cls.__module__)
    return module is not None and getattr(module, cls.__qualname__, None) is cls


def _model_key(model_cls) -> str | None:
    if not _defined_by_its_file(model_cls):
        return None
    files: set[str] = set()
    try:
        classes = [
            c for c in (*model_cls.__mro__, *model_cls.params_type.__mro__) if c.__module__ != "builtins"
        ]
        for c in classes:
            files.add(defining_file(c))
            module = sys.modules.get(c.__module__)
            files.update(getattr(module, COMPANION_FILES, ()))  # a text model's .m files
            for obj in vars(module).values() if module else ():
                target = (
                    obj
                    if isinstance(obj, types.ModuleType)
                    else sys.modules.get(getattr(obj, "__module__", ""))
                )
                path = getattr(target, "__file__", None)
                if path and path.endswith(".py") and _outside_environment(path):
                    files.add(path)
        files |= _generator_files()
    except (TypeError, OSError):
        return None
    # not the module's name: a plug-in's is salted per process (pendverify.analytic.plugin)
    versions = f"{_version()}|{importlib.metadata.version('sympy')}"
    h = hashlib.sha256(f"{_module.GENERATOR}|{versions}|{model_cls.__qualname__}".encode())
    try:  # names and contents, in an order that does not depend on where the files are
        entries = sorted(f"|{Path(path).name}:{_file_digest(path)}" for path in files)
    except OSError:  # a class loaded from a file that is gone and whose text was not remembered
        return None
    for entry in entries:
        h.update(entry.encode())
    return h.hexdigest()


@dataclass(frozen=True)
class Family:
    """A kind of generated module: its file prefix, how a model class's source is rendered, and
    whether it holds numba functions (then numba's files beside it are verified and recorded)."""

    prefix: str
    render: Callable[[type], str]
    numba: bool


def _render_rhs(model_cls) -> str:
    return _module.render(_expressions.expressions(model_cls))


#: the compiled right-hand side, its steppers and the generic references (``pendverify.numerics.generate``)
RHS = Family("rhs", _render_rhs, numba=True)


@dataclass(frozen=True)
class GeneratedKernel:
    """A generated module and where it came from."""

    module: types.ModuleType
    digest: str  # SHA-256 of the source
    path: Path
    origin: str  # "generated" (this call ran SymPy), "disk" (read from the cache), "memory"
    seconds: float  # time of this call (generation + import; compilation happens on first use)

    @property
    def rhs(self):
        return self.module._rhs

    def __reduce__(self):  # pickled by path and digest (process pools): the module is re-imported
        return _restore, (self.path, self.digest, self.origin, self.seconds)

    @property
    def n(self) -> int:
        return self.module.N

    @property
    def parameters(self) -> tuple[str, ...]:
        return self.module.PARAMETERS


_MEMORY: dict[str, types.ModuleType] = {}  # digest → module
_KEYS: dict[tuple[str, str], str] = {}  # (family prefix, model key) → digest
_MODEL_KEYS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # model class → its model key
_KEYLESS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # class without a key → {prefix: digest}
_COMPILED: dict[str, int] = {}  # digest of a numba module → its compilations already recorded


def forget() -> None:
    """Record what this process compiled, then forget the modules, model keys and folder choices
    it holds: the next ``kernel`` call reads the disk, as a new process would (tests)."""
    record_compiled()
    _MEMORY.clear()
    _KEYS.clear()
    _MODEL_KEYS.clear()
    _KEYLESS.clear()
    _COMPILED.clear()
    folder.forget()
    signed.forget()


def _record_path(path: Path) -> Path:
    return path.with_suffix(".json")


def _import(path: Path, digest: str, numba: bool = True) -> types.ModuleType:
    """The module at ``path`` executed from bytes whose SHA-256 is ``digest`` (a PendverifyError if
    they are not); for a numba module, after deleting every numba file of it its signed record
    does not list."""
    if digest in _MEMORY:
        return _MEMORY[digest]
    data = path.read_bytes()
    if hashlib.sha256(data).hexdigest() != digest:
        raise PendverifyError(f"{path}: the generated module changed on disk while it was used")
    if numba:
        record = signed.read(_record_path(path)) or {}
        recorded = record.get("numba") if record.get("sha256") == digest else None
        numba_files.prune(path, recorded if isinstance(recorded, dict) else {})
    name = f"pendverify_generated_{digest[:16]}"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    # the verified bytes, not the file again (nor a .pyc beside it, which a loader would prefer)
    exec(compile(data, str(path), "exec"), module.__dict__)
    _MEMORY[digest] = module
    if numba:
        numba_files.guard(module)
        _COMPILED[digest] = 0
    return module


def record_compiled() -> None:
    """Record, in each module's signed record, the numba files of the modules this process compiled
    since it last recorded (numba writes them as it compiles; one comparison per module otherwise)."""
    for digest in list(_COMPILED):
        module = _MEMORY[digest]
        done = numba_files.compilations(module)
        if done <= _COMPILED.get(digest, 0):
            continue
        _COMPILED[digest] = done
        path = Path(module.__file__)
        record = {"sha256": digest, "pendverify": _version(), "numba": numba_files.digests(path)}
        try:
            signed.write(_record_path(path), record)
        except (PendverifyError, OSError):  # a full disk: the files are compiled again next time
            continue


atexit.register(record_compiled)


def _restore(path: Path, digest: str, origin: str, seconds: float) -> GeneratedKernel:
    return GeneratedKernel(_import(path, digest), digest, path, origin, seconds)


def _module_path(family: Family, name: str, digest: str, where: Path | None = None) -> Path:
    safe = "".join(c if c.isalnum() else "_" for c in name)[:40]
    return (where or cache_dir()) / f"{family.prefix}_{safe}_{digest[:24]}.py"


def _index_name(family: Family, key: str) -> str:
    return f"index_{family.prefix}_{key[:24]}.json"


def _from_index(family: Family, key: str, name: str) -> tuple[str, Path] | None:
    """(digest, path) of the module the signed index of ``key`` names, if it verifies."""
    record = signed.read(cache_dir() / _index_name(family, key))
    if not record or record.get("key") != key or record.get("pendverify") != _version():
        return None
    digest = record.get("sha256")
    if not isinstance(digest, str) or len(digest) != 64:
        return None
    path = _module_path(family, name, digest)
    try:
        if hashlib.sha256(path.read_bytes()).hexdigest() != digest:
            return None
    except OSError:
        return None
    return digest, path


def _write(family: Family, name: str, source: str, digest: str, key: str | None) -> Path:
    """Write the module (unless it is there already) and the index of ``key``; in a temporary folder
    when the cache folder refuses the write (``codegen.folder``)."""
    where = cache_dir()
    while True:
        path = _module_path(family, name, digest, where)
        try:
            if not (path.is_file() and path.read_text(encoding="utf-8") == source):
                write_atomic(path, source)  # never rewritten otherwise: numba's cache keys on the file
            if key:
                record = {"key": key, "sha256": digest, "pendverify": _version()}
                signed.write(where / _index_name(family, key), record)
            return path
        except (FileAccessError, OSError, UnicodeDecodeError) as exc:
            failure = exc
            if not isinstance(exc, FileAccessError):
                failure = FileAccessError(str(path), "write", str(exc))
            where = folder.give_up(where, str(failure))
            if where is None:  # the temporary folder failed too: one line naming the file and why
                raise failure from None


def kernel(model_cls, fresh: bool = False, family: Family = RHS) -> GeneratedKernel:
    """The generated module of ``family`` for ``model_cls``: from memory, from the on-disk cache, or
    generated.

    ``fresh``: skip the model-key index (and memory) and read the model with SymPy again;
    the module itself is still reused when its digest is unchanged."""
    start = time.perf_counter()
    key = None if fresh else model_key(model_cls)
    if fresh:
        digest = None
    elif key:
        digest = _KEYS.get((family.prefix, key))
    else:
        digest = _KEYLESS.get(model_cls, {}).get(family.prefix)
    if digest is not None:
        module = _MEMORY[digest]
        return GeneratedKernel(module, digest, Path(module.__file__), "memory", time.perf_counter() - start)
    found = _from_index(family, key, model_cls.name) if key else None
    if found is not None:
        digest, path = found
        module = _import(path, digest, family.numba)
        _KEYS[(family.prefix, key)] = digest
        return GeneratedKernel(module, digest, path, "disk", time.perf_counter() - start)
    source = family.render(model_cls)
    digest = hashlib.sha256(source.encode()).hexdigest()
    path = _write(family, model_cls.name, source, digest, key)
    module = _import(path, digest, family.numba)
    if key:
        _KEYS[(family.prefix, key)] = digest
    elif not fresh:  # a class loaded from a file that is gone (a certificate's model source)
        _KEYLESS.setdefault(model_cls, {})[family.prefix] = digest
    return GeneratedKernel(module, digest, path, "generated", time.perf_counter() - start)
