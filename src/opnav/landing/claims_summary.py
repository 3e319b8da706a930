"""What paper B's claims (:mod:`opnav.report.landing_claims`) read of B-summary.json, by
meaning (issue 41 item 4): the camera scenarios in order (the headline first), and per
scenario the paired intervals of one method against another, the same-pick rates, the time
to converge, the planning-time reductions, the error envelopes and the yaw reading.

Built from the dict :func:`opnav.landing.report.combine_scenarios` writes (or one
scenario's :func:`opnav.landing.report.scenario_summary`); the verdicts, margins and words
are the report's. Methods are the planner's names (``depth``, ``svd``, ...). Units: m, s,
%, deg, us.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, NamedTuple

#: the per-run errors the paired equivalence intervals cover (landing.equivalence.PRIMARY_METRICS)
PRIMARY = ("lastlm_pos_err_m", "lmrms_pos_err_m")
#: where only B-T3's pair table pairs two methods: descent RMS and touchdown error (95 % intervals)
PAIR_METRICS = ("rms_pos", "final_pos")
#: the 3-sigma envelopes B-C10 compares (B-T3 columns)
ENVELOPES = ("rms_vel_err_mps_3sigma", "rms_att_err_deg_3sigma")


class Interval(NamedTuple):
    """A paired difference, method minus reference (m): its mean and interval, beside the
    reference's own mean (the scale an equivalence margin is relative to)."""

    mean: float
    lo: float
    hi: float
    reference_mean: float


class FasterTime(NamedTuple):
    """Depth minus SVD time to converge (s, mean and interval) over ``n_runs`` paired runs,
    the time at which the position error first stays below ``threshold_m``."""

    mean_s: float
    lo_s: float
    hi_s: float
    n_runs: Any
    threshold_m: Any


@dataclass(frozen=True)
class MethodNumbers:
    """One method's row of B-T3 as the claims read it: the median planning call (us), the
    planning-time reduction against SVD on the configured path and the other one (%, with
    their sd; None where not timed), the velocity and attitude 3-sigma envelopes
    (:data:`ENVELOPES`) and the mean descent RMS and touchdown errors (m, :data:`PAIR_METRICS`).
    Values as the summary holds them (a number, or None)."""

    median_plan_time_us: Any = None
    reduction_vs_svd_pct: Any = None
    reduction_vs_svd_pct_std: Any = None
    reduction_vs_svd_alt_pct: Any = None
    reduction_vs_svd_alt_pct_std: Any = None
    envelopes: Mapping[str, Any] = field(default_factory=dict)
    error_means_m: Mapping[str, Any] = field(default_factory=dict)

    @classmethod
    def from_json(cls, row: Mapping[str, Any]) -> MethodNumbers:
        return cls(median_plan_time_us=row.get("median_plan_time_us"),
                   reduction_vs_svd_pct=row.get("time_reduction_vs_svd_pct"),
                   reduction_vs_svd_pct_std=row.get("time_reduction_vs_svd_pct_std"),
                   reduction_vs_svd_alt_pct=row.get("time_reduction_vs_svd_alt_pct"),
                   reduction_vs_svd_alt_pct_std=row.get("time_reduction_vs_svd_alt_pct_std"),
                   envelopes={c: row.get(c) for c in ENVELOPES},
                   error_means_m={q: row.get(f"{q}_err_m_mean", math.nan) for q in PAIR_METRICS})

    def reductions(self) -> list[tuple[str, float, Any]]:
        """(``path`` | ``alt``, reduction %, its sd) for each path timed."""
        return [(p, v, sd) for p, v, sd in (("path", self.reduction_vs_svd_pct, self.reduction_vs_svd_pct_std),
                                            ("alt", self.reduction_vs_svd_alt_pct, self.reduction_vs_svd_alt_pct_std))
                if v is not None]


@dataclass(frozen=True)
class ScenarioClaims:
    """One camera scenario of B-summary.json (module docstring)."""

    name: str
    methods: Mapping[str, MethodNumbers]
    eval_path: str | None = None
    depth_faster: FasterTime | None = None
    yaw_converges: bool | None = None
    multi_optimum_pct: Any = None
    n_runs: Any = None
    equivalence: Mapping[str, Any] = field(default_factory=dict, repr=False)
    pairs: Mapping[str, Mapping[str, Any]] = field(default_factory=dict, repr=False)

    @classmethod
    def from_json(cls, name: str, s: Mapping[str, Any]) -> ScenarioClaims:
        cf = (s.get("converges_faster") or {}).get("depth")
        return cls(name=name, methods={m: MethodNumbers.from_json(r or {}) for m, r in (s.get("methods") or {}).items()},
                   eval_path=s.get("eval_path"),
                   depth_faster=(FasterTime(float(cf.get("mean_s", math.nan)), float(cf.get("lo_s", math.nan)),
                                            float(cf.get("hi_s", math.nan)), cf.get("n_runs"), cf.get("threshold_m"))
                                 if cf else None),
                   yaw_converges=s.get("yaw_converges"), multi_optimum_pct=s.get("multi_optimum_pct"),
                   n_runs=s.get("n_runs"), equivalence=s.get("equivalence") or {}, pairs=s.get("pairs") or {})

    def method(self, m: str) -> MethodNumbers:
        """``m``'s numbers (all None when the summary does not hold the method)."""
        return self.methods.get(m) or MethodNumbers()

    def paired(self, method: str, reference: str) -> dict[str, Interval] | None:
        """The paired intervals of ``method`` minus ``reference``: {metric: :class:`Interval`},
        or None if the summary pairs them nowhere. The equivalence section (90 % intervals of
        the landmark-phase errors, :data:`PRIMARY`) where it holds the pair, else B-T3's pair
        table (95 % intervals of the descent RMS and touchdown errors, :data:`PAIR_METRICS`)."""
        eq = self.equivalence
        if eq.get("reference") == reference or (reference == "svd" and "reference" not in eq and eq):
            res = (eq.get("methods") or {}).get(method) or {}
            means = {q: ((eq.get("metrics") or {}).get(q) or {}).get("means", {}) for q in PRIMARY}
            if all(q in res for q in PRIMARY):
                return {q: Interval(float(res[q]["mean"]), float(res[q]["lo"]), float(res[q]["hi"]),
                                    float(means[q].get(reference, math.nan))) for q in PRIMARY}
        for a, b, sign in ((method, reference, 1.0), (reference, method, -1.0)):
            p = self.pairs.get(f"{a}_vs_{b}")
            if p is None:
                continue
            out = {}
            for q in PAIR_METRICS:
                m, lo, hi = (float(p[f"d_{q}_m"]), float(p[f"d_{q}_lo_m"]), float(p[f"d_{q}_hi_m"]))
                if sign < 0:
                    m, lo, hi = -m, -hi, -lo
                ref = self.methods.get(reference)
                out[f"{q}_err_m"] = Interval(m, lo, hi, float(ref.error_means_m[q]) if ref is not None else math.nan)
            return out
        return None

    def same_pick_pct(self, method: str) -> float:
        """How often ``method`` picks the reference's landmark (% of planning calls; NaN: not counted)."""
        v = (((self.equivalence.get("methods") or {}).get(method)) or {}).get("same_pick_pct")
        return float(v) if v is not None else math.nan


@dataclass(frozen=True)
class LandingSummary:
    """B-summary.json for the claims: the scenarios with the headline one first, and the
    headline's initial thrust tilt and azimuth (deg; None when absent)."""

    headline: str
    scenarios: tuple[ScenarioClaims, ...]
    initial_tilt_deg: float | None = None
    initial_azimuth_deg: float | None = None

    @classmethod
    def from_json(cls, summary: Mapping[str, Any]) -> LandingSummary:
        """From the combined dict (``scenarios``, ``headline_scenario``) or, for an older
        summary, one scenario's dict (its ``scenario`` name, else ``headline``)."""
        scen = summary.get("scenarios") or {summary.get("scenario", "headline"): summary}
        head = summary.get("headline_scenario") or next(iter(scen))
        order = [head] + [k for k in scen if k != head]
        tilt, az = summary.get("initial_tilt_deg"), summary.get("initial_azimuth_deg")
        return cls(headline=head, scenarios=tuple(ScenarioClaims.from_json(k, scen[k]) for k in order),
                   initial_tilt_deg=None if tilt is None else float(tilt),
                   initial_azimuth_deg=None if az is None else float(az))

    def by_name(self) -> dict[str, ScenarioClaims]:
        """The scenarios by name, the headline first."""
        return {s.name: s for s in self.scenarios}
