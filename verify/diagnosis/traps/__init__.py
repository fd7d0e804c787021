"""The known traps behind a failing check, each a hypothesis tested against the model and the URDF.

``pendverify.diagnosis.diagnose`` runs them and reports the ones that fit; each module here
is one trap (``inertia``, ``damping``, ``conventions``), and ``fit`` holds the language
and thresholds they share.  The convention search has three helpers: the maps the traps
lead to (``convention_maps``), their vectorised screen (``convention_screen``) and their
sentences (``convention_words``).

Internal (``__all__`` is empty): docs/reference/api.md lists what is public.
"""

__all__: list[str] = []
