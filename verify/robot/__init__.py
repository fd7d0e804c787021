"""URDFs in Pinocchio: strict reading, coordinate maps, the reference systems' geometry, the writer."""
