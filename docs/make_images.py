"""Draw the README's pictures into docs/img/ with tumble itself: ``python docs/make_images.py``.

Each picture is a scenario's own output (or frames of its animation, or a headless-Chromium
screenshot of its ``view.html``), shrunk to at most 900 px wide and stored as a palette PNG so
the repository stays small. Needs Debian's ``chromium`` and ``chromium-driver`` for the viewer
(``make test`` installs them).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

from PIL import Image

from tumble import io, scenarios
from tumble.scenarios import beam, compare

IMAGES = Path(__file__).parent / "img"
WIDTH = 900


def shrink(source: Path, name: str, width: int = WIDTH) -> Path:
    """Save ``source`` as ``docs/img/name``: at most ``width`` px wide, 256-colour PNG."""
    with Image.open(source) as image:
        image = image.convert("RGB")
        if image.width > width:
            image = image.resize((width, round(image.height * width / image.width)), Image.LANCZOS)
        target = IMAGES / name
        image.quantize(256).save(target, optimize=True)
    print(f"{target} ({target.stat().st_size // 1024} KB)")
    return target


def strip(gif: Path, name: str, frames: list[float]) -> Path:
    """Frames at the given fractions of ``gif`` side by side, as one PNG."""
    with Image.open(gif) as animation:
        chosen = []
        for fraction in frames:
            animation.seek(min(int(fraction * animation.n_frames), animation.n_frames - 1))
            chosen.append(animation.convert("RGB"))
    width, height = chosen[0].size
    sheet = Image.new("RGB", (width * len(chosen), height), "white")
    for k, frame in enumerate(chosen):
        sheet.paste(frame, (k * width, 0))
    source = Path(tempfile.mkdtemp()) / "strip.png"
    sheet.save(source)
    return shrink(source, name, width=min(WIDTH * 3 // 2, sheet.width))


def screenshot(page: Path, name: str) -> Path:
    """``page`` in headless Chromium, after moving to the middle frame, as a PNG."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = "/usr/bin/chromium"
    for flag in (
        "--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader",
        "--window-size=1200,1100", f"--user-data-dir={tempfile.mkdtemp()}",
    ):  # fmt: skip
        options.add_argument(flag)
    driver = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)
    try:
        driver.get(page.resolve().as_uri())
        driver.implicitly_wait(20)
        driver.find_element("css selector", ".js-plotly-plot .gl-container canvas")
        driver.execute_script(
            "const div = document.querySelector('.js-plotly-plot');"
            "const steps = div.layout.sliders[0].steps;"
            "Plotly.animate(div, [steps[Math.floor(steps.length / 2)].args[0][0]],"
            "{mode: 'immediate', frame: {duration: 0, redraw: true}, transition: {duration: 0}});"
        )
        driver.implicitly_wait(2)
        source = Path(tempfile.mkdtemp()) / "view.png"
        driver.save_screenshot(str(source))
    finally:
        driver.quit()
    return shrink(source, name)


def long_run_energy() -> Path:
    """docs/geometric.md's picture: P1, h = 0.05, 10⁶ steps, the largest energy error so far."""
    import numpy as np

    from tumble import RigidBody, simulate
    from tumble.viz import rigid

    body = RigidBody(1.0, [2.0, 1.0, 2.0 / 3.0], allow_unphysical=True)
    L0 = (np.cos(1.1), 0.0, np.sin(1.1))
    methods = ["split-axes", "split-axes4", "midpoint-lp", "dmv", "rkmk4", "rk4-quat"]
    runs = [
        (method, simulate(body, 50_000.0, method=method, h=0.05, L0=L0, record_every=100))
        for method in methods
    ]
    source = Path(tempfile.mkdtemp()) / "long_run_energy.png"
    title = "Hairer's body P1, h = 0.05, 10⁶ steps: the energy error"
    rigid.energy_error_loglog(runs, source, title=title)
    return shrink(source, "long_run_energy.png")


def flip_map() -> Path:
    """docs/sweeps.md's picture: examples/flip_map.py on a 24 x 24 grid (a local cluster)."""
    import importlib.util

    path = Path(__file__).parents[1] / "examples" / "flip_map.py"
    spec = importlib.util.spec_from_file_location("flip_map", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    work = Path(tempfile.mkdtemp())
    module.run(work / "flip-map.zarr", work / "flip-map.png", size=24)
    return shrink(work / "flip-map.png", "flip_map.png", width=1200)


def main() -> None:
    if sys.argv[1:] == ["flip_map"]:  # only the sweep's picture
        flip_map()
        return
    IMAGES.mkdir(exist_ok=True)
    work = Path(tempfile.mkdtemp())

    def folder(name: str, result, animation: bool = True) -> Path:
        return io.write_run_folder(result, work / name, animation=animation)

    projectile = folder("projectile", scenarios.get("projectile").run())
    shrink(projectile / "trajectory.png", "trajectory.png")

    t_handle = folder("t-handle", scenarios.get("t-handle").run())
    shrink(t_handle / "rotation_grid_spin1.png", "rotation_grid.png")
    shrink(t_handle / "euler_angles_spin1.png", "euler_angles.png")
    shrink(t_handle / "drift.png", "drift.png")
    strip(t_handle / "animation.gif", "animation.png", [0.0, 0.22, 0.45])
    screenshot(t_handle / "view.html", "viewer.png")

    torus = folder("torus", scenarios.get("torus-spin").run(), animation=False)
    shrink(torus / "error_vs_exact.png", "error_vs_exact.png")

    convergence = folder("convergence", scenarios.get("convergence").run())
    shrink(convergence / "convergence.png", "convergence.png")

    work_precision = folder("compare", compare.run("t-handle"))
    shrink(work_precision / "work_precision.png", "work_precision.png")

    cantilever = folder("beam", scenarios.get("beam").run())
    strip(cantilever / "animation.gif", "beam.png", [0.025, 0.05])  # T₁/4, T₁/2
    shrink(cantilever / "energy_midpoint.png", "energy.png")
    stability = folder("stability", beam.stability())
    shrink(stability / "stability_sweep.png", "stability_sweep.png")

    long_run_energy()
    top = folder("spinning-top", scenarios.get("spinning-top").run(), animation=False)
    shrink(top / "top.png", "top.png")
    flip_map()


if __name__ == "__main__":
    sys.exit(main())
