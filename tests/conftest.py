"""Settings every test module shares.

A process started in the background by a shell (``cmd &``, ``nohup``) inherits SIGINT ignored,
and so does everything it starts: Python then installs no KeyboardInterrupt handler, and the
tests that press Ctrl-C, in this process or in a ``dnnevo`` subprocess, would wait out the whole
run and fail. Python's own handler is put back here; a subprocess then starts with SIGINT at its
default, as from a terminal.
"""

import signal

if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)
