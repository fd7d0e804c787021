"""Parameter sets: the defaults load, and every invalid set is rejected by name."""

from __future__ import annotations

import math

import pytest

from pendverify.analytic import CartDoublePendulumParams, DoublePendulumParams
from pendverify.analytic.params import default_parameter_file, load_parameter_file
from pendverify.errors import ParameterError, UserFileError

from ..conftest import default_params


def test_defaults_load(model_name):
    model, name, params = load_parameter_file(default_parameter_file(model_name))
    assert model == model_name == params.model
    assert name == model_name


def test_round_trip_through_toml(tmp_path, model_name):
    params = default_params(model_name)
    path = tmp_path / "p.toml"
    path.write_text(params.to_toml("copy"))
    assert load_parameter_file(path) == (model_name, "copy", params)


def _write(tmp_path, model, table: dict) -> str:
    body = "\n".join(f"{k} = {v}" for k, v in table.items())
    path = tmp_path / "bad.toml"
    path.write_text(f'model = "{model}"\n[parameters]\n{body}\n')
    return str(path)


def _dp_table(**changes):
    table = default_params("double_pendulum").as_dict()
    table.update(changes)
    return {k: v for k, v in table.items() if v is not None}


@pytest.mark.parametrize(
    ("changes", "key", "value", "rule"),
    [
        ({"m1": -1.0}, "m1", -1.0, "a mass must be a finite number > 0 (in kg)"),
        ({"m2": 0.0}, "m2", 0.0, "a mass must be a finite number > 0 (in kg)"),
        ({"l1": 0.0}, "l1", 0.0, "a length must be a finite number > 0 (in m)"),
        ({"r1": -0.1}, "r1", -0.1, "an offset must be a finite number >= 0 (in m)"),
        ({"I2": -1e-3}, "I2", -0.001, "an inertia must be a finite number >= 0 (in kg·m²)"),
        ({"b1": -0.5}, "b1", -0.5, "a damping must be a finite number >= 0"),
        ({"g": "nan"}, "g", math.nan, "a gravity must be a finite number >= 0"),
        ({"m1": "inf"}, "m1", math.inf, "a mass must be a finite number > 0"),
        ({"I1": '"heavy"'}, "I1", "heavy", "an inertia must be a finite number >= 0 (in kg·m²); got a str"),
        ({"m1": "true"}, "m1", True, "got a bool"),
    ],
)
def test_invalid_values_are_named(tmp_path, changes, key, value, rule):
    path = _write(tmp_path, "double_pendulum", _dp_table(**changes))
    with pytest.raises(ParameterError) as info:
        load_parameter_file(path)
    err = info.value
    assert (err.source, err.key) == (path, f"parameters.{key}")
    assert err.value == value or (math.isnan(value) and math.isnan(err.value))
    assert rule in str(err)
    assert str(err).startswith(f"{path}: key 'parameters.{key}' = ")


def test_unknown_and_missing_keys(tmp_path):
    path = _write(tmp_path, "double_pendulum", _dp_table(mass3=1.0))
    with pytest.raises(
        ParameterError, match=r"key 'parameters.mass3' = 1.0: unknown key; the double_pendulum"
    ):
        load_parameter_file(path)
    path = _write(tmp_path, "double_pendulum", _dp_table(r2=None))
    with pytest.raises(ParameterError, match=r"key 'parameters.r2' = None: missing key \(distance joint 2"):
        load_parameter_file(path)


def test_unknown_model_and_top_level_key(tmp_path):
    path = tmp_path / "m.toml"
    path.write_text('model = "triple_pendulum"\n[parameters]\n')
    with pytest.raises(
        ParameterError, match="key 'model' = 'triple_pendulum': must be one of double_pendulum"
    ):
        load_parameter_file(path)
    path.write_text('model = "double_pendulum"\ncolour = "red"\n[parameters]\n')
    with pytest.raises(ParameterError, match="key 'colour' = 'red': unknown key"):
        load_parameter_file(path)


def test_a_model_that_is_not_a_name_is_refused_not_a_crash(tmp_path):
    path = tmp_path / "m.toml"
    path.write_text('model = ["double_pendulum"]\n[parameters]\n')  # unhashable: a registry lookup raised
    with pytest.raises(
        ParameterError, match=r"key 'model' = \['double_pendulum'\]: must be one of double_pendulum"
    ):
        load_parameter_file(path)


def test_bad_toml_and_missing_file(tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text("model = \n")
    with pytest.raises(ParameterError, match=r"broken.toml: key '<file>'.*not valid TOML"):
        load_parameter_file(path)
    with pytest.raises(UserFileError, match=r"parameter file not found: .*absent\.toml; check the path"):
        load_parameter_file(tmp_path / "absent.toml")


def test_singular_double_pendulum_is_rejected(tmp_path):
    path = _write(tmp_path, "double_pendulum", _dp_table(I2=0.0, r2=0.0))
    with pytest.raises(ParameterError, match=r"key 'parameters.I2' = 0.0: M\(θ\) is singular"):
        load_parameter_file(path)


def test_point_masses_are_valid():
    DoublePendulumParams(**{**_dp_table(), "I1": 0.0, "I2": 0.0})
    CartDoublePendulumParams(**default_params("cart_double_pendulum").as_dict())


def test_sets_are_frozen():
    params = default_params("double_pendulum")
    with pytest.raises(AttributeError):
        params.m1 = 2.0
