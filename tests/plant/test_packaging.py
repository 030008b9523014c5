"""The models ship inside the wheel: a non-editable install works from anywhere."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10: the test extras install tomli
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[2]


def test_every_drakegrasp_subpackage_is_in_the_package_list():
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())
    listed = set(config["tool"]["setuptools"]["packages"])
    found = {
        ".".join(p.parent.relative_to(ROOT).parts)
        for p in (ROOT / "drakegrasp").rglob("__init__.py")
        if "__pycache__" not in p.parts
    }
    missing = found - listed
    assert not missing, f"add {sorted(missing)} to [tool.setuptools] packages"
    assert "drakegrasp.models" in listed
    assert config["tool"]["setuptools"]["package-dir"]["drakegrasp.models"] == "models"


CHECK = textwrap.dedent(
    """
    import sys
    from pathlib import Path
    import drakegrasp
    from drakegrasp.plant import (
        analyze_grasp, load_scene, models_dir, register_models)
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    target = Path(sys.argv[1]).resolve()
    assert target in Path(drakegrasp.__file__).resolve().parents, drakegrasp.__file__
    assert target in models_dir().parents, models_dir()
    plant = MultibodyPlant(0.0)
    parser = Parser(plant)
    register_models(parser)
    parser.AddModels(url="package://drakegrasp/hands/three_finger_hand.sdf")
    scene = load_scene()
    report = analyze_grasp(scene.plant, scene.plant_context,
                           **scene.analysis_options())
    assert len(report.contacts) == 2
    print("OK", models_dir())
    """
)


def test_non_editable_install_resolves_package_drakegrasp(tmp_path):
    # Build from a copy of the sources so the checkout stays clean.
    src = tmp_path / "src"
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc")
    shutil.copytree(ROOT / "drakegrasp", src / "drakegrasp", ignore=ignore)
    shutil.copytree(ROOT / "models", src / "models", ignore=ignore)
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        if (ROOT / name).exists():
            shutil.copy2(ROOT / name, src / name)
    if not (src / "README.md").exists():
        (src / "README.md").write_text("drakegrasp\n")
    target = tmp_path / "site"
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "install",
            "--no-deps",
            "--quiet",
            "--target",
            str(target),
            str(src),
        ],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert result.returncode == 0, result.stderr[-2000:]
    assert (target / "drakegrasp" / "models" / "package.xml").is_file()
    assert (target / "drakegrasp" / "models" / "objects" / "hex_prism.obj").is_file()
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = dict(os.environ, PYTHONPATH=str(target))
    result = subprocess.run(
        [sys.executable, "-c", CHECK, str(target)],
        cwd=elsewhere,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, result.stderr[-3000:]
    assert result.stdout.startswith("OK")
