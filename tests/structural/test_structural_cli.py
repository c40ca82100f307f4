"""``tumble stability --analyse``: the amplification picture and the per-mode tables."""

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
