"""Above the tasks: sweeps over seeds (:mod:`.sweep`) and the reproduction of the whole paper
(:mod:`.plan`, :mod:`.jobs`, :mod:`.scheduler`, :mod:`.runsview`, :mod:`.report`)."""
