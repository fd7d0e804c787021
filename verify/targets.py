"""What to verify: pairs of a closed-form model and a URDF loaded in Pinocchio.

* the default parameter sets against their committed URDFs (``urdf/``);
* example-robot-data's double-pendulum URDFs against the seed-000 closed form
  with parameters read off the URDF itself;
* a user's URDF against a user's parameter set, or (double pendulum) against
  the parameters read off that URDF.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from importlib.resources import files
from pathlib import Path

from pendverify.analytic import MODELS, ClosedFormModel, ParameterSet
from pendverify.analytic.params import default_parameter_file, load_parameter_file
from pendverify.erd import double_pendulum_urdfs
from pendverify.errors import PendverifyError, UnknownNameError
from pendverify.robot import PinocchioSystem, load_model
from pendverify.urdf_writer import urdf_for

PARAMETER_MATCH_RTOL = 1e-9


@dataclass
class Target:
    label: str
    model: ClosedFormModel
    system: PinocchioSystem
    source: str
    notes: list[str] = field(default_factory=list)


def committed_urdf(model: str) -> Path:
    return Path(str(files("pendverify.urdf") / f"{model}.urdf"))


def _model_class(name: str):
    if name not in MODELS:
        raise UnknownNameError("model", name, tuple(MODELS))
    return MODELS[name]


def default_target(model_name: str) -> Target:
    _, _, params = load_parameter_file(default_parameter_file(model_name))
    path = committed_urdf(model_name)
    system = PinocchioSystem.from_urdf(model_name, path, params.g)
    return Target(model_name, _model_class(model_name)(params), system, str(path))


def erd_targets() -> list[Target]:
    targets = []
    for stem, path in double_pendulum_urdfs().items():
        system = PinocchioSystem.from_urdf("double_pendulum", path)
        model = _model_class("double_pendulum")(system.geometry.params)
        targets.append(Target(f"erd:{stem}", model, system, str(path), list(system.geometry.notes)))
    return targets


def parameter_differences(urdf_params: ParameterSet, given: ParameterSet) -> list[str]:
    """Name each parameter where the URDF and the parameter set disagree."""
    notes = []
    for key, value in given.as_dict().items():
        read = getattr(urdf_params, key)
        if key == "l2":  # drawing length only: not in the dynamics
            continue
        if abs(read - value) > PARAMETER_MATCH_RTOL * max(abs(read), abs(value)):
            rel = (read - value) / value if value else float("inf")
            notes.append(f"the URDF gives {key} = {read:.6g}, the parameter set {value:.6g} ({rel:+.3%})")
    return notes


def user_target(model_name: str | None, urdf: str | None, params_file: str | None) -> Target:
    """A target from the CLI's --model / --urdf / --params."""
    params = None
    if params_file:
        file_model, _, params = load_parameter_file(params_file)
        if model_name and model_name != file_model:
            raise PendverifyError(f"{params_file}: model is {file_model!r}, but --model says {model_name!r}")
        model_name = file_model
    if model_name is None:
        raise PendverifyError("name the model with --model, or give --params")
    cls = _model_class(model_name)
    if urdf is None:
        # the URDF of this parameter set, as the project writes it
        system = PinocchioSystem.from_urdf(model_name, urdf_for(params), params.g, f"<URDF of {params_file}>")
        return Target(f"{model_name}:{Path(params_file).stem}", cls(params), system, system.source)
    pin_model, source = load_model(urdf)
    del pin_model  # parsed once here for a clear early error
    g = params.g if params is not None else None
    system = PinocchioSystem.from_urdf(model_name, urdf, g, source)
    notes = list(system.geometry.notes)
    if params is None:
        if system.geometry.params is None:
            raise PendverifyError(
                f"{urdf}: give --params: a {model_name} URDF alone does not fix the closed form"
            )
        params = system.geometry.params
        notes.append("parameters read off the URDF")
    elif system.geometry.params is not None:
        notes += parameter_differences(system.geometry.params, params)
    return Target(f"{model_name}:{Path(urdf).stem}", cls(params), system, source, notes)
