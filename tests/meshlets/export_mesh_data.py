"""Dumps a skinned mesh of a .blend file to the raw format tests/meshlets/mesh_data.h reads.

    blender -b FILE.blend --factory-startup --python-exit-code 1 --python export_mesh_data.py -- \
        OUT.spmd [--object NAME] [--min-triangles N]

The mesh is the bind pose (armature in rest position) of every mesh object that is skinned by
one armature (Armature modifier) or rigidly parented to one of its bones, joined in armature
space and triangulated. Influences: the vertex groups of deform bones (joint = bone index in
the armature), the 8 largest per vertex; a bone-parented object gets its parent bone at weight 1.
--min-triangles N applies the smallest Subdivision Surface level that reaches N triangles
(Blender interpolates the vertex-group weights), for scale tests.

Format (little-endian): "SPMD", u32 version 1, u32 vertex_count, u32 index_count,
u32 joint_count, u32 influences (8); then f32 positions[vertex_count][3],
u32 indices[index_count], u16 joints[vertex_count][8], f32 weights[vertex_count][8].
"""
import struct
import sys

import bpy
import numpy as np

MAX_INFLUENCES = 8


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    out, name, min_triangles = None, None, 0
    i = 0
    while i < len(argv):
        if argv[i] == "--object":
            name, i = argv[i + 1], i + 2
        elif argv[i] == "--min-triangles":
            min_triangles, i = int(argv[i + 1]), i + 2
        else:
            out, i = argv[i], i + 1
    if not out:
        raise SystemExit("usage: ... -- OUT.spmd [--object NAME] [--min-triangles N]")
    return out, name, min_triangles


def armature_of(obj):
    if obj.parent and obj.parent.type == "ARMATURE" and obj.parent_type == "BONE":
        return obj.parent
    return obj.find_armature()


def skinned_objects(name):
    if name:
        obj = bpy.data.objects[name]
        return armature_of(obj), [obj]
    candidates = [o for o in bpy.data.objects if o.type == "MESH" and len(o.data.polygons) and armature_of(o)]
    if not candidates:
        raise SystemExit("no skinned mesh in this file")
    # the armature that drives the most polygons, and everything it drives
    counts = {}
    for o in candidates:
        counts[armature_of(o).name] = counts.get(armature_of(o).name, 0) + len(o.data.polygons)
    armature = bpy.data.objects[max(sorted(counts), key=lambda a: counts[a])]
    return armature, sorted((o for o in candidates if armature_of(o) == armature), key=lambda o: o.name)


def subdivision_level(objects, min_triangles):
    sides = sum(len(p.vertices) for o in objects for p in o.data.polygons)
    level = 0
    # a level-L subdivision of an n-gon has n * 4^(L-1) quads, i.e. 2 n 4^(L-1) triangles
    while min_triangles and (level == 0 or 2 * sides * 4 ** (level - 1) < min_triangles):
        level += 1
    return level


def evaluated_mesh(obj, level):
    for modifier in obj.modifiers:
        modifier.show_viewport = False  # the bind pose: no armature deformation
    if level:
        subsurf = obj.modifiers.new("skinpack_subdivision", "SUBSURF")
        subsurf.levels = level
        subsurf.show_viewport = True
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph)
    return evaluated, evaluated.to_mesh()


def influences(obj, mesh, bone_index):
    count = len(mesh.vertices)
    joints = np.zeros((count, MAX_INFLUENCES), dtype=np.uint16)
    weights = np.zeros((count, MAX_INFLUENCES), dtype=np.float32)
    if obj.parent_type == "BONE" and obj.parent_bone in bone_index and not obj.find_armature():
        joints[:, 0] = bone_index[obj.parent_bone]
        weights[:, 0] = 1.0
        return joints, weights
    group_joint = {g.index: bone_index[g.name] for g in obj.vertex_groups if g.name in bone_index}
    for v in mesh.vertices:
        pairs = sorted(((g.weight, group_joint[g.group]) for g in v.groups if g.group in group_joint and g.weight > 0),
                       key=lambda p: (-p[0], p[1]))[:MAX_INFLUENCES]
        for slot, (weight, joint) in enumerate(pairs):
            joints[v.index, slot] = joint
            weights[v.index, slot] = weight
    return joints, weights


def main():
    out, name, min_triangles = parse_args()
    armature, objects = skinned_objects(name)
    armature.data.pose_position = "REST"
    bones = list(armature.data.bones)
    bone_index = {b.name: i for i, b in enumerate(bones) if b.use_deform}
    for o in objects:  # bone-parented parts are rigid: their bone counts even if not deform
        if o.parent_type == "BONE" and o.parent_bone:
            bone_index.setdefault(o.parent_bone, [b.name for b in bones].index(o.parent_bone))
    level = subdivision_level(objects, min_triangles)
    to_armature = armature.matrix_world.inverted()

    positions, indices, joints, weights, base = [], [], [], [], 0
    for obj in objects:
        evaluated, mesh = evaluated_mesh(obj, level)
        mesh.calc_loop_triangles()
        matrix = np.array(to_armature @ evaluated.matrix_world, dtype=np.float64)
        local = np.zeros(len(mesh.vertices) * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", local)
        local = local.reshape(-1, 3).astype(np.float64)
        positions.append((local @ matrix[:3, :3].T + matrix[:3, 3]).astype(np.float32))
        tris = np.zeros(len(mesh.loop_triangles) * 3, dtype=np.uint32)
        mesh.loop_triangles.foreach_get("vertices", tris)
        indices.append(tris + base)
        j, w = influences(obj, mesh, bone_index)
        joints.append(j)
        weights.append(w)
        base += len(mesh.vertices)
        evaluated.to_mesh_clear()

    positions, indices = np.concatenate(positions), np.concatenate(indices)
    joints, weights = np.concatenate(joints), np.concatenate(weights)
    with open(out, "wb") as f:
        f.write(b"SPMD")
        f.write(struct.pack("<5I", 1, len(positions), len(indices), len(bones), MAX_INFLUENCES))
        for array in (positions, indices, joints, weights):
            f.write(np.ascontiguousarray(array).tobytes())
    print("export_mesh_data: %s: %d objects, subdivision %d, %d vertices, %d triangles, %d joints" %
          (out, len(objects), level, len(positions), len(indices) // 3, len(bones)))


main()
