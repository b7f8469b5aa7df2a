"""The tasks, one module each, as the paper names them: sequence learning (:mod:`.sequence`),
one-dimensional navigation (:mod:`.nav1d`) and landmark recognition (:mod:`.landmark`)."""
