"""A verified model written out as code, and that code verified as a model (``pendverify export``).

* ``closed_forms``: the quantities a model writes (M, C·q̇, G, D, B, W), read by SymPy;
* ``writers``: each language's files: C99 (a header and a source), MATLAB/Octave functions with
  their declaration, a NumPy module;
* ``verification``: the written code read back as a model (the C compiled and called through
  ``ctypes``, the ``.m`` files through the MATLAB reader, the NumPy module as NumPy functions)
  and checked against the robot as any model is.

Internal (``__all__`` is empty): docs/reference/api.md lists what is public (``pendverify.api.export``).
"""

__all__: list[str] = []
