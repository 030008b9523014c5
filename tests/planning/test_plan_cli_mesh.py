"""``drakegrasp plan my_object.obj``: a user's mesh is an object to plan for."""

from __future__ import annotations

import json

import numpy as np
import pytest

from drakegrasp.cli import main

# A 40 x 60 x 80 mm box as a Wavefront OBJ: 8 vertices, 12 outward triangles.
_HALF = np.array([0.02, 0.03, 0.04])
_FACES = [
    (1, 3, 2), (2, 3, 4), (5, 6, 7), (6, 8, 7), (1, 2, 5), (2, 6, 5),
    (3, 7, 4), (4, 7, 8), (1, 5, 3), (3, 5, 7), (2, 4, 6), (4, 8, 6),
]  # fmt: skip


def _box_obj(path):
    corners = [
        _HALF * np.array([x, y, z]) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)
    ]
    lines = [f"v {c[0]} {c[1]} {c[2]}" for c in corners]
    lines += [f"f {a} {c} {b}" for a, b, c in _FACES]  # counter-clockwise outside
    path.write_text("\n".join(lines) + "\n")
    return path


def test_a_mesh_file_is_planned_for_like_a_model(tmp_path, capsys):
    obj = _box_obj(tmp_path / "my_box.obj")
    argv = ["plan", str(obj), "--num", "120", "--top", "3", "--json"]
    assert main(argv) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["object_body"].endswith("my_box")
    best = data["candidates"]
    assert len(best) == 3 and all(c["is_closure"] for c in best)
    # every contact is on the mesh's surface, its normal the face's
    for c in best:
        p = np.array([k["p_OC"] for k in c["contacts"]])
        n = np.array([k["nhat_O"] for k in c["contacts"]])
        on_face = np.abs(p) / _HALF
        assert np.allclose(on_face.max(axis=1), 1.0, atol=5e-3)
        face = on_face.argmax(axis=1)
        assert np.allclose(np.abs(n[np.arange(len(n)), face]), 1.0, atol=1e-6)


def test_a_mesh_that_is_not_there_is_named(capsys):
    assert main(["plan", "missing.obj", "--num", "5"]) == 1
    err = capsys.readouterr().err
    assert err == "drakegrasp: error: object file 'missing.obj' not found\n"


@pytest.mark.parametrize("hand", ["missing_hand.sdf", "missing_hand.urdf"])
def test_a_hand_file_that_is_not_there_is_named(capsys, hand):
    assert main(["plan", "box", "--hand", hand, "--num", "5"]) == 1
    err = capsys.readouterr().err
    assert err == f"drakegrasp: error: --hand file {hand!r} not found\n"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "contains no objects"),
        ("\x00\x17garbage\xff", "contains no objects"),
        # Drake's parser would read these vertices at finite places
        ("v nan 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\n", "line 1: a vertex must"),
        ("v 0 0 0\nv inf 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\n", "line 2: a vertex must"),
        ("v 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "line 1: a vertex must"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "volume"),  # flat: no inside
        # as Drake reads them: an indented or tab-separated vertex is a vertex
        ("v 0 0 0\n  v nan 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\n", "line 2: a vertex"),
        ("v 0 0 0\nv\tnan 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\n", "line 2: a vertex"),
        # a face naming a vertex the file lacks stopped the interpreter in Drake
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "line 4: a face names vertex 9"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n", "line 4: a face names vertex -4"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", "line 4: a face names vertex 0"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", "line 4: a face's vertex must"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9.0\n", "line 4: a face names vertex 9"),
    ],
)
def test_a_hostile_mesh_is_refused_in_one_line(tmp_path, capsys, text, message):
    obj = tmp_path / "bad.obj"
    obj.write_text(text, encoding="latin-1")
    assert main(["plan", str(obj), "--num", "5"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("drakegrasp: error: ")
    assert message in err, err
