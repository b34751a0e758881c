"""The one renderer of docs/performance.md (diffengine.bench.render): the checked-in
records reproduce today's sections exactly, and a section without a record is left as it
is."""
from __future__ import annotations

import json
import shutil

import pytest

from diffengine.bench import record, render


def test_docs_are_their_rendering():
    """What `diffengine bench render --check` runs: every kept record renders to the text
    between its markers, byte for byte."""
    assert render.write(check=True) == 0


def test_every_section_has_its_markers():
    doc = render.DOC.read_text()
    for name in render.SECTIONS:
        begin, end = render.markers(name)
        assert doc.count(begin) == 1 and doc.count(end) == 1, name
        assert doc.index(begin) < doc.index(end)


def test_missing_record_keeps_the_section(tmp_path, capsys):
    doc = tmp_path / "performance.md"
    shutil.copyfile(render.DOC, doc)
    assert render.write(folder=tmp_path / "none", doc=doc) == 0
    assert doc.read_text() == render.DOC.read_text()
    assert "section kept as it is" in capsys.readouterr().err


def test_a_new_record_changes_only_its_section(tmp_path):
    rec = record.load("array")
    if rec is None:
        pytest.skip("no docs/bench/array.json")
    rec["data"]["cycles_per_s"]["72"] = 123456
    (tmp_path / "array.json").write_text(json.dumps(rec))
    doc = tmp_path / "performance.md"
    shutil.copyfile(render.DOC, doc)
    render.write(["array"], folder=tmp_path, doc=doc)
    old, new = render.DOC.read_text().splitlines(), doc.read_text().splitlines()
    changed = [(a, b) for a, b in zip(old, new) if a != b]
    assert len(old) == len(new) and len(changed) == 1 and "123,456" in changed[0][1]
