"""Atomic writes: a write that fails half-way leaves the previous file and no temporary behind."""
import os

import pytest

from infsup_contact import io


@pytest.mark.parametrize("write, old, new", [(io.write_atomic, "old text", "new text"),
                                             (io.write_bytes_atomic, b"old\x00", b"new\x01")])
def test_interrupted_write_keeps_the_old_file(tmp_path, monkeypatch, write, old, new):
    target = tmp_path / "out" / "table.csv"
    write(target, old)

    def interrupted(fd):
        raise KeyboardInterrupt  # as if the run were stopped before the rename

    monkeypatch.setattr(os, "fsync", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write(target, new)
    monkeypatch.undo()
    read = target.read_bytes() if isinstance(old, bytes) else target.read_text()
    assert read == old
    assert sorted(p.name for p in target.parent.iterdir()) == ["table.csv"]
    write(target, new)
    assert (target.read_bytes() if isinstance(new, bytes) else target.read_text()) == new


def test_row_lines_are_copied_in_constant_time(tmp_path):
    """pandas deep-copies ``attrs`` on every derived frame: the row → line map must not be
    copied element by element (a list of 50,000 lines made the full ledger 30x slower)."""
    import copy

    from infsup_contact.io import read_table

    p = tmp_path / "t.csv"
    p.write_text("claim_id,paper_ref,statement,evidence,verdict,predicted\n"
                 + "".join(f"c{i},r,s,e,PASS,PASS\n" for i in range(1000)))
    frame = read_table(p, "claims")
    assert copy.deepcopy(frame.attrs)["lines"] is frame.attrs["lines"]
    assert frame[frame.verdict == "PASS"].attrs["lines"] is frame.attrs["lines"]
    assert list(frame.attrs["lines"][:2]) == [2, 3]
