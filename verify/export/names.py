"""The names of exported files: from the model's name, so a bundle knows them before they exist."""

from __future__ import annotations

import re

#: the model methods exported, one file each in MATLAB (``NAME_<method>.m``): those of
#: ``closed_forms.QUANTITIES`` (a test compares them; this module imports neither SymPy nor NumPy)
METHODS = (
    "mass_matrix",
    "coriolis_force",
    "gravity",
    "damping_matrix",
    "input_matrix",
    "disturbance_matrix",
    "det_mass_matrix",
    "acceleration",
)


def c_name(name: str) -> str:
    """A C identifier of the model's name (its functions' and files' prefix)."""
    ident = re.sub(r"\W", "_", name.lower()).strip("_") or "model"
    return ident if not ident[0].isdigit() else f"m_{ident}"


def export_file_names(model_name: str) -> frozenset[str]:
    """Every file ``export`` may write for model ``model_name``, in any language."""
    prefix = c_name(model_name)
    matlab = {f"{prefix}_{method}.m" for method in METHODS}
    code = {f"{prefix}{suffix}" for suffix in (".h", ".c", "_numpy.py", "_casadi.py", "_matlab.toml")}
    return frozenset({*code, *matlab})
