"""Record the batch engine's results on seeded grasps, to compare two trees bit for bit.

Usage::

    NUMBA_CACHE_DIR=$(mktemp -d) PYTHONPATH=TREE python benchmarks/check_bitwise.py \
        record OUT.npz [--grasps 3000]
    PYTHONPATH=TREE python benchmarks/check_bitwise.py single OUT.npz [--grasps 150]
    python benchmarks/check_bitwise.py compare A.npz B.npz
    PYTHONPATH=TREE python benchmarks/check_bitwise.py plan [--num 1500] [--seed 0]
    PYTHONPATH=TREE python benchmarks/check_bitwise.py plan-cloud [--num 150] [--seed 0]

``record`` runs, in this process, ``batch_force_closure`` (d*, rank, verdict,
margin, converged, normal certificate) and ``batch_epsilon_l1`` (ε) on
``--grasps`` seeded grasps for each configuration: spatial hard fingers at
N = 2, 3, 4, 12, 24, planar hard fingers at N = 2, 3, 4, 12, soft fingers at
N = 2, 3, 4, 12, frictionless contacts (form closure, LP1) at N = 4, 7, 12, 24,
with a per-grasp μ and a per-contact μ on the hard fingers.  Run it once per
tree, each in a fresh process with an empty ``NUMBA_CACHE_DIR`` (so each tree's
kernels are compiled from its own sources), then ``compare`` prints, per array,
the number of elements that differ in any bit (NaNs equal where both are NaN).

``single`` decides ``--grasps`` seeded single grasps of 2-6 contacts with the
Drake programs (``force_closure``, ``form_closure``: the route of
``analyze_grasp``) and records d* and the solver status, for ``compare``.

``plan`` runs ``plan_grasps`` with the WSG-50 on the seven objects of
``bench_plan.py`` (``--num`` samples, ``--seed``, one core) and prints, per
object, a SHA-256 of the ranked candidates (in rank order: sample, ``X_WH``,
``q_hand``, verdict, rank, d*, ε, robustness, weight capacity α, squeeze
needed and score, each as its exact bytes), the candidate count and the
rejections by reason; two trees agree bit for bit when the hashes do.

``plan-cloud`` does the same for the multi-finger cloud route: the Allegro
hand (thumb opposed) on the full and the one-sided cloud of the soup can
(3,000 points, seed 0, as ``bench_cloud_hold.py`` samples them), planned with
the can's mass; its hash adds each candidate's torque needed and contacts
(positions and normals) and prints the seconds each plan took.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import sys  # noqa: E402

import numpy as np  # noqa: E402


def configurations():
    """(name, N, d, model, mu kind, nu) of each configuration."""
    for N in (2, 3, 4, 12, 24):
        yield f"spatial_hard_N{N}", N, 3, "hard_finger", "grasp", None
    yield "spatial_hard_N3_mu_contact", 3, 3, "hard_finger", "contact", None
    yield "spatial_hard_N4_mu_scalar", 4, 3, "hard_finger", "scalar", None
    for N in (2, 3, 4, 12):
        yield f"planar_hard_N{N}", N, 2, "hard_finger", "grasp", None
        yield f"soft_N{N}", N, 3, "soft_finger", "grasp", 0.05
    for N in (4, 7, 12, 24):
        yield f"frictionless_N{N}", N, 3, "frictionless", "zero", None


def grasps(K, N, d, seed):
    rng = np.random.default_rng(seed)
    p = rng.normal(size=(K, N, d))
    p /= np.linalg.norm(p, axis=-1, keepdims=True)
    n = -p + 0.35 * rng.normal(size=(K, N, d))
    # Rank-deficient and degenerate grasps: contacts on a line, repeated contacts.
    m = K // 20
    p[:m] = p[:m, :1] * np.linspace(0.5, 1.5, N)[None, :, None]
    n[:m] = -p[:m]
    p[m : 2 * m, -1] = p[m : 2 * m, 0]
    n[m : 2 * m, -1] = n[m : 2 * m, 0]
    return p, n


def record(out: str, K: int) -> None:
    from drakegrasp.batch import batch_epsilon_l1, batch_force_closure

    arrays = {}
    for i, (name, N, d, model, mu_kind, nu) in enumerate(configurations()):
        p, n = grasps(K, N, d, seed=1000 + i)
        rng = np.random.default_rng(2000 + i)
        mu = {
            "grasp": rng.uniform(0.1, 1.0, K),
            "contact": rng.uniform(0.1, 1.0, (K, N)),
            "scalar": 0.5,
            "zero": 0.0,
        }[mu_kind]
        opts = {"contact_model": model, "torsional_friction": nu, "workers": 1}
        r = batch_force_closure(p, n, mu=mu, **opts)
        for key in ("d_star", "rank", "is_closure", "margin", "converged"):
            arrays[f"{name}/{key}"] = np.asarray(getattr(r, key))
        if r.normal_certificate is not None:
            arrays[f"{name}/normal_certificate"] = np.asarray(r.normal_certificate)
        arrays[f"{name}/epsilon"] = np.asarray(batch_epsilon_l1(p, n, mu=mu, **opts))
        print(name, int(r.is_closure.sum()), "closed of", K, flush=True)
    np.savez(out, **arrays)


def single(out: str, K: int) -> None:
    """d* and status of ``K`` seeded single grasps through the Drake programs.

    Grasps of 2 to 6 contacts, cycling hard, soft and frictionless fingers
    (every fifth planar, hard or frictionless), each decided by
    ``force_closure`` (``form_closure`` when frictionless): the route of
    ``analyze_grasp``, with its row space, equilibration and Clp.
    """
    import drakegrasp as dg

    rng = np.random.default_rng(0)
    d_star, status = np.full(K, np.nan), np.zeros(K, dtype="U40")
    for i in range(K):
        N, planar = int(rng.integers(2, 7)), i % 5 == 4
        d = 2 if planar else 3
        P = rng.normal(size=(N, d)) * 0.05
        Nr = -P / np.linalg.norm(P, axis=1, keepdims=True)
        Nr += 0.3 * rng.normal(size=(N, d))
        Nr /= np.linalg.norm(Nr, axis=1, keepdims=True)
        models = ("hard_finger", "frictionless") if planar else (
            "hard_finger", "soft_finger", "frictionless")  # fmt: skip
        model = models[i % len(models)]
        kw = {} if model == "frictionless" else {"mu": 0.5}
        if model == "soft_finger":
            kw["torsional_friction"] = 0.01
        contacts = [
            dg.Contact(p, q, contact_model=model, **kw)
            for p, q in zip(P, Nr, strict=True)
        ]
        g = dg.Grasp(contacts, reference_point=np.zeros(d))
        r = dg.form_closure(g) if model == "frictionless" else dg.force_closure(g)
        d_star[i], status[i] = r.d_star, str(r.status)
    print(f"{K} grasps, {int(np.sum(d_star > 1e-6))} with d* > 1e-6", flush=True)
    np.savez(out, **{"single/d_star": d_star, "single/status": status})


def compare(a: str, b: str) -> int:
    A, B = np.load(a), np.load(b)
    bad = 0
    if sorted(A.files) != sorted(B.files):
        print("different arrays:", sorted(set(A.files) ^ set(B.files)))
        bad += 1
    for key in sorted(set(A.files) & set(B.files)):
        x, y = A[key], B[key]
        if x.shape != y.shape or x.dtype != y.dtype:
            print(f"{key}: shape/dtype {x.shape} {x.dtype} vs {y.shape} {y.dtype}")
            bad += 1
            continue
        if x.dtype.kind == "f":
            bits = x.view(np.uint64) == y.view(np.uint64)
            same = bits | (np.isnan(x) & np.isnan(y))
        else:
            same = x == y
        diff = int((~same).sum())
        bad += diff > 0
        print(f"{key:45s} {x.size:6d} values, {diff} differ")
    print("BITWISE EQUAL" if bad == 0 else f"{bad} arrays differ")
    return 1 if bad else 0


def plan_hashes(num: int, seed: int) -> None:
    import hashlib

    from bench_plan import OWN, YCB, drake_models, object_url

    from drakegrasp.planning import plan_grasps, planning_scene

    models = drake_models()
    if models is None:
        raise SystemExit("drake_models not found (set DRAKEGRASP_DRAKE_MODELS)")
    for name in (*YCB, *OWN):
        scene = planning_scene(object_url(name), models_dir=models)
        result = plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=num, mu=1.0, seed=seed, workers=1,
        )  # fmt: skip
        h = hashlib.sha256()
        for c in result:
            h.update(np.int64(c.sample).tobytes())
            h.update(c.X_WH.GetAsMatrix34().tobytes())
            h.update(np.asarray(c.q_hand, float).tobytes())
            h.update(np.array([c.is_closure, c.rank], np.int64).tobytes())
            values = (
                c.d_star, c.epsilon, c.robustness, c.weight_capacity,
                c.squeeze_needed, c.score,
            )  # fmt: skip
            h.update(np.array(values, float).tobytes())
        reasons = ", ".join(f"{k} {v}" for k, v in sorted(result.rejections.items()))
        print(f"{name:<20} {h.hexdigest()[:16]} {len(result):5d} candidates; {reasons}")


def _hash_candidate(h, c) -> None:
    h.update(np.int64(c.sample).tobytes())
    h.update(c.X_WH.GetAsMatrix34().tobytes())
    h.update(np.asarray(c.q_hand, float).tobytes())
    h.update(np.array([c.is_closure, c.rank], np.int64).tobytes())
    torque = np.nan if c.torque_needed is None else c.torque_needed
    values = (c.d_star, c.epsilon, c.robustness, c.score, torque)
    h.update(np.array(values, float).tobytes())
    for contact in c.grasp.contacts:
        h.update(np.asarray(contact.position, float).tobytes())
        h.update(np.asarray(contact.normal, float).tobytes())


def plan_cloud_hashes(num: int, seed: int) -> None:
    import hashlib

    from bench_cloud_hold import CAN, VIEW, allegro_scene, plan_cloud, sample_cloud
    from bench_plan import drake_models

    models = drake_models()
    if models is None:
        raise SystemExit("drake_models not found (set DRAKEGRASP_DRAKE_MODELS)")
    full, hand = allegro_scene(models, CAN), allegro_scene(models)
    mass = full.object_body.get_mass(full.plant.GetMyContextFromRoot(full.context))
    for name, view in (("full", None), ("one-sided", VIEW)):
        points, normals = sample_cloud(full, 3000, 0, view)
        result, seconds = plan_cloud(
            hand, points, normals, view, num=num, seed=seed, mass=mass
        )
        h = hashlib.sha256()
        for c in result:
            _hash_candidate(h, c)
        reasons = ", ".join(f"{k} {v}" for k, v in sorted(result.rejections.items()))
        print(
            f"{name:<10} {h.hexdigest()[:16]} {len(result):4d} candidates "
            f"in {seconds:5.1f} s; {reasons}"
        )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("record")
    r.add_argument("out")
    r.add_argument("--grasps", type=int, default=3000)
    c = sub.add_parser("compare")
    c.add_argument("a")
    c.add_argument("b")
    si = sub.add_parser("single")
    si.add_argument("out")
    si.add_argument("--grasps", type=int, default=150)
    pl = sub.add_parser("plan")
    pl.add_argument("--num", type=int, default=1500)
    pl.add_argument("--seed", type=int, default=0)
    pc = sub.add_parser("plan-cloud")
    pc.add_argument("--num", type=int, default=150)
    pc.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    if args.cmd == "plan-cloud":
        plan_cloud_hashes(args.num, args.seed)
        return 0
    if args.cmd == "plan":
        plan_hashes(args.num, args.seed)
        return 0
    if args.cmd == "single":
        single(args.out, args.grasps)
        return 0
    if args.cmd == "record":
        record(args.out, args.grasps)
        return 0
    return compare(args.a, args.b)


if __name__ == "__main__":
    sys.exit(main())
