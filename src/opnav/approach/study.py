"""Paper A in a parameter study (:mod:`opnav.studies`): per-seed results of one estimator.

:func:`run_runs` runs the headline case (T1-01, :func:`opnav.approach.cases.headline_case`;
its pixel noise is ``approach.camera.sigma3_px``) of one scenario variant on the
Monte-Carlo seeds ``seeds`` (streams ``SeedSequence([base_seed, 1, seed])``: the same
measurements for every value and estimator, so comparisons are paired) with one estimator:

* ``em``: the EM-EKF with ``approach.em.method`` (:func:`opnav.approach.cases.run_case`);
  ``em_plain`` / ``em_squarem``: the EM-EKF with that scheme; ``em_growing_squarem``:
  SQUAREM over growing windows (``approach.growing``: the same data, N0 to the end), the
  Table-1 scheme that converges to the ML estimate of all the data (its ``crlb_used`` is
  the bound of all data after N0);
* ``augmented``: the augmented EKF (:func:`opnav.approach.alternatives.run_case_alternatives`),
  from the same start.

One row per seed: the final estimate minus the truth of tx, ty, tz (arcsec), the
RMS navigation error after compensation (km, last ``nav_error.last_fraction`` of the
arc), the data needed to converge (samples), the 1-sigma Cramér-Rao bound of tx and
ty for all the data (:func:`opnav.approach.pipeline.total_bound`; the same for every seed)
and for the data the estimator used (``crlb_used_*``: the EM-EKF's last window,
:func:`opnav.approach.pipeline.segment_bounds`; the augmented EKF uses all data), and
whether the stall rule flags the EM run (``stalled_pct``: 100 or 0; NaN for the augmented EKF).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from . import alternatives as alt
from . import cases
from . import scenario as sc
from .pipeline import segment_bounds, total_bound
from .setup import Setup


@dataclass
class _VariantShared:
    """What the estimators of one variant share in a job: the geometry, the bound of all the data
    after N0 and, per segment mode, the bound of the data the EM's last window used (arcsec)."""

    geo: sc.Geometry
    crlb: np.ndarray
    crlb_used: dict[str, np.ndarray] = field(default_factory=dict)


def run_runs(setup: Setup, variant: str, method: str, seeds, shared: dict | None = None) -> pd.DataFrame:
    """One row per seed (module docstring). ``shared``: one dict for the calls of one job (same
    ``setup``): the estimators of a variant then share its geometry and bounds."""
    seeds = [int(s) for s in seeds]
    case = cases.headline_case(setup)
    shared = {} if shared is None else shared
    key = (setup, variant)
    if key not in shared:
        geo = sc.build_geometry(setup, variant)
        Rvar = geo.measurement_variance(case.sigma3_px)
        shared[key] = _VariantShared(geo, total_bound(setup, geo, Rvar, case.truth_arcsec, variant))
    geo, crlb = shared[key].geo, shared[key].crlb
    used = setup.segments.data_samples
    if method.startswith("em"):
        name = method.removeprefix("em").lstrip("_")
        mode = "growing" if name.startswith("growing") else "sliding"
        scheme = name.removeprefix("growing").lstrip("_") or setup.em.method
        s = setup.scheme(mode)
        r = cases.run_case(s, variant, case, seeds, geo=geo, method=scheme)
        used_by_mode = shared[key].crlb_used
        if mode not in used_by_mode:
            used_by_mode[mode] = segment_bounds(s, geo, geo.measurement_variance(case.sigma3_px), case.truth_arcsec,
                                                variant)[-1]
        crlb_used = used_by_mode[mode]
        stalled = 100.0 * np.asarray(r.stalled, float)
        converged = 100.0 * (np.asarray(r.label) == "converged").astype(float)
    elif method == "augmented":
        r = alt.run_case_alternatives(setup, variant, case, seeds, geo, methods=("augmented",)).augmented
        crlb_used, stalled = crlb, np.full(len(seeds), np.nan)
        converged = np.full(len(seeds), np.nan)
    else:
        raise ValueError(f"unknown paper-A study estimator {method!r}")
    err = np.asarray(r.theta_final_arcsec, float) - np.asarray(case.truth_arcsec, float)
    return pd.DataFrame({
        "run": seeds, "variant": variant, "method": method,
        "err_x_arcsec": err[:, 0], "err_y_arcsec": err[:, 1], "err_z_arcsec": err[:, 2],
        "nav_err_after_km": np.asarray(r.nav_err_after_km, float),
        "data_to_converge_samples": np.asarray(r.data_to_converge, float),
        "crlb_x_arcsec": float(crlb[0]), "crlb_y_arcsec": float(crlb[1]),
        "crlb_used_x_arcsec": float(crlb_used[0]), "crlb_used_y_arcsec": float(crlb_used[1]),
        "stalled_pct": stalled,
        "converged_pct": converged,
        "data_samples": used,
    })
