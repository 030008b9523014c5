"""Review r21 of the batch engine: an empty batch's file, per-contact ν arrays.

* A file of no grasps (``K = 0``) holds the columns a file of ``K > 0`` does
  (``normal_certificate`` and the metrics too), with the same dtypes and
  per-grasp shapes, in ``.npz`` and Parquet, for force and form closure.
* A per-contact ``torsional_friction`` array is checked for every contact
  model, as ``mu`` arrays and a scalar ``torsional_friction`` are.
"""

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.batch import stream_file, write_chunks
from drakegrasp.core import examples as ex
from drakegrasp.errors import GraspError

K = 4


def _stack(K: int = K):
    g = ex.equator_fingers(0.5)
    P = np.repeat(np.asarray(g.positions)[None], K, 0)
    N = np.repeat(np.asarray(g.normals)[None], K, 0)
    return P, N


def _write(path, K: int, **extra):
    if K:
        P, N = _stack(K)
    else:
        P = N = np.zeros((0, 3, 3))
    np.savez(path, positions=P, normals=N, mu=np.full(P.shape[:2], 0.5), **extra)
    return path


def _columns(path):
    """Column name -> (dtype, per-grasp shape) of a written result file."""
    if path.suffix == ".npz":
        with np.load(path) as z:
            return {k: (z[k].dtype.str, z[k].shape[1:]) for k in z if z[k].ndim}
    pq = pytest.importorskip("pyarrow.parquet", reason="pyarrow is an optional extra")
    schema = pq.read_schema(path)
    return {name: (str(schema.field(name).type), ()) for name in schema.names}


METRICS = {
    "force": ("sigma_min", "isotropy", "ellipsoid_volume", "epsilon_l1"),
    "form": ("sigma_min", "isotropy", "ellipsoid_volume"),
}


@pytest.mark.parametrize("fmt", ["npz", "parquet"])
@pytest.mark.parametrize("kind", ["force", "form"])
def test_an_empty_batch_file_has_the_columns_of_any_other(tmp_path, kind, fmt):
    if fmt == "parquet":
        pytest.importorskip("pyarrow", reason="pyarrow is an optional extra")
    metrics = METRICS[kind]
    empty = tmp_path / f"k0.{fmt}"
    full = tmp_path / f"k4.{fmt}"
    stream_file(_write(tmp_path / "in0.npz", 0), empty, kind=kind, metrics=metrics)
    stream_file(_write(tmp_path / "in4.npz", K), full, kind=kind, metrics=metrics)
    got, want = _columns(empty), _columns(full)
    assert got == want
    assert ("normal_certificate" in got) == (kind == "force")
    assert set(metrics) <= set(got)
    # and they are the columns of the Python API's result of no grasps
    P = np.zeros((0, 3, 3))
    api = (
        dg.batch_force_closure(P, P, mu=0.5, metrics=metrics)
        if kind == "force"
        else dg.batch_form_closure(P, P, metrics=metrics)
    )
    assert list(got) == list(api.to_arrays())


def test_the_empty_columns_are_those_a_result_is_collected_in():
    from drakegrasp.batch.columns import result_arrays

    out, metrics = result_arrays(0, "force", ("sigma_min",))
    P = np.zeros((0, 3, 3))
    api = dg.batch_force_closure(P, P, mu=0.5, metrics=("sigma_min",))
    arrays = api.to_arrays()
    both = {**out, **metrics}
    assert list(both) == list(arrays)
    for name, a in both.items():
        assert a.dtype == arrays[name].dtype and a.shape == arrays[name].shape


def test_write_chunks_and_write_result_of_no_grasps_keep_the_metrics(tmp_path):
    out = tmp_path / "o.npz"
    write_chunks(
        [], out, K=0, kind="form", tol=1e-6, required_rank=6, metrics=("sigma_min",)
    )
    names = set(_columns(out))
    assert "sigma_min" in names and "normal_certificate" not in names
    P = np.zeros((0, 3, 3))
    result = dg.batch_force_closure(P, P, mu=0.5, metrics=("isotropy",))
    out = dg.batch.write_result(result, tmp_path / "r.npz")
    assert list(_columns(out)) == list(result.to_arrays())


@pytest.mark.parametrize("model", ["hard_finger", "frictionless", "soft_finger"])
@pytest.mark.parametrize("bad", [np.nan, -1.0, np.inf, 1e-13])
def test_a_torsional_friction_array_is_checked_for_every_model(model, bad):
    P, N = _stack()
    nu = np.full((K, 3), 0.1)
    nu[2, 1] = bad
    with pytest.raises(GraspError, match=r"torsional_friction of grasp 2, contact 1"):
        dg.batch_force_closure(P, N, mu=0.5, contact_model=model, torsional_friction=nu)


def test_a_per_grasp_torsional_friction_is_checked_too():
    P, N = _stack()
    nu = np.full((K, 1), 0.1)
    nu[3] = -1.0
    with pytest.raises(GraspError, match=r"torsional_friction of grasp 3"):
        dg.batch_force_closure(P, N, mu=0.5, torsional_friction=nu)


def test_a_file_s_torsional_friction_array_is_checked(tmp_path):
    src = _write(tmp_path / "in.npz", K, torsional_friction=np.full((K, 3), -1.0))
    with pytest.raises(GraspError, match=r"torsional_friction of grasp 0, contact 0"):
        stream_file(src, tmp_path / "out.npz")
    assert not (tmp_path / "out.npz").exists()


@pytest.mark.parametrize("model", ["hard_finger", "frictionless"])
def test_valid_torsional_friction_arrays_leave_results_bit_identical(model):
    P, N = _stack()
    nu = np.linspace(0.0, 2.0, K * 3).reshape(K, 3)
    a = dg.batch_force_closure(P, N, mu=0.5, contact_model=model)
    b = dg.batch_force_closure(P, N, mu=0.5, contact_model=model, torsional_friction=nu)
    for name, x in a.to_arrays().items():
        assert x.tobytes() == b[name].tobytes(), name
