"""Mass properties of the seeds' bodies: the T-handle (seed 002) and the torus (seed 000)
=======================================================================================

The T-handle is two solid cylinders added by the parallel-axis theorem; the torus is the
closed form next to trimesh meshes of increasing section count, whose error falls like
1/sections² (the log-log slope, drawn). Run it: ``python examples/mass_properties.py``.
"""

from __future__ import annotations

import numpy as np

from tumble import mass, meshes


def torus_sections_table(sections: tuple[int, ...]) -> list[dict[str, float]]:
    """Volume and principal inertia of the R = 1, r = 0.5, rho = 1 torus mesh per count."""
    rows = []
    for n in sections:
        body = meshes.from_mesh(meshes.torus(1.0, 0.5, n), density=1.0)
        rows.append(
            {
                "sections": n,
                "volume": body.mass,
                **dict(zip("xyz", body.inertia.diagonal(), strict=True)),
            }
        )
    return rows


def run(sections: tuple[int, ...] = (16, 32, 64, 128)) -> dict[str, object]:
    """T-handle and torus numbers; no files, no printing.

    Returns
    -------
    dict
        ``t_handle``: mass (kg), com (m), inertia diagonal (kg m²); ``torus``: exact volume
        and inertia diagonal; ``torus_meshes``: one row per section count; ``slope``: the
        log-log slope of the mesh volume error against the section count (about -2).
    """
    handle = mass.t_handle()
    torus = mass.torus(1.0, 0.5, density=1.0)
    rows = torus_sections_table(sections)
    errors = [abs(row["volume"] - torus.mass) for row in rows]
    slope = np.polyfit(np.log(sections), np.log(errors), 1)[0]
    return {
        "t_handle": {
            "mass": handle.mass,
            "com": handle.com.tolist(),
            "inertia": handle.inertia.diagonal().tolist(),
        },
        "torus": {"volume": torus.mass, "inertia": torus.inertia.diagonal().tolist()},
        "torus_meshes": rows,
        "slope": float(slope),
    }


def figure(numbers: dict):
    """The torus meshes' relative volume error against the section count, log-log."""
    import matplotlib.pyplot as plt

    rows, exact = numbers["torus_meshes"], numbers["torus"]["volume"]
    sections = np.array([row["sections"] for row in rows])
    error = np.array([abs(row["volume"] - exact) / exact for row in rows])
    fig, axes = plt.subplots(figsize=(6, 4), layout="constrained")
    axes.loglog(sections, error, "o-", label="trimesh torus, mass properties of the mesh")
    fit = error[0] * (sections / sections[0]) ** numbers["slope"]
    axes.loglog(sections, fit, "k--", lw=1, label=f"fitted slope {numbers['slope']:.3f}")
    axes.set_xticks(sections, [str(n) for n in sections], minor=False)
    axes.set_xticks([], minor=True)
    axes.set(xlabel="sections (around the tube and around the axis)")
    axes.set(ylabel="relative volume error [–]", title="torus R = 1, r = 0.5: mesh against exact")
    axes.grid(alpha=0.3, which="both")
    axes.legend()
    return fig


if __name__ == "__main__":
    import matplotlib.pyplot as plt

    numbers = run()
    handle = numbers["t_handle"]
    print(f"T-handle: mass {handle['mass']:.7f} kg, com {handle['com']} m")
    print(f"  inertia diag {np.array(handle['inertia'])} kg m^2")
    torus = numbers["torus"]
    print(f"torus exact: volume {torus['volume']:.6f}, inertia {np.round(torus['inertia'], 6)}")
    print("sections  volume    I_xx      I_zz")
    for row in numbers["torus_meshes"]:
        print(f"{row['sections']:8d}  {row['volume']:.5f}  {row['x']:.5f}  {row['z']:.5f}")
    print(f"volume error ~ sections^{numbers['slope']:.3f}")
    figure(numbers)
    plt.show()
