"""Progress bars for long work (tqdm), on stderr, and only where a person watches: callers
pass ``enabled`` (default: stderr is a terminal), so pipes, logs and tests stay quiet."""
import sys


def bar(total, desc, enabled=True, unit="state"):
    """A tqdm bar of ``total`` steps (of ``unit``), or None when disabled."""
    if not enabled:
        return None
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, unit=unit, leave=False, file=sys.stderr,
                dynamic_ncols=True)


def terminal():
    """Whether progress should be shown by default (stderr is a terminal)."""
    return sys.stderr.isatty()
