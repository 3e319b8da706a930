"""Out-of-sample filter tuning of paper B's EKF (bearing-noise scale and update
iterations), chosen on runs of a separate random stream.

Description
-----------
The Monte Carlo's runs use ``SeedSequence([landing.mc.base_seed, i])``; the
tuning runs use ``SeedSequence([landing.tuning.base_seed, i])``, ``i <
landing.tuning.n_runs``, a stream no reported run shares, so the NEES of the
300 reported runs is held-out evidence of consistency.

For each camera scenario and each candidate ``(meas_noise_scale, iterations)``
of ``landing.tuning.candidates`` the tuning runs are flown with
``landing.tuning.method``; a candidate is *consistent* when the mean position
and velocity NEES (over runs and filter times, 3 dof each) lie in the 95 %
band of an ``n_runs`` mean (``montecarlo.nees_band``). The choice is the
consistent candidate with the smallest scale (then the fewest iterations):
the least inflated noise model that is still honest about its errors; if none
is consistent, the smallest scale that is not overconfident (both NEES at most
the band's upper end: an underconfident filter is the safe side), flagged
(``chosen_consistent`` False).
One tuning serves both camera scenarios (one filter): the smallest scale that
meets the best tier in every scenario. :func:`tuning_report` flies and
chooses; ``config_matches`` says whether the configured ``landing.filter`` is
the choice (the pipeline checks and reports it; it does not change the config:
the Monte Carlo is flown with the config).

Retuned variant (:func:`retune`, :func:`heldout`): the paper tuning above is the flown
default; beside it, per camera scenario and on the tuning runs alone, the bearing-noise
scale whose mean position and velocity NEES lie closest to the band's centre (the larger
of the two log distances, :func:`distance_to_centre`): the candidates at the chosen
iterations, then ``landing.tuning.retune_points`` log-spaced scales between the best
candidate's neighbours. :func:`heldout` flies that scale on the Monte Carlo's own runs (the
held-out evidence) and reads its NEES beside the paper tuning's; nothing else is flown
with it. One scale multiplies the filter's bearing noise only, so it moves the position
and velocity NEES together, and a mean over runs follows its largest runs: the tuning
rows keep the median and the largest run's NEES to show how far the errors are from the
Gaussian the filter assumes.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

from opnav.core.tables import OMIT_NONE
from opnav.landing.montecarlo import NeesConsistency
from opnav.landing.setup import Setup, Tuning

__all__ = ["tuning_report", "tuning_rows", "choose", "tuning_row", "distance_to_centre", "retune", "heldout", "errors",
           "retuned_record", "FilterTuning", "Choice", "Candidate", "Evaluated", "Retuned", "ScenarioTuning",
           "TuningReport", "PositionErrors", "HeldOut", "RetunedSide", "RetunedRecord"]

_NAN = math.nan


def _num(v) -> float:
    """A JSON number back in memory: null (a NaN written out) -> NaN."""
    return _NAN if v is None else float(v)


@dataclass(frozen=True)
class FilterTuning:
    """A filter tuning: the bearing-noise scale and the update iterations (``landing.filter``)."""

    meas_noise_scale: float
    iterations: int


@dataclass(frozen=True)
class Choice(FilterTuning):
    """The chosen tuning and the tier it met (``consistent``, ``not_overconfident`` or
    ``smallest worst NEES``)."""

    tier: str = ""


@dataclass(frozen=True)
class Candidate(FilterTuning):
    """One candidate flown on the tuning runs (:func:`tuning_row`): the mean position and velocity
    NEES, whether both lie in the band (``consistent``) or at least not above it
    (``not_overconfident``), the median and largest run's position NEES and the median
    touchdown and last-landmark position errors (m)."""

    nees_pos: float = _NAN
    nees_vel: float = _NAN
    consistent: bool = False
    not_overconfident: bool = False
    nees_pos_run_median: float = _NAN
    nees_pos_run_max: float = _NAN
    final_pos_err_m_median: float = _NAN
    lastlm_pos_err_m_median: float = _NAN

    @classmethod
    def from_json(cls, d: Mapping) -> "Candidate":
        """A candidate's JSON object (null read as NaN)."""
        def typed(k, v):
            return int(v) if k == "iterations" else bool(v) if k in ("consistent", "not_overconfident") else _num(v)

        return Candidate(*(typed(f.name, d[f.name]) for f in dataclasses.fields(Candidate)))


@dataclass(frozen=True)
class Evaluated:
    """A scale the retuning flew and its mean NEES on the tuning runs."""

    meas_noise_scale: float
    nees_pos: float
    nees_vel: float


@dataclass(frozen=True, kw_only=True)
class Retuned(Candidate):
    """The retuned scale of one scenario (:func:`retune`): its tuning row, its ``distance`` to the
    band's ``centre``, the ``band``, ``in_band`` (both NEES in it) and every scale ``evaluated``."""

    distance: float
    centre: float
    band: tuple[float, float]
    in_band: bool
    evaluated: tuple[Evaluated, ...]

    @classmethod
    def from_json(cls, d: Mapping) -> "Retuned":
        c = Candidate.from_json(d)
        return cls(*(getattr(c, f.name) for f in dataclasses.fields(Candidate)), distance=_num(d["distance"]), centre=_num(d["centre"]),
                   band=tuple(_num(x) for x in d["band"]), in_band=bool(d["in_band"]),
                   evaluated=tuple(Evaluated(_num(e["meas_noise_scale"]), _num(e["nees_pos"]), _num(e["nees_vel"]))
                                   for e in d["evaluated"]))


@dataclass(frozen=True)
class ScenarioTuning:
    """Every candidate of one scenario and that scenario's own choice."""

    candidates: tuple[Candidate, ...]
    chosen: Choice


@dataclass(frozen=True)
class TuningReport:
    """The tuning (:func:`tuning_report`; ``tuning.json``): the tuning runs' seed, count, method and
    NEES band, per scenario its candidates and choice, the one tuning for all (``chosen``), per
    scenario the retuned scale, the configured filter and whether it is the choice."""

    base_seed: int
    n_runs: int
    method: str
    band: tuple[float, float]
    scenarios: dict[str, ScenarioTuning]
    chosen: Choice
    retuned: dict[str, Retuned]
    configured: FilterTuning
    config_matches: bool

    @classmethod
    def from_json(cls, d: Mapping) -> "TuningReport":
        """The record of ``tuning.json`` (the file edge)."""
        def choice(c):
            return Choice(float(c["meas_noise_scale"]), int(c["iterations"]), str(c.get("tier", "")))

        return cls(base_seed=int(d["base_seed"]), n_runs=int(d["n_runs"]), method=str(d["method"]),
                   band=tuple(_num(x) for x in d["band"]),
                   scenarios={s: ScenarioTuning(tuple(Candidate.from_json(c) for c in v["candidates"]),
                                                choice(v["chosen"])) for s, v in d["scenarios"].items()},
                   chosen=choice(d["chosen"]),
                   retuned={s: Retuned.from_json(r) for s, r in d["retuned"].items()},
                   configured=FilterTuning(float(d["configured"]["meas_noise_scale"]),
                                           int(d["configured"]["iterations"])),
                   config_matches=bool(d["config_matches"]))


@dataclass(frozen=True)
class PositionErrors:
    """Median position errors (m) of a Monte Carlo at the last landmark update and at touchdown."""

    lastlm_pos_err_m_median: float
    final_pos_err_m_median: float


@dataclass(frozen=True)
class HeldOut:
    """A filter on the Monte Carlo's own runs: its NEES consistency and median position errors
    (written flat: the NEES's keys beside the errors')."""

    nees: NeesConsistency = field(metadata={"json_flatten": True})
    errors: PositionErrors = field(metadata={"json_flatten": True})


@dataclass(frozen=True)
class RetunedSide:
    """One side of :class:`RetunedRecord`: the tuning (scale, iterations), its NEES on the tuning
    runs (mean position and velocity, median and largest run in position; NaN where the configured
    filter is not a candidate), whether the retuned one lay in the tuning runs' band (the retuned
    side only) and the held-out numbers."""

    meas_noise_scale: float
    iterations: int
    tuning_nees_pos: float
    tuning_nees_vel: float
    tuning_nees_pos_run_median: float
    tuning_nees_pos_run_max: float
    heldout: HeldOut = field(metadata={"json_flatten": True})
    tuning_in_band: bool | None = field(default=None, metadata=OMIT_NONE)

    @classmethod
    def from_json(cls, d: Mapping) -> "RetunedSide":
        nees = NeesConsistency.from_json(d)
        return cls(float(d["meas_noise_scale"]), int(d["iterations"]),
                   *(_num(d[f"tuning_{k}"]) for k in ("nees_pos", "nees_vel", "nees_pos_run_median",
                                                       "nees_pos_run_max")),
                   heldout=HeldOut(nees, PositionErrors(_num(d["lastlm_pos_err_m_median"]),
                                                        _num(d["final_pos_err_m_median"]))),
                   tuning_in_band=None if d.get("tuning_in_band") is None else bool(d["tuning_in_band"]))


@dataclass(frozen=True)
class RetunedRecord:
    """The paper tuning and the retuned scale of one scenario side by side on the held-out runs
    (:func:`retuned_record`; ``retuned/<camera>.json``)."""

    scenario: str
    method: str
    n_runs: int
    tuning_n_runs: int
    tuning_band: tuple[float, float]
    paper: RetunedSide
    retuned: RetunedSide

    @classmethod
    def from_json(cls, d: Mapping) -> "RetunedRecord":
        """The record of a ``retuned/<camera>.json`` (the file edge)."""
        return cls(str(d["scenario"]), str(d["method"]), int(d["n_runs"]), int(d["tuning_n_runs"]),
                   tuple(_num(x) for x in d["tuning_band"]), RetunedSide.from_json(d["paper"]),
                   RetunedSide.from_json(d["retuned"]))


def _tiers(rows_by_scn: Mapping[str, list[Candidate]]) -> Choice:
    """The candidate (scale, iterations) chosen jointly over scenarios: per tier
    (consistent, then not overconfident) the smallest scale, then fewest
    iterations, meeting it in every scenario; else the smallest worst NEES."""
    cands = [(r.meas_noise_scale, r.iterations) for r in next(iter(rows_by_scn.values()))]
    by = {c: [next(r for r in rows if (r.meas_noise_scale, r.iterations) == c)
              for rows in rows_by_scn.values()] for c in cands}
    for tier in ("consistent", "not_overconfident"):
        ok = [c for c in cands if all(getattr(r, tier) for r in by[c])]
        if ok:
            return Choice(min(ok)[0], min(ok)[1], tier)
    c = min(cands, key=lambda c: (max(max(r.nees_pos, r.nees_vel) for r in by[c]),) + c)
    return Choice(c[0], c[1], "smallest worst NEES")


def choose(rows: list[Candidate]) -> Choice:
    """The choice for one scenario (:func:`_tiers` of that scenario alone)."""
    return _tiers({"one": rows})


def tuning_rows(setup: Setup, tuning: Tuning) -> list[Candidate]:
    """Fly the tuning runs of one scenario (``setup``: its landing setup) for every candidate of
    ``tuning`` (``landing.tuning``): one :func:`tuning_row` each."""
    if int(tuning.base_seed) == int(setup.mc.base_seed):
        raise ValueError("landing.tuning.base_seed must differ from landing.mc.base_seed "
                         "(the tuning runs must not be the reported runs)")
    return [tuning_row(setup, tuning, scale, iters) for scale, iters in tuning.candidates]


def tuning_row(setup: Setup, tuning: Tuning, scale: float, iters: int) -> Candidate:
    """The tuning runs (``landing.tuning``'s stream, ``n_runs``, ``method``) flown with the
    filter's bearing-noise scale ``scale`` and ``iters`` update iterations: the mean position
    and velocity NEES, whether both lie in the band (``consistent``) or at least not above it
    (``not_overconfident``), the median and largest run's position NEES, and the median
    touchdown and last-landmark position errors (m)."""
    from opnav.landing.montecarlo import nees_band, per_run_stats, run_chunk

    n = int(tuning.n_runs)
    lo, hi = nees_band(n, 3, 0.95)
    cfg = setup.with_filter(meas_noise_scale=float(scale), iterations=int(iters)).with_seed(tuning.base_seed)
    st = per_run_stats(run_chunk(cfg, tuning.method, range(n), pick_ratio=False))
    npos, nvel = float(st["mean_nees_pos"].mean()), float(st["mean_nees_vel"].mean())
    return Candidate(float(scale), int(iters), nees_pos=npos, nees_vel=nvel,
                     nees_pos_run_median=float(st["mean_nees_pos"].median()),
                     nees_pos_run_max=float(st["mean_nees_pos"].max()),
                     consistent=bool(lo <= npos <= hi and lo <= nvel <= hi),
                     not_overconfident=bool(npos <= hi and nvel <= hi),
                     final_pos_err_m_median=float(st["final_pos_err_m"].median()),
                     lastlm_pos_err_m_median=(float(st["lastlm_pos_err_m"].median())
                                              if "lastlm_pos_err_m" in st else math.nan))


def distance_to_centre(row: Candidate, centre: float) -> float:
    """How far a tuning row's NEES is from ``centre`` (the band's centre): the larger of
    ``|ln(nees_pos / centre)|`` and ``|ln(nees_vel / centre)|`` (a factor, either way, on
    either state)."""
    return max(abs(math.log(row.nees_pos / centre)), abs(math.log(row.nees_vel / centre)))


def retune(setup: Setup, tuning: Tuning, rows: list[Candidate], iterations: int) -> Retuned:
    """The retuned bearing-noise scale of one scenario, on its tuning runs only (module
    docstring): among ``rows`` (:func:`tuning_rows`) at ``iterations``, the candidate
    closest to the band's centre (:func:`distance_to_centre`; ties: the smaller scale), then
    ``tuning.retune_points`` scales log-spaced strictly between its neighbouring
    candidates (at the ends half or twice the candidate, never below 1: the filter's noise
    is not assumed smaller than the true one), flown; the closest of
    all. Returns that row, its ``distance``, the ``centre``, ``in_band`` (both NEES in the
    tuning runs' band) and every row ``evaluated`` in scale order."""
    from opnav.landing.montecarlo import nees_band

    lo, hi = nees_band(int(tuning.n_runs), 3, 0.95)
    centre = 0.5 * (lo + hi)
    rows = sorted((r for r in rows if int(r.iterations) == int(iterations)), key=lambda r: r.meas_noise_scale)
    if not rows:
        raise ValueError(f"landing.tuning.candidates: no candidate with {iterations} iterations to retune from")

    def best(rs):
        return min(rs, key=lambda r: (distance_to_centre(r, centre), r.meas_noise_scale))

    b = best(rows)
    scales = [r.meas_noise_scale for r in rows]
    i = scales.index(b.meas_noise_scale)
    left = scales[i - 1] if i > 0 else b.meas_noise_scale / 2.0
    right = scales[i + 1] if i + 1 < len(scales) else b.meas_noise_scale * 2.0
    k = int(tuning.retune_points)
    new = [float(x) for x in np.geomspace(max(left, 1.0), right, k + 2)[1:-1]] if k > 0 else []
    rows = rows + [tuning_row(setup, tuning, x, iterations) for x in new if x not in scales]
    rows.sort(key=lambda r: r.meas_noise_scale)
    b = best(rows)
    return Retuned(**{f.name: getattr(b, f.name) for f in dataclasses.fields(Candidate)},
                   distance=distance_to_centre(b, centre), centre=centre, band=(lo, hi),
                   in_band=bool(lo <= b.nees_pos <= hi and lo <= b.nees_vel <= hi),
                   evaluated=tuple(Evaluated(r.meas_noise_scale, r.nees_pos, r.nees_vel) for r in rows))


def heldout(setup: Setup, method: str, n_runs: int, meas_noise_scale: float, iterations: int) -> HeldOut:
    """``method`` flown on the Monte Carlo's own runs ``0..n_runs-1`` (``setup``'s
    ``mc.base_seed``: never the tuning runs) with the filter's bearing-noise scale and
    iterations set to the given ones: ``montecarlo.nees_consistency`` of those runs and their
    median last-landmark and touchdown position errors (m)."""
    from opnav.landing import montecarlo

    cfg = setup.with_filter(meas_noise_scale=float(meas_noise_scale), iterations=int(iterations))
    d = montecarlo.run_chunk(cfg, method, range(int(n_runs)), pick_ratio=False)
    return HeldOut(montecarlo.nees_consistency(d), errors(d))


def errors(data) -> PositionErrors:
    """Median last-landmark and touchdown position errors (m) of a Monte Carlo."""
    from opnav.landing import montecarlo

    st = montecarlo.per_run_stats(data)
    return PositionErrors((float(st["lastlm_pos_err_m"].median()) if "lastlm_pos_err_m" in st else math.nan),
                          float(st["final_pos_err_m"].median()))


def tuning_report(scenarios: Mapping[str, Setup], tuning: Tuning) -> TuningReport:
    """:func:`tuning_rows` of every camera scenario (name -> its landing setup), the choice per scenario and the one tuning for all (:func:`_tiers`:
    the smallest scale meeting the best tier in every scenario), whether the
    configured ``landing.filter`` (the same in every scenario) is that choice, and per
    scenario the retuned scale (:func:`retune`, at the chosen iterations; ``retuned``)."""
    from opnav.landing.montecarlo import nees_band

    rows = {s: tuning_rows(c, tuning) for s, c in scenarios.items()}
    joint = _tiers(rows)
    retuned = {s: retune(c, tuning, rows[s], joint.iterations) for s, c in scenarios.items()}
    f = next(iter(scenarios.values())).filter
    n = int(tuning.n_runs)
    configured = FilterTuning(float(f.meas_noise_scale), int(f.iterations))
    return TuningReport(base_seed=int(tuning.base_seed), n_runs=n, method=tuning.method,
                        band=tuple(nees_band(n, 3, 0.95)),
                        scenarios={s: ScenarioTuning(tuple(r), choose(r)) for s, r in rows.items()},
                        chosen=joint, retuned=retuned, configured=configured,
                        config_matches=(configured.meas_noise_scale == joint.meas_noise_scale
                                        and configured.iterations == joint.iterations))


def _tuning_nees(row: Candidate | None) -> tuple[float, float, float, float]:
    """A tuning row's mean position and velocity NEES and its median and largest run's position
    NEES (NaN without a row)."""
    if row is None:
        return (math.nan,) * 4
    return (float(row.nees_pos), float(row.nees_vel), float(row.nees_pos_run_median), float(row.nees_pos_run_max))


def retuned_record(tuning: TuningReport, scenario: str, setup: Setup, method: str, n_runs: int,
                   paper_heldout: HeldOut) -> RetunedRecord:
    """The paper tuning and the retuned scale of ``scenario`` side by side on the held-out
    runs: ``tuning`` is :func:`tuning_report`'s record, ``paper_heldout`` the Monte Carlo's own
    ``nees_consistency`` and :func:`errors` of ``method`` (flown with the configured filter);
    the retuned scale is flown by :func:`heldout` on the same ``n_runs`` runs. Each side holds
    its scale, iterations, the tuning runs' NEES (mean, median and largest run in position;
    NaN where the configured filter is not a candidate) and the held-out numbers."""
    conf = tuning.configured
    row = next((c for c in tuning.scenarios[scenario].candidates
                if c.meas_noise_scale == conf.meas_noise_scale and c.iterations == conf.iterations), None)
    r = tuning.retuned[scenario]
    return RetunedRecord(
        scenario=scenario, method=method, n_runs=int(n_runs), tuning_n_runs=int(tuning.n_runs),
        tuning_band=tuple(tuning.band),
        paper=RetunedSide(float(conf.meas_noise_scale), int(conf.iterations), *_tuning_nees(row),
                          heldout=paper_heldout),
        retuned=RetunedSide(float(r.meas_noise_scale), int(r.iterations), *_tuning_nees(r),
                            heldout=heldout(setup, method, n_runs, r.meas_noise_scale, r.iterations),
                            tuning_in_band=bool(r.in_band)))
