"""The small caches of a run start (``hertz_alpha.json``, ``imports.json`` in the cache root)
give what the computation they replace gives, and a damaged file is recomputed, not trusted."""

from __future__ import annotations

import json

import pytest

from thermodem import _numba_cache
from thermodem.models.mechanics import normal


@pytest.fixture
def cache_root(tmp_path, monkeypatch):
    monkeypatch.setenv("THERMODEM_CACHE_DIR", str(tmp_path))
    normal.hertz_alpha_of_restitution.cache_clear()
    yield tmp_path
    normal.hertz_alpha_of_restitution.cache_clear()


def test_stored_alpha_is_the_computed_one_to_the_bit(cache_root):
    fresh = normal._alpha_of_restitution(0.62)
    assert normal.hertz_alpha_of_restitution(0.62) == fresh
    stored = json.loads((cache_root / normal._ALPHA_FILE).read_text())
    assert stored[repr(0.62)] == fresh
    normal.hertz_alpha_of_restitution.cache_clear()
    assert normal.hertz_alpha_of_restitution(0.62) == fresh  # read back from the file
    # and the value still gives the restitution asked for
    assert normal.hertz_restitution_of_alpha(fresh) == pytest.approx(0.62, abs=1e-9)


def test_damaged_alpha_file_is_recomputed(cache_root):
    (cache_root / normal._ALPHA_FILE).write_text("{not json")
    assert normal.hertz_alpha_of_restitution(0.8) == normal._alpha_of_restitution(0.8)
    (cache_root / normal._ALPHA_FILE).write_text(json.dumps({repr(0.8): "oops"}))
    normal.hertz_alpha_of_restitution.cache_clear()
    assert normal.hertz_alpha_of_restitution(0.8) == normal._alpha_of_restitution(0.8)


def test_import_memo_matches_parsing_and_notices_edits(cache_root, monkeypatch):
    target = _numba_cache.PACKAGE_ROOT / "kernels" / "heat_terms.py"
    memo = _numba_cache._ImportMemo()
    parsed = _numba_cache.imported_files(target)
    assert memo.get(target) == frozenset(parsed)
    memo.save()

    # a new process reads the entry instead of parsing
    def no_parsing(*args, **kwargs):
        raise AssertionError("parsed although the file did not change")

    monkeypatch.setattr(_numba_cache, "imported_files", no_parsing)
    assert _numba_cache._ImportMemo().get(target) == frozenset(parsed)
    # an entry under another size or time is parsed again
    entries = json.loads((cache_root / "imports.json").read_text())
    entries[str(target)][1] -= 1
    (cache_root / "imports.json").write_text(json.dumps(entries))
    with pytest.raises(AssertionError, match="parsed although"):
        _numba_cache._ImportMemo().get(target)
