"""Evolution: the paper's genetic algorithm by ask and tell (:mod:`.ga`), the generation loop with
its run folder and resume (:mod:`.evolve`), seeding a first population from earlier runs
(:mod:`.seeding`) and the progress bar (:mod:`.progress`)."""
