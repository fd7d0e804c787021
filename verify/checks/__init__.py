"""The checks: states, tolerances, the trust rule, verdicts, diagnoses and the report."""
