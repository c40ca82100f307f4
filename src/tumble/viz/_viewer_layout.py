"""The look of the HTML viewer (:mod:`tumble.viz.html`): trace styles, layout, play controls.

:func:`tumble.viz.html.viewer_figure` decides what is shown (the mesh at each frame, the
impulse arrows, the energy curve and the current time); the functions here decide how it
looks and where it sits on the page: colours and lighting (:func:`style_mesh`,
:func:`style_arrow`, :func:`style_now`, :func:`energy_curve`), the equal-aspect 3D axes over
the whole run and the energy axes (:func:`apply_layout`), and the Play/Pause buttons and the
time slider (:func:`controls`). Private: the constants are re-exported by
:mod:`tumble.viz.html`.

plotly is imported only inside the functions.
"""

from __future__ import annotations

import html

import numpy as np

ENERGY_POINTS = 5000
"""Longer energy curves are thinned to about this many samples (the last one kept)."""
FRAME_DURATION_MS = (40, 400)
"""Bounds on the time a frame is shown when playing (ms); between them the play is real-time."""
MESH_COLOR = "#4c78a8"
ARROW_COLOR = "#d62728"
NOW_COLOR = "#e45756"
SCENE_BOTTOM, SLIDER_TOP, ENERGY_TOP = 0.42, 0.405, 0.25
"""Vertical layout (fractions of the plot area): the scene above, the slider, the energy."""


def style_mesh(mesh_trace, faces: np.ndarray):
    """The body's ``Mesh3d`` trace with its faces, colour and smooth lighting."""
    i, j, k = faces.T
    return mesh_trace.update(
        i=i,
        j=j,
        k=k,
        color=MESH_COLOR,
        flatshading=False,
        lighting={"ambient": 0.3, "diffuse": 0.9, "specular": 0.3, "roughness": 0.5},
        lightposition={"x": 1e3, "y": 5e2, "z": 3e3},
        name="body",
        hoverinfo="skip",
    )


def style_arrow(line, cone) -> tuple:
    """An impulse's line and cone traces, in :data:`ARROW_COLOR`."""
    line = line.update(mode="lines", line={"color": ARROW_COLOR, "width": 6}, name="impulse")
    cone = cone.update(
        sizemode="raw",
        anchor="tip",
        colorscale=[[0, ARROW_COLOR], [1, ARROW_COLOR]],
        showscale=False,
        name="impulse",
        hoverinfo="name",
    )
    return line, cone


def energy_curve(t: np.ndarray, energy: np.ndarray):
    """Energy ``T + V`` (J) against time (s), thinned to about :data:`ENERGY_POINTS` samples."""
    import plotly.graph_objects as go

    keep = np.arange(0, len(t), max(1, -(-len(t) // ENERGY_POINTS)))
    keep = np.union1d(keep, [len(t) - 1])
    return go.Scatter(
        x=t[keep],
        y=energy[keep],
        mode="lines",
        line={"color": MESH_COLOR, "width": 2},
        name="energy",
        hovertemplate="t = %{x:.4g} s<br>E = %{y:.8g} J<extra></extra>",
    )


def style_now(line, marker) -> tuple:
    """The current-time line and marker traces of the energy plot."""
    line = line.update(
        mode="lines", line={"color": NOW_COLOR, "width": 1.5, "dash": "dot"}, hoverinfo="skip"
    )
    marker = marker.update(
        mode="markers",
        marker={"color": NOW_COLOR, "size": 10},
        cliponaxis=False,
        name="now",
        hovertemplate="t = %{x:.4g} s<br>E = %{y:.8g} J<extra></extra>",
    )
    return line, marker


def apply_layout(fig, title: str, times, world: np.ndarray, arrows, energy_range) -> None:
    """Title, equal-aspect 3D axes over the whole run, the energy axes, sizes."""
    parts = [world.reshape(-1, 3)]
    for line, cone in arrows:
        parts += [np.column_stack([line["x"], line["y"], line["z"]])]
        parts += [np.column_stack([cone["x"], cone["y"], cone["z"]])]
    points = np.concatenate(parts)
    points = points[np.all(np.isfinite(points), axis=1)]
    if len(points) == 0:
        points = np.zeros((1, 3))
    low, high = points.min(axis=0), points.max(axis=0)
    half = 0.55 * float(np.max(high - low)) or 1.0
    center = 0.5 * (low + high)
    axes = {
        f"{name}axis": {
            "title": {"text": f"{name} (m)"},
            "range": [c - half, c + half],
            "nticks": 8,
        }
        for name, c in zip("xyz", center, strict=True)
    }
    fig.update_layout(
        title={"text": html.escape(title).replace("\n", "<br>"), "x": 0.5, "xanchor": "center"},
        height=850 + 20 * title.count("\n"),
        margin={"l": 150, "r": 40, "t": 60 + 20 * title.count("\n"), "b": 50, "pad": 4},
        showlegend=False,
        uirevision="tumble",
        scene={
            **axes,
            "domain": {"y": [SCENE_BOTTOM, 1.0]},
            "aspectmode": "cube",
            "camera": {"eye": {"x": 1.5, "y": 1.5, "z": 1.1}},
        },
        xaxis={"title": {"text": "t (s)"}, "range": [float(times[0]), float(times[-1])]},
        yaxis={
            "title": {"text": "energy T + V (J)"},
            "range": energy_range,
            "domain": [0.0, ENERGY_TOP],
            "exponentformat": "e",
            "automargin": True,  # long tick labels (4.920394e−5) widen the margin, not the edge
            "title_standoff": 12,
        },
    )


def controls(names: list[str], times: np.ndarray) -> dict:
    """The Play/Pause buttons and the time slider (labels in s) of the animation."""
    spacing = (times[-1] - times[0]) / max(len(times) - 1, 1)
    decimals = max(0, int(np.ceil(-np.log10(spacing / 5)))) if spacing > 0 else 3
    duration = int(np.clip(1000 * spacing, *FRAME_DURATION_MS))
    still = {"mode": "immediate", "frame": {"duration": 0, "redraw": True}}
    still["transition"] = {"duration": 0}
    play = {**still, "frame": {"duration": duration, "redraw": True}, "fromcurrent": True}
    pause = {**still, "frame": {"duration": 0, "redraw": False}}
    steps = [
        {"method": "animate", "label": f"{time:.{decimals}f}", "args": [[name], still]}
        for name, time in zip(names, times, strict=True)
    ]
    return {
        "updatemenus": [
            {
                "type": "buttons",
                "direction": "left",
                "x": 0.0,
                "y": SLIDER_TOP,
                "xanchor": "left",
                "yanchor": "top",
                "pad": {"t": 45, "r": 10},
                "showactive": False,
                "buttons": [
                    {"label": "▶ Play", "method": "animate", "args": [None, play]},
                    {"label": "❚❚ Pause", "method": "animate", "args": [[None], pause]},
                ],
            }
        ],
        "sliders": [
            {
                "active": 0,
                "x": 0.17,
                "y": SLIDER_TOP,
                "len": 0.83,
                "xanchor": "left",
                "yanchor": "top",
                "pad": {"t": 10, "b": 10},
                "currentvalue": {"prefix": "t = ", "suffix": " s", "visible": True},
                "steps": steps,
            }
        ],
    }
