"""URDFs in Pinocchio: strict reading, the coordinate maps, the seed geometry readers, the writer."""
