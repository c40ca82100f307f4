"""``tumble stability --analyse``: the amplification picture and the per-mode tables."""

import numpy as np
from typer.testing import CliRunner

from tumble import structural
from tumble.cli import app

runner = CliRunner()


def test_stability_analyse_writes_the_picture_and_tables_every_mode(tmp_path):
    out = tmp_path / "analysis"
    result = runner.invoke(
        app, ["stability", "--analyse", "--n-elements", "4", "--dt", "1e-3", "--out", str(out)]
    )
    assert result.exit_code == 0, result.output
    assert (out / "amplification.png").stat().st_size > 10_000
    assert (out / "schemes_vs_exact.png").stat().st_size > 10_000
    assert "algorithmic damping ratio" in result.output and "period elongation" in result.output
    beam = structural.cantilever(1.0, 4, 210e9, 7850.0, 0.01, 0.01)
    # every mode is a row, with its Ω = ωΔt; the explicit scheme grows in every mode
    for omega in beam.natural_frequencies(beam.n_dofs) * 1e-3:
        assert f"{omega:.3g}" in result.output
    assert result.output.count("grows") >= 2 * beam.n_dofs


def test_stability_analyse_refuses_to_overwrite_without_force(tmp_path):
    arguments = ["stability", "--analyse", "--n-elements", "2", "--out", str(tmp_path)]
    assert runner.invoke(app, arguments).exit_code == 0
    again = runner.invoke(app, arguments)
    assert again.exit_code == 2 and "--force" in again.output
    assert runner.invoke(app, [*arguments, "--force"]).exit_code == 0


def test_stability_analyse_refuses_a_bad_time_step(tmp_path):
    result = runner.invoke(app, ["stability", "--analyse", "--dt", "-1", "--out", str(tmp_path)])
    assert result.exit_code == 2 and "dt=-1.0 is not allowed" in result.output


def test_amplification_figure_draws_every_scheme_on_log_axes():
    from tumble.viz.amplification import amplification_figure

    omega = 2 * np.pi * np.logspace(-2, 2, 21)
    analyses = [structural.amplification(s, omega) for s in structural.SCHEMES]
    fig = amplification_figure(analyses, title="t")
    axes = fig.get_axes()
    assert len(axes) == 3 and all(ax.get_xscale() == "log" for ax in axes)
    for ax in axes:
        assert [
            line.get_label() for line in ax.get_lines() if not line.get_label().startswith("_")
        ] == list(structural.SCHEMES)
    # the legend names every scheme once
    assert [t.get_text() for t in fig.legends[0].get_texts()] == list(structural.SCHEMES)
