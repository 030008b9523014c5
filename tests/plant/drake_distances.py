"""Drake's own signed distances, pair by pair: the independent route of the tests.

The closing, pose and monitor tests check what the library reports against
``ComputeSignedDistancePairClosestPoints`` of every hand/object geometry pair,
queried one pair at a time (not the library's pairwise query or its reach
filter).  Shared by ``tests/plant`` (on ``sys.path``, see its conftest) and the
fuzz workers (which put this folder on ``sys.path``).
"""

from __future__ import annotations


def hand_object_distances(plant, query, hand, object_body) -> list[tuple]:
    """``(hand body, hand geometry id, object geometry id, ψ)`` of every pair.

    Parameters
    ----------
    plant : MultibodyPlant
    query : QueryObject
        The scene graph's query object in the configuration to measure.
    hand : ModelInstanceIndex
        Every body of this instance is a hand body.
    object_body : RigidBody

    Returns
    -------
    list of (RigidBody, GeometryId, GeometryId, float)
        One row per pair of collision geometries that is not filtered, in the
        order of the hand's bodies and geometries; ψ in metres (negative when
        the pair penetrates).
    """
    inspector = query.inspector()
    return [
        (body, gh, go, query.ComputeSignedDistancePairClosestPoints(go, gh).distance)
        for body in (plant.get_body(i) for i in plant.GetBodyIndices(hand))
        for gh in plant.GetCollisionGeometriesForBody(body)
        for go in plant.GetCollisionGeometriesForBody(object_body)
        if not inspector.CollisionFiltered(go, gh)
    ]
