"""SymPy as a third opinion: the hand-written closed forms against the Lagrangian.

Pinocchio and the hand model can share a wrong assumption (an inertia about the
pivot written into both the URDF and the formulas); the energies written from
the model's stated conventions are a third, independent account.  Each closed
form is compared with its derivation (``pendverify.symbolic.lagrange``) entry by entry,
each entry passing when ``simplify(hand − derived) == 0`` (decided exactly by
``pendverify.symbolic.zero_test.is_zero``):

=============================  =============================================
closed form                    compared with
=============================  =============================================
mass_matrix                    M = ∂²T/∂q̇²
coriolis_matrix                the Christoffel C; if only C·q̇ agrees, a warning
                               that says whether Ṁ − 2C is still skew
gravity                        H = ∂V/∂q
potential_energy               V, up to a constant (∂(V_hand − V)/∂q = 0)
damping / input / disturbance  D = ∂²R/∂q̇², B, W from the input power
det_mass_matrix                det M
inverse_mass_matrix            M_hand⁻¹ · M − I = 0
acceleration                   M q̈_hand + (C + D) q̇ + H − B u − W w = 0, when the
                               code can be read symbolically (not np.linalg.solve)
extra closed forms             what their ``equals`` says, e.g. the cart reference system's
                               f = −C ẏ − H − D ẏ + B u + W w
=============================  =============================================

det M, M⁻¹ and q̈ that the model does not write (``hand_written``) are derived by
the interface from M and the other parts: they are listed as ``skipped``, with
the reason, and not compared; so is V when the model does not write it (it is optional).
"""

from __future__ import annotations

import time
import unicodedata
from dataclasses import dataclass, field

import sympy as sp

from pendverify.analytic import ClosedFormModel
from pendverify.analytic.forms import entry_position
from pendverify.analytic.source_file import where
from pendverify.analytic.symbolic_reading import SymbolicModel, entries, to_sympy
from pendverify.checks.verdict import CHRISTOFFEL_CONSISTENT, NON_CHRISTOFFEL
from pendverify.display import html_text, listed, shortened
from pendverify.errors import PendverifyError
from pendverify.symbolic.lagrange import Lagrangian, derive, mass_matrix_rate
from pendverify.symbolic.work import check_symbolic_work
from pendverify.symbolic.zero_test import is_zero, show

EQUAL, DIFFERS, WARNING, SKIPPED = "equal", "DIFFERS", "warning", "skipped"


@dataclass
class Comparison:
    """One closed form against its derivation, entry by entry."""

    quantity: str
    method: str
    relation: str
    status: str
    entries: int
    differences: list[str] = field(default_factory=list)
    note: str = ""

    def as_dict(self) -> dict:
        return dict(self.__dict__)


@dataclass
class SymbolicReport:
    model: str
    source: str
    comparisons: list[Comparison]
    elapsed_s: float = 0.0

    @property
    def passed(self) -> bool:
        return all(c.status != DIFFERS for c in self.comparisons)

    def __repr__(self) -> str:
        differ = [c.quantity for c in self.comparisons if c.status == DIFFERS]
        head = f"<SymbolicReport {shortened(self.model, 60)}: {'pass' if self.passed else 'DIFFERS'}"
        tail = f", {len(self.comparisons)} closed forms compared"
        return f"{head}{tail}{f' ({listed(differ, 100)} differ)' if differ else ''}>"

    def _repr_html_(self) -> str:
        return html_text(format_report(self))

    def as_dict(self) -> dict:
        return {
            "model": self.model,
            "source": self.source,
            "passed": self.passed,
            "elapsed_s": round(self.elapsed_s, 3),
            "comparisons": [c.as_dict() for c in self.comparisons],
        }


def _label(method: str, shape_of, i: int) -> str:
    if not isinstance(shape_of, sp.MatrixBase):
        return ""
    return f"[{','.join(map(str, entry_position(method, shape_of.shape, i)))}]"


def _compare(quantity, method, relation, residual, angles) -> Comparison:
    """Every entry of ``residual`` (hand − derived, or a residual) must be zero."""
    items = entries(residual)
    differences = [
        f"{quantity}{_label(method, residual, i)}: {show(e, angles)}"
        for i, e in enumerate(items)
        if not is_zero(e, angles)
    ]
    return Comparison(quantity, method, relation, DIFFERS if differences else EQUAL, len(items), differences)


def coriolis_verdict(C_hand: sp.Matrix, lag: Lagrangian, sm: SymbolicModel) -> tuple[bool, bool]:
    """(same C·q̇ as the Christoffel form, Ṁ − 2C skew-symmetric) for a hand-written C."""
    v, angles = sm.column("v"), sm.angles
    same_bias = all(is_zero(e, angles) for e in (C_hand - lag.C) * v)
    N = mass_matrix_rate(lag.M, sm.symbols["q"], sm.symbols["v"]) - 2 * C_hand
    skew = all(is_zero(e, angles) for e in N + N.T)
    return same_bias, skew


def _coriolis(sm, lag) -> Comparison:
    if not sm.cls.has_coriolis_matrix:
        force = sm.evaluate("coriolis_force", "qv") - lag.C * sm.column("v")
        return _compare("C·q̇", "coriolis_force", "hand − Christoffel C·q̇", force, sm.angles)
    C_hand = sm.evaluate("coriolis_matrix", "qv")
    result = _compare("C", "coriolis_matrix", "hand − Christoffel C", C_hand - lag.C, sm.angles)
    if result.status == DIFFERS:
        same_bias, skew = coriolis_verdict(C_hand, lag, sm)
        if same_bias:
            result.status = WARNING
            result.note = (
                CHRISTOFFEL_CONSISTENT if skew else NON_CHRISTOFFEL + " (passivity-based uses of C will fail)"
            )
    return result


def _acceleration(sm, lag) -> Comparison:
    relation = "M q̈_hand + (C + D) q̇ + H − B u − W w"
    try:
        a = to_sympy(sm.model.acceleration(*sm.arguments("qvuw")))
    except Exception as exc:  # e.g. np.linalg.solve on symbols: the code solves numerically
        note = (
            f"the code is not a closed form SymPy can read ({type(exc).__name__}); "
            "the closed forms it is built from are compared instead"
        )
        return Comparison("q̈", "acceleration", relation, SKIPPED, 0, note=note)
    v, u, w = sm.column("v"), sm.column("u"), sm.column("w")
    residual = lag.M * a + (lag.C + lag.D) * v + lag.H - lag.B * u - lag.W * w
    return _compare("q̈", "acceleration", relation, residual, sm.angles)


def _derived(quantity, method, relation, how) -> Comparison:
    """A quantity the model does not write: derived by the interface, so nothing to compare."""
    note = f"not hand-written: derived {how} by the interface, nothing to compare"
    return Comparison(quantity, method, relation, SKIPPED, 0, note=note)


def _extra(sm, lag, method, form) -> Comparison:
    try:
        expected = eval(form.equals, {"__builtins__": {}}, lag.namespace(sm))
    except Exception as exc:
        raise PendverifyError(
            f"{where(sm.cls)}: {sm.cls.__name__}.closed_forms[{method!r}].equals = {form.equals!r} cannot be "
            f"evaluated ({type(exc).__name__}: {exc}); use M, C, H, V, D, B, W and q, v, u, w"
        ) from None
    hand = sm.evaluate(method, form.args)
    if isinstance(hand, sp.MatrixBase) != isinstance(expected, sp.MatrixBase) or (
        isinstance(hand, sp.MatrixBase) and hand.shape != expected.shape
    ):
        raise PendverifyError(
            f"{where(sm.cls)}: {sm.cls.__name__}.{method} and its equals {form.equals!r} differ in shape"
        )
    result = _compare(method, method, f"hand − ({form.equals})", hand - expected, sm.angles)
    n = len(sm.symbols["q"])
    if result.status == DIFFERS and form.args == "qv" and "C" in form.equals and hand.shape == (n, n):
        if all(is_zero(e, sm.angles) for e in (hand - expected) * sm.column("v")):
            result.status = WARNING
            result.note = f"differs from {form.equals} but gives the same C·q̇ (see C above)"
    return result


def compare(model_cls: type[ClosedFormModel], label: str | None = None) -> SymbolicReport:
    """Every closed form of ``model_cls`` against the derivation from its energies."""
    started = time.perf_counter()
    sm = SymbolicModel.of(model_cls)
    check_symbolic_work(sm)
    lag = derive(sm)
    angles, n = sm.angles, len(sm.symbols["q"])
    q = sm.symbols["q"]
    M_hand = sm.evaluate("mass_matrix", "q")
    out = [
        _compare("M", "mass_matrix", "hand − ∂²T/∂q̇²", M_hand - lag.M, angles),
        _coriolis(sm, lag),
        _compare("H", "gravity", "hand − ∂V/∂q", sm.evaluate("gravity", "q") - lag.H, angles),
    ]
    if model_cls.has_potential_energy():
        dV = sm.evaluate("potential_energy", "q") - lag.V
        potential = _compare(
            "V", "potential_energy", "∂(hand − V)/∂q", sp.Matrix([dV.diff(x) for x in q]), angles
        )
        potential.note = "equal up to a constant" if potential.status == EQUAL else ""
    else:  # optional: H is compared with ∂V/∂q of the energies' V above
        note = "not run: the model gives no potential energy V(q) (potential_energy), nothing to compare"
        potential = Comparison("V", "potential_energy", "∂(hand − V)/∂q", SKIPPED, 0, note=note)
    out.append(potential)
    out.append(
        _compare("D", "damping_matrix", "hand − ∂²R/∂q̇²", sm.evaluate("damping_matrix", "") - lag.D, angles)
    )
    out.append(
        _compare("B", "input_matrix", "hand − ∂²P/∂q̇∂u", sm.evaluate("input_matrix", "") - lag.B, angles)
    )
    if model_cls.disturbances:
        W_hand = sm.evaluate("disturbance_matrix", "")
        out.append(_compare("W", "disturbance_matrix", "hand − ∂²P/∂q̇∂w", W_hand - lag.W, angles))
    written = model_cls.hand_written()
    if "det_mass_matrix" in written:
        det = sm.evaluate("det_mass_matrix", "q") - lag.M.det()
        out.append(_compare("det M", "det_mass_matrix", "hand − det M", det, angles))
    else:
        out.append(_derived("det M", "det_mass_matrix", "hand − det M", "from M (LU)"))
    if "inverse_mass_matrix" in written:
        inverse = sm.evaluate("inverse_mass_matrix", "q") * lag.M - sp.eye(n)
        out.append(_compare("M⁻¹", "inverse_mass_matrix", "M⁻¹_hand · M − I", inverse, angles))
    else:
        out.append(_derived("M⁻¹", "inverse_mass_matrix", "M⁻¹_hand · M − I", "from M (solving with M)"))
    if "acceleration" in written:
        out.append(_acceleration(sm, lag))
    else:
        relation = "M q̈_hand + (C + D) q̇ + H − B u − W w"
        out.append(_derived("q̈", "acceleration", relation, "from M, C, H, D, B, W"))
    for method, form in model_cls.closed_forms.items():
        if form.equals and method != "coriolis_force":  # compared as C·q̇ above
            out.append(_extra(sm, lag, method, form))
    return SymbolicReport(label or model_cls.name, where(model_cls), out, time.perf_counter() - started)


def _width(text: str) -> int:
    """Printed width: combining marks (the dots of q̇, q̈) take no column."""
    return sum(not unicodedata.combining(ch) for ch in text)


def _pad(text: str, width: int) -> str:
    return text + " " * (width - _width(text))


def format_report(report: SymbolicReport) -> str:
    header = ("quantity", "method", "compared", "entries", "result")
    rows = [(c.quantity, c.method, c.relation, str(c.entries), c.status) for c in report.comparisons]
    widths = [max(_width(h), *(_width(r[i]) for r in rows)) for i, h in enumerate(header)]
    line = "  ".join(_pad(h, w) for h, w in zip(header, widths, strict=True)).rstrip()
    out = [f"sympy [{report.model}] ({report.source}): closed forms vs the Lagrangian of energies()", line]
    out.append("-" * _width(line))
    out += ["  ".join(_pad(c, w) for c, w in zip(r, widths, strict=True)).rstrip() for r in rows]
    for c in report.comparisons:
        for d in c.differences:
            out.append(f"  differs: {d}   (hand − derived, simplified)")
        if c.note:
            out.append(f"  {c.status if c.status != EQUAL else 'note'} [{c.quantity}]: {c.note}")
    verdict = (
        "every closed form equals its derivation"
        if report.passed
        else "closed forms DIFFER from the derivation"
    )
    out.append(f"{sum(c.entries for c in report.comparisons)} entries, {report.elapsed_s:.2f} s: {verdict}")
    return "\n".join(out)
