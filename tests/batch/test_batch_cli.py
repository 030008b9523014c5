"""`drakegrasp batch IN OUT`: same verdicts as the API, one-line errors."""

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.cli import main


@pytest.fixture
def grasp_file(tmp_path):
    rng = np.random.default_rng(3)
    p = rng.normal(size=(300, 3, 3))
    p /= np.linalg.norm(p, axis=2, keepdims=True)
    n = -p + 0.5 * rng.normal(size=p.shape)
    path = tmp_path / "grasps.npz"
    np.savez(path, positions=p, normals=n, mu=np.full((300, 3), 0.5))
    return path, p, n


def test_batch_command_writes_the_api_verdicts(grasp_file, tmp_path, capsys):
    path, p, n = grasp_file
    out = tmp_path / "out.npz"
    assert main(["batch", str(path), str(out), "--metrics", "sigma_min"]) == 0
    written = np.load(out)
    expected = dg.batch_force_closure(p, n, mu=0.5, metrics=("sigma_min",))
    assert np.array_equal(written["is_closure"], expected.is_closure)
    assert np.allclose(written["d_star"], expected.d_star)
    assert np.allclose(written["sigma_min"], expected.metrics["sigma_min"])
    assert 0 < expected.is_closure.sum() < 300
    assert "force closure of 300 grasps" in capsys.readouterr().out


def test_mu_on_the_command_line_overrides_the_file(grasp_file, tmp_path):
    path, p, n = grasp_file
    out = tmp_path / "out.npz"
    assert main(["batch", str(path), str(out), "--mu", "0"]) == 0
    assert np.array_equal(
        np.load(out)["is_closure"], dg.batch_force_closure(p, n, mu=0.0).is_closure
    )


def test_form_closure_kind(grasp_file, tmp_path):
    path, p, n = grasp_file
    out = tmp_path / "out.npz"
    assert main(["batch", str(path), str(out), "--kind", "form"]) == 0
    assert not np.load(out)["is_closure"].any()  # three contacts never suffice


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda d: np.savez(d / "in.npz", positions=np.zeros((2, 3, 3))), "normals"),
        (lambda d: (d / "in.npz").write_text("not an archive"), "in.npz"),
        (lambda d: None, "does not exist"),
    ],
)
def test_bad_input_prints_one_line_and_fails(tmp_path, capsys, make, message):
    make(tmp_path)
    code = main(["batch", str(tmp_path / "in.npz"), str(tmp_path / "out.npz")])
    err = capsys.readouterr().err
    assert code == 1 and message in err
    assert err.count("\n") == 1 and "Traceback" not in err


def test_a_directory_of_npy_files_is_read_chunk_by_chunk(grasp_file, tmp_path):
    from drakegrasp.batch import read_grasps

    _, p, n = grasp_file
    folder = tmp_path / "grasps"
    folder.mkdir()
    np.save(folder / "positions.npy", p)
    np.save(folder / "normals.npy", n)
    arrays = read_grasps(folder)
    assert isinstance(arrays["positions"], np.memmap)  # nothing loaded yet
    out = tmp_path / "out.npz"
    assert (
        main(["batch", str(folder), str(out), "--mu", "0.5", "--chunk-size", "64"]) == 0
    )
    expected = dg.batch_force_closure(p, n, mu=0.5)
    assert np.array_equal(np.load(out)["is_closure"], expected.is_closure)


def test_a_directory_without_normals_is_named(tmp_path, capsys):
    (tmp_path / "g").mkdir()
    np.save(tmp_path / "g" / "positions.npy", np.zeros((2, 3, 3)))
    assert (
        main(["batch", str(tmp_path / "g"), str(tmp_path / "o.npz"), "--mu", "1"]) == 1
    )
    assert "has no array(s) ['normals']" in capsys.readouterr().err


@pytest.mark.parametrize(
    "extra, named",
    [
        (["--workers", "2"], "--workers"),
        (["--progress"], "--progress"),
        (["--format", "npz"], "--format"),
        (["--workers", "1", "--progress"], "--workers, --progress"),
    ],
)
def test_scheduler_refuses_options_it_would_ignore(
    grasp_file, tmp_path, capsys, extra, named
):
    # No scheduler is contacted: the refusal comes before any connection.
    path, _, _ = grasp_file
    out = tmp_path / "dataset"
    args = ["batch", str(path), str(out), "--scheduler", "127.0.0.1:1", *extra]
    assert main(args) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{named} cannot be used with --scheduler" in err
    assert not out.exists()


def test_an_unwritable_output_names_the_users_path_not_a_temporary_one(
    grasp_file, tmp_path, capsys, monkeypatch
):
    import os

    path, _, _ = grasp_file
    out = tmp_path / "out.npz"
    real_open = os.open

    def refuse(name, flags, *args):  # a read-only folder, even for root
        if str(name).endswith(".partial"):
            raise PermissionError(13, "Permission denied", str(name))
        return real_open(name, flags, *args)

    monkeypatch.setattr(os, "open", refuse)
    code = main(["batch", str(path), str(out)])
    err = capsys.readouterr().err
    assert code == 1 and f"cannot write '{out}': Permission denied" in err
    assert ".partial" not in err and err.count("\n") == 1
    assert not list(tmp_path.glob(".out.npz*"))


@pytest.mark.parametrize(
    "name, fmt, ok",
    [
        ("o.npz", "parquet", False),
        ("o.PARQUET", "npz", False),
        ("o.npz", "npz", True),
    ],
)
def test_format_contradicting_the_suffix_is_refused(
    grasp_file, tmp_path, capsys, name, fmt, ok
):
    # A Parquet file named .npz fooled every reader that trusts the suffix.
    if fmt == "parquet":
        pytest.importorskip("pyarrow", reason="pyarrow is an optional extra")
    path, _, _ = grasp_file
    out = tmp_path / name
    code = main(["batch", str(path), str(out), "--format", fmt])
    err = capsys.readouterr().err
    if ok:
        assert code == 0 and out.exists()
    else:
        assert code == 1 and not out.exists()
        assert err.count("\n") == 1 and f"but the format is {fmt!r}" in err


def test_an_output_name_near_the_length_limit_is_written(grasp_file, tmp_path):
    # The temporary sibling added 22 characters to the name: an output named
    # with 234-255 bytes could not be written at all.
    path, _, _ = grasp_file
    out = tmp_path / ("r" * 251 + ".npz")
    assert main(["batch", str(path), str(out)]) == 0
    assert out.exists() and [p.name for p in tmp_path.iterdir() if p != path] == [
        out.name
    ]


def test_an_output_under_a_file_says_so(grasp_file, tmp_path, capsys):
    path, _, _ = grasp_file
    (tmp_path / "plain").write_text("")
    assert main(["batch", str(path), str(tmp_path / "plain" / "o.npz")]) == 1
    assert (
        "'" + str(tmp_path / "plain") + "' is not a directory"
        in capsys.readouterr().err
    )
