"""Bad inputs name the offending grasp, contact and value; chunking and streaming."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from batch_support import random_grasps

import drakegrasp.batch.run.chunk as chunks
from drakegrasp.batch import batch_force_closure, batch_form_closure, iter_batch_closure
from drakegrasp.errors import (
    GraspError,
    InvalidContactError,
    InvalidGraspError,
    InvalidOptionError,
)


@pytest.fixture
def grasps():
    rng = np.random.default_rng(11)
    return random_grasps(rng, 40, 3, 3)


@pytest.mark.parametrize("bad", [0.0, np.nan, np.inf])
def test_bad_normal_names_grasp_and_contact(grasps, bad):
    P, Nrm = grasps
    Nrm = Nrm.copy()
    Nrm[27, 2] = bad
    with pytest.raises(InvalidContactError, match=r"grasp 27, contact 2"):
        batch_force_closure(P, Nrm, mu=0.5, chunk_size=8)
    with pytest.raises(InvalidContactError, match=r"grasp 27, contact 2"):
        batch_form_closure(P, Nrm)


def test_non_finite_position(grasps):
    P, Nrm = grasps
    P = P.copy()
    P[5, 0, 1] = np.nan
    with pytest.raises(InvalidContactError, match=r"grasp 5, contact 0.*not finite"):
        batch_force_closure(P, Nrm, mu=0.5)


@pytest.mark.parametrize("bad", [-0.1, np.nan])
def test_bad_mu_names_index_and_value(grasps, bad):
    P, Nrm = grasps
    mu = np.full((40, 3), 0.5)
    mu[33, 1] = bad
    with pytest.raises(
        InvalidContactError, match=rf"mu of grasp 33, contact 1 is {bad}"
    ):
        batch_force_closure(P, Nrm, mu=mu, chunk_size=16)
    with pytest.raises(InvalidContactError, match="mu must be finite"):
        batch_force_closure(P, Nrm, mu=bad)


def test_shape_errors(grasps):
    P, Nrm = grasps
    with pytest.raises(InvalidContactError, match=r"\(K, N, 2\) or \(K, N, 3\)"):
        batch_force_closure(P[..., :1], Nrm[..., :1], mu=0.5)
    with pytest.raises(InvalidContactError, match="normals must have the shape"):
        batch_force_closure(P, Nrm[:, :2], mu=0.5)
    with pytest.raises(InvalidContactError, match=r"mu must be a scalar.*\(7,\)"):
        batch_force_closure(P, Nrm, mu=np.ones(7))
    with pytest.raises(InvalidGraspError, match="reference_points"):
        batch_force_closure(P, Nrm, mu=0.5, reference_points=np.zeros((3, 3)))
    with pytest.raises(InvalidGraspError, match="reference point of grasp 4"):
        p = np.zeros((40, 3))
        p[4, 0] = np.inf
        batch_force_closure(P, Nrm, mu=0.5, reference_points=p)
    with pytest.raises(InvalidGraspError, match="characteristic length of grasp 0"):
        batch_force_closure(P, Nrm, mu=0.5, characteristic_lengths=-1.0)


def test_option_errors(grasps):
    P, Nrm = grasps
    with pytest.raises(InvalidContactError, match="unknown contact model 'sticky'"):
        batch_force_closure(P, Nrm, mu=0.5, contact_model="sticky")
    with pytest.raises(InvalidContactError, match="soft-finger contact is spatial"):
        batch_force_closure(
            P[..., :2], Nrm[..., :2], mu=0.5, contact_model="soft_finger"
        )
    with pytest.raises(
        InvalidOptionError, match="num_generators must be an integer >= 3"
    ):
        batch_force_closure(P, Nrm, mu=0.5, num_generators=2)
    with pytest.raises(
        InvalidOptionError, match="chunk_size must be an integer >= 1, got 0"
    ):
        batch_force_closure(P, Nrm, mu=0.5, chunk_size=0)
    with pytest.raises(InvalidOptionError, match="tol must be finite"):
        batch_force_closure(P, Nrm, mu=0.5, tol=-1)
    with pytest.raises(InvalidOptionError, match="unknown metric 'beauty'"):
        batch_force_closure(P, Nrm, mu=0.5, metrics=["beauty"])
    with pytest.raises(InvalidContactError, match="torsional_friction of grasp 1"):
        nu = np.zeros((40, 3))
        nu[1, 1] = -2
        batch_force_closure(
            P, Nrm, mu=0.5, contact_model="soft_finger", torsional_friction=nu
        )
    assert issubclass(InvalidOptionError, GraspError)


def test_empty_batch():
    res = batch_force_closure(np.zeros((0, 3, 3)), np.zeros((0, 3, 3)), mu=0.5)
    assert len(res) == 0 and res.d_star.shape == (0,) and res.required_rank == 6


def test_chunk_size_does_not_change_results():
    rng = np.random.default_rng(12)
    K = 230
    P, Nrm = random_grasps(rng, K, 4, 3)
    mu = rng.uniform(0, 1, (K, 4))
    mu[rng.random((K, 4)) < 0.25] = 0.0  # several layouts per chunk
    ref = batch_force_closure(P, Nrm, mu=mu, chunk_size=K, metrics=["sigma_min"])
    assert 0 < ref.is_closure.sum() < K
    for cs in (1, 7, 64):
        res = batch_force_closure(P, Nrm, mu=mu, chunk_size=cs, metrics=["sigma_min"])
        np.testing.assert_array_equal(res.is_closure, ref.is_closure)
        np.testing.assert_array_equal(res.rank, ref.rank)
        # The interior-point method stops at ~1e-10 on t = d*/N; the vectorised
        # QR rounds differently for other stack sizes, which moves d* within
        # that tolerance (chunk boundaries, not workers: see test_batch_scale).
        np.testing.assert_allclose(res.d_star, ref.d_star, rtol=0, atol=1e-9)
        np.testing.assert_allclose(
            res.metrics["sigma_min"], ref.metrics["sigma_min"], rtol=1e-12
        )
    form = [batch_form_closure(P, Nrm, chunk_size=cs).d_star for cs in (3, K)]
    np.testing.assert_allclose(form[0], form[1], rtol=0, atol=1e-9)


def test_default_chunks_spread_a_small_batch_over_the_workers():
    """chunk_size=None: bytes-sized chunks, cut into TARGET_CHUNKS for small K."""
    from drakegrasp.batch.run.stream import (
        MIN_CHUNK_CONTACTS,
        TARGET_CHUNKS,
        chunk_size_for,
    )

    for N in (3, 12, 24):
        by_bytes = chunk_size_for(N, 3, None)
        assert chunk_size_for(N, 3, None, K=10**8) == by_bytes  # large: unchanged
        floor = -(-MIN_CHUNK_CONTACTS // N)
        for K in (10, 5 * floor, 3 * TARGET_CHUNKS * floor, 10 * by_bytes):
            size = chunk_size_for(N, 3, None, K=K)
            assert floor <= size <= by_bytes or size == by_bytes < floor
            n_chunks = -(-K // size)
            if K >= TARGET_CHUNKS * floor:  # enough work for TARGET_CHUNKS
                assert n_chunks >= TARGET_CHUNKS - 1
            if K <= TARGET_CHUNKS * by_bytes:  # and not more than needed
                assert n_chunks <= TARGET_CHUNKS
        assert chunk_size_for(N, 3, 100, K=10**6) == 100  # explicit: as given


class _RecordingArray:
    """An array-like that records how many grasps each read touches."""

    def __init__(self, a):
        self._a = a
        self.shape = a.shape
        self.reads = []

    def __getitem__(self, key):
        out = self._a[key]
        self.reads.append(out.shape[0])
        return out


def test_driver_reads_and_builds_one_chunk_at_a_time(monkeypatch):
    rng = np.random.default_rng(13)
    K, cs = 1000, 128
    P, Nrm = random_grasps(rng, K, 3, 3)
    mu = rng.uniform(0.2, 0.8, (K, 3))
    sizes = []
    real = chunks.solve_dstar_blocks

    def spy(G, *args, **kwargs):
        sizes.append(G.shape[0])
        return real(G, *args, **kwargs)

    monkeypatch.setattr(chunks, "solve_dstar_blocks", spy)
    arrays = [_RecordingArray(a) for a in (P, Nrm, mu)]
    res = batch_force_closure(arrays[0], arrays[1], mu=arrays[2], chunk_size=cs)
    assert max(sizes) <= cs and sum(sizes) == K
    for a in arrays:
        assert max(a.reads) <= cs and sum(a.reads) == K
    direct = batch_force_closure(P, Nrm, mu=mu, chunk_size=cs)
    np.testing.assert_array_equal(res.d_star, direct.d_star)


def test_progress_bar_and_missing_tqdm(monkeypatch, capsys):
    rng = np.random.default_rng(14)
    P, Nrm = random_grasps(rng, 50, 3, 3)
    pytest.importorskip("tqdm")
    res = batch_force_closure(P, Nrm, mu=0.5, chunk_size=10, progress=True)
    assert "50/50" in capsys.readouterr().err
    assert len(res) == 50
    monkeypatch.setitem(sys.modules, "tqdm", None)
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    with pytest.raises(InvalidOptionError, match="needs the optional package tqdm"):
        batch_force_closure(P, Nrm, mu=0.5, progress=True)


def test_result_accessors_and_text():
    rng = np.random.default_rng(15)
    P, Nrm = random_grasps(rng, 30, 3, 3)
    res = batch_force_closure(P, Nrm, mu=0.5, metrics=("isotropy",))
    assert res["d_star"] is res.d_star and res["isotropy"] is res.metrics["isotropy"]
    with pytest.raises(KeyError, match="available"):
        res["nope"]
    d = res.to_dict()
    assert d["kind"] == "force" and len(d["d_star"]) == 30
    text = str(res)
    assert "force closure of 30 grasps" in text and "isotropy" in text
    np.testing.assert_allclose(res.margin, (res.d_star - res.tol) / res.tol)
    with pytest.raises(AttributeError):
        res.tol = 1.0
    with pytest.raises(ValueError, match="read-only"):
        res.d_star[0] = 1.0


def test_iter_batch_closure_is_lazy_and_matches_one_call():
    rng = np.random.default_rng(16)
    P, Nrm = random_grasps(rng, 90, 3, 3)
    mu = rng.uniform(0.2, 0.8, (90, 3))
    produced = []

    def chunks():
        for start in range(0, 90, 30):
            produced.append(start)
            sl = slice(start, start + 30)
            yield {"positions": P[sl], "normals": Nrm[sl], "mu": mu[sl]}

    stream = iter_batch_closure(chunks(), chunk_size=16)
    first = next(stream)
    assert produced == [0] and len(first) == 30
    parts = [first, *stream]
    assert produced == [0, 30, 60]
    whole = batch_force_closure(P, Nrm, mu=mu)
    np.testing.assert_allclose(
        np.concatenate([r.d_star for r in parts]), whole.d_star, atol=1e-12
    )
    form = list(
        iter_batch_closure([(P[:50], Nrm[:50]), (P[50:], Nrm[50:])], kind="form")
    )
    np.testing.assert_allclose(
        np.concatenate([r.d_star for r in form]),
        batch_form_closure(P, Nrm).d_star,
        atol=1e-12,
    )
    with pytest.raises(InvalidOptionError, match="need mu"):
        next(iter_batch_closure([(P, Nrm)]))


def test_missing_tqdm_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)  # import fails
    P, Nrm = random_grasps(np.random.default_rng(0), 3, 3, 3)
    with pytest.raises(
        InvalidOptionError, match=r'pip install "drakegrasp\[progress\]"'
    ):
        batch_force_closure(P, Nrm, mu=0.5, progress=True)


def test_soft_fingers_need_torsional_friction_explicit_zero_acts_hard():
    P, Nrm = random_grasps(np.random.default_rng(1), 6, 4, 3)
    with pytest.raises(InvalidContactError, match="needs torsional_friction"):
        batch_force_closure(P, Nrm, mu=0.5, contact_model="soft_finger")
    soft0 = batch_force_closure(
        P, Nrm, mu=0.5, contact_model="soft_finger", torsional_friction=0
    )
    hard = batch_force_closure(P, Nrm, mu=0.5)
    np.testing.assert_array_equal(soft0.is_closure, hard.is_closure)
    np.testing.assert_allclose(soft0.d_star, hard.d_star, atol=1e-9)


@pytest.mark.parametrize("workers", [True, False, np.bool_(True), 1.0, "1"])
def test_workers_must_be_a_count(grasps, workers):
    # workers=True ran as one worker: a bool is not a count
    P, Nrm = grasps
    with pytest.raises(InvalidOptionError, match="workers"):
        batch_force_closure(P, Nrm, mu=0.5, workers=workers)


def _structured_cases(P):
    """(what, structured value) pairs of the grasps' points ``P`` (K, N, 3)."""
    K, N, _ = P.shape
    xyz = np.zeros((K, N), dtype=[("x", float), ("y", float), ("z", float)])
    xyz["x"], xyz["y"], xyz["z"] = P[..., 0], P[..., 1], P[..., 2]
    one = np.zeros(P.shape, dtype=[("x", float)])
    one["x"] = P
    return [
        ("fields x, y, z", xyz),
        ("one field", one),
        ("record array", xyz.view(np.recarray)),
        ("np.rec", np.rec.fromarrays([P[..., 0], P[..., 1], P[..., 2]], names="x,y,z")),
        ("list of grasps", list(xyz)),
        ("ragged list", [xyz[0], xyz[1, :2]]),
    ]


@pytest.mark.parametrize("arg", ["positions", "normals"])
@pytest.mark.parametrize("call", ["force", "form", "epsilon"])
def test_a_structured_array_is_named_and_refused(grasps, arg, call):
    from drakegrasp.batch import batch_epsilon_l1

    P, Nrm = grasps
    for what, bad in _structured_cases(P if arg == "positions" else Nrm):
        ragged = what == "ragged list"
        good = P if arg == "normals" else Nrm
        if ragged:
            good = [good[0], good[1, :2]]
        elif what == "list of grasps":
            good = list(good)
        args = (bad, good) if arg == "positions" else (good, bad)
        with pytest.raises(InvalidContactError) as err:
            if call == "force":
                batch_force_closure(*args, mu=0.5)
            elif call == "form":
                batch_form_closure(*args)
            else:
                batch_epsilon_l1(*args, mu=0.5)
        text = str(err.value)
        assert text.startswith(arg), (what, text)
        assert "must be a plain float array, not a structured" in text, (what, text)
