"""URDFs of the default parameter sets, written by ``pendverify.robot.writer``."""
