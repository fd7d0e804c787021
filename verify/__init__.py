"""pendverify: checks hand-derived pendulum dynamics against their URDF in Pinocchio.

The Python API (``pendverify.api``, ``pendverify.testing``)::

    import pendverify

    report = pendverify.check("double_pendulum")     # a CheckReport; print(report) gives the CLI's table
    report["crba"]                                   # one check's rows (CheckRows), one per model
    run = pendverify.simulate("scenes/damped_double_pendulum.toml")   # a Run

A model file imports what it builds on from here::

    from pendverify import ClosedFormModel, ParameterSet, quantity   # BiasOnlyModel, Energies too

The names below are imported on first use, so ``import pendverify`` stays cheap: it imports
neither Pinocchio nor SymPy.  ``dir(pendverify)`` lists exactly them (``__all__``), the names
docs/python-api.md documents; the functions behind the other commands are in ``pendverify.api``.
"""

import importlib as _importlib
import typing as _typing

#: public name -> the module that defines it, imported when the name is first used
_LAZY = {
    "check": "pendverify.api",
    "implied_parameters": "pendverify.api",
    "load_model": "pendverify.api",
    "load_params": "pendverify.api",
    "load_urdf": "pendverify.api",
    "simulate": "pendverify.api",
    "certify_set": "pendverify.api",
    "ros_packages": "pendverify.api",
    "CheckReport": "pendverify.checks.report",
    "CheckRows": "pendverify.checks.report",
    "Run": "pendverify.simulation.simulate",
    "assert_verified": "pendverify.testing",
    "PendverifyError": "pendverify.errors",
    # what a model file builds on (docs/models.md)
    "ClosedFormModel": "pendverify.analytic.interface",
    "BiasOnlyModel": "pendverify.analytic.interface",
    "ParameterSet": "pendverify.analytic.parameter_set",
    "quantity": "pendverify.analytic.parameter_set",
    "Energies": "pendverify.analytic.forms",
}

__all__ = [
    "BiasOnlyModel",
    "CheckReport",
    "CheckRows",
    "ClosedFormModel",
    "Energies",
    "ParameterSet",
    "PendverifyError",
    "Run",
    "__version__",
    "assert_verified",
    "certify_set",
    "check",
    "implied_parameters",
    "load_model",
    "load_params",
    "load_urdf",
    "quantity",
    "ros_packages",
    "simulate",
]

if _typing.TYPE_CHECKING:  # pragma: no cover - for type checkers and IDEs only
    from pendverify.analytic.forms import Energies
    from pendverify.analytic.interface import BiasOnlyModel, ClosedFormModel
    from pendverify.analytic.parameter_set import ParameterSet, quantity
    from pendverify.api import (
        certify_set,
        check,
        implied_parameters,
        load_model,
        load_params,
        load_urdf,
        ros_packages,
        simulate,
    )
    from pendverify.checks.report import CheckReport, CheckRows
    from pendverify.errors import PendverifyError
    from pendverify.simulation.simulate import Run
    from pendverify.testing import assert_verified


def __getattr__(name: str):
    if name == "__version__":  # the installed distribution's (pyproject.toml), read on first use
        from importlib.metadata import version

        value = globals()[name] = version("pendverify")
        return value
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'pendverify' has no attribute {name!r}")
    value = getattr(_importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    """The public names only (``__all__``): not the submodules imported since, nor this module's own
    helpers."""
    return sorted(__all__)
