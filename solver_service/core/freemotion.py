"""Exact outcome of free rocking once the excitation has ended (theory §1.8, §6.3).

Between impacts the free linearised motion on side ``s`` conserves
``E = (x'/p)**2 - (s*x - 1)**2``. From a state ``(x, v)`` the body overturns on the current
excursion if and only if ``(s*x - 1) + s*v/p > 0``; otherwise it returns to ``x = 0`` with
speed ``p*sqrt(E + 1)``, is scaled by the impact rule, and the next excursion overturns if
and only if its outward speed exceeds ``p`` of the new side. Every later excursion is
smaller (its speed carries another factor ``eta**2`` two-sided, the product of the two
directions' values when they differ, ``|eta|`` one-sided), so two excursions decide the
outcome and the peak, and only the restitution of the next impact enters.

The computation lives in the integrator's kernels (``_kernels.free_rocking_kernel``), which
the exact integrator calls compiled; this module is its documented Python entry point.
"""

from __future__ import annotations

from . import _kernels

__all__ = ["free_rocking"]


def free_rocking(
    s: float,
    x: float,
    v: float,
    p_s: float,
    p_o: float,
    r_so: float,
    eta: float,
    one_sided: bool,
    v_rest: float,
) -> tuple[bool, float, float, float]:
    """Outcome of free rocking from a state on side ``s``.

    Parameters
    ----------
    s : float
        Side in motion, +1 or -1.
    x, v : float
        Normalised rotation ``phi/phi_ov`` [-] and its rate [1/s]; ``s*x >= 0``.
    p_s, p_o : float
        Frequency parameter of the current and of the opposite side [rad/s].
    r_so : float
        ``phi_ov`` of the current side over ``phi_ov`` of the opposite side [-].
    eta : float
        Coefficient of restitution [-] of the next impact (<= 0 for one-sided rocking): for
        two-sided rocking the value into the opposite side (``RockingModel.eta_into(-s)``);
        later impacts cannot change the outcome.
    one_sided : bool
        One-sided rocking: impacts keep the body on side +1.
    v_rest : float
        Outward speed [1/s] (in ``x`` units) below which an impact ends in rest.

    Returns
    -------
    collapses : bool
        True when the body overturns in free motion.
    dt_cross : float
        Time from now until ``|x|`` reaches 1 on the collapsing excursion [s]; 0 when
        already past 1; NaN when it does not collapse.
    peak : float
        Largest ``|x|`` of the future free motion, at least the current ``|x|`` [-]
        (1.0 when it collapses).
    dt_peak : float
        Time from now to that peak [s].

    Notes
    -----
    theory §1.8 (invariant and overturning test) and §6.3 ("after the pulse").

    Examples
    --------
    A symmetric block released from rest at ``x = 0.5`` with ``eta = 0.8`` comes back at
    speed ``p*sqrt(0.75)`` and leaves the impact at 0.8 of it; neither excursion overturns:

    >>> out = free_rocking(1.0, 0.5, 0.0, 2.0, 2.0, 1.0, 0.8, False, 0.0)
    >>> out[0], round(out[2], 12)
    (False, 0.5)

    Released beyond ``x = 1`` it runs away:

    >>> free_rocking(1.0, 1.2, 0.0, 2.0, 2.0, 1.0, 0.8, False, 0.0)[0]
    True
    """
    col, dt_cross, peak, dt_peak = _kernels.free_rocking_kernel(
        float(s),
        float(x),
        float(v),
        float(p_s),
        float(p_o),
        float(r_so),
        float(eta),
        bool(one_sided),
        float(v_rest),
    )
    return bool(col), float(dt_cross), float(peak), float(dt_peak)
