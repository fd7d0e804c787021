"""The integrators: one home for every method that advances ẋ = f(t, x).

Conventions.  A state is one 1-D float array x; for a mechanical model x = (q, q̇) (the
compiled implicit methods work on y = (q, p), p = M(q) q̇, and convert).  A right-hand
side is f(t, x) → ẋ, scipy's ``solve_ivp`` signature; an autonomous one ignores t.  A
step is ``x_new = explicit_rk_step(f, t, x, h, tableau, k1=None)``.

* ``tableaux``: the explicit Runge–Kutta methods as data (``EULER``, ``RK4``, by name in
  ``TABLEAUX``), with their stability functions.
* ``runge_kutta``: the one explicit stepper, ``explicit_rk_step``, which runs any tableau on
  numpy arrays (the scene driver ``pendverify.simulation.integrate`` and ``model_runs`` step
  with it).
* ``model_runs``: recorded runs of a closed-form model's own equations in Python (RK4 on the
  one stepper, scipy's RK45, backward Euler, Störmer–Verlet), for the stress suite.
* ``fixedstep``: the compiled fast path, numba templates copied into each model's generated
  module: the run of each tableau written from it (``render_explicit_runs``), and the two
  implicit symplectic methods; ``fixedstep_runner`` runs them.
* ``dop853``: scipy's adaptive DOP853 step for step, compiled the same way; ``dop853_runner``
  runs it on one state or an ensemble (the fast path; ``pendverify.simulation.compiled_scene``
  runs a scene on it).
* ``taylor``: the Taylor-series reference in high precision (``pendverify.numerics.reference``).

scipy's ``solve_ivp`` (RK45, DOP853, Radau, BDF, LSODA, RK23) is called by the scene driver
and by ``model_runs.rk45``; none of its methods is written here.

Internal (``__all__`` is empty): docs/reference/api.md lists what is public; the names imported
below are this package's interface to the rest of pendverify.
"""

from pendverify.numerics.integrators.runge_kutta import explicit_rk_step as explicit_rk_step
from pendverify.numerics.integrators.tableaux import EULER as EULER
from pendverify.numerics.integrators.tableaux import RK4 as RK4
from pendverify.numerics.integrators.tableaux import TABLEAUX as TABLEAUX
from pendverify.numerics.integrators.tableaux import Tableau as Tableau

__all__: list[str] = []
