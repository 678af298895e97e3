"""How many seeds a claim needs, and the interval of the difference it reports.

**The seed rule.**  A study's pairs (every ``than`` of every claim) are Holm-corrected together, so a pair
can be significant only if its raw p-value can fall below ``alpha / m`` in the worst case (``m`` pairs in
the study: Holm's first step).  Each test has a smallest p-value it can give at all, whatever the data, for
a given number of runs per side (:func:`smallest_p`: complete separation for the rank-sum test, every
paired difference of one sign for the signed-rank test, all successes against all failures for Fisher's).
The rule: a claim's runs per side must be at least

    ``n = max(MIN_SEEDS, smallest n with smallest_p(test, n, n) < alpha / m)``

(:func:`seeds_needed`; :data:`MIN_SEEDS` = 10, so that a claim that *can* reach alpha also has some power
for a moderate effect: with 10 a side the rank-sum test detects A12 = 0.8 about half the time at alpha =
0.05).  A pair whose runs (those that produced the metric) cannot reach ``alpha / m`` is **underpowered**:
its claim's verdict says so instead of "inconclusive" (:func:`can_reach`).

**Deterministic planners.**  A planner that ignores its seed (:data:`DETERMINISTIC`: A*, Dijkstra, the exact
optimum, IMMAS with its default ``selection = "best"``, ...) gives one plan however many seeds run: when all
its runs of a scenario (and world seed) have the same plan, its side counts as **one** run (the median of its
values: for a time, the machine's noise is not a sample of the algorithm), never as ten samples.
Two deterministic sides compare their single values (no test); a deterministic side against a stochastic
one is the one-sample Wilcoxon signed-rank test of the stochastic side's values against the single value.

**The interval.**  Each pair reports the difference claimed planner minus other (the metric's units; for
success, the difference of success rates): of means (rank-sum, Fisher), of the mean paired difference
(signed-rank), and its 95 % bootstrap percentile interval (:data:`BOOTSTRAP` resamples of each side, or of
the pairs, from a fixed seed, so the same rows give the same interval).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from scipy import stats

MIN_SEEDS = 10
MAX_SEEDS = 1000
BOOTSTRAP = 2000
#: Planners whose plan does not depend on the seed (their ``rng`` is unused).
DETERMINISTIC = frozenset({"astar", "dijkstra", "theta_star", "optimal", "straight", "dstar_lite", "immas"})


@lru_cache(maxsize=None)
def smallest_p(test: str, n_a: int, n_b: int) -> float:
    """The smallest two-sided p-value ``test`` can give with ``n_a`` and ``n_b`` runs (pairs: the smaller)."""
    if n_a < 1 or n_b < 1:
        return 1.0
    if test == "rank_sum":
        return float(stats.ranksums(np.arange(n_a), np.arange(n_a, n_a + n_b)).pvalue)
    if test in ("signed_rank", "signed_rank_scenarios", "one_sample"):
        n = max(n_a, n_b) if test == "one_sample" else min(n_a, n_b)
        return float(stats.wilcoxon(np.arange(1.0, n + 1.0)).pvalue) if n >= 1 else 1.0
    if test == "fisher":
        return float(stats.fisher_exact([[n_a, 0], [0, n_b]]).pvalue)
    return 1.0


def seeds_needed(test: str, pairs_in_study: int, alpha: float) -> int:
    """The seed rule (module docstring): runs per side for ``test`` among ``pairs_in_study`` Holm-corrected pairs.
    An aggregate claim (``signed_rank_scenarios``) samples scenarios, not seeds: it needs :data:`MIN_SEEDS` seeds
    per scenario, and its pair is underpowered when its scenarios are too few (:func:`can_reach`)."""
    if test == "signed_rank_scenarios":
        return MIN_SEEDS
    threshold = alpha / max(1, pairs_in_study)
    n = 1
    while n < MAX_SEEDS and smallest_p(test, n, n) >= threshold:
        n += 1
    return max(MIN_SEEDS, n)


def can_reach(test: str, n_a: int, n_b: int, pairs_in_study: int, alpha: float) -> bool:
    """Whether a pair with these runs can be significant after Holm's correction over the study, worst case."""
    return smallest_p(test, n_a, n_b) < alpha / max(1, pairs_in_study)


def difference_interval(a: np.ndarray, b: np.ndarray, paired: bool) -> tuple[float, float, float]:
    """(difference, low, high): mean(a) - mean(b) (paired: mean(a - b)) and its 95 % bootstrap percentile
    interval (NaN without values; a side of one value is held fixed)."""
    if a.size == 0 or b.size == 0:
        return math.nan, math.nan, math.nan
    rng = np.random.default_rng(0)
    if paired:
        d = a - b
        draws = d[rng.integers(0, d.size, (BOOTSTRAP, d.size))].mean(axis=1)
        estimate = float(d.mean())
    else:
        draws = (a[rng.integers(0, a.size, (BOOTSTRAP, a.size))].mean(axis=1)
                 - b[rng.integers(0, b.size, (BOOTSTRAP, b.size))].mean(axis=1))
        estimate = float(a.mean() - b.mean())
    low, high = np.percentile(draws, [2.5, 97.5])
    return estimate, float(low), float(high)
