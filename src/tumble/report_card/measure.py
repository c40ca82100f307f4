"""What the report card measures of a row: its order, its error at T, its invariants.

* the **order**: the least-squares slope ``p`` of log e against log h, e = ‖R(T) − R_ref(T)‖_F,
  fitted by :func:`tumble.exact.fit_order` through the four finest runs whose error lies in
  the asymptotic window (:data:`ASYMPTOTIC`), on P1 — or on the forced body when P1 leaves
  every error at round-off (the splittings on the exact flow); it agrees with the declared
  :attr:`~tumble.rigid.Method.order` when ``|p − order| ≤`` :data:`ORDER_TOLERANCE`. An
  adaptive method's order is that of the formula it propagates, measured at fixed steps
  (:func:`~tumble.report_card.peers.fixed_step_end`); through its controller, against the
  mean step T/steps, the slope wanders by up to an order with the tolerance (the step
  distribution changes with it), and is reported beside;
* the **error at T** on every problem at one setting (h = :data:`STANDARD_H`, or
  rtol = :data:`STANDARD_RTOL` for an adaptive method: tumble's scale atol with it, scipy's
  take atol = rtol);
* the **invariants over a long run** (h = :data:`LONG_H`, rtol = :data:`LONG_RTOL`): the
  growth law of the energy error (:func:`growth_law`), the Casimir
  ``max ||RᵀL| − |L₀|| / |L₀|``, ``max ‖RᵀR − I‖_F`` and ``max ||q| − 1|`` of a carried
  quaternion;

and :func:`contradictions` says which of a row's declarations they contradict. Every sweep
runs through :func:`tumble.exact.study`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import partial

import numpy as np

from tumble import exact
from tumble.report_card.peers import Row, Sampled, fixed_step_end, run_row
from tumble.report_card.problems import CardProblem, attitude_error

ORDER_TOLERANCE = 0.3
"""A measured order agrees with the declared one within this (the slope of a least-squares
fit through the asymptotic window; the tests of single methods ask ±0.2 on chosen steps)."""
FIT_POINTS = 4
"""The order is fitted through the (up to) four finest runs inside the window: the nearest
to the asymptotic regime."""
ASYMPTOTIC = (1e-11, 1e-1)
"""Errors e = ‖R(T) − R_ref(T)‖_F fitted for the order on P1: below 1e-1 the runs are in
the asymptotic range, above 1e-11 they are truncation, not round-off (which reaches 1e-13
after 10⁵ steps)."""
FORCED_FLOOR = 1e-9
"""The forced body's reference (DOP853 at 1e-13) is good to about 1e-11: errors below this
are not fitted."""
STEP_COUNTS = (10, 13, 16, 20, 25, 32, 40, 50, 64, 80, 100, 200, 500, 1000, 2000, 5000, 10000,
               20000, 50000)  # fmt: skip
"""Steps over [0, T] of the fixed-step sweeps (T = 10 s: h = 1 … 2·10⁻⁴ s), dense at the
coarse end, where an eighth-order method's errors fall from 1e-7 to round-off."""
TOLERANCES = tuple(10.0**-k for k in range(3, 13))
"""rtol of the adaptive sweeps, 1e-3 … 1e-12 (tumble's methods scale atol with it, scipy's
take atol = rtol)."""
STANDARD_H = 0.01
"""The step (s) of the error-at-T table."""
STANDARD_RTOL = 1e-8
"""The tolerance of the error-at-T table for adaptive methods."""
LONG_H = 0.02
"""The step (s) of the long runs."""
LONG_RTOL = 1e-6
"""The tolerance of the long runs for adaptive methods."""
LONG_SAMPLES = 2000
"""Samples kept from a long run (the energy law is fitted through them)."""
ROUND_OFF = 1e-11
"""An invariant whose largest relative change stays below this is kept to round-off (10⁵
steps of 10⁻¹⁶ each, with three decades to spare)."""
BOUNDED_SLOPE = 0.5
"""An energy error whose running maximum grows over the last decade of t with a log–log
slope below this is bounded: a systematic drift has slope 1, a sum of independent errors
(a random walk) ½, and only an error that keeps returning grows slower. (``midpoint-lp`` with
the dipole: 0.38 over [100, 1000] s, 0.13 over [10³, 10⁴] s, at 6e-5 both times.)"""


AMORTISE = 100
"""A work–precision run shorter than this many times the fixed cost of a call is timed again
over repeated spans of T (:func:`amortised_seconds`): the figure then shows what the steps
cost, not the call (a compiled method's 10 steps take 2 µs, the call about 50 µs)."""
MAX_SPANS = 1000
"""At most this many spans of T in one timed run."""


@dataclass
class Study:
    """One row's runs over its settings on one problem (:func:`tumble.exact.study`'s trials):
    the work–precision points. (Not :func:`tumble.sweep`, which runs a scenario over a grid.)

    ``mean_step`` is h for a fixed-step row, T / accepted steps for an adaptive one."""

    problem: str
    settings: list[float] = field(default_factory=list)
    mean_step: list[float] = field(default_factory=list)
    steps: list[int] = field(default_factory=list)
    seconds: list[float] = field(default_factory=list)
    error: list[float] = field(default_factory=list)
    energy_error: list[float] = field(default_factory=list)


@dataclass
class Order:
    """The measured order of a row: the slope, the fit range of h̄, the problem, the verdict."""

    measured: float
    h_min: float
    h_max: float
    points: int
    problem: str
    verdict: str  # "agrees", "contradicts", "exact"
    against_mean_step: float = math.nan  # an adaptive row: the slope against T/steps


def standard_setting(row: Row) -> float:
    """The setting of the error-at-T table and the cost: :data:`STANDARD_H` or
    :data:`STANDARD_RTOL`."""
    return STANDARD_RTOL if row.adaptive else STANDARD_H


def sampled(row: Row, problem: CardProblem, setting: float, **options) -> Sampled:
    """:func:`~tumble.report_card.peers.run_row` of a row that takes the problem's loads."""
    run = run_row(row, problem, setting, **options)
    assert run is not None, f"{row.name} takes no loads: {problem.name} is not its problem"
    return run


def against(R_ref: np.ndarray):
    """The error of a run against ``R_ref``: ``‖R(T) − R_ref‖_F``, inf for a failed run."""
    return lambda run: attitude_error(run.R_end, R_ref) if run.ok else math.inf


def study_row(row: Row, problem: CardProblem, R_ref: np.ndarray, repeat: int = 1,
              fixed: float = 0.0) -> Study | None:  # fmt: skip
    """Run ``row`` over :data:`STEP_COUNTS` (or :data:`TOLERANCES`) on ``problem``; each
    run's time is the best of ``repeat``, after one warm-up run (numba's dispatch, the first
    call's imports), and with a call's fixed cost ``fixed`` (s) known, the time of a short
    run is :func:`amortised_seconds`."""
    if problem.forced and not row.takes_loads:
        return None
    settings = TOLERANCES if row.adaptive else [problem.t_end / n for n in STEP_COUNTS]
    warm_t = 0.01 if row.adaptive else 2 * settings[0]
    trials = exact.study(
        lambda setting: sampled(row, problem, setting, samples=200),
        settings,
        against(R_ref),
        repeat=repeat,
        warm_up=lambda: run_row(row, problem, settings[0], t_end=warm_t),
        seconds=lambda run: run.seconds,
    )
    out = Study(problem.name)
    for trial in trials:
        run = trial.result
        out.settings.append(trial.setting)
        out.mean_step.append(problem.t_end / max(run.steps, 1) if row.adaptive else trial.setting)
        out.steps.append(int(run.steps))
        out.seconds.append(amortised_seconds(row, problem, trial.setting, trial.seconds, fixed))
        out.error.append(trial.error)
        out.energy_error.append(_energy_error(run))
    return out


def amortised_seconds(row: Row, problem: CardProblem, setting: float, seconds: float,
                      fixed: float) -> float:  # fmt: skip
    """The time of a run of T with the fixed cost of a call spread out: a run that took
    less than :data:`AMORTISE` × ``fixed`` is timed again over ``k`` spans of T in one call
    (``k`` up to :data:`MAX_SPANS`, so that it lasts about that long) and counted as 1/k of
    it. A run that fails over the longer span keeps its own time."""
    if not fixed > 0 or seconds >= AMORTISE * fixed:
        return float(seconds)
    spans = min(MAX_SPANS, math.ceil(AMORTISE * fixed / max(seconds, 1e-9)))
    with np.errstate(over="ignore", invalid="ignore"):
        run = run_row(row, problem, setting, t_end=spans * problem.t_end)
    if run is None or not run.ok:
        return float(seconds)
    return run.seconds / spans


def _energy_error(run: Sampled) -> float:
    """``max |E − E₀| / |E₀|`` over the run's samples (inf when not finite)."""
    with np.errstate(over="ignore", invalid="ignore"):
        energy = float(np.max(np.abs(run.energy - run.energy[0])) / abs(run.energy[0]))
    return energy if math.isfinite(energy) else math.inf


def error_at(row: Row, problem: CardProblem, R_ref: np.ndarray) -> float:
    """``‖R(T) − R_ref(T)‖_F`` at :func:`standard_setting` (NaN: the row takes no loads and
    the problem has some)."""
    if problem.forced and not row.takes_loads:
        return math.nan
    run = partial(sampled, row, problem)
    (trial,) = exact.study(run, [standard_setting(row)], against(R_ref))
    return trial.error


def _fit(row: Row, data: Study, window: tuple[float, float]) -> Order | None:
    """:func:`tumble.exact.fit_order` of e against h̄ through the :data:`FIT_POINTS` finest
    errors inside ``window``, with the verdict; None when fewer than three are."""
    fit = exact.fit_order(data.mean_step, data.error, window=window, finest=FIT_POINTS,
                          minimum=3)  # fmt: skip
    if fit is None:
        return None
    verdict = "agrees" if abs(fit.order - row.order) <= ORDER_TOLERANCE else "contradicts"
    return Order(fit.order, fit.h_min, fit.h_max, fit.points, data.problem, verdict)


def fixed_step_study(row: Row, problem: CardProblem, R_ref: np.ndarray) -> Study:
    """An adaptive row's errors at the fixed steps of :data:`STEP_COUNTS` (no timing), up to
    the second error at round-off (finer steps add nothing to the fit)."""

    def at_round_off(trials: list) -> bool:
        return sum(trial.error <= ASYMPTOTIC[0] for trial in trials) >= 2

    trials = exact.study(
        lambda h: fixed_step_end(row, problem, h),
        [problem.t_end / n for n in STEP_COUNTS],
        lambda R: attitude_error(R, R_ref),
        until=at_round_off,
    )
    out = Study(problem.name)
    for trial, n in zip(trials, STEP_COUNTS, strict=False):
        out.settings.append(trial.setting)
        out.mean_step.append(trial.setting)
        out.steps.append(n)
        out.error.append(trial.error)
    return out


def measured_order(row: Row, free: Study, forced: Study | None) -> Order:
    """The order on P1, else on the forced body; an exact method at round-off on P1 is
    ``exact``; a row with no fit anywhere is ``no fit`` (a contradiction if it declares a
    finite order)."""
    found = _fit(row, free, ASYMPTOTIC)
    if found is not None:
        return found
    at_round_off = all(e <= ASYMPTOTIC[0] for e in free.error)
    if at_round_off and math.isinf(row.order):
        return Order(math.inf, math.nan, math.nan, 0, free.problem, "exact")
    if forced is not None:
        found = _fit(row, forced, (FORCED_FLOOR, ASYMPTOTIC[1]))
        if found is not None:
            return found
    return Order(math.nan, math.nan, math.nan, 0, free.problem, "contradicts")


def adaptive_order(row: Row, free: Study, R_ref: np.ndarray, problem: CardProblem) -> Order:
    """An adaptive row's order: that of the formula it propagates, at fixed steps on
    ``problem``, with the slope of its tolerance sweep ``free`` against h̄ beside."""
    order = measured_order(row, fixed_step_study(row, problem, R_ref), None)
    through_controller = _fit(row, free, ASYMPTOTIC)
    if through_controller is not None:
        order.against_mean_step = through_controller.measured
    return order


# --- invariants over a long run ------------------------------------------------------------


@dataclass
class Invariants:
    """A long run's invariants: energy law (slope, largest relative change, verdict), the
    Casimir's largest relative change, orthogonality and quaternion-norm defects."""

    problem: str
    t_end: float
    energy_slope: float
    energy_max: float
    energy_law: str  # "round-off", "bounded", "drift", "grows", "failed"
    casimir_slope: float
    casimir_max: float
    casimir_law: str
    orthogonality_max: float
    quaternion_max: float
    steps: int


def growth_law(t: np.ndarray, energy: np.ndarray) -> tuple[float, float, str]:
    """``(slope, max |ΔE|/|E₀|, verdict)`` of a sampled invariant E (the energy, |L|).

    The running maximum m(t) = max_{τ≤t} |E(τ) − E₀| / |E₀| is fitted as m ∝ t^s over
    the last decade, t ∈ [T/10, T]: bounded below :data:`BOUNDED_SLOPE`, a drift up to
    1.3 (linear: s = 1), above it grows. Below :data:`ROUND_OFF` the
    error is round-off, whatever its slope (round-off random-walks, s ≈ ½).
    """
    with np.errstate(over="ignore", invalid="ignore"):
        error = np.abs(energy - energy[0]) / abs(energy[0])
    if not np.all(np.isfinite(error)):
        return math.nan, math.inf, "failed"
    running = np.maximum.accumulate(error)
    largest = float(running[-1])
    if largest <= ROUND_OFF:
        return math.nan, largest, "round-off"
    late = (t >= t[-1] / 10) & (running > 0)
    slope = float(np.polyfit(np.log(t[late]), np.log(running[late]), 1)[0])
    if slope < BOUNDED_SLOPE:
        verdict = "bounded"
    elif slope <= 1.3:
        verdict = "drift"
    else:
        verdict = "grows"
    return slope, largest, verdict


def invariants(row: Row, problem: CardProblem, t_end: float) -> Invariants | None:
    """Run ``row`` for ``t_end`` on ``problem`` at :data:`LONG_H` (:data:`LONG_RTOL`)."""
    run = run_row(row, problem, LONG_RTOL if row.adaptive else LONG_H, t_end=t_end,
                  samples=LONG_SAMPLES)  # fmt: skip
    if run is None:
        return None
    slope, largest, law = growth_law(run.t, run.energy)
    casimir_slope, casimir, casimir_law = growth_law(run.t, run.casimir)
    if not run.ok:  # stopped before T (non-finite, or MuJoCo's reset of an unstable body)
        law = casimir_law = "failed"
    return Invariants(problem.name, t_end, slope, largest, law, casimir_slope, casimir,
                      casimir_law, run.orthogonality, run.quaternion, run.steps)  # fmt: skip


# --- verdicts ---------------------------------------------------------------------------------


def contradictions(row: Row, order: Order, free: Invariants, forced: Invariants | None) -> list:
    """What ``row`` declares and its measurements contradict, one sentence each."""
    found = []
    if order.verdict == "contradicts":
        measured = "no fit" if math.isnan(order.measured) else f"{order.measured:.2f}"
        found.append(f"order: declared {row.order:g}, measured {measured} on {order.problem}")
    if "energy" in row.claims and free.energy_law != "round-off":
        found.append(
            f"energy-preserving: max |ΔE|/E₀ = {free.energy_max:.1e} over {free.t_end:g} s "
            f"on {free.problem} (round-off is ≤ {ROUND_OFF:g})"
        )
    if "symplectic" in row.claims:
        for inv in (free, forced):
            if inv is not None and inv.energy_law not in ("round-off", "bounded"):
                found.append(
                    f"symplectic: the energy error's law is {inv.energy_law} (slope "
                    f"{inv.energy_slope:.2f}) over {inv.t_end:g} s on {inv.problem}"
                )
    if "casimir" in row.claims and free.casimir_law != "round-off":
        found.append(f"Casimir |L|: max relative change {free.casimir_max:.1e} on {free.problem}")
    if "orthogonality" in row.claims and not free.orthogonality_max <= ROUND_OFF:
        found.append(f"stays on SO(3): max ‖RᵀR − I‖ = {free.orthogonality_max:.1e}")
    return found
