"""The Cramér-Rao bound of theta for the data an estimate used (SPEC A.3b), per variant.

Description
    :func:`bound_curve` - the CRLB of theta versus data used after ``N0`` for a variant's
    information set (see :mod:`opnav.approach.crlb`); :func:`segment_bounds` - the bound of
    each segment's data; their plural forms run several items, and every window of each, as
    one batched recursion (:func:`opnav.approach.crlb.crlb_curves`); :func:`bound_data` names
    the samples a segment's bound covers. Below :mod:`opnav.approach.cases` (its convergence
    label reads these bounds) and re-exported by :mod:`opnav.approach.pipeline`.
Units: arcsec, samples.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from . import crlb, kalman
from . import scenario as sc
from .ekf import Window, run_filter
from .setup import Setup


def _window(geo: sc.Geometry, Rvar: np.ndarray, zero_q: bool = False) -> Window:
    win = geo.window(Rvar)
    return replace(win, Q=np.zeros_like(win.Q)) if zero_q else win


def _start_covariances(geo: sc.Geometry, win: Window, variant: str) -> np.ndarray:
    """Covariance of the state at every sample (n+1, 6, 6) that a window starting there
    begins with: the prior propagated without data (``prior``, ``roll``) or the theta = 0
    filter's ``P`` (``reference-start``: the truth as mean, with the filter's covariance;
    ``P`` of a linear filter does not depend on the data)."""
    n = win.n
    if sc.START_OF[variant] == "truth":
        z = np.zeros((1, n + 1, 3))
        return run_filter(z, np.zeros((1, 3)), np.zeros((1, 6)), geo.P0, win, predicted=False).Pf[0]
    return kalman.propagate(None, geo.P0, win.Phi, win.Q)[1]


def bound_curve(setup: Setup, geo: sc.Geometry, Rvar: np.ndarray, theta_arcsec, variant: str,
                zero_q: bool = False) -> np.ndarray:
    """1-sigma CRLB (arcsec) of theta after d = 0..n-N0 samples from N0, (n-N0+1, 3): the
    bound of the *cumulative* data (growing windows, all-data estimators).

    ``literal``: all data from t0 with the prior P_X0 (the literal filter start
    re-uses the data before N0, so this is its honest bound); ``prior`` and
    ``roll``: data after N0 with the prior propagated to N0; ``reference-start``
    (diagnostic): data after N0 with the true state known to the filter's P_N0.
    ``zero_q``: the same with no process noise (the truth has none).
    """
    return bound_curves(setup, geo, [(Rvar, theta_arcsec, zero_q)], variant)[0]


def bound_curves(setup: Setup, geo: sc.Geometry, items, variant: str) -> list[np.ndarray]:
    """:func:`bound_curve` of several ``(Rvar, theta_arcsec, zero_q)`` items in one batched recursion."""
    N0 = setup.segments.N0
    a = 0 if sc.START_OF[variant] == "filter" else N0
    wins = [_window(geo, Rvar, zq) for Rvar, _, zq in items]
    P = [geo.P0 if a == 0 else _start_covariances(geo, w.slice(0, N0), variant)[-1] for w in wins]
    B, n1 = len(items), geo.Phi.shape[0] - a
    curves = crlb.crlb_curves(np.broadcast_to(geo.Phi[a:], (B, n1, 6, 6)), np.broadcast_to(geo.C[a:], (B, n1, 3, 3)),
                              np.stack([w.Rvar[a:] for w in wins]), np.stack([w.Q for w in wins]),
                              np.broadcast_to(geo.u_true[a:], (B, n1, 3)), np.stack(P),
                              np.stack([sc.rad(th) for _, th, _ in items]), setup.crlb_prior_sigma_rad,
                              _star_info(geo, slice(a, None), B))
    return [sc.arcsec(c[N0 - a:]) for c in curves]


def _star_info(geo: sc.Geometry, idx, B: int) -> np.ndarray | None:
    """The star images' information on theta at the samples ``idx`` for a batch of B (``stars``)."""
    info = geo.star_info()
    return None if info is None else np.broadcast_to(info[idx], (B,) + info[idx].shape)


def segment_bounds(setup: Setup, geo: sc.Geometry, Rvar: np.ndarray, theta_arcsec, variant: str,
                   zero_q: bool = False) -> np.ndarray:
    """The bound for the data each segment's estimate rests on (L, 3), arcsec, 1-sigma.

    ``growing``: the cumulative data from N0 to the segment's end (:func:`bound_curve`).
    ``sliding``: that one window, started from the variant's state at its first sample
    (prior propagated without data; the filter's covariance for reference-start). The
    ``literal`` start is the theta = 0 filter's estimate, which carries every earlier
    sample: its bound is the cumulative one from t0 to the window's end in both modes.
    """
    return segment_bounds_many(setup, geo, [(Rvar, theta_arcsec, zero_q)], variant)[0]


@dataclass(frozen=True)
class BoundData:
    """The samples a bound rests on (:func:`bound_data`): first and last (1-based after t0), how
    many, and a phrase naming them (the CLI's)."""

    first_sample: int
    last_sample: int
    n_samples: int
    text: str


def bound_data(setup: Setup, variant: str) -> BoundData:
    """The samples the last segment's bound (:func:`segment_bounds`) rests on: ``first`` and
    ``last`` sample indices (1-based after t0 = sample 0), whether the prior enters, and a
    phrase naming them. ``literal``: every sample from t0 (its window starts from the theta = 0
    filter, which carries them all); ``growing``: every sample after N0; ``sliding``: the
    last window."""
    s = setup.segments
    a, b = s.windows()[-1]
    if sc.START_OF[variant] == "filter":
        first, why = 1, "all data from t0 with the prior P_X0: the literal start carries every earlier sample"
    elif s.mode == "growing":
        first, why = s.N0 + 1, f"all data after N0 = {s.N0} (growing segments), {_start_phrase(variant)}"
    else:
        first, why = a + 1, f"the last sliding window, {_start_phrase(variant)}"
    return BoundData(first_sample=int(first), last_sample=int(b), n_samples=int(b - first + 1),
                     text=f"samples {first}..{b} ({why})")


def _start_phrase(variant: str) -> str:
    return ("started from the true state with the filter's P (diagnostic)" if sc.START_OF[variant] == "truth"
            else "started from the prior propagated without data")


def segment_bounds_many(setup: Setup, geo: sc.Geometry, items, variant: str,
                        curves: list[np.ndarray] | None = None) -> list[np.ndarray]:
    """:func:`segment_bounds` of several ``(Rvar, theta_arcsec, zero_q)`` items, every window
    of every item in one batched recursion; ``curves``: their :func:`bound_curves`, if known."""
    windows = setup.segments.windows()
    N0 = setup.segments.N0
    if setup.segments.mode == "growing" or sc.START_OF[variant] == "filter":
        curves = curves if curves is not None else bound_curves(setup, geo, items, variant)
        return [np.stack([c[b - N0] for (_, b) in windows]) for c in curves]
    idx = np.array([np.arange(a, b + 1) for (a, b) in windows])  # (L, N+1): the samples of each window
    start = [a for (a, _) in windows]
    wins = [_window(geo, Rvar, zq) for Rvar, _, zq in items]
    Pa = [_start_covariances(geo, w, variant)[start] for w in wins]
    L, n1 = idx.shape
    B = len(items) * L
    out = crlb.crlb_curves(np.broadcast_to(geo.Phi[idx], (len(items), L, n1, 6, 6)).reshape(B, n1, 6, 6),
                           np.broadcast_to(geo.C[idx], (len(items), L, n1, 3, 3)).reshape(B, n1, 3, 3),
                           np.concatenate([w.Rvar[idx] for w in wins]),
                           np.repeat(np.stack([w.Q for w in wins]), L, axis=0),
                           np.broadcast_to(geo.u_true[idx], (len(items), L, n1, 3)).reshape(B, n1, 3),
                           np.concatenate(Pa), np.repeat(np.stack([sc.rad(th) for _, th, _ in items]), L, axis=0),
                           setup.crlb_prior_sigma_rad,
                           None if geo.stars is None else
                           np.broadcast_to(_window_star_info(geo, windows), (len(items), L, n1, 3, 3)
                                           ).reshape(B, n1, 3, 3))[:, -1]
    return list(sc.arcsec(out).reshape(len(items), L, 3))


def _window_star_info(geo: sc.Geometry, windows) -> np.ndarray:
    """Per sliding window (a, b), the information on theta of each of its samples' star images
    (L, N+1, 3, 3), rad^-2, from the window's own star rows whitened by their joint covariance
    (:meth:`opnav.approach.stars.StarField.select`): the window's star data marginalised exactly
    over the drift and the attitude errors, nothing of the images before it."""
    return np.stack([geo.stars.select(a, b).info_per_sample(b - a) for a, b in windows])
