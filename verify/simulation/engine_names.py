"""The names of pendverify's simulation engines, in a module that imports nothing: the command
line reads them for its ``--engine`` choices without loading NumPy, and the scene reader, the API
and the engine study (``pendverify.simulation.engines``) use the same tuples.

A right-hand side q̈(q, v, τ) is made by the closed form (``closed_form``), its generated compiled
code (``compiled``) or Pinocchio (``aba``; ``crba_cholesky``: CRBA then a Cholesky solve;
``minverse``: the inverse mass matrix).  A scene integrates ABA or the closed form, or ABA with
the closed form compared along the trajectory (``both``).
"""

#: the engines Pinocchio runs
PINOCCHIO_ENGINES = ("aba", "crba_cholesky", "minverse")
#: the engines ``pendverify.simulation.engines.build`` makes a right-hand side of
RHS_ENGINES = ("closed_form", "compiled", *PINOCCHIO_ENGINES)
#: what a scene's ``engine`` (and ``simulate --engine``, ``render --engine``) may be
SCENE_ENGINE_CHOICES = ("aba", "closed_form", "both")
