"""SymPy's view of a model: Lagrange's equations, the exact comparison, mutation testing."""
