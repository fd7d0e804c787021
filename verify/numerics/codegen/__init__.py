"""Code generated from a ``ClosedFormModel``: every numeric back end's model-specific code.

``pendverify.numerics.generate`` is the entry point (its docstring describes what is
generated and the packed layout).  The pieces:

* ``expressions``: the model's M(q), bias C(q, q̇)·q̇ + H(q) and V(q), read by SymPy;
* ``printers``: SymPy printers for numba (floats) and for generic numbers (``N``);
* ``ldlt``: the unrolled root-free Cholesky solve both renderers share;
* ``templates``: functions written once in dop853 / fixedstep and copied into
  each generated module, so that they call that model's right-hand side directly (inlined
  where short);
* ``compiled``: the numba functions ``_rhs``, ``_hamilton``, ``_to_momentum``;
* ``generic``: the plain-Python ``field``, ``energy`` and ``potential`` (Taylor, mpmath);
* ``cache``: the on-disk cache of generated modules, keyed by the model's source;
* ``folder``: the cache's folder, private to its user (else a temporary one);
* ``signed``: the cache's index and module records, signed with the user's cache key;
* ``numba_files``: numba's cache files of a module, recorded by digest and pruned before import.

Internal (``__all__`` is empty): docs/reference/api.md lists what is public.
"""

__all__: list[str] = []
