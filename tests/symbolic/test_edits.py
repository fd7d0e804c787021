"""The words of an edit (``pendverify.symbolic.edits``): the same text as before they were put off,
and not printed until read (a repair search screens thousands of edits and shows a few)."""

from __future__ import annotations

import sympy as sp

from pendverify.symbolic import edits
from pendverify.symbolic.edits import phrase, structural_edits, term_edits

t1, t2, w1, w2, m1, m2 = sp.symbols("theta1 theta2 dtheta1 dtheta2 m1 m2")
ENTRY = m1 * sp.cos(t1 - t2) * w1**2 + m2 * sp.sin(t2)


def test_the_words_read_as_the_edit_written_out():
    said = {}
    for e in term_edits(ENTRY, (w1, w2), factors=(("scale", 2, "2"),)):
        said.setdefault(e.operator, e.what)  # the top-level sum's first term first
    term = m2 * sp.sin(t2)
    assert said["sign"] == f"{term} → {-term}"
    assert said["scale"] == f"{term} → 2·{term}"
    assert said["swap θ̇"] == f"{w1} ↔ {w2} in {m1 * sp.cos(t1 - t2) * w1**2}"
    pair = edits.Edit("pair", ENTRY, ENTRY, ENTRY, phrase("{}, then {}", phrase("{} → {}", t1, t2), "drop x"))
    assert pair.what == "theta1 → theta2, then drop x"


def test_enumerating_edits_prints_no_expression(monkeypatch):
    """Symbols are printed (SymPy sorts them by name), a term or a sum only when words are read."""
    printed = []
    original = sp.Basic.__str__

    def counting(self):
        if not self.is_Atom:
            printed.append(self)
        return original(self)

    monkeypatch.setattr(sp.Basic, "__str__", counting)
    enumerated = list(structural_edits(ENTRY, (t1, t2), (w1, w2), {m1: "mass", m2: "mass"}))
    enumerated += list(term_edits(ENTRY, (w1, w2)))
    assert len(enumerated) > 10 and not printed
    assert enumerated[0].what and printed  # read: printed then
