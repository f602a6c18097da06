"""What a resumed run may keep of its folder: every committed row checked against its record.

``curve.csv`` is the commit record. Each of its rows carries ``crc32``, a checksum of the row
seeded with the run's scene id (:func:`femadh.io.writers.row_crc`); a per-row checksum was
chosen over a digest of the committed prefix in summary.json because it costs ~1 us and 9
bytes a row, holds after a kill -9 (when summary.json still says "running" and would carry no
digest of the last rows) and names the first row that does not match. Beyond the checksum a
row must be the state the scene's sweep puts there (state number, branch, separation d).

- A curve.csv row that does not match is **refused** in one line naming the file and the row
  (``curve.csv row 41 does not match its record (...); use --overwrite, or --resume-from 40``):
  the record itself is damaged and the user decides. A torn last line (a kill mid-write) is
  not a row. An empty curve.csv (no header) holds no committed state: the run starts over.
- The side files (fields.csv, diagnostics.csv, jumps.csv) are **repaired**: a lost, truncated
  or damaged one cuts the resume point back to the longest prefix of states complete in every
  file (their rows are then computed again, to the same values), with one note.
- A missing or unreadable summary.json is repaired when curve.csv's first row checks with
  this scene's id (the checksum's seed proves the scene); otherwise refused.
"""
import csv

from ..errors import OutputError
from .writers import (CRC, CURVE_HEADER, DIAG_HEADER, FIELD_HEADER, JUMP_HEADER, _g,
                      extra_outputs, row_crc)

#: columns write_instrument may have appended to curve.csv after the checksum
INSTRUMENT_COLUMNS = ("z_m", "F_instrument_N")


class DamagedFolder(OutputError):
    """A resumed folder whose commit record does not match: names the file and the row."""


def _lines(path):
    """The complete lines of a file as text (a torn last line dropped), or None if the file
    is missing; undecodable bytes become U+FFFD (the row then fails its check)."""
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        return None
    except OSError as exc:
        raise OutputError(f"cannot read {path}: {exc.strerror or exc}") from None
    parts = data.split(b"\n")
    parts = parts[:-1]               # the piece after the last newline is torn (or empty)
    return [p.decode("utf-8", errors="replace") for p in parts]


def _floats_ok(cells):
    for c in cells:
        try:
            float(c)
        except ValueError:
            return False
    return True


def plan_rows(scene):
    """(branch, d) of every committed state of a stepping sweep, in the order it runs."""
    d = list(scene.d_values)
    out = []
    if "approach" in scene.directions:
        out += [("approach", x) for x in d]
        if "retract" in scene.directions:
            out += [("retract", x) for x in d[::-1]]
    else:
        out += [("retract", x) for x in d]
    return out


def check_curve(folder, scene, problem, run_id, resume_from=None):
    """The committed rows of curve.csv that match their record: (k, cells of each, notes).

    Raises DamagedFolder naming the first row that does not match (unless ``resume_from``
    keeps only rows before it)."""
    path = folder / "curve.csv"
    lines = _lines(path)
    if lines is None or not lines:
        note = ("resume: curve.csv is " + ("missing" if lines is None else "empty")
                + ": no committed state; the run starts from its first state")
        if resume_from:
            raise DamagedFolder(f"--resume-from {resume_from}: {path} holds no committed row")
        return 0, [], [note] if lines is not None else []
    extra = [o.force for o in extra_outputs(problem)]
    header = next(csv.reader([lines[0]]))
    base = CURVE_HEADER + extra
    with_crc = base + [CRC]
    if header[:len(with_crc)] == with_crc and all(h in INSTRUMENT_COLUMNS
                                                  for h in header[len(with_crc):]):
        n_crc = len(base)
    elif header[:len(base)] == base and all(h in INSTRUMENT_COLUMNS
                                           for h in header[len(base):]):
        n_crc = None                   # a folder written before the checksum: structure only
    else:
        raise DamagedFolder(f"{path} row 0 (the header) does not match its record (expected "
                            f"{','.join(with_crc)}); use --overwrite")
    plan = plan_rows(scene)
    rows, why = [], None
    for i, line in enumerate(lines[1:]):
        why = row_problem(line, i, header, n_crc, plan, run_id)
        if why:
            break
        rows.append(next(csv.reader([line])))
    k = len(rows)
    if why and (resume_from is None or resume_from > k):
        if k == 0 and why.startswith("checksum") and n_crc is not None:
            why += ": a run of another scene, or of this scene changed"
        raise DamagedFolder(f"{path.name} row {k + 1} does not match its record ({why}); use "
                            f"--overwrite, or --resume-from {k} to keep the {k} rows before it"
                            if resume_from is None else
                            f"--resume-from {resume_from}: {path.name} row {k + 1} does not "
                            f"match its record ({why}); use --resume-from {k} or less")
    if resume_from is not None:
        if resume_from > k:
            raise DamagedFolder(f"--resume-from {resume_from}: {path.name} has {k} committed "
                                "rows; give at most that")
        rows = rows[:resume_from]
    return len(rows), rows, []


def row_problem(line, i, header, n_crc, plan, run_id):
    """Why curve.csv data row i (0-based) does not match its record, or None."""
    try:
        cells = next(csv.reader([line]))
    except (csv.Error, StopIteration):
        return "not a csv row"
    if len(cells) != len(header):
        return f"{len(cells)} cells, the header has {len(header)}"
    if n_crc is not None and row_crc(cells[:n_crc], run_id) != cells[n_crc]:
        return "checksum"
    if cells[0] != str(i):
        return f"state number {cells[0]!r}, expected {i}"
    if i >= len(plan):
        return f"state {i} is beyond the scene's sweep of {len(plan)} states"
    b, d = plan[i]
    if cells[1] != b or cells[2] != _g(d):
        return f"{cells[1]} d = {cells[2]}, the sweep has {b} d = {_g(d)} there"
    num = [c for j, c in enumerate(cells[2:], start=2)
           if header[j] not in ("converged", "stable", CRC)]
    if not _floats_ok(num) or any(cells[header.index(c)] not in ("True", "False")
                                  for c in ("converged", "stable")):
        return "a cell that is not a number"
    return None


def check_side_files(folder, rows, n_nodes):
    """How many of the committed states (``rows``: curve.csv cells) are complete in
    fields.csv and diagnostics.csv, and how many states jumps.csv vouches for: (k, notes)."""
    k = len(rows)
    notes = []
    ok_f, why_f = _fields_prefix(folder / "fields.csv", rows, n_nodes)
    ok_d, why_d = _diag_prefix(folder / "diagnostics.csv", rows)
    ok_j, why_j = _jumps_limit(folder / "jumps.csv", rows)
    keep = min(k, ok_f, ok_d, ok_j)
    for name, ok, why in (("fields.csv", ok_f, why_f), ("diagnostics.csv", ok_d, why_d),
                          ("jumps.csv", ok_j, why_j)):
        if ok < k and ok == keep:
            notes.append(f"resume: {name} {why}; the run continues after state {keep} "
                         f"(the {k - keep} committed states after it are computed again)")
            break
    return keep, notes


def _fields_prefix(path, rows, n_nodes):
    lines = _lines(path)
    if lines is None:
        return 0, "is missing"
    if not lines or not lines[0].startswith(",".join(FIELD_HEADER)):
        return 0, "has no header"
    width = len(next(csv.reader([lines[0]])))
    k, count = 0, 0
    for n, line in enumerate(lines[1:], start=1):
        if k >= len(rows):
            break
        cells = line.split(",")
        want = rows[k]
        if (len(cells) != width or cells[0] != want[0] or cells[1] != want[1]
                or cells[2] != want[2] or not _floats_ok(cells[2:])):
            return k, f"row {n} does not match state {k} of curve.csv"
        count += 1
        if count == n_nodes:
            k, count = k + 1, 0
    if k < len(rows):
        return k, f"ends inside state {k} (of {len(rows)} committed)"
    return k, ""


def _diag_prefix(path, rows):
    lines = _lines(path)
    if lines is None:
        return 0, "is missing"
    if not lines or not lines[0].startswith(",".join(DIAG_HEADER)):
        return 0, "has no header"
    for k, want in enumerate(rows):
        if k + 1 >= len(lines):
            return k, f"ends at state {k} (of {len(rows)} committed)"
        cells = lines[k + 1].split(",")
        if len(cells) != len(DIAG_HEADER) or cells[:3] != want[:3]:
            return k, f"row {k + 1} does not match state {k} of curve.csv"
    return len(rows), ""


def _jumps_limit(path, rows):
    """States the jump record vouches for: all of them if jumps.csv is intact; else those
    before the landing of its last intact jump (a lost jump lies after it)."""
    lines = _lines(path)
    intact, why = [], ""
    if lines is None:
        why = "is missing"
    elif not lines or lines[0] != ",".join(JUMP_HEADER):
        why = "has no header"
    else:
        for n, line in enumerate(lines[1:], start=1):
            cells = line.split(",")
            if (len(cells) != len(JUMP_HEADER) or cells[0] not in ("approach", "retract")
                    or not _floats_ok(cells[1:])):
                why = f"row {n} is damaged"
                break
            intact.append((cells[0], float(cells[2])))
        else:
            return len(rows), ""
    if not intact:
        return 0, why
    b, d_land = intact[-1]
    for k, r in enumerate(rows):
        d = float(r[2])
        if r[1] == b and (d <= d_land if b == "approach" else d >= d_land):
            return k, why
    return len(rows), why


def field_states(folder, wanted, columns=("w_m", "P_LJ_Pa", "P_el_Pa")):
    """{state number: (d, *arrays)} of the wanted committed states from fields.csv, one
    array per name in ``columns`` (default: w, P_LJ, P_el; the repr floats the run wrote:
    the same bits as the states it held)."""
    import numpy as np

    out = {}
    wanted = set(wanted)
    if not wanted:
        return out
    top = max(wanted)
    with open(folder / "fields.csv", newline="") as f:
        rd = csv.reader(f)
        head = next(rd)
        cols = [head.index(c) for c in columns]
        for cells in rd:
            k = int(cells[0])
            if k > top:
                break
            if k in wanted:
                out.setdefault(k, (float(cells[2]), *([] for _ in cols)))
                for lst, j in zip(out[k][1:], cols):
                    lst.append(float(cells[j]))
    return {k: (d, *(np.array(x) for x in v)) for k, (d, *v) in out.items()}


def kept_jumps(folder, rows):
    """How many rows of jumps.csv a resume keeps: the jumps landed before the last kept
    state of their branch (a jump written just before a kill whose next state was not
    committed is found again by the resumed run)."""
    last = {r[1]: float(r[2]) for r in rows}
    lines = _lines(folder / "jumps.csv") or []
    j = 0
    for line in lines[1:]:
        cells = line.split(",")
        b, d_land = cells[0], float(cells[2])
        if b not in last or not (d_land >= last[b] if b == "approach" else d_land <= last[b]):
            break
        j += 1
    return j
