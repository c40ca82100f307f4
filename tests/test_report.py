"""The report card: `tumble report --quick` measures every method as it declares itself.

One quick report (the CLI, about 20 s) is shared by the tests of this module; its raw numbers
are read back from ``report.nc``. A method given a wrong declaration must be flagged: the
check can fail. The HTML page is loaded in headless Chromium as tests/viz/test_viz_browser.py
does (Debian's ``chromium`` and ``chromium-driver``; ``make test`` installs them).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from tumble import report_card
from tumble.cli import app
from tumble.rigid import METHODS
from tumble.rigid.methods import Method
from tumble.structural import SCHEMES
from tumble.viz.report_card import DIV_ID, FLAG, pareto_front, report_figure


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("report")
    result = CliRunner().invoke(app, ["report", "--quick", "--out", str(out)])
    assert result.exit_code == 0, result.output
    return out


@pytest.fixture(scope="module")
def numbers(folder):
    import xarray as xr

    with xr.open_datatree(folder / "report.nc") as tree:
        return {name: tree[name].to_dataset().load() for name in tree.children}


def test_the_quick_report_writes_its_three_files_with_a_row_per_method(folder, numbers):
    # (its time, 15 s on an idle 2-core machine, is reported in report.md, not asserted)
    assert {p.name for p in folder.iterdir()} == {"report.md", "report.html", "report.nc"}
    text = (folder / "report.md").read_text(encoding="utf-8")
    assert "the report took " in text and "Machine: " in text
    # every method of METHODS and the two scipy peers are rows: nothing listed by hand
    methods = list(numbers["methods"]["method"].values)
    assert set(METHODS) | {"scipy DOP853", "scipy RK45"} <= set(methods)
    for name in METHODS:
        assert f"\n| {name} |" in text


@pytest.mark.parametrize("name", list(METHODS))
def test_measured_order_agrees_with_the_declared_one(numbers, name):
    row = numbers["methods"].sel({"method": name})
    declared = METHODS[name].order
    assert float(row["order_declared"]) == declared
    if math.isinf(declared):  # the exact flow: every error at round-off
        assert str(row["order_verdict"].values) == "exact"
        return
    # an adaptive method's formula is measured at fixed steps, like the others
    assert abs(float(row["order_measured"]) - declared) <= report_card.ORDER_TOLERANCE
    assert str(row["order_verdict"].values) == "agrees"


@pytest.mark.parametrize("name", list(METHODS))
def test_measured_invariants_agree_with_the_declared_ones(numbers, name):
    row = numbers["methods"].sel({"method": name})
    method = METHODS[name]
    if "energy" in method.conserves:
        assert float(row["energy_max"]) <= report_card.ROUND_OFF
    if method.symplectic:
        assert str(row["energy_law"].values) in ("round-off", "bounded")
        if not method.exact:  # with the dipole's conservative torque, too
            assert str(row["forced_energy_law"].values) in ("round-off", "bounded")
    if "casimir" in method.conserves:
        assert float(row["casimir_max"]) <= report_card.ROUND_OFF
        assert str(row["casimir_law"].values) == "round-off"
    if "orthogonality" in method.conserves:
        assert float(row["orthogonality_max"]) <= report_card.ROUND_OFF
    assert str(row["contradictions"].values) == ""


def test_the_markdown_lists_no_contradiction_and_the_structural_schemes(folder, numbers):
    text = (folder / "report.md").read_text(encoding="utf-8")
    assert text.index("## Contradictions") < text.index("## Order")
    assert "None: every method" in text
    schemes = numbers["structural"]
    assert list(schemes["scheme"].values) == list(SCHEMES)
    laws = schemes["energy_law"].to_series()
    assert laws["midpoint"] == "round-off" and laws["explicit"] == "grows"
    assert laws["implicit"] == "dissipates"
    assert float(schemes["critical_dt"].sel(scheme="explicit")) == 0.0


@pytest.mark.parametrize("name", [name for name in SCHEMES if name != "explicit"])
def test_structural_orders_measured_against_the_exact_response(numbers, name):
    # each scheme's declared order, measured against structural.exact_response; the
    # explicit scheme grows at every Δt and has no order (NaN, below)
    scheme = numbers["structural"].sel({"scheme": name})
    assert float(scheme["order_expected"]) == SCHEMES[name].order
    assert abs(float(scheme["order_measured"]) - SCHEMES[name].order) <= 0.2


def test_the_explicit_scheme_has_no_order(numbers):
    assert math.isnan(float(numbers["structural"]["order_measured"].sel({"scheme": "explicit"})))


def test_a_wrong_declared_order_is_flagged(tmp_path, monkeypatch):
    monkeypatch.setitem(METHODS, "rkmk4", dataclasses.replace(METHODS["rkmk4"], order_override=3))
    card = report_card.report(
        tmp_path, quick=True, methods=["rkmk4"], peers=False, structural=False
    )
    (result,) = card.results
    assert result.order.verdict == "contradicts"
    assert abs(result.order.measured - 4) <= 0.2  # the measurement is unchanged
    assert list(card.contradictions) == ["rkmk4"]
    assert card.contradictions["rkmk4"][0].startswith("order: declared 3, measured 4.0")
    text = (tmp_path / "report.md").read_text(encoding="utf-8")
    top = text[text.index("## Contradictions") : text.index("## Order")]
    assert "**rkmk4** — order: declared 3" in top
    page = (tmp_path / "report.html").read_text(encoding="utf-8")
    assert '<div id="contradictions" style="color:#d62728">' in page
    figure = report_figure(report_card.plot_data(card))
    curves = [trace for trace in figure.data if trace.legendgroup == "rkmk4"]
    assert len(curves) == 4 and {trace.line.color for trace in curves} == {FLAG}
    assert curves[0].name == "rkmk4 ✗ contradicts"


class _ClaimsEnergy(Method):
    """``rkmk4`` claiming to keep the energy, which it does not (a drift of 1e-10)."""

    @property
    def conserves(self) -> frozenset[str]:
        return super().conserves | {"energy"}


def test_a_wrong_conservation_claim_is_flagged(monkeypatch):
    spec = METHODS["rkmk4"]
    fake = _ClaimsEnergy(spec.name, spec.family, spec.tableau)
    monkeypatch.setitem(METHODS, "rkmk4", fake)
    card = report_card.report(quick=True, methods=["rkmk4"], peers=False, structural=False)
    (sentence,) = card.contradictions["rkmk4"]
    assert sentence.startswith("energy-preserving: max |ΔE|/E₀ = ")
    assert card.results[0].free.energy_max > report_card.ROUND_OFF


def test_the_methods_of_the_figure_can_be_told_apart(folder):
    """Every method that agrees has its own colour, dash and marker (19+ methods on nine
    colours: the dash and the marker change with each nine)."""
    from tumble.viz.report_card import PALETTE, style

    styles = [style(k) for k in range(len(METHODS) + 4)]
    assert len(set(styles)) == len(styles)
    assert FLAG not in PALETTE
    page = (folder / "report.html").read_text(encoding="utf-8")
    drawn = {(m["legendgroup"], m["line"]["color"], m["line"].get("dash"), m["marker"]["symbol"])
             for m in _traces(page) if m.get("legendgroup") not in (None, "pareto")}  # fmt: skip
    assert len({d[1:] for d in drawn}) == len({d[0] for d in drawn}) >= len(METHODS)


def _traces(page: str) -> list[dict]:
    """The traces plotly was given, read back from the page's JSON."""
    import json
    import re

    found = re.search(r"Plotly\.newPlot\(\s*\"[^\"]+\",\s*(\[.*?\]),\s*\{", page, re.DOTALL)
    assert found, "no Plotly.newPlot call in the page"
    return json.loads(found.group(1))


def test_report_html_stands_alone_with_the_verdict_tables(folder):
    page = (folder / "report.html").read_text(encoding="utf-8")
    tables = page[page.index('<div id="report-tables">') :]
    for heading in ("Contradictions", "Order", "Orientation error at T",
                    "Invariants over a long run", "Cost", "Structural schemes"):  # fmt: skip
        assert f"<h2>{heading}</h2>" in tables, heading
    for name in METHODS:
        assert f"<tr><td>{name}</td>" in tables, name


def test_the_report_says_why_euler_quat_and_lie_euler_agree(folder, numbers):
    text = (folder / "report.md").read_text(encoding="utf-8")
    assert "Why `euler-quat` and `lie-euler` show the same errors" in text
    errors = numbers["errors"]["error"].values
    names = list(numbers["errors"]["method"].values)
    quat, lie = errors[names.index("euler-quat")], errors[names.index("lie-euler")]
    assert np.all(np.abs(quat / lie - 1) < 0.05)  # measured: 3e-6 to 2.8 %


def test_a_short_run_is_timed_over_spans_of_t_so_the_steps_cost_shows(monkeypatch):
    """A run that took about the call's fixed cost is timed again over k spans of T in one
    call and counted as 1/k of it; a long run keeps its time; a failing one too."""
    from tumble.report_card import measure

    fixed, step_cost = 50e-6, 2e-6  # a compiled method's call, and its 10 steps over T
    calls = []

    def fake(row, problem, setting, *, t_end=None, samples=0):
        spans = round(t_end / problem.t_end)
        calls.append(spans)
        return report_card.Sampled(np.zeros(1), np.eye(3), np.ones(1), np.ones(1), 0.0,
                                   math.nan, 10 * spans, fixed + spans * step_cost,
                                   ok=spans < 500)  # fmt: skip

    monkeypatch.setattr(measure, "run_row", fake)
    p1 = report_card.problems()[0]
    row = report_card.method_row(METHODS["rkmk4"])
    seconds = measure.amortised_seconds(row, p1, 1.0, fixed + step_cost, fixed)
    assert calls == [math.ceil(measure.AMORTISE * fixed / (fixed + step_cost))]  # 97 spans
    assert seconds == pytest.approx(step_cost + fixed / calls[0])
    assert measure.amortised_seconds(row, p1, 1.0, 1.0, fixed) == 1.0  # long: as it was
    assert measure.amortised_seconds(row, p1, 1.0, 1e-7, fixed) == 1e-7  # 1000 spans fail


def test_peers_that_are_not_installed_are_said_skipped(tmp_path, monkeypatch):
    from tumble.report_card import peers

    monkeypatch.setattr(peers, "mujoco_available", lambda: False)
    monkeypatch.setattr(peers, "heyoka_available", lambda: False)
    names = [row.name for row in report_card.rows(["rkmk4"])]
    assert names == ["rkmk4", "scipy DOP853", "scipy RK45"]
    # the card of one method, with the peers' note as report() makes it (their runs skipped)
    card = report_card.report(quick=True, methods=["rkmk4"], peers=False, structural=False)
    card = dataclasses.replace(card, skipped=report_card.skipped_peers(True))
    report_card.write(card, tmp_path)
    said = "MuJoCo RK4, MuJoCo Euler: not installed: rows skipped"
    assert said in (tmp_path / "report.md").read_text(encoding="utf-8")
    assert "heyoka: not installed: row skipped" in (tmp_path / "report.md").read_text("utf-8")
    assert said in (tmp_path / "report.html").read_text(encoding="utf-8")


def test_growth_law_reads_bounded_drift_and_round_off():
    t = np.linspace(0.0, 1000.0, 2001)
    drift = 1.0 + 1e-6 * t
    bounded = 1.0 + 1e-4 * np.sin(t)
    flat = 1.0 + 1e-15 * np.cos(t)
    slope, largest, law = report_card.growth_law(t, drift)
    assert law == "drift" and abs(slope - 1) < 0.01 and largest == pytest.approx(1e-3)
    assert report_card.growth_law(t, bounded)[2] == "bounded"
    assert report_card.growth_law(t, flat)[2] == "round-off"
    assert report_card.growth_law(t, 1.0 + 1e-6 * t**2)[2] == "grows"


def test_pareto_front_keeps_only_the_undominated_points():
    seconds = [1.0, 2.0, 3.0, 4.0, 0.5]
    errors = [1e-3, 1e-2, 1e-5, 1e-5, 1e-1]
    assert pareto_front(seconds, errors).tolist() == [4, 0, 2]


# --- report.html in headless Chromium -------------------------------------------------------

CHROMIUM = Path("/usr/bin/chromium")
CHROMEDRIVER = Path("/usr/bin/chromedriver")
FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--window-size=1400,1400")  # the whole plot in view: offsets from its centre  # fmt: skip
WAIT_S = 20
PLOT = f"document.getElementById('{DIV_ID}')"


@pytest.fixture(scope="module")
def page(folder, tmp_path_factory):
    """report.html loaded in headless Chromium, the plot drawn."""
    missing = [str(path) for path in (CHROMIUM, CHROMEDRIVER) if not path.exists()]
    if missing:
        pytest.fail(f"{', '.join(missing)} not found: run `make test` (it installs them)",
                    pytrace=False)  # fmt: skip
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.support.ui import WebDriverWait

    options = webdriver.ChromeOptions()
    options.binary_location = str(CHROMIUM)
    for flag in (*FLAGS, f"--user-data-dir={tmp_path_factory.mktemp('chromium-profile')}"):
        options.add_argument(flag)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("SE_OFFLINE", "true")
        driver = webdriver.Chrome(service=Service(str(CHROMEDRIVER)), options=options)
    try:
        driver.get((folder / "report.html").as_uri())
        WebDriverWait(driver, WAIT_S).until(
            lambda d: d.execute_script(f"const d = {PLOT}; return Boolean(d && d._fullData);")
        )
        driver.save_screenshot(str(folder.parent / "report.png"))
        yield driver
    finally:
        driver.quit()


def severe(driver) -> list[str]:
    return [entry["message"] for entry in driver.get_log("browser") if entry["level"] == "SEVERE"]


POINT = f"""
const div = {PLOT}, name = arguments[0];
const xa = div._fullLayout.xaxis, ya = div._fullLayout.yaxis;
const pixels = t => Array.from(t.x, (x, i) => [xa.c2p(x), ya.c2p(t.y[i])]);
const panel = div._fullData.filter(t => t.xaxis === 'x' && t.visible === true);
const mine = pixels(panel.find(t => t.legendgroup === name));
const others = panel.filter(t => t.legendgroup !== name).flatMap(pixels);
// the method's point farthest from every other method's: its hover is unambiguous
let best = null, room = -1;
for (const [x, y] of mine) {{
    const d = Math.min(...others.map(([u, v]) => Math.hypot(x - u, y - v)));
    if (d > room) {{ room = d; best = [x, y]; }}
}}
const box = div.getBoundingClientRect();
return [xa._offset + best[0] - box.width / 2, ya._offset + best[1] - box.height / 2, room];
"""


def test_report_html_has_no_console_errors_and_a_hover_names_the_method(page):
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait

    assert severe(page) == []
    div = page.find_element(By.ID, DIV_ID)
    dx, dy, room = page.execute_script(POINT, "rkmk4")
    assert room > 5  # pixels to the nearest point of another method
    ActionChains(page).move_to_element_with_offset(div, round(dx), round(dy)).perform()
    WebDriverWait(page, WAIT_S).until(
        lambda d: d.find_elements(By.CSS_SELECTOR, ".hoverlayer .hovertext"),
        message="no hover label appeared over rkmk4's last point",
    )
    label = page.find_element(By.CSS_SELECTOR, ".hoverlayer .hovertext").text
    assert "rkmk4" in label and "h = " in label


VISIBLE = f"""
const div = {PLOT}, name = arguments[0];
return div._fullData.filter(t => t.legendgroup === name).map(t => t.visible);
"""


def test_clicking_a_legend_entry_hides_the_methods_curves(page):
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait

    name = "split-axes"
    drawn = len(page.find_elements(By.CSS_SELECTOR, f"#{DIV_ID} .scatterlayer .trace"))
    assert page.execute_script(VISIBLE, name) == [True] * 4
    entries = page.find_elements(By.CSS_SELECTOR, f"#{DIV_ID} .legend .traces")
    (entry,) = [e for e in entries if e.find_element(By.CSS_SELECTOR, "text").text == name]
    entry.find_element(By.CSS_SELECTOR, ".legendtoggle").click()
    WebDriverWait(page, WAIT_S).until(
        lambda d: d.execute_script(VISIBLE, name) == ["legendonly"] * 4,
        message=f"clicking {name!r} in the legend did not hide its curves",
    )
    after = len(page.find_elements(By.CSS_SELECTOR, f"#{DIV_ID} .scatterlayer .trace"))
    assert after == drawn - 4  # its four curves are gone from the drawing
    assert severe(page) == []


def test_heyoka_is_a_row_or_is_said_skipped(monkeypatch):
    from tumble.report_card import peers

    names = [row.name for row in report_card.rows(["rkmk4"])]
    if peers.heyoka_available():
        assert "heyoka" in names and "heyoka" not in report_card.skipped_peers(True)
        row = next(row for row in report_card.rows(["rkmk4"]) if row.name == "heyoka")
        # its declared order is the one heyoka itself gives its Taylor method there
        p1 = report_card.problems()[0]
        ta = peers._heyoka_integrator(p1, peers.HEYOKA_FIXED_TOL)
        assert row.order == ta.order == 6
        # heyoka's system is the card's rhs: the forced body's y(T) agrees with scipy's
        forced = report_card.problems()[-1]
        run = peers.run_row(row, forced, 1e-12)
        assert run.ok
        assert report_card.attitude_error(run.R_end, report_card.reference(forced)) < 1e-9
    monkeypatch.setattr(peers, "heyoka_available", lambda: False)
    assert "heyoka" not in [row.name for row in report_card.rows(["rkmk4"])]
    said = report_card.skipped_peers(True)["heyoka"]
    assert said.startswith("not installed: row skipped")
