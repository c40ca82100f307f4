"""The mesh animation (tumble.viz.animation) and the beam animation (tumble.viz.structural)."""

import numpy as np
import pytest
from PIL import Image, ImageSequence
from roundoff import sum_bound

from tumble import meshes, so3, structural
from tumble.rigid import Force, Gravity, Impulse, RigidBody, Trajectory, simulate
from tumble.viz.animation import (
    animate_body,
    load_arrows,
    mp4_available,
    resample,
    world_vertices,
)
from tumble.viz.structural import beam_animation

HEADING_ROWS = 40
"""Rows at the top of a 240 px frame that hold the title and the time."""


@pytest.fixture(scope="module")
def box():
    return meshes.box([1.0, 0.5, 0.25])


def _gif_frames(path) -> list[np.ndarray]:
    with Image.open(path) as image:
        return [np.asarray(frame.convert("RGB")) for frame in ImageSequence.Iterator(image)]


def _spin(omega: float, t_end: float = 1.0, v0=(0.0, 0.0, 0.0)) -> Trajectory:
    """A sphere-inertia body spun about z: ``R(t) = exp(ω t ẑ)`` exactly with lie-euler."""
    body = RigidBody(1.0, np.eye(3))
    return simulate(body, t_end, method="lie-euler", h=t_end / 4, omega0=(0, 0, omega), v0=v0)


def test_world_vertices_are_x_plus_R_v():
    rng = np.random.default_rng(3)
    vertices, x = rng.normal(size=(5, 3)), rng.normal(size=(4, 3))
    R = so3.random_rotation(rng, size=4)
    world = world_vertices(vertices, x, R)
    for k in range(4):
        for j in range(5):
            # x + R v in two orders of its 4 terms, 4 roundings a side (in the CPU's BLAS kernel)
            expected = x[k] + R[k] @ vertices[j]
            terms = np.abs(x[k]) + np.abs(R[k]) @ np.abs(vertices[j])
            np.testing.assert_array_less(
                np.abs(world[k, j] - expected), sum_bound(terms, 4) + 1e-300
            )


def test_resample_follows_the_rotation_between_samples():
    # samples every 0.25 s of a spin at 2 rad/s; frames every 0.125 s fall between them,
    # where the geodesic interpolation is exact for a rotation about a fixed axis
    run = _spin(2.0, v0=(1.0, 0.0, 0.0))
    frames = resample(run, 9)
    np.testing.assert_allclose(frames.t, np.linspace(0, 1, 9))
    for time, R in zip(frames.t, frames.R, strict=True):
        np.testing.assert_allclose(R, so3.exp([0.0, 0.0, 2.0 * time]), atol=1e-12)
    np.testing.assert_allclose(frames.x[:, 0], frames.t, atol=1e-12)  # x = v0 t


def test_resample_keeps_a_matrix_that_left_so3_as_it_is():
    body = RigidBody(1.0, np.eye(3))
    zeros = np.zeros((2, 3))
    run = Trajectory(np.array([0.0, 1.0]), zeros, zeros, np.array([np.eye(3), 2 * np.eye(3)]),
                     zeros, body, "euler")  # fmt: skip
    np.testing.assert_allclose(resample(run, 3).R[1], 1.5 * np.eye(3), atol=1e-14)


def test_impulse_arrow_shows_only_in_frames_near_its_time():
    frames = resample(_spin(0.0, t_end=4.0), 9)  # frames every 0.5 s: window 0.75 s
    impulse = Impulse(point=(1.0, 2.0, 3.0), impulse=(0.0, 0.0, -4.0), time=2.0)
    arrows = load_arrows(frames, [impulse, Gravity()], mass=1.0, length=0.5)
    shown = [len(frame) for frame in arrows]
    assert shown == [0, 0, 0, 1, 1, 1, 0, 0, 0]  # t = 1.5, 2, 2.5 s
    tail, head, kind = arrows[4][0]
    assert kind == "impulse"
    np.testing.assert_allclose(head, [1.0, 2.0, 3.0])
    np.testing.assert_allclose(tail, [1.0, 2.0, 3.5])  # 0.5 m back along J


def test_force_arrow_starts_at_its_body_point_moved_with_the_body():
    run = _spin(np.pi / 2, v0=(0.0, 0.0, 1.0))  # a quarter turn about z in 1 s, rising 1 m
    frames = resample(run, 2)
    force = Force((2.0, 0.0, 0.0), point=(1.0, 0.0, 0.0))
    arrows = load_arrows(frames, [force], mass=1.0, length=0.25)
    tail, head, kind = arrows[-1][0]
    np.testing.assert_allclose(tail, [0.0, 1.0, 1.0], atol=1e-12)  # x + R p
    np.testing.assert_allclose(head - tail, [0.25, 0.0, 0.0], atol=1e-12)  # along F (world)
    assert kind == "force"


def test_gif_has_the_frames_and_size_asked_for(tmp_path, box):
    path = tmp_path / ".animation.partial.gif"  # the format comes from the suffix alone
    written = animate_body(_spin(1.0), box, path, title="spin", frames=7, size=(200, 150))
    frames = _gif_frames(written)
    assert len(frames) == 7
    assert frames[0].shape == (150, 200, 3)


def test_spinning_body_changes_the_picture_and_a_still_body_does_not(tmp_path, box):
    spinning = _gif_frames(
        animate_body(_spin(1.5), box, tmp_path / "spin.gif", title="T", frames=4, size=(240, 240))
    )
    still = _gif_frames(
        animate_body(_spin(0.0), box, tmp_path / "still.gif", title="T", frames=4, size=(240, 240))
    )
    below = slice(HEADING_ROWS, None)
    assert np.any(spinning[0][below] != spinning[-1][below])
    for frame in still[1:]:
        np.testing.assert_array_equal(frame[below], still[0][below])
    assert np.any(still[0][:HEADING_ROWS] != still[-1][:HEADING_ROWS])  # only the time changes


def test_impulse_arrow_is_drawn_in_its_colour(tmp_path, box):
    impulse = Impulse(point=(0.5, 0.0, 0.0), impulse=(-1.0, 0.0, 0.0), time=0.0)
    run = simulate(RigidBody(1.0, np.eye(3)), 2.0, method="rkmk4", h=0.1, forces=[impulse])
    frames = _gif_frames(
        animate_body(run, box, tmp_path / "hit.gif", title="hit", loads=[impulse], frames=5)
    )
    red = np.array([214, 39, 40])  # matplotlib's tab:red

    def red_pixels(frame):
        return int(np.sum(np.all(np.abs(frame.astype(int) - red) <= 10, axis=-1)))

    assert red_pixels(frames[0]) > 20
    assert red_pixels(frames[-1]) == 0


def test_mp4_is_an_mp4_file(tmp_path, box):
    # imageio-ffmpeg is a dependency: the MP4 path runs on every machine (issue 18 item 14)
    assert mp4_available()
    path = animate_body(_spin(1.0), box, tmp_path / "spin.mp4", title="spin", frames=6)
    with open(path, "rb") as file:
        assert file.read(12)[4:8] == b"ftyp"


def test_too_few_frames_are_refused(tmp_path, box):
    with pytest.raises(ValueError, match="frames=1"):
        animate_body(_spin(1.0), box, tmp_path / "a.gif", title="t", frames=1)


def test_unknown_suffix_is_refused_before_drawing(tmp_path, box):
    with pytest.raises(
        ValueError, match=r"path=.*a\.png' is not allowed: must be a file name ending in '\.gif'"
    ):
        animate_body(_spin(1.0), box, tmp_path / "a.png", title="t")
    assert not (tmp_path / "a.png").exists()


def test_beam_gif_has_one_frame_per_every_records(tmp_path):
    beam = structural.cantilever(1.0, 4, 210e9, 7850.0, 0.01, 0.01, 1.0)
    response = structural.integrate(beam, "midpoint", 1e-4, n_steps=20)
    path = beam_animation(beam, response, tmp_path / "beam.gif", every=5, title="beam",
                          size=(320, 180))  # fmt: skip
    frames = _gif_frames(path)
    assert len(frames) == 5  # records 0, 5, 10, 15, 20
    assert frames[0].shape == (180, 320, 3)


def test_beam_animation_refuses_every_below_one(tmp_path):
    beam = structural.cantilever(1.0, 4, 210e9, 7850.0, 0.01, 0.01, 1.0)
    response = structural.integrate(beam, "midpoint", 1e-4, n_steps=4)
    with pytest.raises(ValueError, match="every=0"):
        beam_animation(beam, response, tmp_path / "beam.gif", every=0, title="beam")
