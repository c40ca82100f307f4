"""Today's code against an earlier commit, in one process (issue 25's speed checks).

Run ``.venv/bin/python benchmarks/bench_renovation.py [--against COMMIT] [--repeat N]
[--groups rigid,beam,solve]``. The package as it was at ``COMMIT`` (default: the last commit
before the renovation) is taken from git into ``$TMPDIR/tumble-COMMIT`` as ``tumble_old``
(its imports renamed, and its named tuples, which numba's dispatcher tells apart by class
name only), so both run in this process on the same numba and the same machine. Each case is
warmed up, then timed alternately (in both orders) by the CPU time of the thread, per step
(two lengths of run, so setup cancels) or per call; each row gives both medians (min–max)
and new/old. The groups: ``rigid`` (the issue's ``rkmk4``, ``rkmk-dopri5`` and batch cases,
every split method, ``rk4-quat`` and ``cg4``), ``beam`` (docs/structural.md's beams and
schemes) and ``solve`` (a compiled right-hand side: long runs, events and dense output, and
short calls of 10 and 13 steps).
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # before numpy loads OpenBLAS

import argparse  # noqa: E402
import importlib  # noqa: E402
import re  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tarfile  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from io import BytesIO  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from _timing import load, machine, spread, table  # noqa: E402

BEFORE = "75320d1"
"""The last commit of main before the renovation."""

ROOT = Path(__file__).resolve().parents[1]


def old_package(commit: str, folder: Path) -> object:
    """``tumble`` as it was at ``commit``, importable as ``tumble_old`` from ``folder`` (kept
    between runs, so that numba's cache beside it spares the old kernels' compilation)."""
    if not (folder / "tumble_old").exists():
        _extract(commit, folder)
    sys.path.insert(0, str(folder))
    return importlib.import_module("tumble_old")


def _extract(commit: str, folder: Path) -> None:
    archive = subprocess.run(
        ["git", "-C", str(ROOT), "archive", commit, "src/tumble"],
        check=True, capture_output=True,
    ).stdout  # fmt: skip
    with tarfile.open(fileobj=BytesIO(archive)) as tar:
        tar.extractall(folder, filter="data")
    (folder / "src" / "tumble").rename(folder / "tumble_old")
    paths = list((folder / "tumble_old").rglob("*.py"))
    # numba's dispatcher keys a named tuple's type by its class name: the copy's Grid,
    # KernelProblem, … would share the typecodes of today's and miss its compiled loops at
    # every call (numba's slow dispatch path, ~0.7 ms), so they get names of their own.
    tuples = {
        name
        for path in paths
        for name in re.findall(r"^class (\w+)\(NamedTuple\)", path.read_text(), re.M)
    }
    for path in paths:
        text = path.read_text()
        text = re.sub(r"\btumble\.", "tumble_old.", text)
        text = re.sub(r"from tumble import", "from tumble_old import", text)
        for name in tuples:
            text = re.sub(rf"\b{name}\b", f"{name}Then", text)
        path.write_text(text)


# A case is (run, steps): ``run(n)`` does n steps (or, with steps None, the whole call),
# timed as µs per step ``(T(n₂) − T(n₁)) / (n₂ − n₁)`` for ``steps = (n₁, n₂)``, so that
# what a call costs besides its steps (its setup, a factorisation) cancels.
SPLIT = ("split-axes", "split-axes4", "midpoint-lp", "dmv", "exact", "strang", "yoshida4")
"""Every split method; ``strang`` and ``yoshida4`` with a load (a weight off the centre)."""
BEAMS = (
    ("axial", 100, "newmark"), ("axial", 1000, "newmark"), ("axial", 10_000, "newmark"),
    ("bending", 100, "newmark"), ("bending", 1000, "newmark"), ("bending", 10_000, "newmark"),
    ("bending", 1000, "midpoint"), ("bending", 1000, "implicit"), ("bending", 1000, "hht"),
    ("bending", 1000, "generalized-alpha"), ("bending", 1000, "bathe"),
    ("bending", 1000, "wilson"), ("bending", 4, "newmark"),
)  # fmt: skip
"""docs/structural.md's cases (1 m steel cantilever, 1 cm square, Δt = T₁/200 from rest under
a 1 N tip load) and the 4-element beam where a step costs least."""
BEAM_STEPS = {4: (2000, 200_000), 100: (200, 20_200), 1000: (100, 4100), 10_000: (20, 420)}


def rigid_cases(package) -> dict:
    """The issue's rigid cases, the split flows and the charts, µs per step."""
    body = package.RigidBody(mass=1.0, inertia=np.diag([3.0, 2.0, 1.5]))
    omega = np.array([0.3, 1.0, 0.2])
    weight = [package.rigid.forces.Force([0.0, 0.0, -9.81], point=[0.0, 0.0, 0.1])]

    def fixed(method: str, loads=()):
        return lambda n: package.simulate(body, n * 0.01, method=method, h=0.01, omega0=omega,
                                          record_every=n, forces=loads)  # fmt: skip

    def adaptive(n):
        return package.simulate(body, n * 0.01, method="rkmk-dopri5", rtol=1e-8, atol=1e-10,
                                omega0=omega)  # fmt: skip

    spins = np.random.default_rng(1).normal(size=(1000, 3))

    def batch(method: str):
        return lambda n: package.simulate_batch(body, 10.0, method=method, h=0.01,
                                                omega0=spins, record_every=1000)  # fmt: skip

    out = {f"{m}{' (weight)' if m in ('strang', 'yoshida4') else ''}":
           (fixed(m, weight if m in ("strang", "yoshida4") else ()), (2000, 42_000))
           for m in SPLIT}  # fmt: skip
    out.update({m: (fixed(m), (2000, 22_000)) for m in ("rkmk4", "rk4-quat", "cg4")})
    out["rkmk-dopri5, rtol 1e-8 (per 0.01 s)"] = (adaptive, (2000, 22_000))
    out["simulate_batch rkmk4, 1000 bodies × 1000 steps"] = (batch("rkmk4"), None)
    out["simulate_batch split-axes, 1000 bodies × 1000 steps"] = (batch("split-axes"), None)
    return out


def beam_cases(package) -> dict:
    """docs/structural.md's beams, µs per step of the public ``integrate``."""
    structural = package.structural
    dt = 2 * np.pi / structural.cantilever(1.0, 100, 210e9, 7850.0, 0.01, 0.01) \
        .natural_frequencies(1)[0] / 200  # fmt: skip
    out = {}
    for kind, n, scheme in BEAMS:
        with warnings.catch_warnings():  # N ≥ 3700 is ill-conditioned; cost is what we time
            warnings.simplefilter("ignore")
            beam = structural.cantilever(1.0, n, 210e9, 7850.0, 0.01, 0.01, tip_load=1.0,
                                         axial=kind == "axial")  # fmt: skip

        def run(k, beam=beam, scheme=scheme):
            return structural.integrate(beam, scheme, dt, n_steps=k, record_every=k)

        steps = (50, 2050) if scheme == "bathe" else BEAM_STEPS[n]
        out[f"beam {kind}, {n} elements, {scheme}"] = (run, steps)
    return out


def solve_cases(package) -> dict:
    """``solve`` with a compiled right-hand side: long runs (µs per step) and short calls
    (µs per call)."""
    fun = _van_der_pol()

    def position(t, y):
        return y[0]

    def call(**options):
        return lambda n: package.solve(fun, (0, n * 0.01), [2, 0], **options)

    return {
        "solve rk4 (per step)": (call(method="rk4", h=0.01), (1000, 21_000)),
        "solve rk8 (per step)": (call(method="rk8", h=0.01), (1000, 11_000)),
        "solve dopri5 rtol 1e-8 (per 0.01 s)": (
            call(method="dopri5", rtol=1e-8, atol=1e-8),
            (1000, 21_000),
        ),  # fmt: skip
        "solve rkf45, events and dense output (per 0.01 s)": (
            call(method="rkf45", rtol=1e-6, events=position, dense_output=True),
            (100, 2100),
        ),
        "solve rk4, a call of 10 steps": (lambda n: call(method="rk4", h=0.01)(10), None),
        "solve dopri5, a call of 1 s (13 steps)": (
            lambda n: call(method="dopri5", rtol=1e-6)(100),
            None,
        ),
    }


def _van_der_pol():
    import numba

    @numba.njit
    def van_der_pol(t, y):
        return np.array([y[1], 2.0 * (1 - y[0] ** 2) * y[1] - y[0]])

    return van_der_pol


GROUPS = {"rigid": rigid_cases, "beam": beam_cases, "solve": solve_cases}


def _sample(run, steps) -> float:
    """One timing (CPU time of this thread): µs per step, or per call."""
    if steps is None:
        start = time.thread_time()
        for _ in range(50):
            run(0)
        return (time.thread_time() - start) / 50 * 1e6
    times = []
    for n in steps:
        start = time.thread_time()
        run(n)
        times.append(time.thread_time() - start)
    return (times[1] - times[0]) / (steps[1] - steps[0]) * 1e6


def compare(new: dict, old: dict, repeat: int) -> list[list[str]]:
    rows = []
    for name, (run, steps) in new.items():
        other = old[name][0]
        for fn in (run, other):  # warm up: compile or load from the cache
            fn(steps[0] if steps else 0)
        times: dict[str, list[float]] = {"new": [], "old": []}
        for i in range(repeat):  # alternate, in both orders: drifts of the machine hit both
            pair = (("new", run), ("old", other)) if i % 2 == 0 else (("old", other), ("new", run))
            for key, fn in pair:
                times[key].append(_sample(fn, steps))
        n, o = np.array(times["new"]), np.array(times["old"])
        unit = "µs/call" if steps is None else "µs/step"
        rows.append([
            name,
            f"{spread(np.median(n), n.min(), n.max(), 1.0, 3)} {unit}",
            f"{spread(np.median(o), o.min(), o.max(), 1.0, 3)} {unit}",
            f"{np.median(n) / np.median(o):.3f}",
        ])  # fmt: skip
        print(" | ".join(rows[-1]), flush=True)
    return rows


def main() -> str:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--against", default=BEFORE, help="the commit to compare with")
    parser.add_argument("--repeat", type=int, default=11)
    parser.add_argument("--groups", default=",".join(GROUPS), help="of " + ", ".join(GROUPS))
    args = parser.parse_args()
    import tumble

    old = old_package(args.against, Path(tempfile.gettempdir()) / f"tumble-{args.against}")
    rows = []
    for group in args.groups.split(","):
        rows += compare(GROUPS[group](tumble), GROUPS[group](old), args.repeat)
    text = "\n".join([
        f"## Today's code against {args.against} (median (min–max) of {args.repeat}, CPU time)",
        "",
        table(["case", "now", f"at {args.against}", "now/then"], rows),
        "",
        f"{machine()}; {load()}",
    ])  # fmt: skip
    print(text)
    return text


if __name__ == "__main__":
    main()
