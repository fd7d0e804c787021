"""Keys a text model derives from another it writes: never repaired themselves, re-derived instead.

A text or LaTeX model that gives V and not H gets H = ∂V/∂q; one that gives H and not V gets V
integrated from H (``pendverify.analytic.text_model``).  An error in the written key shows in
the derived one too, but the user never wrote the derived key: a repair names the written key
only, and is confirmed with the derived key derived again from the repaired one, as the model
file would derive it (``with_derived``).  ``derived_methods`` says which interface methods are
derived, and from which.
"""

from __future__ import annotations

import sympy as sp

from pendverify.analytic.symbolic_reading import entries

#: how a text model derives a key from another (``spec.derived``'s words): the derived method, the
#: method it comes from and the key's words
_DERIVED = {
    ("H", "∂V/∂q"): ("gravity", "potential_energy"),
    ("V", "integrated from H"): ("potential_energy", "gravity"),
}


def derived_methods(model_cls) -> dict[str, str]:
    """{derived method: the method it is derived from} of a text model; {} for any other model."""
    spec = getattr(model_cls, "text_spec", None)
    if spec is None:
        return {}
    return dict(pair for (key, how), pair in _DERIVED.items() if spec.derived.get(key) == how)


def _potential(H, q):
    """V with ∂V/∂q = H, integrated one coordinate at a time (as the text model integrates it)."""
    V = sp.S.Zero
    for i, x in enumerate(q):
        V += sp.integrate(sp.expand(H[i] - sp.diff(V, x)), x)
    return V


def with_derived(changes: dict, sm, derived: dict[str, str]) -> dict:
    """``changes`` with the entries of each derived method derived again from its changed source."""
    out = dict(changes)
    q = sm.flat_arguments("q")
    for method, source in derived.items():
        edited = {i: new for (m, i), (_, new) in changes.items() if m == source}
        if not edited or method not in sm.closed_forms:
            continue
        values = [edited.get(i, e) for i, e in enumerate(entries(sm.closed_forms[source]))]
        new = [sp.diff(values[0], x) for x in q] if method == "gravity" else [_potential(values, q)]
        for i, (old, value) in enumerate(zip(entries(sm.closed_forms[method]), new, strict=True)):
            if value != old:
                out[(method, i)] = (old, value)
    return out
