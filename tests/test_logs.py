"""Quiet logs: a params-change reason names the changed keys, not whole sections."""

from opnav.core.snakeio import compact_params_change_reasons, params_change_text


def test_only_changed_leaves_are_named():
    old = {"mc": {"n_runs": 4, "runs_per_job": 2, "bounds": {"r_m": 1000.0}}, "duration_s": 198.0}
    new = {"mc": {"n_runs": 4, "runs_per_job": 1, "bounds": {"r_m": 500.0}}, "duration_s": 198.0}
    text = params_change_text({repr(old)}, {repr(new)})
    assert text == "mc.bounds.r_m: 1000.0 -> 500.0; mc.runs_per_job: 2 -> 1"


def test_several_params_are_paired_by_keys_and_added_keys_shown():
    old = [repr({"a": 1, "b": 2}), repr({"x": [1, 2]}), repr("plain")]
    new = [repr({"x": [1, 3]}), repr({"a": 1, "b": 2, "c": 5}), repr("other")]
    text = params_change_text(set(old), set(new))
    assert "x: [1, 2] -> [1, 3]" in text
    assert "c: (new) 5" in text
    assert "value: 'plain' -> 'other'" in text
    assert "a:" not in text and "b:" not in text


def test_long_reasons_are_bounded():
    old = {f"k{i}": i for i in range(50)}
    new = {f"k{i}": i + 1 for i in range(50)}
    text = params_change_text({repr(old)}, {repr({**new, "big": list(range(1000))})})
    assert "(and 43 more)" in text and len(text) < 400


def test_snakemake_reason_uses_it():
    from snakemake.persistence import ParamsChange

    compact_params_change_reasons()
    change = ParamsChange(only_old={repr({"a": {"b": 1}})}, only_new={repr({"a": {"b": 2}})})
    assert str(change) == "a.b: 1 -> 2"
