"""``python -m femadh``: the command line."""
import sys

try:
    from .cli import main
except KeyboardInterrupt:
    # a Ctrl-C while femadh.cli is being imported, before its own handler is in place
    # (femadh.cli._stop_at_once): one line, as at any other moment
    sys.stderr.write("femadh: error: interrupted by SIGINT while starting; nothing was "
                     "written\n")
    sys.exit(130)

sys.exit(main())
