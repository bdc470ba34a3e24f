"""Independent high-precision reference for the linearised rocking model (mpmath, 30 digits).

This module re-implements, from docs/theory.md alone and without importing any of the project's
solvers, the rules that the exact integrator (``solver_service.core.exact``) follows, in
``mpmath`` arithmetic at ``DPS = 30`` significant digits. It is the yardstick of the
work-precision benchmark (``benchmarks/work_precision.py``) and may be used by tests.

Model (theory §1.4, §1.8), in ``x = phi/phi_ov(s)`` on side ``s = ±1``::

    x'' = p_s**2 * (x - s - q(t)),      q(t) = scale * a_g(t) / (g * lam_s),   g = 9.80665

* uplift from rest when the drive ``-s q(t)`` exceeds 1 (the crossing time is solved exactly);
* impact at ``x = 0``: two-sided ``s -> -s``, ``v -> eta (phi_ov_s/phi_ov_new) v``; one-sided
  ``v -> eta v`` (``eta <= 0``, rebound);
* rest rule: an impact that leaves ``|v| < V_REST_REL * p_new`` ends at rest (theory §10);
  an impact is counted when it arrives with ``|v| >= V_REST_REL * p`` (the exact integrator
  counts the same way);
* a null excursion (back at rest at the very instant of an uplift) holds the body at rest to
  the end of the current cell (theory §10, sub-resolution uplift; counted in ``n_holds``);
* certain collapse during the excitation: ``s x > 1 + max_future|a_g| scale/(g lam_s)`` while
  ``s v > 0`` (theory §10), checked at the end of every closed-form interval;
* after the excitation, the free-rocking outcome of theory §1.8 decides exactly (current
  excursion, then at most one more).

Closed forms and event location
-------------------------------
*Sampled record* (linear acceleration between samples, ``q = q0 + q1 tau`` from the anchor
``(t_a, x_a, v_a)``), written about the anchor so nothing of size ``lam`` cancels
(theory §10)::

    x(tau)  = x_a + v_a sinh(u)/p + A (cosh u - 1) - q1 (sinh u - u)/p,   u = p tau,
    x'(tau) = (v_a - q1) cosh u + A p sinh u + q1,                        A = x_a - s - q0.

With ``e^u = 1 + d`` the turning-point condition ``x' = 0`` is the quadratic
``(v_a - q1 + A p) d**2 + 2 (v_a + A p) d + 2 v_a = 0``, solved in closed form; so every
turning point is exact, ``x`` is monotone between them, and every impact is bracketed by a
sign change and solved by ``mpmath.findroot`` (Anderson-Björck on the bracket, polished by
Newton steps with the analytic derivative; bisection as fallback).

*One-sine (or cosine) pulse* ``a_g = a_p sin(omega t + phase)``, ``0 <= t <= 2 pi/omega``::

    x(t) = s + k sin(omega t + phase) + y_a cosh(p tau) + (y'_a/p) sinh(p tau),
    k = p**2 Q / (p**2 + omega**2),   Q = scale a_p / (g lam_s).

Turning points are transcendental here. The pulse is cut into ``4 * PULSE_SUBCELLS`` cells
(quarter-period boundaries included, so ``q'`` keeps one sign in each cell); in a cell a sign
change of ``x'`` between the ends brackets one turning point, and a possible double zero of
``x'`` (a dip) is looked for at the zero of ``x''`` when ``x''`` changes sign. This assumes
that ``x''`` has at most one zero in a cell of ``p h ~ 0.01``, which holds for the smooth
pulse motions used here. An uplift time (from ``asin``) is moved forward by a few units of
the working precision until the drive is ``>= 1`` there, so that the closed form started at
the uplift moves outward (for records the start is put exactly on the threshold instead).

Inputs are taken as the float64 values the solvers receive (samples, ``p_eq``, ``lam``, ...),
converted to ``mpf`` exactly; ``g`` and ``pi`` are exact to working precision. The reference
and a float64 solver therefore solve the same mathematical problem, and their difference is
the float64 solver's error.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Optional

import mpmath
from mpmath import mp, mpf

__all__ = [
    "DPS",
    "G_EXACT",
    "V_REST_REL",
    "MPModel",
    "MPResult",
    "simulate_mp",
]

#: Working precision [significant decimal digits].
DPS = 30
#: Standard gravity [m/s²], as defined (exact decimal).
G_EXACT = "9.80665"
#: Rest rule: an impact leaving at below ``V_REST_REL * p`` ends in rest (theory §10).
V_REST_REL = 1e-9
#: Pulse cells per quarter period in which turning points are searched.
PULSE_SUBCELLS = 64
#: Newton steps that polish a bracketed root found by ``findroot``.
NEWTON_POLISH = 3
#: Impact times kept in the result (the first ones).
KEEP_IMPACT_TIMES = 1000


@dataclass(frozen=True)
class MPModel:
    """Side constants of a mechanism, as plain numbers (converted to ``mpf`` exactly).

    Parameters
    ----------
    p_pos, p_neg : float
        Frequency parameters of the positive and negative side [rad/s].
    lam_pos, lam_neg : float
        Static load multipliers [-].
    phiov_pos, phiov_neg : float
        Overturning rotations [rad].
    eta : float
        Coefficient of restitution [-] (``<= 0`` one-sided).
    one_sided : bool
        One-sided rocking (only ``x >= 0``).
    """

    p_pos: float
    p_neg: float
    lam_pos: float
    lam_neg: float
    phiov_pos: float
    phiov_neg: float
    eta: float
    one_sided: bool = False

    @classmethod
    def from_model(cls, model: Any) -> MPModel:
        """Read a ``RockingModel``-like object (duck-typed: ``positive``, ``negative``, ...)."""
        pos = model.positive
        neg = model.negative if model.negative is not None else pos
        if model.eta is None:
            raise ValueError("the model needs eta for a time history")
        if getattr(model, "is_directional", False):
            raise ValueError(
                "the reference applies one eta to every impact; this model has two "
                "(eta_to_negative, eta_to_positive)"
            )
        return cls(
            float(pos.p_eq),
            float(neg.p_eq),
            float(pos.lam),
            float(neg.lam),
            float(pos.phi_ov),
            float(neg.phi_ov),
            float(model.eta),
            bool(model.one_sided),
        )

    @classmethod
    def symmetric(cls, p_eq: float, lam: float, eta: float) -> MPModel:
        """Two-sided symmetric mechanism with ``phi_ov = lam``."""
        return cls(p_eq, p_eq, lam, lam, lam, lam, eta, False)


@dataclass
class MPResult:
    """Outcome of one high-precision simulation.

    Attributes
    ----------
    peak : mpf
        Peak ``|phi|/phi_ov`` over the motion including the free-rocking tail [-];
        1 when the body collapses.
    collapsed : bool
        The body can no longer come back (theory §1.8, §10).
    n_impacts : int
        Impacts arriving with ``|v| >= V_REST_REL * p`` during the excitation.
    t_peak : mpf
        Time of the peak [s] (end of the excitation when the peak is in the analytic tail
        of a later excursion it is the start of that tail).
    t_impacts : list of mpf
        The first ``KEEP_IMPACT_TIMES`` impact times [s].
    n_segments : int
        Closed-form segments evaluated (work counter).
    n_holds : int
        Null excursions (back at rest at the instant of uplift) after which the body was
        held at rest to the end of the cell; 0 in ordinary runs.
    runtime_s : float
        Wall-clock time [s].
    dps : int
        Working precision [digits].
    """

    peak: Any
    collapsed: bool
    n_impacts: int
    t_peak: Any
    t_impacts: list[Any] = field(default_factory=list)
    n_segments: int = 0
    n_holds: int = 0
    runtime_s: float = 0.0
    dps: int = DPS

    @property
    def peak_float(self) -> float:
        """``peak`` rounded to float64."""
        return float(self.peak)


# ------------------------------------------------------------------------------------------
# Closed-form segments
# ------------------------------------------------------------------------------------------


def _sinh_minus(u: Any) -> Any:
    """``sinh(u) - u`` without cancellation (series for small ``|u|``)."""
    if abs(u) > mpf("0.1"):
        return mp.sinh(u) - u
    u2 = u * u
    term = u * u2 / 6
    total = term
    k = 3
    tiny = mp.eps * abs(term)
    while abs(term) > tiny:
        term = term * u2 / ((k + 1) * (k + 2))
        total += term
        k += 2
    return total


class _LinearSeg:
    """Flight on side ``s`` under ``q = q0 + q1 tau`` from the anchor ``(x_a, v_a)``."""

    __slots__ = ("a", "p", "q0", "q1", "s", "va", "xa")

    def __init__(self, s: int, p: Any, xa: Any, va: Any, q0: Any, q1: Any) -> None:
        self.s, self.p, self.xa, self.va, self.q0, self.q1 = s, p, xa, va, q0, q1
        self.a = xa - s - q0

    def state(self, tau: Any) -> tuple[Any, Any, Any]:
        """``(x, x', x'')`` at ``tau`` [s] after the anchor."""
        p = self.p
        u = p * tau
        sh = mp.sinh(u)
        h = mp.sinh(u / 2)
        chm1 = 2 * h * h
        x = self.xa + self.va * sh / p + self.a * chm1 - self.q1 * _sinh_minus(u) / p
        v = self.va + (self.va - self.q1) * chm1 + self.a * p * sh
        acc = p * p * (x - self.s - self.q0 - self.q1 * tau)
        return x, v, acc

    def turning_points(self, h: Any) -> list[Any]:
        """Zeros of ``x'`` in ``(0, h)``: the quadratic in ``d = e^{p tau} - 1``."""
        p = self.p
        ap = self.a * p
        qa = self.va - self.q1 + ap
        hb = self.va + ap  # half of the linear coefficient
        qc = 2 * self.va
        roots: list[Any] = []
        if qa == 0:
            if hb != 0:
                roots = [-qc / (2 * hb)]
        else:
            disc = hb * hb - qa * qc
            if disc >= 0:
                sq = mp.sqrt(disc)
                big = -(hb + (sq if hb >= 0 else -sq))
                if big != 0:
                    roots = [big / qa, qc / big]
                else:
                    roots = [mpf(0)]
        d_max = mp.expm1(p * h)
        taus = sorted(mp.log1p(d) / p for d in roots if 0 < d < d_max)
        # x' has a double zero only when it touches 0 without a sign change: keep the points
        # anyway; they only split a monotone piece.
        return taus


class _SineSeg:
    """Flight on side ``s`` under ``q = Q sin(omega t + phase)`` from ``(t_a, x_a, v_a)``."""

    __slots__ = ("k", "om", "p", "ph", "qq", "s", "ta", "xa", "ya", "yda")

    def __init__(
        self, s: int, p: Any, ta: Any, xa: Any, va: Any, qq: Any, om: Any, ph: Any
    ) -> None:
        self.s, self.p, self.ta, self.xa, self.qq, self.om, self.ph = s, p, ta, xa, qq, om, ph
        self.k = p * p * qq / (p * p + om * om)
        th = om * ta + ph
        self.ya = xa - s - self.k * mp.sin(th)
        self.yda = va - self.k * om * mp.cos(th)

    def state(self, tau: Any) -> tuple[Any, Any, Any]:
        """``(x, x', x'')`` at ``tau`` [s] after the anchor."""
        p, om = self.p, self.om
        u = p * tau
        ch, sh = mp.cosh(u), mp.sinh(u)
        th = om * (self.ta + tau) + self.ph
        sn, cs = mp.sin(th), mp.cos(th)
        x = self.s + self.k * sn + self.ya * ch + self.yda * sh / p
        v = self.k * om * cs + self.ya * p * sh + self.yda * ch
        acc = p * p * (x - self.s - self.qq * sn)
        return x, v, acc

    def jerk(self, tau: Any) -> Any:
        """``x'''`` at ``tau`` [1/s³]."""
        _, v, _ = self.state(tau)
        th = self.om * (self.ta + tau) + self.ph
        return self.p * self.p * (v - self.qq * self.om * mp.cos(th))

    def turning_points(self, h: Any, sig0: int) -> list[Any]:
        """Zeros of ``x'`` in ``(0, h)`` (one cell, see the module docstring).

        ``sig0`` is the sign of ``x'`` just after 0 (given at an uplift, where ``x' = x'' = 0``).
        """
        a0 = self.state(mpf(0))[2]
        _, vh, ah = self.state(h)
        s_lo = sig0
        s_hi = _sgn(vh) if vh != 0 else -_sgn(ah)
        if s_lo != s_hi and s_lo != 0 and s_hi != 0:
            return [_root(lambda t: self.state(t)[1], lambda t: self.state(t)[2], mpf(0), h)]
        # Same sign at both ends: a dip of x' needs x'' to change sign against x'.
        if s_lo != 0 and _sgn(a0) == -s_lo and _sgn(ah) == s_lo:
            m = _root(lambda t: self.state(t)[2], self.jerk, mpf(0), h)
            vm = self.state(m)[1]
            if _sgn(vm) == -s_lo:
                z1 = _root(lambda t: self.state(t)[1], lambda t: self.state(t)[2], mpf(0), m)
                z2 = _root(lambda t: self.state(t)[1], lambda t: self.state(t)[2], m, h)
                return [z1, z2]
        return []


def _sgn(z: Any) -> int:
    return 1 if z > 0 else (-1 if z < 0 else 0)


def _root(f: Callable[[Any], Any], df: Callable[[Any], Any], lo: Any, hi: Any) -> Any:
    """Root of ``f`` in ``[lo, hi]`` (sign change assumed), to working precision.

    ``findroot`` (Anderson-Björck) on the bracket mapped to ``[0, 1]`` and ``f`` scaled to its
    end values, then Newton polishing with ``df`` kept inside the bracket; bisection if the
    bracketing solver fails.
    """
    width = hi - lo
    f_lo, f_hi = f(lo), f(hi)
    if f_lo == 0:
        return lo
    if f_hi == 0:
        return hi
    scale = max(abs(f_lo), abs(f_hi))
    sig_lo = _sgn(f_lo)

    def g(sig: Any) -> Any:
        return f(lo + sig * width) / scale

    tol = mp.eps * 4
    try:
        r = mp.findroot(g, (mpf(0), mpf(1)), solver="anderson", tol=tol, verify=False, maxsteps=200)
        r = mp.re(r)
        if not 0 <= r <= 1:
            raise ValueError("root left the bracket")
    except (ValueError, ZeroDivisionError):
        r = mp.findroot(g, (mpf(0), mpf(1)), solver="bisect", tol=tol, verify=False, maxsteps=400)
    t = lo + r * width
    # Shrink the bracket around t, then polish.
    a, b = lo, hi
    for _ in range(NEWTON_POLISH):
        ft = f(t)
        if ft == 0:
            return t
        if _sgn(ft) == sig_lo:
            a = t
        else:
            b = t
        d = df(t)
        if d == 0:
            break
        tn = t - ft / d
        if not a <= tn <= b:
            break
        if tn == t:
            return t
        t = tn
    return t


# ------------------------------------------------------------------------------------------
# The simulation
# ------------------------------------------------------------------------------------------


class _Sim:
    """State machine shared by the pulse and the record loops."""

    def __init__(self, mdl: MPModel, scale: Any, x0: Any, t0: Any) -> None:
        self.g = mpf(G_EXACT)
        self.p = {1: mpf(mdl.p_pos), -1: mpf(mdl.p_neg)}
        self.lam = {1: mpf(mdl.lam_pos), -1: mpf(mdl.lam_neg)}
        self.phiov = {1: mpf(mdl.phiov_pos), -1: mpf(mdl.phiov_neg)}
        self.eta = mpf(mdl.eta)
        self.one_sided = mdl.one_sided
        self.sides = (1,) if mdl.one_sided else (1, -1)
        self.scale = scale
        self.vrest = mpf(V_REST_REL)
        self.t = t0
        self.flight = x0 != 0
        self.s = 1 if x0 >= 0 else -1
        self.x = x0
        self.v = mpf(0)
        self.sig0: Optional[int] = None  # sign of x' just after an uplift
        self.peak = abs(x0)
        self.t_peak = t0
        self.collapsed = False
        self.n_imp = 0
        self.t_imp: list[Any] = []
        self.n_seg = 0
        self.t_uplift: Any = None
        self.t_cell_end: Any = t0
        self.hold_until: Any = t0
        self.n_holds = 0

    def ks(self, s: int) -> Any:
        """Factor from ground acceleration [m/s²] to ``q`` on side ``s``."""
        return self.scale / (self.g * self.lam[s])

    def see(self, t: Any, sx: Any) -> None:
        if sx > self.peak:
            self.peak = sx
            self.t_peak = t

    def fly(self, seg: Any, h: Any, crit: list[Any]) -> bool:
        """Follow a flight segment of length ``h``; return True when it ended in an impact."""
        self.n_seg += 1
        s = self.s
        tau_l = mpf(0)
        sx_l = s * self.x
        pieces = [*crit, h]
        for tau_r in pieces:
            xr = seg.state(tau_r)[0]
            sx_r = s * xr
            if sx_r < 0:
                if sx_l <= 0:
                    # Moves inward from x = 0 at once: nothing to integrate; rest.
                    tau_i = tau_l
                else:
                    tau_i = _root(
                        lambda t: seg.state(t)[0], lambda t: seg.state(t)[1], tau_l, tau_r
                    )
                self._impact(seg, tau_i)
                return True
            self.see(self.t + tau_r, sx_r)
            tau_l, sx_l = tau_r, sx_r
        self.x, self.v = seg.state(h)[:2]
        self.t = self.t + h
        return False

    def _impact(self, seg: Any, tau: Any) -> None:
        s = self.s
        _, vi, _ = seg.state(tau)
        self.t = self.t + tau
        p_old = self.p[s]
        if abs(vi) >= self.vrest * p_old:
            self.n_imp += 1
            if len(self.t_imp) < KEEP_IMPACT_TIMES:
                self.t_imp.append(self.t)
        if self.one_sided:
            s_new, v_new = s, self.eta * vi
        else:
            s_new = -s
            v_new = self.eta * (self.phiov[s] / self.phiov[s_new]) * vi
        self.x = mpf(0)
        self.sig0 = None
        if abs(v_new) < self.vrest * self.p[s_new] or vi == 0:
            self.flight = False
            self.v = mpf(0)
            if self.t == self.t_uplift:
                # Back at rest at the very instant of the uplift (a null excursion): hold the
                # body to the end of the current cell, as the exact integrator does
                # (sub-resolution uplift, theory §10). Counted in ``n_holds``.
                self.hold_until = self.t_cell_end
                self.n_holds += 1
        else:
            self.s, self.v = s_new, v_new

    def uplift(self, t_up: Any, s: int) -> None:
        self.t_uplift = t_up
        self.flight = True
        self.t, self.s, self.x, self.v = t_up, s, mpf(0), mpf(0)
        self.sig0 = s

    def check_collapse(self, qmax_future: Any) -> bool:
        """Certain collapse during the excitation (theory §10)."""
        s = self.s
        if self.flight and s * self.v > 0 and s * self.x > 1 + qmax_future * self.ks(s):
            self.collapsed = True
            return True
        return False

    def free_tail(self) -> None:
        """Exact outcome of the free motion after the excitation (theory §1.8)."""
        if not self.flight or self.collapsed:
            return
        s = self.s
        ps = self.p[s]
        y = s * self.x - 1
        w = s * self.v
        if y + w / ps > 0:
            self.collapsed = True
            return
        e = (w / ps) ** 2 - y * y
        if w > 0:
            self.see(self.t, 1 - mp.sqrt(-e))
        speed = ps * mp.sqrt(e + 1)
        if self.one_sided:
            w_new, p_new = abs(self.eta) * speed, ps
        else:
            o = -s
            w_new, p_new = self.eta * (self.phiov[s] / self.phiov[o]) * speed, self.p[o]
        if w_new < self.vrest * p_new:
            return
        if w_new > p_new:
            self.collapsed = True
            return
        self.see(self.t, 1 - mp.sqrt(1 - (w_new / p_new) ** 2))

    def result(self, wall0: float, dps: int) -> MPResult:
        peak = mpf(1) if self.collapsed else self.peak
        return MPResult(
            peak=peak,
            collapsed=self.collapsed,
            n_impacts=self.n_imp,
            t_peak=self.t_peak,
            t_impacts=self.t_imp,
            n_segments=self.n_seg,
            n_holds=self.n_holds,
            runtime_s=time.perf_counter() - wall0,
            dps=dps,
        )


def _run_record(sim: _Sim, acc: list[Any], dt: Any, t0: Any) -> None:
    n = len(acc)
    absmax_after = [mpf(0)] * n
    run = mpf(0)
    for i in range(n - 1, -1, -1):
        run = max(run, abs(acc[i]))
        absmax_after[i] = run
    for k in range(n - 1):
        tk = t0 + k * dt
        tk1 = t0 + (k + 1) * dt
        a0 = acc[k]
        slope = (acc[k + 1] - a0) / dt
        sim.t_cell_end = tk1
        while True:
            at_threshold = False
            if not sim.flight:
                best = None
                for s in sim.sides:
                    ks = sim.ks(s)
                    if -s * ks * (a0 + slope * (sim.t - tk)) > 1:
                        cand, exact = sim.t, False
                    else:
                        if -s * ks * acc[k + 1] <= 1:
                            continue
                        # The drive is linear in the interval: exact crossing of 1.
                        cand, exact = max(tk + (-s / ks - a0) / slope, sim.t), True
                    if best is None or cand < best[0]:
                        best = (cand, s, exact)
                if best is None or best[0] >= tk1 or sim.t < sim.hold_until:
                    sim.t = tk1
                    break
                sim.uplift(best[0], best[1])
                at_threshold = best[2]
            s = sim.s
            h = tk1 - sim.t
            if h <= 0:
                break
            ks = sim.ks(s)
            # An uplift inside the interval starts exactly at the threshold q = -s (the
            # computed crossing time carries a rounding error of the working precision).
            q0 = -mpf(s) if at_threshold else ks * (a0 + slope * (sim.t - tk))
            seg = _LinearSeg(s, sim.p[s], sim.x, sim.v, q0, ks * slope)
            crit = seg.turning_points(h)
            if sim.fly(seg, h, crit):
                continue
            sim.t = tk1
            if sim.check_collapse(absmax_after[k + 1]):
                return
            break


def _run_pulse(sim: _Sim, a_p: Any, om: Any, ph: Any, t_end: Any) -> None:
    ncell = 4 * PULSE_SUBCELLS
    edges = [t_end * j / ncell for j in range(ncell + 1)]
    two_pi = 2 * mp.pi
    # Uplift windows: -s Q_s sin(theta) > 1, theta = om t + ph in [ph, ph + 2 pi].
    windows: dict[int, list[tuple[Any, Any]]] = {}
    for s in sim.sides:
        c = -s * a_p * sim.ks(s)
        wins: list[tuple[Any, Any]] = []
        if abs(c) > 1:
            th1 = mp.asin(1 / abs(c))
            lo0, hi0 = (th1, mp.pi - th1) if c > 0 else (mp.pi + th1, two_pi - th1)
            for n in range(-1, 3):
                lo = (lo0 + n * two_pi - ph) / om
                hi = (hi0 + n * two_pi - ph) / om
                lo, hi = max(lo, mpf(0)), min(hi, t_end)
                if lo < hi:
                    wins.append((lo, hi))
        windows[s] = wins
    qabs = abs(a_p)

    def drive(s: int, t: Any) -> Any:
        return -s * a_p * sim.ks(s) * mp.sin(om * t + ph)

    for j in range(ncell):
        tb = edges[j + 1]
        sim.t_cell_end = tb
        while True:
            if not sim.flight:
                best = None
                for s in sim.sides:
                    for lo, hi in windows[s]:
                        if hi <= sim.t:
                            continue
                        cand = max(lo, sim.t)
                        # The window edge carries the rounding of asin: step to the first
                        # time at which the drive is >= 1 in working precision, so that the
                        # closed form started there moves outward.
                        step = mp.eps * max(abs(cand), 1)
                        for _ in range(200):
                            if drive(s, cand) >= 1 or cand >= hi:
                                break
                            cand += step
                            step *= 2
                        if best is None or cand < best[0]:
                            best = (cand, s)
                        break
                if best is None or best[0] >= tb or sim.t < sim.hold_until:
                    sim.t = tb
                    break
                sim.uplift(best[0], best[1])
            s = sim.s
            h = tb - sim.t
            if h <= 0:
                break
            seg = _SineSeg(s, sim.p[s], sim.t, sim.x, sim.v, a_p * sim.ks(s), om, ph)
            if sim.sig0 is not None and sim.x == 0 and sim.v == 0:
                sig0 = sim.sig0
            else:
                _, v0, a0 = seg.state(mpf(0))
                sig0 = _sgn(v0) if v0 != 0 else _sgn(a0)
            sim.sig0 = None
            crit = seg.turning_points(h, sig0)
            if sim.fly(seg, h, crit):
                continue
            sim.t = tb
            if sim.check_collapse(qabs):
                return
            break


def simulate_mp(
    model: Any,
    excitation: Any,
    *,
    scale: float = 1.0,
    x0: float = 0.0,
    dps: int = DPS,
    t_max: Optional[float] = None,
) -> MPResult:
    """Simulate the linearised rocking model in ``dps``-digit arithmetic.

    Parameters
    ----------
    model : MPModel or RockingModel-like
        The mechanism (``eta`` required).
    excitation : Pulse-like or SampledAccel-like
        Duck-typed: an object with ``a_p``, ``f_p`` (and optionally ``phase``) is a pulse
        ``a_g = a_p sin(2 pi f_p t + phase)`` on ``[0, 1/f_p]``; one with ``acc``, ``dt``
        (and optionally ``t0``) is a record, linear between samples [m/s²], [s].
    scale : float
        Factor on the acceleration [-].
    x0 : float
        Initial ``phi/phi_ov``, released from rest [-].
    dps : int
        Working precision [significant digits].
    t_max : float, optional
        Use only the record up to this time [s] (documented shortcut for slow runs).

    Returns
    -------
    MPResult
    """
    wall0 = time.perf_counter()
    mdl = model if isinstance(model, MPModel) else MPModel.from_model(model)
    with mp.workdps(dps):
        sc = mpf(float(scale))
        xs = mpf(float(x0))
        if hasattr(excitation, "acc"):
            dt = mpf(float(excitation.dt))
            t0 = mpf(float(getattr(excitation, "t0", 0.0)))
            acc = [mpf(float(a)) for a in excitation.acc]
            if t_max is not None:
                n_keep = math.floor((t_max - float(t0)) / float(excitation.dt)) + 1
                acc = acc[: max(n_keep, 2)]
            sim = _Sim(mdl, sc, xs, t0)
            _run_record(sim, acc, dt, t0)
        elif hasattr(excitation, "a_p"):
            fp = mpf(float(excitation.f_p))
            om = 2 * mp.pi * fp
            ph_f = float(getattr(excitation, "phase", 0.0))
            # Exact pi/2 for the cosine shape rather than its float64 rounding.
            ph = mp.pi / 2 if ph_f == 0.5 * math.pi else mpf(ph_f)
            sim = _Sim(mdl, sc, xs, mpf(0))
            _run_pulse(sim, mpf(float(excitation.a_p)), om, ph, 1 / fp)
        else:
            raise TypeError(f"unknown excitation {type(excitation).__name__}")
        if not sim.collapsed:
            sim.free_tail()
        res = sim.result(wall0, dps)
    return res


def mpf_str(value: Any, digits: int = 20) -> str:
    """Format an ``mpf`` with ``digits`` significant digits."""
    return mpmath.nstr(value, digits)
