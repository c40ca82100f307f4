"""The T-handle's flip period over ω0's perturbations, beside the exact period's map.

Sweeps ``examples/flip-map.toml`` (ω0 = (1, ω_y, ω_z) rad/s near the intermediate axis) on
Dask, then computes the exact period ``4K(m)/λ`` of every member with
:func:`tumble.exact.free_body_period` and draws the measured map, the exact map (one colour
scale) and their relative difference side by side.

Run it: ``python examples/flip_map.py`` (writes ``runs/flip-map.zarr`` and
``runs/flip-map.png``; starts a local cluster, one worker per core). What it draws, on a
24 × 24 grid (``docs/img/flip_map.png``, made by ``docs/make_images.py``):

.. image:: /img/flip_map.png
   :alt: the measured flip period, the exact one and their relative difference
"""

# The gallery does not run this example (a Dask cluster): its card shows the picture above.
# sphinx_gallery_thumbnail_path = "img/flip_map.png"

from __future__ import annotations

from pathlib import Path

import numpy as np

import tumble
from tumble import RigidBody, exact
from tumble.sweeps.picture import axis_label
from tumble.viz.sweep import heat_maps

SCENARIO = Path(__file__).with_name("flip-map.toml")


def run(
    store: str | Path = "runs/flip-map.zarr",
    picture: str | Path | None = "runs/flip-map.png",
    *,
    size: int = 10,
    client=None,
) -> dict:
    """Sweep ``size`` × ``size`` perturbations; return the measured and exact periods.

    Returns
    -------
    dict
        ``measured`` and ``exact`` (s, shape (size, size): ω_y down, ω_z across),
        ``largest_relative_difference`` (max |measured/exact − 1|) and ``members``.
    """
    grid = {"omega0.1": np.linspace(0.01, 0.1, size), "omega0.2": np.linspace(0.0, 0.1, size)}
    dataset = tumble.sweep(SCENARIO, grid, client=client, store=store)
    body = RigidBody(1.0, np.asarray(_inertia(dataset)))
    measured = dataset["flip_period"].transpose("omega0.1", "omega0.2").values
    periods = [[exact.free_body_period(body.inertia, [1.0, wy, wz]) for wz in grid["omega0.2"]]
               for wy in grid["omega0.1"]]  # fmt: skip
    exact_map = np.array(periods)
    difference = np.abs(measured / exact_map - 1)
    if picture is not None:
        Path(picture).parent.mkdir(parents=True, exist_ok=True)
        heat_maps(
            [("measured (sweep, rkmk4, h = 0.01 s)", measured, "flip period (s)"),
             ("exact 4K(m)/λ", exact_map, "flip period (s)"),
             ("|measured / exact − 1|", difference, "relative difference (1)")],
            grid["omega0.2"], grid["omega0.1"], picture,
            xlabel=axis_label(dataset, "omega0.2"), ylabel=axis_label(dataset, "omega0.1"),
            title="T-handle spun about its intermediate axis x: flip period over ω0 = "
            "(1, ω_y, ω_z) rad/s",
            log={"relative difference (1)"},
        )  # fmt: skip
    return {
        "measured": measured,
        "exact": exact_map,
        "largest_relative_difference": float(np.nanmax(difference)),
        "members": int(dataset["done"].sum()),
    }


def _inertia(dataset) -> np.ndarray:
    """The swept body's inertia (kg m²), from the scenario the store was written from."""
    import json

    from tumble.scenarios.rigid_body import OPTIONS

    options = OPTIONS.model_validate(json.loads(dataset.attrs["options"]))
    description: object = options.body
    return np.asarray(description.mass_properties().inertia)  # type: ignore[attr-defined]


if __name__ == "__main__":
    numbers = run()
    print(f"{numbers['members']} members; largest |measured/exact - 1| = "
          f"{numbers['largest_relative_difference']:.2g}")  # fmt: skip
