"""A user's own misalignment estimator (opnav.approach.estimators, issue 58): the refusals before
any work (one line naming the estimator), the worked example (examples/batch_ls.py) on Table-1
cases scored against the truth and the bound of the data it used, and a failure during a run
named with the estimator, variant, case, seed and window."""

from __future__ import annotations

import copy
import re
import textwrap

import numpy as np
import pytest

from opnav.approach import cases
from opnav.approach import estimators as E
from opnav.approach import estimator_summary as ES
from opnav.approach import scenario as sc
from opnav.approach.setup import Setup
from opnav.core.config import load_config
from opnav.core.registry import MethodError

EXAMPLE = "examples/batch_ls.py:estimate"


@pytest.fixture(scope="module")
def approach():
    return copy.deepcopy(load_config(overlays=["config/quick.yaml"])["approach"])


def with_estimators(a: dict, **entries) -> dict:
    return {**a, "custom_estimators": entries}


def user_file(tmp_path, body: str, name: str) -> str:
    f = tmp_path / name
    f.write_text(textwrap.dedent(body))
    return str(f)


def _one_line(a, name, **entries) -> str:
    lines = E.problems(with_estimators(a, **entries))
    assert len(lines) == 1, lines
    assert lines[0].startswith(f"invalid config key 'approach.custom_estimators.{name}'") and "\n" not in lines[0]
    return lines[0]


def test_the_example_passes_and_none_is_the_default(approach):
    assert approach["custom_estimators"] == {}
    assert E.problems(approach) == []
    assert E.problems(with_estimators(approach, batch_ls={"path": EXAMPLE, "label": "batch LS"})) == []


@pytest.mark.parametrize("path, match", [
    ("no_such_module_xyz:estimate", "does not import"),
    ("examples/nope.py:estimate", "not found"),
    ("examples/batch_ls.py:nope", "has no attribute 'nope'"),
    ("examples/batch_ls.py", "is not 'module:function'"),
])
def test_a_path_that_does_not_import_is_refused(approach, path, match):
    assert re.search(match, _one_line(approach, "mine", mine=path))


@pytest.mark.parametrize("name", ["em", "augmented", "batch_ml", "squarem"])
def test_a_builtin_name_is_refused(approach, name):
    assert "is a built-in estimator's" in _one_line(approach, name, **{name: EXAMPLE})


def test_a_wrong_signature_is_refused(approach, tmp_path):
    f = user_file(tmp_path, "def est(p, q):\n    return [0.0, 0.0, 0.0]\n", "two.py")
    assert "exactly one argument (a opnav.approach.estimators.Problem)" in _one_line(approach, "mine", mine=f"{f}:est")


@pytest.mark.parametrize("body, match", [
    ("raise RuntimeError('singular')", "raised RuntimeError: singular on the probe call"),
    ("return np.full(3, np.nan)", "non-finite estimate"),
    ("return np.zeros(2)", r"shape \(2,\), expected theta"),
    ("return 'x'", "expected theta"),
    ("return np.zeros(3), np.eye(2)", "covariance that is not a finite symmetric 3 x 3"),
    ("return np.zeros(3), np.full((3, 3), np.nan)", "covariance that is not"),
    ("return np.zeros(3), np.eye(3), 1", "a tuple of 3"),
])
def test_a_bad_probe_is_refused(approach, tmp_path, body, match):
    f = user_file(tmp_path, f"import numpy as np\n\ndef est(p):\n    {body}\n", f"b{abs(hash(body))}.py")
    assert re.search(match, _one_line(approach, "mine", mine=f"{f}:est"))


def test_the_preflight_carries_the_line(tmp_path):
    from opnav.preflight import problems

    cfg = load_config(overlays=["config/quick.yaml"])
    f = user_file(tmp_path, "def est(p):\n    raise ValueError('no')\n", "pre.py")
    cfg["approach"]["custom_estimators"] = {"mine": f"{f}:est"}
    lines = [ln for ln in problems(cfg) if "custom_estimators" in ln]
    assert len(lines) == 1 and lines[0].startswith("invalid config key 'approach.custom_estimators.mine'")


def test_the_problem_is_documented(approach):
    """The record's fields have the documented shapes; its measurements follow eq. 3 at theta0."""
    p = E.probe_problem(approach)
    n1 = Setup.from_config(approach).segments.N + 1
    assert isinstance(p, E.Problem)
    assert [np.shape(x) for x in p[:10]] == [(n1, 3), (n1,), (n1, 6, 6), (n1, 3, 3), (n1, 3), (n1, 3), (6, 6), (6,),
                                             (6, 6), (3,)]
    np.testing.assert_allclose(np.diff(p.t_s), Setup.from_config(approach).dt_s)
    # across the line of sight z - u_ref is a tiny angle of u_ref (misalignment, position error, noise);
    # along it the range noise (Rvar's third entry, from the disc's size) dominates
    d = p.z[1:] - p.u_ref[1:]
    assert np.all(np.linalg.norm(d[:, :2], axis=1) < 1e-3 * np.linalg.norm(p.u_ref[1:], axis=1))
    assert np.all(p.Rvar[1:, 2] > 100 * p.Rvar[1:, 0])


@pytest.fixture(scope="module")
def scored(approach):
    setup = Setup.from_config(approach)
    geo = sc.build_geometry(setup, "prior")
    est = E.load(E.specs({"batch_ls": EXAMPLE})["batch_ls"])
    return [E.run_case(setup, "prior", c, range(3), geo, [est]) for c in cases.table1_cases(setup)[:2]]


def test_batch_least_squares_reaches_the_bound_of_its_data(scored):
    """Known answer: on the linear model, batch least squares with the start's prior is the
    efficient estimator of the data it used, so its own sigma equals the Cramér-Rao bound of
    that data (the bound counts the small process noise the estimator ignores: within 3 %), and
    its errors are of that size."""
    for r in scored:
        e = r.estimators["batch_ls"]
        sig, b = e.sigma_seg_arcsec[:, :, :2], r.bound_seg_arcsec[None, :, :2]
        np.testing.assert_allclose(sig, np.broadcast_to(b, sig.shape), rtol=0.03)
        err = e.theta_final_arcsec[:, :2] - r.truth_arcsec[:2]
        assert np.all(np.abs(err) < 4 * r.bound_seg_arcsec[-1, :2])
        assert e.runtime_s_per_call > 0 and np.all(e.nav_err_after_km > 0)


def test_the_table_and_curves(scored):
    df = ES.long_frame(scored)
    assert list(df["case_id"]) == ["T1-01", "T1-02"] and set(df["estimator"]) == {"batch_ls"}
    r, e = scored[0], scored[0].estimators["batch_ls"]
    row = df.iloc[0]
    err = e.theta_final_arcsec[:, 0] - r.truth_arcsec[0]
    assert row["err_x_mean_arcsec"] == pytest.approx(err.mean())
    assert row["err_over_bound_x"] == pytest.approx(np.sqrt(np.mean(err ** 2)) / r.bound_seg_arcsec[-1, 0])
    assert row["sigma_x_mean_arcsec"] == pytest.approx(e.sigma_final_arcsec[:, 0].mean())
    c = ES.curves(scored)["prior"]
    assert c.estimators["batch_ls"].shape == (3, len(c.data), 3)


def test_a_failure_in_a_run_names_estimator_variant_case_seed_and_window(approach, tmp_path):
    f = user_file(tmp_path, """
        import numpy as np

        def est(p):
            if len(p.z) > 150:
                raise np.linalg.LinAlgError('too long')
            return p.theta0
        """, "late.py")
    a = with_estimators(approach, late=f"{f}:est")
    assert E.problems(a) == []
    setup = Setup.from_config(a)
    geo = sc.build_geometry(setup, "prior")
    est = E.load(E.specs(a["custom_estimators"])["late"])
    with pytest.raises(MethodError, match=r"^approach\.custom_estimators\.late: \S+ raised LinAlgError: too long "
                                          r"on variant prior, case T1-01, seed 0, window of 150 samples after N0"):
        E.run_case(setup, "prior", cases.headline_case(setup), range(2), geo, [est])
