"""A full disk in the middle of a campaign: a case file that cannot be written is a failed case
with the operating system's reason (the others are done, no temporary file is left), and an
index that cannot be written stops the campaign with one line naming it, keeping every case
recorded before; the next run resumes with every case exactly once, the case whose record was
lost taken from its file."""
from __future__ import annotations

import errno
import sqlite3
from pathlib import Path


from mpc_wt.campaign import run_campaign, spec_from_dict
from mpc_wt.campaign.store import CampaignStore
from mpc_wt.cli import main
from mpc_wt.simulation.results import ClosedLoopResult

SPEC = {"name": "disk", "duration": 10, "transient": 0, "winds": [12, 16, 20], "seeds": 1,
        "turbulence": "steady", "controllers": ["baseline"]}


def test_a_case_file_on_a_full_disk_is_a_failed_case(monkeypatch, tmp_path: Path) -> None:
    save = ClosedLoopResult.save

    def full(self, path, *a, **k):
        if "v16" in Path(path).name:
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        return save(self, path, *a, **k)
    monkeypatch.setattr(ClosedLoopResult, "save", full)
    out = tmp_path / "c"
    summary = run_campaign(spec_from_dict(SPEC), out, engine="serial", progress=False)
    assert summary.failed == 1 and summary.done == 2
    with CampaignStore(out) as store:
        rows = {r.case_id: r for r in store.rows()}
    bad = [r for r in rows.values() if r.status == "failed"]
    assert len(bad) == 1 and "v16" in bad[0].case_id
    assert "No space left on device" in bad[0].error
    assert not list((out / "cases").glob("*.tmp")) and not list((out / "cases").glob(".*"))


class _FullAfter:
    """The index's connection, whose commits fail as on a full disk once ``full`` is set."""

    def __init__(self, db: sqlite3.Connection) -> None:
        self._db, self.full = db, False

    def execute(self, sql: str, *args):
        if sql == "COMMIT" and self.full:
            raise sqlite3.OperationalError("database or disk is full")
        return self._db.execute(sql, *args)

    def __getattr__(self, name: str):
        return getattr(self._db, name)


def test_an_index_on_a_full_disk_stops_with_one_line_and_resumes(monkeypatch, tmp_path: Path,
                                                                 capsys) -> None:
    record, calls = CampaignStore.record, []

    def filling(self, case_id, outcome, spec_hash):
        if not isinstance(self.db, _FullAfter):
            self.db = _FullAfter(self.db)
        self.db.full = len(calls) >= 1          # the second record finds the disk full
        calls.append(case_id)
        return record(self, case_id, outcome, spec_hash)
    monkeypatch.setattr(CampaignStore, "record", filling)
    out = tmp_path / "c"
    spec = tmp_path / "s.yaml"
    import yaml

    spec.write_text(yaml.safe_dump(SPEC))
    args = ["campaign", "run", str(spec), "--out", str(out), "--engine", "serial"]
    assert main(args) == 1                     # the run failed (errors.md), not the input
    err = [ln for ln in capsys.readouterr().err.strip().splitlines()
           if not ln.startswith("campaign disk:")]      # the progress bar
    assert len(err) == 1 and err[0].startswith("mpcwt campaign: run failed: ")
    assert f"{out / 'index.sqlite'}: cannot be written: database or disk is full" in err[0]
    assert "run the same command again to resume" in err[0]
    monkeypatch.undo()
    with CampaignStore(out) as store:
        assert store.counts().get("done") == 1
    summary = run_campaign(spec_from_dict(SPEC), out, engine="serial", progress=False)
    assert summary.done == 3 - 1 and summary.failed == 0
    with CampaignStore(out) as store:
        rows = store.rows()
    assert sorted(r.case_id for r in rows) == sorted({r.case_id for r in rows})
    assert [r.status for r in rows] == ["done"] * 3
    assert summary.reused == 1                  # the case whose record was lost: its file


def test_an_index_that_cannot_be_opened_for_a_full_disk_is_not_called_damaged(
        monkeypatch, tmp_path: Path, capsys) -> None:
    """Opening the index on a full disk: exit 1 and "free space ... resume" (it said exit 2,
    "a damaged index: move it away"); an index that is not a database: exit 2, damaged."""
    import yaml

    import mpc_wt.campaign.store as store

    spec = tmp_path / "s.yaml"
    spec.write_text(yaml.safe_dump(SPEC))
    out = tmp_path / "c"
    args = ["campaign", "run", str(spec), "--out", str(out), "--engine", "serial"]
    real = sqlite3.connect

    class _Full:
        def __init__(self, *a, **k):
            self._db = real(*a, **k)

        def execute(self, sql, *a):
            if sql.startswith("PRAGMA journal_mode"):
                raise sqlite3.OperationalError("database or disk is full")
            return self._db.execute(sql, *a)

        def __getattr__(self, name):
            return getattr(self._db, name)
    monkeypatch.setattr(store.sqlite3, "connect", _Full)
    assert main(args) == 1
    err = capsys.readouterr().err
    assert "index.sqlite: cannot be written: database or disk is full (free space" in err
    assert "damaged" not in err
    monkeypatch.undo()
    (out / "index.sqlite").write_bytes(b"not a database" * 100)
    assert main(args) == 2
    assert "a damaged index: move it away" in capsys.readouterr().err
