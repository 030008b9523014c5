"""Review r21 of the ``drakegrasp`` command: flag words and one-line errors.

* ``batch --kind form --metrics epsilon_l1`` names the flag that gives
  friction (``--kind force``), not a Python function.
* ``plan --hand ""`` is refused (listing the hands), not planned with the
  flat jaw.
* ``batch --model`` (deprecated) keeps every error to one line on stderr.
* ``batch`` of an empty file writes every column; a file's per-contact
  ``torsional_friction`` array is checked for every contact model.
"""

from __future__ import annotations

import numpy as np
import pytest

from drakegrasp.cli import PLAN_HANDS, main
from drakegrasp.core import examples as ex


def _good(path, K: int = 4, **extra):
    g = ex.equator_fingers(0.5)
    P = np.repeat(np.asarray(g.positions)[None], K, 0)
    N = np.repeat(np.asarray(g.normals)[None], K, 0)
    np.savez(path, positions=P, normals=N, mu=np.full(P.shape[:2], 0.5), **extra)
    return str(path)


def _one_line_error(capsys, argv) -> str:
    code = main(argv)
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.strip()]
    assert code == 1, err
    assert len(lines) == 1, err
    assert lines[0].startswith("drakegrasp: error: ")
    return lines[0]


def test_form_closure_epsilon_names_the_flag_not_the_function(tmp_path, capsys):
    line = _one_line_error(
        capsys,
        ["batch", _good(tmp_path / "good.npz"), str(tmp_path / "m4.npz"),
         "--kind", "form", "--metrics", "epsilon_l1"],
    )  # fmt: skip
    assert "needs friction" in line and "--kind force" in line
    assert "batch_force_closure" not in line
    assert not (tmp_path / "m4.npz").exists()


def test_the_python_api_keeps_its_own_remedy():
    import drakegrasp as dg

    P = np.zeros((1, 3, 3))
    with pytest.raises(dg.GraspError, match="use batch_force_closure"):
        dg.batch_form_closure(P, P + [0, 0, 1], metrics=("epsilon_l1",))


@pytest.mark.parametrize("hand", ["", "   "])
def test_an_empty_hand_is_refused_with_the_valid_ones(capsys, hand):
    line = _one_line_error(capsys, ["plan", "--hand", hand, "--num", "1"])
    assert "--hand" in line and "empty" in line
    assert all(name in line for name in PLAN_HANDS)


def test_no_hand_is_still_the_flat_jaw():
    from drakegrasp.cli import _plan_hand

    assert _plan_hand(None) == PLAN_HANDS["flat"]


def test_model_and_contact_model_that_disagree_are_one_line(tmp_path, capsys):
    line = _one_line_error(
        capsys,
        ["batch", _good(tmp_path / "good.npz"), str(tmp_path / "o.npz"),
         "--model", "soft_finger", "--contact-model", "hard_finger"],
    )  # fmt: skip
    assert "disagree" in line and "--model" in line and "--contact-model" in line
    assert not (tmp_path / "o.npz").exists()


def test_an_error_with_the_deprecated_model_is_one_line_with_the_note(tmp_path, capsys):
    # soft fingers without a torsional friction: the error, the note folded in
    line = _one_line_error(
        capsys,
        ["batch", _good(tmp_path / "good.npz"), str(tmp_path / "o.npz"),
         "--model", "soft_finger"],
    )  # fmt: skip
    assert "--torsional-friction" in line  # still the CLI's words
    assert "--model is deprecated" in line


def test_the_deprecated_model_still_says_so_when_it_works(tmp_path, capsys):
    out = tmp_path / "o.npz"
    code = main(["batch", _good(tmp_path / "good.npz"), str(out),
                 "--model", "hard_finger"])  # fmt: skip
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert "--model is deprecated; use --contact-model" in captured.err
    assert f"wrote {out}" in captured.out
    with np.load(out) as z:
        assert z["is_closure"].all()


@pytest.mark.parametrize("suffix", ["npz", "parquet"])
def test_batch_of_no_grasps_writes_every_column(tmp_path, capsys, suffix):
    if suffix == "parquet":
        pq = pytest.importorskip("pyarrow.parquet", reason="pyarrow is optional")
    src = tmp_path / "k0.npz"
    zero = np.zeros((0, 3, 3))
    np.savez(src, positions=zero, normals=zero, mu=np.zeros((0, 3)))
    out = tmp_path / f"w.{suffix}"
    argv = ["batch", str(src), str(out), "--metrics", "sigma_min", "epsilon_l1"]
    assert main(argv) == 0, capsys.readouterr().err
    if suffix == "npz":
        with np.load(out) as z:
            names = [k for k in z if z[k].ndim]
    else:
        names = pq.read_schema(out).names
    assert names == [
        "is_closure", "d_star", "rank", "margin", "converged",
        "normal_certificate", "sigma_min", "epsilon_l1",
    ]  # fmt: skip


def test_a_file_torsional_friction_array_is_checked_like_the_flag(tmp_path, capsys):
    bad = _good(tmp_path / "tf.npz", torsional_friction=np.full((4, 3), -1.0))
    line = _one_line_error(capsys, ["batch", bad, str(tmp_path / "o.npz")])
    assert "torsional_friction of grasp 0, contact 0 is -1.0" in line
    # as the flag is (by argparse, status 2)
    with pytest.raises(SystemExit) as exit_:
        main(["batch", _good(tmp_path / "good.npz"), str(tmp_path / "o.npz"),
              "--torsional-friction", "-1"])  # fmt: skip
    assert exit_.value.code == 2
    assert "--torsional-friction" in capsys.readouterr().err
    assert not (tmp_path / "o.npz").exists()
