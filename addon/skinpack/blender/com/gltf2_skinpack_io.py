"""Imports from Blender's glTF add-on that were renamed between versions (4.3 shortened the
exporter module names), plus the extension's fixed names (docs/extension/CONTRACT.md)."""

EXTENSION_NAME = "SKINPACK_packed_skin"

COMPONENT_UNSIGNED_BYTE = 5121
COMPONENT_UNSIGNED_SHORT = 5123
COMPONENT_UNSIGNED_INT = 5125
COMPONENT_FLOAT = 5126

VECTOR_TYPES = {1: "SCALAR", 2: "VEC2", 3: "VEC3", 4: "VEC4"}

NUMPY_COMPONENTS = {COMPONENT_UNSIGNED_BYTE: "<u1", COMPONENT_UNSIGNED_SHORT: "<u2",
                    COMPONENT_UNSIGNED_INT: "<u4", COMPONENT_FLOAT: "<f4"}
NORMALIZED_SCALE = {COMPONENT_UNSIGNED_BYTE: 255.0, COMPONENT_UNSIGNED_SHORT: 65535.0}


def gltf_io():
    from io_scene_gltf2.io.com import gltf2_io
    return gltf2_io


def extension_class():
    from io_scene_gltf2.io.com.gltf2_io_extensions import Extension
    return Extension


def binary_data_class():
    try:
        from io_scene_gltf2.io.exp.gltf2_io_binary_data import BinaryData
    except ImportError:  # Blender 4.3+
        from io_scene_gltf2.io.exp.binary_data import BinaryData
    return BinaryData
