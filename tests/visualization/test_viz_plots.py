"""matplotlib pictures of planar grasps: what is drawn, in data coordinates."""

import subprocess
import sys

import numpy as np
import pytest

from drakegrasp import Contact, Grasp, InvalidOptionError
from drakegrasp.closure.verdicts import force_closure
from drakegrasp.visualization import plot_planar_grasp


def _disc_grasp(mu=0.5):
    """Three fingers on a unit disc, normals towards the centre."""
    angles = np.deg2rad([0.0, 110.0, 235.0])
    contacts = [
        Contact([np.cos(a), np.sin(a)], [-np.cos(a), -np.sin(a)], mu=mu) for a in angles
    ]
    contacts.append(Contact([0.0, -1.0], [0.0, 1.0], contact_model="frictionless"))
    return Grasp(contacts)


def _unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def test_import_drakegrasp_does_not_import_matplotlib():
    code = (
        "import sys, drakegrasp, drakegrasp.visualization\n"
        "assert 'matplotlib' not in sys.modules, 'matplotlib imported'\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


def test_missing_matplotlib_raises_a_clear_error(monkeypatch):
    # A None entry in sys.modules makes `import matplotlib.pyplot` fail.
    monkeypatch.setitem(sys.modules, "matplotlib.pyplot", None)
    with pytest.raises(ImportError, match=r"drakegrasp\[viz\]"):
        plot_planar_grasp(_disc_grasp())


@pytest.mark.parametrize("side", ["outside", "inside"])
def test_cone_wedges_follow_the_edge_rays(plt, side):
    """Each wedge is [c, c ± L u+, c ± L u-] with u± = n rotated by ±atan μ."""
    mu = 0.5
    grasp = _disc_grasp(mu)
    out = plot_planar_grasp(grasp, cone_length=0.25, side=side)
    sign = -1.0 if side == "outside" else 1.0
    assert len(out.cones) == grasp.num_contacts
    assert out.cones[3] is None  # frictionless: the cone is the normal ray
    drawn = [p for p in out.ax.patches if p in out.cones]
    assert len(drawn) == 3
    a = np.arctan(mu)
    for contact, poly in zip(grasp.contacts[:3], out.cones[:3], strict=True):
        xy = poly.get_xy()[:3]  # matplotlib repeats the first vertex to close it
        np.testing.assert_allclose(xy[0], contact.position, atol=1e-12)
        edges = xy[1:] - xy[0]
        np.testing.assert_allclose(np.linalg.norm(edges, axis=1), 0.25)
        n = contact.normal
        for edge, angle in zip(edges, (a, -a), strict=True):
            c, s = np.cos(angle), np.sin(angle)
            expected = sign * np.array([c * n[0] - s * n[1], s * n[0] + c * n[1]])
            np.testing.assert_allclose(_unit(edge), expected, atol=1e-12)
        # The half-angle between the two edges is atan(mu).
        cos_full = np.dot(_unit(edges[0]), _unit(edges[1]))
        assert np.arccos(cos_full) == pytest.approx(2 * a)


def test_normals_and_contacts(plt):
    grasp = _disc_grasp()
    out = plot_planar_grasp(grasp, cone_length=0.3)
    np.testing.assert_allclose(out.contacts.get_offsets(), grasp.positions)
    # Outside: a normal arrow of length L ends at the contact point.
    U = np.column_stack([out.normals.U, out.normals.V])
    tails = np.column_stack([out.normals.X, out.normals.Y])
    np.testing.assert_allclose(U, 0.3 * grasp.normals, atol=1e-12)
    np.testing.assert_allclose(tails + U, grasp.positions, atol=1e-12)
    assert [t.get_text() for t in out.labels] == ["0", "1", "2", "3"]
    assert out.forces is None and out.force_scale == 0.0
    # Everything drawn is inside the view.
    x0, x1 = out.ax.get_xlim()
    y0, y1 = out.ax.get_ylim()
    for poly in out.cones[:3]:
        xy = poly.get_xy()
        assert np.all((xy[:, 0] > x0) & (xy[:, 0] < x1))
        assert np.all((xy[:, 1] > y0) & (xy[:, 1] < y1))


def test_forces_of_a_closure_result_are_drawn_in_the_grasp_frame(plt):
    grasp = Grasp(
        [
            Contact([1.0, 0.3], [-1.0, 0.0], mu=0.4),
            Contact([-1.0, -0.3], [1.0, 0.0], mu=0.4),
        ]
    )
    result = force_closure(grasp)
    assert result.is_closure
    out = plot_planar_grasp(grasp, result=result, force_scale=0.5)
    vec = np.column_stack([out.forces.U, out.forces.V])
    tails = np.column_stack([out.forces.X, out.forces.Y])
    expected = [
        c.frame @ np.asarray(f, dtype=float)
        for c, f in zip(grasp.contacts, result.contact_forces, strict=True)
    ]
    np.testing.assert_allclose(vec, 0.5 * np.array(expected), atol=1e-9)
    np.testing.assert_allclose(tails + vec, grasp.positions, atol=1e-12)
    # An internal force: the drawn forces balance (G f = 0).
    np.testing.assert_allclose(vec.sum(axis=0), 0.0, atol=1e-6)
    # Equilibrium of moments too, by the independent 2-D cross product.
    r = grasp.positions
    assert np.sum(r[:, 0] * vec[:, 1] - r[:, 1] * vec[:, 0]) == pytest.approx(
        0.0, abs=1e-6
    )


def test_default_force_scale_and_inside_side(plt):
    grasp = _disc_grasp()
    forces = [[2.0, 0.5], [1.0, -0.2], [0.5, 0.0], [3.0]]
    out = plot_planar_grasp(grasp, result=forces, side="inside")
    vec = np.column_stack([out.forces.U, out.forces.V])
    tails = np.column_stack([out.forces.X, out.forces.Y])
    np.testing.assert_allclose(tails, grasp.positions)  # inside: start at c
    lengths = np.linalg.norm(vec, axis=1)
    assert lengths.max() == pytest.approx(0.6 * grasp.characteristic_length)
    magnitudes = np.linalg.norm([np.pad(f, (0, 2 - len(f))) for f in forces], axis=1)
    np.testing.assert_allclose(lengths / magnitudes, out.force_scale)


def test_outlines(plt):
    from matplotlib.patches import Circle, Polygon

    grasp = _disc_grasp()
    out = plot_planar_grasp(grasp, outline={"center": (0.0, 0.0), "radius": 1.0})
    assert isinstance(out.outline, Circle) and out.outline in out.ax.patches
    assert out.outline.get_radius() == 1.0
    square = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=float)
    out = plot_planar_grasp(grasp, outline=square)
    assert isinstance(out.outline, Polygon)
    np.testing.assert_allclose(out.outline.get_xy()[:4], square)
    # The view contains the whole outline.
    assert out.ax.get_xlim()[0] < -1 and out.ax.get_xlim()[1] > 1
    _, ax = plt.subplots()
    out = plot_planar_grasp(grasp, ax=ax, outline=Circle((0, 0), 1.0))
    assert out.ax is ax


def test_bad_inputs(plt):
    grasp = _disc_grasp()
    with pytest.raises(InvalidOptionError, match="spatial"):
        plot_planar_grasp(Grasp([Contact([0, 0, 1], [0, 0, -1], mu=0.1)]))
    with pytest.raises(InvalidOptionError, match="shape"):
        plot_planar_grasp(grasp, outline=[[0.0, 0.0], [1.0, 0.0]])
    with pytest.raises(InvalidOptionError, match="center"):
        plot_planar_grasp(grasp, outline={"centre": (0, 0), "radius": 1.0})
    with pytest.raises(InvalidOptionError, match="side"):
        plot_planar_grasp(grasp, side="above")
    with pytest.raises(InvalidOptionError, match="cone_length"):
        plot_planar_grasp(grasp, cone_length=-1.0)
    with pytest.raises(InvalidOptionError, match="colour"):
        plot_planar_grasp(grasp, colors={"arrow": "red"})
    fig = plt.figure()
    with pytest.raises(InvalidOptionError, match="2-D axes"):
        plot_planar_grasp(grasp, ax=fig.add_subplot(projection="3d"))
