"""Reading skin weights from a Blender mesh, by the glTF exporter's rule.

Only vertex groups named after a deform bone of the object's armature are influences
(`Object.find_armature()`, `Bone.use_deform`), exactly what the glTF exporter writes as
JOINTS/WEIGHTS; every other group is ignored and counted so the panel can say so.

Speed: Blender 3.4 has no bulk accessor for vertex-group weights. Measured on RE_Player
subdivided to 178k vertices (docs/benchmarks-blender.md): one pass over `vertex.groups`
with bound appends 0.26 s, per-vertex `groups.foreach_get` 0.21 s for the indices alone,
bmesh deform layer 0.71 s, a temporary Geometry Nodes modifier storing every group as a float
attribute read with `foreach_get` 0.86 s. The single pass is the fastest path and everything
after it is numpy; the pass also records every group element in mesh order, which is what the
A/B toggle needs to write weights back bit-exactly.
"""

import numpy as np

from .io import native


class GatherError(Exception):
    """Invalid input; the message names the object and how many vertices are affected."""


class SkinWeights:
    """Flat copy of a mesh's vertex-group elements plus the dense skin the library takes."""

    def __init__(self):
        self.armature = None
        self.joint_names = []  # deform bone names; a joint index is a position in this list
        self.ignored_groups = []  # vertex groups that are not deform bones of the armature
        self.element_counts = None  # (V,) group elements per vertex, in mesh order
        self.element_groups = None  # (E,) vertex group index of every element
        self.element_weights = None  # (E,) float32 weight of every element, bit-exact
        self.element_joints = None  # (E,) joint index or -1 for a non-deform group
        self.joints = None  # (V, S) uint16, S = most influences of any vertex
        self.weights = None  # (V, S) float32, zero-padded

    @property
    def vertex_count(self):
        return len(self.element_counts)


def find_armature(obj):
    """The armature deforming obj (modifier or armature parent), as the glTF exporter finds it."""
    if obj is None or obj.type != 'MESH':
        return None
    return obj.find_armature()


def deform_bone_names(armature):
    return [bone.name for bone in armature.data.bones if bone.use_deform]


def group_summary(obj):
    """(deform group count, ignored group names) for the panel, without reading weights."""
    armature = find_armature(obj)
    if armature is None:
        return 0, [g.name for g in obj.vertex_groups]
    names = set(deform_bone_names(armature))
    deform = [g.name for g in obj.vertex_groups if g.name in names]
    return len(deform), [g.name for g in obj.vertex_groups if g.name not in names]


def read_elements(mesh):
    """(counts, groups, weights) of every vertex-group element in mesh order."""
    counts = np.empty(len(mesh.vertices), dtype=np.int32)
    groups = []
    weights = []
    add_group = groups.append
    add_weight = weights.append
    for index, vertex in enumerate(mesh.vertices):
        elements = vertex.groups
        counts[index] = len(elements)
        for element in elements:
            add_group(element.group)
            add_weight(element.weight)
    return counts, np.array(groups, dtype=np.int32), np.array(weights, dtype=np.float32)


def write_element_weights(mesh, counts, weights, current):
    """Writes one weight per group element (read_elements order) where it differs from current.

    `groups.foreach_set` writes the stored float32 as is; the `weight` setter (and
    VertexGroup.add, bmesh) clamp to [0, 1] and would lose weights above 1, which real rigs
    have. Only vertices with a changed element are touched.
    """
    if len(counts) != len(mesh.vertices):
        raise GatherError("%s: the vertex count changed (%d, expected %d)" % (mesh.name, len(mesh.vertices), len(counts)))
    weights = np.ascontiguousarray(weights, dtype=np.float32)
    vertex_of = np.repeat(np.arange(len(counts)), counts)
    differs = weights.view(np.uint32) != np.ascontiguousarray(current, dtype=np.float32).view(np.uint32)
    changed = np.nonzero(np.bincount(vertex_of[differs], minlength=len(counts)))[0]
    ends = np.cumsum(counts)
    starts = ends - counts
    vertices = mesh.vertices
    for index in changed.tolist():
        elements = vertices[index].groups
        if len(elements) != counts[index]:
            raise GatherError("%s: the vertex groups of vertex %d changed" % (mesh.name, index))
        elements.foreach_set("weight", weights[starts[index]:ends[index]])


def checked_armature(obj):
    """The armature deforming obj and its deform bone names; GatherError where there is none."""
    name = obj.name if obj else "<none>"
    if obj is None or obj.type != 'MESH':
        raise GatherError("%s is not a mesh" % name)
    if obj.mode == 'EDIT':
        raise GatherError("%s is in Edit Mode; switch to Object Mode first" % name)
    armature = find_armature(obj)
    if armature is None:
        raise GatherError("%s is not deformed by an armature (no Armature modifier or armature parent)" % name)
    joint_names = deform_bone_names(armature)
    if len(joint_names) > native.SP_MAX_JOINTS:
        raise GatherError("%s: armature %s has %d deform bones, more than the supported %d"
                          % (name, armature.name, len(joint_names), native.SP_MAX_JOINTS))
    return armature, joint_names


def check_influences(name, armature, deform, weights, vertex_of, vertex_count):
    """The used elements (deform, weight > 0) and each vertex's count of them; GatherError for
    non-finite or negative deform weights and for vertices with no influence."""
    bad = deform & ~np.isfinite(weights)
    if bad.any():
        raise GatherError("%s: %d vertices have non-finite (NaN or infinite) weights"
                          % (name, len(np.unique(vertex_of[bad]))))
    bad = deform & (weights < 0)
    if bad.any():
        raise GatherError("%s: %d vertices have negative weights" % (name, len(np.unique(vertex_of[bad]))))
    # Zero weights are not influences (the exporter drops them too).
    used = deform & (weights > 0)
    influence_count = np.bincount(vertex_of[used], minlength=vertex_count)
    unweighted = int((influence_count == 0).sum())
    if unweighted:
        raise GatherError("%s: %d of %d vertices have no weight on a deform bone of %s (assign them, "
                          "e.g. Weight Paint or Automatic Weights)" % (name, unweighted, vertex_count, armature.name))
    return used, influence_count


def dense_influences(result, used, joints, weights, vertex_of, influence_count):
    """result.joints / result.weights as dense (V, stride) arrays, stride the most influences a
    vertex has: every influence goes to the library, which keeps the K strongest and reports the
    pruning. Slot = rank of the element among its vertex's used elements."""
    vertex_count, stride = len(influence_count), int(influence_count.max())
    used_vertices = vertex_of[used]
    starts = np.concatenate(([0], np.cumsum(influence_count)[:-1]))
    slots = np.arange(len(used_vertices)) - starts[used_vertices]
    result.joints = np.zeros((vertex_count, stride), dtype=np.uint16)
    result.weights = np.zeros((vertex_count, stride), dtype=np.float32)
    result.joints[used_vertices, slots] = joints[used]
    result.weights[used_vertices, slots] = weights[used]


def gather(obj):
    """Reads obj's deform weights; raises GatherError with a clear message on invalid input."""
    armature, joint_names = checked_armature(obj)
    name = obj.name
    joint_of_name = {bone: index for index, bone in enumerate(joint_names)}
    group_to_joint = np.array([joint_of_name.get(g.name, -1) for g in obj.vertex_groups] + [-1], dtype=np.int64)
    if not (group_to_joint[:-1] >= 0).any():
        raise GatherError("%s has no vertex group named after a deform bone of %s" % (name, armature.name))

    result = SkinWeights()
    result.armature = armature
    result.joint_names = joint_names
    result.ignored_groups = [g.name for g in obj.vertex_groups if g.name not in joint_of_name]
    counts, groups, weights = read_elements(obj.data)
    result.element_counts, result.element_groups, result.element_weights = counts, groups, weights
    vertex_count = len(counts)
    if vertex_count == 0:
        raise GatherError("%s has no vertices" % name)

    # Elements of groups beyond the object's list (stale data) count as non-deform.
    safe_groups = np.where((groups >= 0) & (groups < len(group_to_joint) - 1), groups, -1)
    joints = group_to_joint[safe_groups]
    result.element_joints = joints
    vertex_of = np.repeat(np.arange(vertex_count), counts)
    used, influence_count = check_influences(name, armature, joints >= 0, weights, vertex_of, vertex_count)
    dense_influences(result, used, joints, weights, vertex_of, influence_count)
    return result


def decoded_element_weights(skin_weights, decoded_joints, decoded_weights):
    """New per-element weights for the A/B view: a deform element gets its joint's decoded
    weight (0 if pruned), a non-deform element keeps its value. Memberships stay as they are,
    so the originals can be written back element by element."""
    vertex_of = np.repeat(np.arange(skin_weights.vertex_count), skin_weights.element_counts)
    joints = skin_weights.element_joints
    match = (decoded_joints[vertex_of].astype(np.int64) == joints[:, None]) & (decoded_weights[vertex_of] > 0)
    new = (decoded_weights[vertex_of] * match).sum(axis=1).astype(np.float32)
    return np.where(joints >= 0, new, skin_weights.element_weights).astype(np.float32)
