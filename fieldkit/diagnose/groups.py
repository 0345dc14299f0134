"""Independent groups of observations and the cross-validation folds made of them.

Cross-validation must never put neighbouring impacts of one rock on both sides of a
split (they share the rock's shape, mass and the error of its survey), so the unit
held out is a *group*: a path (one rock's impacts) when the table has enough paths,
else a run of consecutive impacts along a path (a *block*), which is the best a
single-path survey such as Tornado Mountain boulder A allows. The same groups are
the units of the jackknife that gives each held-out gain its standard error
(:mod:`fieldkit.diagnose.scoring`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fieldkit.errors import ArgumentError

#: Paths needed before groups are whole paths (fewer: blocks along the paths).
MIN_PATH_GROUPS = 10
#: Groups wanted when a table has too few paths (blocks of consecutive impacts).
BLOCK_GROUPS = 20
#: Folds of the cross-validation (fewer when there are fewer groups).
DEFAULT_FOLDS = 5
#: Fewest folds: one to fit on and one to hold out.
MIN_FOLDS = 2
#: Most folds. Every model is refitted once per fold, so the time grows with the
#: folds, while the held-out error barely changes beyond about ten (and a table
#: never has more folds than groups: the folds are clipped to the groups).
MAX_FOLDS = 100


def check_folds(folds: int) -> int:
    """``folds`` if it lies in [:data:`MIN_FOLDS`, :data:`MAX_FOLDS`], else raise.

    Raises
    ------
    ArgumentError
        Naming the argument ``folds`` and the limits.

    Examples
    --------
    >>> check_folds(5)
    5
    """
    if not MIN_FOLDS <= folds <= MAX_FOLDS:
        raise ArgumentError(
            f"folds must be between {MIN_FOLDS} and {MAX_FOLDS} (got {folds}): each "
            "fold refits every model, and more than about ten folds barely change "
            "the held-out error",
            source="folds",
        )
    return folds


@dataclass(frozen=True)
class Groups:
    """Group and fold of each row, and how the groups were made.

    Attributes
    ----------
    group
        Group index of each row (0 .. n_groups-1).
    fold
        Fold index of each row (0 .. n_folds-1); a group sits in one fold.
    unit
        ``"path"`` or ``"block"``.
    description
        One sentence for reports (how many groups of what, how many folds).
    """

    group: np.ndarray
    fold: np.ndarray
    unit: str
    description: str

    @property
    def n_groups(self) -> int:
        """Number of groups."""
        return int(self.group.max()) + 1 if self.group.size else 0

    @property
    def n_folds(self) -> int:
        """Number of folds."""
        return int(self.fold.max()) + 1 if self.fold.size else 0


def make_groups(
    path_id: np.ndarray,
    rng: np.random.Generator,
    *,
    folds: int = DEFAULT_FOLDS,
    min_paths: int = MIN_PATH_GROUPS,
    blocks: int = BLOCK_GROUPS,
) -> Groups:
    """Groups (paths, or blocks of consecutive impacts) and their folds.

    Rows are taken in table order (impacts along a path are consecutive rows).
    Groups are dealt to folds in a random order drawn from ``rng``, round robin,
    so fold sizes differ by at most one group.

    Examples
    --------
    >>> g = make_groups(np.array(list("aabbbcc") * 2), np.random.default_rng(0),
    ...                 folds=2, min_paths=2)
    >>> g.unit, g.n_groups, g.n_folds
    ('path', 3, 2)
    >>> g = make_groups(np.array(["A"] * 8), np.random.default_rng(0), folds=2,
    ...                 blocks=4)
    >>> g.unit, g.group.tolist()
    ('block', [0, 0, 1, 1, 2, 2, 3, 3])

    Raises
    ------
    ArgumentError
        ``folds`` outside [:data:`MIN_FOLDS`, :data:`MAX_FOLDS`] (:func:`check_folds`).
    """
    check_folds(folds)
    labels = np.asarray(path_id).astype(str)
    n = labels.size
    _, path_index = np.unique(labels, return_inverse=True)
    n_paths = int(path_index.max()) + 1 if n else 0
    if n_paths >= min_paths:
        group, unit = path_index, "path"
        text = f"{n_paths} paths (whole paths held out)"
    else:
        size = max(1, int(np.ceil(n / blocks)))
        group = np.empty(n, np.int64)
        next_group = 0
        for p in range(n_paths):
            rows = np.flatnonzero(path_index == p)
            local = np.arange(rows.size) // size
            group[rows] = next_group + local
            next_group += int(local.max()) + 1
        unit = "block"
        text = (
            f"{next_group} blocks of up to {size} consecutive impacts "
            f"(only {n_paths} path(s): fewer than {min_paths}, so runs of "
            "neighbouring impacts are held out instead of whole paths)"
        )
    n_groups = int(group.max()) + 1 if n else 0
    k = max(1, min(folds, n_groups))
    order = rng.permutation(n_groups)
    fold_of_group = np.empty(n_groups, np.int64)
    fold_of_group[order] = np.arange(n_groups) % k
    return Groups(
        group=group,
        fold=fold_of_group[group] if n else np.zeros(0, np.int64),
        unit=unit,
        description=f"{text}; {k}-fold cross-validation",
    )
