"""A text model file (TOML) made into a ``ClosedFormModel`` subclass like any other.

``pendverify.analytic.text_parse`` reads the file; here the equations are
completed (H = ∂V/∂q when only V is given, V integrated from H when only H is;
C = C_plus_D − D; f split into H = −f(q, 0, 0, 0), D = −∂f/∂q̇ at q̇ = 0 (required
constant), C·q̇ = the rest of f(q, q̇, 0, 0) − f(q, 0, 0, 0) (required quadratic in
q̇), B = ∂f/∂u and W = ∂f/∂w (required constant, f affine in u and w)), checked
(M symmetric, C or Cqdot, B when there are inputs) and turned into a
class whose methods evaluate them: numerically through ``sympy.lambdify`` onto
``self.math``'s functions (Python's ``math``, mpmath for the high-precision judge,
complex functions for the LQR's complex step), and as the SymPy expressions
themselves when ``self.math`` is SymPy's (``pendverify.analytic.symbolic_reading``), so that
``sympy``, ``mutate`` and the code generator read the text model as they read a
Python one.  Only the methods whose equations the file gives are defined, so
``hand_written()`` tells the truth.  The class's module is a stand-in that names
the text file in ``pendverify.analytic.source_file.TEXT_FILE`` (messages and the
generated-code cache name it) and has no ``__file__``, which would claim Python source.
"""

from __future__ import annotations

import dataclasses
import sys
import types
from pathlib import Path

import numpy as np
import sympy as sp

from pendverify.analytic.forms import Energies
from pendverify.analytic.interface import AccelerationOnlyModel, BiasOnlyModel, ClosedFormModel
from pendverify.analytic.module_names import module_name
from pendverify.analytic.parameter_set import ParameterSet
from pendverify.analytic.source_file import COMPANION_FILES, TEXT_FILE
from pendverify.analytic.text_parse import EQUATIONS, Reader, TextModelSpec, read_text_model
from pendverify.display import shortened

#: equation key → (method, its arguments)
METHODS = {
    "M": ("mass_matrix", "q"),
    "C": ("coriolis_matrix", "qv"),
    "Cqdot": ("coriolis_force", "qv"),
    "H": ("gravity", "q"),
    "V": ("potential_energy", "q"),
    "D": ("damping_matrix", ""),
    "B": ("input_matrix", ""),
    "W": ("disturbance_matrix", ""),
    "det_M": ("det_mass_matrix", "q"),
    "M_inv": ("inverse_mass_matrix", "q"),
    "qddot": ("acceleration", "qvuw"),
}


def _is_zero(expr) -> bool:
    expr = sp.expand(sp.expand_trig(expr))
    return expr == 0 or sp.simplify(expr) == 0


def complete_equations(reader: Reader, spec: TextModelSpec) -> None:
    """Check the set of equations and derive what is given in another form (module docstring)."""
    eq = spec.equations
    if spec.balance:
        _acceleration_from_balance(reader, spec)
    if "M" not in eq and "qddot" in eq:
        if not _mass_from_acceleration(reader, spec):
            return  # q̈ alone, inputs that do not span the coordinates: an AccelerationOnlyModel
    if "M" not in eq:
        reader.fail("M", "missing: the mass matrix, a list of rows of expressions")
    if "f" in eq:
        _split_f(reader, spec)
    if "C_plus_D" in eq:
        if "D" not in eq:
            reader.fail("C_plus_D", "needs D: C_plus_D is C with the friction inside, C = C_plus_D − D")
        if "C" in eq or "Cqdot" in eq:
            reader.fail("C_plus_D", "give one of C, Cqdot or C_plus_D")
        eq["C"] = eq.pop("C_plus_D") - eq["D"]
        spec.derived["C"] = "C_plus_D − D"
    if ("C" in eq) == ("Cqdot" in eq):
        reader.fail("C", "give exactly one of C (the matrix), C_plus_D (C + D) or Cqdot (the vector C·q̇)")
    M = eq["M"]
    for i in range(M.rows):
        for j in range(i + 1, M.cols):
            if not _is_zero(M[i, j] - M[j, i]):
                reader.fail(
                    "M",
                    f"not symmetric: M[{i},{j}] = {shortened(str(M[i, j]), 60)} "
                    f"but M[{j},{i}] = {shortened(str(M[j, i]), 60)}; if M q̈ = f are balance "
                    "equations (Newton–Euler, MATLAB's equationsToMatrix), whose M is not the mass "
                    "matrix, declare balance = true",
                )
    q = spec.symbols["q"]
    if "H" not in eq and "V" not in eq:
        reader.fail("H", "missing: give H (the gravity vector) or V (the potential energy), or both")
    if "H" not in eq:
        eq["H"] = sp.Matrix([sp.diff(eq["V"], x) for x in q])
        spec.derived["H"] = "∂V/∂q"
    elif "V" not in eq:
        eq["V"] = _integrated(reader, eq["H"], q)
        spec.derived["V"] = "integrated from H"
    elif "H" in spec.derived and not all(_is_zero(sp.diff(eq["V"], x) - eq["H"][i]) for i, x in enumerate(q)):
        reader.fail("V", f"∂V/∂q is not the gravity vector H ({spec.derived['H']})")
    if spec.inputs and "B" not in eq:
        reader.fail("B", f"missing: the model declares inputs {', '.join(spec.inputs)}")


_F_PARTS = {
    "H": "−f(q, 0, 0, 0)",
    "Cqdot": "the part quadratic in q̇",
    "D": "−∂f/∂q̇ at q̇ = 0",
    "B": "∂f/∂u",
    "W": "∂f/∂w",
}


def _cancelled(matrix):
    return matrix.applyfunc(lambda x: sp.cancel(sp.together(x)))


def _acceleration_from_balance(reader: Reader, spec: TextModelSpec) -> None:
    """``balance = true``: M q̈ = f are balance equations, q̈ = M⁻¹ f, read as a q̈ alone is.

    Newton–Euler balances (a torque about each joint, MATLAB's ``equationsToMatrix`` of them) give
    T·M q̈ = T·f for some invertible T: the same motion, but T·M is not the mass matrix and need
    not be symmetric.  Only q̈ is then the model's own: it is solved for exactly (SymPy's LU
    solve, each entry cancelled) and the model goes on as one that writes q̈ and B."""
    eq = spec.equations
    if "M" not in eq or "f" not in eq:
        reader.fail("balance", "balance equations are M q̈ = f: give M and f")
    others = [k for k in ("C", "C_plus_D", "Cqdot", "H", "V", "qddot", "det_M", "M_inv") if k in eq]
    if others:
        reader.fail("balance", f"balance equations are M q̈ = f alone (with B, D, W): not {others[0]}")
    M, f = eq.pop("M"), eq.pop("f")
    if _is_zero(M.det()):
        reader.fail("M", "is singular (det M = 0): the balance equations do not determine q̈")
    eq["qddot"] = _cancelled(M.LUsolve(f))
    spec.derived["qddot"] = "M⁻¹ f of the balance equations"


def _mass_from_acceleration(reader: Reader, spec: TextModelSpec) -> bool:
    """q̈ alone (no M): M = B (∂q̈/∂u)⁻¹ and f = M q̈ where B is square and invertible; else False.

    q̈ = M⁻¹(B u + …) is required affine in u with ∂q̈/∂u = M⁻¹B free of u.  With as many
    inputs as coordinates and B invertible, M = B (M⁻¹B)⁻¹ exactly, f = M q̈(q, q̇, u, w), and
    f goes the one way every f goes (``_split_f``); the hand-written q̈ stays q̈, checked by aba.
    The declared D and W must be the ones q̈ implies.  With fewer inputs M is not determined:
    the model is an ``AccelerationOnlyModel`` (D, W as declared, zero by default).
    """
    eq, sym = spec.equations, spec.symbols
    if "H" in eq or "V" in eq or "C" in eq or "Cqdot" in eq or "C_plus_D" in eq or "f" in eq:
        reader.fail("qddot", "without M, give q̈ alone (with B, D, W): not H, V, C, Cqdot or f")
    if spec.inputs and "B" not in eq:
        reader.fail("B", f"missing: the model declares inputs {', '.join(spec.inputs)}; q̈ alone needs B too")
    a = eq["qddot"]
    if not spec.inputs:
        return False
    G = a.jacobian(list(sym["u"]))
    if G.free_symbols & set(sym["u"]):
        reader.fail("qddot", "is not affine in the inputs (∂q̈/∂u depends on u)")
    B = eq["B"]
    if B.rows != B.cols or B.det() == 0:
        return False
    M = _cancelled(B * G.inv())
    declared = {k: eq.pop(k) for k in ("B", "D", "W") if k in eq}
    eq["M"], eq["f"] = M, _cancelled(M * a)
    qddot = eq.pop("qddot")
    spec.derived["f"] = "q̈'s M·q̈"
    _split_f(reader, spec)
    eq["qddot"] = qddot
    spec.derived["M"] = "from q̈: B (∂q̈/∂u)⁻¹"
    n = len(spec.coordinates)
    zero = {"D": sp.zeros(n, n), "W": sp.zeros(n, len(spec.disturbances))}
    for key, value in declared.items():
        implied = eq.get(key, zero.get(key))
        if not all(_is_zero(x) for x in implied - value):
            reader.fail(key, f"q̈ implies {key} = {shortened(str(implied.tolist()), 60)}, not the one given")
    return True


def _split_f(reader: Reader, spec: TextModelSpec) -> None:
    """M q̈ = f(q, q̇, u, w) split into H, Cqdot, D, B, W (module docstring); each part is checked."""
    eq, sym = spec.equations, spec.symbols
    parts = [k for k in ("C", "C_plus_D", "Cqdot", "H", "D", "B", "W", "qddot") if k in eq]
    if parts:
        reader.fail("f", f"give f or its parts, not both (the file also gives {', '.join(parts)})")
    f = eq.pop("f")
    zero = {s: 0 for g in "vuw" for s in sym[g]}
    rest = {s: 0 for g in "uw" for s in sym[g]}
    H = -f.xreplace(zero)
    for key, group in (("B", "u"), ("W", "w")):
        if sym[group]:
            J = f.jacobian(list(sym[group]))
            if J.free_symbols & set(sym["q"] + sym["v"] + sym["u"] + sym["w"]):
                reader.fail(
                    "f",
                    f"is not f0(q, q̇) + {key}·{group} with a constant {key}: "
                    f"∂f/∂{group} = {shortened(str(J.tolist()), 80)}",
                )
            eq[key] = J
    driven = f.xreplace(rest)
    if not all(
        _is_zero(x)
        for x in f
        - driven
        - sum((eq[k] * sp.Matrix(sym[g]) for k, g in (("B", "u"), ("W", "w")) if sym[g]), sp.zeros(f.rows, 1))
    ):
        reader.fail("f", "is not affine in the inputs and disturbances")
    velocity = driven + H  # f(q, q̇, 0, 0) − f(q, 0, 0, 0)
    v = sp.Matrix(sym["v"])
    D = -velocity.jacobian(list(v)).xreplace(zero)
    if D.free_symbols & set(sym["q"]):
        reader.fail(
            "f",
            "its part linear in q̇ (the damping −D·q̇) depends on the coordinates: "
            f"D = {shortened(str(D.tolist()), 80)}",
        )
    Cqdot = -(velocity + D * v)  # kept as written: the homogeneity test below expands a copy
    lam = sp.Dummy("lam")
    if not all(_is_zero(x) for x in Cqdot.xreplace({s: lam * s for s in v}) - lam**2 * Cqdot):
        reader.fail("f", "its velocity part is not −D·q̇ − C(q, q̇)·q̇ (linear plus quadratic in q̇)")
    eq["H"], eq["Cqdot"] = H, Cqdot
    if any(x != 0 for x in D):
        eq["D"] = D
    source = spec.derived.pop("f", "f")  # where f came from: "f", "the equations' f", …
    spec.derived.update({k: f"from {source}: {how}" for k, how in _F_PARTS.items() if k in eq})


def _integrated(reader: Reader, H, q):
    """V with ∂V/∂q = H, integrated one coordinate at a time; refused if H is not a gradient.

    V is returned as integrated, exact and proved to be H's potential: ``sympy.simplify`` made it
    about 15 % shorter at a cost growing steeply with its size (8 s for a 5-link chain's)."""
    V = sp.S.Zero
    for i, x in enumerate(q):
        V += sp.integrate(sp.expand(H[i] - sp.diff(V, x)), x)
    if not all(_is_zero(sp.diff(V, x) - H[i]) for i, x in enumerate(q)):
        reader.fail(
            "H",
            "is not the gradient of any potential (∂H_i/∂q_j ≠ ∂H_j/∂q_i): a typo in H? else give V as well",
        )
    return V


def _method(key: str, args: str, spec: TextModelSpec):
    expr = spec.equations[key]
    syms = [s for g in args + "p" for s in spec.symbols[g]]
    params = [s.name for s in spec.symbols["p"]]
    entries = expr.tolist() if isinstance(expr, sp.MatrixBase) else expr
    # a vector by its key's declared shape, never by its own: a 1 × 1 M (one coordinate) is a matrix
    vector = isinstance(expr, sp.MatrixBase) and EQUATIONS[key][0] == "n"
    if vector:
        entries = [row[0] for row in entries]
    compiled: dict[int, tuple] = {}

    def method(self, *arrays):
        values = [x for a in arrays for x in a] + [getattr(self.params, p) for p in params]
        if self.math.cos is sp.cos:  # read by SymPy: the expressions themselves
            value = expr.xreplace({s: sp.sympify(x) for s, x in zip(syms, values, strict=True)})
            if not isinstance(value, sp.MatrixBase):
                return value
            return np.array(list(value) if vector else value.tolist(), dtype=object)
        namespace = self.math
        cached = compiled.get(id(namespace))
        if cached is None or cached[0] is not namespace:
            cached = compiled[id(namespace)] = (
                namespace,
                sp.lambdify(syms, entries, modules=[vars(namespace)]),
            )
        value = cached[1](*values)
        if not isinstance(value, list):
            return value
        result = np.array(value)
        return result.astype(float) if result.dtype.kind in "iub" else result

    method.__name__ = METHODS[key][0]
    method.__doc__ = f"{key} as written in {spec.path}"
    return method


def _energies(self, q, v, u, w) -> Energies:
    """T = ½ q̇ᵀ M q̇, V, R = ½ q̇ᵀ D q̇ and P = (B u + W w)ᵀ q̇, from the file's own M, V, D, B, W."""
    vv = sp.Matrix(list(v))
    M, D = sp.Matrix(self.mass_matrix(q)), sp.Matrix(self.damping_matrix())
    force = sp.Matrix(self.input_matrix()) * sp.Matrix(list(u)) if len(u) else sp.zeros(len(v), 1)
    if len(w):
        force += sp.Matrix(self.disturbance_matrix()) * sp.Matrix(list(w))
    half = sp.Rational(1, 2)
    return Energies(
        kinetic=half * (vv.T * M * vv)[0],
        potential=self.potential_energy(q),
        dissipation=half * (vv.T * D * vv)[0],
        power=(force.T * vv)[0],
    )


def _how_to_name_joints(spec: TextModelSpec):
    """A text model's ``how_to_name_joints``: in the terms of its TOML file, or of the declaration
    that came with a derivation or a right-hand side (``pendverify.analytic.mechanics_model``)."""
    coordinates = ", ".join(spec.coordinates)
    joints = ", ".join(f'"<URDF joint of {c}>"' for c in spec.coordinates)
    if str(spec.path).lower().endswith(".toml"):
        text = (
            f"add a [urdf] table with joints = [{joints}], the URDF joint of each coordinate ({coordinates}) "
            "in order (and transform, offset when q = T (θ − θ0) is not the identity)"
        )
    else:
        text = (
            f'add "urdf": {{"joints": [{joints}]}} to its declaration, the URDF joint of each coordinate '
            f"({coordinates}) in order"
        )
    return classmethod(lambda cls: text)


def parameter_type(spec: TextModelSpec, class_name: str) -> type[ParameterSet]:
    """The ``ParameterSet`` dataclass ``<class_name>Params`` of the declared parameters (kind, unit)."""
    fields = [
        (p, float, dataclasses.field(metadata={"kind": kind, "unit": unit, "doc": f"{p} in [{unit}]"}))
        for p, (kind, unit) in spec.parameters.items()
    ]
    return dataclasses.make_dataclass(
        f"{class_name}Params", fields, bases=(ParameterSet,), frozen=True, namespace={"model": spec.name}
    )


def class_name_of(spec: TextModelSpec) -> str:
    """The model class's name: the model's name in CamelCase (``double_pendulum`` → ``DoublePendulum``)."""
    return "".join(part.capitalize() for part in spec.name.split("_")) or "TextModel"


def declared_attributes(spec: TextModelSpec, params_type: type[ParameterSet]) -> dict[str, object]:
    """The class attributes a declaration gives every model built from it: its name, parameter set,
    coordinates, inputs, disturbances and map to the URDF's joints."""
    return {
        "name": spec.name,
        "params_type": params_type,
        "coordinates": spec.coordinates,
        "angular": spec.angular,
        "inputs": spec.inputs,
        "disturbances": spec.disturbances,
        "urdf_joints": spec.urdf_joints,
        "joint_transform": spec.joint_transform,
        "joint_offset": spec.joint_offset,
    }


def build_model_class(
    spec: TextModelSpec, module: types.ModuleType | None = None, base: type[ClosedFormModel] | None = None
) -> type[ClosedFormModel]:
    """The ``ClosedFormModel`` (``BiasOnlyModel``, ``AccelerationOnlyModel``) subclass of a text model.

    ``module``: the module the class is to live in (a Python model file's own); None: a stand-in
    module naming ``spec.path`` (a text file, or the object a model was made from).  ``base``: the
    class a model without M derives from instead of ``AccelerationOnlyModel`` (one whose q̈ is
    code, ``pendverify.analytic.python_dynamics``).
    """
    class_name = class_name_of(spec)
    if module is None:
        module = types.ModuleType(module_name(spec.path))
        setattr(module, TEXT_FILE, str(spec.path))
        if spec.matlab is not None:
            setattr(module, COMPANION_FILES, tuple(str(p) for p in spec.matlab.files))
        sys.modules[module.__name__] = module
    params_type = parameter_type(spec, class_name)
    namespace = {
        **declared_attributes(spec, params_type),
        "text_spec": spec,
        "written_names": dict(spec.written_names),
        "how_to_name_joints": _how_to_name_joints(spec),
        "energies": _energies,
    }
    for key, (method, args) in METHODS.items():
        if key in spec.equations:
            namespace[method] = _method(key, args, spec)
    if "M" not in spec.equations:  # q̈ alone, M not determined (``_mass_from_acceleration``)
        base = base or AccelerationOnlyModel
        del namespace["energies"]
    elif "Cqdot" in spec.equations:
        base = BiasOnlyModel
    else:
        base = ClosedFormModel
    cls = type(class_name, (base,), namespace)
    for c in (cls, params_type):
        c.__module__ = module.__name__
        setattr(module, c.__name__, c)
    return cls


def load_text_model(path: str | Path) -> type[ClosedFormModel]:
    """Read, check and build the model class of a text model file."""
    spec = read_text_model(path)
    complete_equations(Reader(spec.path), spec)
    return build_model_class(spec)
