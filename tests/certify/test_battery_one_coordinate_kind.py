"""The battery's stress items on a model with no angular coordinate (the one-joint cart).

``certify`` crashed (exit 3) on the cart: the large-angle case took max() over its angular
coordinates, of which it has none.  Such a model has no angle to shift: the item is left out,
and the items it does get still fail a wrong model.
"""

from __future__ import annotations

from pendverify.analytic.plugin import load_model_class
from pendverify.api import load_params
from pendverify.certify.battery import BatterySettings, stress_items
from pendverify.stress.cases import large_angle_case
from pendverify.stress.catalogue import run_case
from pendverify.stress.framework import QUICK, Context

from ..robot.one_joint import write_one_joint

SETTINGS = BatterySettings(samples=20)


def _items(tmp_path, robot: str, planted: bool = False):
    r = write_one_joint(robot, tmp_path, planted)
    cls = load_model_class(r.model)
    return stress_items(cls, load_params(cls, r.params), SETTINGS, str(r.robot))


def test_a_model_without_angles_gets_no_large_angle_item_and_passes(tmp_path):
    items = _items(tmp_path, "cart")
    names = {i.name for i in items}
    assert names == {"stress:high-speeds", "stress:zero-gravity", "stress:conditioning"}
    assert all(i.passed for i in items), [(i.name, i.detail) for i in items]


def test_a_wrong_cart_still_fails_its_stress_items(tmp_path):
    """M 1 % too heavy: every item that compares M with Pinocchio fails."""
    items = _items(tmp_path, "cart", planted=True)
    assert not any(i.passed for i in items if i.name != "stress:conditioning"), [i.name for i in items]


def test_a_model_with_an_angle_keeps_its_large_angle_item(tmp_path):
    names = {i.name for i in _items(tmp_path, "pendulum")}
    assert "stress:large-angles" in names


def test_the_large_angle_case_says_it_is_not_run_without_an_angle(tmp_path):
    r = write_one_joint("cart", tmp_path)
    cls = load_model_class(r.model)
    params = load_params(cls, r.params)
    ctx = Context(QUICK, urdf=str(r.robot), model_cls=cls)
    result = run_case(large_angle_case("large angles", lambda: params, cls), ctx)
    assert result.notes == ["not run: no angle to shift"] and result.error is None
    assert result.status == "not run"
