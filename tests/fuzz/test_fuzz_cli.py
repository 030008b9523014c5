"""The ``drakegrasp`` command as a user runs it: a subprocess per call.

Every bad input exits non-zero with exactly one line on stderr and no
traceback; Ctrl-C (SIGINT) in the middle of a long batch exits 130 with one
line, leaves no partial output and keeps the input intact.
"""

import hashlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from odd_scenes import BOX_WELD, SECOND_BOX, SHIPPED_BOX_POSE, edited_shipped

from drakegrasp.core import examples as ex

ROOT = Path(__file__).resolve().parents[2]


def _run(*args, timeout=120):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run(
        [sys.executable, "-m", "drakegrasp", *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        env=env,
    )


def _grasps(path: Path, K: int, *, mu=True) -> Path:
    g = ex.equator_fingers(0.5)
    arrays = {
        "positions": np.repeat(g.positions[None], K, 0),
        "normals": np.repeat(g.normals[None], K, 0),
    }
    if mu:
        arrays["mu"] = np.full((K, 3), 0.5)
    with open(path, "wb") as f:
        np.savez(f, **arrays)
    return path


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _one_line_error(proc, code=1):
    lines = [line for line in proc.stderr.splitlines() if line.strip()]
    assert proc.returncode == code, proc.stderr
    assert "Traceback" not in proc.stderr
    assert len(lines) == 1, proc.stderr
    return lines[0]


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        ((), "required: COMMAND"),
        (("bogus",), "invalid choice: 'bogus'"),
        (("plan", "--top", "abc"), "argument --top: not a whole number"),
        (("plan", "--top", "-2"), "argument --top: must be >= 0"),  # was all but 2
        (("plan", "--num", "1e9"), "argument --num"),
        (("plan", "--mass", "0"), "argument --mass: must be finite and > 0"),
        (("plan", "--mass", "inf"), "argument --mass: must be finite and > 0"),
        (("plan", "--torque-limit", "nan"), "argument --torque-limit: must be"),
        (("plan", "--squeeze-limit", "0"), "argument --squeeze-limit: must be"),
        (("plan", "--squeeze-limit", "1e400"), "argument --squeeze-limit: must"),
        (("plan", "--contact-model", "glue"), "argument --contact-model: invalid"),
        (("plan", "--torsional-friction", "nan"), "argument --torsional-friction"),
        (("plan", "--preshape", "joint_12=nan"), "argument --preshape: expected"),
        (("plan", "--preshape", "=1"), "argument --preshape: expected"),
        (("plan", "--preshape", "j=1e400"), "argument --preshape: expected"),
        (("plan", "--preshape", "opened"), "or 'open', got 'opened'"),
        (("analyze", "--tol", "abc"), "argument --tol"),
        (("analyze", "--load", "heavy"), "argument --load: expected 'gravity'"),
        (("analyze", "--load", "1,,2"), "argument --load: expected 'gravity'"),
        (("analyze", "--torque-limits", "x"), "argument --torque-limits: expected"),
        (("batch",), "required: input, output"),
        (("plan", "--json", "--out", "x.parquet"), "not allowed with argument"),
        (("plan", "--shake", "abc"), "argument --shake: not a whole number"),
        (("plan", "--shake", "-1"), "argument --shake: must be >= 0"),
        (("plan", "--shake", "1", "--squeeze", "0"), "argument --squeeze: must be"),
        (("plan", "--shake", "1", "--damping", "inf"), "argument --damping: must be"),
        (("plan", "--shake", "1", "--hydroelastic", "1e400"), "a modulus in Pa"),
        (("plan", "--shake", "1", "--hydroelastic", "-"), "a modulus in Pa"),
    ],
)
def test_argument_errors_are_one_line_too(argv, message):
    line = _one_line_error(_run(*argv), code=2)
    assert line.startswith("drakegrasp") and message in line, line
    assert line.endswith("--help)"), line


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (("--shake", "0"), "--shake must be a whole number of candidates from 1"),
        (("--shake", "99999"), "--shake must be a whole number of candidates"),
        (("--stiffness", "5"), "--stiffness is an option of the shake test"),
        (("--shake", "1", "--hydroelastic", "1e20"), "--hydroelastic must be none"),
        (("--shake", "1", "--hydroelastic", "1"), "--hydroelastic must be none ("),
        (("parallel_jaw_flat_box", "--shake", "1"), "--shake is for an object"),
    ],
)
def test_plan_shake_refusals_are_one_line_before_planning(argv, message):
    line = _one_line_error(_run("plan", "--num", "5", *argv), code=1)
    assert message in line, line


def test_bad_inputs_one_line_each(tmp_path):
    good = _grasps(tmp_path / "good.npz", 5)
    truncated = tmp_path / "truncated.npz"
    truncated.write_bytes(good.read_bytes()[:100])
    text = tmp_path / "text.npz"
    text.write_text("positions,normals\n")
    link = tmp_path / "link.npz"
    link.symlink_to(good)
    existing = tmp_path / "existing.npz"
    existing.write_bytes(b"earlier results")
    before = {p: _digest(p) for p in (good, existing)}
    cases = [
        (["batch", str(truncated), str(tmp_path / "o1.npz")], "damaged or truncated"),
        (["batch", str(text), str(tmp_path / "o2.npz")], "is not a .npz archive"),
        (["batch", str(good), str(good)], "is the input file"),
        (["batch", str(good), str(link)], "is the input file"),
        (["batch", str(good), str(existing)], "--overwrite"),
        (
            [
                "batch",
                str(good),
                str(tmp_path / "o3.npz"),
                "--num-generators",
                "100000000",
            ],
            "--num-generators",
        ),
        (
            [
                "batch",
                str(good),
                str(tmp_path / "o4.npz"),
                "--contact-model",
                "soft_finger",
            ],
            "torsional_friction",
        ),
    ]
    for argv, message in cases:
        line = _one_line_error(_run(*argv))
        assert line.startswith("drakegrasp: error:") and message in line, line
    assert {p: _digest(p) for p in (good, existing)} == before
    assert not list(tmp_path.glob(".*.partial"))


# Edits of the shipped parallel_jaw_box that `plan` refuses, and the cause the
# one line must name (before: a misleading cause, or a plan on nonsense)
HOSTILE_SCENES = {
    "object welded": (
        [(SHIPPED_BOX_POSE, ""), ("drakegrasp:\n", BOX_WELD + "drakegrasp:\n")],
        "object_body box::box is welded to the world",
    ),
    "object world": (
        [("object_body: box::box", "object_body: world")],
        "is the world body",
    ),
    "object palm": (
        [("object_body: box::box", "object_body: gripper::palm")],
        "is part of the hand",
    ),
    "hand object's instance": (
        [("  hand: gripper\n", "  hand: box\n")],
        "is the model instance of the object",
    ),
    "no hand, second free box": (
        [("  hand: gripper\n", ""), ("drakegrasp:\n", SECOND_BOX + "drakegrasp:\n")],
        "names no hand",
    ),
    "object unknown": (
        [("object_body: box::box", "object_body: box::lid")],
        "object_body: no body named 'box::lid'",
    ),
    "hand a body": (
        [("  hand: gripper\n", "  hand: gripper::palm\n")],
        "'gripper::palm' is a body",
    ),
    "hand of no model": (
        [("  hand: gripper\n", "  hand: [gripper::palm, box::box]\n")],
        "also listed as a body of the hand",
    ),
}


@pytest.mark.parametrize("case", sorted(HOSTILE_SCENES))
def test_hostile_scenes_one_line_each(tmp_path, case):
    edits, cause = HOSTILE_SCENES[case]
    text = edited_shipped("parallel_jaw_box", *edits)
    scene = tmp_path / "hostile.yaml"
    scene.write_text(text)
    line = _one_line_error(_run("plan", str(scene), "--num", "5"))
    assert line.startswith("drakegrasp: error:") and cause in line, line


@pytest.mark.parametrize("flag", [(), ("--allow-any-file",)])
def test_a_model_file_name_longer_than_any_path_is_one_line(tmp_path, flag):
    # Drake's PackageMap.ResolveUrl crashed the process (SIGSEGV, no line at
    # all) on a file: of 100,000 characters.
    long_name = "package://drakegrasp/objects/box.sdf"
    text = edited_shipped("parallel_jaw_box", (long_name, "x" * 100_000))
    scene = tmp_path / "long.yaml"
    scene.write_text(text)
    line = _one_line_error(_run("analyze", str(scene), *flag))
    assert "characters, more than any path can have" in line, line


def test_upper_case_suffix_overwrite_and_the_deprecated_alias(tmp_path):
    good = _grasps(tmp_path / "good.npz", 5)
    out = tmp_path / "OUT.NPZ"
    proc = _run("batch", str(good), str(out), "--model", "hard_finger")
    assert proc.returncode == 0, proc.stderr
    assert "--model is deprecated" in proc.stderr
    assert out.exists() and not (tmp_path / "OUT.NPZ.npz").exists()
    with np.load(out) as data:
        assert data["is_closure"].all()
    first = _digest(out)
    _one_line_error(_run("batch", str(good), str(out)))
    assert _digest(out) == first  # refused: untouched
    proc = _run("batch", str(good), str(out), "--overwrite", "--kind", "form")
    assert proc.returncode == 0, proc.stderr
    with np.load(out) as data:
        assert str(data["kind"]) == "form"


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_sigint_during_a_long_batch(tmp_path, checkout_env):
    # 80,000 random grasps of 16 contacts with the ε metric: about 20 s of work
    # on two cores (the batch ε kernel runs ~3,000 grasps/s per core at N = 16),
    # so the signal lands mid-run, in the LPs or in the ε kernel.
    rng = np.random.default_rng(0)
    K = 80_000
    P = rng.normal(size=(K, 16, 3))
    P /= np.linalg.norm(P, axis=2, keepdims=True)
    big = tmp_path / "big.npz"
    with open(big, "wb") as f:
        np.savez(f, positions=P, normals=-P + 0.3 * rng.normal(size=P.shape), mu=0.5)
    digest = _digest(big)
    out = tmp_path / "out.npz"
    env = checkout_env  # kernels warm: no compile notice on stderr
    argv = ["batch", str(big), str(out), "--metrics", "epsilon_l1"]
    proc = subprocess.Popen(
        [sys.executable, "-m", "drakegrasp", *argv],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    time.sleep(6.0)  # past the imports, inside the engine's numpy work
    assert proc.poll() is None, "the batch finished before the signal: make it bigger"
    sent = time.perf_counter()
    proc.send_signal(signal.SIGINT)
    _, stderr = proc.communicate(timeout=120)
    latency = time.perf_counter() - sent
    assert proc.returncode == 130, stderr
    assert stderr.strip() == "drakegrasp: interrupted"
    assert not out.exists() and not list(tmp_path.glob(".*.partial"))
    assert _digest(big) == digest
    print(f"SIGINT answered in {latency:.2f} s")  # shown with -s; never asserted
