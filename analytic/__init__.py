"""Closed-form (hand-derived) models, one module each, all with one interface."""

from pendverify.analytic.cart_double_pendulum import CartDoublePendulum, CartDoublePendulumParams
from pendverify.analytic.double_pendulum import DoublePendulum, DoublePendulumParams
from pendverify.analytic.interface import ClosedFormModel
from pendverify.analytic.parameter_set import ParameterSet

MODELS: dict[str, type[ClosedFormModel]] = {
    DoublePendulum.name: DoublePendulum,
    CartDoublePendulum.name: CartDoublePendulum,
}
PARAMETER_TYPES: dict[str, type[ParameterSet]] = {name: model.params_type for name, model in MODELS.items()}

__all__ = [
    "MODELS",
    "PARAMETER_TYPES",
    "CartDoublePendulum",
    "CartDoublePendulumParams",
    "ClosedFormModel",
    "DoublePendulum",
    "DoublePendulumParams",
    "ParameterSet",
]
