"""Misalignment by batch maximum likelihood over the whole data window, CasADi + IPOPT (A-X2 (b)).

Description
    The model is the one the EM-EKF uses (SPEC A.1-A.2, paper eq. 2-6): in
    deviations from the reference trajectory,

        dX_k = Phi_{k,k-1} dX_{k-1} + W_{k-1},          W ~ N(0, Q),
        z_k  = A_m(theta) (u_ref,k - C_k dr_k) + v_k,   v ~ N(0, R_k),
        dX_0 ~ N(x0, P0),                                A_m = I - [theta x],

    linear-Gaussian in the state for any fixed ``theta``. The batch estimate
    maximises the *marginal* likelihood of the whole window, with the initial
    state and every process-noise sample integrated out exactly:

        -log p(z_1..z_n | theta) = sum_k 1/2 [ log det S_k(theta)
                                   + nu_k(theta)^T S_k(theta)^-1 nu_k(theta) + 3 log 2 pi ],

    the prediction-error (innovation) decomposition, where ``nu_k`` and
    ``S_k`` are the innovation and its covariance of the Kalman filter run
    with that ``theta`` from ``N(x0, P0)``. This is exact for the model above
    (no linearisation in ``theta`` or in the state: ``A_m(theta)`` enters ``H_k``
    and ``z_hat_k`` as written), and it is the function whose stationary
    points are the fixed points of the EM iteration (the EM maximises the same
    observed-data likelihood, paper eq. 10-26). The initial state is estimated
    together with theta: the filter/smoother at ``theta_hat`` gives its
    posterior. (Minimising the joint ``-log p(z, X_0 | theta)`` over ``X_0``
    instead would differ by ``1/2 log det`` of the posterior information of
    ``X_0``, which depends on theta through ``A_m^T R^-1 A_m``, and cannot
    absorb the process noise; the innovation form needs neither approximation.)

    A Gaussian prior ``N(theta_0, sigma_theta^2 I)`` is added, with
    ``sigma_theta`` from the config (default 3600 arcsec). It carries no
    practical information on (tx, ty) (its curvature is orders of magnitude
    below the data's) and pins the unobservable roll ``tz`` at ``theta_0``,
    as the EM's M-step does by holding unobservable directions fixed.

Implementation
    One filter step is written once in CasADi SX, folded over the samples with
    ``mapaccum`` (both optionally JIT-compiled with the system C compiler), and the
    gradient comes from CasADi's reverse mode. The decision variable is theta
    in arcsec (O(1-10)); the objective is in nats. IPOPT runs with a
    limited-memory Hessian (3 unknowns; the exact Hessian costs ~10 gradients).
    Checkpoints (e.g. the ends of the EM segments) are solved in turn, each
    warm-started at the previous solution, so the "data needed to converge"
    rule of the EM applies unchanged.

Units: km, km/s, rad (theta in arcsec only as IPOPT's decision variable).
"""

from __future__ import annotations

import atexit
import shutil
import tempfile
from dataclasses import dataclass

import casadi as ca
import numpy as np

from .dynamics import ARCSEC
from .ekf import Window
from .kalman import LOG2PI

_STEP: dict[bool, ca.Function] = {}
_ACCUM: dict[tuple[int, bool], ca.Function] = {}
_JIT_DIRS: list[str] = []


def _cleanup_jit_dirs() -> None:  # pragma: no cover - process exit
    for d in _JIT_DIRS:  # CasADi's own cleanup is off; a loaded .so may be unlinked on Linux
        shutil.rmtree(d, ignore_errors=True)


atexit.register(_cleanup_jit_dirs)


def kf_step_sx() -> ca.Function:
    """One Kalman-filter step of the model in the module docstring, as a CasADi SX function.

    Inputs: x (6), P (6x6), nll (1), theta (3, rad), Phi (6x6), C (3x3),
    u_ref (3), rvar (3), e = z - u_ref (3), Q (6x6).
    Outputs: filtered x, P, and nll + the step's innovation term.
    """
    x = ca.SX.sym("x", 6)
    P = ca.SX.sym("P", 6, 6)
    nll = ca.SX.sym("nll")
    th = ca.SX.sym("theta", 3)
    Phi = ca.SX.sym("Phi", 6, 6)
    C = ca.SX.sym("C", 3, 3)
    u = ca.SX.sym("u_ref", 3)
    rv = ca.SX.sym("rvar", 3)
    e = ca.SX.sym("e", 3)
    Q = ca.SX.sym("Q", 6, 6)
    xp = Phi @ x
    Pp = Phi @ P @ Phi.T + Q
    T = ca.skew(th)
    Hr = -(ca.SX.eye(3) - T) @ C  # d z / d dr
    uk = u - C @ xp[:3]
    # nu = z - A_m u_k = (z - u_ref) + C dr + [theta x] u_k
    nu = e + C @ xp[:3] + T @ uk
    PHt = Pp[:, :3] @ Hr.T
    S = Hr @ PHt[:3, :] + ca.diag(rv)
    Sinv = ca.inv(S)
    K = PHt @ Sinv
    xn = xp + K @ nu
    Pn = Pp - K @ PHt.T
    Pn = 0.5 * (Pn + Pn.T)
    nlln = nll + 0.5 * (ca.log(ca.det(S)) + ca.dot(nu, Sinv @ nu) + 3.0 * LOG2PI)
    return ca.Function("kf_step", [x, P, nll, th, Phi, C, u, rv, e, Q], [xn, Pn, nlln],
                       ["x", "P", "nll", "theta", "Phi", "C", "u_ref", "rvar", "e", "Q"],
                       ["x_next", "P_next", "nll_next"])


def _jit_options() -> dict:
    """CasADi options that JIT-compile a function with the system C compiler, in a temporary
    directory removed at exit. -O1: gcc takes 1.8-1.9 s for the step, fold and derivatives
    of the full profile's window where -O2 takes 2.6-3.0 s, and the compiled gradient is as
    fast (40 evaluations in 0.19-0.20 s either way; measured). Both give the virtual
    machine's numbers bit for bit (a test checks the compiled fold)."""
    d = tempfile.mkdtemp(prefix="opnav_jit_")
    _JIT_DIRS.append(d)
    return {"jit": True, "compiler": "shell", "jit_cleanup": False,
            "jit_options": {"flags": ["-O1"], "directory": d + "/", "verbose": False, "cleanup": False}}


def kf_step(jit: bool = True) -> ca.Function:
    """The step function, JIT-compiled once per process when ``jit`` and a C compiler work."""
    if jit in _STEP:
        return _STEP[jit]
    f = kf_step_sx()
    if jit:
        try:
            jo = _jit_options()
            # derivative functions (IPOPT's reverse-mode gradient) are compiled too
            f = ca.Function("kf_step_jit", f.sx_in(), f.call(f.sx_in()),
                            dict(jo, jit_name="kf_step", der_options=dict(jo)))
        except RuntimeError:  # no working compiler: the virtual machine gives the same numbers
            f = kf_step_sx()
    _STEP[jit] = f
    return f


def kf_accum(d: int, jit: bool = True) -> ca.Function:
    """The step folded over ``d`` samples (``mapaccum``: x, P, nll carried; per-sample inputs
    side by side), once per process and length. With ``jit`` (and a working compiler) the
    fold and its derivatives are compiled too: the same calls of the compiled step in the
    same order as CasADi's virtual machine makes them (the same numbers, bit for bit; a test
    checks it), without the machine's cost per call (about half of an IPOPT solve)."""
    key = (int(d), bool(jit))
    if key not in _ACCUM:
        step = kf_step(jit)
        f = step.mapaccum(f"kf_{d}", int(d), [0, 1, 2], [0, 1, 2])
        if jit and step.name() == "kf_step_jit":
            try:
                jo = _jit_options()
                f = ca.Function(f"kf_{d}_jit", f.mx_in(), f.call(f.mx_in()),
                                dict(jo, jit_name=f"kf_{d}", der_options=dict(jo)))
            except RuntimeError:  # pragma: no cover - the step compiled, so the fold does
                pass
        _ACCUM[key] = f
    return _ACCUM[key]


@dataclass
class BatchMLResult:
    theta: np.ndarray  # (S, J, 3) rad, solution at each checkpoint
    grad_norm: np.ndarray  # (S, J) |d objective / d theta| at the solution, nats per arcsec
    iterations: np.ndarray  # (S, J) IPOPT iterations
    success: np.ndarray  # (S, J) bool
    nll: np.ndarray  # (S, J) objective at the solution (nats, prior included)


class BatchML:
    """Batch ML of theta for one window geometry, solved at data checkpoints.

    ``checkpoints``: increasing sample counts ``n_j <= win.n``; the estimate
    at ``n_j`` uses samples 1..n_j of the window. The NLPs are built once
    (all Monte-Carlo seeds of a case share the geometry) and solved per seed;
    per-seed data enter as IPOPT parameters.

    Scaling: IPOPT's unknown is ``eta`` with ``theta = theta_s + L eta`` (arcsec),
    ``theta_s`` the starting point and ``L L^T`` a covariance of theta (e.g.
    the Cramér-Rao bound at the checkpoint, :meth:`solve`'s ``metric``). Then
    the Hessian in ``eta`` is close to the identity, and the limited-memory
    IPOPT started from the identity takes nearly Newton steps. The metric only
    preconditions: the solution is the stationary point of the exact objective
    (IPOPT's convergence test is on its exact gradient).
    """

    def __init__(self, win: Window, checkpoints, theta_prior_sigma_rad: float, jit: bool = True,
                 tol: float = 1e-9, max_iter: int = 100):
        cps = [int(c) for c in checkpoints]
        if not cps or cps[0] < 1 or any(b <= a for a, b in zip(cps, cps[1:])) or cps[-1] > win.n:
            raise ValueError(f"checkpoints must increase within 1..{win.n}, got {cps}")
        self.checkpoints = cps
        self.n = cps[-1]
        self.sig = theta_prior_sigma_rad / ARCSEC  # arcsec
        eta = ca.MX.sym("eta", 3)
        th_s = ca.MX.sym("theta_start_as", 3)
        Lm = ca.MX.sym("L", 3, 3)
        th0 = ca.MX.sym("theta0_as", 3)
        x0 = ca.MX.sym("x0", 6)
        P0 = ca.MX.sym("P0", 6, 6)
        e = ca.MX.sym("e", 3, self.n)
        # measurement variances: IPOPT parameters too (default: the window's), so one NLP
        # serves every pixel noise of the geometry (the fold takes them as inputs either way)
        rv = ca.MX.sym("rvar", 3, self.n)
        if np.ndim(win.Rvar) != 2:
            raise ValueError("BatchML: one measurement variance per sample, (n+1, 3), not per seed")
        self.rvar = np.array(win.Rvar[1:self.n + 1], float)
        p = ca.vertcat(th_s, ca.vec(Lm), th0, x0, ca.vec(P0), ca.vec(e), ca.vec(rv))
        th = th_s + Lm @ eta
        Qd = ca.DM(win.Q)
        x, P, nll = x0, P0, ca.MX(0.0)
        prior = 0.5 * ca.sumsqr(th - th0) / self.sig**2
        objectives = []
        a = 0
        for b in cps:
            sl = slice(a + 1, b + 1)
            out = kf_accum(b - a, jit)(x, P, nll, th * ARCSEC,
                          ca.DM(np.hstack(list(win.Phi[sl]))), ca.DM(np.hstack(list(win.C[sl]))),
                          ca.DM(win.u_ref[sl].T), rv[:, a:b], e[:, a:b], Qd)
            x, P, nll = out[0][:, -1], out[1][:, -6:], out[2][-1]
            objectives.append(nll + prior)
            a = b
        opts = {"print_time": False, "ipopt.print_level": 0, "ipopt.sb": "yes",
                "ipopt.hessian_approximation": "limited-memory",
                "ipopt.limited_memory_initialization": "constant",
                "ipopt.limited_memory_init_val": 1.0,
                "ipopt.nlp_scaling_method": "none",
                "ipopt.tol": tol, "ipopt.max_iter": max_iter,
                # no multipliers after the solve (nothing reads them; the bound-free NLP's lam_p
                # costs one more reverse sweep through the whole window per solve)
                "calc_lam_p": False, "calc_lam_x": False}
        self.solvers = [ca.nlpsol(f"batch_ml_{j}", "ipopt", {"x": eta, "p": p, "f": f}, opts)
                        for j, f in enumerate(objectives)]
        # objective and gradient in theta (arcsec) for the stationarity check; L = I, theta_s = 0
        thv = ca.MX.sym("theta_as", 3)
        self.objective = []
        for f in objectives:
            fe = ca.Function("f_eta", [eta, p], [f])
            pt = ca.vertcat(ca.DM.zeros(3), ca.vec(ca.DM.eye(3)), p[12:])
            ft = fe(thv, pt)
            self.objective.append(ca.Function("obj", [thv, p], [ft, ca.gradient(ft, thv)]))
        self._thv, self._p, self._fe, self._eta = thv, p, objectives, eta

    def params(self, e: np.ndarray, x0: np.ndarray, P0: np.ndarray, theta0_rad: np.ndarray,
               theta_start_rad: np.ndarray | None = None, L_rad: np.ndarray | None = None,
               rvar: np.ndarray | None = None) -> np.ndarray:
        """IPOPT parameter vector of one seed: e (n, 3) = z - u_ref for samples 1..n; ``rvar``
        (n, 3) km^2 their measurement variances (default: the window's)."""
        e = np.asarray(e, float)[: self.n]
        rv = self.rvar if rvar is None else np.asarray(rvar, float)[: self.n]
        if rv.shape != (self.n, 3):
            raise ValueError(f"BatchML.params: rvar must be ({self.n}, 3), got {rv.shape}")
        ths = np.zeros(3) if theta_start_rad is None else np.asarray(theta_start_rad, float)
        L = np.eye(3) * ARCSEC if L_rad is None else np.asarray(L_rad, float)
        return np.concatenate([ths / ARCSEC, (L / ARCSEC).ravel(order="F"),
                               np.asarray(theta0_rad, float) / ARCSEC, np.asarray(x0, float),
                               np.asarray(P0, float).ravel(order="F"), e.ravel(), rv.ravel()])

    def hessian(self, j: int = -1) -> ca.Function:
        """Exact Hessian of checkpoint ``j``'s objective w.r.t. theta (arcsec)."""
        if not hasattr(self, "_hess"):
            self._hess = {}
        j = j % len(self.checkpoints)
        if j not in self._hess:
            f, g = self.objective[j](self._thv, self._p)
            self._hess[j] = ca.Function(f"hessian_theta_{j}", [self._thv, self._p],
                                        [ca.jacobian(g, self._thv)])
        return self._hess[j]

    def metric(self, p: np.ndarray, theta_rad: np.ndarray, h_arcsec: float = 1.0) -> np.ndarray:
        """Preconditioner (J, 3, 3) rad^2: the inverse Hessian at ``theta`` for the data in ``p``,
        by central differences of the exact (CasADi) gradient, eigenvalues floored at the
        prior's curvature. (Only a scaling: it does not change the solution. The exact
        Hessian, :meth:`hessian`, takes long to build when JIT-compiled.)"""
        out = np.empty((len(self.checkpoints), 3, 3))
        th = np.asarray(theta_rad, float) / ARCSEC
        for j in range(len(self.checkpoints)):
            H = np.empty((3, 3))
            for i in range(3):
                d = np.zeros(3)
                d[i] = h_arcsec
                gp = np.asarray(self.objective[j](th + d, p)[1]).ravel()
                gm = np.asarray(self.objective[j](th - d, p)[1]).ravel()
                H[:, i] = (gp - gm) / (2.0 * h_arcsec)
            lam, V = np.linalg.eigh(0.5 * (H + H.T))
            lam = np.maximum(lam, 1.0 / self.sig**2)
            out[j] = (V / lam) @ V.T * ARCSEC**2
        return out

    def solve(self, z: np.ndarray, x0: np.ndarray, P0: np.ndarray, theta0: np.ndarray,
              u_ref: np.ndarray, metric: np.ndarray | None = None,
              rvar: np.ndarray | None = None) -> BatchMLResult:
        """Solve every checkpoint for every seed.

        z (S, n+1, 3) km (index 0 ignored); x0 (S, 6); P0 (6, 6) or (S, 6, 6);
        theta0 (S, 3) or (3,) rad, the prior mean and the first starting point;
        u_ref (n+1, 3) of the window; metric (J, 3, 3) or (S, J, 3, 3), rad^2:
        covariance used to scale IPOPT's unknown (default: :meth:`metric` of
        the first seed at its ``theta0``, shared by all seeds); rvar (n+1, 3) km^2 the
        measurement variances (index 0 ignored; default: the window's).
        """
        rv = None if rvar is None else np.asarray(rvar, float)[1:]
        z = np.asarray(z, float)
        S, J = z.shape[0], len(self.checkpoints)
        P0 = np.broadcast_to(P0, (S, 6, 6))
        th0 = np.broadcast_to(np.asarray(theta0, float), (S, 3))
        x0 = np.broadcast_to(np.asarray(x0, float), (S, 6))
        if metric is None:
            metric = self.metric(self.params(z[0, 1:] - u_ref[1:], x0[0], P0[0], th0[0], rvar=rv), th0[0])
        Ls = np.linalg.cholesky(np.broadcast_to(metric, (S, J, 3, 3)))
        out = BatchMLResult(np.empty((S, J, 3)), np.empty((S, J)), np.zeros((S, J), int),
                            np.zeros((S, J), bool), np.empty((S, J)))
        for s in range(S):
            e = z[s, 1:] - u_ref[1:]
            start = th0[s]
            for j, solver in enumerate(self.solvers):
                p = self.params(e, x0[s], P0[s], th0[s], start, Ls[s, j], rv)
                sol = solver(x0=np.zeros(3), p=p)
                st = solver.stats()
                eta = np.asarray(sol["x"]).ravel()
                start = start + Ls[s, j] @ eta
                f, g = self.objective[j](start / ARCSEC, p)
                out.theta[s, j] = start
                out.grad_norm[s, j] = float(np.linalg.norm(np.asarray(g)))
                out.iterations[s, j] = int(st.get("iter_count", -1))
                out.success[s, j] = bool(st.get("success", False))
                out.nll[s, j] = float(f)
        return out
