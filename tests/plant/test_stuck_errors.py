"""Errors that name the way out (issue 20, point 10).

- A ``package://drake_models/...`` scene whose download fails says how to
  use a local copy: ``DRAKEGRASP_DRAKE_MODELS`` or ``--package
  drake_models=DIR``.  Reproduced in a child process without a network
  (``unshare -rn``: a user namespace with no network device; skipped where
  the kernel forbids it) and with Drake's ``DRAKE_ALLOW_NETWORK=none``.
- ``plant.CreateDefaultContext()`` of a plant whose scene graph lives in a
  diagram has no geometry: every entry point says so with an
  :class:`~drakegrasp.InvalidContextError` naming the diagram's context.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from hand_models import Rig, ball, palm_hand
from pydrake.math import RigidTransform

import drakegrasp
from drakegrasp import (
    InvalidContextError,
    analyze_grasp,
    close_hand,
    find_contacts,
    load_scene,
)
from drakegrasp.plant.models import (
    DRAKE_MODELS_ENV,
    DRAKE_MODELS_HINT,
    explain_drake_models,
)
from drakegrasp.plant.scale import object_radius

SCENE = """directives:
- add_model:
    name: wsg
    file: package://drake_models/wsg_50_description/sdf/schunk_wsg_50_with_tip.sdf
- add_weld:
    parent: world
    child: wsg::body
- add_model:
    name: box
    file: package://drakegrasp/objects/box.sdf
drakegrasp:
  object_body: box::box
  hand: wsg
  mu: 0.5
"""

REPO = Path(drakegrasp.__file__).resolve().parents[1]


def _run_offline(tmp_path: Path, prefix: list[str], command=None, **env: str):
    scene = tmp_path / "wsg.yaml"
    scene.write_text(SCENE)
    command = command or ["analyze", str(scene)]
    cache = tmp_path / "cache"  # an empty download cache
    cache.mkdir()
    child = {
        k: v
        for k, v in os.environ.items()
        if k not in (DRAKE_MODELS_ENV, "DRAKE_ALLOW_NETWORK")
    }
    child.update(XDG_CACHE_HOME=str(cache), PYTHONPATH=str(REPO), **env)
    return subprocess.run(
        [*prefix, sys.executable, "-m", "drakegrasp", *command],
        capture_output=True,
        text=True,
        env=child,
        timeout=300,
    )


def _names_the_way_out(stderr: str) -> None:
    # Drake may log its download attempt first; the error is one last line.
    assert stderr.splitlines()[-1].startswith("drakegrasp: error: ")
    assert f"set {DRAKE_MODELS_ENV}=DIR" in stderr
    assert "--package drake_models=DIR" in stderr
    assert "Traceback" not in stderr


def test_failed_download_names_the_variable_and_the_flag(tmp_path):
    if shutil.which("unshare") is None:
        pytest.skip("no unshare(1) to run a child process without a network")
    probe = subprocess.run(["unshare", "-rn", "true"], capture_output=True)
    if probe.returncode != 0:
        pytest.skip(f"unshare -rn is not permitted here: {probe.stderr.strip()}")
    done = _run_offline(tmp_path, ["unshare", "-rn"])
    assert done.returncode == 1 and done.stdout == ""
    assert "when downloading 'drake_models'" in done.stderr
    _names_the_way_out(done.stderr)


def test_network_forbidden_names_the_variable_and_the_flag(tmp_path):
    done = _run_offline(tmp_path, [], DRAKE_ALLOW_NETWORK="none")
    assert done.returncode == 1 and done.stdout == ""
    assert "unset DRAKE_ALLOW_NETWORK" in done.stderr
    _names_the_way_out(done.stderr)


def test_network_forbidden_stops_plan_with_the_same_words(tmp_path):
    # plan made its parser unguarded: Drake's words alone, no way out named
    done = _run_offline(
        tmp_path, [], ["plan", "box", "--num", "5"], DRAKE_ALLOW_NETWORK="none"
    )
    assert done.returncode == 1 and done.stdout == ""
    assert "the planning scene: cannot make Drake's parser" in done.stderr
    assert "unset DRAKE_ALLOW_NETWORK" in done.stderr
    _names_the_way_out(done.stderr)


def test_the_hint_is_added_only_to_drake_models_failures():
    failed = (
        "PackageMap: when downloading 'drake_models', the downloader experienced "
        "an error: All downloads failed"
    )
    assert explain_drake_models(failed).endswith(DRAKE_MODELS_HINT)
    other = "PackageMap: when downloading 'my_pkg', the downloader failed"
    assert explain_drake_models(other) == other
    unrelated = "no such file: package://drake_models/x.sdf\n  (a typo)"
    assert (
        explain_drake_models(unrelated)
        == "no such file: package://drake_models/x.sdf (a typo)"
    )


def test_local_copy_through_package_map(drake_models_dir, tmp_path, monkeypatch):
    # What the hint says works: --package drake_models=DIR (package_map=).
    monkeypatch.delenv(DRAKE_MODELS_ENV, raising=False)
    scene = tmp_path / "wsg.yaml"
    scene.write_text(SCENE)
    loaded = load_scene(scene, package_map={"drake_models": str(drake_models_dir)})
    assert loaded.plant.HasModelInstanceNamed("wsg")


@pytest.fixture
def lone_context():
    rig = Rig(
        [(palm_hand(), "sdf"), (ball(0.035), "sdf")],
        "ball",
        RigidTransform([0.0, 0.0, 0.035 + 5e-5]),
    )
    return rig, rig.plant.CreateDefaultContext()


@pytest.mark.parametrize(
    "call",
    [
        lambda r, c: analyze_grasp(r.plant, c, r.object, hand=r.hand, mu=0.5),
        lambda r, c: find_contacts(r.plant, c, r.object, hand=r.hand),
        lambda r, c: close_hand(r.plant, c, r.object, hand=r.hand),
        lambda r, c: object_radius(r.plant, c, r.object),
    ],
    ids=["analyze_grasp", "find_contacts", "close_hand", "object_radius"],
)
def test_a_plant_alone_context_names_the_fix(lone_context, call):
    rig, context = lone_context
    with pytest.raises(InvalidContextError) as info:
        call(rig, context)
    message = str(info.value)
    assert "geometry_query input port is not connected" in message
    assert "plant.GetMyContextFromRoot(diagram_context)" in message
    assert "CreateDefaultContext()" in message
    # The fix it names works.
    diagram_context = rig.diagram.CreateDefaultContext()
    plant_context = rig.plant.GetMyContextFromRoot(diagram_context)
    rig.plant.SetFreeBodyPose(
        plant_context, rig.object, RigidTransform([0.0, 0.0, 0.035 + 5e-5])
    )
    call(rig, plant_context)
