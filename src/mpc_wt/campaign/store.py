"""The campaign directory: one time-series file per case and an SQLite index committed per case.

Layout::

    DIR/spec.yaml         the spec of the latest run (as given)
    DIR/index.sqlite      cases, status, metrics, software version, spec hash, each file's SHA-256
    DIR/cases/ID.nc       one result per case (ClosedLoopResult netCDF, written atomically)
    DIR/cases/ID.partial.nc   what a diverged simulation produced before it stopped
    DIR/report/           tables and plots of ``mpcwt campaign report``

Only the client writes the index (one writer: an exclusive lock on ``DIR/.lock``); workers
write case files (temp file + rename), so a killed worker or client leaves at worst a temp
file, never a half-written result, and the index never names a file that is not complete.
The index keeps each result file's SHA-256: a file changed or cut short after it was recorded is
found when the campaign resumes (it is computed again, with a logged reason) and when it is
reported (refused, naming the files).
"""
from __future__ import annotations

import contextlib
import fcntl
import hashlib
import json
import logging
import os
import sqlite3
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterable

from mpc_wt.campaign.checksum import file_sha256
from mpc_wt.campaign.spec import CampaignSpec, Case
from mpc_wt.errors import CampaignIndexError, CampaignLockedError

log = logging.getLogger(__name__)

__all__ = ["CampaignStore", "CampaignLockedError", "CaseRow", "STATUSES"]

#: pending: not run yet; submitted: handed to the engine by a client (if that client died,
#: the case is re-run); done: file and metrics stored; failed: raised (traceback stored);
#: stale: in the index but no longer in the spec (kept, not reported).
STATUSES = ("pending", "submitted", "done", "failed", "stale")

_SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS cases (
    case_id TEXT PRIMARY KEY,
    controller TEXT NOT NULL,
    run_name TEXT NOT NULL,
    wind_mps REAL NOT NULL,
    seed INTEGER NOT NULL,
    turbulence TEXT NOT NULL,
    case_hash TEXT NOT NULL,
    assess_hash TEXT NOT NULL,
    case_json TEXT NOT NULL,
    status TEXT NOT NULL CHECK (status IN ('pending', 'submitted', 'done', 'failed', 'stale')),
    file TEXT,
    metrics TEXT,
    error TEXT,
    traceback TEXT,
    software_version TEXT,
    spec_hash TEXT,
    attempts INTEGER NOT NULL DEFAULT 0,
    wall_s REAL,
    worker TEXT,
    updated REAL NOT NULL,
    sha256 TEXT,
    metrics_sha256 TEXT
);
"""


@dataclass(frozen=True)
class CaseRow:
    """One row of the index.

    Parameters
    ----------
    case_id, controller, run_name : str
        The case, its controller label and the registered kind it runs.
    wind_mps : float
        Mean wind [m/s].
    seed : int
        Seed of the field.
    turbulence : str
        Class letter or intensity, as text.
    case_hash, assess_hash : str
        Hashes of the simulation and the assessment inputs.
    status : str
        pending, submitted, done, failed or stale.
    file : str or None
        The result file, relative to the campaign directory.
    metrics : dict or None
        :func:`~mpc_wt.campaign.task.case_metrics` of a done case.
    error, traceback : str or None
        Of a failed case.
    software_version, spec_hash : str or None
        Who computed it, under which spec.
    attempts : int
        Submissions so far.
    wall_s : float or None
        Wall time of the last attempt [s].
    worker : str or None
        host:pid of the last attempt.
    sha256 : str or None
        SHA-256 of the result file as it was recorded (None before checksums were kept).
    """

    case_id: str
    controller: str
    run_name: str
    wind_mps: float
    seed: int
    turbulence: str
    case_hash: str
    assess_hash: str
    status: str
    file: str | None
    metrics: dict[str, Any] | None
    error: str | None
    traceback: str | None
    software_version: str | None
    spec_hash: str | None
    attempts: int
    wall_s: float | None
    worker: str | None
    sha256: str | None = None

    @property
    def turbulence_value(self) -> str | float:
        """The turbulence as in the spec: a class letter or an intensity."""
        try:
            return float(self.turbulence)
        except ValueError:
            return self.turbulence


def _storage_error(err: sqlite3.DatabaseError) -> bool:
    """Whether SQLite could not write (a full disk, a read-only file or folder, an I/O
    error), as against a file that is not an index."""
    text = str(err).lower()
    return isinstance(err, sqlite3.OperationalError) and any(
        w in text for w in ("full", "readonly", "read-only", "disk i/o", "unable to open"))


def _text_sha256(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()


def _metrics_match(metrics: str | None, recorded: str | None) -> bool:
    """Whether a case's metrics are as recorded (an index of before metrics checksums were
    kept, or a row without metrics, has nothing to check)."""
    return recorded is None or metrics is None or _text_sha256(metrics) == recorded


class CampaignStore:
    """Open (and create) a campaign directory.

    Parameters
    ----------
    root : path
        The campaign directory.
    lock : bool
        Take the exclusive client lock (``run``); ``status`` and ``report`` read without it.

    Raises
    ------
    CampaignLockedError
        If ``lock`` and another live client holds the directory.
    """

    def __init__(self, root: str | Path, *, lock: bool = False) -> None:
        self.root = Path(root)
        self.cases_dir = self.root / "cases"
        self._lock_fh = None
        if lock:
            self.cases_dir.mkdir(parents=True, exist_ok=True)
            fh = open(self.root / ".lock", "a+")
            try:
                fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError as err:
                fh.seek(0)
                who = fh.read().strip() or "?"
                fh.close()
                raise CampaignLockedError(f"campaign {self.root} is being run by another client "
                                          f"({who}); wait for it or stop it") from err
            fh.seek(0)
            fh.truncate()
            fh.write(f"pid {os.getpid()} on {os.uname().nodename}\n")
            fh.flush()
            self._lock_fh = fh
        elif not (self.root / "index.sqlite").is_file():
            raise FileNotFoundError(f"{self.root}: not a campaign directory (no index.sqlite)")
        index = self.root / "index.sqlite"
        try:
            self.db = sqlite3.connect(index, timeout=30.0, isolation_level=None)
            self.db.execute("PRAGMA journal_mode=WAL")
            self.db.execute("PRAGMA synchronous=FULL")
            if lock:
                self.db.executescript(_SCHEMA)
                cols = {r[1] for r in self.db.execute("PRAGMA table_info(cases)")}
                for col in ("sha256", "metrics_sha256"):    # an index of before they were kept
                    if col not in cols:
                        self.db.execute(f"ALTER TABLE cases ADD COLUMN {col} TEXT")
            cols = {r[1] for r in self.db.execute("PRAGMA table_info(cases)")}
            self._has_sha = "sha256" in cols
            self._has_msha = "metrics_sha256" in cols
        except sqlite3.DatabaseError as err:       # not a database, disk full, read-only ...
            self.close()
            if _storage_error(err):
                raise CampaignIndexError(
                    f"{index}: cannot be written: {err} (free space or make it writable, "
                    f"then run the same command again to resume: every case recorded before "
                    f"is kept)", storage=True) from None
            raise CampaignIndexError(f"{index}: cannot be used as a campaign index: {err} "
                                     f"(a damaged index: move it away and run the campaign "
                                     f"again; its finished case files are reused)") from None

    def close(self) -> None:
        """Close the index and release the lock."""
        if getattr(self, "db", None) is not None:
            self.db.close()
        if self._lock_fh is not None:
            fcntl.flock(self._lock_fh, fcntl.LOCK_UN)
            self._lock_fh.close()
            self._lock_fh = None

    def __enter__(self) -> "CampaignStore":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    # -- metadata -------------------------------------------------------------------------
    def set_meta(self, **items: Any) -> None:
        """Store campaign-level values (JSON) in one transaction.

        Parameters
        ----------
        **items
            Key -> JSON-serialisable value.
        """
        with self._tx():
            self.db.executemany("INSERT OR REPLACE INTO meta VALUES (?, ?)",
                                [(k, json.dumps(v)) for k, v in items.items()])

    def meta(self) -> dict[str, Any]:
        """The campaign-level values.

        Returns
        -------
        dict
            Key -> value (name, spec hash, software version, spec, last run ...).
        """
        return {k: json.loads(v) for k, v in self.db.execute("SELECT key, value FROM meta")}

    # -- cases ----------------------------------------------------------------------------
    def sync(self, spec: CampaignSpec) -> dict[str, int]:
        """Bring the index in line with ``spec`` in one transaction.

        New cases are added as pending; a case whose simulation inputs changed (case hash),
        or whose controller kind resolves its options differently now (its defaults changed
        with the software: design hash; logged), goes back to pending (its old file is
        overwritten when it reruns); a case no longer in
        the spec becomes ``stale`` (kept). Returns the counts of each action.

        Parameters
        ----------
        spec : CampaignSpec
            The campaign.

        Returns
        -------
        dict of str to int
            Counts of ``added``, ``invalidated``, ``stale``, ``reassess``, ``kept`` and
            ``redesigned`` (computed under other defaults of its kind: computed again).
        """
        cases = spec.cases()
        ids = {c.case_id for c in cases}
        now = time.time()
        counts = {"added": 0, "invalidated": 0, "reassess": 0, "kept": 0, "stale": 0,
                  "redesigned": 0}
        unrecorded = 0
        with self._tx():
            old = {r[0]: r for r in self.db.execute(
                "SELECT case_id, case_hash, assess_hash, status, case_json FROM cases")}
            for c in cases:
                row = old.get(c.case_id)
                cj = json.dumps(c.to_dict(), sort_keys=True)
                # the design hash it was computed under (None: recorded before designs were)
                before = None if row is None else json.loads(row[4]).get("design_hash")
                redesigned = None not in (before, c.design_hash) and before != c.design_hash
                if row is None:
                    self.db.execute(
                        "INSERT INTO cases (case_id, controller, run_name, wind_mps, seed, "
                        "turbulence, case_hash, assess_hash, case_json, status, updated) "
                        "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, 'pending', ?)",
                        (c.case_id, c.controller, c.run_name, c.wind_mps, c.seed,
                         str(c.turbulence), c.case_hash, c.assess_hash, cj, now))
                    counts["added"] += 1
                elif row[1] != c.case_hash or redesigned:
                    self.db.execute(
                        "UPDATE cases SET status='pending', case_hash=?, assess_hash=?, "
                        "case_json=?, run_name=?, metrics=NULL, error=NULL, traceback=NULL, "
                        "updated=? WHERE case_id=?",
                        (c.case_hash, c.assess_hash, cj, c.run_name, now, c.case_id))
                    counts["invalidated" if row[1] != c.case_hash else "redesigned"] += 1
                elif row[2] != c.assess_hash:
                    self.db.execute("UPDATE cases SET assess_hash=?, case_json=?, updated=?, "
                                    "status=CASE WHEN status='done' THEN 'pending' ELSE status "
                                    "END WHERE case_id=?", (c.assess_hash, cj, now, c.case_id))
                    counts["reassess"] += 1
                else:
                    if row[3] == "stale":
                        self.db.execute("UPDATE cases SET status='pending' WHERE case_id=?",
                                        (c.case_id,))
                    if before is None and c.design_hash is not None:
                        self.db.execute("UPDATE cases SET case_json=? WHERE case_id=?",
                                        (cj, c.case_id))
                        unrecorded += row[3] == "done"
                    counts["kept"] += 1
            if unrecorded:
                log.warning("%d finished cases carry no record of the defaults their controller "
                            "kinds had (computed by a version that did not record them): they "
                            "are kept and take today's; remove their files from cases/ to "
                            "compute them under today's defaults", unrecorded)
            if counts["redesigned"]:
                log.warning("%d cases were computed under other defaults of their controller "
                            "kind (the software changed them since): they are computed again",
                            counts["redesigned"])
            for cid, r in old.items():
                if cid not in ids and r[3] != "stale":
                    self.db.execute("UPDATE cases SET status='stale', updated=? WHERE case_id=?",
                                    (now, cid))
                    counts["stale"] += 1
        return counts

    def todo(self) -> list[Case]:
        """Cases to submit: everything not done, and done cases whose file has gone or no
        longer matches the SHA-256 recorded with it (logged; the changed file is moved to
        ``cases/ID.changed.nc`` so that the case is computed again, not reused). A done
        case recorded before checksums were kept gets its file's checksum now.

        Returns
        -------
        list of Case
            In insertion order.
        """
        out, first_sums = [], []
        msha = "metrics_sha256" if self._has_msha else "NULL"
        for cid, status, file, cj, sha, metrics, mhash in self.db.execute(
                f"SELECT case_id, status, file, case_json, sha256, metrics, {msha} FROM cases "
                "WHERE status != 'stale' ORDER BY rowid").fetchall():
            if status == "done" and file and (self.root / file).is_file():
                if sha is None:
                    first_sums.append((file_sha256(self.root / file), cid))
                    continue
                edited = not _metrics_match(metrics, mhash)
                if file_sha256(self.root / file) == sha and not edited:
                    continue
                moved = (self.root / file).with_suffix(".changed.nc")
                os.replace(self.root / file, moved)
                log.warning("case %s: %s does not match the checksum recorded when it was "
                            "written (%s since); computing the case again (the file is kept "
                            "as %s)", cid, "its metrics in the index" if edited else file,
                            "edited" if edited else "changed or cut short", moved.name)
            out.append(Case.from_dict(json.loads(cj)))
        if first_sums:
            with self._tx():
                self.db.executemany("UPDATE cases SET sha256=? WHERE case_id=?", first_sums)
            log.info("checksums recorded for %d case files written before checksums were kept",
                     len(first_sums))
        return out

    def redo(self, case_ids: Iterable[str], suffix: str) -> int:
        """Done cases to compute again: each result file is kept as ``cases/ID.SUFFIX.nc``
        (nothing computed is lost) and the case goes back to pending.

        Parameters
        ----------
        case_ids : iterable of str
            The cases.
        suffix : str
            Letters naming why, e.g. ``redesigned``.

        Returns
        -------
        int
            The cases sent back.
        """
        if not suffix.isalpha():
            raise ValueError(f"suffix must be letters, got {suffix!r}")
        ids = list(case_ids)
        now = time.time()
        with self._tx():
            for cid in ids:
                row = self.db.execute("SELECT file FROM cases WHERE case_id=?", (cid,)).fetchone()
                if row is not None and row[0] and (self.root / row[0]).is_file():
                    os.replace(self.root / row[0],
                               (self.root / row[0]).with_suffix(f".{suffix}.nc"))
                self.db.execute("UPDATE cases SET status='pending', metrics=NULL, error=NULL, "
                                "traceback=NULL, updated=? WHERE case_id=?", (now, cid))
        return len(ids)

    def changed_files(self) -> list[tuple[str, str]]:
        """Done cases whose result file is missing or no longer matches its recorded SHA-256
        (a row that names no file, as an index made by hand, has nothing to check).

        Returns
        -------
        list of (str, str)
            (case id, what is wrong) per such case; empty when every file is as recorded.
        """
        if not self._has_sha:
            return []
        bad = []
        msha = "metrics_sha256" if self._has_msha else "NULL"
        for cid, file, sha, metrics, mhash in self.db.execute(
                f"SELECT case_id, file, sha256, metrics, {msha} FROM cases WHERE status = "
                "'done' AND file IS NOT NULL ORDER BY rowid"):
            path = self.root / file
            if not path.is_file():
                bad.append((cid, f"{file}: missing"))
            elif sha is not None and file_sha256(path) != sha:
                bad.append((cid, f"{file}: changed or cut short since it was recorded"))
            elif not _metrics_match(metrics, mhash):
                bad.append((cid, "its metrics in index.sqlite: edited since they were recorded"))
        return bad

    def mark_submitted(self, case_ids: Iterable[str]) -> None:
        """Record that this client handed the cases to the engine (attempts + 1).

        Parameters
        ----------
        case_ids : iterable of str
            The cases.
        """
        now = time.time()
        with self._tx():
            self.db.executemany("UPDATE cases SET status='submitted', attempts=attempts+1, "
                                "updated=? WHERE case_id=?", [(now, c) for c in case_ids])

    def record(self, case_id: str, outcome: dict[str, Any], spec_hash: str) -> None:
        """Commit one finished case (``outcome`` of :func:`mpc_wt.campaign.task.run_case`).

        Parameters
        ----------
        case_id : str
            The case.
        outcome : dict
            What the task returned.
        spec_hash : str
            The spec it ran under.
        """
        now = time.time()
        with self._tx():
            if outcome["status"] == "done":
                text = json.dumps(outcome["metrics"])
                self.db.execute(
                    "UPDATE cases SET status='done', file=?, metrics=?, error=NULL, "
                    "traceback=NULL, software_version=?, spec_hash=?, wall_s=?, worker=?, "
                    "updated=?, sha256=?, metrics_sha256=? WHERE case_id=?",
                    (outcome["file"], text, outcome.get("software_version"), spec_hash,
                     outcome.get("wall_s"), outcome.get("worker"), now, outcome.get("sha256"),
                     _text_sha256(text), case_id))
            else:
                self.db.execute(
                    "UPDATE cases SET status='failed', error=?, traceback=?, "
                    "software_version=?, spec_hash=?, wall_s=?, worker=?, updated=? "
                    "WHERE case_id=?",
                    (outcome.get("error", "unknown error"), outcome.get("traceback"),
                     outcome.get("software_version"), spec_hash, outcome.get("wall_s"),
                     outcome.get("worker"), now, case_id))

    def rows(self, *, include_stale: bool = False) -> list[CaseRow]:
        """All rows (of the current spec unless ``include_stale``), in insertion order.

        Parameters
        ----------
        include_stale : bool
            Also the cases no longer in the spec.

        Returns
        -------
        list of CaseRow
            The rows.
        """
        q = ("SELECT case_id, controller, run_name, wind_mps, seed, turbulence, case_hash, "
             "assess_hash, status, file, metrics, error, traceback, software_version, spec_hash, "
             "attempts, wall_s, worker" + (", sha256" if self._has_sha else "") + " FROM cases")
        if not include_stale:
            q += " WHERE status != 'stale'"
        out = []
        for r in self.db.execute(q + " ORDER BY rowid"):
            r = list(r)
            r[10] = json.loads(r[10]) if r[10] else None
            out.append(CaseRow(*r))
        return out

    def counts(self) -> dict[str, int]:
        """Number of cases per status.

        Returns
        -------
        dict of str to int
            Status -> count.
        """
        c = {s: 0 for s in STATUSES}
        for s, n in self.db.execute("SELECT status, count(*) FROM cases GROUP BY status"):
            c[s] = n
        return c

    def stray_temp_files(self) -> list[Path]:
        """Temp files left by writers that were killed mid-write (safe to delete once no
        worker of this campaign runs).

        Returns
        -------
        list of Path
            The files.
        """
        return sorted(self.cases_dir.glob(".*.tmp")) if self.cases_dir.is_dir() else []

    def _tx(self) -> "_Tx":
        return _Tx(self.db, self.root / "index.sqlite")


class _Tx:
    """BEGIN IMMEDIATE ... COMMIT (ROLLBACK on error): one durable commit per call. An index
    that cannot be written (a full disk, a read-only folder) raises
    :class:`~mpc_wt.errors.CampaignIndexError` naming it; the commits before are kept."""

    def __init__(self, db: sqlite3.Connection, index: Path) -> None:
        self.db, self.index = db, index

    def _failed(self, err: sqlite3.Error) -> CampaignIndexError:
        return CampaignIndexError(
            f"{self.index}: cannot be written: {err} (free space or make it writable, then "
            f"run the same command again to resume: every case recorded before is kept)",
            storage=True)

    def __enter__(self) -> sqlite3.Connection:
        try:
            self.db.execute("BEGIN IMMEDIATE")
        except sqlite3.OperationalError as err:
            raise self._failed(err) from None
        return self.db

    def __exit__(self, et: Any, ev: Any, tb: Any) -> bool:
        try:
            self.db.execute("ROLLBACK" if et else "COMMIT")
        except sqlite3.OperationalError as err:
            if et is None:
                with contextlib.suppress(sqlite3.Error):
                    self.db.execute("ROLLBACK")
                raise self._failed(err) from None
        if et is not None and issubclass(et, sqlite3.OperationalError):
            raise self._failed(ev) from None
        return False

