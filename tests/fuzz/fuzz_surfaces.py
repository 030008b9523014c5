"""Generated hostile inputs for the surfaces of issue 21, part 3.

Families (all seeded, so the counts are reproducible):

``certificates``
    Real witnesses of random grasps, forged (NaN/inf/huge entries at random
    places), rescaled (the check is scale invariant: the rescaled witness must
    get the verdict of the original), checked on another random grasp, or with a
    random ``tol``.  Independent routes: ``G_nᵀ v`` evaluated here for escape
    twists; the original witness's own check for rescaled ones.
``second order``
    Random surface curvatures and principal directions drawn from pools of
    valid and hostile values (refused exactly when a value is hostile), the
    Hessian of a rescaled direction against that of its unit direction, and
    ``first_order`` results of other random grasps (a "yes" at first order must
    agree with scipy's LP1 of the grasp).
``scene YAML``
    Random scene files built from hostile pieces (file URLs with hosts, tags on
    directives, duplicate keys, quoted multi-line values, include graphs with
    loops and fan-out, aliases in includes, YAML 1.1/1.2 numbers, control
    characters), each loaded in a sandboxed worker (time and memory limits: a
    crash or a hang is counted, not suffered).  A scene that loads must not hold
    the outside model and must read the numbers as YAML 1.2.
``numerics``
    Single-grasp ``force_closure`` at random scales 1e-307..1e19 m against the
    same grasp at 1 m; ``patch_polygon`` with random and undefined normals.
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Iterator
from pathlib import Path

import numpy as np
from fuzz_cases import Case
from sandbox import Sandbox
from scipy.optimize import linprog

import drakegrasp as dg
from drakegrasp import ContactCurvature, SurfaceCurvature
from drakegrasp.core.curvature import contact_hessian

# ------------------------------------------------------------ random grasps


def random_grasp(rng: np.random.Generator, *, n: int | None = None, planar=None):
    """A random grasp of 2..6 contacts, spatial or planar, of a random model."""
    planar = bool(rng.random() < 0.3) if planar is None else planar
    d = 2 if planar else 3
    n = int(rng.integers(2, 7)) if n is None else n
    models = ["frictionless", "hard_finger"] + ([] if planar else ["soft_finger"])
    model = models[int(rng.integers(len(models)))]
    mu = float(rng.uniform(0.05, 0.9))
    contacts = []
    for _ in range(n):
        p = rng.normal(size=d)
        p /= np.linalg.norm(p)
        normal = -p + 0.6 * rng.normal(size=d)
        contacts.append(
            dg.Contact(p, normal, mu=mu, contact_model=model, torsional_friction=0.1)
        )
    return dg.Grasp(contacts, reference_point=0.3 * rng.normal(size=d))


def lp1(grasp) -> bool:
    """scipy's LP1: G_n of full rank and strictly positive balancing f_n."""
    G_n = dg.normal_grasp_matrix(grasp)
    m, n = G_n.shape
    if np.linalg.matrix_rank(G_n) < m:
        return False
    res = linprog(
        np.r_[np.zeros(n), -1.0],
        A_ub=np.c_[-np.eye(n), np.ones(n)],
        b_ub=np.zeros(n),
        A_eq=np.vstack([np.c_[G_n, np.zeros(m)], np.r_[np.ones(n), 0.0]]),
        b_eq=np.r_[np.zeros(m), n],
        bounds=[(0, None)] * n + [(None, 1)],
        method="highs",
    )
    return res.status == 0 and -res.fun > 1e-6


# ----------------------------------------------------------- certificates

_FORGERIES = (math.nan, math.inf, -math.inf, 1e154, 1e300, -1e308)


def _array_fields(cert) -> list[str]:
    names = []
    for name in ("direction", "separating_twist"):
        if getattr(cert, name) is not None:
            names.append(name)
    if cert.contact_forces is not None:
        names.append("contact_forces")
    return names


def _forged(cert, rng):
    """The certificate with one entry of one array replaced by a hostile value."""
    import dataclasses

    name = rng.choice(_array_fields(cert))
    value = _FORGERIES[int(rng.integers(len(_FORGERIES)))]
    if name == "contact_forces":
        forces = [np.array(f, dtype=float) for f in cert.contact_forces]
        i = int(rng.integers(len(forces)))
        forces[i][int(rng.integers(len(forces[i])))] = value
        return dataclasses.replace(cert, contact_forces=tuple(forces)), value
    a = np.array(getattr(cert, name), dtype=float)
    a[int(rng.integers(len(a)))] = value
    return dataclasses.replace(cert, **{name: a}), value


def _scaled(cert, s):
    import dataclasses

    changes = {}
    for name in ("direction", "separating_twist"):
        if getattr(cert, name) is not None:
            changes[name] = s * np.asarray(getattr(cert, name))
    for name in ("null_basis", "separating_basis"):
        changes[name] = s * np.asarray(getattr(cert, name))
    if cert.contact_forces is not None:
        changes["contact_forces"] = tuple(
            s * np.asarray(f) for f in cert.contact_forces
        )
    return dataclasses.replace(cert, **changes)


def _escape_truth(grasp, cert) -> bool:
    """Whether an escape twist (one-sided) is a witness: G_nᵀ v >= 0, by hand."""
    v = np.asarray(cert.direction, dtype=float)
    if not np.all(np.isfinite(v)) or not np.any(v):
        return False
    v = v / np.max(np.abs(v))
    G_n = dg.normal_grasp_matrix(grasp)
    rates = G_n.T @ v / (np.linalg.norm(G_n, axis=0) * np.linalg.norm(v))
    return bool(rates.min() >= -1e-7)


def certificate_cases(seed: int = 210, count: int = 300) -> Iterator[Case]:
    """Forged, rescaled and foreign witnesses; bad tolerances."""
    rng = np.random.default_rng(seed)
    made = 0
    while made < count:
        g = random_grasp(rng)
        r = (dg.form_closure if rng.random() < 0.4 else dg.force_closure)(g)
        cert = r.certificate
        if cert is None or not _array_fields(cert):
            continue
        base = cert.check(g)
        what = int(rng.integers(4))
        name = f"{cert.kind}#{made}"
        # Each case checks a witness on a grasp: (label, witness, grasp,
        # check options, expected outcome, judge of the answer).
        if what == 0:
            forged, value = _forged(cert, rng)
            if math.isfinite(value):  # a huge entry: the witness of a new vector
                judge = None
                if forged.kind == "escape twist" and not forged.two_sided:

                    def judge(c, g=g, f=forged):
                        return c.holds == _escape_truth(g, f)

                case = (f"huge {name}", forged, g, {}, "answer", judge)
            else:

                def judge(c):
                    return not c.holds and c.violation == math.inf

                case = (f"non-finite {name}", forged, g, {}, "answer", judge)
        elif what == 1:
            s = float(10.0 ** rng.uniform(-250, 250))

            def judge(c, base=base):
                return c.holds == base.holds and math.isclose(
                    c.violation, base.violation, rel_tol=1e-6, abs_tol=1e-12
                )

            case = (f"scaled {s:.1e} {name}", _scaled(cert, s), g, {}, "answer", judge)
        elif what == 2:

            def judge(c):
                return isinstance(c.holds, bool) and not math.isnan(c.violation)

            h = random_grasp(rng)
            case = (f"foreign {name}", cert, h, {}, "either", judge)
        else:
            tol = [math.inf, math.nan, 0.0, -1e-7, 1.0, 3.0, "1e-7", None, True, 1j][
                int(rng.integers(10))
            ]
            case = (f"tol={tol!r} {name}", cert, g, {"tol": tol}, "refuse", None)
        label, witness, grasp, options, expect, judge = case
        yield Case(
            "certificates",
            label,
            lambda c=witness, h=grasp, o=options: c.check(h, **o),
            expect,
            judge,
        )
        made += 1


# ------------------------------------------------------------ second order

_GOOD_K = (0.0, 1.0, -0.5, 25.0, math.inf, 1e3)
_BAD_K = (math.nan, -math.inf, 1e308, -1e200, 1 + 1j, None, "k", [1.0])
_BAD_D = ("zero", "nan", "inf", "complex", "short", "string")


def _direction(kind, n, rng):
    t = np.cross(n, rng.normal(size=3))
    t /= np.linalg.norm(t)
    if kind == "unit":
        return t
    if kind == "scaled":
        return t * float(10.0 ** rng.uniform(-300, 300))
    return {
        "zero": np.zeros(3),
        "nan": np.array([math.nan, 0.0, 1.0]),
        "inf": np.array([math.inf, 0.0, 0.0]),
        "complex": t.astype(complex) * 1j,
        "short": t[:2],
        "string": "abc",
    }[kind]


def second_order_cases(seed: int = 211, count: int = 250) -> Iterator[Case]:
    """Random curvature inputs, rescaled directions, foreign first_order results."""
    rng = np.random.default_rng(seed)
    g1 = dg.Grasp([dg.Contact([0.0, 0.0, 1.0], [0.0, 0.0, -1.0])])
    n = np.array([0.0, 0.0, -1.0])
    for i in range(count):
        what = i % 5
        if what in (0, 1, 2):
            bad_k = rng.random() < 0.4
            bad_d = rng.random() < 0.3
            pool = _BAD_K if bad_k else _GOOD_K
            k = [pool[int(rng.integers(len(pool)))], _GOOD_K[int(rng.integers(5))]]
            if bad_k:
                rng.shuffle(k)
            dkind = _BAD_D[int(rng.integers(len(_BAD_D)))] if bad_d else "scaled"
            d = _direction(dkind, n, rng)
            # the finger is a sharp point: an object sharp in some direction too
            # has no contact normal there (a documented refusal)
            sharp = any(x == math.inf for x in k if isinstance(x, float))
            expect = "refuse" if (bad_k or bad_d or sharp) else "answer"
            args = (tuple(k), d)

            def make(args=args):
                surface = SurfaceCurvature(*args)
                cc = ContactCurvature(surface, SurfaceCurvature.point())
                return contact_hessian(g1, 0, cc), surface

            def same_as_unit(out, args=args):
                H, surface = out
                unit = np.asarray(args[1], dtype=float)
                unit = unit / np.max(np.abs(unit))
                unit = unit / np.linalg.norm(unit)
                ref = contact_hessian(
                    g1,
                    0,
                    ContactCurvature(
                        SurfaceCurvature(args[0], unit), SurfaceCurvature.point()
                    ),
                )
                return np.allclose(H, ref, rtol=1e-12, atol=1e-12)

            yield Case(
                "second order",
                f"surface#{i} k={k} d={dkind}",
                make,
                expect,
                same_as_unit if expect == "answer" else None,
            )
        elif what == 3:
            bad = [None, "x", 3, SurfaceCurvature.point(planar=True)][
                int(rng.integers(4))
            ]
            yield Case(
                "second order",
                f"contact-curvature#{i}",
                lambda b=bad: ContactCurvature(b, SurfaceCurvature.flat()),
                "refuse",
            )
        else:
            N = int(rng.integers(3, 8))
            g = random_grasp(rng, n=N, planar=False)
            h = random_grasp(rng, n=N if rng.random() < 0.8 else N + 1, planar=False)
            fo = (dg.form_closure if rng.random() < 0.8 else dg.force_closure)(h)
            pts = [ContactCurvature.point_finger(SurfaceCurvature.flat())] * N

            def first_order_agrees(r, g=g):
                return r.order != 1 or lp1(g)

            yield Case(
                "second order",
                f"first_order#{i}",
                lambda g=g, pts=pts, fo=fo: dg.second_order_form_closure(
                    g, pts, first_order=fo
                ),
                "either",
                first_order_agrees,
            )


# --------------------------------------------------------------- scene YAML

_DEFAULT = None


def _default_scene() -> str:
    global _DEFAULT
    if _DEFAULT is None:
        from drakegrasp.plant.scene import DEFAULT_SCENE, scene_path

        _DEFAULT = scene_path(DEFAULT_SCENE).read_text()
    return _DEFAULT


BOX = "package://drakegrasp/objects/box.sdf"


def load_scene_summary(path: str, allow_any_file: bool) -> dict:
    """Worker side: load a scene; its model instances and section numbers."""
    scene = dg.load_scene(path, allow_any_file=allow_any_file)
    plant = scene.plant
    from pydrake.multibody.tree import ModelInstanceIndex

    names = [
        plant.GetModelInstanceName(ModelInstanceIndex(i))
        for i in range(plant.num_model_instances())
    ]
    # Freeing the hand flattens the includes first: the same models load (a
    # scene whose hand cannot be freed is refused with its reason)
    try:
        free = dg.load_scene(path, allow_any_file=allow_any_file, free_hand=True)
    except dg.GraspError:
        pass
    else:
        freed = {
            free.plant.GetModelInstanceName(ModelInstanceIndex(i))
            for i in range(free.plant.num_model_instances())
        }
        assert freed == set(names), (sorted(freed), names)
    return {
        "instances": names,
        "mu": scene.info.mu,
        "tol": scene.info.distance_tolerance,
    }


def _evil_line(url: str, tag: str = "") -> str:
    body = f"{{name: evil, file: '{url}'}}"
    return f"- add_model: {tag} {body}\n" if tag else f"- add_model: {body}\n"


def _scene_piece(kind: str, rng, root: Path, outside: Path, i: int):
    """(text, allow_any_file, expect, check) for one generated scene."""
    base = _default_scene()
    scene_dir = root / "scene"
    allow = bool(rng.random() < 0.25)
    no_evil = lambda s: "evil" not in s["instances"]  # noqa: E731

    def evil_first(line):
        """``line`` first of the directives: loaded only with ``allow_any_file``."""
        text = base.replace("directives:\n", "directives:\n" + line, 1)
        return text, allow, "either" if allow else "refuse", None if allow else no_evil

    if kind == "url":
        host = ["", "localhost", "evil.example", "127.0.0.1", "tmp"][
            int(rng.integers(5))
        ]
        form = int(rng.integers(4))
        url = [
            f"file://{host}{outside}",
            f"file://{host}{scene_dir}/../outside/evil.sdf",
            "../outside/evil.sdf",
            "package://drakegrasp/"
            + "../" * int(rng.integers(1, 9))
            + str(outside).lstrip("/"),
        ][form]
        return evil_first(_evil_line(url))
    if kind == "tag":
        tag = ["!!set", "!!omap", "!x", "!!map", "!Rpy", "!!python/object"][
            int(rng.integers(6))
        ]
        which = "add_model" if rng.random() < 0.6 else "add_directives"
        inner = root / f"inner{i}.yaml"
        inner.write_text("directives:\n" + _evil_line(f"file://{outside}"))
        line = (
            _evil_line(f"file://{outside}", tag)
            if which == "add_model"
            else f"- add_directives: {tag} {{file: 'file://{inner}'}}\n"
        )
        return evil_first(line)
    if kind == "duplicate":
        hidden = textwrap.dedent(
            f"""\
            drakegrasp: "x
            directives:
            {_evil_line(f"file://{outside}").rstrip()}
            "
            """
        )
        text = hidden + base if rng.random() < 0.5 else base + hidden
        return text, allow, "refuse", None
    if kind == "quoted":
        text = base.replace(
            '  description: "Parallel',
            '  description: "x\ndirectives:\n'
            + _evil_line(f"file://{outside}")
            + "  Parallel",
        )
        return text, allow, "either", no_evil
    if kind == "includes":
        # A random include graph over k files: loops refused, the rest load.
        k = int(rng.integers(1, 7))
        files = [root / f"g{i}_{j}.yaml" for j in range(k)]
        edges = {
            j: sorted({int(x) for x in rng.integers(0, k, int(rng.integers(0, 3)))})
            for j in range(k)
        }
        for j, f in enumerate(files):
            lines = "".join(
                f"- add_directives:\n    file: file://{files[t]}\n" for t in edges[j]
            )
            f.write_text("directives:\n" + lines if lines else "directives: []\n")
        text = base.replace(
            "directives:\n",
            f"directives:\n- add_directives:\n    file: file://{files[0]}\n",
            1,
        )
        loop = _has_cycle(edges, 0)
        loads = _loads(edges, 0, 64)
        if loop or loads > 32:
            return text, allow, "refuse", None
        return text, True, "answer", no_evil
    if kind == "alias":
        bomb = root / f"bomb{i}.yaml"
        depth = int(rng.integers(2, 9))
        lines = ['a0: &a0 ["' + "x" * 100 + '"]']
        for j in range(1, depth):
            lines.append(f"a{j}: &a{j} [{', '.join([f'*a{j - 1}'] * 12)}]")
        bomb.write_text("\n".join(lines) + "\ndirectives: []\n")
        text = base.replace(
            "directives:\n",
            f"directives:\n- add_directives:\n    file: file://{bomb}\n",
            1,
        )
        return text, allow, "refuse", None
    if kind == "number":
        good = [
            ("5e-1", 0.5),
            ("1e0", 1.0),
            ("+.25", 0.25),
            ("050", 50.0),
            ("0x1", 1.0),
            ("2.5E-1", 0.25),
        ]
        bad = [
            "yes",
            "on",
            "1_000",
            "1:30",
            "2001-12-14",
            "0b1",
            ".nan",
            "-1",
            "1" + "0" * 400,
        ]
        if rng.random() < 0.5:
            value, want = good[int(rng.integers(len(good)))]
            text = base.replace(
                "  mu: 0.5", f"  mu: {value}\n  distance_tolerance: 1e-3"
            )
            return (
                text,
                False,
                "answer",
                lambda s, w=want: s["mu"] == w and s["tol"] == 1e-3,
            )
        value = bad[int(rng.integers(len(bad)))]
        return base.replace("  mu: 0.5", f"  mu: {value}"), False, "refuse", None
    assert kind == "control"
    ch = ["\\e[2J", "\\a", "\\x9b", "\\u202E", "\\t", "\\0", "\\x7f"][
        int(rng.integers(7))
    ]
    text = base.replace('  description: "Parallel', f'  description: "{ch}Parallel')
    return text, False, "refuse", None


def _has_cycle(edges, start) -> bool:
    state = {}

    def visit(u):
        state[u] = 1
        for v in edges[u]:
            if state.get(v) == 1 or (v not in state and visit(v)):
                return True
        state[u] = 2
        return False

    return visit(start)


def _loads(edges, start, cap) -> int:
    """Directive files loaded from ``start`` (itself counted), up to ``cap``."""
    count, stack = 0, [start]
    while stack and count <= cap:
        u = stack.pop()
        count += 1
        stack.extend(edges[u])
    return count


SCENE_KINDS = (
    "url",
    "tag",
    "duplicate",
    "quoted",
    "includes",
    "alias",
    "number",
    "control",
)


def scene_cases(
    root: Path, sandbox: Sandbox, seed: int = 212, count: int = 240
) -> Iterator[Case]:
    """Generated scene files, each loaded in the sandbox."""
    rng = np.random.default_rng(seed)
    outside = root / "outside" / "evil.sdf"
    outside.parent.mkdir(parents=True, exist_ok=True)
    (root / "scene").mkdir(exist_ok=True)
    from drakegrasp.plant.models import models_dir

    outside.write_text((models_dir() / "objects" / "box.sdf").read_text())
    for i in range(count):
        kind = SCENE_KINDS[i % len(SCENE_KINDS)]
        text, allow, expect, check = _scene_piece(kind, rng, root, outside, i)
        path = root / "scene" / f"s{i}.yaml"
        path.write_text(text)
        yield Case(
            "scene YAML",
            f"{kind}#{i} allow_any_file={allow}",
            lambda p=str(path), a=allow: sandbox.call(
                "fuzz_surfaces:load_scene_summary", p, a
            ),
            expect,
            check,
            files=(outside,),
        )


# ----------------------------------------------------------------- numerics


def numeric_cases(seed: int = 213, count: int = 160) -> Iterator[Case]:
    """Grasps at random length scales; patch polygons with random normals."""
    from drakegrasp.plant.contact_results import patch_polygon

    rng = np.random.default_rng(seed)
    for i in range(count):
        if i % 2 == 0:
            g = random_grasp(rng, planar=False)
            s = float(10.0 ** rng.uniform(-307, 19))
            h = dg.Grasp(
                [c.with_(position=np.asarray(c.position) * s) for c in g.contacts],
                reference_point=np.asarray(g.reference_point) * s,
            )
            ref = dg.force_closure(g)

            def same(r, ref=ref):
                return r.is_closure == ref.is_closure and r.rank == ref.rank

            yield Case(
                "numerics",
                f"scale {s:.1e}#{i}",
                lambda h=h: dg.force_closure(h),
                "answer",
                same,
            )
        else:
            pts = rng.normal(size=(int(rng.integers(3, 9)), 3))
            kind = int(rng.integers(4))
            normal = [
                rng.normal(size=3) * 10.0 ** rng.uniform(-200, 200),
                np.array([math.nan] * 3),
                np.zeros(3),
                np.array([math.inf, 0.0, 1.0]),
            ][kind]
            if kind == 0:
                nhat = (
                    normal
                    / np.linalg.norm(normal / np.max(np.abs(normal)))
                    / np.max(np.abs(normal))
                )

                def on_plane(poly, pts=pts, nhat=nhat):
                    return poly.shape[1] == 3 and np.allclose(
                        (poly - pts.mean(axis=0)) @ nhat, 0.0, atol=1e-9
                    )

                yield Case(
                    "numerics",
                    f"patch#{i}",
                    lambda p=pts, n=normal: patch_polygon(p, n),
                    "answer",
                    on_plane,
                )
            else:
                yield Case(
                    "numerics",
                    f"patch-bad#{i}",
                    lambda p=pts, n=normal: patch_polygon(p, n),
                    "refuse",
                )


def all_cases(root: Path, sandbox: Sandbox) -> Iterator[Case]:
    """Every family of this module, in a fixed order."""
    yield from certificate_cases()
    yield from second_order_cases()
    yield from numeric_cases()
    yield from scene_cases(root, sandbox)
