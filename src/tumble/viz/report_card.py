"""The report card's interactive page: work–precision for orientation and energy error.

:func:`report_figure` draws, for P1 and the forced body (rows) and for the orientation error
``‖R(T) − R_ref(T)‖_F`` and the energy error ``max |ΔE|/|E₀|`` (columns), every method's
runs against their wall time: one curve per method (one legend entry toggles its curves in
all four panels), the Pareto front of each panel (the runs no other run beats in both time
and error) as a dashed black line, and the methods whose measurements contradict their
declaration in red. Hovering a point shows the method, its setting (h or rtol), its steps,
time and error. :func:`write_html` writes the page (plotly.js inlined, so it opens offline)
atomically. The data come from :func:`tumble.report_card.plot_data`.
"""

from __future__ import annotations

import html
import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from tumble._atomic import atomic_write

DIV_ID = "tumble-report"
"""The id of the plot's ``div`` (the browser test finds the figure by it)."""
PROBLEMS = ("P1", "forced")
"""The rows of panels: the problems swept over every setting."""
ERRORS = (("error", "‖R(T) − R_ref(T)‖_F"), ("energy", "max |E − E₀| / |E₀|"))
"""The columns: which error, and its axis title."""
FLOOR = 1e-17
"""Errors at or below this (exact to round-off) are drawn here, on the log axis."""
CEILING = 10.0
"""Errors above this are not drawn: an attitude error ‖R − R_ref‖_F of a rotation is at most
2√3, so beyond it (and an energy error of 1000 %) the run has diverged, and one such point
would squeeze every other curve into a sliver of the axis."""
FLAG = "#d62728"
"""The colour of a method that contradicts its declaration."""
PALETTE = (
    "#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22",
    "#17becf",
)  # fmt: skip
"""Nine colours that stay apart (Tableau's ten without its red, which marks contradictions)."""
DASHES = ("solid", "dash", "dot", "dashdot")
"""Line styles: the methods of one group of nine share none."""
SYMBOLS = ("circle", "square", "diamond", "triangle-up", "cross")
"""Marker symbols, changing with the line style."""


def style(k: int) -> tuple[str, str, str]:
    """``(colour, dash, symbol)`` of the ``k``-th method that agrees: the colour cycles
    through :data:`PALETTE`, the dash and the symbol change after each nine, so no two of
    the first 36 methods share all three.

    Examples
    --------
    >>> style(0), style(9)
    (('#1f77b4', 'solid', 'circle'), ('#1f77b4', 'dash', 'square'))
    """
    group = k // len(PALETTE)
    return PALETTE[k % len(PALETTE)], DASHES[group % len(DASHES)], SYMBOLS[group % len(SYMBOLS)]


def pareto_front(seconds: Sequence[float], errors: Sequence[float]) -> np.ndarray:
    """Indices of the points no other point beats in both cost and error, by cost.

    Examples
    --------
    >>> pareto_front([1.0, 2.0, 3.0, 4.0], [1e-3, 1e-2, 1e-5, 1e-5]).tolist()
    [0, 2]
    """
    cost, error = np.asarray(seconds, float), np.asarray(errors, float)
    front, best = [], math.inf
    for k in np.lexsort((error, cost)):
        if np.isfinite(error[k]) and error[k] < best:
            front.append(int(k))
            best = error[k]
    return np.array(front, dtype=int)


def report_figure(rows: Sequence[dict]):
    """The 2 × 2 work–precision figure (see the module docstring).

    Parameters
    ----------
    rows : sequence of dict
        :func:`tumble.report_card.plot_data`: per method ``name``, ``setting`` (``"h"`` or
        ``"rtol"``), ``flagged``, ``why`` and ``sweeps`` (per problem ``seconds``,
        ``error``, ``energy``, ``settings``, ``steps``).

    Returns
    -------
    plotly.graph_objects.Figure
        One trace per method and panel (``legendgroup`` the method's name), then one Pareto
        trace per panel.
    """
    from plotly.subplots import make_subplots

    titles = [f"{problem}: {label}" for problem in PROBLEMS for _, label in ERRORS]
    figure = make_subplots(rows=len(PROBLEMS), cols=len(ERRORS), subplot_titles=titles,
                           horizontal_spacing=0.08, vertical_spacing=0.12)  # fmt: skip
    agreeing = iter(range(len(rows)))
    panels: dict[tuple[int, int], list] = {}
    for row in rows:
        colour, dash, symbol = (FLAG, "solid", "x") if row["flagged"] else style(next(agreeing))
        label = f"{row['name']} ✗ contradicts" if row["flagged"] else row["name"]
        first = True
        for i, problem in enumerate(PROBLEMS, start=1):
            data = row["sweeps"].get(problem)
            if data is None:
                continue
            for j, (key, axis_title) in enumerate(ERRORS, start=1):
                seconds = np.asarray(data["seconds"], float)
                error = np.asarray(data[key], float)
                shown = np.isfinite(error) & np.isfinite(seconds) & (error <= CEILING)
                y = np.maximum(error[shown], FLOOR)
                x = seconds[shown]
                custom = [
                    [row["name"], f"{row['setting']} = {s:.3g}" + (" s" if row["setting"] == "h"
                                                                   else ""), int(n)]
                    for s, n in zip(np.asarray(data["settings"])[shown],
                                    np.asarray(data["steps"])[shown], strict=True)
                ]  # fmt: skip
                figure.add_scatter(
                    x=x, y=y, mode="lines+markers", name=label, legendgroup=row["name"],
                    showlegend=first, customdata=custom,
                    line={"color": colour, "width": 3 if row["flagged"] else 1.8, "dash": dash},
                    marker={"size": 7, "color": colour, "symbol": symbol},
                    hovertemplate="<b>%{customdata[0]}</b><br>%{customdata[1]}<br>"
                    "steps %{customdata[2]}<br>time %{x:.3g} s<br>"
                    + axis_title + " %{y:.2e}<extra></extra>",
                    row=i, col=j,
                )  # fmt: skip
                first = False
                panels.setdefault((i, j), []).extend(
                    (xs, ys, c) for xs, ys, c in zip(x, y, custom, strict=True)
                )
    for (i, j), points in panels.items():
        xs = [p[0] for p in points]
        ys = [p[1] for p in points]
        front = pareto_front(xs, ys)
        figure.add_scatter(
            x=[xs[k] for k in front], y=[ys[k] for k in front], mode="lines+markers",
            line={"color": "black", "dash": "dash", "width": 2.5, "shape": "hv"},
            marker={"symbol": "circle-open", "size": 13, "color": "black",
                    "line": {"width": 2}},
            name="Pareto front", legendgroup="pareto", showlegend=(i, j) == (1, 1),
            customdata=[points[k][2] for k in front],
            hovertemplate="<b>Pareto front: %{customdata[0]}</b><br>%{customdata[1]}"
            "<extra></extra>",
            row=i, col=j,
        )  # fmt: skip
    _fixed_cost(figure, rows)
    for i in range(1, len(PROBLEMS) + 1):
        for j, (_, axis_title) in enumerate(ERRORS, start=1):
            figure.update_xaxes(type="log", title_text="wall time of a run of T (s)", row=i,
                                col=j, exponentformat="power")  # fmt: skip
            figure.update_yaxes(type="log", title_text=axis_title, row=i, col=j,
                                exponentformat="power")  # fmt: skip
    figure.update_layout(
        height=900,
        hovermode="closest",
        legend={"title": {"text": "method (click to hide)"}, "font": {"size": 11}},
        margin={"l": 70, "r": 20, "t": 40, "b": 60},
        template="plotly_white",
    )
    return figure


def _fixed_cost(figure, rows: Sequence[dict]) -> None:
    """The fixed cost of a call (the median over tumble's rows and the peers' own), a dotted
    vertical line in every panel: what any run costs before its first step."""
    fixed = [row["fixed"] for row in rows if math.isfinite(row.get("fixed", math.nan))]
    if not fixed:
        return
    median = float(np.median(fixed))
    for i in range(1, len(PROBLEMS) + 1):
        for j in range(1, len(ERRORS) + 1):
            figure.add_vline(x=median, line={"color": "#555555", "dash": "dot", "width": 1.5},
                             row=i, col=j)  # fmt: skip
    figure.add_annotation(
        x=math.log10(median), y=0, xref="x", yref="y domain", xanchor="left",
        yanchor="bottom", text=f" fixed cost of a call (median {median * 1e6:.3g} µs)",
        showarrow=False, font={"size": 10, "color": "#444"}, bgcolor="rgba(255,255,255,0.8)",
    )  # fmt: skip


def markdown_html(text: str) -> str:
    r"""The report's markdown as HTML: headings, paragraphs, lists, pipe tables, ``**bold**``
    and ```code``` (the only markdown :func:`tumble.report_card.markdown` writes).

    Examples
    --------
    >>> markdown_html("## Order\n\n| a | b |\n| --- | ---: |\n| **x** | `1` |")
    '<h2>Order</h2>\n<table><tr><th>a</th><th>b</th></tr><tr><td><b>x</b></td><td><code>1</code></td></tr></table>'
    """  # noqa: E501 - the doctest's output is one line
    out: list[str] = []
    lines = text.splitlines()
    k = 0
    while k < len(lines):
        line = lines[k]
        if line.startswith("|"):
            table = []
            while k < len(lines) and lines[k].startswith("|"):
                table.append([cell.strip() for cell in lines[k].strip("|").split("|")])
                k += 1
            head, body = table[0], [r for r in table[1:] if not set("".join(r)) <= set("-: ")]
            cells = "".join(f"<th>{_inline(c)}</th>" for c in head)
            rows = "".join(
                "<tr>" + "".join(f"<td>{_inline(c)}</td>" for c in r) + "</tr>" for r in body
            )
            out.append(f"<table><tr>{cells}</tr>{rows}</table>")
            continue
        if line.startswith("#"):
            level = len(line) - len(line.lstrip("#"))
            out.append(f"<h{level}>{_inline(line[level:].strip())}</h{level}>")
        elif line.startswith("- "):
            items = []
            while k < len(lines) and lines[k].startswith("- "):
                items.append(f"<li>{_inline(lines[k][2:])}</li>")
                k += 1
            out.append(f"<ul>{''.join(items)}</ul>")
            continue
        elif line.strip():
            out.append(f"<p>{_inline(line)}</p>")
        k += 1
    return "\n".join(out)


def _inline(text: str) -> str:
    """Escaped text with ``**bold**`` and ```code``` spans."""
    import re

    escaped = html.escape(text, quote=False)
    escaped = re.sub(r"\*\*(.+?)\*\*", r"<b>\1</b>", escaped)
    return re.sub(r"`([^`]+)`", r"<code>\1</code>", escaped)


TABLE_STYLE = (
    "<style>#report-tables{font-family:sans-serif;margin:8px 16px;max-width:1400px}"
    "#report-tables table{border-collapse:collapse;margin:8px 0 16px;font-size:13px}"
    "#report-tables th,#report-tables td{border:1px solid #ccc;padding:2px 8px}"
    "#report-tables th{background:#f3f3f3}#report-tables p{max-width:1100px}</style>"
)
"""How the tables below the figure look."""


def write_html(path: str | Path, rows: Sequence[dict], *, title: str, tables: str = "",
               notes: Sequence[str] = ()) -> Path:  # fmt: skip
    """Write the page: the contradictions above :func:`report_figure`, the report's tables
    (``tables``, its markdown) below it, plotly.js inlined; ``notes`` are lines shown under
    the title (a peer that is not installed)."""
    figure = report_figure(rows)
    page = figure.to_html(include_plotlyjs=True, full_html=True, div_id=DIV_ID,
                          config={"displaylogo": False, "responsive": True})  # fmt: skip
    flagged = [row for row in rows if row["flagged"]]
    if flagged:
        items = "".join(
            f"<li><b>{html.escape(row['name'])}</b>: {html.escape('; '.join(row['why']))}</li>"
            for row in flagged
        )
        note = (
            f'<div id="contradictions" style="color:{FLAG}"><b>Contradictions</b>'
            f"<ul>{items}</ul></div>"
        )
    else:
        note = (
            '<div id="contradictions">No contradictions: every method agrees with its '
            "declaration.</div>"
        )
    remarks = "".join(f'<p class="peer-note">{html.escape(line)}.</p>' for line in notes)
    header = (
        f'<div style="font-family:sans-serif;margin:8px 16px"><h2>{html.escape(title)}</h2>'
        f"{note}{remarks}<p>Each point is one run at one setting, timed over a run of T "
        "(short runs over several spans of T in one call, so that the points show what the "
        "steps cost; the dotted line is the fixed cost of a call); hover for the method and "
        "its setting, click a legend entry to hide a method. The tables of the report "
        "follow the figure.</p></div>"
    )
    page = page.replace("<body>", "<body>\n" + header, 1)
    if tables:
        below = f'{TABLE_STYLE}<div id="report-tables">{markdown_html(tables)}</div>'
        page = page.replace("</body>", below + "\n</body>", 1)
    page = page.replace("</head>", f"    <title>{html.escape(title)}</title>\n</head>", 1)
    atomic_write(path, lambda tmp: tmp.write_text(page, encoding="utf-8"))
    return Path(path)
