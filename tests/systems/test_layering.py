"""The systems module is the outer ring: nothing inside imports it."""

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "drakegrasp"
INNER = ["plant", "quality", "batch"] + [
    p.stem
    for p in PACKAGE.glob("*.py")
    if p.stem in {"antipodal", "closure", "contact", "grasp", "friction_cone"}
]


def _imports(path: Path) -> set[str]:
    names = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            names.add(node.module)
    return names


def test_inner_layers_never_import_systems():
    files = []
    for name in INNER:
        target = PACKAGE / name
        files += (
            sorted(target.rglob("*.py"))
            if target.is_dir()
            else [target.with_suffix(".py")]
        )
    assert len(files) > 10
    offenders = [
        str(f.relative_to(PACKAGE))
        for f in files
        if any(m.startswith("drakegrasp.systems") for m in _imports(f))
    ]
    assert not offenders


def test_systems_imports_the_plant_layer():
    assert "drakegrasp.plant.analysis" in _imports(PACKAGE / "systems.py")
