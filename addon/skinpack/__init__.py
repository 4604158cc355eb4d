"""Skinpack: compressed skinning weights for Blender (Kuth & Meyer, Vertex-Blend Attribute Compression).

The compression itself is the native library bundled next to this file (libskinpack.so,
loaded with ctypes by native.py); this package gathers weights, shows the error, swaps the
decoded weights in for an A/B comparison and hooks into Blender's own glTF exporter/importer.
"""

bl_info = {
    "name": "Skinpack",
    "author": "Skinpack authors",
    "version": (1, 0, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Object Data > Skinpack; File > Export > glTF 2.0 > Skinpack",
    "description": "Compress skinning weights, preview the error, export SKINPACK_packed_skin glTF",
    "doc_url": "",
    "category": "Import-Export",
}

import bpy  # noqa: E402

from . import operators, panel, properties  # noqa: E402
from .blender.exp import gltf2_skinpack_export  # noqa: E402

# The glTF add-on looks these names up on every enabled add-on's top-level module.
from .blender.exp.gltf2_skinpack_export import glTF2ExportUserExtension, register_panel  # noqa: E402,F401
from .blender.imp.gltf2_skinpack_import import glTF2ImportUserExtension  # noqa: E402,F401


def menu_func_export(self, context):
    self.layout.operator(operators.SKINPACK_OT_export_gltf.bl_idname, text="Skinpack Compressed glTF (.glb)")


def register():
    properties.register()
    operators.register()
    panel.register()
    gltf2_skinpack_export.register()
    bpy.types.TOPBAR_MT_file_export.append(menu_func_export)


def unregister():
    bpy.types.TOPBAR_MT_file_export.remove(menu_func_export)
    gltf2_skinpack_export.unregister()
    panel.unregister()
    operators.unregister()
    properties.unregister()
