"""The explorer: four lessons as a marimo app (``signorini explore`` serves it).

Each slider's release re-solves in the package through :mod:`signorini.output.lessons`;
this file only lays the sliders, numbers and figures out.
"""

import marimo

__generated_with = "0.25.2"
app = marimo.App(width="full", app_title="signorini: interactive lessons")

with app.setup:
    import marimo as mo

    import signorini

    from signorini.output import lessons
    from signorini.output.lesson_figures import (hertz_figure, prices_figure, race_figure,
                                                 uzawa_figure)
    from signorini.output.lesson_html import (certificate_table, figure_image, number,
                                              numbers_table, race_table)
    from signorini.output.range_slider import RangeSlider


@app.function
def screen(title, text, controls, tables, figure):
    """One lesson on one screen: its title and text over its controls and numbers (left) and
    its figure (right)."""
    return mo.vstack([mo.md(f"## {title}"), mo.md(text),
                      mo.hstack([mo.vstack([*controls, mo.Html(tables)]), mo.Html(figure)],
                                widths=[2, 3], align="start")])


@app.cell
def _():
    mo.md("# Contact as one QP: four lessons\n\n"
          "[Uzawa on the bogie](#uzawa) · [Hertz live](#hertz) · [Prices](#prices) · "
          "[Methods race](#race). Every slider re-solves in the package when released; "
          "each lesson shows the answer's KKT certificate.")
    return


@app.cell
def _():
    bound = lessons.uzawa_step_bound()
    rho = mo.ui.anywidget(RangeSlider(value=round(0.8 * bound, 4), start=0.005,
                                      stop=round(1.5 * bound, 4), step=0.001, name="rho",
                                      label="step ρ"))
    return bound, rho


@app.cell
def _(bound, rho):
    uzawa = lessons.uzawa_lesson(rho.value["value"])
    screen("Uzawa on the bogie",
           "Projected gradient ascent on the dual, λ ← max(0, λ + ρ (N u(λ) − d)), drawn on "
           f"the dual function D(λ). It converges for 0 < ρ < 2/λ_max(W) = **{bound:.4f}**; "
           "past it the iterates fly off or bounce, and the status turns `diverged`. Far below "
           "it the status may read `inaccurate`: Uzawa's own stop test is met before the "
           "certificate's duality gap is under the tolerance.",
           [rho],
           numbers_table("uzawa", {"rho": ("ρ", uzawa.rho), "bound": ("2/λ_max(W)", uzawa.bound),
                                   "force": ("λ (last iterate)", " ".join(
                                       number(v) for v in uzawa.result.force))})
           + certificate_table("uzawa", uzawa.result),
           figure_image(uzawa_figure(uzawa), "uzawa-figure", "Uzawa's iterates on D(λ)"))
    return


@app.cell
def _():
    load = mo.ui.anywidget(RangeSlider(value=0.005, start=0.001, stop=0.02, step=0.001,
                                       name="load", label="load P"))
    modulus = mo.ui.anywidget(RangeSlider(value=1.0, start=0.5, stop=4.0, step=0.1,
                                          name="E", label="Young's modulus E"))
    poisson = mo.ui.anywidget(RangeSlider(value=0.3, start=0.0, stop=0.45, step=0.05,
                                          name="nu", label="Poisson's ratio ν"))
    return load, modulus, poisson


@app.cell
def _(load, modulus, poisson):
    hertz = lessons.hertz_lesson(load.value["value"], modulus.value["value"],
                                 poisson.value["value"])
    screen("Hertz live",
           "An elastic cylinder pressed on a rigid flat (plane strain, meshed by Triangle, the "
           "fast mesher), solved by pdas: its pressure against Hertz's p₀ √(1 − x²/a²), and "
           "the contact set node by node.",
           [load, modulus, poisson],
           numbers_table("hertz", {
               "a": ("contact half-width a (fitted)", hertz.a), "a_ref": ("Hertz's a", hertz.a_ref),
               "p0": ("peak pressure p₀ (fitted)", hertz.p0), "p0_ref": ("Hertz's p₀", hertz.p0_ref),
               "active": ("nodes in contact", int(hertz.active.sum()))})
           + certificate_table("hertz", hertz.result),
           figure_image(hertz_figure(hertz), "hertz-figure", "pressure against Hertz"))
    return


@app.cell
def _():
    gap = mo.ui.anywidget(RangeSlider(value=0.3, start=-0.2, stop=2.4, step=0.05, name="gap",
                                      label="gap under wheel 2, d₂"))
    lowering = mo.ui.anywidget(RangeSlider(value=1.0, start=0.2, stop=2.0, step=0.1,
                                           name="lowering", label="load (lowering)"))
    return gap, lowering


@app.cell
def _(gap, lowering):
    prices = lessons.prices_lesson(gap.value["value"], lowering.value["value"])
    screen("Prices",
           "Move the rail under wheel 2 or the load: the contact force λᵢ is the price of the "
           "gap, ∂J*/∂dᵢ = −λᵢ (the envelope theorem), checked by re-solving at dᵢ ± h.",
           [gap, lowering],
           numbers_table("prices", {
               "force1": ("λ₁", prices.force[0]), "force2": ("λ₂", prices.force[1]),
               "price1": ("−∂J*/∂d₁ (re-solves)", prices.prices[0]),
               "price2": ("−∂J*/∂d₂ (re-solves)", prices.prices[1]),
               "energy": ("J*", prices.result.energy),
               "miss": ("max |λ − price| / ‖λ‖", prices.envelope_error)})
           + certificate_table("prices", prices.result),
           figure_image(prices_figure(prices), "prices-figure", "J* and its tangent"))
    return


@app.cell
def _():
    installed = {m.name for m in signorini.methods(installed_only=True)}
    offered = [m for m in lessons.RACE_METHODS if m in installed]
    picked = mo.ui.multiselect(options=offered, label="methods",
                               value=[m for m in ("pdas", "uzawa", "qp-clarabel", "qp-osqp")
                                      if m in offered])
    tolerance = mo.ui.anywidget(RangeSlider(value=-8, start=-12, stop=-4, step=1, name="tol",
                                            label="tolerance 10^"))
    return picked, tolerance


@app.cell
def _(picked, tolerance):
    race = lessons.race_lesson(picked.value, 10.0 ** tolerance.value["value"])
    screen("Methods race",
           "The same cylinder, the methods picked, one tolerance: iterations, wall time and "
           "the certificate's residuals side by side.",
           [picked, tolerance],
           race_table(race) if race else "Pick a method.",
           figure_image(race_figure(race), "race-figure", "iterations and residuals")
           if race else "")
    return


if __name__ == "__main__":
    app.run()


__all__ = ["screen"]
