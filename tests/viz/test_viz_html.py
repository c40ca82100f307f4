"""The HTML viewer's page and figure: self-contained, the right vertices in each frame."""

import dataclasses
import re

import numpy as np
import pytest
import trimesh

import tumble
from tumble import meshes
from tumble.rigid.forces import Gravity, Impulse
from tumble.viz.html import DIV_ID, display_mesh, html_viewer, viewer_figure

FRAMES = 12
KICK = Impulse(point=(0.03, 0.0, 0.0), impulse=(0.0, 0.0, 2e-3), time=0.5)


@pytest.fixture(scope="module")
def run():
    """A T-handle spinning near its unstable axis, 1 s at h = 0.01 s (101 samples)."""
    body = tumble.rigid.RigidBody.from_mass_properties(tumble.mass.t_handle())
    return tumble.rigid.simulate(body, 1.0, h=0.01, omega0=(0.0, 5.0, 0.1))


@pytest.fixture(scope="module")
def mesh():
    return meshes.t_handle(8)


@pytest.fixture(scope="module")
def figure(run, mesh):
    return viewer_figure(run, mesh, title="T-handle", loads=(KICK,), frames=FRAMES)


def nearest_samples(t, count):
    """Index of the sample nearest to each of ``count`` evenly spaced times (independent)."""
    wanted = np.linspace(t[0], t[-1], count)
    return np.abs(t[:, None] - wanted[None, :]).argmin(axis=0)


def test_page_inlines_plotly_and_loads_nothing_external(run, mesh):
    page = html_viewer(run, mesh, title="T-handle", frames=3)
    assert "plotly.js v" in page  # the bundle's own banner: the library is inlined
    assert len(page) > 3_000_000
    assert re.search(r"<script[^>]*\bsrc\s*=", page, re.IGNORECASE) is None
    assert re.search(r"<link[^>]*href\s*=\s*[\"']?(https?:)?//", page, re.IGNORECASE) is None
    assert f'id="{DIV_ID}"' in page
    assert "<title>T-handle</title>" in page


def test_page_is_written_to_path_as_returned(run, mesh, tmp_path):
    path = tmp_path / ".view.partial.html"
    page = html_viewer(run, mesh, path, title="T-handle <&>", frames=3)
    assert path.read_text(encoding="utf-8") == page
    assert "<title>T-handle &lt;&amp;&gt;</title>" in page


def triangles(vertices, faces):
    """The mesh's triangles as a sorted array of sorted corner triples (order-free)."""
    corners = np.round(np.asarray(vertices)[np.asarray(faces)], 12)  # (faces, 3, 3)
    corners = np.array([sorted(map(tuple, triangle)) for triangle in corners])
    return corners[np.lexsort(corners.reshape(len(corners), -1).T[::-1])]


def test_display_mesh_keeps_the_triangles(mesh):
    shown = display_mesh(mesh)
    np.testing.assert_array_equal(
        triangles(shown.vertices, shown.faces), triangles(mesh.vertices, mesh.faces)
    )


def test_display_mesh_splits_only_sharp_edges():
    assert len(display_mesh(meshes.box((1.0, 1.0, 1.0))).vertices) == 24  # 3 per corner
    assert len(display_mesh(meshes.sphere(1.0, 2)).vertices) == 162  # all smooth


def test_frames_hold_world_vertices_at_resampled_times(run, mesh, figure):
    index = nearest_samples(run.t, FRAMES)
    assert len(figure.frames) == FRAMES
    vertices = display_mesh(mesh).vertices
    scale = np.max(np.abs(vertices)) + np.max(np.abs(run.x))
    for frame, k in zip(figure.frames, index, strict=True):
        expected = run.x[k] + vertices @ run.R[k].T  # x[k] + R[k] v for each vertex v
        drawn = np.column_stack([frame.data[0].x, frame.data[0].y, frame.data[0].z])
        np.testing.assert_allclose(drawn, expected, rtol=0, atol=1e-7 * scale)  # float32


def test_mesh_moves_between_frames(figure):
    first, last = figure.frames[0].data[0], figure.frames[-1].data[0]
    assert np.max(np.abs(np.asarray(first.x) - np.asarray(last.x))) > 1e-3


def test_first_frame_is_the_initial_picture(mesh, figure):
    np.testing.assert_array_equal(figure.data[0].x, figure.frames[0].data[0].x)
    base = figure.data[0]
    np.testing.assert_array_equal(
        np.column_stack([base.i, base.j, base.k]), display_mesh(mesh).faces
    )


def test_frames_update_every_trace_but_the_energy_curve(figure):
    names = [trace.name for trace in figure.data]
    updated = [k for k, name in enumerate(names) if name != "energy"]
    for frame in figure.frames:
        assert list(frame.traces) == updated
        assert [trace.type for trace in frame.data] == [figure.data[k].type for k in updated]


def test_frames_send_no_faces(figure):
    assert all(frame.data[0].i is None for frame in figure.frames)


def test_slider_steps_show_frames_with_time_labels(run, figure):
    times = run.t[nearest_samples(run.t, FRAMES)]
    slider = figure.layout.sliders[0]
    assert [list(step.args[0]) for step in slider.steps] == [[f.name] for f in figure.frames]
    labels = np.array([float(step.label) for step in slider.steps])
    np.testing.assert_allclose(labels, times, atol=0.005)  # spacing 0.09 s: 2 decimals
    assert slider.currentvalue.suffix == " s"


def test_play_and_pause_buttons_animate(figure):
    play, pause = figure.layout.updatemenus[0].buttons
    assert (play.method, play.args[0], list(pause.args[0])) == ("animate", None, [None])
    assert play.args[1]["frame"]["redraw"] is True


def test_energy_trace_matches_trajectory(run, figure):
    curve = next(trace for trace in figure.data if trace.name == "energy")
    np.testing.assert_array_equal(curve.x, run.t)
    np.testing.assert_array_equal(curve.y, run.energy)
    assert (curve.xaxis, curve.yaxis) == ("x", "y")
    assert "(J)" in figure.layout.yaxis.title.text and "(s)" in figure.layout.xaxis.title.text


def test_current_time_marker_follows_frames(run, figure):
    index = nearest_samples(run.t, FRAMES)
    for frame, k in zip(figure.frames, index, strict=True):
        line, marker = frame.data[-2], frame.data[-1]
        assert tuple(line.x) == (run.t[k], run.t[k])
        assert (marker.x, marker.y) == ((run.t[k],), (run.energy[k],))
        assert frame.traces[-2:] == (len(figure.data) - 2, len(figure.data) - 1)


def test_scene_axes_are_equal_and_hold_the_whole_run(figure):
    scene = figure.layout.scene
    ranges = np.array([scene.xaxis.range, scene.yaxis.range, scene.zaxis.range])
    spans = ranges[:, 1] - ranges[:, 0]
    np.testing.assert_allclose(spans, np.full(3, spans[0]))
    for frame in figure.frames:
        drawn = np.column_stack([frame.data[0].x, frame.data[0].y, frame.data[0].z])
        assert np.all((drawn >= ranges[:, 0]) & (drawn <= ranges[:, 1]))
    assert scene.aspectmode == "cube"
    assert [axis.title.text for axis in (scene.xaxis, scene.yaxis, scene.zaxis)] == [
        "x (m)",
        "y (m)",
        "z (m)",
    ]


def test_impulse_arrow_points_along_j_at_its_point_near_its_time(run, figure):
    line, cone = figure.data[1], figure.data[2]
    assert (line.type, cone.type) == ("scatter3d", "cone")
    np.testing.assert_allclose([cone.x[0], cone.y[0], cone.z[0]], KICK.point)
    direction = np.array([cone.u[0], cone.v[0], cone.w[0]])
    np.testing.assert_allclose(direction / np.linalg.norm(direction), [0.0, 0.0, 1.0])
    times = run.t[nearest_samples(run.t, FRAMES)]
    spacing = (times[-1] - times[0]) / (FRAMES - 1)
    near = np.abs(times - KICK.time) <= 2 * spacing
    assert 0 < near.sum() < FRAMES
    assert [frame.data[1].visible for frame in figure.frames] == near.tolist()
    assert [frame.data[2].visible for frame in figure.frames] == near.tolist()


def test_other_loads_are_accepted_and_not_drawn(run, mesh):
    figure = viewer_figure(run, mesh, title="T", loads=(Gravity(),), frames=3)
    assert [trace.type for trace in figure.data] == ["mesh3d", "scatter", "scatter", "scatter"]


def test_fewer_samples_than_frames_gives_one_frame_per_sample(run, mesh):
    short = dataclasses.replace(run, t=run.t[:4], x=run.x[:4], v=run.v[:4], R=run.R[:4])
    short = dataclasses.replace(
        short, L_world=run.L_world[:4], potential_energy=run.potential_energy[:4]
    )
    assert len(viewer_figure(short, mesh, title="T", frames=20).frames) == 4


@pytest.mark.parametrize("frames", [1, 0, -5, 2.5, True])
def test_bad_frames_raise(run, mesh, frames):
    with pytest.raises(ValueError, match="frames"):
        html_viewer(run, mesh, title="T", frames=frames)


def test_mesh_without_faces_raises(run):
    empty = trimesh.Trimesh(vertices=np.eye(3), faces=np.zeros((0, 3), dtype=int))
    with pytest.raises(ValueError, match="mesh.*no faces"):
        html_viewer(run, empty, title="T")


@pytest.mark.parametrize("name", ["x", "R"])
def test_mismatched_lengths_raise(run, mesh, name):
    broken = dataclasses.replace(run, **{name: getattr(run, name)[:-1]})
    with pytest.raises(ValueError, match=f"trajectory.{name}"):
        html_viewer(broken, mesh, title="T")


def test_non_load_raises(run, mesh):
    with pytest.raises(ValueError, match=r"loads\[1\]"):
        html_viewer(run, mesh, title="T", loads=(Gravity(), "kick"))


def test_title_must_be_text(run, mesh):
    with pytest.raises(ValueError, match="title"):
        html_viewer(run, mesh, title=None)
