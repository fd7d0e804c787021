"""Data shipped with pendverify: the sweeps folder (read with importlib.resources)."""
