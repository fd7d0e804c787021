"""The certification battery, certificates and sweeps."""
