"""Skinpack: compressed skinning weights for Blender (Kuth & Meyer, Vertex-Blend Attribute Compression).

The compression itself is the native library bundled in io/ (libskinpack, loaded with ctypes
by io/native.py); this package gathers weights, shows the error, swaps the decoded weights in
for an A/B comparison and hooks into Blender's own glTF exporter/importer.

Layout (as io_scene_gltf2 separates blender/ from io/):
  io/            Blender-free: native binding, stored-result format, extension fields
  skin_services  compress, options, A/B swap: shared by operators and the exporter, no operators
  gather, preview, meshlet_preview   reading weights, colour previews (Blender data)
  operators, panel, properties       the UI
  blender/exp, blender/imp           glTF exporter/importer user extensions
Installed from the zip it is a legacy add-on (bl_info, Blender 3.x-4.1) and, through
blender_manifest.toml, an Extension (Blender 4.2+).
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

import sys  # noqa: E402

# Re-enabling after an update re-runs this file in the same module: drop the old submodules so
# that the imports below load the new files (and the new library copy), not a mix of versions.
# `from . import x` would hand back the old submodule still bound in this namespace, so those
# names go too.
if "bpy" in locals():
    for _name in [name for name in sys.modules if name.startswith(__name__ + ".")]:
        del sys.modules[_name]
        globals().pop(_name[len(__name__) + 1:].split(".")[0], None)

import bpy  # noqa: E402

from .io import native  # noqa: E402


def library_cache_dir():
    """A folder no add-on install or update writes to, for native.py's private library copy."""
    extension_path_user = getattr(bpy.utils, "extension_path_user", None)
    if extension_path_user is not None and __package__.startswith("bl_ext."):
        return extension_path_user(__package__, path="library", create=True)  # Blender 4.2+ Extension
    return bpy.utils.user_resource('DATAFILES', path="skinpack", create=True)


# Before the modules below: properties.py asks the library for its defaults when imported.
native.set_cache_dir(library_cache_dir())

from . import operators, panel, properties  # noqa: E402
from .blender.exp import gltf2_skinpack_export  # noqa: E402

# The glTF add-on looks these names up on every enabled add-on's top-level module.
from .blender.exp.gltf2_skinpack_export import glTF2ExportUserExtension, register_panel  # noqa: E402,F401
from .blender.imp.gltf2_skinpack_import import glTF2ImportUserExtension  # noqa: E402,F401


def glTF2_pre_export_callback(export_settings):
    gltf2_skinpack_export.pre_export(export_settings)


def glTF2_post_export_callback(export_settings):
    gltf2_skinpack_export.post_export(export_settings)


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
