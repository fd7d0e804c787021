"""The compiled right-hand side generated from any ``ClosedFormModel``: the model is the one source.

What is generated.  For a model class with n coordinates, ``pendverify.symbolic.model``
reads its closed forms as SymPy expressions (the model's own code, called with
symbols for q, q̇ and the parameters): M(q) from ``mass_matrix`` and the bias
C(q, q̇)·q̇ + H(q) from ``bias`` (the interface's ``coriolis_matrix @ v + gravity``,
or ``coriolis_force + gravity`` for a ``BiasOnlyModel``).  From them this module
writes the Python source of a numba function ``_rhs(P, x, out)`` with n literal:

* the parameters and the force law read from the packed array P (layout below);
* M's lower triangle and the bias, with common subexpressions eliminated
  (``sympy.cse``), printed as scalar code (``math.cos``..., small integer powers
  as products, floats as exact ``repr`` literals);
* τ = B (u0 − K x) − D q̇, the time-invariant force law of
  ``pendverify.numerics.kernels`` (D diagonal);
* M q̈ = τ − bias solved by an unrolled root-free Cholesky factorisation
  M = L diag(d) Lᵀ (M is symmetric positive definite: no pivoting needed, n
  divisions), skipping the entries of L that are structurally zero;
* ẋ = (q̇, q̈) and, when x has 2n + 2 entries, the two work integrals
  dW_in/dt = q̇ᵀ B u and dW_diss/dt = q̇ᵀ D q̇.

The generated module also holds a DOP853 stepper: the numba functions of
``pendverify.numerics.fastpath`` copied verbatim (their source, read with
``inspect``; ``cache=CACHE`` becomes ``cache=True``) with the constants they read
as exact literals, so that they call this model's ``_rhs`` inlined — the hand
kernels' arrangement — and are cached with it.  ``integrate`` runs it; it takes
scipy's steps exactly as fastpath's does.  Why copied and not passed as an
argument: numba specialises a function on a dispatcher argument, but its on-disk
cache keys that specialisation on the dispatcher object, so a new process never
hits it and compiles the stepper again (≈ 10 s per model here); a
``types.FunctionType`` argument (explicit signature) is cached once for all
models, but every call then goes through a pointer, not inlined, and a whole
DOP853 run took 1.7–1.8× as long.

Packed layout (``GeneratedSystem.packed``), for n coordinates, n_p parameters and
nu inputs of the force law::

    P[0] = n,  P[1] = nu,
    P[2 : 2 + n_p]            the parameter values, in the field order of the model's params_type,
    then D (n), B (n × nu, row-major), K (nu × 2n, row-major), u0 (nu).

Cache.  The generated module is written to ``$PENDVERIFY_CACHE/generated`` (or
``~/.cache/pendverify/generated``, ``pendverify.numerics.reference.cache_dir``) as
``rhs_<model>_<digest>.py``, the digest the SHA-256 of the generated source: it
depends on the model's expressions (and on the copied stepper), never on
parameter values.  It is imported with importlib and compiled with
``@njit(cache=True)``, so numba's machine code lands in ``__pycache__`` beside it.
An index file maps a *model key* — the SHA-256 of the source files that define
the model class, its bases and its parameter set (and of the modules they use
from outside the standard library and site-packages), of this generator, of
the symbolic reader and of fastpath — to that digest, so that a second process
neither reads the model with SymPy nor compiles again.  A model whose formulas
depend on code the key does not see may pass ``fresh=True`` to regenerate.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import importlib.metadata
import importlib.util
import inspect
import sys
import sysconfig
import time
import types
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pendverify.atomic import write_atomic
from pendverify.errors import PendverifyError

GENERATOR = "rhs-ldlt-1"  # bump when the generated code changes meaning
HEADER = 2  # P[0] = n, P[1] = nu
#: the numba functions of fastpath copied into each generated module (in this order)
STEPPER = ("_rms", "_initial_step", "_stages", "_dense", "_interpolate", "_error_norm", "_dop853")


def cache_dir() -> Path:
    """Where generated modules (and numba's cache of them) live."""
    from pendverify.numerics.reference import cache_dir as base

    return base() / "generated"


# --- reading the model ----------------------------------------------------------------------
@dataclass(frozen=True)
class Expressions:
    """M(q) and the bias C(q, q̇)·q̇ + H(q) of a model class, in SymPy."""

    name: str
    coordinates: tuple[str, ...]
    parameters: tuple[str, ...]  # field order of params_type
    q: tuple  # SymPy symbols
    v: tuple
    p: tuple
    mass: object  # sp.Matrix n × n
    bias: object  # sp.Matrix n × 1

    @property
    def n(self) -> int:
        return len(self.coordinates)


def expressions(model_cls) -> Expressions:
    """Read M and the bias of ``model_cls`` with ``SymbolicModel`` (a PendverifyError if it cannot)."""
    import sympy as sp

    from pendverify.analytic.plugin import where
    from pendverify.symbolic.model import SymbolicModel, is_zero

    sm = SymbolicModel.of(model_cls)
    n = len(model_cls.coordinates)
    mass, bias = sm.evaluate("mass_matrix", "q"), sm.evaluate("bias", "qv")
    if not isinstance(mass, sp.MatrixBase) or mass.shape != (n, n):
        raise PendverifyError(f"{where(model_cls)}: mass_matrix must return an {n} × {n} array")
    if not isinstance(bias, sp.MatrixBase) or bias.shape != (n, 1):
        raise PendverifyError(f"{where(model_cls)}: bias (C·q̇ + H) must return {n} entries")
    q, v = sm.symbols["q"], sm.symbols["v"]
    p = tuple(sm.parameters[f.name] for f in dataclasses.fields(model_cls.params_type))
    allowed = set(q) | set(v) | set(p)
    for what, matrix in (("mass_matrix", mass), ("bias", bias)):
        stray = sorted(s.name for s in matrix.free_symbols - allowed)
        if stray:
            raise PendverifyError(f"{where(model_cls)}: {what} depends on {', '.join(stray)}")
    if mass.has(*v):
        raise PendverifyError(f"{where(model_cls)}: mass_matrix depends on the rates")
    for i in range(n):
        for j in range(i):
            diff = mass[i, j] - mass[j, i]
            if sp.expand(diff) != 0 and not is_zero(diff, sm.angles):
                raise PendverifyError(
                    f"{where(model_cls)}: mass_matrix is not symmetric (entries {i},{j} and {j},{i})"
                )
    return Expressions(
        model_cls.name,
        tuple(model_cls.coordinates),
        tuple(f.name for f in dataclasses.fields(model_cls.params_type)),
        q,
        v,
        p,
        mass,
        bias,
    )


# --- printing ---------------------------------------------------------------------------------
def _printer():
    """A PythonCodePrinter for numba: exact float literals, small powers as products."""
    import sympy as sp
    from sympy.printing.precedence import PRECEDENCE, precedence
    from sympy.printing.pycode import PythonCodePrinter

    class Printer(PythonCodePrinter):
        def _print_Float(self, expr):
            return repr(float(expr))

        def _print_Rational(self, expr):
            return repr(int(expr.p) / int(expr.q))  # correctly rounded p/q

        def _print_Pow(self, expr, rational=False):
            base, exp = expr.base, expr.exp
            if exp.is_Integer and 2 <= int(exp) <= 4:
                b = self.parenthesize(base, PRECEDENCE["Mul"])
                return "(" + "*".join([b] * int(exp)) + ")"
            if exp.is_Integer and -4 <= int(exp) <= -1:
                inner = base if exp == -1 else sp.Pow(base, -exp, evaluate=False)
                return f"(1.0/{self.parenthesize(inner, PRECEDENCE['Atom'])})"
            if exp == sp.S.Half:
                return f"math.sqrt({self._print(base)})"
            if exp == -sp.S.Half:
                return f"(1.0/math.sqrt({self._print(base)}))"
            return (
                f"{self.parenthesize(base, precedence(expr))}**{self.parenthesize(exp, PRECEDENCE['Atom'])}"
            )

    return Printer({"fully_qualified_modules": True, "standard": "python3"})


def _ldlt(n: int, zero: list[list[bool]]) -> list[str]:
    """Lines solving M a = f by M = L diag(d) Lᵀ, entries m{i}_{j} (i ≥ j) and f{i} given.

    ``zero[i][j]``: M_ij is structurally zero; an entry of L is zero when M_ij is and
    no earlier column fills it in.  Writes a0 … a{n-1}."""
    lz = [[zero[i][j] for j in range(n)] for i in range(n)]  # L_ij structurally zero
    lines = []
    for j in range(n):
        terms = [f" - E{j}_{k}*L{j}_{k}" for k in range(j) if not lz[j][k]]
        lines.append(f"d{j} = m{j}_{j}{''.join(terms)}")
        lines.append(f"r{j} = 1.0/d{j}")
        for i in range(j + 1, n):
            fill = [k for k in range(j) if not lz[i][k] and not lz[j][k]]
            if zero[i][j] and not fill:
                lz[i][j] = True
                continue
            lz[i][j] = False
            head = "0.0" if zero[i][j] else f"m{i}_{j}"
            lines.append(f"E{i}_{j} = {head}{''.join(f' - E{i}_{k}*L{j}_{k}' for k in fill)}")
            lines.append(f"L{i}_{j} = E{i}_{j}*r{j}")
    for i in range(n):  # L y = f
        terms = "".join(f" - L{i}_{k}*y{k}" for k in range(i) if not lz[i][k])
        lines.append(f"y{i} = f{i}{terms}")
    for i in reversed(range(n)):  # Lᵀ a = diag(d)⁻¹ y
        terms = "".join(f" - L{k}_{i}*a{k}" for k in range(i + 1, n) if not lz[k][i])
        lines.append(f"a{i} = y{i}*r{i}{terms}")
    return lines


def _stepper_source() -> str:
    """fastpath's numba functions as source calling this module's ``_rhs``, with the constants they read."""
    from pendverify.numerics import fastpath

    chunks, used = [], set()
    for name in STEPPER:
        func = getattr(fastpath, name).py_func
        text = inspect.getsource(func).replace("cache=CACHE", "cache=True")
        if "cache=True" not in text.splitlines()[0]:
            raise PendverifyError(f"pendverify.numerics.fastpath.{name}: unexpected decorator {text[:80]!r}")
        chunks.append(text)
        used |= set(func.__code__.co_names)
    names = sorted(
        n
        for n in used
        if n in vars(fastpath)
        and n not in STEPPER
        and n not in ("_rhs", "CACHE", "njit")
        and not isinstance(vars(fastpath)[n], types.ModuleType)
    )
    header = [
        "# DOP853: the numba functions of pendverify.numerics.fastpath, verbatim but for cache=True,",
        "# and the constants they read, as exact literals (importing fastpath would import scipy.integrate).",
    ]
    for n in names:
        value = getattr(fastpath, n)
        if isinstance(value, np.ndarray):
            flat = ", ".join(repr(float(x)) for x in value.ravel())
            header.append(f"{n} = np.array([{flat}]).reshape({value.shape!r})")
        elif isinstance(value, float):
            header.append(f"{n} = {float(value)!r}")
        elif isinstance(value, int):
            header.append(f"{n} = {int(value)}")
        else:
            raise PendverifyError(f"pendverify.numerics.fastpath.{n}: cannot copy a {type(value).__name__}")
    return "\n".join(header) + "\n\n\n" + "\n\n".join(chunks)


def render(ex: Expressions, stepper: bool = True) -> str:
    """The generated module's source for the expressions (see the module docstring)."""
    import sympy as sp

    n, n_p = ex.n, len(ex.parameters)
    rename = {s: sp.Symbol(f"p{k}", real=True) for k, s in enumerate(ex.p)}
    rename |= {s: sp.Symbol(f"q{k}", real=True) for k, s in enumerate(ex.q)}
    rename |= {s: sp.Symbol(f"v{k}", real=True) for k, s in enumerate(ex.v)}
    mass = ex.mass.xreplace(rename)
    bias = ex.bias.xreplace(rename)
    lower = [(i, j) for i in range(n) for j in range(i + 1)]
    exprs = [mass[i, j] for i, j in lower] + [bias[i, 0] for i in range(n)]
    replacements, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("e"), order="canonical")
    pr = _printer()
    od = HEADER + n_p
    body = [
        "nu = int(P[1])",
        f"ob = {od + n}",
        f"ok = ob + {n}*nu",
        f"ou = ok + {2 * n}*nu",
    ]
    body += [f"p{k} = P[{HEADER + k}]  # {name}" for k, name in enumerate(ex.parameters)]
    body += [f"q{k} = x[{k}]  # {name}" for k, name in enumerate(ex.coordinates)]
    body += [f"v{k} = x[{n + k}]  # d{name}" for k, name in enumerate(ex.coordinates)]
    body += ["# tau = B (u0 - K x) - D v"]
    body += [f"ti{i} = 0.0" for i in range(n)]
    body += ["for j in range(nu):", f"    k = ok + {2 * n}*j"]
    kx = " + ".join([f"P[k + {k}]*q{k}" for k in range(n)] + [f"P[k + {n + k}]*v{k}" for k in range(n)])
    body += [f"    u = P[ou + j] - ({kx})"]
    body += [f"    ti{i} += P[ob + {i}*nu + j]*u" for i in range(n)]
    body += [f"td{i} = -P[{od + i}]*v{i}" for i in range(n)]
    body += ["# M (lower triangle) and the bias C(q, v) v + H(q)"]
    body += [f"{pr.doprint(s)} = {pr.doprint(e)}" for s, e in replacements]
    zero = [[True] * n for _ in range(n)]
    for (i, j), e in zip(lower, reduced[: len(lower)], strict=True):
        zero[i][j] = zero[j][i] = e == 0
        if e != 0:
            body.append(f"m{i}_{j} = {pr.doprint(e)}")
    for i, e in enumerate(reduced[len(lower) :]):
        body.append(f"f{i} = ti{i} + td{i}" + ("" if e == 0 else f" - ({pr.doprint(e)})"))
    if any(zero[i][i] for i in range(n)):
        raise PendverifyError(f"{ex.name}: mass_matrix has a diagonal entry that is identically zero")
    body += ["# M a = f: M = L diag(d) L^T"]
    body += _ldlt(n, zero)
    body += [f"out[{i}] = v{i}" for i in range(n)]
    body += [f"out[{n + i}] = a{i}" for i in range(n)]
    body += [
        f"if x.shape[0] > {2 * n}:",
        f"    out[{2 * n}] = " + " + ".join(f"v{i}*ti{i}" for i in range(n)),
        f"    out[{2 * n + 1}] = -(" + " + ".join(f"v{i}*td{i}" for i in range(n)) + ")",
    ]
    lines = [
        f'"""Generated by pendverify.numerics.generate ({GENERATOR}) from model {ex.name!r}; do not edit.',
        "",
        f"ẋ = f(x) for x = (q, v[, W_in, W_diss]), q = ({', '.join(ex.coordinates)}), under",
        "τ = B (u0 − K x) − D v; packed layout in pendverify.numerics.generate.",
        '"""',
        "",
        "import math",
        "",
        "import numpy as np",
        "from numba import njit",
        "",
        f"MODEL = {ex.name!r}",
        f"N = {n}",
        f"COORDINATES = {ex.coordinates!r}",
        f"PARAMETERS = {ex.parameters!r}",
        "",
        "",
        '@njit(cache=True, error_model="numpy", inline="always")',
        "def _rhs(P, x, out):",
        *[f"    {line}" for line in body],
        "",
    ]
    source = "\n".join(lines)
    if stepper:
        source += "\n\n" + _stepper_source()
    return source


# --- the cache --------------------------------------------------------------------------------
def _file_digest(path: str) -> str:
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
    """A module's source file, without importing it (fastpath would import scipy.integrate)."""
    return importlib.util.find_spec(module).origin


def model_key(model_cls) -> str | None:
    """SHA-256 of everything the generated source depends on, without reading the model (docstring).

    None when a class has no source file (the generator then always runs)."""
    files: set[str] = set()
    try:
        classes = [
            c for c in (*model_cls.__mro__, *model_cls.params_type.__mro__) if c.__module__ != "builtins"
        ]
        for c in classes:
            files.add(inspect.getfile(c))
            module = sys.modules.get(c.__module__)
            for obj in vars(module).values() if module else ():
                target = (
                    obj
                    if isinstance(obj, types.ModuleType)
                    else sys.modules.get(getattr(obj, "__module__", ""))
                )
                path = getattr(target, "__file__", None)
                if path and path.endswith(".py") and _outside_environment(path):
                    files.add(path)
        files |= {
            __file__,
            *(_origin(m) for m in ("pendverify.symbolic.model", "pendverify.numerics.fastpath")),
        }
    except (TypeError, OSError):
        return None
    # not the module's name: a plug-in's is salted per process (pendverify.analytic.plugin)
    h = hashlib.sha256(f"{GENERATOR}|{importlib.metadata.version('sympy')}|{model_cls.__qualname__}".encode())
    for path in sorted(files):
        h.update(f"|{Path(path).name}:{_file_digest(path)}".encode())
    return h.hexdigest()


@dataclass(frozen=True)
class GeneratedKernel:
    """A generated module: its compiled ``_rhs`` and where it came from."""

    module: types.ModuleType
    digest: str  # SHA-256 of the source
    path: Path
    origin: str  # "generated" (this call ran SymPy), "disk" (read from the cache), "memory"
    seconds: float  # time of this call (generation + import; compilation happens on first use)

    @property
    def rhs(self):
        return self.module._rhs

    @property
    def n(self) -> int:
        return self.module.N

    @property
    def parameters(self) -> tuple[str, ...]:
        return self.module.PARAMETERS


_MEMORY: dict[str, types.ModuleType] = {}  # digest → module
_KEYS: dict[str, str] = {}  # model key → digest


def forget() -> None:
    """Forget the modules this process loaded: the next ``kernel`` call reads the disk (tests)."""
    _MEMORY.clear()
    _KEYS.clear()


def _import(path: Path, digest: str) -> types.ModuleType:
    if digest in _MEMORY:
        return _MEMORY[digest]
    name = f"pendverify_generated_{digest[:16]}"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    _MEMORY[digest] = module
    return module


def _module_path(name: str, digest: str) -> Path:
    safe = "".join(c if c.isalnum() else "_" for c in name)[:40]
    return cache_dir() / f"rhs_{safe}_{digest[:24]}.py"


def kernel(model_cls, fresh: bool = False) -> GeneratedKernel:
    """The generated module of ``model_cls``: from memory, from the on-disk cache, or generated.

    ``fresh``: skip the model-key index (and memory) and read the model with SymPy again;
    the module itself is still reused when its digest is unchanged."""
    start = time.perf_counter()
    key = None if fresh else model_key(model_cls)
    index = cache_dir() / f"index_{key[:24]}.txt" if key else None
    if key and key in _KEYS:
        digest = _KEYS[key]
        module = _MEMORY[digest]
        return GeneratedKernel(module, digest, Path(module.__file__), "memory", time.perf_counter() - start)
    if index is not None and index.is_file():
        digest = index.read_text().strip()
        path = _module_path(model_cls.name, digest)
        if path.is_file() and hashlib.sha256(path.read_bytes()).hexdigest() == digest:
            module = _import(path, digest)
            _KEYS[key] = digest
            return GeneratedKernel(module, digest, path, "disk", time.perf_counter() - start)
    source = render(expressions(model_cls))
    digest = hashlib.sha256(source.encode()).hexdigest()
    path = _module_path(model_cls.name, digest)
    if not (path.is_file() and path.read_text() == source):
        write_atomic(path, source)  # never rewritten otherwise: numba's cache keys on the file's mtime
    module = _import(path, digest)
    if key:
        write_atomic(index, digest + "\n")
        _KEYS[key] = digest
    return GeneratedKernel(module, digest, path, "generated", time.perf_counter() - start)


# --- the packed system ------------------------------------------------------------------------
@dataclass(frozen=True)
class GeneratedSystem:
    """A model's generated kernel and a time-invariant force law τ = B (u0 − K x) − D q̇, packed."""

    kernel: GeneratedKernel
    params: np.ndarray  # parameter values in the field order of the model's params_type
    D: np.ndarray  # (n,) viscous friction per coordinate
    B: np.ndarray  # (n, nu) input map
    K: np.ndarray  # (nu, 2n) state feedback
    u0: np.ndarray  # (nu,) feed-forward input

    @property
    def model(self) -> str:
        return self.kernel.module.MODEL

    @property
    def nv(self) -> int:
        return self.D.shape[0]

    @property
    def conservative(self) -> bool:
        return not (np.any(self.D) or np.any(self.K) or np.any(self.u0))

    def packed(self) -> np.ndarray:
        """The one array the generated kernel takes (layout in the module docstring)."""
        head = np.array([self.nv, self.B.shape[1]], dtype=float)
        return np.concatenate([head, self.params, self.D, self.B.ravel(), self.K.ravel(), self.u0])

    @classmethod
    def from_model(cls, model, D=None, B=None, K=None, u0=None, fresh: bool = False) -> GeneratedSystem:
        """Pack a ``ClosedFormModel`` instance with its parameter values; no forces unless given."""
        k = kernel(type(model), fresh=fresh)
        n = model.nv
        names = tuple(f.name for f in dataclasses.fields(model.params_type))
        if k.n != n or k.parameters != names:
            raise PendverifyError(f"{model.name}: the generated kernel {k.path} does not match the model")
        params = np.array([float(getattr(model.params, f)) for f in names])
        B = np.zeros((n, 0)) if B is None else np.asarray(B, float).reshape(n, -1)
        nu = B.shape[1]
        K = np.zeros((nu, 2 * n)) if K is None else np.asarray(K, float).reshape(nu, 2 * n)
        u0 = np.zeros(nu) if u0 is None else np.asarray(u0, float).reshape(nu)
        D = np.zeros(n) if D is None else np.asarray(D, float).reshape(n)
        return cls(k, params, D, np.ascontiguousarray(B), np.ascontiguousarray(K), u0)

    # --- evaluations -----------------------------------------------------------------
    def rhs(self, x: np.ndarray) -> np.ndarray:
        out = np.empty_like(x, dtype=float)
        self.kernel.rhs(self.packed(), np.ascontiguousarray(x, dtype=float), out)
        return out

    def scipy_rhs(self):
        """fun(t, x) for ``solve_ivp`` calling the compiled right-hand side."""
        P, rhs = self.packed(), self.kernel.rhs

        def fun(t, x):
            out = np.empty(x.shape[0])
            rhs(P, x, out)
            return out

        return fun


def integrate(system: GeneratedSystem, x0, t_end, rtol, atol, t_out=None, record=False):
    """``pendverify.numerics.fastpath.integrate`` on the generated kernel (same DOP853, same result type)."""
    from pendverify.numerics.fastpath import OK, STEP_TOO_SMALL, FastResult

    dop853 = system.kernel.module._dop853
    t_out = np.zeros(0) if t_out is None else np.ascontiguousarray(t_out, dtype=float)
    x0 = np.ascontiguousarray(x0, dtype=float)
    n = x0.shape[0]
    out = np.empty((t_out.shape[0], n))
    cap = 4096 if record else 0
    while True:
        y, st, sx = x0.copy(), np.empty(cap), np.empty((cap, n))
        nfev, steps, rejected, status, rows = dop853(
            system.packed(), y, float(t_end), float(rtol), float(atol), t_out, out, st, sx
        )
        if rows <= cap or not record:
            break
        cap = rows
    if status != OK:
        why = "step size fell below 10 ulp" if status == STEP_TOO_SMALL else "non-finite error estimate"
        raise RuntimeError(f"generated DOP853 failed: {why} (rtol {rtol:g}, atol {atol:g})")
    rows = rows if record else 1
    st, sx = (st[:rows], sx[:rows]) if record else (np.zeros(1), x0[None, :].copy())
    return FastResult(y, out, st, sx, int(nfev), int(steps), int(rejected))
