"""What a model file imports: ``from pendverify import ClosedFormModel, ParameterSet, quantity``.

The top-level names are the classes and functions themselves (imported on first use); the old
home of the parameter set, ``pendverify.analytic.params``, still gives ``ParameterSet``,
``quantity`` and ``check_value`` with a ``DeprecationWarning`` naming the new one, and a model file
written against it loads and passes.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import pendverify
from pendverify.analytic import forms, interface, parameter_set
from pendverify.analytic.plugin import load_model_class
from tests.analytic.test_optional_potential import PARAMS, PENDULUM

REPO = Path(__file__).resolve().parents[2]
URDF = REPO / "tests" / "analytic" / "data" / "pendulum_functions.urdf"
MODEL_NAMES = ("ClosedFormModel", "BiasOnlyModel", "ParameterSet", "quantity", "Energies")


def test_a_model_files_names_are_the_analytic_ones():
    from pendverify import BiasOnlyModel, ClosedFormModel, Energies, ParameterSet, quantity

    assert ClosedFormModel is interface.ClosedFormModel and BiasOnlyModel is interface.BiasOnlyModel
    assert ParameterSet is parameter_set.ParameterSet and quantity is parameter_set.quantity
    assert Energies is forms.Energies
    assert set(MODEL_NAMES) <= set(pendverify.__all__) and set(MODEL_NAMES) <= set(dir(pendverify))


def test_they_are_imported_on_first_use_without_sympy_or_pinocchio():
    script = textwrap.dedent(
        """
        import sys
        import pendverify
        assert "pendverify.analytic" not in sys.modules
        from pendverify import ClosedFormModel, ParameterSet, quantity, BiasOnlyModel, Energies
        heavy = {"pinocchio", "sympy", "scipy"} & set(sys.modules)
        assert not heavy, heavy
        print("ok")
        """
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr


@pytest.mark.parametrize("name", ["ParameterSet", "quantity", "check_value"])
def test_the_old_path_warns_naming_the_new_one_and_works(name):
    with pytest.warns(DeprecationWarning, match=rf"moved to pendverify\.analytic\.parameter_set\.{name}"):
        from pendverify.analytic import params

        value = getattr(params, name)
    assert value is getattr(parameter_set, name)


def test_an_unknown_name_of_the_old_module_is_an_attribute_error():
    from pendverify.analytic import params

    with pytest.raises(AttributeError, match="no attribute 'ParameterSets'"):
        _ = params.ParameterSets


def test_a_model_file_written_against_the_old_path_loads_and_passes(tmp_path):
    old = "from pendverify.analytic import ClosedFormModel\nfrom pendverify.analytic.forms import Energies\n"
    old += "from pendverify.analytic.params import ParameterSet, quantity\n"
    text = PENDULUM.replace("from pendverify import ClosedFormModel, Energies, ParameterSet, quantity\n", old)
    assert "analytic.params import ParameterSet" in text
    model, params = tmp_path / "old_pendulum.py", tmp_path / "pendulum.toml"
    model.write_text(text)
    params.write_text(PARAMS)
    with pytest.warns(DeprecationWarning) as caught:
        cls = load_model_class(model)
    said = sorted(str(w.message).split("; ")[1] for w in caught)
    assert said == [
        "import it as `from pendverify import ParameterSet`",
        "import it as `from pendverify import quantity`",
    ]
    assert issubclass(cls.params_type, parameter_set.ParameterSet)
    report = pendverify.check(cls, URDF, params, samples=30)
    assert report.status == "pass", report
