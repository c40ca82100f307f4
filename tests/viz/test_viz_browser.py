"""view.html in a real browser: headless Chromium (Debian's ``chromium``, ``chromium-driver``;
the ``browser`` fixture is in tests/conftest.py).

``make test`` installs both packages when they are missing. Without them these tests fail
(they are not skipped): the viewer is only known to work once a browser has drawn it.

WebGL runs on SwiftShader (software); ``--enable-unsafe-swiftshader`` opts in to it, so
Chromium logs no deprecation warning for the automatic fallback.
"""

import numpy as np
import pytest

import tumble
from tumble import meshes
from tumble.viz.html import DIV_ID, html_viewer, viewer_figure

WAIT_S = 20
FRAMES = 20
PLOT = f"document.getElementById('{DIV_ID}')"
DRAWN_SCENE = f"""
const div = {PLOT};
return Boolean(div && div.classList.contains('js-plotly-plot') && div._fullLayout
    && div._fullLayout.scene && div._fullLayout.scene._scene
    && div._fullLayout.scene._scene.glplot
    && div.querySelector('.gl-container canvas'));
"""
SLIDER_STATE = f"""
const div = {PLOT};
return [div._fullLayout.sliders[0].active, Array.from(div._fullData[0].x)];
"""


@pytest.fixture(scope="module")
def view(tmp_path_factory):
    """view.html of a 5 s T-handle run (h = 0.01 s, 20 frames) and the figure it draws."""
    body = tumble.rigid.RigidBody.from_mass_properties(tumble.mass.t_handle())
    run = tumble.rigid.simulate(body, 5.0, h=0.01, omega0=(0.0, 5.0, 0.1))
    path = tmp_path_factory.mktemp("view") / "view.html"
    html_viewer(run, meshes.t_handle(16), path, title="T-handle", frames=FRAMES)
    return path, viewer_figure(run, meshes.t_handle(16), title="T-handle", frames=FRAMES)


@pytest.fixture
def page(browser, view):
    """The browser with view.html loaded and its 3D scene drawn (WebGL context live)."""
    from selenium.webdriver.support.ui import WebDriverWait

    browser.get_log("browser")  # drop the previous page's messages
    browser.get(view[0].as_uri())
    WebDriverWait(browser, WAIT_S).until(
        lambda driver: driver.execute_script(DRAWN_SCENE),
        message=f"the 3D scene of {view[0].name} was not drawn within {WAIT_S} s",
    )
    return browser


def severe_messages(driver) -> list[str]:
    """The console's SEVERE entries since the last call (warnings, e.g. GPU stalls, pass)."""
    return [entry["message"] for entry in driver.get_log("browser") if entry["level"] == "SEVERE"]


def test_view_loads_with_a_webgl_scene_and_no_console_errors(page):
    """The plot, its 3D scene with a live WebGL context and a canvas appear (the ``page``
    fixture waits for them); the console holds no SEVERE entry; the mesh is the first trace."""
    assert severe_messages(page) == []
    assert page.execute_script(f"return {PLOT}._fullLayout.scene.xaxis.title.text") == "x (m)"
    assert page.execute_script(f"return {PLOT}._fullData[0].type") == "mesh3d"


def test_clicking_the_slider_rail_moves_the_mesh(page, view):
    """Drive the real slider UI: a click on its rail at 70 % of its width.

    The slider's active step must change to about 70 % of the frames, and the drawn mesh's
    vertices (``_fullData[0].x``) must change to exactly that frame's vertices.
    """
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait

    active, before = page.execute_script(SLIDER_STATE)
    assert active == 0
    rail = page.find_element(By.CSS_SELECTOR, f"#{DIV_ID} .slider-rail-touch-rect")
    offset = round(0.2 * rail.size["width"])  # from the rail's centre: 70 % along
    ActionChains(page).move_to_element_with_offset(rail, offset, 0).click().perform()
    WebDriverWait(page, WAIT_S).until(
        lambda driver: driver.execute_script(SLIDER_STATE)[0] != 0,
        message=f"the slider did not move within {WAIT_S} s of a click on its rail",
    )
    WebDriverWait(page, WAIT_S).until(
        lambda driver: driver.execute_script(SLIDER_STATE)[1] != before,
        message=f"the mesh was not redrawn within {WAIT_S} s of moving the slider",
    )
    active, after = page.execute_script(SLIDER_STATE)
    assert abs(active - 0.7 * (FRAMES - 1)) <= 1.5
    expected = np.asarray(view[1].frames[active].data[0].x, dtype=float)
    np.testing.assert_allclose(after, expected, rtol=1e-6)
    assert severe_messages(page) == []


ENERGY_AXIS_BOXES = f"""
const div = {PLOT};
const box = (el) => {{ const r = el.getBoundingClientRect(); return [r.left, r.right]; }};
const ticks = Array.from(div.querySelectorAll('.yaxislayer-above .ytick text')).map(box);
const title = div.querySelector('.g-ytitle text');
return [ticks, title ? box(title) : null, div.getBoundingClientRect().left];
"""


@pytest.mark.parametrize("height", [0.0, 1e4])
def test_energy_tick_labels_and_title_keep_clear_of_the_edge_and_each_other(
    browser, tmp_path, height
):
    # Energy tick labels are long (4.920394e−5 J; 1.0000001e+5 J for a body high in gravity);
    # they used to run into the page edge and into the axis title.
    from selenium.webdriver.support.ui import WebDriverWait

    body = tumble.rigid.RigidBody.from_mass_properties(tumble.mass.t_handle())
    loads = [tumble.rigid.Gravity()] if height else []
    run = tumble.rigid.simulate(
        body, 2.0, h=0.01, x0=(0, 0, height), omega0=(0.0, 5.0, 0.1), forces=loads
    )
    path = tmp_path / "view.html"
    html_viewer(run, meshes.t_handle(16), path, title="T-handle", frames=FRAMES)
    browser.get(path.as_uri())
    WebDriverWait(browser, WAIT_S).until(lambda driver: driver.execute_script(DRAWN_SCENE))
    ticks, title, left = browser.execute_script(ENERGY_AXIS_BOXES)
    assert ticks and title is not None
    first_tick = min(start for start, _ in ticks)
    assert first_tick >= left + 4, f"a tick label starts {first_tick - left:.0f} px from the edge"
    # a clear gap from the page edge (it was 10-15 px) and from the tick labels
    assert title[0] >= left + 24, f"the axis title starts {title[0] - left:.0f} px from the edge"
    assert title[1] + 6 <= first_tick, (
        f"title ends at {title[1]:.0f}, labels start {first_tick:.0f}"
    )
