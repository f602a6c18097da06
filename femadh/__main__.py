"""``python -m femadh``: the command line."""
import os
import signal
import sys


def _sigterm_while_importing(signum, frame):
    """SIGTERM while femadh.cli is being imported, before its own handler is in place
    (femadh.cli._stop_at_once): one line and exit 143, as at any other moment of the start
    (the default action was a silent death, exit -15)."""
    try:
        os.write(2, b"femadh: error: interrupted by SIGTERM while starting; nothing was "
                    b"written\n")
    except OSError:
        pass
    os._exit(128 + signum)


# (only where SIGTERM has its default action: a parent that ignores it keeps it ignored)
_ours = signal.getsignal(signal.SIGTERM) is signal.SIG_DFL
if _ours:
    signal.signal(signal.SIGTERM, _sigterm_while_importing)
try:
    from . import cli
except KeyboardInterrupt:
    # a Ctrl-C while femadh.cli is being imported, before its own handler is in place
    # (femadh.cli._stop_at_once): one line, as at any other moment
    sys.stderr.write("femadh: error: interrupted by SIGINT while starting; nothing was "
                     "written\n")
    sys.exit(130)
if _ours and signal.getsignal(signal.SIGTERM) is _sigterm_while_importing:
    # femadh.cli saw a handler in place and left SIGTERM alone: its own handler from here
    # on, as the femadh script has it (main swaps it for its guard's)
    signal.signal(signal.SIGTERM, cli._stop_at_once)

sys.exit(cli.main())
