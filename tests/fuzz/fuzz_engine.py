"""Generated hostile inputs for the batch engine: dtypes, layouts, values, options.

Each case is a random batch of ``K`` grasps (0..5 grasps of 1..5 contacts,
planar or spatial) with one hostile change: a dtype (float32/16, integers,
long double, complex, strings, objects, bools), a memory layout (Fortran,
non-contiguous, read-only, negative strides, zero strides, memory-mapped), a
value (NaN, ±inf, 1e300, 1e-300, zero or huge normals), a friction array of
the wrong shape or kind, a wrong shape, or a hostile option.  The call runs in
the sandbox (a crash of compiled code or a hang is a row, not the end of the
run).

Independent routes for an answer:

* the verdict of every grasp against ``fuzz_oracles.closure_verdict``, an LP
  written with scipy on the generator form of the cones (hard fingers and
  frictionless contacts; no verdict where the oracle calls it borderline);
* the engine's own answer for the same numbers as a C-contiguous float64
  array, bit for bit: a dtype or layout may change how the numbers arrive,
  never the result.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import fuzz_oracles as oracle
import numpy as np
from fuzz_cases import Case
from hostile import LAYOUTS, array, opaque, pick
from sandbox import Sandbox

FLOATS = ("<f8", "<f4", "<f2", "<i8", "<i4", np.dtype(np.longdouble).str, ">f8")

# option -> (valid values, hostile values); valid ones must be answered
OPTIONS = {
    "num_generators": ((3, 4, 8, 12), (2, 0, -1, 3.5, "8", None, True, math.nan, 1j)),
    "tol": ((1e-6, 1e-8), (math.nan, -1.0, math.inf, "x", None, 1j, True)),
    "rank_tol": ((1e-9, 1e-7), (math.nan, -1.0, math.inf, "x", 1j, True, 2.0)),
    "chunk_size": ((None, 1, 2, 1000), (0, -1, 1.5, "2", True, math.nan, 1j)),
    "workers": ((1,), (0, -1, 1.5, "2", True, math.nan, 1j)),
    "kernel": (("auto", "numpy", "numba"), ("fast", None, 1, "")),
    "metrics": (
        ((), ("sigma_min",), ("isotropy", "ellipsoid_volume")),
        (("bogus",), [None], 5, [1j]),
    ),
    "progress": ((False,), ("yes", 1, None, math.nan)),
    "contact_model": (("hard_finger", "frictionless"), ("soft", None, 1, "")),
}


def _geometry_option(rng, K, N, d):
    """(option, value, expect, soft): reference points, lengths, torsion.

    Force closure does not depend on the reference point nor, for hard
    fingers, on the characteristic length: a valid value must give the
    oracle's verdict.  Soft fingers get no oracle verdict (bitwise only).
    """
    option = pick(rng, ("reference_points", "characteristic_lengths", "torsion"))
    good = rng.random() < 0.5
    if option == "reference_points":
        if good:
            return (
                option,
                rng.normal(size=(K, d) if rng.random() < 0.5 else d),
                "answer",
                False,
            )
        bad = (np.full(d, np.nan), np.zeros(d + 1), np.zeros((K + 1, d)), "x", 1j)
        return option, pick(rng, bad), "refuse", False
    if option == "characteristic_lengths":
        if good:
            return (
                option,
                pick(rng, (0.5, 1e-3, rng.uniform(0.1, 2, K))),
                "answer",
                False,
            )
        bad = (-1.0, 0.0, np.nan, np.inf, np.full(K + 1, 0.5), "1", True)
        return "characteristic_lengths", pick(rng, bad), "refuse", False
    if d == 2:  # soft fingers are spatial only
        return "torsional_friction", 0.1, "refuse", True
    if good:
        return (
            "torsional_friction",
            pick(rng, (0.1, 0.0, rng.uniform(0, 0.5, (K, N)))),
            "answer",
            True,
        )
    bad = (np.nan, -0.1, "x", 1j, np.full((K, N + 1), 0.1))
    return "torsional_friction", pick(rng, bad), "refuse", True


def _grasps(rng, K, N, d):
    """Random positions and inward normals, (K, N, d) each."""
    P = rng.normal(size=(K, N, d))
    P /= np.linalg.norm(P, axis=2, keepdims=True)
    Nrm = -P + 0.6 * rng.normal(size=(K, N, d))
    return P, Nrm


def engine_call(kind, positions, normals, mu, options):
    """Worker side: the engine's answer, and its answer for float64 C copies."""
    import drakegrasp as dg

    def run(P, Nrm, mu):
        if kind == "form":
            return dg.batch_form_closure(P, Nrm, **options)
        return dg.batch_force_closure(P, Nrm, mu=mu, **options)

    r = run(positions, normals, mu)
    out = {
        "is_closure": np.asarray(r.is_closure).tolist(),
        "d_star": np.asarray(r.d_star, dtype=float).tolist(),
        "rank": np.asarray(r.rank).tolist(),
        "canonical": None,
    }
    try:
        P = np.array(positions, dtype=float, order="C")
        Nrm = np.array(normals, dtype=float, order="C")
        m = np.array(mu, dtype=float, order="C") if isinstance(mu, np.ndarray) else mu
    except (TypeError, ValueError):
        return out
    c = run(P, Nrm, m)
    out["canonical"] = {
        "is_closure": np.asarray(c.is_closure).tolist(),
        "d_star": np.asarray(c.d_star, dtype=float).tolist(),
        "rank": np.asarray(c.rank).tolist(),
    }
    return out


def _same(a, b) -> bool:
    return (
        a["is_closure"] == b["is_closure"]
        and a["rank"] == b["rank"]
        and all(
            (x == y) or (math.isnan(x) and math.isnan(y))
            for x, y in zip(a["d_star"], b["d_star"], strict=True)
        )
    )


def _checker(P, Nrm, mus, K, *, verdicts: bool, n_g=8):
    """The answer agrees with scipy's LP per grasp and bitwise with float64 C."""
    truth = []
    if verdicts:
        for k in range(K):
            v = oracle.closure_verdict(P[k], Nrm[k], mus[k], n_g=n_g)
            truth.append(None if v is None else v[0])

    def check(out):
        if len(out["is_closure"]) != K:
            return False
        if out["canonical"] is not None and not _same(out, out["canonical"]):
            return False
        return not truth or all(
            t is None or t == got
            for t, got in zip(truth, out["is_closure"], strict=True)
        )

    return check


def engine_cases(sandbox: Sandbox, seed: int = 214, count: int = 300) -> Iterator[Case]:
    """Generated batch-engine cases (see the module docstring)."""
    rng = np.random.default_rng(seed)
    for i in range(count):
        K = int(rng.integers(0, 6))
        N = int(rng.integers(2, 6))
        d = 3 if rng.random() < 0.7 else 2
        kind = "form" if rng.random() < 0.25 else "force"
        P, Nrm = _grasps(rng, K, N, d)
        mu_value = float(rng.uniform(0.1, 0.9))
        mu = mu_value
        mus = np.full((K, N), 0.0 if kind == "form" else mu_value)
        options = {"workers": 1}
        what = ("layout", "dtype", "value", "mu", "shape", "option", "geometry")[i % 7]
        expect, name = "answer", what
        p_in, n_in = P, Nrm
        if what == "layout":
            layout = pick(rng, LAYOUTS)
            dtype = pick(rng, ("<f8", "<f4", ">f8"))
            target = int(rng.integers(3))
            if target == 2 and kind == "force":
                mu_arr = rng.uniform(0.1, 0.9, size=(K, N))
                mus = mu_arr
                mu = array(mu_arr, dtype=dtype, layout=layout)
            elif target == 1:
                n_in = array(Nrm, dtype=dtype, layout=layout)
            else:
                if layout == "broadcast" and K:
                    P = np.repeat(P[:1], K, axis=0)
                    Nrm = np.repeat(Nrm[:1], K, axis=0)
                    n_in = Nrm
                p_in = array(P, dtype=dtype, layout=layout)
            if dtype == "<f4":  # the float32 numbers are the grasp
                if target == 0:
                    P = P.astype(np.float32).astype(float)
                elif target == 1:
                    Nrm = Nrm.astype(np.float32).astype(float)
                else:
                    mus = mus.astype(np.float32).astype(float)
            name = (
                f"layout {layout} {dtype} on {('positions', 'normals', 'mu')[target]}"
            )
        elif what == "dtype":
            dtype = pick(rng, (*FLOATS, "<c16", "<U8", "O", "|b1", "<m8"))
            if dtype in FLOATS:
                if dtype[1] == "i":  # integer contacts: a lattice grasp
                    P = np.rint(3 * P)
                    Nrm = np.rint(3 * Nrm)
                    Nrm[np.all(Nrm == 0, axis=2)] = 1.0
                P = P.astype(dtype).astype(float)
                Nrm = Nrm.astype(dtype).astype(float)
                p_in = array(P, dtype=dtype)
                n_in = array(Nrm, dtype=dtype)
            elif dtype == "<c16":
                p_in = array(P + 1j * rng.normal(size=P.shape), dtype=dtype)
                expect = "refuse" if K else "either"
            elif dtype == "O":
                objs = P.astype(object)
                if K:
                    objs[int(rng.integers(K)), 0, 0] = pick(rng, (None, "x", opaque()))
                p_in = array(objs, dtype="O")
                expect = "refuse" if K else "either"
            else:
                p_in = array(P.astype(dtype) if dtype != "<U8" else P.astype(str))
                expect = "refuse" if K else "either"
            name = f"dtype {dtype}"
        elif what == "value":
            where = int(rng.integers(2))
            value = pick(rng, (math.nan, math.inf, -math.inf, 1e300, 1e-300, 0.0))
            if K == 0:
                expect = "either"
            elif where == 0 and value in (1e300, 1e-300, 0.0):
                # a scaled grasp (all positions) is the same grasp
                P = P * value if value else P
                p_in = P
                expect = "either"
            else:
                A = (P if where == 0 else Nrm).copy()
                k, j = int(rng.integers(K)), int(rng.integers(N))
                if value == 0.0:
                    A[k, j] = 0.0
                else:
                    A[k, j, int(rng.integers(d))] = value
                refuse = not math.isfinite(value) or (where == 1 and value == 0.0)
                if where == 0:
                    P, p_in = A, A
                else:
                    Nrm, n_in = A, A
                expect = "refuse" if refuse else "either"
            name = f"{value!r} in {('positions', 'normals')[where]}"
        elif what == "mu":
            if kind == "form":
                kind = "force"
            choice = int(rng.integers(9))
            good = {
                0: (mu_value, np.full((K, N), mu_value)),
                # (K,) is one value per grasp unless K == N (documented as
                # ambiguous there): (K, 1) says so
                1: (
                    np.full(K if K != N else (K, 1), mu_value),
                    np.full((K, N), mu_value),
                ),
                2: (np.zeros((K, N)), np.zeros((K, N))),
            }
            if choice in good:
                mu, mus = good[choice]
            else:
                bad = (math.nan, -0.5, 1e13, 0.5 + 0.1j, "0.5", np.full((K + 1,), 0.5))
                mu = bad[choice - 3]
                expect = "refuse"
            name = f"mu {mu!r}"[:60]
        elif what == "shape":
            choice = int(rng.integers(6))
            if choice == 2 and d == 2:  # (K, N, 3) is a valid spatial batch
                choice = 0
            if choice == 0:
                p_in = P.reshape(K, N * d)
            elif choice == 1:
                n_in = Nrm[:, :-1] if N > 1 else Nrm[:, :, :1]
            elif choice == 2:
                p_in = np.concatenate([P, P[..., :1]], axis=2)
                n_in = np.concatenate([Nrm, Nrm[..., :1]], axis=2)
            elif choice == 3:
                p_in, n_in = P[:, :0], Nrm[:, :0]
            elif choice == 4:
                p_in, n_in = P[..., :1], Nrm[..., :1]
            else:
                p_in = P[None]
            expect = "refuse" if K or choice == 5 else "either"
            name = f"shape {np.shape(p_in)} / {np.shape(n_in)}"
        elif what == "geometry":
            option, value, expect, soft = _geometry_option(rng, K, N, d)
            if kind == "form" and option == "torsional_friction":
                kind, mus = "force", np.full((K, N), mu_value)
            if soft:
                options["contact_model"] = "soft_finger"
            options[option] = value
            if K == 0 and expect == "refuse":
                expect = "either"
            name = f"{option}={value!r}"[:80]
        else:
            option = pick(rng, tuple(OPTIONS))
            good, bad = OPTIONS[option]
            if rng.random() < 0.4:
                value = pick(rng, good)
            else:
                value, expect = pick(rng, bad), "refuse"
            if option in ("contact_model", "num_generators"):  # force closure's options
                if kind == "form":
                    kind, mus = "force", np.full((K, N), mu_value)
                if value == "frictionless":
                    mus = np.zeros((K, N))
            options[option] = value
            if K == 0 and expect == "refuse":
                expect = "either"
            name = f"{option}={value!r}"
        verdicts = (
            expect != "refuse"
            and options.get("tol", 1e-6) == 1e-6
            and options.get("contact_model")
            != "soft_finger"  # no soft cones in the oracle
        )
        n_g = options.get("num_generators", 8)
        check = _checker(P, Nrm, mus, K, verdicts=verdicts, n_g=n_g)
        yield Case(
            "batch engine",
            f"{kind} K={K} N={N} d={d} {name}#{i}",
            lambda a=(kind, p_in, n_in, mu, options): sandbox.call(
                "fuzz_engine:engine_call", *a
            ),
            expect,
            check if expect != "refuse" else None,
        )
