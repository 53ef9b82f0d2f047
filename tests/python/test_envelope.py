"""solve_trap, working_envelope, clip_command, working_envelope_3d (ot-envelope)."""

import numpy as np
import pytest

import nanohaptics as nh

NM = 1e-9
DT = nh.PAPER_DT
TICK = dict(method="rk4", substeps=8)  # the default tick map of these calls


@pytest.fixture
def paper():
    return nh.paper_trap()


def inside(poly, pts):
    """Even-odd point-in-polygon test, vectorised."""
    x, y = pts[:, 0][:, None], pts[:, 1][:, None]
    x1, y1 = poly[:, 0][None, :], poly[:, 1][None, :]
    x2, y2 = np.roll(poly[:, 0], -1)[None, :], np.roll(poly[:, 1], -1)[None, :]
    crosses = (y1 > y) != (y2 > y)
    dy = np.where(y2 - y1 == 0, 1.0, y2 - y1)
    xc = x1 + (y - y1) * (x2 - x1) / dy
    return np.sum(crosses & (x < xc), axis=1) % 2 == 1


def distance_to_boundary(poly, pts):
    a = poly[None, :, :]
    b = np.roll(poly, -1, axis=0)[None, :, :]
    p = pts[:, None, :]
    ab = b - a
    t = np.clip(np.sum((p - a) * ab, -1) / np.sum(ab * ab, -1), 0.0, 1.0)
    return np.min(np.linalg.norm(a + t[..., None] * ab - p, axis=-1), axis=1)


def signed_area(poly):
    x, y = poly[:, 0], poly[:, 1]
    return 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)


@pytest.mark.parametrize("v0", [(0.0, 0.0), nh.PAPER_V0_MOVING])
def test_every_solution_reaches_the_target(paper, v0):
    target = np.array([300 * NM, 0.0])
    offsets = nh.solve_trap(paper, v0, DT, target)
    assert offsets.shape == (2, 2)  # the paper's Fig. 7: two trap positions
    # solve_trap answers for the true dynamics (issue 13): converged reference, 0.01 nm
    d = paper.displacement(offsets, v0, DT, rtol=1e-13)
    assert np.max(np.abs(d - target)) <= 1e-2 * NM
    assert not np.allclose(offsets[0], offsets[1])
    if v0 == (0.0, 0.0):
        assert np.all(offsets[:, 1] == 0.0)  # symmetric well, target on the axis
    # Far beyond the envelope: plainly no solution.
    assert nh.solve_trap(paper, v0, DT, (5e-6, 0.0)).shape == (0, 2)


@pytest.mark.parametrize("v0", [(0.0, 0.0), nh.PAPER_V0_MOVING])
def test_envelope_bounds_the_brute_force_image_and_its_vertices_are_the_edge(paper, v0):
    poly = nh.working_envelope(paper, v0, DT)
    assert poly.ndim == 2 and poly.shape[1] == 2 and len(poly) > 50
    assert signed_area(poly) > 0  # counter-clockwise
    assert not np.array_equal(poly[0], poly[-1])  # first vertex not repeated
    # Dense forward sampling of the search region (3 waists around the free drift):
    drift = 0.5 * DT * np.array(v0)
    gx = np.linspace(-1.8e-6, 1.8e-6, 241) + drift[0]
    gy = np.linspace(-0.9e-6, 0.9e-6, 121) + drift[1]
    offsets = np.stack(np.meshgrid(gx, gy), -1).reshape(-1, 2)
    image = paper.displacement(offsets, v0, DT, **TICK)
    out = image[~inside(poly, image)]
    # Every reachable displacement lies inside, up to the 0.5 nm polygon tolerance.
    if len(out):
        assert distance_to_boundary(poly, out).max() <= 0.5 * NM
    # Each vertex is the edge: 1 nm inside is solvable, 1 nm outside is not.
    for p in poly[::7]:
        u = p / np.linalg.norm(p)
        assert len(nh.solve_trap(paper, v0, DT, p - 1 * NM * u)) > 0
        assert len(nh.solve_trap(paper, v0, DT, p + 1 * NM * u)) == 0


def test_tolerance_argument_refines_the_polygon(paper):
    coarse = nh.working_envelope(paper, (0, 0), DT, tol=5 * NM)
    fine = nh.working_envelope(paper, (0, 0), DT, tol=0.1 * NM)
    assert len(fine) > len(coarse)
    assert signed_area(fine) == pytest.approx(signed_area(coarse), rel=1e-2)


def test_clip_command_radial_and_nearest(paper):
    v0 = (0.0, 0.0)
    poly = nh.working_envelope(paper, v0, DT)
    inner = np.array([200 * NM, 50 * NM])
    allowed, excess = nh.clip_command(paper, v0, DT, inner)
    assert np.array_equal(allowed, inner) and np.array_equal(excess, [0.0, 0.0])
    command = np.array([2e-6, 0.5e-6])
    allowed, excess = nh.clip_command(paper, v0, DT, command)
    assert np.allclose(allowed + excess, command, rtol=0, atol=1e-21)
    # Radial: on the segment from zero displacement to the command, on the boundary.
    assert abs(allowed[0] * command[1] - allowed[1] * command[0]) <= 1e-9 * np.linalg.norm(command) ** 2
    assert 0 < np.dot(allowed, command) < np.dot(command, command)
    assert distance_to_boundary(poly, allowed[None, :])[0] <= 1e-3 * NM
    # Nearest: the closest boundary point, no farther from the command than the radial one.
    near, ex2 = nh.clip_command(paper, v0, DT, command, mode="nearest")
    assert distance_to_boundary(poly, near[None, :])[0] <= 1e-3 * NM
    assert np.linalg.norm(ex2) == pytest.approx(distance_to_boundary(poly, command[None, :])[0], rel=1e-9)
    assert np.linalg.norm(ex2) <= np.linalg.norm(excess)


def test_3d_envelope_is_a_closed_outward_mesh_matching_the_planar_one():
    t3 = nh.GaussianTrap(1e-15, (600e-9, 300e-9), 1e-15, axial_waist=1.5e-6)
    vertices, triangles = nh.working_envelope_3d(t3, (0.0, 0.0, 0.0), DT, level=3)
    assert vertices.shape == (642, 3) and triangles.shape == (1280, 3)
    assert triangles.dtype == np.int64
    # Closed: every edge belongs to exactly two triangles, Euler characteristic 2.
    edges = np.sort(np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert np.all(counts == 2)
    assert len(vertices) - len(counts) + len(triangles) == 2
    # Outward, counter-clockwise triangles: positive enclosed volume.
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    assert np.sum(np.einsum("ij,ij->i", a, np.cross(b, c))) / 6 > 0
    # Its reach along x matches the planar envelope's (same dynamics at z = 0).
    planar = nh.working_envelope(nh.paper_trap(), (0.0, 0.0), DT)
    assert vertices[:, 0].max() == pytest.approx(planar[:, 0].max(), rel=0.02)


def test_envelope_errors_name_the_argument(paper):
    t3 = nh.GaussianTrap(1e-15, (600e-9, 300e-9), 1e-15, axial_waist=1.5e-6)
    cases = [
        (lambda: nh.solve_trap(t3, (0, 0, 0), DT, (1e-7, 0)),
         "trap: solve_trap needs a 2D trap (axial_waist=None); use working_envelope_3d for 3D"),
        (lambda: nh.working_envelope(paper, (0, 0), DT, tol=-1.0),
         "tol [m] = -1 is out of range: allowed finite and > 0"),
        (lambda: nh.clip_command(paper, (0, 0), DT, (1e-7, 0), mode="sideways"),
         'mode = "sideways": allowed "radial", "nearest"'),
        (lambda: nh.solve_trap(paper, (0, 0), DT, (1e-7, 0, 0)), "target: expected shape (2,), got (3,)"),
        (lambda: nh.solve_trap(paper, (0, 0), DT, (float("nan"), 0)),
         "target[0] = NaN is out of range: allowed finite (m)"),
        (lambda: nh.working_envelope(paper, (0, 0), -DT), "dt [s] = -1e-6 is out of range: allowed finite and > 0"),
        (lambda: nh.working_envelope_3d(paper, (0, 0), DT), "trap: working_envelope_3d needs a 3D trap (give axial_waist)"),
        (lambda: nh.working_envelope_3d(t3, (0, 0, 0), DT, level=7), "level = 7 is out of range: allowed 0 ..= 6"),
    ]
    for fn, msg in cases:
        with pytest.raises(ValueError) as e:
            fn()
        assert str(e.value) == msg
