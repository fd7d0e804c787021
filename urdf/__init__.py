"""URDFs of the default parameter sets, written by ``pendverify.urdf_writer``."""
