"""The integrators: one home for every method that advances ẋ = f(t, x).

* ``dop853``: scipy's DOP853 step for step, as numba templates copied into each model's
  generated module (``pendverify.numerics.fastpath`` runs the copy).
* ``fixedstep``: the compiled fixed-step methods, templates as well; ``fixedstep_runner`` runs them.
* ``taylor``: the Taylor-series reference in high precision (``pendverify.numerics.reference``).
"""
