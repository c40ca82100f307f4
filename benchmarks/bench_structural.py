"""Cost per time step of the structural schemes, and against OpenSeesPy.

Run ``.venv/bin/python benchmarks/bench_structural.py [--quick]``. Prints three tables:

1. µs per step of each scheme on the 1 m steel cantilever (1 cm square) with 10², 10³,
   10⁴, 10⁵ elements (``--quick``: 10², 10³), and the fitted exponent of cost against
   size (1 = linear). Start: the static deflection shape of a 1 N tip load, at rest, with
   no load (free vibration), so every DOF is O(1 mm) and no subnormal numbers appear;
   Δt = 0.1 · 2/ω_max, so the explicit schemes stay finite over the timed steps.
2. The effect of the start on the explicit scheme: from rest under the step load its
   state fills with subnormal numbers (far from the tip), which x86 handles slowly.
3. ``newmark`` (γ = ½, β = ¼) against OpenSeesPy's ``Newmark 0.5 0.25`` with
   ``algorithm Linear -factorOnce`` and ``system BandSPD`` on the same beam
   (elasticBeamColumn, consistent mass, axial DOFs fixed), from rest under the step tip
   load at Δt = T₁/200; the ratio is OpenSees time / tumble time (> 1: tumble is faster).
   Skipped, with a message, when ``openseespy`` cannot be imported (it needs Debian's
   ``libblas3 liblapack3``).

Per-step cost is ``(T(n₂) − T(n₁)) / (n₂ − n₁)`` of the public ``integrate`` (setup and
factorisation cancel), best of three. BLAS runs single-threaded (``OPENBLAS_NUM_THREADS=1``
unless set): OpenSees uses the reference BLAS, and OpenBLAS threads made SuperLU's small
triangular solves 3× slower on a busy 2-core machine.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # before numpy loads OpenBLAS

import argparse  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402

import numpy as np  # noqa: E402

from tumble import structural  # noqa: E402

LENGTH, E, RHO, SIDE, LOAD = 1.0, 210e9, 7850.0, 0.01, 1.0
EI = E * SIDE**4 / 12
SCHEMES = ("explicit", "semi-implicit", "implicit", "midpoint", "newmark")
REPEATS = 3


def steps_for(n_elements: int) -> tuple[int, int]:
    """(n₁, n₂) step counts: the difference is timed; about 0.1–1 s per size."""
    return {100: (200, 2200), 1000: (100, 1100), 10_000: (20, 220)}.get(n_elements, (5, 35))


def beam(n_elements: int, tip_load: float) -> structural.LinearSystem:
    with warnings.catch_warnings():  # N ≥ 4000 is ill-conditioned; cost is what we time
        warnings.simplefilter("ignore", structural.IllConditionedWarning)
        return structural.cantilever(LENGTH, n_elements, E, RHO, SIDE, SIDE, tip_load=tip_load)


def static_shape(n_elements: int) -> np.ndarray:
    """Exact static (v, θ) of nodes 1..N under the tip load.

    ``v = F ξ²(3L − ξ)/(6EI)``, ``θ = F ξ(2L − ξ)/(2EI)``.
    """
    xi = np.linspace(0, LENGTH, n_elements + 1)[1:]
    v = LOAD * xi**2 * (3 * LENGTH - xi) / (6 * EI)
    theta = LOAD * xi * (2 * LENGTH - xi) / (2 * EI)
    return np.column_stack([v, theta]).ravel()


def omega_max(n_elements: int) -> float:
    """ω_max ∝ 1/h² on a uniform mesh: scale the exact value at 100 elements."""
    reference = structural.critical_dt(beam(100, 0.0), "semi-implicit").omega
    return reference * (n_elements / 100) ** 2


def seconds_per_step(run_steps) -> float:
    """Best of REPEATS of (T(n₂) − T(n₁)) / (n₂ − n₁); ``run_steps(n)`` runs n steps."""
    n1, n2 = run_steps.steps
    best = np.inf
    for _ in range(REPEATS):
        times = []
        for n in (n1, n2):
            start = time.perf_counter()
            run_steps(n)
            times.append(time.perf_counter() - start)
        best = min(best, (times[1] - times[0]) / (n2 - n1))
    return max(best, 0.0)


def tumble_runner(system, scheme, dt, steps, **start):
    def run(n):
        result = structural.integrate(system, scheme, dt, n_steps=n, record_every=n, **start)
        if not result.success:
            raise RuntimeError(f"{scheme}: {result.message}")

    run.steps = steps
    return run


def scheme_table(sizes: list[int]) -> None:
    print("1. µs per step; start: static shape, no load; Δt = 0.1·2/ω_max")
    print(f"{'elements':>9} {'DOFs':>7} " + " ".join(f"{s:>13}" for s in SCHEMES))
    costs = {s: [] for s in SCHEMES}
    for n in sizes:
        system, dt = beam(n, 0.0), 0.1 * 2 / omega_max(n)
        row = []
        for scheme in SCHEMES:
            runner = tumble_runner(system, scheme, dt, steps_for(n), x0=static_shape(n))
            costs[scheme].append(seconds_per_step(runner) * 1e6)
            row.append(f"{costs[scheme][-1]:13.1f}")
        print(f"{n:>9} {system.n_dofs:>7} " + " ".join(row), flush=True)
    if len(sizes) >= 3:
        fit = slice(1, None)  # from 10³ on; 10² is dominated by per-call overhead
        exponents = [np.polyfit(np.log(sizes[fit]), np.log(costs[s][fit]), 1)[0] for s in SCHEMES]
        print(f"{'exponent':>17} " + " ".join(f"{e:13.2f}" for e in exponents), "(1 = linear)")


def subnormal_table(n: int) -> None:
    print(f"\n2. explicit scheme, {n} elements, Δt = 0.1·2/ω_max: the start matters")
    dt = 0.1 * 2 / omega_max(n)
    for label, system, start in (
        ("static shape, no load", beam(n, 0.0), {"x0": static_shape(n)}),
        ("rest, step tip load", beam(n, LOAD), {}),
    ):
        runner = tumble_runner(system, "explicit", dt, steps_for(n), **start)
        cost = seconds_per_step(runner) * 1e6
        last = structural.integrate(
            system, "explicit", dt, n_steps=steps_for(n)[1], record_every=steps_for(n)[1], **start
        )
        state = np.concatenate([last.x[-1], last.y[-1]])
        tiny = np.count_nonzero((state != 0) & (np.abs(state) < np.finfo(float).tiny))
        print(f"   {label:24s} {cost:9.1f} µs/step   subnormal entries: {tiny}/{state.size}")


def opensees_runner(ops, n, dt, steps):
    """The same cantilever in OpenSeesPy: one analyze call per timing."""
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for i, x in enumerate(np.linspace(0, LENGTH, n + 1)):
        ops.node(i + 1, float(x), 0.0)
        ops.fix(i + 1, 1, int(i == 0), int(i == 0))  # clamp node 1; axial DOFs fixed
    ops.geomTransf("Linear", 1)
    for e in range(n):
        ops.element(
            "elasticBeamColumn",
            e + 1,
            e + 1,
            e + 2,
            SIDE**2,
            E,
            SIDE**4 / 12,
            1,
            "-mass",
            RHO * SIDE**2,
            "-cMass",
        )
    ops.timeSeries("Constant", 1)
    ops.pattern("Plain", 1, 1)
    ops.load(n + 1, 0.0, LOAD, 0.0)
    ops.constraints("Plain")
    ops.numberer("Plain")
    ops.system("BandSPD")
    ops.algorithm("Linear", "-factorOnce")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    ops.analyze(1, dt)  # forms and factorises K_eff once

    def run(k):
        if ops.analyze(k, dt) != 0:
            raise RuntimeError("OpenSees analyze failed")

    run.steps = steps
    return run


def textbook_newmark(system, dt: float, n_steps: int) -> np.ndarray:
    """Average-acceleration Newmark from rest with a₀ = 0, as OpenSees starts it."""
    import scipy.sparse.linalg as spla

    M, f = system.M, system.f
    solve = spla.splu((system.S + 4 / dt**2 * M).tocsc()).solve
    x, v, a = (np.zeros(system.n_dofs) for _ in range(3))
    for _ in range(n_steps):
        x_new = solve(f + M @ (4 / dt**2 * x + 4 / dt * v + a))
        a_new = 4 / dt**2 * (x_new - x) - 4 / dt * v - a
        v, x, a = v + dt / 2 * (a + a_new), x_new, a_new
    return x


def peer_table(sizes: list[int]) -> None:
    try:
        from importlib.metadata import version

        import openseespy.opensees as ops
    except Exception as error:  # noqa: BLE001 — any import failure means: no peer
        print(f"\n3. OpenSeesPy not available ({type(error).__name__}: {error}); peer skipped.")
        print("   Install: pip install openseespy; apt-get install -y libblas3 liblapack3")
        return
    print(f"\n3. newmark vs OpenSeesPy {version('openseespy')} (Newmark ½ ¼, Linear -factorOnce,")
    print("   BandSPD); from rest under the 1 N step tip load, Δt = T₁/200;")
    print("   ratio = OpenSees µs / tumble µs (> 1: tumble faster). Tip error after 100 steps,")
    print("   over F L³/(3EI), against a converged 100-element run started the same way:")
    print("   tumble uses the consistent a₀ = M⁻¹f, OpenSees a₀ = 0 (its reference is a textbook")
    print("   a₀ = 0 Newmark on tumble's M, S). Beyond ~4000 elements double precision makes")
    print("   both meaningless (κ(S) ∝ N⁴; tumble warns): those rows time the cost only.")
    print(
        f"{'elements':>9} {'tumble µs':>10} {'OpenSees µs':>12} {'ratio':>7} "
        f"{'tumble tip err':>15} {'OpenSees tip err':>17}"
    )
    static_tip = LOAD * LENGTH**3 / (3 * EI)
    n_check = 100
    dt = 2 * np.pi / beam(100, 0.0).natural_frequencies(1)[0] / 200
    reference = {
        "tumble": structural.integrate(beam(100, LOAD), "newmark", dt, n_steps=n_check).x[-1, -2],
        "OpenSees": textbook_newmark(beam(100, LOAD), dt, n_check)[-2],
    }
    for n in sizes:
        system = beam(n, LOAD)
        ours = seconds_per_step(tumble_runner(system, "newmark", dt, steps_for(n))) * 1e6
        peer = seconds_per_step(opensees_runner(ops, n, dt, steps_for(n))) * 1e6
        opensees_runner(ops, n, dt, steps_for(n))(n_check - 1)  # 1 step already taken
        tip_peer = ops.nodeDisp(n + 1, 2)
        tip_ours = structural.integrate(system, "newmark", dt, n_steps=n_check).x[-1, -2]
        print(
            f"{n:>9} {ours:10.1f} {peer:12.1f} {peer / ours:7.2f} "
            f"{abs(tip_ours - reference['tumble']) / static_tip:15.1e} "
            f"{abs(tip_peer - reference['OpenSees']) / static_tip:17.1e}",
            flush=True,
        )
    ops.wipe()


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="10² and 10³ elements only")
    args = parser.parse_args(argv)
    sizes = [100, 1000] if args.quick else [100, 1000, 10_000, 100_000]
    print(
        f"tumble structural benchmark — python {sys.version.split()[0]}, numpy "
        f"{np.__version__}, OPENBLAS_NUM_THREADS={os.environ['OPENBLAS_NUM_THREADS']}"
    )
    structural.integrate(beam(10, LOAD), "midpoint", 1e-4, n_steps=2)  # compile kernels
    scheme_table(sizes)
    subnormal_table(1000)
    peer_table(sizes)


if __name__ == "__main__":
    main()
