"""A sweep's limits and their defaults, in a module that imports nothing: the command line
reads them for its options' defaults and help without loading NumPy, and the sweep
(``pendverify.certify.sweep``, ``pendverify.certify.sweep_run``) applies them."""

DEFAULT_MAX_SETS = 100_000  # sets a sweep may have (--max-sets raises it)
WORKER_TIMEOUT_S = 60.0  # s a Dask cluster may have no worker before the sweep stops (--worker-timeout)
