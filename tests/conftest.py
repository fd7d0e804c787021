"""Shared fixtures: default models, their Pinocchio systems, seeded states; the run's code cache.

The generated-code cache (``PENDVERIFY_CACHE``) of a test run is one empty folder
under pytest's base temporary folder, shared by the run's xdist workers
(``pytest-N/pendverify-cache``), so that the suite neither reads nor writes the
user's ``~/.cache/pendverify`` and each model is generated and compiled about once
per run, whichever worker gets there first (the cache's files are written
atomically).  A ``PENDVERIFY_CACHE`` set in the environment is used instead (a warm
cache for repeated runs).  Tests that need an empty cache of their own make one.
"""

from __future__ import annotations

import importlib
import importlib.util
import os
import sys
from pathlib import Path

import numpy as np
import pytest

from pendverify.analytic import MODELS
from pendverify.analytic.params import default_parameter_file, load_parameter_file
from pendverify.checks.sampling import sample_states
from pendverify.robot.system import PinocchioSystem

SEED = 1234
MODEL_NAMES = tuple(MODELS)


def _run_folder(tmp_path_factory) -> Path:
    """pytest's base temporary folder of this run: each xdist worker's own is one level below."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


@pytest.fixture(scope="session", autouse=True)
def _generated_code_cache(tmp_path_factory):
    """``PENDVERIFY_CACHE`` for the whole run (module docstring), also for the subprocesses tests start."""
    if os.environ.get("PENDVERIFY_CACHE"):
        yield Path(os.environ["PENDVERIFY_CACHE"])
        return
    folder = _run_folder(tmp_path_factory) / "pendverify-cache"
    folder.mkdir(exist_ok=True)
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("PENDVERIFY_CACHE", str(folder))
        yield folder


@pytest.fixture
def fresh_cache(tmp_path, monkeypatch):
    """An empty generated-code cache of this test's own (its ``generated`` folder), forgotten in
    this process before and after."""
    from pendverify.numerics.codegen import cache as code_cache

    monkeypatch.setenv("PENDVERIFY_CACHE", str(tmp_path / "cache"))
    code_cache.forget()
    yield tmp_path / "cache" / "generated"
    code_cache.forget()


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


def example_module(stem: str):
    """The module of the shipped example ``examples/<stem>.py``, imported under a private name."""
    name = f"_pendverify_example_{stem}"
    path = Path(__file__).resolve().parents[1] / "examples" / f"{stem}.py"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up while the file runs
    try:
        spec.loader.exec_module(module)
    finally:
        del sys.modules[name]
    return module
