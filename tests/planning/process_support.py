"""Work that the pickling tests send to a spawned process (importable there:
tests/planning is on the ``sys.path`` that ``spawn`` hands the child)."""

from __future__ import annotations

import json

from drakegrasp.errors import GraspError

JAW = "package://drakegrasp/hands/parallel_jaw_flat.sdf"
BOX = "package://drakegrasp/objects/box.sdf"


def echo(value):
    """``value`` as the worker unpickled it, pickled back."""
    return value


def inspect_candidates(candidates) -> dict:
    """What a user gets from candidates unpickled in a process that did not plan
    them: their dictionaries, lines and grasp matrices, the type of their
    geometry ids, the refusal of a function that reads a geometry, and the
    contacts found again there after ``apply``."""
    from drakegrasp import find_contacts, force_closure
    from drakegrasp.core.grasp import grasp_matrix
    from drakegrasp.planning import planning_scene
    from drakegrasp.plant.friction import plant_friction

    scene = planning_scene(BOX, hand_url=JAW)
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    out = {"json": [], "str": [], "G": [], "closure": [], "ids": set(), "found": []}
    for c in candidates:
        out["json"].append(json.dumps(c.to_dict(), sort_keys=True))
        out["str"].append(str(c))
        out["G"].append(grasp_matrix(c.grasp))
        out["closure"].append(bool(force_closure(c.grasp).is_closure))
        for k in c.contacts:
            out["ids"] |= {type(k.object_geometry).__name__}
            out["ids"] |= {type(k.finger_geometry).__name__}
            out["ids"] |= {type(k.finger_body_index).__name__}
        c.apply(scene.plant, ctx, object_body=scene.object_body)
        found = find_contacts(scene.plant, ctx, scene.object_body, hand=scene.hand)
        out["found"].append(
            [(k.finger_geometry_label, k.p_OC, k.nhat_O) for k in found]
        )
    try:
        plant_friction(scene.plant, ctx, candidates[0].contacts)
    except GraspError as e:
        out["refused"] = f"{type(e).__name__}: {e}"
    return out
