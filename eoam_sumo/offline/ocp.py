"""Minimum-distance lane change: the nonlinear optimal control problem of eqs. 14-29 in CasADi.

Minimise x(t_f) (eq. 14) over the free final time t_f, subject to the design model
(``model.dynamics``, eqs. 15-20, with the plant's tyre), x(0) = 0 and the given entry speed
(eqs. 21-22, 24), the lateral offset y(t_f) = y_f (eq. 23), the friction ellipse of each axle
within ``friction_use`` of it (eqs. 25, 28), the steering angle limits (eqs. 26-27), the brake
limit and the engine limit (eq. 29).

Final conditions imposed besides eq. 23, so that the ego ends parallel and settled in the next
lane: lateral speed, yaw angle, yaw rate and steering angle all zero at t_f.

Transcription: direct collocation (Radau, ``settings.collocation_degree`` points in each of
``settings.ocp_intervals`` intervals of t_f / N; A-stable, as the friction-scaled tyres make the
lateral dynamics stiff at low speed), piecewise-constant controls (steering rate, longitudinal
force); the path constraints hold at every interval start (with the new control) and at every
collocation point. A small penalty on the control steps (``settings.regularisation``) smooths
the bang-bang optimum. IPOPT solves it; the problem is built once per ``LaneChangeOcp`` with
the entry speed, the friction, the tyre blend and the ellipse bound as parameters.

One friction's speeds are solved as a chain from the highest down (``solve_chain``): each
solve starts from a prediction through the two previous optima (``predicted_guess``) with a
small initial barrier parameter; a step that fails is split into half steps, and only where
those fail too is the point solved with IPOPT's defaults or by continuation from the paper's
tyre and the whole ellipse (``solve_continued``).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, replace

import casadi as ca
import numpy as np

from eoam_sumo.offline.design import DesignSettings
from eoam_sumo.offline.inverse import inverse_dynamics
from eoam_sumo.offline.model import N_CONTROLS, N_STATES, dynamics, split_force
from eoam_sumo.offline.quintic import quintic_lateral, quintic_path
from eoam_sumo.params import G_MPS2, VehicleParams

_STATE_SCALE = np.array([100.0, 30.0, 3.5, 5.0, 0.2, 0.5, 0.1])
_TIME_SCALE_S = 3.0


class OcpError(RuntimeError):
    """An optimal lane change that failed or broke its constraints (names speed and friction)."""


@dataclass(frozen=True)
class OcpSolution:
    """A (candidate) optimal lane change: node states (N+1, 7) and interval controls (N, 2)."""

    speed_mps: float
    mu: float
    duration_s: float
    states: np.ndarray
    controls: np.ndarray
    iterations: int = 0
    colloc_states: np.ndarray | None = None  # (N * degree, 7), interval-major
    tyre_blend: float = 0.0  # the design model's tyre: 0 the paper's, 1 the plant's

    @property
    def distance_m(self) -> float:
        """x(t_f), the cost of eq. 14."""
        return float(self.states[-1, 0])


def solver_options(settings: DesignSettings, patient: bool = False) -> dict:
    """The CasADi/IPOPT options (also written to metadata.json): the speed chain's (a small
    initial barrier parameter, ``settings.attempt_max_iter`` iterations) or, ``patient``, the
    last resort's (IPOPT's default barrier, ``settings.ipopt_max_iter`` iterations)."""
    options: dict = {
        "print_time": False,
        "expand": True,
        "ipopt.print_level": 0,
        "ipopt.sb": "yes",
        "ipopt.tol": settings.ipopt_tol,
        "ipopt.max_iter": settings.ipopt_max_iter,
    }
    if not patient:
        options["ipopt.max_iter"] = settings.attempt_max_iter
        options["ipopt.mu_init"] = settings.ipopt_mu_init
    return options


def _interval_function(params: VehicleParams, degree: int) -> ca.Function:
    """Radau collocation on one interval: (x0, xc, u, mu, h, blend) -> (defects, x_end, path
    values), ``blend`` the tyre blend of ``model.dynamics``.

    ``xc`` holds the states at the ``degree`` collocation points (7 x degree); the defects are
    h f(x_j, u) - sum_r C[r, j] x_r; path values are (ellipse front, ellipse rear, body speed)
    at the interval start (with this interval's control) and at each collocation point.
    """
    tau = np.concatenate(([0.0], ca.collocation_points(degree, "radau")))
    deriv = np.zeros((degree + 1, degree + 1))
    for r in range(degree + 1):
        others = [tau[q] for q in range(degree + 1) if q != r]
        poly = np.poly1d([1.0])
        for q in others:
            poly *= np.poly1d([1.0, -q]) / (tau[r] - q)
        dpoly = poly.deriv()
        deriv[r, :] = [dpoly(t) for t in tau]
    x0 = ca.SX.sym("x0", N_STATES)
    xc = ca.SX.sym("xc", N_STATES, degree)
    u = ca.SX.sym("u", N_CONTROLS)
    mu = ca.SX.sym("mu")
    h = ca.SX.sym("h")
    blend = ca.SX.sym("blend")
    points = ca.horzcat(x0, xc)
    defects, path = [], []
    for j in range(degree + 1):
        xdot, out = dynamics(points[:, j], u, mu, params, ca, blend)
        path += [out.ellipse_front, out.ellipse_rear, out.vx_body_mps]
        if j > 0:
            slope = sum(deriv[r, j] * points[:, r] for r in range(degree + 1))
            defects.append(h * ca.vertcat(*xdot) - slope)
    return ca.Function(
        "radau_interval",
        [x0, xc, u, mu, h, blend],
        [ca.horzcat(*defects), points[:, degree], ca.vertcat(*path)],
    )


class LaneChangeOcp:
    """The lane-change OCP built once; ``solve`` per entry speed and friction. IPOPT's options
    are the speed chain's, or the last resort's if ``patient`` (``solver_options``)."""

    def __init__(self, params: VehicleParams, settings: DesignSettings, patient: bool = False):
        self.params = params
        self.settings = settings
        self.patient = patient
        n, d = settings.ocp_intervals, settings.collocation_degree
        p = params
        opti = ca.Opti()
        self._z = opti.variable(N_STATES, n + 1)
        self._zc = opti.variable(N_STATES, n * d)
        self._w = opti.variable(N_CONTROLS, n)
        self._tau = opti.variable()
        self._v0 = opti.parameter()
        self._mu = opti.parameter()
        self._blend = opti.parameter()
        self._ellipse = opti.parameter()
        mg = p.mass_kg * G_MPS2
        self._control_scale = np.array([p.max_steer_rate_radps, mg])
        scale = ca.diag(ca.DM(_STATE_SCALE))
        xs = scale @ self._z
        xc = scale @ self._zc
        us = ca.diag(ca.DM(self._control_scale)) @ self._w
        t_f = _TIME_SCALE_S * self._tau
        interval = _interval_function(p, d).map(n)
        defects, x_end, path = interval(
            xs[:, :-1],
            xc,
            us,
            ca.repmat(self._mu, 1, n),
            ca.repmat(t_f / n, 1, n),
            ca.repmat(self._blend, 1, n),
        )
        opti.subject_to(ca.vec(defects / ca.repmat(ca.DM(_STATE_SCALE), 1, n * d)) == 0.0)
        opti.subject_to(self._z[:, 1:] == x_end / ca.DM(_STATE_SCALE))
        # eqs. 21, 22, 24 (steering starts centred)
        opti.subject_to(xs[:, 0] == ca.vertcat(0.0, self._v0, 0.0, 0.0, 0.0, 0.0, 0.0))
        # eq. 23 and the settled end: no lateral speed, yaw, yaw rate or steering
        opti.subject_to(xs[2:, -1] == ca.vertcat(settings.lane_change_m, 0.0, 0.0, 0.0, 0.0))
        for j in range(d + 1):
            opti.subject_to(ca.vec(path[3 * j : 3 * j + 2, :]) <= self._ellipse)  # eqs. 25, 28
            opti.subject_to(path[3 * j + 2, :] >= settings.min_speed_fraction * self._v0)
        steer = xs[6, :]
        opti.subject_to(opti.bounded(-p.max_steer_rad, steer, p.max_steer_rad))  # eqs. 26-27
        opti.subject_to(opti.bounded(-settings.max_yaw_rad, xs[4, :], settings.max_yaw_rad))
        opti.subject_to(opti.bounded(-1.0, self._w[0, :], 1.0))  # steering rate limit
        drive = split_force(us[1, :])[1]
        opti.subject_to(opti.bounded(-p.max_brake_force_n, us[1, :], p.max_drive_force_n))
        opti.subject_to(drive * xs[1, :-1] <= p.max_drive_power_w)  # eq. 29, power
        opti.subject_to(opti.bounded(0.1 / _TIME_SCALE_S, self._tau, 30.0 / _TIME_SCALE_S))
        # control steps relative to the steer-rate limit and to the friction force mu m g
        dw = ca.vertcat(
            self._w[0, 1:] - self._w[0, :-1], (self._w[1, 1:] - self._w[1, :-1]) / self._mu
        )
        opti.minimize(xs[0, -1] + settings.regularisation * ca.sumsqr(dw))  # eq. 14
        opti.solver("ipopt", solver_options(settings, patient))
        self._opti = opti
        self._degree = d

    def solve(
        self, speed_mps: float, mu: float, guess: OcpSolution, step: float = 1.0
    ) -> OcpSolution:
        """Solve for this entry speed and friction from ``guess``; raise ``OcpError`` on failure.

        ``step`` in [0, 1] is the continuation parameter: 1 is the problem of the settings
        (tyre ``settings.tyre_blend``, ellipse within ``settings.friction_use``), 0 the paper's
        (its tyre, the whole ellipse), linear in between."""
        opti = self._opti
        st = self.settings
        blend = step * st.tyre_blend
        opti.set_value(self._v0, speed_mps)
        opti.set_value(self._mu, mu)
        opti.set_value(self._blend, blend)
        opti.set_value(self._ellipse, 1.0 + step * (st.friction_use**2 - 1.0))
        opti.set_initial(self._z, (guess.states / _STATE_SCALE).T)
        colloc = guess.colloc_states
        if colloc is None:
            colloc = _interpolate_nodes(guess.states, self._degree)
        opti.set_initial(self._zc, (colloc / _STATE_SCALE).T)
        opti.set_initial(self._w, (guess.controls / self._control_scale).T)
        opti.set_initial(self._tau, guess.duration_s / _TIME_SCALE_S)
        try:
            sol = opti.solve_limited()
        except RuntimeError as exc:  # IPOPT gave up (e.g. restoration failed)
            raise OcpError(
                f"optimal lane change at mu={mu:g}, {speed_mps * 3.6:g} km/h did not "
                f"converge: {opti.stats()['return_status']}"
            ) from exc
        stats = opti.stats()
        if not stats["success"]:
            raise OcpError(
                f"optimal lane change at mu={mu:g}, {speed_mps * 3.6:g} km/h did not converge: "
                f"IPOPT {stats['return_status']} after {stats['iter_count']} iterations"
            )
        return OcpSolution(
            speed_mps=float(speed_mps),
            mu=float(mu),
            duration_s=float(sol.value(self._tau)) * _TIME_SCALE_S,
            states=np.asarray(sol.value(self._z)).T * _STATE_SCALE,
            controls=np.asarray(sol.value(self._w)).T * self._control_scale,
            iterations=int(stats["iter_count"]),
            colloc_states=np.asarray(sol.value(self._zc)).T * _STATE_SCALE,
            tyre_blend=blend,
        )


def _interpolate_nodes(states: np.ndarray, degree: int) -> np.ndarray:
    """Collocation-point states linearly interpolated between the nodes (a guess)."""
    tau = np.asarray(ca.collocation_points(degree, "radau"))
    a, b = states[:-1], states[1:]
    points = [a + t * (b - a) for t in tau]
    return np.stack(points, axis=1).reshape(-1, states.shape[1])


def quintic_guess(
    speed_mps: float, mu: float, params: VehicleParams, settings: DesignSettings
) -> OcpSolution:
    """Initial guess: the quintic at constant speed with its inverse-dynamics steering."""
    n = settings.ocp_intervals
    t_f = settings.quintic_time_s(mu)
    path = quintic_path(speed_mps, t_f, settings.lane_change_m, samples=4 * n + 1)
    inv = inverse_dynamics(path, params, mu)
    t = np.linspace(0.0, t_f, n + 1)
    idx = np.arange(0, 4 * n + 1, 4)
    _, dy, _, _ = quintic_lateral(t, t_f, settings.lane_change_m)
    steer = np.clip(inv.steer_rad[idx], -params.max_steer_rad, params.max_steer_rad)
    steer[-1] = 0.0
    states = np.column_stack(
        [
            speed_mps * t,
            np.full(n + 1, speed_mps),
            path.y_m[idx],
            dy,
            inv.yaw_rad[idx],
            inv.yaw_rate_radps[idx],
            steer,
        ]
    )
    steer_rate = np.clip(
        np.diff(steer) / (t_f / n), -params.max_steer_rate_radps, params.max_steer_rate_radps
    )
    controls = np.column_stack([steer_rate, np.zeros(n)])
    return OcpSolution(float(speed_mps), float(mu), t_f, states, controls)


def rescaled_guess(previous: OcpSolution, speed_mps: float) -> OcpSolution:
    """Warm start from the solution at a neighbouring speed: distances scale with speed."""
    ratio = speed_mps / previous.speed_mps
    states = previous.states.copy()
    states[:, 0] *= ratio
    states[:, 1] *= ratio
    assert previous.colloc_states is not None  # every solved chain keeps its collocation states
    colloc = previous.colloc_states.copy()
    colloc[:, :2] *= ratio
    return OcpSolution(
        float(speed_mps),
        previous.mu,
        previous.duration_s,
        states,
        previous.controls.copy(),
        colloc_states=colloc,
        tyre_blend=previous.tyre_blend,
    )


def solve_continued(
    ocp: LaneChangeOcp, speed_mps: float, mu: float, guess: OcpSolution
) -> OcpSolution:
    """Solve the paper's problem (``step`` 0) from ``guess``, then step to the settings' one
    in ``settings.continuation_steps`` equal steps, each warm-started from the last; a step
    that fails is halved (down to 1/16 of one) before the failure is raised."""
    sol = ocp.solve(speed_mps, mu, guess, 0.0)
    step = 0.0
    size = base = 1.0 / ocp.settings.continuation_steps
    while step < 1.0:
        target = min(1.0, step + size)
        try:
            sol = ocp.solve(speed_mps, mu, sol, target)
        except OcpError:
            if size <= base / 16.0:
                raise
            size *= 0.5
            continue
        step = target
        size = min(base, 2.0 * size)
    return sol


def predicted_guess(history: list[OcpSolution], speed_mps: float) -> OcpSolution:
    """Warm start at ``speed_mps`` from the chain's solutions so far (nearest last): the last
    one rescaled (``rescaled_guess``) and extrapolated linearly through the one before it
    (a secant predictor: the optimum moves smoothly with the entry speed)."""
    last = rescaled_guess(history[-1], speed_mps)
    if len(history) < 2:
        return last
    before = rescaled_guess(history[-2], speed_mps)
    w = (speed_mps - history[-1].speed_mps) / (history[-1].speed_mps - history[-2].speed_mps)
    assert last.colloc_states is not None and before.colloc_states is not None
    return replace(
        last,
        duration_s=last.duration_s + w * (last.duration_s - before.duration_s),
        states=last.states + w * (last.states - before.states),
        controls=last.controls + w * (last.controls - before.controls),
        colloc_states=last.colloc_states + w * (last.colloc_states - before.colloc_states),
    )


class _Chain:
    """One friction's speed chain: its solver, and the last resort's built when needed."""

    def __init__(self, ocp: LaneChangeOcp, mu: float):
        self.ocp = ocp
        self.mu = mu
        self._patient: LaneChangeOcp | None = ocp if ocp.patient else None

    def first(self, speed_mps: float) -> OcpSolution:
        """The chain's first (highest) speed, from ``quintic_guess``."""
        guess = quintic_guess(speed_mps, self.mu, self.ocp.params, self.ocp.settings)
        try:
            return self.ocp.solve(speed_mps, self.mu, guess)
        except OcpError:
            return self.last_resort(speed_mps, guess)

    def step(self, history: list[OcpSolution], speed_mps: float, halvings: int) -> OcpSolution:
        """The next speed from ``predicted_guess``; where that fails, two half steps (each
        allowed ``halvings - 1`` further splits), then the last resort."""
        try:
            return self.ocp.solve(speed_mps, self.mu, predicted_guess(history, speed_mps))
        except OcpError:
            if halvings <= 0:
                return self.last_resort(speed_mps, rescaled_guess(history[-1], speed_mps))
        middle = self.step(history, 0.5 * (history[-1].speed_mps + speed_mps), halvings - 1)
        return self.step([*history, middle], speed_mps, halvings - 1)

    def last_resort(self, speed_mps: float, guess: OcpSolution) -> OcpSolution:
        """IPOPT's defaults from ``guess``, then continuation from the paper's problem."""
        if self._patient is None:
            self._patient = LaneChangeOcp(self.ocp.params, self.ocp.settings, patient=True)
        try:
            return self._patient.solve(speed_mps, self.mu, guess)
        except OcpError:
            return solve_continued(self._patient, speed_mps, self.mu, guess)


def chain_speeds_mps(speeds_mps, step_kmh: float) -> list[tuple[float, bool]]:
    """The chain's speeds from the highest down: each asked speed (``True``) and, between
    two of them further apart than ``step_kmh``, equally spaced intermediate ones."""
    ordered = sorted(speeds_mps, reverse=True)
    out = [(ordered[0], True)] if ordered else []
    for hi, lo in itertools.pairwise(ordered):
        n = max(1, math.ceil((hi - lo) * 3.6 / step_kmh - 1e-9))
        out += [(hi + (lo - hi) * k / n, False) for k in range(1, n)]
        out.append((lo, True))
    return out


def solve_chain(ocp: LaneChangeOcp, mu: float, speeds_mps, on_solved=None) -> list[OcpSolution]:
    """Solve one friction's speeds from the highest down, each warm-started from the previous.

    The highest speed starts from ``quintic_guess`` (fast lane changes converge easily from
    it), the next ones from ``predicted_guess``, at most ``settings.chain_step_kmh`` apart
    (``chain_speeds_mps``); a step that fails all the same is halved up to
    ``settings.speed_halvings`` times, then solved by the last resort (``_Chain``).
    ``on_solved(solution)`` is called after each asked speed. Returns the asked speeds'
    solutions, highest first.
    """
    chain = _Chain(ocp, mu)
    halvings = ocp.settings.speed_halvings
    history: list[OcpSolution] = []
    solutions: list[OcpSolution] = []
    for v, asked in chain_speeds_mps(speeds_mps, ocp.settings.chain_step_kmh):
        sol = chain.step(history, v, halvings) if history else chain.first(v)
        history.append(sol)
        if asked:
            solutions.append(sol)
            if on_solved is not None:
                on_solved(sol)
    return solutions
