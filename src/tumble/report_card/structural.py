"""The report card's structural table: every scheme of :data:`tumble.structural.SCHEMES` on a
small steel cantilever — its energy over a long run, its order, its critical step."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tumble import exact
from tumble.report_card.measure import LONG_SAMPLES, growth_law

ORDER_WINDOW = (1e-12, 0.5)
"""Relative tip errors fitted for a scheme's order: above 1e-12 they are truncation, not the
round-off of the solves; below ½ the steps resolve the response."""
ORDER_RUNS = 5
"""Runs of the order study, the steps halving from :data:`ORDER_COARSEST`."""
ORDER_COARSEST = {1: 1 / 2, 2: 1 / 32}
"""The order study's coarsest step by the order a scheme declares, in units of
Δt_crit(semi-implicit), at T = a quarter of the fundamental period (0.030 s). A second-order
scheme's tip error is asymptotic only once the highest mode's phase error over the run is
small: from Δt_crit/2 the local slopes of the ten halvings were, for midpoint,
1.77 −2.00 0.32 1.94 2.00 2.00 …, for Wilson-θ 5.3 −5.7 0.82 1.53 1.98 2.00 …, and every
second-order scheme's are within 0.07 of 2 from Δt_crit/32 on. The first-order schemes keep ½:
the implicit scheme's damping of the upper modes bends its local slopes up to 1.27 between
Δt_crit/16 and Δt_crit/1024 before they fall back towards 1 (1.19 at the last), and its fit
through the five runs from ½ is 1.14; the semi-implicit scheme's is 1.05."""


@dataclass
class StructuralRow:
    """One structural scheme: energy behaviour, order, critical step."""

    scheme: str
    energy_law: str
    energy_slope: float
    energy_max: float
    order_expected: float
    order_measured: float
    order_fit: str
    critical_dt: float


def structural_rows(quick: bool) -> tuple[list[StructuralRow], dict]:
    """Every scheme of :data:`tumble.structural.SCHEMES` on a small cantilever.

    The beam: 1 m steel, 4 elements, 1 cm square, a 1 N tip load from rest. Energy: a run of
    :math:`200` (quick: 50) fundamental periods at h = ½ Δt_crit of the semi-implicit
    scheme, the energy error ``E − E₀`` relative to :func:`~tumble.structural.energy_scale`
    with :func:`~tumble.report_card.measure.growth_law`'s verdict. Order: the tip
    displacement at T = a quarter period against :func:`tumble.structural.exact_response`
    (modal superposition), steps halving from :data:`ORDER_COARSEST` Δt_crit, fitted by
    :func:`tumble.exact.fit_order` through the errors in :data:`ORDER_WINDOW`, compared with
    the order the scheme declares (its ``order``).
    """
    from tumble import structural
    from tumble.scenarios.beam import steel_cantilever

    beam = steel_cantilever(4)
    omega1 = float(beam.natural_frequencies(1)[0])  # rad/s
    period = 2 * math.pi / omega1
    setup = {"omega1": omega1, "period": period,
             "dt_crit_semi_implicit": structural.critical_dt(beam, "semi-implicit").dt,
             "periods": 50 if quick else 200, "T_order": period / 4,
             "n_dofs": beam.n_dofs}  # fmt: skip
    out = []
    for name, scheme in structural.SCHEMES.items():
        law, slope, largest = _energy(beam, name, setup)
        critical = structural.critical_dt(beam, scheme).dt
        measured, fit = _order(beam, name, setup, scheme.order, unstable=critical == 0)
        out.append(StructuralRow(name, law, slope, largest, float(scheme.order), measured, fit,
                                 critical))  # fmt: skip
    return out, setup


def _energy(beam, name: str, setup: dict) -> tuple[str, float, float]:
    """``(law, slope, largest)`` of the energy error over ``setup["periods"]`` periods at
    h = ½ Δt_crit(semi-implicit): :func:`growth_law`'s, or ``dissipates`` (the energy falls
    by more than 5 % of the scale), or ``grows`` (a failed run, or ten times the scale)."""
    from tumble import structural

    scale = structural.energy_scale(beam)
    dt = 0.5 * setup["dt_crit_semi_implicit"]
    steps = round(setup["periods"] * setup["period"] / dt)
    response = structural.integrate(beam, name, dt, n_steps=steps,
                                    record_every=max(1, steps // LONG_SAMPLES))  # fmt: skip
    t, E = response.t, response.energy
    with np.errstate(over="ignore", invalid="ignore"):
        law_energy = (E - E[0]) / scale + 1.0  # relative to the scale, about 1
    slope, largest, law = growth_law(t[1:], law_energy[1:]) if response.success else (
        math.nan, math.inf, "grows")  # fmt: skip
    if response.success and np.mean(E[len(E) // 2 :] - E[0]) < -0.05 * scale:
        law = "dissipates"
    if not response.success or largest > 10:
        law = "grows"
    return law, slope, largest


def _order(beam, name: str, setup: dict, order: int, *, unstable: bool) -> tuple[float, str]:
    """The scheme's observed order and its fit range: the relative tip error at
    ``setup["T_order"]`` against the exact response, the steps halving from
    :data:`ORDER_COARSEST` Δt_crit for the scheme's declared ``order``.
    ``unstable`` (at every Δt): the growth, not the truncation, sets the error: no order."""
    from tumble import structural

    T = setup["T_order"]
    tip_exact = float(structural.exact_response(beam, [T]).tip_displacement[0])
    coarsest = T / math.ceil(T / (ORDER_COARSEST[order] * setup["dt_crit_semi_implicit"]))

    def run(dt: float):
        return structural.integrate(beam, name, dt, n_steps=round(T / dt), record_every=10**9)

    def error(response) -> float:
        return abs(float(response.tip_displacement[-1]) - tip_exact) / abs(tip_exact)

    trials = exact.study(run, [coarsest / 2**k for k in range(ORDER_RUNS)], error)
    fit = None if unstable else exact.fit_order(
        [trial.setting for trial in trials], [trial.error for trial in trials],
        window=ORDER_WINDOW)  # fmt: skip
    if fit is None:
        return math.nan, "—"
    return fit.order, f"Δt = {fit.h_min:.2g} … {fit.h_max:.2g} s"
