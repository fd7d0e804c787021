"""Closed-form (hand-derived) models, one module each, all with one interface.

The public names are ``__all__``: the two reference systems and their parameters (``MODELS``
and ``PARAMETER_TYPES`` by name), and what a model class builds on (``ClosedFormModel``,
``BiasOnlyModel``, ``ParameterSet``, ``quantity``, ``Energies``, ``ClosedForm``,
``STANDARD_CLOSED_FORMS``, ``InterfaceMethod``).  The modules of this package are internal:
import from here or from ``pendverify`` (docs/reference/api.md).
"""

from pendverify.analytic.cart_double_pendulum import CartDoublePendulum, CartDoublePendulumParams
from pendverify.analytic.double_pendulum import DoublePendulum, DoublePendulumParams
from pendverify.analytic.forms import STANDARD_CLOSED_FORMS, ClosedForm, Energies, InterfaceMethod
from pendverify.analytic.interface import BiasOnlyModel, ClosedFormModel
from pendverify.analytic.parameter_set import ParameterSet, quantity

MODELS: dict[str, type[ClosedFormModel]] = {
    DoublePendulum.name: DoublePendulum,
    CartDoublePendulum.name: CartDoublePendulum,
}
PARAMETER_TYPES: dict[str, type[ParameterSet]] = {name: model.params_type for name, model in MODELS.items()}

__all__ = [
    "MODELS",
    "PARAMETER_TYPES",
    "STANDARD_CLOSED_FORMS",
    "BiasOnlyModel",
    "CartDoublePendulum",
    "CartDoublePendulumParams",
    "ClosedForm",
    "ClosedFormModel",
    "DoublePendulum",
    "DoublePendulumParams",
    "Energies",
    "InterfaceMethod",
    "ParameterSet",
    "quantity",
]
