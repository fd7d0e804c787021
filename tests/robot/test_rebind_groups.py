"""Parameters that share a value in a URDF (m1 = m2): moved together by one rewrite, refused apart.

The URDF of two equal rods (``examples/corpus_double_pendulum.urdf``) holds 1.0 kg twice,
0.25 m twice, 1/48 kg·m² four times and 0.5 m once (l1; l2 draws only, with the same value).
"""

from __future__ import annotations

import pytest

from pendverify.analytic.plugin import load_model_class
from pendverify.errors import RebindError
from pendverify.robot.rebind import Binding
from pendverify.robot.xml_reading import parse_xml
from pendverify.shipped import shipped_file
from pendverify.targets import parameter_values


@pytest.fixture(scope="module")
def binding() -> Binding:
    cls = load_model_class(str(shipped_file("examples", "corpus_double_pendulum.toml")))
    params = parameter_values(cls, str(shipped_file("examples", "corpus_double_pendulum_params.toml")))
    text = shipped_file("examples", "corpus_double_pendulum.urdf").read_text(encoding="utf-8")
    return Binding.of(text, params)


def _masses(text: str) -> list[float]:
    return [float(e.get("value")) for e in parse_xml(text, "<rewritten>").findall("link/inertial/mass")]


def test_equal_values_form_groups_and_stay_unbound_alone(binding):
    assert set(binding.groups) == {("m1", "m2"), ("lc1", "lc2"), ("I1", "I2"), ("l1", "l2")}
    assert binding.group_of("m2") == ("m1", "m2") and binding.group_of("g") is None
    assert not binding.bound("m1")  # a sweep still cannot vary m1 alone
    assert binding.reasons["m1"] == "its value also belongs to m2 in the URDF"
    assert len(binding.groups[("I1", "I2")]) == 4  # ixx and iyy of both links


def test_a_group_is_rewritten_together(binding):
    moved = binding.params.replace(m1=1.3, m2=1.3)
    assert _masses(binding.rewrite(moved)) == [1.3, 1.3]


def test_a_group_given_two_values_is_refused_naming_both(binding):
    with pytest.raises(RebindError, match=r"parameter m1 cannot be changed in the URDF apart from m2: .*"):
        binding.rewrite(binding.params.replace(m1=1.3))
    with pytest.raises(RebindError, match="apart from m2"):
        binding.rewrite(binding.params.replace(m1=1.3, m2=1.2))


def test_a_parameter_found_nowhere_is_still_refused():
    cls = load_model_class(str(shipped_file("examples", "cart_pole.py")))
    params = parameter_values(cls, str(shipped_file("examples", "cart_pole.toml")))
    binding = Binding.of(shipped_file("examples", "cart_pole.urdf").read_text(encoding="utf-8"), params)
    assert binding.groups == {}
    said = r"parameter bx cannot be changed in the URDF: its value 0\.2 is not"
    with pytest.raises(RebindError, match=said):
        binding.rewrite(params.replace(bx=0.3))
