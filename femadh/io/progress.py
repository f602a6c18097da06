"""Progress on stderr, and only where a person watches.

A run shows **one** display from its start to its end (:func:`display`): a tqdm line whose
label names the phase - ``paper1-fig4 › operator``, ``› approach 12/36``, ``› estimate:
member 1/2 (N = 100) › retract``, ``› refinement 2``, ``› figures`` - and whose counter
restarts with each phase that has a known number of steps. Code that runs inside a run (its
branches, its estimate members, the refinements of an adaptive run) names its part with
:func:`phase`, :func:`part` (the next part of the open phase: an estimate's next member,
without the line falling back to the enclosing phase between them) and :func:`begin` /
:func:`advance`; these are no-ops when no display is shown, so pipes, logs, tests and nested
runs stay quiet. Callers decide ``enabled`` (default: stderr is a
terminal).

The width is the terminal's, asked again at each phase; a terminal that reports 0 columns
(some CI runners, ``docker exec`` without a tty size) gets 80 (or ``COLUMNS``), not a bar of
width 0 that tqdm would not draw at all.
"""
import contextlib
import os
import sys
import time

#: the display of the run in progress (one per process), or None
_active = None

#: width used when the terminal reports none
FALLBACK_COLUMNS = 80
#: height used when the terminal reports none (tqdm hides a bar below the screen's last row,
#: so a terminal of 0 rows - a pty nobody sized - would show nothing)
FALLBACK_ROWS = 24


def terminal():
    """Whether progress should be shown by default (stderr is a terminal)."""
    return sys.stderr.isatty()


def _size(stream, field, env, fallback):
    """One dimension of the terminal behind ``stream`` (default stderr): what it reports,
    else the environment variable ``env``, else ``fallback`` (a pty of size 0x0 reports 0)."""
    stream = stream or sys.stderr
    try:
        n = getattr(os.get_terminal_size(stream.fileno()), field)
    except (AttributeError, OSError, ValueError):
        n = 0
    if n <= 0:
        try:
            n = int(os.environ.get(env, "0"))
        except ValueError:
            n = 0
    return n if n > 0 else fallback


def width(stream=None):
    """Columns of the terminal behind ``stream`` (default stderr); COLUMNS or 80."""
    return _size(stream, "columns", "COLUMNS", FALLBACK_COLUMNS)


def height(stream=None):
    """Rows of the terminal behind ``stream`` (default stderr); LINES or 24."""
    return _size(stream, "lines", "LINES", FALLBACK_ROWS)


class Display:
    """One tqdm line for a whole run; see the module docstring."""

    def __init__(self, name, stream=None):
        from tqdm import tqdm

        self.stream = stream or sys.stderr
        self.name = name
        self.frames = []          # labels of the open phases, outermost first
        self.bases = []           # their names as opened (a part's label adds to its own)
        self.leaf = None          # the current step's label inside the innermost phase
        self.t0 = time.perf_counter()
        self.bar = tqdm(total=None, desc=name, file=self.stream, leave=False,
                        ncols=width(self.stream), nrows=height(self.stream),
                        dynamic_ncols=False, unit="state",
                        bar_format="{desc}")

    def label(self, room=None):
        """The phase path, its middle elided when it would not leave ``room`` columns for
        the counter (the innermost part and the run's name are what a reader needs)."""
        parts = [self.name] + self.frames + ([self.leaf] if self.leaf else [])
        text = " › ".join(parts)
        while room is not None and len(text) > room and len(parts) > 2:
            parts = [parts[0], "…"] + parts[2 + (parts[1] == "…"):]
            text = " › ".join(parts)
            if parts[1] == "…" and len(parts) == 3:
                break
        return text

    def _redraw(self, total=None):
        cols = width(self.stream)
        self.bar.ncols = cols
        # a phase without a count shows its name; the time is the whole run's so far
        self.bar.bar_format = ("{desc}: {n_fmt}/{total_fmt}{postfix}" if total
                               else "{desc}{postfix}")
        self.bar.set_postfix_str(self._elapsed(), refresh=False)
        self.bar.set_description_str(self.label(room=cols - 22), refresh=False)
        # reset last: it draws once, with the new label (reset first drew the finished
        # phase's label at 0/n - "approach: 0/36" after "approach: 32/36")
        self.bar.reset(total=total)

    def _elapsed(self):
        return f"{time.perf_counter() - self.t0:.1f} s"

    def push(self, label):
        self.frames.append(label)
        self.bases.append(label)
        self.leaf = None
        self._redraw()

    def pop(self):
        if self.frames:
            self.frames.pop()
            self.bases.pop()
        self.leaf = None
        self._redraw()

    def part(self, label):
        if self.frames:
            self.frames[-1] = f"{self.bases[-1]}: {label}"
        self.leaf = None
        self._redraw()

    def begin(self, label, total=None):
        self.leaf = label
        self._redraw(total)

    def advance(self, n=1):
        self.bar.set_postfix_str(self._elapsed(), refresh=False)
        self.bar.update(n)

    def note(self, msg):
        self.bar.write(msg, file=self.stream)

    def close(self):
        self.bar.close()


@contextlib.contextmanager
def display(name, enabled=None):
    """The run's display while the block runs: created by the outermost run when
    ``enabled`` (default: stderr is a terminal); a nested run (an estimate member, a trial of
    an adaptive run) reports into the one already shown. Yields the display or None."""
    global _active
    if enabled is None:
        enabled = terminal()
    if _active is not None or not enabled:
        yield _active
        return
    _active = Display(name)
    try:
        yield _active
    finally:
        _active.close()
        _active = None


@contextlib.contextmanager
def phase(label):
    """Name a part of the run (``operator``, ``estimate: N = 100``, ``figures``) while the
    block runs; nothing when no display is shown."""
    d = _active
    if d is None:
        yield
        return
    d.push(label)
    try:
        yield
    finally:
        d.pop()


def part(label):
    """The open phase's next part (``estimate`` -> ``estimate: member 2/2 (N = 100)``): the
    phase stays open, so its parts follow one another on the line without the enclosing
    phase's label (the grid's sweep) between them; nothing when no display is shown."""
    if _active is not None:
        _active.part(label)


def begin(label, total=None):
    """A step of ``total`` counted items (a branch of n states) inside the current phase."""
    if _active is not None:
        _active.begin(label, total)


def advance(n=1):
    """Count ``n`` items of the current step."""
    if _active is not None:
        _active.advance(n)


def note(msg):
    """A line above the display (or on stderr when none is shown)."""
    if _active is not None:
        _active.note(msg)
    else:
        print(msg, file=sys.stderr)


def bar(total, desc, enabled=True, unit="state"):
    """A standalone tqdm bar of ``total`` steps (of ``unit``), or None when disabled (studies,
    convergence ladders: work that is not one run)."""
    if not enabled:
        return None
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, unit=unit, leave=False, file=sys.stderr,
                ncols=width(), dynamic_ncols=False)


class StudyProgress:
    """The study's bar in a terminal: points done of all, with failed and reused counts."""

    def __init__(self, total, reused, name):
        self.failed, self.reused = 0, reused
        self.bar = bar(total, f"study {name}", unit="point")
        if self.bar is not None:
            self.bar.update(reused)
            self._postfix()

    def _postfix(self):
        self.bar.set_postfix_str(f"failed {self.failed}, reused {self.reused}")

    def point(self, rec):
        if self.bar is None:
            return
        self.failed += rec.get("status") != "converged"
        self.bar.update(1)
        self._postfix()

    def close(self):
        if self.bar is not None:
            self.bar.close()
