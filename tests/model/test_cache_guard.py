"""The numba cache guard: stale cache files go when a compiled source changes."""

from __future__ import annotations

from fieldkit.model.cache_guard import guard, sources_hash


def test_guard_deletes_cache_files_when_a_compiled_source_changes(tmp_path):
    package = tmp_path / "pkg"
    (package / "sub" / "__pycache__").mkdir(parents=True)
    kernel = package / "sub" / "kernel.py"
    kernel.write_text("from numba import njit\n@njit\ndef f(x):\n    return x\n")
    (package / "plain.py").write_text("x = 1\n")
    cached = package / "sub" / "__pycache__" / "kernel.f-3.py311.nbi"
    stamp = package / "sub" / "__pycache__" / "stamp"
    cached.write_text("index")
    assert guard(package, stamp) is True  # no stamp yet: the cache is of unknown age
    assert not cached.exists()
    cached.write_text("index")
    assert guard(package, stamp) is False  # same sources: the cache is kept
    assert cached.exists()
    before = sources_hash(package)
    (package / "plain.py").write_text("x = 2\n")  # not compiled: no effect
    assert sources_hash(package) == before
    kernel.write_text(kernel.read_text() + "# changed\n")
    assert guard(package, stamp) is True
    assert not cached.exists()
