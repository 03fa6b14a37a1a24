"""Figures are printable: drawn at most the PDF's text width wide, their smallest text
at least 7 pt on the page (the PDF places them at their own size), units on the axes."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.text import Text  # noqa: E402

from lcvreport import load_preset, load_vehicle, modes  # noqa: E402
from lcvreport.measures.amplification import single_sine
from lcvreport.measures.stability import speed_sweep
from lcvreport.plotting.charts import fig_bars
from lcvreport.plotting.frequency import fig_damping_over_speed, fig_frequency, fig_root_locus
from lcvreport.thesis.figures import fig_free_body, fig_load_configuration
from lcvreport.plotting.vehicle import fig_mode_shape, fig_vehicle
from lcvreport.plotting.time import fig_time
from lcvreport.report.tables import PORTRAIT_LINE_PT, setup  # noqa: E402

from conftest import EXAMPLES  # noqa: E402

U = 24.4444


def _figures():
    setup(None)
    aucnat, semi = load_preset("aucnat"), load_preset("tractor_semitrailer")
    western = load_vehicle(EXAMPLES / "western_double.toml")
    sweep = speed_sweep(aucnat, np.linspace(10, 130, 13))
    f = np.linspace(0.1, 2, 20)
    return {
        "free body, triple (Figure 4-1)": fig_free_body(aucnat, "x"),
        "free body, semi (Figure 3-1)": fig_free_body(semi, "x"),
        "vehicle drawing": fig_vehicle(western, "x"),
        "mode shape": fig_mode_shape(aucnat, modes(aucnat, U), 4, "x"),
        "load configuration": fig_load_configuration(aucnat, "balanced", "x"),
        "root locus": fig_root_locus(sweep.speeds_kph, sweep.eigenvalues, "x"),
        "damping over speed": fig_damping_over_speed(sweep.speeds_kph, sweep.least_damping_ratio,
                                                              sweep.max_real, "x", None, 88.0),
        "RA curve": fig_frequency(f, [("RA", np.ones_like(f))], "rearward amplification [-]", "x"),
        "single sine": single_sine(aucnat, U).plot(),
        "bars": fig_bars(["a", "b"], [("g", np.array([1.0, 2.0]))], "y [m]", "x"),
    }


FIGURES = _figures()


@pytest.mark.parametrize("name", sorted(FIGURES))
def test_figure_fits_the_text_width_and_its_text_is_at_least_7_pt(name):
    fig = FIGURES[name]
    assert fig.get_size_inches()[0] * 72 <= PORTRAIT_LINE_PT
    small = sorted({round(t.get_fontsize(), 2) for t in fig.findobj(Text) if t.get_text().strip() and t.get_visible()})
    assert small and small[0] >= 7.0, (name, small[:3])


@pytest.mark.parametrize("name", sorted(FIGURES))
def test_every_axis_names_its_unit(name):
    for ax in FIGURES[name].axes:
        for label in (ax.get_xlabel(), ax.get_ylabel()):
            if label and ax.get_label() != "<colorbar>":
                assert "[" in label and "]" in label, (name, label)


def _text_boxes(fig):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    return [(t.get_text(), Text.get_window_extent(t, renderer)) for t in fig.findobj(Text)   # text only, no arrow
            if t.get_visible() and t.get_text().strip()]


CROWDED = {
    "time, 16 series with peaks (Figure 5-2)": lambda: fig_time(
        [(f"run {k}" + (" (as published)" if k >= 8 else ""), np.linspace(0, 3, 61),
          np.sin(np.linspace(0, 3, 61) + 0.01 * k) * (1 + 0.001 * k), {}) for k in range(16)],
        "y6 [in]", "x", xlim=(0, 3), annotate_peaks=True),
    "time, close horizontal lines (Figure 5-3)": lambda: fig_time(
        [("a", np.linspace(5, 10, 11), np.full(11, 0.46), {})], "y6 [in]", "x",
        hlines=[(f"run {k}: {v:.3f}", v) for k, v in enumerate([0.341, 0.461, 0.466, 0.927, 0.969, 1.268, 1.436])]),
    "bars, 22 categories across (Figure 5-20)": lambda: fig_bars(
        [f"study {k // 5}: case {k}" for k in range(22)],
        [("corrected", np.linspace(-60, 60, 22)), ("thesis loads", np.linspace(50, -90, 22))],
        "change [%]", "x", height=6.4, horizontal=True),
}


@pytest.mark.parametrize("name", sorted(CROWDED))
def test_crowded_figures_keep_their_text_apart(name):
    """No two pieces of text on a crowded figure overlap (peak values, line labels, bar values)."""
    boxes = _text_boxes(CROWDED[name]())
    clashes = [(a, b) for i, (a, ba) in enumerate(boxes) for b, bb in boxes[i + 1:]
               if ba.overlaps(bb) and min(ba.width, bb.width) > 0 and
               min(ba.x1, bb.x1) - max(ba.x0, bb.x0) > 1 and min(ba.y1, bb.y1) - max(ba.y0, bb.y0) > 1]
    assert not clashes, clashes[:5]


def test_plan_view_draws_every_axle_above_every_body_and_measures_from_the_cab_front():
    """Issue 22: a tractor's drive axles and a dolly hidden under the next unit's body, and
    an overall length that left out the cab (CG to steer axle)."""
    from matplotlib.patches import Polygon
    from lcvreport.model.presets import load_preset
    from lcvreport.model.body import FRONT_OVERHANG_M, unit_kind
    from lcvreport.plotting.vehicle import fig_vehicle
    v = load_preset("aucnat")
    fig = fig_vehicle(v, "aucnat")
    ax = fig.axes[0]
    bodies = [p for p in ax.patches if isinstance(p, Polygon) and p.get_facecolor()[:3] != (0.0, 0.0, 0.0)]
    tires = [p for p in ax.patches if isinstance(p, Polygon) and p.get_facecolor()[:3] == (0.0, 0.0, 0.0)]
    assert len(tires) == sum(max(a.tires // 2, 1) * 2 for a in v.axles)
    assert min(t.get_zorder() for t in tires) > max(b.get_zorder() for b in bodies)
    assert [unit_kind(v, k) for k in range(6)] == ["tractor", "trailer", "dolly", "trailer", "dolly", "trailer"]
    # the bodies of the vehicle file (issue 19): the overall length is theirs
    from lcvreport.model.body import overall_length_m
    front_x = max(p.get_xy()[:, 0].max() for p in bodies)
    rear_x = min(p.get_xy()[:, 0].min() for p in bodies)
    assert front_x - rear_x == pytest.approx(overall_length_m(v), rel=1e-12)
    assert f"overall {overall_length_m(v):.2f} m (bodies from the vehicle file)" in ax.get_title()
    # without body keys: guessed, from the cab front
    from dataclasses import replace
    bare = replace(v, units=tuple(replace(u, body_front_m=None, body_rear_m=None, body_width_m=None)
                                  for u in v.units))
    ax = fig_vehicle(bare, "aucnat").axes[0]
    bodies = [p for p in ax.patches if isinstance(p, Polygon) and p.get_facecolor()[:3] != (0.0, 0.0, 0.0)]
    steer_x = max(a.x_m for a in v.units[0].axles)
    rear_x = min(p.get_xy()[:, 0].min() for p in bodies)
    expected = steer_x + FRONT_OVERHANG_M - rear_x
    assert f"overall about {expected:.1f} m" in ax.get_title()
