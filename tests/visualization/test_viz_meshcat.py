"""Meshcat drawings: the scene tree holds what draw_grasp drew, under its prefix."""

import numpy as np
import pytest
from pydrake.math import RigidTransform

from drakegrasp import Contact, Grasp, InvalidOptionError
from drakegrasp.closure.verdicts import force_closure
from drakegrasp.visualization import clear_grasp, draw_grasp


def _ring(n=3, mu=0.5, radius=0.1):
    angles = 2 * np.pi * np.arange(n) / n
    return Grasp(
        [
            Contact(
                [radius * np.cos(a), radius * np.sin(a), 0.0],
                [-np.cos(a), -np.sin(a), 0.0],
                mu=mu,
            )
            for a in angles
        ]
    )


def _parts(i, prefix="drakegrasp/grasp"):
    base = f"{prefix}/contact_{i}"
    return [f"{base}/point"] + [f"{base}/frame/{a}" for a in ("n", "t1", "t2")]


def test_draw_then_clear(meshcat):
    grasp = _ring()
    result = force_closure(grasp)
    assert result.is_closure
    drawing = draw_grasp(meshcat, grasp, result=result, cone="both")
    expected = []
    for i in range(3):
        expected += _parts(i)
        expected += [
            f"drakegrasp/grasp/contact_{i}/cone/exact",
            f"drakegrasp/grasp/contact_{i}/cone/pyramid",
            f"drakegrasp/grasp/contact_{i}/force",
            f"drakegrasp/grasp/contact_{i}/force/shaft",
            f"drakegrasp/grasp/contact_{i}/force/head",
        ]
    for path in expected:
        assert meshcat.HasPath(path), path
    assert set(drawing.paths) <= set(expected)
    assert all(meshcat.HasPath(p) for p in drawing.paths)
    assert len(drawing.paths) == 3 * 7
    clear_grasp(meshcat)
    assert not meshcat.HasPath("drakegrasp/grasp")
    assert not any(meshcat.HasPath(p) for p in expected)


def test_drawn_forces_are_the_result_in_the_grasp_frame(meshcat):
    grasp = _ring(4, mu=0.3)
    result = force_closure(grasp)
    drawing = draw_grasp(meshcat, grasp, result=result, prefix="test/forces")
    expected = np.array(
        [
            c.frame @ f
            for c, f in zip(grasp.contacts, result.contact_forces, strict=True)
        ]
    )
    np.testing.assert_allclose(drawing.forces_G, expected, atol=1e-12)
    # An internal force balances: Σ f = 0 and Σ c × f = 0 (independent of G).
    np.testing.assert_allclose(drawing.forces_G.sum(axis=0), 0.0, atol=1e-6)
    moments = np.cross(grasp.positions, drawing.forces_G).sum(axis=0)
    np.testing.assert_allclose(moments, 0.0, atol=1e-6)
    # Default scale: the largest force is drawn 0.6 b long.
    longest = np.linalg.norm(drawing.forces_G, axis=1).max() * drawing.force_scale
    assert longest == pytest.approx(0.6 * grasp.characteristic_length)
    clear_grasp(meshcat, "test/forces")


def test_redraw_replaces_and_prefixes_are_independent(meshcat):
    draw_grasp(meshcat, _ring(4), prefix="test/a")
    draw_grasp(meshcat, _ring(2), prefix="test/b")
    assert meshcat.HasPath("test/a/contact_3/point")
    draw_grasp(meshcat, _ring(2), prefix="test/a")
    assert meshcat.HasPath("test/a/contact_1/point")
    assert not meshcat.HasPath("test/a/contact_2")
    assert not meshcat.HasPath("test/a/contact_3")
    clear_grasp(meshcat, "test/a")
    assert not meshcat.HasPath("test/a")
    assert meshcat.HasPath("test/b/contact_1/point")
    clear_grasp(meshcat, "test/b")


@pytest.mark.parametrize(
    ("cone", "present", "absent"),
    [
        ("exact", ["cone/exact"], ["cone/pyramid"]),
        ("pyramid", ["cone/pyramid"], ["cone/exact"]),
        (None, [], ["cone"]),
    ],
)
def test_cone_choice(meshcat, cone, present, absent):
    drawing = draw_grasp(meshcat, _ring(), cone=cone, prefix="test/cone")
    for i in range(3):
        for p in present:
            assert meshcat.HasPath(f"test/cone/contact_{i}/{p}")
        for p in absent:
            assert not meshcat.HasPath(f"test/cone/contact_{i}/{p}")
        assert not meshcat.HasPath(f"test/cone/contact_{i}/force")
    assert drawing.forces_G is None and drawing.force_scale == 0.0
    clear_grasp(meshcat, "test/cone")


def test_frictionless_planar_and_soft_contacts(meshcat):
    planar = Grasp(
        [
            Contact([1.0, 0.0], [-1.0, 0.0], mu=0.4),
            Contact([-1.0, 0.0], [1.0, 0.0], contact_model="frictionless"),
        ]
    )
    drawing = draw_grasp(
        meshcat,
        planar,
        cone="both",
        result=[[1.0, 0.2], [1.0]],
        prefix="test/planar",
        X_WG=RigidTransform([0.0, 0.0, 0.5]),
        show_frames=False,
    )
    assert meshcat.HasPath("test/planar/contact_0/cone/exact")
    assert meshcat.HasPath("test/planar/contact_0/cone/pyramid")
    assert meshcat.HasPath("test/planar/contact_1/cone/ray")
    assert not meshcat.HasPath("test/planar/contact_1/cone/exact")
    assert not meshcat.HasPath("test/planar/contact_0/frame")
    # Planar forces stay in the z = 0 plane of the grasp frame.
    np.testing.assert_allclose(drawing.forces_G, [[-1.0, -0.2, 0.0], [1.0, 0, 0]])
    clear_grasp(meshcat, "test/planar")

    soft = Grasp(
        [
            Contact(
                [0, 0, 0.1],
                [0, 0, -1],
                mu=0.5,
                contact_model="soft_finger",
                torsional_friction=0.2,
            )
        ]
    )
    draw_grasp(meshcat, soft, cone="pyramid", prefix="test/soft")
    assert meshcat.HasPath("test/soft/contact_0/cone/pyramid")
    clear_grasp(meshcat, "test/soft")


def test_bad_options(meshcat):
    grasp = _ring()
    with pytest.raises(InvalidOptionError, match="cone"):
        draw_grasp(meshcat, grasp, cone="cylinder")
    with pytest.raises(InvalidOptionError, match="side"):
        draw_grasp(meshcat, grasp, side="under")
    with pytest.raises(InvalidOptionError, match="X_WG"):
        draw_grasp(meshcat, grasp, X_WG=np.eye(4))
    with pytest.raises(InvalidOptionError, match="prefix"):
        draw_grasp(meshcat, grasp, prefix="/")
    with pytest.raises(InvalidOptionError, match="cone_height"):
        draw_grasp(meshcat, grasp, cone_height=0.0)
    with pytest.raises(InvalidOptionError, match="3 contacts"):
        draw_grasp(meshcat, grasp, result=[[1.0, 0, 0]])
    with pytest.raises(InvalidOptionError, match="colour"):
        draw_grasp(meshcat, grasp, colors={"arrow": (1, 0, 0)})
    with pytest.raises(InvalidOptionError, match="Grasp"):
        draw_grasp(meshcat, grasp.contacts)
    # Nothing was left half-drawn by the failed calls.
    assert not meshcat.HasPath("drakegrasp/grasp")
