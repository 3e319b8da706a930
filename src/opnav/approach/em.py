"""EM estimation of the camera misalignment (paper A sec. 2.2-2.3, eq. 10-27; SPEC A.3).

Description
    E-step: with the smoothed moments ``X_{k|N}, P_{k|N}`` (and ``P_{k,k-1|N}``)
    of one window, the expected complete-data log-likelihood (eq. 21) depends
    on theta only through ``-1/2 sum_k Tr(R_k^-1 B_k(theta))`` (eq. 23, 26).

    M-step (closed form): with the small-angle ``A_m = I - [theta x]`` and the
    Mars vector in the calibrated camera frame ``u_k = A_c^i,k (X_M - r_k)``,
    ``z_k - A_m u_k = e_k - [u_k x] theta`` with ``e_k = z_k - u_k``, so

        Tr(R^-1 B(theta)) = sum_k E[(e_k - U_k theta)^T W_k (e_k - U_k theta)],
        U_k = [u_k x], W_k = R_k^-1,

    is quadratic in theta; its minimiser solves ``N theta = b`` with
    ``N = sum E[U^T W U]``, ``b = sum E[U^T W e]`` (expectations over the
    smoothed Gaussian of ``u_k``). ``N`` is singular along the boresight roll
    tz (``u`` along the camera z axis): directions whose eigenvalue is below
    ``tz_tol`` times the largest are held at their current value and reported
    unobservable.

    Iterations: :func:`em_window` runs plain EM (``method="plain"``) or the
    SQUAREM accelerator of Varadhan & Roland (2008, scheme S3, with the
    stabilising EM step and a monotonicity fall-back to the plain double step,
    ``method="squarem"``). Both never decrease the observed-data
    log-likelihood (prediction-error decomposition, reported per evaluation).

Units: rad inside; arcsec only in outputs.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from opnav.core.compiled import kernel, warms

from .camera import misalignment_small
from .ekf import Window, ekf_step
from .kalman import _loglik1, carray
from .smoother import SmootherResult, bf_back, bf_moments

@dataclass
class EStats:
    """Sufficient statistics of the M-step: ``N theta = b`` (S,3,3), (S,3)."""

    N: np.ndarray
    b: np.ndarray
    J_stars: np.ndarray | None = None  # (3, 3) the star images' part of N (``stars`` variant)


@kernel(inline="always")
def estep_add(obs, sm, stats, work):
    """Add one sample's E-step terms to ``stats = (N (3, 3), b (3,))`` (see :func:`estep`).

    ``obs = (z, C, u_ref, rvar)``: the measurement (3,), A_c^i (3, 3), the reference vector
    (3,) km and the noise variances (3,) km^2; ``sm = (xs (>=3,), Ps (>=3, >=3))`` the smoothed
    moments (position first). With the mean ``m = u_ref - C x_r`` and second moment
    ``M = C P_rr C^T + m m^T`` of ``u``, ``w = 1/R`` and ``U = [u x]`` (``U_ik = -eps_ijk u_j``):
    ``N_kl += sum_i w_i eps_ijk eps_inl M_jn``, ``b_k += sum_i w_i eps_ijk (m_j z_i - M_ji)``.
    ``work = (m (3,), M, CP (3, 3))`` scratch."""
    z, C, u_ref, rvar = obs
    xs, Ps = sm
    N, b = stats
    m, M, CP = work
    for i in range(3):
        m[i] = u_ref[i] - (C[i, 0] * xs[0] + C[i, 1] * xs[1] + C[i, 2] * xs[2])
    for i in range(3):
        for l in range(3):
            CP[i, l] = C[i, 0] * Ps[0, l] + C[i, 1] * Ps[1, l] + C[i, 2] * Ps[2, l]
    for i in range(3):
        for j in range(3):
            M[i, j] = (CP[i, 0] * C[j, 0] + CP[i, 1] * C[j, 1] + CP[i, 2] * C[j, 2]) + m[i] * m[j]
    for i in range(3):
        w = 1.0 / rvar[i]
        # eps_ijk is +1 at (j, k) = (i+1, i+2) and -1 at (i+2, i+1) (mod 3)
        j1 = (i + 1) % 3
        k1 = (i + 2) % 3
        N[k1, k1] += w * M[j1, j1]
        N[k1, j1] -= w * M[j1, k1]
        N[j1, k1] -= w * M[k1, j1]
        N[j1, j1] += w * M[k1, k1]
        b[k1] += w * (m[j1] * z[i] - M[j1, i])
        b[j1] -= w * (m[k1] * z[i] - M[k1, i])


@kernel
def _estep_window(z, xs, Ps, C, u_ref, Rvar, N, b):
    """:func:`estep_add` over samples 1..n for every seed: z (S, n+1, 3); xs (S, n+1, >=3),
    Ps (S, n+1, >=3, >=3); C (n+1, 3, 3); u_ref (n+1, 3); Rvar (n+1, S, 3); N (S, 3, 3), b (S, 3)."""
    work = (np.empty(3), np.empty((3, 3)), np.empty((3, 3)))
    for s in range(z.shape[0]):
        N[s, :, :] = 0.0
        b[s, :] = 0.0
        for t in range(1, z.shape[1]):
            estep_add((z[s, t], C[t], u_ref[t], Rvar[t, s]), (xs[s, t], Ps[s, t]), (N[s], b[s]), work)


@kernel
def _em_map_window(z, A, start, model, out):
    """The E-step statistics of one EM map for every seed, seed by seed in one pass: the EKF
    forward (:func:`opnav.approach.ekf.ekf_step`), the position Bryson-Frazier smoother
    backward (:func:`opnav.approach.smoother.bf_moments`, ``bf_back``) and :func:`estep_add`
    at each sample as its smoothed moments come out (summed n..1), with per-seed buffers
    of one window (no (seeds x samples) arrays). ``z, A, start, model`` as
    :func:`opnav.approach.ekf.filter_window`; fills ``out = (N, b, ll, x_last, P_last)``:
    N (S, 3, 3), b (S, 3), the log-likelihood ll (S,) and the filtered state at the last sample
    x_last (S, 6), P_last (S, 6, 6). Returns the smallest det S."""
    x0, P0 = start
    Phi, C, u_ref, Rvar, Q = model
    N, b, ll, x_last, P_last = out
    S, n1 = z.shape[0], z.shape[1]
    xf = np.empty((n1, 6))
    Pf = np.empty((n1, 6, 6))
    K = np.empty((n1, 6, 3))
    Sinv = np.empty((n1, 3, 3))
    nu = np.empty((n1, 3))
    Hr = np.empty((n1, 3, 3))
    T = np.empty((6, 6))
    step_work = (np.empty((6, 6)), np.empty((6, 3)), np.empty((3, 3)), T)      # ekf_step's
    L = np.empty((6, 6))
    lv = np.empty(6)
    back_work = (np.empty((6, 3)), T, np.empty((6, 6)), np.empty(6), np.empty((3, 3)))  # bf_back's
    xs = np.empty(3)
    Ps = np.empty((3, 3))
    estep_work = (np.empty(3), np.empty((3, 3)), np.empty((3, 3)))
    dmin = np.inf
    for s in range(S):
        for i in range(6):
            xf[0, i] = x0[s, i]
            for j in range(6):
                Pf[0, i, j] = P0[s, i, j]
        acc_ll = 0.0
        for k in range(1, n1):
            det = ekf_step((xf[k - 1], Pf[k - 1]), (Phi[k], Q), (A[s], C[k], u_ref[k], z[s, k], Rvar[k, s]),
                           (xf[k], Pf[k], K[k], Sinv[k], nu[k], Hr[k]), step_work)
            dmin = min(dmin, det)
            if det > 0.0:
                acc_ll += _loglik1(nu[k], Sinv[k], det)
        ll[s] = acc_ll
        for i in range(6):
            x_last[s, i] = xf[n1 - 1, i]
            for j in range(6):
                P_last[s, i, j] = Pf[n1 - 1, i, j]
        L[:, :] = 0.0
        lv[:] = 0.0
        N[s, :, :] = 0.0
        b[s, :] = 0.0
        for k in range(n1 - 1, 0, -1):
            bf_moments(xf[k], Pf[k], L, lv, 0, xs, Ps, T)
            estep_add((z[s, k], C[k], u_ref[k], Rvar[k, s]), (xs, Ps), (N[s], b[s]), estep_work)
            bf_back((K[k], Hr[k], Sinv[k], nu[k]), Phi[k], (L, lv), back_work)
    return dmin


def estep(z: np.ndarray, s: SmootherResult, win: Window) -> EStats:
    """E-step statistics of eq. 23/26 for the closed-form M-step (see module docstring):
    with the mean ``m_k`` and second moment ``E[u u^T] = C P_rr C^T + m m^T`` of ``u_k`` under
    the smoothed Gaussian, ``N = sum_k E[U^T W U]``, ``b = sum_k E[U^T W e]`` (compiled,
    :func:`_estep_window`; a test checks it against the einsums of the definition)."""
    S = z.shape[0]
    Rvar = win.Rvar if win.Rvar.ndim == 3 else win.Rvar[:, None, :]
    N, b = np.empty((S, 3, 3)), np.empty((S, 3))
    c = carray
    _estep_window(c(z), c(s.xs), c(s.Ps), c(win.C), c(win.u_ref), c(np.broadcast_to(Rvar, (win.n + 1, S, 3))), N, b)
    return _with_stars(N, b, win)


def _with_stars(N: np.ndarray, b: np.ndarray, win: Window) -> EStats:
    """The E-step statistics with the star images' normal equations added (``stars``
    variant: a direct measurement of theta), if the window has any."""
    if win.stars is not None and win.star_y is not None:
        from .stars import normal_equations

        J, h = normal_equations(win.stars, win.star_yw)
        return EStats(N + J, b + h, J)
    return EStats(N, b)


def mstep(st: EStats, theta: np.ndarray, tz_tol: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """Closed-form minimiser of Tr(R^-1 B(theta)) in the observable subspace.

    Returns the new theta (S,3) and a boolean (S,3) mask of the eigen-directions
    kept fixed (unobservable), sorted like ``numpy.linalg.eigh``.
    """
    lam, V = np.linalg.eigh(st.N)
    keep = lam > tz_tol * lam[:, -1:]
    if st.J_stars is not None:  # star images observe every direction they inform (tz too), however
        # weakly next to the Mars vector's lateral information: held only where they add nothing
        sj = np.einsum("sik,ij,sjk->sk", V, st.J_stars, V)
        keep |= sj > tz_tol * np.linalg.eigvalsh(st.J_stars)[-1]
    inv = np.where(keep, 1.0 / np.where(keep, lam, 1.0), 0.0)
    r = st.b - np.einsum("sij,sj->si", st.N, theta)
    step = np.einsum("sij,sj,skj,sk->si", V, inv, V, r)
    return theta + step, ~keep


@dataclass
class EMTrace:
    """Per-evaluation history of one EM run over a window."""

    theta: list = field(default_factory=list)  # (S,3) after each map evaluation
    loglik: list = field(default_factory=list)  # (S,) observed-data LL at the evaluated theta
    unobservable: np.ndarray | None = None  # (S,3) bool, of the last M-step
    last_state: tuple | None = None  # (x (S,6), P (S,6,6)) filtered at the window's end, last map


def em_map(theta, z, x0, P0, win, tz_tol):
    """One EM map theta -> theta' (filter, smoother, E-step, M-step) and LL(theta): the
    fused compiled pass :func:`_em_map_window` (the same filter, position smoother and E-step
    as :func:`opnav.approach.ekf.run_filter`, :func:`opnav.approach.smoother.bryson_frazier`
    and :func:`estep`, seed by seed), then :func:`mstep`. Returns theta', LL(theta), the
    unobservable mask and the filtered state at the window's end ``(x (S, 6), P (S, 6, 6))``.

    Fused because the EM iterations dominate paper A's CPU; its measured gain is in
    docs/performance.md ("Measurements formerly in docstrings")."""
    S, n = z.shape[0], win.n
    A = misalignment_small(np.asarray(theta, float))
    Rvar = win.Rvar if win.Rvar.ndim == 3 else win.Rvar[:, None, :]
    N, b, ll = np.empty((S, 3, 3)), np.empty((S, 3)), np.empty(S)
    x_last, P_last = np.empty((S, 6)), np.empty((S, 6, 6))
    c = carray
    dmin = _em_map_window(c(z), c(A), (c(np.broadcast_to(x0, (S, 6))), c(np.broadcast_to(P0, (S, 6, 6)))),
                          (c(win.Phi), c(win.C), c(win.u_ref), c(np.broadcast_to(Rvar, (n + 1, S, 3))), c(win.Q)),
                          (N, b, ll, x_last, P_last))
    if not dmin > 0:
        raise FloatingPointError("innovation covariance not positive definite")
    new, unobs = mstep(_with_stars(N, b, win), theta, tz_tol)
    if win.stars is not None and win.star_y is not None:
        from .stars import loglik

        ll = ll + loglik(win.stars, win.star_yw, theta)
    return new, ll, unobs, (x_last, P_last)


def em_window(z: np.ndarray, theta0: np.ndarray, x0: np.ndarray, P0: np.ndarray, win: Window,
              iterations: int, method: str = "plain", tz_tol: float = 1e-6) -> EMTrace:
    """EM over one window with a budget of ``iterations`` EM maps.

    ``plain``: that many EM iterations (paper M); ``squarem``: ceil(M/3) SQUAREM
    cycles of 3 maps each, i.e. ``3 ceil(M/3)`` maps (6 for M = 5: the budget is
    rounded *up* to whole cycles; :func:`maps_per_segment` gives the count).
    """
    tr = EMTrace()
    theta = np.array(theta0, float)

    def F(th):
        new, ll, unobs, end = em_map(th, z, x0, P0, win, tz_tol)
        tr.theta.append(new)
        tr.loglik.append(ll)
        tr.unobservable = unobs
        tr.last_state = end
        return new, ll

    if method == "plain":
        for _ in range(iterations):
            theta, _ = F(theta)
    elif method == "squarem":
        for _ in range(max(1, -(-iterations // 3))):
            theta = squarem_cycle(theta, F)
    else:
        raise ValueError(f"approach.em.method must be 'plain' or 'squarem', got {method!r}")
    return tr


def maps_per_segment(method: str, iterations: int) -> int:
    """EM map evaluations :func:`em_window` spends on one segment (plain: M; SQUAREM: 3 ceil(M/3))."""
    return iterations if method == "plain" else 3 * max(1, -(-iterations // 3))


def ml_estimate(z: np.ndarray, theta0: np.ndarray, x0: np.ndarray, P0: np.ndarray, win: Window,
                tz_tol: float = 1e-6, max_maps: int = 60, step_tol_rad: float = 1e-4 * np.pi / 648000.0,
                per_seed: bool = True, axes: int = 2) -> tuple[np.ndarray, np.ndarray, EMTrace]:
    """Maximum-likelihood theta of one window's data: SQUAREM cycles from ``theta0`` until
    the cycle step in the first ``axes`` components (2: tx, ty; 3: tz too, where the data
    observe it) is below ``step_tol_rad``, or ``max_maps`` maps.

    ``per_seed`` (default): each seed stops at its own first cycle that meets the step
    criterion and only the seeds still moving are iterated, so the other seeds of the batch
    (a Snakemake job's cases, ``approach.scatter``) no longer decide how long a seed iterates
    (they still touch its last bits, which SQUAREM amplifies to ~1e-4 arcsec on flat
    likelihoods), and stopped seeds cost nothing more. ``per_seed=False``: every seed is
    iterated until all meet it in the same cycle (the whole history of every seed, for the
    convergence study).

    Returns theta_ML (S,3), a per-seed flag that the step criterion was met, and the
    trace of every map (its last entries are the reference iterates; with ``per_seed``, a
    stopped seed keeps its estimate in ``theta`` and has NaN ``loglik``).
    """
    th = np.array(theta0, float)
    S = th.shape[0]
    tr = EMTrace()
    done = np.zeros(S, bool)
    act = np.arange(S)
    P0 = np.asarray(P0, float)
    while len(tr.theta) < max_maps and act.size:
        if act.size < S:               # (only per_seed ever drops seeds)
            t = em_window(z[act], th[act], x0[act], P0[act] if P0.ndim == 3 else P0, win.rows(act),
                          3, "squarem", tz_tol)
        else:
            t = em_window(z, th, x0, P0, win, 3, "squarem", tz_tol)
        for th_m, ll_m in zip(t.theta, t.loglik):
            full, ll = th.copy(), np.full(S, np.nan)
            full[act], ll[act] = th_m, ll_m
            tr.theta.append(full)
            tr.loglik.append(ll)
        if tr.unobservable is None:
            tr.unobservable = np.zeros((S, 3), bool)
        tr.unobservable[act] = t.unobservable
        new = t.theta[-1]
        step_ok = np.abs(new - th[act])[:, :axes].max(1) < step_tol_rad
        th[act] = new
        if per_seed:
            done[act] = step_ok
            act = act[~step_ok]
        else:
            done[:] = step_ok
            if done.all():
                break
    return th, done, tr


def contraction_per_map(theta_start: np.ndarray, theta_end: np.ndarray, theta_ml: np.ndarray,
                        maps: int, floor_rad: float = 1e-6 * np.pi / 648000.0, axes: int = 2) -> np.ndarray:
    """Measured contraction factor per EM map toward the ML estimate of the same data (S,).

    ``(d_end / d_start) ** (1 / maps)`` with ``d = max(|tx - tx_ML|, |ty - ty_ML|)`` (and
    ``|tz - tz_ML|`` when ``axes`` is 3): about 1 means the iteration does not approach its fixed
    point (stalled), 0 means it got there at once. NaN where the start is already within
    ``floor_rad`` of it.
    """
    d0 = np.abs(theta_start - theta_ml)[:, :axes].max(1)
    d1 = np.abs(theta_end - theta_ml)[:, :axes].max(1)
    with np.errstate(divide="ignore", invalid="ignore"):
        rate = (np.maximum(d1, 1e-300) / d0) ** (1.0 / max(maps, 1))
    return np.where(d0 > floor_rad, rate, np.nan)


#: Convergence labels of an EM run (SPEC A.3c as read in issue 28): from the data, not the start.
CONVERGED, STALLED, UNFINISHED = "converged", "stalled", "not converged"


def convergence_labels(dist_ml_arcsec: np.ndarray, rate: np.ndarray, ml_tol_arcsec: float,
                       rate_max: float) -> np.ndarray:
    """Per seed, what the EM run reached, read from the data it used (S,) str:

    * ``converged``: within ``ml_tol_arcsec`` (in tx and ty) of the maximum-likelihood
      estimate of that data, wherever it started;
    * ``stalled``: farther than that, and its measured contraction factor per map toward
      the ML estimate is at least ``rate_max`` (about 1: the iteration does not approach
      its fixed point);
    * ``not converged``: farther than that but still contracting (its map budget ran out).

    Whether a converged estimate means anything is the bound's reading, not this label's
    (:func:`opnav.report.approach.text.reading_text`). Two starts on the same data
    reach the same ML estimate, hence the same label."""
    dist = np.asarray(dist_ml_arcsec, float)
    slow = np.nan_to_num(np.asarray(rate, float), nan=0.0) >= rate_max
    return np.where(dist <= ml_tol_arcsec, CONVERGED, np.where(slow, STALLED, UNFINISHED))


def squarem_cycle(theta0: np.ndarray, F) -> np.ndarray:
    """One SQUAREM (S3) cycle per seed, monotone in the observed-data log-likelihood."""
    th1, ll0 = F(theta0)
    th2, _ = F(th1)
    r = th1 - theta0
    v = th2 - th1 - r
    nr, nv = np.linalg.norm(r, axis=1), np.linalg.norm(v, axis=1)
    alpha = np.where(nv > 0, -nr / np.where(nv > 0, nv, 1.0), -1.0)
    alpha = np.minimum(alpha, -1.0)[:, None]
    th_acc = theta0 - 2.0 * alpha * r + alpha**2 * v
    th3, ll_acc = F(th_acc)
    ok = (ll_acc >= ll0)[:, None]
    return np.where(ok, th3, th2)


@warms
def _warm() -> None:
    """The E-step kernels once with the pipeline's argument types."""
    n1 = 2
    win = Window(np.broadcast_to(np.eye(6), (n1, 6, 6)).copy(), np.broadcast_to(np.eye(3), (n1, 3, 3)).copy(),
                 np.ones((n1, 3)), np.ones((n1, 3)), np.eye(6))
    estep(np.zeros((1, n1, 3)), SmootherResult(np.zeros((1, n1, 3)), np.zeros((1, n1, 3, 3)), None, None), win)
    em_map(np.zeros((1, 3)), np.zeros((1, n1, 3)), np.zeros((1, 6)), np.eye(6), win, 1e-6)
