"""Paper B's typed descent records (issue 56 item 1): ``records.Descent`` (one run, what
``descent.run_descents`` returns) and ``records.MonteCarlo`` (runs stacked, a chunk or a
gathered Monte Carlo); arrays only at the file edge (``montecarlo.save`` / ``load``)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from opnav.landing import montecarlo
from opnav.landing.records import CALL_KEYS, TRACK_KEYS, Descent, MonteCarlo


def _descent(seed: int, n_calls: int, n_t: int = 4) -> Descent:
    rng = np.random.default_rng(seed)
    kw = {k: rng.normal(size=(n_t, 3)) for k in TRACK_KEYS}
    kw.update(updated=rng.random(n_t) < 0.5, lm_updated=rng.random(n_t) < 0.5, sig_yaw_deg=rng.random(n_t),
              nees_r=rng.random(n_t), nees_v=rng.random(n_t), cut_alt_m=rng.random(n_t))
    calls = {k: rng.normal(size=(n_calls,)) for k in CALL_KEYS}
    calls["plan_index"] = rng.integers(0, 9, n_calls)
    return Descent(t=np.arange(n_t, dtype=float), n_landmarks=n_calls, init_error=rng.normal(size=9),
                   **kw, **calls)


def test_runs_stack_save_load_and_gather_in_run_order(tmp_path):
    """Two chunks saved and loaded are the same records; gathered out of order they come back in
    run order with each call's run index (mutation: of_runs tagging calls by position fails it)."""
    a = MonteCarlo.of_runs([2, 3], [_descent(2, 3), _descent(3, 1)], np.arange(4.0))
    b = MonteCarlo.of_runs([0, 1], [_descent(0, 2), _descent(1, 0)], np.arange(4.0))
    assert list(a.plan_run) == [2, 2, 2, 3] and list(b.n_landmarks) == [2, 0]
    for i, rec in enumerate((a, b)):
        montecarlo.save(tmp_path / f"c{i}.npz", rec, "depth")
    back = [montecarlo.load(tmp_path / f"c{i}.npz") for i in range(2)]
    assert all(r.method == "depth" and r.reuse_key is None for r in back)
    for want, got in zip((a, b), back):
        for k, v in want.arrays().items():
            np.testing.assert_array_equal(getattr(got, k), v, err_msg=k)
    g = montecarlo.gather(back)
    assert g.method == "depth" and list(g.run_index) == [0, 1, 2, 3] and list(g.plan_run) == [0, 0, 2, 2, 2, 3]
    np.testing.assert_array_equal(g.err_r[2], a.err_r[0])
    np.testing.assert_array_equal(g.plan_index[:2], b.plan_index)


def test_a_file_of_other_arrays_is_not_a_monte_carlo():
    with pytest.raises(ValueError, match="unknown arrays.*plan_ns"):
        MonteCarlo.from_arrays({"run_index": np.arange(2), "plan_ns": np.zeros(2)})


def test_a_record_is_typed_and_frozen():
    d = _descent(0, 2)
    with pytest.raises(dataclasses.FrozenInstanceError):
        d.t = np.zeros(4)
    with pytest.raises(TypeError):
        d["err_r"]     # noqa: B018  (records are read by attribute, never by key)
    rec = MonteCarlo.of_descent(d, 7)
    assert rec.n_runs == 1 and list(rec.plan_run) == [7, 7] and not rec.replace(updated=None).has("updated")
