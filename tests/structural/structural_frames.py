"""Frames shared by the factorisation and compiled-loop tests."""

import numpy as np

from tumble import structural


def tilted_frame():
    """A portal frame with a leaning column, four elements per member: b = 5."""
    corners = np.array([[0, 0], [0.3, 2], [2, 2], [2, 0]], dtype=float)
    t = np.linspace(0, 1, 5)[1:, None]
    members = zip(corners[:-1], corners[1:], strict=True)
    nodes = np.vstack([corners[:1]] + [a + t * (b - a) for a, b in members])
    return structural.build_frame(
        nodes,
        np.column_stack([np.arange(12), np.arange(1, 13)]),
        E=2e11,
        rho=7850,
        area=1e-3,
        second_moment=1e-6,
        supports={0: "clamped", 12: "pinned"},
        loads={4: (1e3, 0, 0)},
    )


def wheel(n_rim):
    """A rim of ``n_rim`` nodes, each joined to a hub: the hub couples to every node."""
    angles = 2 * np.pi * np.arange(n_rim) / n_rim
    nodes = np.vstack([[0.0, 0.0], np.column_stack([np.cos(angles), np.sin(angles)])])
    rim = [[1 + i, 1 + (i + 1) % n_rim] for i in range(n_rim)]
    spokes = [[0, 1 + i] for i in range(n_rim)]
    return structural.build_frame(
        nodes,
        rim + spokes,
        E=2e11,
        rho=7850,
        area=1e-4,
        second_moment=1e-8,
        supports={1: "pinned", 1 + n_rim // 2: "pinned"},
        loads={0: (0.0, -100.0, 0.0)},
    )


def shuffled_cantilever(n_elements, seed=0):
    """The seed's cantilever with its nodes numbered in random order."""
    rank = np.random.default_rng(seed).permutation(n_elements + 1)  # new number of node i
    x = np.linspace(0, 1, n_elements + 1)
    nodes = np.zeros((n_elements + 1, 2))
    nodes[rank, 0] = x
    connectivity = np.column_stack([rank[:-1], rank[1:]])
    return structural.build_frame(
        nodes,
        connectivity,
        E=210e9,
        rho=7850,
        area=1e-4,
        second_moment=1e-8 / 12,
        supports={int(rank[0]): "clamped"},
        loads={int(rank[-1]): (0.0, 1.0, 0.0)},
    )
