"""Cube face selection and its inverse (generator/backends/numpy/resources.py: cube_face, cube_texel_direction;
Vulkan "Cube Map Face Selection"), shared by the NumPy target's texturecube and the homomorphic factorization."""
from __future__ import annotations

import numpy as np

from generator.backends.numpy.resources import cube_face, cube_texel_direction


def test_a_texel_centre_direction_selects_its_own_face_and_coordinates():
    for size in (1, 2, 5, 16):
        k = np.arange(size)
        f, i, j = np.arange(6)[:, None, None], k[None, None, :], k[None, :, None]
        d = cube_texel_direction(f, i, j, size)
        assert d.shape == (6, size, size, 3)
        np.testing.assert_allclose(np.linalg.norm(d, axis=-1), 1.0, rtol=1e-15)
        face, s, t = cube_face(d)
        assert (face == np.broadcast_to(f, face.shape)).all()
        np.testing.assert_allclose(s, np.broadcast_to((i + 0.5) / size, s.shape), atol=1e-15)
        np.testing.assert_allclose(t, np.broadcast_to((j + 0.5) / size, t.shape), atol=1e-15)


def test_a_step_past_the_edge_of_a_face_lands_on_the_adjacent_face():
    # +Z's last column (s_c → +1 is the +X side: r = (s_c, −t_c, 1)); one texel further is +X's first column
    size = 4
    face, s, _ = cube_face(cube_texel_direction(4, size, 1, size))
    assert int(face) == 0 and 0.0 < float(s) < 1.0 / size
