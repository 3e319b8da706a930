"""The evidence table (``results/paper/evidence.csv``): every number a verdict may read.

One :class:`EvidenceRow` per claim x sample x scope x method x versus x quantity (x setting),
long format. The extractors (:mod:`opnav.report.approach_claims` for paper A,
:mod:`opnav.report.landing_claims` for paper B) turn the pipeline's summaries into *all* the
rows the summaries hold, without any verdict logic; :func:`for_claims` then copies each row
to every claim whose plan entry reads its quantity (``claim_id``; a row no claim reads keeps
``claim_id = ""``). The scorer (:mod:`opnav.report.scorer`) reads only this table and the
analysis plan, and every number a claim row quotes (its cause, ``would_take``, the ours
columns) is the estimate, lo or hi of one of these rows.

Columns (:data:`COLUMNS`; units in ``unit``):

``claim_id``  the claim the row is evidence for (``A-C1``...), ``""``: read by no claim.
``sample``    ``main`` (the build's Monte Carlo), ``replication`` (an independent seed base),
              ``pooled`` (both, :func:`pooled`); for planning times ``replay1`` ... ``replayK``
              (independent replays of the same recorded calls) and ``between_replays``
              (their mean, with the interval of the spread between replays).
``scope``     where it was measured: a camera scenario (paper B: ``interior``, ``site-tilt``)
              or a Table-1 case (paper A: ``T1-01``...); ``""`` for the paper as a whole.
``method``    paper A: the variant label (``literal``, ``roll+growing+squarem``...); paper B:
              the planner method (``depth``, ``svd``, ``random``...); ``""`` for a published value.
``versus``    the baseline or control the method is compared with (a paired difference
              ``method - versus``, a ratio ``method / versus``, a reduction of ``method``'s time
              against ``versus``'s); ``""`` when the row is one method's own value.
``role``      what the method is for the claim: ``as_written`` (the paper as written),
              ``faithful`` (a variant adding something the paper does not state), ``diagnostic``
              (uses the truth), ``beyond`` (beyond the paper), ``compared`` (a baseline's own
              value), ``control`` (a negative control), ``bound`` (an information bound or a
              Monte-Carlo floor), ``published`` (a number of published.yaml), ``derived``
              (computed by the scorer from other rows: where a swept choice flips the verdict,
              the margin at which a condition would pass; ``source`` names the rows).
``quantity``  the quantity's name (:data:`QUANTITIES` defines each, with its unit).
``estimate``  the point estimate (mean, RMS, ratio, count, median...).
``lo, hi``    the interval at ``level`` (NaN: no interval).
``level``     the two-sided interval level (0.9 = 90 %; NaN: no interval).
``n``         the sample behind the estimate: seeds, runs, planning calls or replays.
``unit``      the unit of estimate, lo and hi.
``source``    the output the number comes from (a file and the key inside it).
``se``        the standard error of the estimate (NaN: unknown); with ``n`` it gives the
              interval at any level (:func:`t_interval`) and the test between samples.
``setting``   the value of a swept choice (``arc_s=4100``, ``threshold_m=50``); ``""`` for the
              configured reading a verdict reads.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path

import pandas as pd
from scipy import special

__all__ = ["COLUMNS", "QUANTITIES", "ROLES", "SAMPLES", "Evidence", "EvidenceRow", "Quantity", "for_claims",
           "pooled", "read_csv", "se_from_interval", "t_interval", "t_quantile", "write_csv"]

NAN = math.nan

ROLES = ("as_written", "faithful", "diagnostic", "beyond", "compared", "control", "bound", "published", "derived")
#: the fixed sample names (timing adds replay1 ... replayK)
SAMPLES = ("main", "replication", "pooled", "between_replays")


@dataclass(frozen=True)
class EvidenceRow:
    """One number a verdict may read (module docstring: every field)."""

    claim_id: str
    sample: str
    scope: str
    method: str
    versus: str
    role: str
    quantity: str
    estimate: float
    lo: float = NAN
    hi: float = NAN
    level: float = NAN
    n: int = 0
    unit: str = ""
    source: str = ""
    se: float = NAN
    setting: str = ""

    def __post_init__(self):
        if self.role not in ROLES:
            raise ValueError(f"evidence row {self.quantity}: role {self.role!r} is not one of {ROLES}")
        if not (self.sample in SAMPLES or self.sample.startswith("replay")):
            raise ValueError(f"evidence row {self.quantity}: sample {self.sample!r} is not one of {SAMPLES} "
                             "or replay<k>")

    @property
    def has_interval(self) -> bool:
        return math.isfinite(self.lo) and math.isfinite(self.hi)

    def key(self) -> tuple:
        """What identifies the row within a claim and sample."""
        return (self.scope, self.method, self.versus, self.quantity, self.setting)

    def at_level(self, level: float) -> EvidenceRow:
        """The row with its interval at ``level`` (from ``se`` and ``n``, a t interval); unchanged
        when already there or when it cannot be recomputed (no ``se``)."""
        if math.isfinite(self.level) and abs(self.level - level) < 1e-12:
            return self
        if not (math.isfinite(self.se) and self.n >= 2):
            return self
        lo, hi = t_interval(self.estimate, self.se, self.n, level)
        return replace(self, lo=lo, hi=hi, level=float(level))


COLUMNS = [f.name for f in fields(EvidenceRow)]


@dataclass(frozen=True)
class Quantity:
    """A quantity's definition: its unit, how two samples pool (``mean``: an average over
    ``n`` independent draws, pooled by the combined mean and variance; ``rms``: a root mean
    square over ``n`` seeds; ``none``: not pooled) and what it is."""

    unit: str
    pool: str
    text: str


#: every quantity an extractor writes (a test checks that each row's quantity is here)
QUANTITIES: dict[str, Quantity] = {}


def quantity(name: str, unit: str, pool: str, text: str) -> str:
    """Register a quantity (the extractors call this at import); returns its name."""
    if pool not in ("mean", "rms", "none"):
        raise ValueError(f"quantity {name}: pool {pool!r}")
    old = QUANTITIES.get(name)
    if old is not None and (old.unit, old.pool) != (unit, pool):
        raise ValueError(f"quantity {name} registered twice with different units or pooling")
    QUANTITIES[name] = Quantity(unit, pool, text)
    return name


# ------------------------------------------------------------ intervals
def t_quantile(level: float, n: int) -> float:
    """The two-sided Student-t quantile of a ``level`` interval of a mean of ``n`` draws."""
    if n < 2:
        return NAN
    return float(special.stdtrit(n - 1, 0.5 + level / 2.0))


def t_interval(mean: float, se: float, n: int, level: float) -> tuple[float, float]:
    """(lo, hi) of ``mean +- t(level, n - 1) se``."""
    q = t_quantile(level, n)
    return mean - q * se, mean + q * se


def se_from_interval(lo: float, hi: float, n: int, level: float) -> float:
    """The standard error behind a symmetric t interval ``[lo, hi]`` at ``level`` over ``n`` draws."""
    q = t_quantile(level, n)
    if not (math.isfinite(q) and q > 0 and math.isfinite(lo) and math.isfinite(hi)):
        return NAN
    return (hi - lo) / (2.0 * q)


def rms_se(rms: float, n: int) -> float:
    """Standard error of an RMS error over ``n`` seeds, about ``rms / sqrt(2 n)`` (the same
    allowance as the bound guard's)."""
    return rms / math.sqrt(2.0 * n) if n >= 1 and math.isfinite(rms) else NAN


# ------------------------------------------------------------ the table
class Evidence:
    """A set of evidence rows with lookups by key (what the scorer reads)."""

    def __init__(self, rows: Iterable[EvidenceRow] = ()):
        self.rows: list[EvidenceRow] = list(rows)

    def __len__(self) -> int:
        return len(self.rows)

    def __iter__(self):
        return iter(self.rows)

    def select(self, **kw) -> list[EvidenceRow]:
        """Rows whose fields equal every given value (a list or tuple value: any of them)."""
        out = []
        for r in self.rows:
            ok = True
            for k, v in kw.items():
                x = getattr(r, k)
                if isinstance(v, (list, tuple, set, frozenset)):
                    if x not in v:
                        ok = False
                        break
                elif x != v:
                    ok = False
                    break
            if ok:
                out.append(r)
        return out

    def one(self, **kw) -> EvidenceRow | None:
        """The row matching ``kw`` (None if none; the first if several)."""
        rows = self.select(**kw)
        return rows[0] if rows else None

    def samples(self) -> list[str]:
        return list(dict.fromkeys(r.sample for r in self.rows))

    def frame(self) -> pd.DataFrame:
        return pd.DataFrame([asdict(r) for r in self.rows], columns=COLUMNS)


def for_claims(rows: Iterable[EvidenceRow], reads: Mapping[str, Iterable[str]]) -> list[EvidenceRow]:
    """Each row copied once per claim that reads its quantity (``reads``: claim id -> the
    quantities its plan entry names, :meth:`opnav.report.plan.Plan.reads`); a row no claim
    reads is kept once with ``claim_id = ""``."""
    by_q: dict[str, list[str]] = {}
    for cid, qs in reads.items():
        for q in qs:
            by_q.setdefault(q, []).append(cid)
    out = []
    for r in rows:
        cids = by_q.get(r.quantity, [])
        if not cids:
            out.append(replace(r, claim_id=""))
        out += [replace(r, claim_id=c) for c in cids]
    return out


def pooled(main: Iterable[EvidenceRow], rep: Iterable[EvidenceRow]) -> list[EvidenceRow]:
    """The ``pooled`` sample: every row held by both samples under the same key whose quantity
    pools (:data:`QUANTITIES`): a ``mean`` by the combined mean and variance of the ``n1 + n2``
    draws (from each row's ``se`` and ``n``), an ``rms`` by the root of the combined mean square.
    Rows of quantities that do not pool, or without ``n``, are left out."""
    r2 = {(r.claim_id, r.role) + r.key(): r for r in rep}
    out = []
    for a in main:
        b = r2.get((a.claim_id, a.role) + a.key())
        q = QUANTITIES.get(a.quantity)
        if b is None or q is None or q.pool == "none" or a.n < 1 or b.n < 1:
            continue
        n = a.n + b.n
        if q.pool == "rms":
            est = math.sqrt((a.n * a.estimate ** 2 + b.n * b.estimate ** 2) / n)
            se = rms_se(est, n)
        else:
            if not (math.isfinite(a.se) and math.isfinite(b.se)):
                continue
            est = (a.n * a.estimate + b.n * b.estimate) / n
            v1, v2 = a.se ** 2 * a.n, b.se ** 2 * b.n          # the samples' variances
            var = ((a.n - 1) * v1 + (b.n - 1) * v2 + a.n * b.n / n * (a.estimate - b.estimate) ** 2) / max(n - 1, 1)
            se = math.sqrt(var / n)
        row = replace(a, sample="pooled", estimate=est, se=se, n=n, lo=NAN, hi=NAN, level=NAN,
                      source=f"{a.source} + {b.source}")
        out.append(row.at_level(a.level) if math.isfinite(a.level) else row)
    return out


# ------------------------------------------------------------ csv at the edge
def write_csv(rows: Iterable[EvidenceRow], path: str | Path) -> None:
    Evidence(rows).frame().to_csv(path, index=False)


def read_csv(path: str | Path) -> Evidence:
    """The evidence table from its CSV (empty strings stay strings, numbers floats)."""
    df = pd.read_csv(path, keep_default_na=False, dtype=str)
    rows = []
    num = {"estimate", "lo", "hi", "level", "se"}
    for rec in df.to_dict("records"):
        kw = {}
        for f in fields(EvidenceRow):
            v = rec.get(f.name, "")
            if f.name in num:
                kw[f.name] = float(v) if v not in ("", "nan", "NaN") else NAN
            elif f.name == "n":
                kw[f.name] = int(float(v)) if v not in ("", "nan") else 0
            else:
                kw[f.name] = v
        rows.append(EvidenceRow(**kw))
    return Evidence(rows)
