"""B-summary.json typed: what paper B's summary holds of one camera scenario (and of all of
them), read back by meaning for the claims' evidence and the scorecard (issue 56 item 1).

Description
-----------
The summary is written once per camera scenario by the landing summary job (the report layer's
``opnav.report.landing.summary.scenario_summary`` with this package's tests, replays and
counts) and gathered by ``combine_scenarios``; its readers take it through
:meth:`BSummary.from_json` / :meth:`ScenarioSummary.from_json` and read attributes, never the
document's keys. Every part is optional in the document (a summary of an older build, a test's
hand-made part): a missing number reads NaN, a missing section None or empty. Where a reader
must tell a key that is absent from one written as null (JSON's NaN), the field is ``None`` for
absent and NaN for null (:func:`_opt`).

The records: :class:`Stat` (mean, median, 3-sigma over the runs), :class:`PairedTest` and
:class:`EquivalenceResult` / :class:`EquivalenceSection` (``opnav.landing.equivalence``'s paired
test of one method / of every method against one reference), :class:`ConvergesFaster`
(``equivalence.converges_faster``), :class:`YawSigma`, the planning-time evidence
(:class:`BetweenReplays`, :class:`ReplayReading`, :class:`Decomposition`,
:class:`OverheadCurve`, :class:`PlanningTime`: ``timing_summary.planning_time_evidence``) and the
one-replay comparison of older summaries (:class:`VsDepth`), :class:`OptimaCount`
(``optima.count_summary``). B-T3's rows (``methods``) stay rows of a table, keyed by column.

Units: m, s, deg, us, %.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Mapping

__all__ = ["Stat", "PairedTest", "MetricMargin", "EquivalenceResult", "EquivalenceSection", "ConvergesFaster",
           "YawSigma", "BetweenReplays", "ReplayReading", "Decomposition", "OverheadCurve", "PlanningTime",
           "VsDepth", "OptimaCount", "ScenarioSummary", "BSummary", "num"]

NAN = math.nan


def num(x: Any) -> float:
    """A number of the document as a float; NaN for null, a missing key or anything else."""
    try:
        return float(x)
    except (TypeError, ValueError):
        return NAN


def _opt(d: Mapping, key: str) -> float | None:
    """``d[key]`` as a float (null: NaN); None if the key is absent."""
    return num(d[key]) if key in d else None


def _map(d: Any) -> Mapping:
    return d if isinstance(d, Mapping) else {}


def _floats(x: Any) -> tuple[float, ...]:
    return tuple(num(v) for v in (x or ()))


@dataclass(frozen=True)
class Stat:
    """Mean, median and 3-sigma of a per-run error over the runs (``errors.<method>.<quantity>``)."""

    mean: float = NAN
    median: float = NAN
    sigma3: float | None = None

    @classmethod
    def from_json(cls, d: Any) -> "Stat":
        d = _map(d)
        return cls(num(d.get("mean")), num(d.get("median")), None if d.get("3sigma") is None else num(d["3sigma"]))


@dataclass(frozen=True)
class PairedTest:
    """One metric of a paired equivalence test: the mean of ``method - reference`` (m), its
    interval at ``level``, its se, the runs, the margin, the TOST p-value and the outcome."""

    mean: float = NAN
    lo: float = NAN
    hi: float = NAN
    se: float = NAN
    level: float = NAN
    n: int = 0
    margin: float = NAN
    p: float = NAN
    equivalent: bool = False

    @classmethod
    def from_json(cls, d: Any) -> "PairedTest":
        d = _map(d)
        return cls(num(d.get("mean")), num(d.get("lo")), num(d.get("hi")), num(d.get("se")), num(d.get("level")),
                   int(d.get("n") or 0), num(d.get("margin")), num(d.get("p")), bool(d.get("equivalent", False)))


@dataclass(frozen=True)
class MetricMargin:
    """One metric of an equivalence section: every method's mean (m), the margin and its rule."""

    means: Mapping[str, float] = field(default_factory=dict)
    margin: float = NAN
    reference_mean: float = NAN
    rel: float = NAN
    best: tuple[str, ...] = ()
    text: str = ""

    @classmethod
    def from_json(cls, d: Any) -> "MetricMargin":
        d = _map(d)
        return cls({str(m): v for m, v in _map(d.get("means")).items()}, num(d.get("margin")),
                   num(d.get("reference_mean")), num(d.get("rel")), tuple(d.get("best") or ()), str(d.get("text") or ""))


@dataclass(frozen=True)
class EquivalenceResult:
    """One method against the section's reference: a :class:`PairedTest` per metric (by metric
    key), the same-pick rate (%, None if not given), the outcome and its sentence."""

    tests: Mapping[str, PairedTest] = field(default_factory=dict)
    same_pick_pct: float | None = None
    equivalent: bool = False
    verdict: str = ""
    text: str = ""

    @classmethod
    def from_json(cls, d: Any) -> "EquivalenceResult":
        d = _map(d)
        tests = {k: PairedTest.from_json(v) for k, v in d.items() if isinstance(v, Mapping) and v}
        sp = d.get("same_pick_pct")
        return cls(tests, None if sp is None else num(sp), bool(d.get("equivalent", False)),
                   str(d.get("verdict") or ""), str(d.get("text") or ""))


@dataclass(frozen=True)
class EquivalenceSection:
    """Every tested method against one ``reference`` (``equivalence``, or one of
    ``equivalence_vs_baselines``): alpha of each one-sided test and the relative margin (None:
    absent), the metrics' margins and each method's result, in the document's order."""

    reference: str | None = None
    alpha: float | None = None
    margin_rel: float | None = None
    metrics: Mapping[str, MetricMargin] = field(default_factory=dict)
    methods: Mapping[str, EquivalenceResult] = field(default_factory=dict)

    @classmethod
    def from_json(cls, d: Any) -> "EquivalenceSection":
        d = _map(d)
        return cls(None if d.get("reference") is None else str(d["reference"]), _opt(d, "alpha"),
                   _opt(d, "margin_rel"),
                   {k: MetricMargin.from_json(v) for k, v in _map(d.get("metrics")).items()},
                   {m: EquivalenceResult.from_json(v) for m, v in _map(d.get("methods")).items()})


@dataclass(frozen=True)
class ConvergesFaster:
    """First time below ``threshold_m``, ``method - versus`` (s): mean, interval at ``level``
    (NaN: not given), se, runs, the smallest difference that counts, the outcome and its words."""

    versus: str | None = None
    mean_s: float = NAN
    lo_s: float = NAN
    hi_s: float = NAN
    se_s: float = NAN
    level: float = NAN
    threshold_m: float = NAN
    min_difference_s: float | None = None
    n_runs: int = 0
    verdict: str = ""
    text: str = ""

    @classmethod
    def from_json(cls, d: Any) -> "ConvergesFaster":
        d = _map(d)
        return cls(d.get("versus") or None, num(d.get("mean_s")), num(d.get("lo_s")), num(d.get("hi_s")),
                   num(d.get("se_s")), num(d.get("level")), num(d.get("threshold_m")), _opt(d, "min_difference_s"),
                   int(d.get("n_runs") or 0), str(d.get("verdict") or ""), str(d.get("text") or ""))


@dataclass(frozen=True)
class YawSigma:
    """The yaw error's Monte-Carlo 3-sigma at the start and at touchdown (deg) of ``method``."""

    method: str | None = None
    start: float = NAN
    end: float = NAN
    n_runs: int = 0

    @classmethod
    def from_json(cls, d: Any) -> "YawSigma":
        d = _map(d)
        return cls(d.get("method"), num(d.get("start")), num(d.get("end")), int(d.get("n_runs") or 0))


@dataclass(frozen=True)
class BetweenReplays:
    """A planning-time statistic over independent replays (``interval`` ``between_replays``:
    mean, interval, sd between the replays' readings ``per_replay``), or one replay's with a
    bootstrap interval over the calls (``interval`` ``bootstrap``, its ``path`` and calls). A
    key absent from the document is None (:func:`_opt`)."""

    mean: float | None = None
    lo: float = NAN
    hi: float = NAN
    level: float = NAN
    sd_between: float | None = None
    per_replay: tuple[float, ...] = ()
    interval: str | None = None
    path: str | None = None
    n_calls: int = 0

    @classmethod
    def from_json(cls, d: Any) -> "BetweenReplays":
        d = _map(d)
        return cls(_opt(d, "mean"), num(d.get("lo")), num(d.get("hi")), num(d.get("level")), _opt(d, "sd_between"),
                   _floats(d.get("per_replay")), d.get("interval"), d.get("path") or None, int(d.get("n_calls") or 0))


@dataclass(frozen=True)
class ReplayReading:
    """One independent replay: calls replayed, each method's median call (us)."""

    n_calls: int = 0
    median_us: Mapping[str, float] = field(default_factory=dict)

    @classmethod
    def from_json(cls, d: Any) -> "ReplayReading":
        d = _map(d)
        return cls(int(d.get("n_calls") or 0), {str(m): v for m, v in _map(d.get("median_us")).items()})


@dataclass(frozen=True)
class Decomposition:
    """A call's two parts for one method: the cost of one evaluation, the shared part and the
    evaluations per call (us; None where the document does not give one)."""

    per_eval_us: float | None = None
    shared_us: float | None = None
    evals_per_call: float | None = None

    @classmethod
    def from_json(cls, d: Any) -> "Decomposition":
        d = _map(d)
        get = lambda k: None if d.get(k) is None else num(d[k])   # noqa: E731
        return cls(get("per_eval_us"), get("shared_us"), get("evals_per_call"))


@dataclass(frozen=True)
class OverheadCurve:
    """Method ``a``'s reduction against ``b`` (%) as a function of the shared part (us)."""

    a: str = "depth"
    b: str = "svd"
    shared_us: tuple[float, ...] = ()
    reduction_pct: tuple[float, ...] = ()

    @classmethod
    def from_json(cls, d: Any) -> "OverheadCurve":
        d = _map(d)
        return cls(str(d.get("a", "depth")), str(d.get("b", "svd")), _floats(d.get("shared_us")),
                   _floats(d.get("reduction_pct")))


@dataclass(frozen=True)
class PlanningTime:
    """The planning-time evidence (``planning_time``): each replay, per method the median call
    and per pair ``a_vs_b`` the reduction (:class:`BetweenReplays`), the decomposition, the
    overhead curve and the shared part at which the published reduction would hold (us)."""

    replays: tuple[ReplayReading, ...] = ()
    median_us: Mapping[str, BetweenReplays] = field(default_factory=dict)
    reduction_pct: Mapping[str, BetweenReplays] = field(default_factory=dict)
    decomposition: Mapping[str, Decomposition] = field(default_factory=dict)
    overhead_curve: OverheadCurve = field(default_factory=OverheadCurve)
    shared_us_at_published: float | None = None

    @classmethod
    def from_json(cls, d: Any) -> "PlanningTime":
        d = _map(d)
        sp = d.get("shared_us_at_published")
        return cls(tuple(ReplayReading.from_json(x) for x in d.get("replays") or ()),
                   {m: BetweenReplays.from_json(v) for m, v in _map(d.get("median_us")).items()},
                   {k: BetweenReplays.from_json(v) for k, v in _map(d.get("reduction_pct")).items()},
                   {m: Decomposition.from_json(v) for m, v in _map(d.get("decomposition")).items()},
                   OverheadCurve.from_json(d.get("overhead_curve")), None if sp is None else num(sp))


@dataclass(frozen=True)
class VsDepth:
    """One replay's depth-against-a-baseline reduction (``planning_time_vs_depth.<label>``, %)."""

    depth_reduction_pct: float = NAN
    lo: float = NAN
    hi: float = NAN

    @classmethod
    def from_json(cls, d: Any) -> "VsDepth":
        d = _map(d)
        return cls(num(d.get("depth_reduction_pct")), num(d.get("depth_reduction_lo_pct")),
                   num(d.get("depth_reduction_hi_pct")))


@dataclass(frozen=True)
class OptimaCount:
    """B-C8's count (``optima.count_summary``): calls counted, calls with more than one local
    minimum on a side, the most minima of one call (None: not given)."""

    method: str = "depth"
    n_calls: int = 0
    calls_multi_minimum: float = NAN
    max_minima_per_call: float | None = None

    @classmethod
    def from_json(cls, d: Any) -> "OptimaCount":
        d = _map(d)
        mx = d.get("max_minima_per_call")
        return cls(str(d.get("method", "depth")), int(d.get("n_calls") or 0), num(d.get("calls_multi_minimum")),
                   None if mx is None else num(mx))


@dataclass(frozen=True)
class ScenarioSummary:
    """One camera scenario's summary (``B-summary_<scenario>.json``, or one of ``scenarios``)."""

    scenario: str = ""
    n_runs: int = 0
    eval_path: str = ""
    methods: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)
    errors: Mapping[str, Mapping[str, Stat]] = field(default_factory=dict)
    equivalence: EquivalenceSection | None = None
    equivalence_vs_baselines: Mapping[str, EquivalenceSection] = field(default_factory=dict)
    same_pick_max_pct: float | None = None
    controls: tuple[str, ...] = ()
    controls_equivalent: tuple[str, ...] = ()
    converges_faster: Mapping[str, ConvergesFaster] = field(default_factory=dict)
    converges_faster_by_threshold: Mapping[str, Mapping[str, ConvergesFaster]] = field(default_factory=dict)
    yaw_sigma3: YawSigma | None = None
    yaw_converges: bool | None = None
    yaw_reason: str | None = None
    planning_time: PlanningTime | None = None
    planning_time_vs_depth: Mapping[str, VsDepth] = field(default_factory=dict)
    optima: OptimaCount | None = None
    initial_tilt_deg: float | None = None
    initial_azimuth_deg: float | None = None

    @classmethod
    def from_json(cls, d: Any, name: str = "") -> "ScenarioSummary":
        d = _map(d)
        eq = d.get("equivalence")
        pt = d.get("planning_time")
        yaw = d.get("yaw_sigma3_deg")
        opt = d.get("optima")
        return cls(
            scenario=str(d.get("scenario") or name), n_runs=int(d.get("n_runs") or 0),
            eval_path=str(d.get("eval_path") or ""),
            methods={str(m): _map(r) for m, r in _map(d.get("methods")).items()},
            errors={str(m): {str(k): Stat.from_json(v) for k, v in _map(e).items()}
                    for m, e in _map(d.get("errors")).items()},
            equivalence=EquivalenceSection.from_json(eq) if eq else None,
            equivalence_vs_baselines={str(b): EquivalenceSection.from_json(v)
                                      for b, v in _map(d.get("equivalence_vs_baselines")).items()},
            same_pick_max_pct=_opt(d, "same_pick_max_pct"),
            controls=tuple(d.get("controls") or ()), controls_equivalent=tuple(d.get("controls_equivalent") or ()),
            converges_faster={str(m): ConvergesFaster.from_json(v) for m, v in _map(d.get("converges_faster")).items()},
            converges_faster_by_threshold={str(t): {str(m): ConvergesFaster.from_json(v) for m, v in _map(per).items()}
                                           for t, per in _map(d.get("converges_faster_by_threshold")).items()},
            yaw_sigma3=YawSigma.from_json(yaw) if yaw else None,
            yaw_converges=None if d.get("yaw_converges") is None else bool(d["yaw_converges"]),
            yaw_reason=d.get("yaw_reason"),
            planning_time=PlanningTime.from_json(pt) if pt else None,
            planning_time_vs_depth={str(k): VsDepth.from_json(v)
                                    for k, v in _map(d.get("planning_time_vs_depth")).items()},
            optima=OptimaCount.from_json(opt) if opt else None,
            initial_tilt_deg=_opt(d, "initial_tilt_deg"), initial_azimuth_deg=_opt(d, "initial_azimuth_deg"))


@dataclass(frozen=True)
class BSummary:
    """B-summary.json: every camera scenario's summary (``scenarios``, in the document's order)
    and the headline scenario's name; a one-scenario document (no ``scenarios``: ``combined``
    false) reads as that scenario alone. The initial attitude is the document's (the same in
    every scenario)."""

    scenarios: Mapping[str, ScenarioSummary]
    headline: str
    initial_tilt_deg: float | None = None
    initial_azimuth_deg: float | None = None
    combined: bool = True

    @classmethod
    def from_json(cls, d: Any) -> "BSummary":
        if not isinstance(d, Mapping):
            raise TypeError(f"B-summary: expected the summary mapping, got {type(d).__name__}")
        raw = d.get("scenarios") or {d.get("scenario", "headline"): d}
        scen = {str(n): ScenarioSummary.from_json(s, str(n)) for n, s in raw.items()}
        head = d.get("headline_scenario") or next(iter(scen))
        return cls(scen, str(head), _opt(d, "initial_tilt_deg"), _opt(d, "initial_azimuth_deg"),
                   bool(d.get("scenarios")))

    @property
    def headline_first(self) -> list[str]:
        """The scenarios' names, the headline first."""
        return [self.headline] + [k for k in self.scenarios if k != self.headline]
