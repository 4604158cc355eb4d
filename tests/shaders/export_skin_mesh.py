"""Exports a skinned mesh from a .blend (or .glb) for the shader tests and the GPU benchmark.

    blender -b FILE --factory-startup --python-exit-code 1 --python export_skin_mesh.py -- \
        --object RE_Player --output out.spskin [--subdivide LEVELS] [--name NAME] [--join]

Writes the SPSKIN01 layout that tests/shaders/sp_gpu.h documents: bind-pose positions in mesh
space, triangles, up to 8 (joint, weight) pairs per vertex from deform-bone vertex groups, and
one pose: rest-to-posed 3x4 matrices of the deform bones, for a few bones rotated by fixed
angles (deterministic, so C and GPU skin the same pose).
"""
import argparse
import math
import struct
import sys

import bpy
import mathutils

MAX_INFLUENCES = 8


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser()
    parser.add_argument("--object", help="mesh object name (default: the first mesh with an armature)")
    parser.add_argument("--import-gltf", help="import this .glb/.gltf first (for assets that are not .blend)")
    parser.add_argument("--output", required=True)
    parser.add_argument("--subdivide", type=int, default=0, help="Catmull-Clark levels applied before export")
    parser.add_argument("--name", default=None)
    parser.add_argument("--join", action="store_true",
                        help="join every mesh skinned to the same armature into one (multi-part characters)")
    return parser.parse_args(argv)


def find_skinned_object(name):
    if name:
        obj = bpy.data.objects.get(name)
        if obj is None or obj.type != "MESH":
            raise SystemExit(f"no mesh object named {name!r}")
        return obj
    candidates = [o for o in bpy.data.objects if o.type == "MESH" and o.find_armature() is not None]
    if not candidates:
        raise SystemExit("no skinned mesh in the file")
    return max(candidates, key=lambda o: len(o.data.vertices))


def pose_some_bones(rig):
    """Rotates every third deform bone about a fixed axis; angles grow along the bone list."""
    deform = [pb for pb in rig.pose.bones if pb.bone.use_deform]
    for index, pose_bone in enumerate(deform):
        if index % 3 != 1:
            continue
        pose_bone.rotation_mode = "XYZ"
        angle = math.radians(10.0 + (index * 7) % 35)
        pose_bone.rotation_euler = (angle, 0.5 * angle, -0.25 * angle)
    bpy.context.view_layer.update()
    return deform


def main():
    args = parse_args()
    if args.import_gltf:
        bpy.ops.import_scene.gltf(filepath=args.import_gltf)
    obj = find_skinned_object(args.object)
    rig = obj.find_armature()
    if rig is None:
        raise SystemExit(f"{obj.name} has no armature")
    if args.join:
        parts = [o for o in bpy.data.objects if o.type == "MESH" and o.find_armature() == rig]
        bpy.ops.object.select_all(action="DESELECT")
        for part in parts:
            part.select_set(True)
        bpy.context.view_layer.objects.active = obj
        bpy.ops.object.join()  # vertex groups merge by name, i.e. by bone

    # Work on a copy of the mesh without the armature deformation: bind pose, optional subdivision
    # (Blender interpolates the vertex groups when a Subdivision modifier is applied).
    for modifier in list(obj.modifiers):
        if modifier.type != "SUBSURF":
            obj.modifiers.remove(modifier)
    if args.subdivide > 0:
        modifier = obj.modifiers.new("export_subdivision", "SUBSURF")
        modifier.levels = args.subdivide
        modifier.render_levels = args.subdivide
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph)
    mesh = bpy.data.meshes.new_from_object(evaluated, preserve_all_data_layers=True, depsgraph=depsgraph)
    mesh.calc_loop_triangles()

    deform = pose_some_bones(rig)
    joint_of_bone = {pb.name: i for i, pb in enumerate(deform)}
    joint_of_group = {g.index: joint_of_bone[g.name] for g in obj.vertex_groups if g.name in joint_of_bone}

    positions = bytearray()
    joints = bytearray()
    weights = bytearray()
    unweighted = 0
    for vertex in mesh.vertices:
        positions += struct.pack("<3f", *vertex.co)
        pairs = [(g.weight, joint_of_group[g.group]) for g in vertex.groups
                 if g.group in joint_of_group and g.weight > 0.0]
        pairs.sort(key=lambda p: (-p[0], p[1]))
        pairs = pairs[:MAX_INFLUENCES]
        if not pairs:
            # No deform-bone weight: libskinpack needs one influence per vertex, so such a
            # vertex follows the first deform bone (reported below; RE_Player has none).
            pairs = [(1.0, 0)]
            unweighted += 1
        pairs += [(0.0, 0)] * (MAX_INFLUENCES - len(pairs))
        joints += struct.pack(f"<{MAX_INFLUENCES}H", *[j for _, j in pairs])
        weights += struct.pack(f"<{MAX_INFLUENCES}f", *[w for w, _ in pairs])

    indices = bytearray()
    for triangle in mesh.loop_triangles:
        indices += struct.pack("<3I", *triangle.vertices)

    # Skin matrix of a deform bone in mesh space: mesh^-1 * rig * posed * rest^-1 * rig^-1 * mesh.
    to_rig = rig.matrix_world.inverted() @ obj.matrix_world
    from_rig = to_rig.inverted()
    pose = bytearray()
    for pose_bone in deform:
        skin = from_rig @ pose_bone.matrix @ pose_bone.bone.matrix_local.inverted() @ to_rig
        for row in range(3):
            pose += struct.pack("<4f", *skin[row])

    name = (args.name or obj.name).encode()[:63]
    with open(args.output, "wb") as out:
        out.write(b"SPSKIN01")
        out.write(struct.pack("<5I", len(mesh.vertices), len(mesh.loop_triangles), len(deform), MAX_INFLUENCES, 1))
        out.write(positions)
        out.write(indices)
        out.write(joints)
        out.write(weights)
        out.write(pose)
        out.write(name + b"\0" * (64 - len(name)))
    print(f"export_skin_mesh: {obj.name}: {len(mesh.vertices)} vertices, {len(mesh.loop_triangles)} triangles, "
          f"{len(deform)} joints, {unweighted} vertices without deform weights -> {args.output}")


main()
