"""The command's messages speak its own language: flags, not Python keywords.

A newcomer's walkthrough found messages that named ``num_candidates`` for
``--num`` or ``overwrite=True`` for ``--overwrite``, a ``plan`` hint about a
contact model plan has no flag for, no ``--version``, a wrong
``DRAKEGRASP_DRAKE_MODELS`` reported as unset, and a warmup estimate twice the
measured time.
"""

from __future__ import annotations

import importlib.metadata
from types import SimpleNamespace

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.cli import PLAN_HANDS, build_parser, main
from drakegrasp.plant.scene import DEFAULT_SCENE, scene_path


def _one_line(capsys, *argv, code=1):
    assert main(list(argv)) == code
    captured = capsys.readouterr()
    assert captured.err.count("\n") == 1, captured.err
    assert captured.err.startswith("drakegrasp: error: "), captured.err
    return captured.err


@pytest.fixture
def grasps(tmp_path):
    rng = np.random.default_rng(0)
    p = rng.normal(size=(4, 3, 3))
    path = tmp_path / "in.npz"
    np.savez(path, positions=p, normals=-p)
    return str(path), str(tmp_path / "out.npz")


@pytest.mark.parametrize(
    ("argv", "flag"),
    [
        (("analyze", "--num-generators", "2"), "--num-generators"),
        (("analyze", "--distance-tolerance", "0"), "--distance-tolerance"),
        (("analyze", "--tol", "0.9"), "--tol"),
        (("analyze", "--characteristic-length", "1e40"), "--characteristic-length"),
        (("analyze", "--torsional-friction", "1e40"), "--torsional-friction"),
        (("analyze", "--mu", "1e13"), "--mu"),
    ],
)
def test_an_analyze_value_out_of_range_names_its_flag(capsys, argv, flag):
    err = _one_line(capsys, *argv)
    assert err.startswith(f"drakegrasp: error: {flag} must be"), err


@pytest.mark.parametrize("value", ["0.02", "1e9"])
def test_a_distance_tolerance_in_millimetres_is_refused_naming_the_unit(capsys, value):
    # --distance-tolerance 1e9 counted a palm 15 mm away as 4 contacts
    err = _one_line(capsys, "analyze", "--distance-tolerance", value)
    assert err.startswith(f"drakegrasp: error: --distance-tolerance {float(value):g} m")
    assert "0.01 m (10 mm)" in err and "the unit is metres" in err


@pytest.mark.parametrize(
    ("extra", "flag"),
    [
        (("--num-generators", "2"), "--num-generators"),
        (("--chunk-size", "0"), "--chunk-size"),
        (("--tol", "2"), "--tol"),
        (("--mu", "1e13"), "--mu"),
        (("--mu", "0.5", "--torsional-friction", "1e13"), "--torsional-friction"),
    ],
)
def test_a_batch_value_out_of_range_names_its_flag(capsys, grasps, extra, flag):
    err = _one_line(capsys, "batch", *grasps, *extra)
    assert err.startswith(f"drakegrasp: error: {flag} must be"), err


@pytest.mark.parametrize(
    ("extra", "flag"),
    [(("--num", "-5"), "--num"), (("--num", "3", "--seed", "-1"), "--seed")],
)
def test_a_plan_value_out_of_range_names_its_flag(capsys, extra, flag):
    err = _one_line(capsys, "plan", *extra)
    assert err.startswith(f"drakegrasp: error: {flag} must be"), err
    assert "num_candidates" not in err


def test_an_existing_output_asks_for_the_overwrite_flag(capsys, grasps):
    src, out = grasps
    assert main(["batch", src, out, "--mu", "0.5"]) == 0
    capsys.readouterr()
    err = _one_line(capsys, "batch", src, out, "--mu", "0.5")
    assert "pass --overwrite to replace it" in err
    assert "overwrite=True" not in err


def test_soft_fingers_without_nu_ask_for_the_flag(capsys, grasps, tmp_path):
    err = _one_line(
        capsys, "batch", *grasps, "--mu", "0.5", "--contact-model", "soft_finger"
    )
    assert "--contact-model soft_finger needs" in err
    assert "--torsional-friction NU" in err and "torsional_friction" in err
    assert "contact_model=" not in err
    scene = tmp_path / "no_nu.yaml"  # the default scene without its nu
    text = scene_path(DEFAULT_SCENE).read_text()
    scene.write_text(text.replace("torsional_friction: 0.1", ""))
    err = _one_line(capsys, "analyze", str(scene), "--contact-model", "soft_finger")
    assert "--torsional-friction NU" in err and "contact_model=" not in err


def test_a_wrong_hand_alias_lists_the_aliases_and_suggests_one(capsys):
    # (an alias in other letter case is taken: "WSG", "Allegro")
    err = _one_line(capsys, "plan", "box", "--hand", "wsg50", "--num", "1")
    assert "did you mean 'wsg'?" in err
    assert all(alias in err for alias in PLAN_HANDS)


def test_metrics_warns_that_it_takes_the_words_after_it(capsys, grasps):
    _, sub = build_parser()
    metrics = next(
        a for a in sub.choices["batch"]._actions if "--metrics" in a.option_strings
    )
    assert "after the positional arguments or before another option" in metrics.help
    assert "end it with --" in metrics.help
    with pytest.raises(SystemExit) as exit_:
        main(["batch", "--metrics", "sigma_min", *grasps])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "end it with --" in err


def test_plan_suggests_soft_fingers_only_where_they_can_be_had(capsys):
    """Two point contacts: the hint named contact_model=; plan now has the flags."""
    assert main(["plan", "sphere", "--hand", "rounded", "--num", "4"]) == 0
    out = capsys.readouterr().out
    assert "torque about the line" in out  # the reason is still given
    assert "contact_model='soft_finger' with torsional_friction models" not in out
    assert "(--contact-model soft_finger --torsional-friction NU)" in out


def test_version(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["--version"])
    assert exit_.value.code == 0
    # the running code's version, which the installed metadata agrees with
    assert capsys.readouterr().out == f"drakegrasp {dg.__version__}\n"
    assert importlib.metadata.version("drakegrasp") == dg.__version__


def test_a_wrong_drake_models_variable_is_reported_as_set(capsys, monkeypatch):
    monkeypatch.setenv("DRAKEGRASP_DRAKE_MODELS", "/nope")
    err = _one_line(capsys, "plan", "box", "--hand", "wsg", "--num", "1")
    assert "DRAKEGRASP_DRAKE_MODELS is set to '/nope'" in err
    assert "set DRAKEGRASP_DRAKE_MODELS or" not in err


def test_warmup_promises_what_it_measured(capsys, monkeypatch):
    """86 functions compiled in 42-59 s of one core (2 shared cores, under load);
    a process's first closure and ε calls took up to two minutes at load 8-10."""
    from drakegrasp.batch import aot, warmup

    monkeypatch.setattr(aot, "status", lambda: "numba's JIT runs")
    report = SimpleNamespace(available=True, compiled=86, seconds=41.7)
    report.cache_dir, report.route = None, "numba's JIT runs"
    monkeypatch.setattr(warmup, "warmup", lambda progress: report)
    assert main(["warmup"]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    said = "40 s to two minutes, depending on the machine and its load"
    assert said in first and "under a minute" not in first
    _, sub = build_parser()
    description = sub.choices["warmup"].description
    assert said in description


def test_a_path_holding_the_keyword_is_not_rewritten(capsys, grasps, tmp_path):
    # The rewrite of the library's remedy reached into the user's path.
    src, _ = grasps
    odd = tmp_path / "keep overwrite=True"
    odd.mkdir()
    out = str(odd / "r.npz")
    assert main(["batch", src, out, "--mu", "0.5"]) == 0
    capsys.readouterr()
    err = _one_line(capsys, "batch", src, out, "--mu", "0.5")
    assert repr(out) in err and "pass --overwrite to replace it" in err


@pytest.mark.parametrize("mu", ["1e-13", "2e12"])
def test_batch_form_closure_ignores_mu_as_its_help_says(capsys, grasps, mu):
    # --kind form ignores --mu: refusing its value was a regression.
    src, out = grasps
    assert main(["batch", src, out, "--kind", "form", "--mu", mu]) == 0


def test_a_misspelt_model_file_does_not_blame_the_folder(
    capsys, drake_models_dir, monkeypatch
):
    monkeypatch.setenv("DRAKEGRASP_DRAKE_MODELS", str(drake_models_dir))
    url = "package://drake_models/wsg_50_description/sdf/nonexistent.sdf"
    err = _one_line(capsys, "plan", "box", "--hand", url, "--num", "1")
    assert "nonexistent.sdf" in err and "DRAKEGRASP_DRAKE_MODELS is set" not in err


def test_an_empty_or_endless_name_gets_a_short_line(tmp_path, capsys):
    # "" read as "a directory, not a scene file"; a 5,000-character name gave
    # "[Errno 36] File name too long: '…'" with the whole name in it
    assert main(["analyze", ""]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "the scene's name is empty" in err[0], err
    endless = "a" * 5000
    assert main(["analyze", endless]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and len(err[0]) < 400 and "..." in err[0], err
    src = tmp_path / "in.npz"
    np.savez(src, positions=np.zeros((2, 2, 3)), normals=np.ones((2, 2, 3)), mu=0.5)
    assert main(["batch", str(src), str(tmp_path / f"{endless}.npz")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and len(err[0]) < 400 and "too long" in err[0], err


@pytest.mark.parametrize(
    "error, want",
    [
        (OSError(18, "Invalid cross-device link", "/a/o.partial", None, "/b/o.npz"),
         "Invalid cross-device link: '/a/o.partial' -> '/b/o.npz'"),
        (OSError(9, "Bad file descriptor", 3), "[Errno 9] Bad file descriptor: 3"),
    ],
)  # fmt: skip
def test_a_file_error_names_both_files_and_never_fails_itself(
    monkeypatch, capsys, error, want
):
    # os.replace's failure named only the temporary file; an int file name
    # (a descriptor) would have raised TypeError in the message itself
    import drakegrasp.cli as cli

    def fails(_args):
        raise error

    monkeypatch.setattr(cli, "_analyze", fails)
    assert main(["analyze"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].endswith(want), err
