"""Session cache of diagnoses of the synthetic tables of :mod:`diagnose_cases`.

A diagnosis takes about a second, so each distinct (table, fold seed) is
diagnosed once per session and shared between tests.
"""

from __future__ import annotations

import numpy as np
import pytest
from diagnose_cases import hidden_table

from fieldkit.diagnose.impacts import diagnose_impacts


@pytest.fixture(scope="session")
def diagnosed():
    """``diagnosed(effects, noise=, paths=, seed=, impacts=None, fold_seed=None)``.

    Returns ``(table, diagnosis)`` for :func:`hidden_table`, diagnosed against the
    base model with ``rng = default_rng(fold_seed)`` (default: ``seed``); cached
    for the session.
    """
    cache: dict = {}

    def run(
        effects: tuple[str, ...],
        *,
        noise: float,
        paths: int,
        seed: int,
        impacts: int | None = None,
        fold_seed: int | None = None,
    ):
        key = (tuple(effects), noise, paths, seed, impacts, fold_seed)
        if key not in cache:
            table = hidden_table(
                effects, noise=noise, paths=paths, seed=seed, impacts=impacts
            )
            rng = np.random.default_rng(seed if fold_seed is None else fold_seed)
            cache[key] = (table, diagnose_impacts(table, None, rng=rng))
        return cache[key]

    return run
