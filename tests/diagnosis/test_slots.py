"""The entries a repair search screens: the model's own values (its generated code, as the checks
evaluate it) find the same disagreeing entries, with the same values to rounding, as each entry's
lambdified SymPy form, which took minutes on a 20-link chain (110 s of the diagnosis's 123 s)."""

from __future__ import annotations

import numpy as np

from pendverify.analytic.plugin import load_model_class, plugin_parameters
from pendverify.analytic.symbolic_reading import SymbolicModel
from pendverify.checks.batch import CheckBatch
from pendverify.checks.sampling import sample_states
from pendverify.diagnosis import slots
from pendverify.robot.system import PinocchioSystem

from .planar_chain import write_chain

EPS = float(np.finfo(float).eps)


def _slots(tmp_path):
    # a 3-link chain whose mass_matrix (written as such: the checks generate its code) has M[2,2] wrong
    model_file, urdf, params_file = write_chain(tmp_path, 3, (1, 1, 1.5))
    cls = load_model_class(model_file)
    model = cls(plugin_parameters(cls, model_file, params_file))
    batch = CheckBatch(model, PinocchioSystem.for_model(cls, urdf), sample_states(model, 20, 7))
    assert "mass_matrix" in batch.forms.written
    return slots.find_slots(batch, SymbolicModel.of(cls))


def test_the_models_own_values_find_the_entries_each_lambdified_entry_finds(tmp_path, monkeypatch):
    own = _slots(tmp_path / "own")
    assert [(s.method, s.label) for s in own] == [("mass_matrix", "M[2,2]")]
    # each entry lambdified: the same entries, the same values to rounding
    monkeypatch.setattr(slots, "_entry_values", _lambdified)
    each = _slots(tmp_path / "each")
    assert [(s.method, s.label) for s in each] == [("mass_matrix", "M[2,2]")]
    for a, b in zip(own, each, strict=True):
        # one expression in two operation orders: each a sum of a few dozen products, each at most the
        # quantity's size (the slot's scale), so they differ by a few dozen ε·scale at most
        assert np.allclose(a.values, b.values, rtol=0, atol=64 * EPS * a.scale)
        assert np.array_equal(a.target, b.target)


def _lambdified(batch, evaluate, method, form, flat):
    return np.stack([evaluate(e, form.args) for e in flat], axis=-1) if flat else None
