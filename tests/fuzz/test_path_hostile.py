"""Hostile paths, file names and URLs at every public entry point that takes one.

A path may come as a ``str`` subclass whose ``__str__``, ``__format__`` or
``__fspath__`` raises, an ``os.PathLike`` whose ``__fspath__`` raises or
returns an int, bytes or 10**7 characters, or a plain string that pathlib,
``os.stat`` or Drake refuse with a bare exception (a NUL, a lone surrogate, a
name longer than ``NAME_MAX``, ``~nobody``).  Every entry point reads it with
:func:`~drakegrasp.core.validation.path_text`: it answers, or refuses with a
short :class:`~drakegrasp.GraspError`; never a raw exception, never a file
left behind.  Each value of ``hostile.path_hostile`` goes to each path
argument of :data:`CALLS`; the command line gets the plain strings.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pytest
from pydrake.multibody.parsing import PackageMap, Parser
from pydrake.multibody.plant import MultibodyPlant

import drakegrasp as dg
from drakegrasp import cli
from drakegrasp.core.validation import NAME_MAX, PATH_MAX, path_text
from drakegrasp.plant.models import DRAKE_MODELS_ENV

sys.path.insert(0, str(Path(__file__).resolve().parent))
import hostile  # noqa: E402
from cli_runs import run_cli  # noqa: E402

SHORT = 2_000
"""Characters a refusal's message may take, whatever the path."""

PATHS = hostile.path_hostile()
IDS = [f"{type(v).__name__}-{i}" for i, v in enumerate(PATHS)]

BOX = "package://drakegrasp/objects/box.sdf"
JAW = "package://drakegrasp/hands/parallel_jaw_flat.sdf"


def _refused_by_the_reader(value) -> bool:
    try:
        path_text("x", value)
    except dg.GraspError:
        return True
    return False


REFUSED = [v for v in PATHS if _refused_by_the_reader(v)]
REFUSED_IDS = [IDS[i] for i, v in enumerate(PATHS) if _refused_by_the_reader(v)]


def _keyed(value, folder) -> dict:
    """``{value: folder}``, or no such dict (a bytearray is no key, nor a str
    whose ``__hash__`` raises)."""
    try:
        hash(value)
    except Exception:  # noqa: BLE001 - TypeError, or a hostile __hash__
        return {}
    return {value: str(folder)}


class _Meshcat:
    """Takes every Meshcat call and does nothing (no server, no port)."""

    def __getattr__(self, name):
        return lambda *args, **kwargs: None


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A grasp file, a batch result and a free folder to write in."""
    folder = tmp_path_factory.mktemp("paths")
    g = dg.core.examples.equator_fingers(0.5)
    P, N = g.positions[None], g.normals[None]
    np.savez(folder / "in.npz", positions=P, normals=N, mu=np.full((1, 3), 0.5))
    result = dg.batch_force_closure(P, N, mu=0.5)
    return folder, folder / "in.npz", result


def _calls(files):
    """``(name, call)``: ``call(value)`` passes ``value`` as one path argument."""
    folder, grasps, result = files
    out = folder / "out.npz"
    yield "read_grasps", lambda v: dg.batch.read_grasps(v)
    yield "evaluate_file(input)", lambda v: dg.evaluate_file(v, out, mu=0.5)
    yield "evaluate_file(output)", lambda v: dg.evaluate_file(grasps, v, mu=0.5)
    yield "stream_file(input)", lambda v: dg.batch.stream_file(v, out, mu=0.5)
    yield "stream_file(output)", lambda v: dg.batch.stream_file(grasps, v, mu=0.5)
    yield "write_result", lambda v: dg.batch.write_result(result, v)
    yield (
        "write_chunks",
        lambda v: dg.batch.write_chunks(
            [], v, K=0, kind="force", tol=1e-6, required_rank=6
        ),
    )
    yield "read_dataset", lambda v: dg.distributed.read_dataset(v)
    yield "load_scene", lambda v: dg.load_scene(v)
    yield "read_scene_info", lambda v: dg.plant.scene.read_scene_info(v)
    yield "scene_path", lambda v: dg.plant.scene.scene_path(v)
    yield (
        "load_scene(package_map={name: v})",
        lambda v: dg.load_scene("parallel_jaw_box", package_map={"mine": v}),
    )
    yield (
        "load_scene(package_map=[v])",
        lambda v: dg.load_scene("parallel_jaw_box", package_map=[v]),
    )
    yield (
        "load_scene(package_map={v: folder})",
        lambda v: dg.load_scene("parallel_jaw_box", package_map=_keyed(v, folder)),
    )
    yield "planning_scene(object_url)", lambda v: dg.planning_scene(v, hand_url=JAW)
    yield "planning_scene(hand_url)", lambda v: dg.planning_scene(BOX, hand_url=v)
    yield (
        "planning_scene(models_dir)",
        lambda v: dg.planning_scene(None, hand_url=JAW, models_dir=v),
    )
    yield (
        "planning_scene(package_map={name: v})",
        lambda v: dg.planning_scene(BOX, hand_url=JAW, package_map={"mine": v}),
    )
    yield (
        "planning_scene(package_map={v: folder})",
        lambda v: dg.planning_scene(BOX, hand_url=JAW, package_map=_keyed(v, folder)),
    )
    yield "use_local_drake_models", lambda v: dg.use_local_drake_models(PackageMap(), v)
    yield (
        "add_models(file_name)",
        lambda v: dg.plant.add_models(Parser(MultibodyPlant(0.0)), v),
    )
    yield (
        "add_models(url)",
        lambda v: dg.plant.add_models(Parser(MultibodyPlant(0.0)), url=v),
    )
    for key in ("hand_file", "object_file", "folder"):
        paths = {"hand_file": JAW, "object_file": BOX, "folder": ".", key: None}

        def scene_text(v, key=key, paths=paths):
            from drakegrasp.planning.grasp_scene import grasp_scene_text

            return grasp_scene_text(
                None, None, None, object_body=None, mu=0.5, **{**paths, key: v}
            )

        yield f"grasp_scene_text({key})", scene_text
    yield "set_translucent", lambda v: dg.visualization.set_translucent(_Meshcat(), v)
    yield (
        "draw_grasp(prefix)",
        lambda v: dg.visualization.draw_grasp(
            _Meshcat(), dg.core.examples.spatial_two_fingers(0.5), prefix=v
        ),
    )


def _refuses_briefly(call, value) -> None:
    try:
        call(value)
    except dg.GraspError as error:
        message = str(error)
        assert type(message) is str
        assert len(message) <= SHORT, f"a {len(message)}-character message"


@pytest.mark.parametrize("value", PATHS, ids=IDS)
def test_every_path_argument_answers_or_refuses_a_hostile_path_briefly(
    files, value, monkeypatch
):
    monkeypatch.chdir(files[0])  # a relative path that is accepted lands here
    failures = []
    for name, call in _calls(files):
        try:
            _refuses_briefly(call, value)
        except Exception as error:  # noqa: BLE001 - collected, then reported
            failures.append(f"{name}: {type(error).__name__}: {error}"[:300])
    assert not failures, "\n".join(failures)
    left = {p.name for p in files[0].iterdir()} - {"in.npz"}
    assert not left, f"files left behind: {sorted(left)}"


@pytest.mark.parametrize("value", REFUSED, ids=REFUSED_IDS)
def test_a_cluster_run_refuses_a_hostile_path_before_it_connects(files, value):
    # Refused before a scheduler is looked for: client=None would start one.
    _, grasps, _ = files
    g = dg.core.examples.equator_fingers(0.5)
    P, N = g.positions[None], g.normals[None]
    calls = [
        lambda v: dg.distributed.evaluate_on_cluster(None, P, N, mu=0.5, output_dir=v),
        lambda v: dg.distributed.stream_file_on_cluster(
            v, "/nonexistent/out", scheduler="tcp://127.0.0.1:9", mu=0.5
        ),
        lambda v: dg.distributed.stream_file_on_cluster(
            grasps, v, scheduler="tcp://127.0.0.1:9", mu=0.5
        ),
    ]
    for call in calls:
        with pytest.raises(dg.BatchFileError) as refused:
            call(value)
        assert len(str(refused.value)) <= SHORT
    # read here, not pickled to every worker to fail there once per task
    with pytest.raises(dg.InvalidOptionError, match="^scene ") as refused:
        dg.distributed.analyze_poses(None, value, np.zeros((1, 3)))
    assert len(str(refused.value)) <= SHORT


@pytest.mark.parametrize(
    ("value", "said"),
    [
        (hostile.FspathRaises(), "its __fspath__() raised HostileError"),
        (hostile.FspathReturns(42), "returned a int, not a str"),
        (hostile.FspathReturns(b"/tmp"), "returned a bytes, not a str"),
        (b"/tmp", "got bytes b'/tmp'"),
        ("", "is empty"),
        ("a\0b", "NUL"),
        ("\ud800", "cannot encode"),
        ("x" * (PATH_MAX + 1), f"too long: {PATH_MAX + 1} bytes"),
        ("d/" + "y" * (NAME_MAX + 1), f"name too long: {NAME_MAX + 1} bytes"),
    ],
)
def test_the_reader_names_the_parameter_and_what_is_wrong(value, said):
    with pytest.raises(dg.InvalidOptionError, match="^input_path ") as refused:
        path_text("input_path", value)
    assert said in str(refused.value)
    assert len(str(refused.value)) <= SHORT


def test_the_reader_returns_the_plain_text_of_a_str_subclass_or_a_path_like():
    text = path_text("p", hostile.StrFspathRaises("/tmp/a.npz"))
    assert type(text) is str and text == "/tmp/a.npz"
    text = path_text("p", hostile.FspathReturns(hostile.StrFormatRaises("b")))
    assert type(text) is str and text == "b"
    assert path_text("p", Path("/tmp/c")) == "/tmp/c"
    assert path_text("p", "", empty=True) == ""
    many = "/" + "d/" * ((PATH_MAX - 2) // 2)  # PATH_MAX - 1 or - 2 bytes
    assert path_text("p", many) == many


def _path_of_bytes(n: int) -> str:
    """An absolute path of ``n`` bytes, each name within ``NAME_MAX``."""
    names = "/".join(["p" * 200] * (n // 201 + 1))
    return ("/" + names)[:n]


def test_a_path_of_path_max_bytes_is_refused_as_too_long():
    # PATH_MAX counts the NUL that ends a path: the kernel refuses a path of
    # PATH_MAX bytes (ENAMETOOLONG), and pathlib's is_file() raised it.
    assert path_text("p", _path_of_bytes(PATH_MAX - 1)) == _path_of_bytes(PATH_MAX - 1)
    with pytest.raises(dg.InvalidOptionError, match="^p ") as refused:
        path_text("p", _path_of_bytes(PATH_MAX))
    assert f"too long: {PATH_MAX} bytes" in str(refused.value)
    with pytest.raises(dg.BatchFileError, match="too long"):
        dg.batch.read_grasps(_path_of_bytes(PATH_MAX))


def test_path_max_is_the_systems():
    # 4096 on Linux, 1024 on macOS: a path of 1024 to 4095 bytes passed the
    # reader there and met pathlib's bare OSError.
    if not hasattr(os, "pathconf"):
        pytest.skip("no os.pathconf on this platform")
    assert PATH_MAX == os.pathconf("/", "PC_PATH_MAX")


def test_the_reader_raises_the_error_it_is_given():
    with pytest.raises(dg.BatchFileError, match="output must be"):
        path_text("output", 3, error=dg.BatchFileError)


@pytest.mark.parametrize(
    "value",
    ["x" * hostile.HUGE, "y" * 300, "/tmp/" + "z" * 300, "~drakegrasp-nobody/x"],
    ids=["huge", "long-name", "long-name-in-folder", "no-such-user"],
)
def test_a_hostile_drake_models_variable_is_a_model_error(value, monkeypatch):
    monkeypatch.setenv(DRAKE_MODELS_ENV, value)
    with pytest.raises(dg.ModelError, match=DRAKE_MODELS_ENV) as refused:
        dg.use_local_drake_models(PackageMap())
    assert len(str(refused.value)) <= SHORT


LONG_NAME = "/tmp/" + "q" * 300


@pytest.mark.parametrize(
    "argv",
    [
        ["batch", LONG_NAME + ".npz", "out.npz", "--mu", "0.5"],
        ["batch", "in.npz", LONG_NAME + ".npz", "--mu", "0.5"],
        ["analyze", LONG_NAME + ".yaml"],
        ["analyze", "y" * 300],
        ["plan", LONG_NAME + ".sdf"],
        ["plan", "box", "--hand", LONG_NAME + ".sdf"],
        ["plan", "box", "--out", LONG_NAME + ".parquet"],
        ["plan", "box", "--scene-out", LONG_NAME + ".yaml"],
        ["analyze", "--package", f"mine={LONG_NAME}"],
        ["plan", "box", "--package", f"mine={LONG_NAME}"],
    ],
    ids=[
        "batch-in",
        "batch-out",
        "analyze-file",
        "analyze-name",
        "plan-object",
        "plan-hand",
        "plan-out",
        "plan-scene-out",
        "analyze-package",
        "plan-package",
    ],  # fmt: skip
)
def test_the_command_refuses_a_path_of_a_long_name_on_one_line(
    argv, capsys, files, monkeypatch
):
    monkeypatch.chdir(files[0])
    status, err = run_cli(argv, capsys)
    assert status != 0
    assert err.count("\n") == 1, err[:300]
    assert "unexpected" not in err, err[:300]  # the CLI's last net: a bug
    assert len(err) <= SHORT, f"a {len(err)}-character refusal"


UNDECODABLE = os.fsdecode(b"\xff\xfe")
"""Bytes no UTF-8 decodes, as Python hands them to ``main`` in ``sys.argv``
(``surrogateescape``: lone surrogates U+DCFF U+DCFE)."""


@pytest.fixture(scope="module")
def gripper(tmp_path_factory):
    """A multi-finger hand's model file (two hinged jaws): --preshape reads it."""
    from coupled_hands import angular_gripper_urdf

    path = tmp_path_factory.mktemp("hand") / "angular_gripper.urdf"
    path.write_text(angular_gripper_urdf())
    return str(path)


def _undecodable_argvs(gripper: str) -> dict:
    b = UNDECODABLE
    plan = ["plan", "box", "--num", "2"]
    return {
        "batch-in": ["batch", f"{b}.npz", "out.npz", "--mu", "0.5"],
        "batch-out-folder": ["batch", "in.npz", f"{b}/out.npz", "--mu", "0.5"],
        "analyze-scene": ["analyze", f"{b}.yaml"],
        "analyze-name": ["analyze", b],
        "analyze-package": ["analyze", "--package", f"mine=/tmp/{b}"],
        "plan-object": ["plan", f"{b}.sdf", "--num", "2"],
        "plan-object-name": ["plan", b, "--num", "2"],
        "plan-hand-file": [*plan, "--hand", f"{b}.urdf"],
        "plan-hand-name": [*plan, "--hand", b],
        "plan-preshape-joint": [*plan, "--hand", gripper, "--preshape", f"{b}=0.1"],
        "plan-preshape-surrogate": [
            *plan, "--hand", gripper, "--preshape", "\ud800=0.1"
        ],
        "plan-preshape-word": [*plan, "--hand", gripper, "--preshape", b],
        "plan-scene-out": [*plan, "--scene-out", f"{b}/x.yaml"],
    }  # fmt: skip


@pytest.mark.parametrize(
    "case",
    [
        "batch-in", "batch-out-folder", "analyze-scene", "analyze-name",
        "analyze-package", "plan-object", "plan-object-name", "plan-hand-file",
        "plan-hand-name", "plan-preshape-joint", "plan-preshape-surrogate",
        "plan-preshape-word", "plan-scene-out",
    ],
)  # fmt: skip
def test_the_command_refuses_undecodable_bytes_on_one_line(
    case, gripper, capsys, files, monkeypatch
):
    # These gave a one-line refusal when probed by hand; now they are fuzzed.
    monkeypatch.chdir(files[0])
    argv = _undecodable_argvs(gripper)[case]
    status, err = run_cli(argv, capsys)
    assert status != 0
    assert err.count("\n") == 1, err[:300]
    assert err.startswith("drakegrasp") and "unexpected" not in err, err[:300]
    assert len(err) <= SHORT, f"a {len(err)}-character refusal"


def test_a_batch_output_of_undecodable_bytes_is_written_under_that_name(
    files, tmp_path
):
    # Not an error: the bytes are a file name the file system takes.  Run as a
    # user runs it, argv given as bytes, stdout and stderr pipes.
    import subprocess

    name = os.fsencode(tmp_path) + b"/\xff\xfe.npz"
    done = subprocess.run(
        [sys.executable, "-m", "drakegrasp", "batch", str(files[1]), name],
        capture_output=True, timeout=300,
        env={**os.environ, "PYTHONPATH": str(Path(cli.__file__).parents[1])},
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-500:]
    assert b"Traceback" not in done.stderr
    assert [p.name for p in tmp_path.iterdir()] == [os.fsdecode(b"\xff\xfe.npz")]
    with np.load(os.fsdecode(name)) as written:
        assert written["is_closure"].tolist() == [True]


def test_the_command_names_a_drake_models_variable_of_a_long_name(capsys, monkeypatch):
    # _cli_words asked pathlib whether the folder holds the model, inside the
    # handler of the first error: a name too long raised OSError there.
    monkeypatch.setenv(DRAKE_MODELS_ENV, "/tmp/" + "w" * 300)
    status = cli.main(["plan", "package://drake_models/nowhere/x.sdf"])
    err = capsys.readouterr().err
    assert status != 0
    assert err.count("\n") == 1, err[:300]
    assert DRAKE_MODELS_ENV in err
    assert os.environ[DRAKE_MODELS_ENV].startswith("/tmp/w")


@pytest.mark.parametrize(
    "value",
    ["/tmp/" + "r" * 300, "s" * 5000, "/nonexistent:/tmp/" + "t" * 300],
    ids=["long-name", "too-long", "second-entry"],
)
def test_a_hostile_ros_package_path_is_a_scene_error(value, monkeypatch):
    # Drake's PopulateFromRosPackagePath raised a bare RuntimeError
    # ("filesystem error: ... File name too long").
    monkeypatch.setenv("ROS_PACKAGE_PATH", value)
    with pytest.raises(dg.SceneError, match="ROS_PACKAGE_PATH") as refused:
        dg.load_scene("parallel_jaw_box")
    assert len(str(refused.value)) <= SHORT
