"""The compressed result and the A/B originals, stored on the mesh so they survive save/reload.

Custom properties (ID properties) are used because they travel with the mesh datablock, take
part in undo and need no registered class to be read back. Binary arrays are stored as bytes;
numbers that can exceed 32 bits (codec parameters) go into a JSON string because ID property
integers are 32-bit in Blender 3.x.
"""

import json
import zlib

import numpy as np

from . import native

RESULT_KEY = "skinpack_result"
ORIGINAL_KEY = "skinpack_original_weights"
PREVIEW_KEY = "skinpack_preview"
FORMAT_VERSION = 1


class StoredResult:
    """A compressed skin as stored on a mesh."""

    def __init__(self, info, words, lut, per_vertex_error, per_vertex_pruning):
        self.info = info  # dict: codec parameters, joint names, stats
        self.words = words
        self.lut = lut
        self.per_vertex_error = per_vertex_error
        self.per_vertex_pruning = per_vertex_pruning

    @property
    def stats(self):
        return self.info["stats"]

    def decode(self):
        info = self.info
        return native.decompress(info["method"], info["influences"], info["n"], info["axis_samples"],
                                 self.words, info["vertex_count"], info["tuple_bits"], self.lut,
                                 info["joint_count"])


def save_result(mesh, compressed, stats, skin_weights, settings_summary):
    """Stores a native.Compressed skin, its stats (native.stats_dict) and what it was made from."""
    stats = dict(stats, ignored_groups=len(skin_weights.ignored_groups))
    info = {
        "version": FORMAT_VERSION,
        "method": compressed.method,
        "influences": int(compressed.skin.influences),
        "n": int(compressed.skin.codec.n),
        "axis_samples": compressed.axis_samples(),
        "tuple_bits": int(compressed.skin.tuple_bits),
        "weight_bits": int(compressed.skin.weight_bits),
        "words_per_vertex": int(compressed.skin.words_per_vertex),
        "vertex_count": int(compressed.skin.vertex_count),
        "joint_count": int(compressed.skin.joint_count),
        "joint_names": skin_weights.joint_names,
        "armature": skin_weights.armature.name,
        "weights_fingerprint": weights_fingerprint(skin_weights),
        "settings": settings_summary,
        "stats": stats,
    }
    mesh[RESULT_KEY] = {
        "info": json.dumps(info),
        "words": compressed.words.astype("<u4").tobytes(),
        "lut": compressed.lut.astype("<u2").tobytes(),
        "per_vertex_error": compressed.per_vertex_error.astype("<f4").tobytes(),
        "per_vertex_pruning": compressed.per_vertex_pruning.astype("<f4").tobytes(),
    }
    return load_result(mesh)


def weights_fingerprint(skin_weights):
    """CRC of every group element (counts, groups, weight bits): tells whether the weights the
    result was made from are still the mesh's."""
    crc = zlib.crc32(skin_weights.element_counts.astype("<i4").tobytes())
    crc = zlib.crc32(skin_weights.element_groups.astype("<i4").tobytes(), crc)
    return zlib.crc32(skin_weights.element_weights.astype("<f4").tobytes(), crc)


def matches_weights(result, skin_weights):
    return (result.info.get("weights_fingerprint") == weights_fingerprint(skin_weights)
            and result.info["joint_names"] == skin_weights.joint_names)


def load_result(mesh):
    """The stored result, or None if the mesh has none (or one this version cannot read)."""
    if mesh is None or RESULT_KEY not in mesh:
        return None
    group = mesh[RESULT_KEY]
    try:
        info = json.loads(group["info"])
        if info.get("version") != FORMAT_VERSION:
            return None
        return StoredResult(info,
                            np.frombuffer(bytes(group["words"]), dtype="<u4"),
                            np.frombuffer(bytes(group["lut"]), dtype="<u2"),
                            np.frombuffer(bytes(group["per_vertex_error"]), dtype="<f4"),
                            np.frombuffer(bytes(group["per_vertex_pruning"]), dtype="<f4"))
    except (KeyError, TypeError, ValueError):
        return None


def is_stale(mesh, result):
    """True when the mesh no longer has the vertices the result was made from."""
    return result is None or result.info["vertex_count"] != len(mesh.vertices)


def clear_result(mesh):
    if RESULT_KEY in mesh:
        del mesh[RESULT_KEY]


# --- A/B originals ----------------------------------------------------------------------------

def save_originals(mesh, counts, groups, weights):
    mesh[ORIGINAL_KEY] = {
        "counts": counts.astype("<i4").tobytes(),
        "groups": groups.astype("<i4").tobytes(),
        "weights": weights.astype("<f4").tobytes(),
    }


def load_originals(mesh):
    if ORIGINAL_KEY not in mesh:
        return None
    group = mesh[ORIGINAL_KEY]
    return (np.frombuffer(bytes(group["counts"]), dtype="<i4"),
            np.frombuffer(bytes(group["groups"]), dtype="<i4"),
            np.frombuffer(bytes(group["weights"]), dtype="<f4"))


def showing_decoded(mesh):
    return mesh is not None and ORIGINAL_KEY in mesh


def clear_originals(mesh):
    if ORIGINAL_KEY in mesh:
        del mesh[ORIGINAL_KEY]
