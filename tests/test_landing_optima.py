"""B-C8's count of local minima (opnav.landing.optima): known shapes, curves built with a
known number of dips (Hypothesis), infinite points left out, and the summary's numbers."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from opnav.landing import optima


def test_known_shapes():
    assert optima.count_minima([3, 2, 1, 2, 3]) == 1          # a U
    assert optima.count_minima([1, 2, 3]) == 1                # monotone: the minimum at an end
    assert optima.count_minima([3, 1, 3, 1, 3]) == 2          # a W: what the golden section cannot handle
    assert optima.count_minima([1, 1, 1]) == 1                # flat
    assert optima.count_minima([2, 1, 1, 1, 2]) == 1          # a flat bottom is one minimum
    assert optima.count_minima([5, np.inf, 1, 2]) == 1        # no parallax points left out
    assert optima.count_minima([]) == 0


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 5), st.floats(0.1, 3.0))
def test_a_curve_with_k_dips_has_k_minima(k, depth):
    """cos(2 pi k x) (1 + depth (x - 1/2)^2 / 5) over [0, 1] has exactly k minima, all inside; cut after its
    last minimum it keeps k (the last at the end: mutation tried once, counting only interior
    minima reads k - 1 there)."""
    x = np.linspace(0, 1, 721)
    f = np.cos(2 * np.pi * k * x) * (1 + depth * (x - 0.5) ** 2 / 5)
    assert optima.count_minima(f) == k
    assert optima.count_minima(f[::-1]) == k
    cut = f[: int(720 * (2 * k - 1) / (2 * k)) - 5]           # ends falling toward the last minimum
    assert optima.count_minima(cut) == k


def test_summary_counts_calls_with_a_second_minimum():
    from opnav.core.tables import json_ready
    from opnav.report.landing.equivalence_text import Worded
    from opnav.report.landing.optima_text import optima_text

    s = optima.count_summary(optima.OptimaCounts([[1, 1], [1], [2, 1], [1, 3]], 2, 6, 181), "interior")
    assert s.calls_multi_minimum == 2 and s.n_calls == 4 and s.max_minima_per_call == 3
    assert "2 of 4 planning calls" in optima_text(s)
    doc = json_ready(Worded(s, optima_text(s)))        # optima/<camera>.json: the count's keys and its sentence
    assert set(doc) == {"scenario", "method", "n_calls", "calls_multi_minimum", "max_minima_per_call",
                        "sides_counted", "calls_skipped", "n_recorded", "n_grid", "text"}
