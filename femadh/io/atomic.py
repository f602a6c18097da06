"""Writing files so that a reader never sees a torn line or a half file.

- :func:`write_atomic`: a whole file (summary.json, a figure, a VTK file) goes to a temporary
  file in the same folder, is flushed to the disk (fsync: else a power loss can leave the
  renamed file empty; ~1 ms here) and renamed into place (atomic on one filesystem), with the
  permissions a plain ``open`` would give it (mkstemp's are owner-only).
- :class:`RowLog`: a csv that grows by whole chunks (the rows of one state): each chunk is one
  ``write`` of the unbuffered file, and a failed write (disk full) is cut back to the last
  whole chunk before the error is raised, so earlier rows stay intact.
"""
import csv
import io
import os
from pathlib import Path
import tempfile

from ..errors import OutputError


def _reason(exc):
    return exc.strerror or str(exc)


def _umask():
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


#: files get 0o666 & ~umask, as open() would create them
_MODE = 0o666 & ~_umask()


def _publish(tmp, path):
    """fsync ``tmp``, give it ordinary permissions and rename it to ``path``."""
    fd = os.open(tmp, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)
    os.chmod(tmp, _MODE)
    os.replace(tmp, path)


def write_atomic(path, data):
    """Write ``data`` (str or bytes) to ``path`` via a temporary file and a rename."""
    path = Path(path)
    blob = data.encode() if isinstance(data, str) else data
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as exc:
        raise OutputError(f"cannot write {path}: {_reason(exc)}") from None
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(blob)
        _publish(tmp, path)
    except OSError as exc:
        raise OutputError(f"cannot write {path}: {_reason(exc)}") from None
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def save_atomic(path, writer):
    """Let ``writer(tmp_path)`` write a file (e.g. matplotlib's savefig, meshio), then rename
    it into place. The temporary file keeps the final suffix (writers pick formats by it)."""
    path = Path(path)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=path.suffix, dir=path.parent)
        os.close(fd)
    except OSError as exc:
        raise OutputError(f"cannot write {path}: {_reason(exc)}") from None
    try:
        writer(tmp)
        _publish(tmp, path)
    except OSError as exc:
        raise OutputError(f"cannot write {path}: {_reason(exc)}") from None
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def csv_text(rows):
    """rows (lists) as csv text."""
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerows(rows)
    return buf.getvalue()


class RowLog:
    """A csv file appended to in whole chunks.

    Parameters
    ----------
    path : Path
    header : list of str
    keep : int or None
        Resume: keep the existing file's first ``keep`` data lines (and its header), cutting
        anything after them (a torn last line, rows of an uncommitted state); None: start a
        new file.
    """

    def __init__(self, path, header, keep=None):
        self.path = Path(path)
        self.header = list(header)
        try:
            if keep is not None and not self.path.exists():
                keep = None             # a lost file (its rows are recomputed): a new one
            if keep is None:
                self.fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
                self.size = 0
                self.append([self.header])
            else:
                self.size = _byte_offset_after(self.path, keep + 1)
                self.fd = os.open(self.path, os.O_WRONLY)
                os.ftruncate(self.fd, self.size)
                os.lseek(self.fd, self.size, os.SEEK_SET)
        except OSError as exc:
            raise OutputError(f"cannot write {self.path}: {_reason(exc)}") from None

    def append(self, rows):
        """Append the rows (lists) as one chunk; on failure the file is cut back to its size
        before the chunk and OutputError names the file."""
        self.append_text(csv_text(rows))

    def append_text(self, text):
        """Append ``text`` - whole csv lines, formatted by the caller exactly as
        :func:`csv_text` would (see :func:`femadh.io.writers.field_lines`) - as one chunk,
        like :meth:`append`."""
        blob = text.encode()
        done = 0
        try:
            while done < len(blob):
                done += os.write(self.fd, blob[done:])
        except OSError as exc:
            try:
                os.ftruncate(self.fd, self.size)
                os.lseek(self.fd, self.size, os.SEEK_SET)
            except OSError:
                pass
            raise OutputError(f"cannot write {self.path}: {_reason(exc)}; its earlier rows "
                              "are intact") from None
        self.size += len(blob)

    def close(self):
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None


def _byte_offset_after(path, lines):
    """Byte offset just after the first ``lines`` complete lines of a file (a last line
    without its newline is torn and does not count)."""
    offset = 0
    with open(path, "rb") as f:
        for _ in range(lines):
            line = f.readline()
            if not line.endswith(b"\n"):
                break
            offset += len(line)
    return offset
