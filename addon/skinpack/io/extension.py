"""The SKINPACK_packed_skin extension object (docs/extension/CONTRACT.md) as plain data.

No Blender here: the exporter hook turns the arrays into glTF accessors, the importer reads
the same fields back. Field names and the LUT's component width are defined once, here.
"""

import numpy as np

from . import _abi  # generated from skinpack.h (addon/generate_abi.py)
from . import native

EXTENSION_NAME = "SKINPACK_packed_skin"

COMPONENT_UNSIGNED_BYTE = 5121
COMPONENT_UNSIGNED_SHORT = 5123
COMPONENT_UNSIGNED_INT = 5125
COMPONENT_FLOAT = 5126

VECTOR_TYPES = {1: "SCALAR", 2: "VEC2", 3: "VEC3", 4: "VEC4"}
NUMPY_COMPONENTS = {COMPONENT_UNSIGNED_BYTE: "<u1", COMPONENT_UNSIGNED_SHORT: "<u2",
                    COMPONENT_UNSIGNED_INT: "<u4", COMPONENT_FLOAT: "<f4"}
NORMALIZED_SCALE = {COMPONENT_UNSIGNED_BYTE: 255.0, COMPONENT_UNSIGNED_SHORT: 65535.0}


def joint_component(joint_count):
    """JOINTS_n and LUT entries: u8 up to 256 joints, else u16 (the library's sp_joint_bytes)."""
    return COMPONENT_UNSIGNED_BYTE if native.joint_bytes(joint_count) == 1 else COMPONENT_UNSIGNED_SHORT


class ArrayField:
    """An accessor-to-be: the data, its component type and width, whether min/max are given."""

    def __init__(self, data, component_type, width, bounds=False):
        self.data = np.ascontiguousarray(data, dtype=NUMPY_COMPONENTS[component_type])
        self.component_type = component_type
        self.width = width
        self.bounds = bounds


def extension_fields(compressed, joint_count):
    """The extension's fields for a native.Compressed skin; arrays as ArrayField."""
    skin = compressed.skin
    lut_type = joint_component(joint_count)
    fields = {
        "vertices": ArrayField(compressed.words, COMPONENT_UNSIGNED_INT, int(skin.words_per_vertex)),
        "tupleTable": ArrayField(compressed.lut, lut_type, int(skin.influences), bounds=True),
        "influences": int(skin.influences),
        "jointCount": int(joint_count),
        "method": compressed.method,
        "n": int(skin.codec.n),
        "weightBits": int(skin.weight_bits),
        "tupleBits": int(skin.tuple_bits),
        "maxError": float(skin.codec.max_error),
    }
    if compressed.method == "any":
        fields["axisSamples"] = compressed.axis_samples()
    return fields


# Compact mode's fallback buffer (docs/extension/loaders.md, "The container rule"): JOINTS_0 and
# WEIGHTS_0 keep their accessors, whose views lie in a buffer with no uri and no data, marked
# with this extension object, so a loader without the extension fails to load the file instead
# of reading a rigid, all-zero skin. The views start at 2^24 because three.js fetches a uri-less
# buffer as the page itself; no page is that large. The offset is the library's, as the CLI's.
FALLBACK_GUARD_BYTES = _abi.CONSTANTS["SP_FALLBACK_VIEW_OFFSET"]
FALLBACK_BUFFER_EXTENSIONS = {EXTENSION_NAME: {"fallback": True}}


def fallback_layout(byte_lengths):
    """Byte offsets in the fallback buffer for views of byte_lengths (4-aligned, from
    FALLBACK_GUARD_BYTES), and the buffer's byteLength."""
    offsets, end = [], FALLBACK_GUARD_BYTES
    for length in byte_lengths:
        offsets.append(end)
        end = (end + int(length) + 3) & ~3
    return offsets, end


def accessor_byte_length(component_type, width, count):
    """The bytes count elements of width components of component_type take, tightly packed."""
    return int(count) * int(width) * np.dtype(NUMPY_COMPONENTS[component_type]).itemsize
