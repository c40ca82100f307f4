"""Writing the card: ``report.md`` (:func:`markdown`, one function per section),
``report.html`` (:mod:`tumble.viz.report_card`, from :func:`plot_data`) and ``report.nc``
(:func:`datasets`), each atomically."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from tumble import _checks
from tumble._atomic import atomic_write
from tumble.report_card.card import ReportCard, RowResult
from tumble.report_card.measure import (
    AMORTISE,
    ASYMPTOTIC,
    BOUNDED_SLOPE,
    FIT_POINTS,
    LONG_H,
    LONG_RTOL,
    MAX_SPANS,
    ORDER_TOLERANCE,
    ROUND_OFF,
    STANDARD_H,
    STANDARD_RTOL,
    STEP_COUNTS,
    TOLERANCES,
)
from tumble.report_card.peers import CLAIMS
from tumble.report_card.problems import PROBLEM_T, SWEEP_T


def write(card: ReportCard, out: str | os.PathLike[str]) -> Path:
    """Write ``report.md``, ``report.html`` and ``report.nc`` into ``out``, each atomically."""
    from tumble.io import write_dataset
    from tumble.viz.report_card import write_html

    folder = Path(out)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise _checks.fail("out", str(out), "a folder that can be created",
                           remedy=str(error.strerror or error)) from None  # fmt: skip
    text = markdown(card)
    atomic_write(folder / "report.md", lambda tmp: tmp.write_text(text, encoding="utf-8"))
    below = text.split("\n", 1)[1]  # the page has the title already
    write_html(folder / "report.html", plot_data(card), title=card.title, tables=below,
               notes=_peer_notes(card))  # fmt: skip
    write_dataset(folder / "report.nc", datasets(card), {"title": card.title, **card.machine})
    return folder


def plot_data(card: ReportCard) -> list[dict]:
    """One dict per row for the HTML page: name, setting name, flagged, and per problem the
    work (s), orientation error, energy error and settings."""
    out = []
    for result in card.results:
        out.append(
            {
                "name": result.row.name,
                "setting": "rtol" if result.row.adaptive else "h",
                "flagged": bool(result.contradictions),
                "why": result.contradictions,
                "fixed": result.fixed_us * 1e-6,
                "sweeps": {
                    name: {
                        "seconds": data.seconds,
                        "error": data.error,
                        "energy": data.energy_error,
                        "settings": data.settings,
                        "steps": data.steps,
                    }
                    for name, data in result.sweeps.items()
                },
            }
        )
    return out


def datasets(card: ReportCard) -> dict:
    """The raw numbers as xarray Datasets: ``methods`` (per row), ``errors`` (row × problem),
    ``sweep_P1`` and ``sweep_forced`` (row × run), ``structural`` (per scheme)."""
    import xarray as xr

    names = [r.row.name for r in card.results]
    errors = xr.Dataset(
        {"error": (("method", "problem"),
                   np.array([[r.errors[p] for p in card.problems] for r in card.results]),
                   {"long_name": "‖R(T) − R_ref(T)‖_F at h = 0.01 s or rtol = 1e-8"})},
        coords={"method": names, "problem": card.problems},
    )  # fmt: skip
    groups = {"methods": _per_row(card), "errors": errors}
    for problem in ("P1", "forced"):
        groups[f"sweep_{problem}"] = xr.Dataset(
            {key: (("method", "run"), value) for key, value in _sweeps(card, problem).items()},
            coords={"method": names},
        )
    if card.structural:
        groups["structural"] = _structural(card)
    return groups


def _per_row(card: ReportCard):
    """The ``methods`` Dataset: one value of each measurement per row."""
    import xarray as xr

    def column(get) -> np.ndarray:
        return np.array([get(r) for r in card.results], dtype=float)

    return xr.Dataset(
        {
            "order_declared": ("method", column(lambda r: r.row.order)),
            "order_measured": ("method", column(lambda r: r.order.measured)),
            "order_h_min": ("method", column(lambda r: r.order.h_min), {"units": "s"}),
            "order_h_max": ("method", column(lambda r: r.order.h_max), {"units": "s"}),
            "order_verdict": ("method", [r.order.verdict for r in card.results]),
            "order_problem": ("method", [r.order.problem for r in card.results]),
            "order_against_mean_step": ("method", column(lambda r: r.order.against_mean_step)),
            "energy_slope": ("method", column(lambda r: r.free.energy_slope)),
            "energy_max": ("method", column(lambda r: r.free.energy_max)),
            "energy_law": ("method", [r.free.energy_law for r in card.results]),
            "forced_energy_slope": (
                "method", column(lambda r: r.forced.energy_slope if r.forced else math.nan)),
            "forced_energy_law": (
                "method", [r.forced.energy_law if r.forced else "" for r in card.results]),
            "casimir_max": ("method", column(lambda r: r.free.casimir_max)),
            "casimir_slope": ("method", column(lambda r: r.free.casimir_slope)),
            "casimir_law": ("method", [r.free.casimir_law for r in card.results]),
            "orthogonality_max": ("method", column(lambda r: r.free.orthogonality_max)),
            "quaternion_max": ("method", column(lambda r: r.free.quaternion_max)),
            "cost_us_per_step": ("method", column(lambda r: r.cost_us), {"units": "µs"}),
            "fixed_cost_us": ("method", column(lambda r: r.fixed_us), {"units": "µs",
                              "long_name": "the fixed cost of one call (a run of one step)"}),
            "first_call_s": ("method", column(lambda r: r.first_call_s), {"units": "s"}),
            "contradictions": ("method", ["; ".join(r.contradictions) for r in card.results]),
            "claims": ("method", [", ".join(sorted(r.row.claims)) for r in card.results]),
        },
        coords={"method": [r.row.name for r in card.results]},
        attrs={"long_run_s": card.long_t, "first_call": card.first_call_note},
    )  # fmt: skip


SWEEP_FIELDS = ("setting", "steps", "seconds", "error", "energy_error")
"""What ``report.nc`` keeps of each sweep run."""


def _sweeps(card: ReportCard, problem: str) -> dict[str, np.ndarray]:
    """Each of :data:`SWEEP_FIELDS` as (row, run), NaN-padded (the settings are the
    :data:`STEP_COUNTS` or the :data:`TOLERANCES`), NaN for a row with no sweep there."""
    shape = (len(card.results), max(len(STEP_COUNTS), len(TOLERANCES)))
    fields = {key: np.full(shape, np.nan) for key in SWEEP_FIELDS}
    for i, r in enumerate(card.results):
        data = r.sweeps.get(problem)
        if data is None:
            continue
        k = len(data.settings)
        fields["setting"][i, :k] = data.settings
        fields["steps"][i, :k] = data.steps
        fields["seconds"][i, :k] = data.seconds
        fields["error"][i, :k] = data.error
        fields["energy_error"][i, :k] = data.energy_error
    return fields


def _structural(card: ReportCard):
    """The ``structural`` Dataset: one value of each measurement per scheme."""
    import xarray as xr

    s = card.structural
    return xr.Dataset(
        {
            "energy_law": ("scheme", [x.energy_law for x in s]),
            "energy_slope": ("scheme", [x.energy_slope for x in s]),
            "energy_max": ("scheme", [x.energy_max for x in s]),
            "order_expected": ("scheme", [x.order_expected for x in s]),
            "order_measured": ("scheme", [x.order_measured for x in s]),
            "critical_dt": ("scheme", [x.critical_dt for x in s], {"units": "s"}),
        },
        coords={"scheme": [x.scheme for x in s]},
        attrs=dict(card.structural_setup.items()),
    )


def _number(value: float, digits: int = 2) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "—"
    if math.isinf(value):
        return "∞" if value > 0 else "−∞"
    if abs(value) >= 100:
        return f"{value:.0f}"
    return f"{value:.{digits}g}" if abs(value) >= 1e-3 or value == 0 else f"{value:.1e}"


def _law(law: str, slope: float) -> str:
    """``drift (0.99)``: a law with its slope; round-off and failed runs have none."""
    return law if law in ("round-off", "failed") else f"{law} ({_number(slope)})"


def _sci(value: float) -> str:
    if value is None or math.isnan(value):
        return "—"
    if math.isinf(value):
        return "∞"
    return f"{value:.1e}"


def markdown(card: ReportCard) -> str:
    """The report as markdown: the contradictions first, then the tables."""
    sections = [_heading, _contradictions, _orders, _errors, _twins, _invariants, _costs,
                _schemes, _closing]  # fmt: skip
    return "\n".join(line for section in sections for line in section(card))


def _heading(card: ReportCard) -> list[str]:
    m = card.machine
    return [
        f"# {card.title}",
        "",
        "Generated by `tumble report` (`make report`); every number below is measured, every "
        "verdict computed against what the method declares in `tumble.rigid.METHODS`.",
        "",
        f"Machine: {m['cpu']}, {m['cores']} cores, {m['system']}; Python {m['python']}, "
        f"numpy {m['numpy']}, scipy {m['scipy']}, numba {m['numba']}, tumble {m['tumble']}; "
        f"{m['date']}; the report took {card.seconds:.0f} s. Other work shared the machine, "
        "so the times are indicative.",
        "",
        *[f"{note}." for note in _peer_notes(card)],
        *([""] if card.skipped else []),
    ]


def _peer_notes(card: ReportCard) -> list[str]:
    """One sentence per skipped peer group: ``MuJoCo RK4, MuJoCo Euler: not installed: …``."""
    groups: dict[str, list[str]] = {}
    for name, why in card.skipped.items():
        groups.setdefault(why, []).append(name)
    return [f"{', '.join(names)}: {why}" for why, names in groups.items()]


TWINS = ("euler-quat", "lie-euler")
"""Two first-order methods whose errors agree to about two digits, for a reason (below)."""


def _twins(card: ReportCard) -> list[str]:
    """Why ``euler-quat`` and ``lie-euler`` show the same errors, with the measured gap."""
    found = {r.row.name: r for r in card.results if r.row.name in TWINS}
    if len(found) < 2:
        return []
    a, b = (found[name].errors for name in TWINS)
    gaps = [abs(a[p] / b[p] - 1) for p in card.problems
            if math.isfinite(a[p]) and math.isfinite(b[p]) and b[p] > 0]  # fmt: skip
    gap = f"{max(gaps):.1%}" if gaps else "—"
    return [
        f"Why `euler-quat` and `lie-euler` show the same errors above (largest relative "
        f"difference {gap} over the problems): both turn the body, over a step, about the "
        "axis of the angular velocity ω at its start, the one first-order error they share; "
        "`lie-euler` by the angle h|ω| (R exp(hω̂)), `euler-quat` by 2 arctan(h|ω|/2) = "
        "h|ω| − (h|ω|)³/12 + … (the normalised q + (h/2) q ⊗ ω). Their steps differ by "
        "O(h³), below the O(h²) error each step makes, so their errors agree to relative "
        "O(h²), and in two digits.",
        "",
    ]


def _contradictions(card: ReportCard) -> list[str]:
    lines = ["## Contradictions", ""]
    flagged = card.contradictions
    if not flagged:
        lines.append("None: every method's measured order and invariants agree with what it "
                     "declares.")  # fmt: skip
    for name, why in flagged.items():
        for sentence in why:
            lines.append(f"- **{name}** — {sentence}")
    return [*lines, ""]


def _orders(card: ReportCard) -> list[str]:
    lines = [
        "## Order",
        "",
        f"Slope of log ‖R(T) − R_ref(T)‖_F against log h (T = {SWEEP_T:g} s), fitted through "
        f"the {FIT_POINTS} finest runs with errors in ({ASYMPTOTIC[0]:g}, {ASYMPTOTIC[1]:g}) on "
        "P1, or on the forced body when P1 is at round-off; it agrees when within "
        f"±{ORDER_TOLERANCE} of the declared order. Adaptive methods: the formula they "
        "propagate at fixed steps (the order they declare); the last column is the slope of "
        "their tolerance sweep against the mean step h̄ = T/steps, which the step controller "
        "bends away from it.",
        "",
        "| method | family | declared | measured | fit range h (s) | runs | problem | verdict "
        "| adaptive: vs h̄ |",
        "| --- | --- | ---: | ---: | --- | ---: | --- | --- | ---: |",
    ]
    for r in card.results:
        o = r.order
        fit = "—" if math.isnan(o.h_min) else f"{o.h_min:.2g} … {o.h_max:.2g}"
        verdict = "**contradicts**" if o.verdict == "contradicts" else o.verdict
        lines.append(
            f"| {r.row.name} | {r.row.family} | {_number(r.row.order)} | "
            f"{'round-off' if o.verdict == 'exact' else _number(o.measured, 3)} | {fit} | "
            f"{o.points} | {o.problem} | {verdict} | {_number(o.against_mean_step, 3)} |"
        )
    return [*lines, ""]


def _errors(card: ReportCard) -> list[str]:
    lines = [
        "## Orientation error at T",
        "",
        f"‖R(T) − R_ref(T)‖_F at h = {STANDARD_H:g} s (adaptive: rtol = "
        f"{STANDARD_RTOL:g}). P1 and forced: T = {SWEEP_T:g} s; the T-handle: T = "
        f"{PROBLEM_T:g} s. Reference: the exact solution, or for the forced body (magnetic "
        "dipole) scipy DOP853 at rtol = atol = 1e-13. — : the method takes no loads.",
        "",
        f"| method | {' | '.join(card.problems)} |",
        "| --- |" + " ---: |" * len(card.problems),
    ]
    for r in card.results:
        cells = " | ".join(_sci(r.errors[p]) for p in card.problems)
        lines.append(f"| {r.row.name} | {cells} |")
    return [*lines, ""]


def _invariants(card: ReportCard) -> list[str]:
    lines = [
        "## Invariants over a long run",
        "",
        f"T = {card.long_t:g} s at h = {LONG_H:g} s (adaptive: rtol = {LONG_RTOL:g}). "
        "Law of an invariant E (the energy; the Casimir ‖RᵀL‖, the body momentum's norm): "
        "the slope s of log max_{τ≤t} ΔE(τ) against log t over [T/10, T], ΔE = "
        f"abs(E − E₀)/abs(E₀): round-off (max ΔE ≤ {ROUND_OFF:g}), bounded "
        f"(s < {BOUNDED_SLOPE}), drift (s ≈ 1), grows (s > 1.3); failed: the run stopped. "
        "Claims: S symplectic (energy bounded, also with the dipole's conservative torque), "
        "E energy, C Casimir, O stays on SO(3); a claim the measurement contradicts is in "
        "bold. The forced body's ‖RᵀL‖ changes by the torque: not an invariant there. "
        "Δ‖q‖: how far a carried quaternion leaves the unit sphere in a step (— : none "
        "carried; the peers' q is never renormalised, MuJoCo renormalises it).",
        "",
        "| method | claims | P1 energy: law (s) | max ΔE | forced energy: law (s) | "
        "P1 ‖RᵀL‖: law (s) | max Δ‖RᵀL‖ | max ‖RᵀR − I‖ | max Δ‖q‖ |",
        "| --- | --- | --- | ---: | --- | --- | ---: | ---: | ---: |",
    ]
    for r in card.results:
        forced = "—" if r.forced is None else _law(r.forced.energy_law, r.forced.energy_slope)
        lines.append(
            f"| {r.row.name} | {_claims(r)} | "
            f"{_law(r.free.energy_law, r.free.energy_slope)} | {_sci(r.free.energy_max)} | "
            f"{forced} | {_law(r.free.casimir_law, r.free.casimir_slope)} | "
            f"{_sci(r.free.casimir_max)} | {_sci(r.free.orthogonality_max)} | "
            f"{_sci(r.free.quaternion_max)} |"
        )
    return [*lines, ""]


LETTERS = {"symplectic": "S", "energy": "E", "casimir": "C", "orthogonality": "O"}
"""The letter of each claim in the invariants table."""


def _claims(result: RowResult) -> str:
    """The row's claims as letters, in bold where a measurement contradicts one."""
    letters = "".join(
        f"**{LETTERS[c]}**" if any(c_word(c) in s for s in result.contradictions) else LETTERS[c]
        for c in CLAIMS
        if c in result.row.claims
    )
    return letters or "—"


def _costs(card: ReportCard) -> list[str]:
    lines = [
        "## Cost",
        "",
        f"Warm µs per accepted step on P1 (h = {STANDARD_H:g} s, adaptive rtol = "
        f"{STANDARD_RTOL:g}; best of {1 if card.quick else 3}); {card.first_call_note}. "
        "tumble's methods run compiled wherever their loads allow (as `simulate` chooses), "
        "scipy in Python, MuJoCo in C called step by step from Python, heyoka compiled by "
        "LLVM (its integrator built once per problem and tolerance, outside the timing; "
        "its order is that of its Taylor method at tol 1e-4, stepped at fixed h). An "
        "adaptive method's cost per step includes `simulate`'s per-call work spread over "
        "few steps. The fixed "
        "cost of a call is what a run of one step takes (best of 5): every run pays it "
        f"once, whatever its length. In the work–precision figures of `report.html`, a run "
        f"shorter than {AMORTISE} times it is timed over up to {MAX_SPANS} spans of T in "
        "one call, so that the points show what the steps cost; the fixed cost is drawn "
        "there as a line of its own.",
        "",
        "| method | µs/step | fixed µs/call | first call (s) |",
        "| --- | ---: | ---: | ---: |",
    ]
    for r in card.results:
        lines.append(f"| {r.row.name} | {_number(r.cost_us, 3)} | {_number(r.fixed_us, 3)} | "
                     f"{_number(r.first_call_s)} |")  # fmt: skip
    return [*lines, ""]


def _schemes(card: ReportCard) -> list[str]:
    if not card.structural:
        return []
    s = card.structural_setup
    lines = [
        "## Structural schemes",
        "",
        f"A 4-element steel cantilever ({s['n_dofs']} DOFs, ω₁ = {s['omega1']:.4g} rad/s) "
        "under a 1 N tip load from rest. Energy over "
        f"{s['periods']} periods at h = ½ Δt_crit(semi-implicit) = "
        f"{s['dt_crit_semi_implicit'] / 2:.3g} s, relative to the energy exchanged; order: "
        f"the tip displacement at T = {s['T_order']:.3g} s against the exact response "
        "(modal superposition, `tumble.structural.exact_response`); the scheme declares "
        "its order.",
        "",
        "| scheme | energy | max ΔE / scale | order declared | measured | fit range | "
        "critical Δt (s) |",
        "| --- | --- | ---: | ---: | ---: | --- | ---: |",
    ]
    for x in card.structural:
        lines.append(
            f"| {x.scheme} | {x.energy_law} | {_sci(x.energy_max)} | "
            f"{_number(x.order_expected)} | {_number(x.order_measured, 3)} | {x.order_fit} "
            f"| {_critical(x.critical_dt)} |"
        )
    return [*lines, ""]


def _closing(card: ReportCard) -> list[str]:
    return [
        "The interactive work–precision diagrams (orientation and energy error against wall "
        "time, the Pareto front marked) are in `report.html`, above these tables, the raw "
        "numbers in `report.nc`, "
        "both written beside `report.md` by `tumble report` (`make report` keeps them in "
        "`runs/report/` and copies this page to `docs/report.md`).",
        "",
    ]


def c_word(claim: str) -> str:
    """The word a contradiction sentence of ``claim`` starts with."""
    return {"symplectic": "symplectic", "energy": "energy-preserving", "casimir": "Casimir",
            "orthogonality": "SO(3)"}[claim]  # fmt: skip


def _critical(dt: float) -> str:
    if dt == 0:
        return "0 (never stable)"
    if math.isinf(dt):
        return "∞ (unconditional)"
    return f"{dt:.3g}"
