"""Keep numba's on-disk cache from serving machine code of old sources.

numba keys a cached function by *its own* source file (path, modification time,
size). A compiled function that calls a compiled function of another file (the
impact fit's ``predict_rows`` calls :func:`fieldkit.model.kernel.restitution`)
keeps its cached machine code when only the other file changes -- old physics,
silently (seen in issue 18: a new effect in the kernel was ignored by the impact
fit until the cache was deleted by hand). So on import a hash of every fieldkit
source that numba compiles is compared with the one recorded beside the cache;
when they differ, fieldkit's numba cache files are deleted (they are rebuilt on
first use) and the new hash recorded. A read-only install is left alone (numba
cannot write a cache there either).
"""

from __future__ import annotations

import hashlib
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1]
STAMP = PACKAGE / "model" / "__pycache__" / "numba_sources.sha256"


def sources_hash(package: Path = PACKAGE) -> str:
    """SHA-256 over the fieldkit files that define numba-compiled code."""
    digest = hashlib.sha256()
    for path in sorted(package.rglob("*.py")):
        text = path.read_bytes()
        if b"@njit" in text or b"numba.njit" in text:
            digest.update(str(path.relative_to(package)).encode())
            digest.update(text)
    return digest.hexdigest()


def guard(package: Path = PACKAGE, stamp: Path = STAMP) -> bool:
    """Delete stale numba cache files under ``package``; True when it did."""
    current = sources_hash(package)
    try:
        if stamp.exists() and stamp.read_text().strip() == current:
            return False
        for pattern in ("*.nbi", "*.nbc"):
            for cached in package.rglob(pattern):
                cached.unlink(missing_ok=True)
        stamp.parent.mkdir(parents=True, exist_ok=True)
        stamp.write_text(current + "\n")
    except OSError:
        return False
    return True
