"""Shared fixtures: default models, their Pinocchio systems, seeded states."""

from __future__ import annotations

import numpy as np
import pytest

from pendverify.analytic import MODELS
from pendverify.analytic.params import default_parameter_file, load_parameter_file
from pendverify.checks.sampling import sample_states
from pendverify.robot.system import PinocchioSystem

SEED = 1234
MODEL_NAMES = tuple(MODELS)


def default_params(name: str):
    return load_parameter_file(default_parameter_file(name))[2]


def system_for(params) -> PinocchioSystem:
    return PinocchioSystem.for_params(params)


@pytest.fixture(params=MODEL_NAMES)
def model_name(request) -> str:
    return request.param


@pytest.fixture
def setup(model_name):
    """(closed-form model, Pinocchio system, states) for a default parameter set."""
    params = default_params(model_name)
    model = MODELS[model_name](params)
    return model, system_for(params), sample_states(model, 60, SEED)


def assert_close(actual, expected, rtol, context=""):
    """Fail on NaN as well as on a difference beyond rtol·max(1, |expected|)."""
    actual, expected = np.asarray(actual, float), np.asarray(expected, float)
    assert np.all(np.isfinite(actual)), f"non-finite result {context}"
    err = np.max(np.abs(actual - expected) / np.maximum(1.0, np.abs(expected)))
    assert err <= rtol, f"error {err:.3g} > {rtol:.3g} {context}"
