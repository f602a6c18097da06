"""One folder, one run: an output folder is claimed before anything is computed.

- It must be (or become) a writable folder - not an existing file - checked by creating its
  lock file; a lock (``fcntl.flock`` on ``.femadh.lock``) stops a second run writing into it.
- A folder that holds another run's outputs is refused, unless the run is asked to replace
  them (``overwrite``: femadh's own output files are removed first, nothing else) or to
  continue them (``resume``: only a run of the same scene that did not finish).
- ``summary.json`` exists from the start with ``status = "running"`` and is rewritten
  atomically as the run ends: converged / failed / interrupted.
"""
import fcntl
import json
import os
from pathlib import Path
import shutil

from ..errors import OutputError
from .atomic import write_atomic

LOCK = ".femadh.lock"
#: what femadh writes into a run folder (files and folders), removed by ``overwrite``
OUTPUTS = ("summary.json", "curve.csv", "diagnostics.csv", "fields.csv", "jumps.csv",
           "equilibrium_curve.csv", "checkpoint.npz", "meniscus.csv", "profiles.csv",
           "vtk", "approach.pvd", "retract.pvd", "force_curve.png", "fig3_panels.png",
           "profiles_and_forces.png", "meniscus_force.png", "render.png")


def previous_run(path):
    """The summary of the run a folder holds (dict), or None; a folder with femadh outputs but
    no readable summary counts as a run of unknown status."""
    path = Path(path)
    s = path / "summary.json"
    if s.exists():
        try:
            return json.loads(s.read_text())
        except (OSError, ValueError):
            return {"status": "unknown (unreadable summary.json)"}
    if any((path / name).exists() for name in OUTPUTS[1:]) or any(path.glob("meniscus_*.pvd")):
        return {"status": "unknown (no summary.json)"}
    return None


def _finished(prev):
    """Whether the run a folder holds has finished (converged, not a trial): there is
    nothing in it to resume."""
    return prev.get("status") == "converged" and not prev.get("trial")


def _drop_unheld(fd, lock):
    """Close ``fd`` (open on the lock file ``lock``), removing the file first if this process
    holds (or can now take) its lock and it is still the folder's."""
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        if os.stat(lock).st_ino == os.fstat(fd).st_ino:
            os.unlink(lock)
    except OSError:
        pass                        # another run's lock, or the file already gone
    os.close(fd)


class RunFolder:
    """Claim ``path`` for a run.

    Parameters
    ----------
    path : str or Path
    scene_id : str
        Content hash of the resolved scene (a resumed run must be of the same scene).
    scene_name : str
    mode : {"new", "overwrite", "resume", "amend"}
        ``amend`` reopens the folder of a run of the same scene that has just written it, to
        update its summary, and touches none of its outputs.
    given : dict, optional
        The scene's keys as the user gave them (:attr:`Scene.as_given`): summary.json records
        them ("scene_given"), and a ``resume`` of a folder whose run had other keys names
        the keys that changed.

    Raises
    ------
    OutputError
        The path is a file, not writable, locked by another run, or holds another run's
        outputs that ``mode`` does not allow to touch.
    """

    def __init__(self, path, scene_id, scene_name, mode="new", given=None):
        self.path = Path(os.path.normpath(path))      # ('a/../b' is b: a is not made)
        self.scene_id, self.scene_name, self.mode = scene_id, scene_name, mode
        # as summary.json holds them (JSON's lists and numbers), to compare with a previous
        # run's
        self.given = None if given is None else json.loads(json.dumps(
            given, default=lambda o: _json_default(o, str)))
        if self.path.exists() and not self.path.is_dir():
            raise OutputError(f"output folder {self.path} is an existing file; give a folder "
                              "(--out DIR)")
        # the folders this call creates (deepest first): a refused claim removes them again
        # when empty, so that a refusal leaves the file system as it found it. Made one level
        # at a time on the normalised path, each counted only if this call's mkdir made it
        # ('a/../b' names b, not a; a folder another process makes meanwhile is not ours)
        full = Path(os.path.abspath(self.path))
        created = []
        try:
            for q in reversed([full, *full.parents]):
                try:
                    q.mkdir()
                    created.insert(0, q)
                except FileExistsError:
                    if not q.is_dir():
                        raise
        except OSError as exc:
            raise OutputError(f"cannot create the output folder {self.path}: "
                              f"{exc.strerror or exc}") from None
        self.lock_fd = None
        try:
            self._lock()
            self.previous = self._check_previous()
        except BaseException:
            # a refusal, or a signal while the folder was being claimed (SIGINT or SIGTERM
            # raised as KeyboardInterrupt: no ``with`` was entered to release it): the lock
            # file is not left behind, nor a folder this call created
            self.release()
            for q in created:
                try:
                    q.rmdir()               # (an empty folder only)
                except OSError:
                    break
            raise

    def _lock(self):
        lock = self.path / LOCK
        # a lock taken on a file that another run removed as it ended (it had been opened
        # just before) guards nothing: taken again on the folder's current file (budget 5)
        for _ in range(5):
            try:
                fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
            except OSError as exc:
                raise OutputError(f"output folder {self.path} is not writable: "
                                  f"{exc.strerror or exc}") from None
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                other = os.read(fd, 64).decode(errors="replace").strip() or "?"
                os.close(fd)
                raise OutputError(f"output folder {self.path} is in use by another femadh "
                                  f"run (pid {other}); wait for it or give another --out") \
                    from None
            except BaseException:
                # a signal (raised as KeyboardInterrupt) at the lock: the file this run
                # created is removed if the lock is (or now becomes) ours - never another
                # run's - and the descriptor closed
                _drop_unheld(fd, lock)
                raise
            # held from here on: release() removes the file and closes it
            self.lock_fd = fd
            try:
                same = os.stat(lock).st_ino == os.fstat(self.lock_fd).st_ino
            except FileNotFoundError:
                same = False
            if same:
                break
            os.close(self.lock_fd)
            self.lock_fd = None
        else:
            raise OutputError(f"output folder {self.path}: its lock file keeps being replaced "
                              "by another run; wait for it or give another --out")
        os.ftruncate(self.lock_fd, 0)
        os.write(self.lock_fd, str(os.getpid()).encode())

    def _check_previous(self):
        prev = previous_run(self.path)
        if prev is None:
            if self.mode == "resume":
                raise OutputError(f"nothing to resume in {self.path}: it holds no femadh run")
            return None
        what = (f"{self.path} holds the results of a previous run (scene "
                f"{prev.get('scene', {}).get('name', '?')!r}, status {prev.get('status')})")
        if self.mode == "overwrite":
            self.clean()
            return None
        if self.mode == "amend":
            if prev.get("scene_id") != self.scene_id:
                raise OutputError(f"{what} of another scene: its summary cannot be amended")
            return prev
        if self.mode == "resume":
            if str(prev.get("status", "")).startswith("unknown"):
                # summary.json lost or unreadable: the run checks curve.csv's rows against
                # this scene (their checksums are seeded with its id) before it keeps any
                return prev
            if prev.get("scene_id") != self.scene_id:
                raise OutputError(self._changed(what, prev))
            if _finished(prev):
                raise OutputError(f"{what}: it has finished, there is nothing to resume")
            return prev
        if _finished(prev):
            # (--resume would only be refused: the refusal advises what can be done)
            raise OutputError(f"{what}; it has finished: use --overwrite to replace it or "
                              "give another --out")
        raise OutputError(f"{what}; use --resume to continue it or --overwrite to replace it "
                          "(or give another --out)")

    def _changed(self, what, prev):
        """The one line refusing to resume a run of other keys: the first few keys that
        changed (dotted, as the scene names them), each with the run's value and this
        scene's, and what to do."""
        old = prev.get("scene_given")
        if old is None or self.given is None:
            # (a folder written before its summary recorded the scene's keys)
            return (f"{what} of another scene (or of this scene changed): it cannot be "
                    "resumed; use --overwrite to replace it")
        diff = changed_keys(old, self.given)
        if not diff:
            return (f"{what} of the same scene keys resolved otherwise (femadh "
                    f"{prev.get('femadh_version', '?')} wrote it): it cannot be resumed; use "
                    "--overwrite to run it again")
        shown = "; ".join(f"{k} was {_value(a)}, is {_value(b)} now" for k, a, b in diff[:3])
        more = (f" (and {len(diff) - 3} more key{'s' if len(diff) > 4 else ''})"
                if len(diff) > 3 else "")
        keys = ", ".join(k for k, _, _ in diff[:3]) + (", ..." if more else "")
        return (f"{what}, whose scene has changed since: {shown}{more}; it cannot be resumed: "
                "rerun with --overwrite instead of --resume to start again, or restore "
                f"{keys} to resume it")

    def clean(self):
        """Remove femadh's own outputs (and nothing else) from the folder."""
        for name in OUTPUTS:
            p = self.path / name
            try:
                if p.is_dir():
                    shutil.rmtree(p)
                elif p.exists():
                    p.unlink()
            except OSError as exc:
                raise OutputError(f"cannot remove {p}: {exc.strerror or exc}") from None
        for p in self.path.glob("meniscus_*.pvd"):
            p.unlink()

    def write_summary(self, data):
        """summary.json, atomically; ``data`` gets the scene id."""
        given = {} if self.given is None else {"scene_given": self.given}
        write_atomic(self.path / "summary.json",
                     json.dumps({"scene_id": self.scene_id, **given, **data}, indent=2,
                                default=_json_default) + "\n")

    def release(self):
        """Give the folder up: the lock file is removed while it is still held, then closed
        (closing first would let a second run lock the file in between and then lose it
        to the unlink: two runs could both believe they hold the folder). A run that opened
        the file just before the unlink holds a lock on a removed file: ``_lock`` checks
        that the file it locked is still the folder's."""
        if getattr(self, "lock_fd", None) is not None:
            try:
                os.unlink(self.path / LOCK)
            except OSError:
                pass
            os.close(self.lock_fd)
            self.lock_fd = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.release()
        return False


def _json_default(o, other=None):
    """``o`` as JSON (numpy scalars and arrays); anything else by ``other`` (e.g. str: a
    TOML date among a scene's keys), else TypeError."""
    import numpy as np

    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, np.bool_):
        return bool(o)
    if other is not None:
        return other(o)
    raise TypeError(type(o))


#: a key one scene sets and the other does not
_UNSET = object()


def changed_keys(old, new, prefix=""):
    """[(dotted key, old value, new value)] of every leaf that differs between two scenes'
    keys (nested dicts as the TOML tables; a list of tables by index,
    ``substrate.layers.0.thickness``); a key only one of them sets has ``_UNSET`` on the
    other side."""
    out = []
    if isinstance(old, dict) and isinstance(new, dict):
        for k in list(old) + [k for k in new if k not in old]:
            out += changed_keys(old.get(k, _UNSET), new.get(k, _UNSET), f"{prefix}{k}.")
        return out
    if (isinstance(old, list) and isinstance(new, list) and len(old) == len(new)
            and any(isinstance(x, dict) for x in old + new)):
        for i, (a, b) in enumerate(zip(old, new)):
            out += changed_keys(a, b, f"{prefix}{i}.")
        return out
    return [] if old == new else [(prefix[:-1], old, new)]


def _value(v):
    """A scene value as the refusal shows it: as written in TOML (strings quoted)."""
    if v is _UNSET:
        return "not set"
    if isinstance(v, bool):
        return "true" if v else "false"
    return repr(v) if isinstance(v, str) else json.dumps(v)
