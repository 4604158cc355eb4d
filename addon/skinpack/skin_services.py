"""Skin services shared by the operators and the glTF exporter hook (no operators here).

Options from a mesh's settings, Compress, the texts that describe a result (stats, pruning),
and swapping the decoded weights in and out for the A/B view. Every function raises
GatherError, SkinpackError, PreviewError or ValueError with a message that names the object;
callers decide how to show it (operator report, export log).
"""

from . import gather, preview
from .io import native, storage


def compression_options(settings):
    """sp_compress_options from plain settings (options_summary() of the mesh settings)."""
    method, budget = settings["method"], settings["budget"]
    if budget == 'ERROR':  # the library finds the fewest weight bits for the K it uses
        return native.make_options(method, settings["max_influences"], max_error=settings["max_error"])
    bits = settings["custom_bits"] if budget == 'CUSTOM' else int(budget)
    return native.make_options(method, settings["max_influences"], vertex_bits=bits)


def budget_text(settings):
    if settings["budget"] == 'ERROR':
        return "max error %g" % settings["max_error"]
    bits = settings["custom_bits"] if settings["budget"] == 'CUSTOM' else int(settings["budget"])
    return "%d bits per vertex for tuple index and weights" % bits


def most_influences(weights):
    """The most non-zero weights of any vertex (for the pruning message)."""
    return int((weights > 0).sum(axis=1).max()) if len(weights) else 0


def compress_skin(name, joints, weights, joint_count, settings):
    """(native.Compressed, stats dict) with the options of settings; errors name `name` and the
    vertex or budget."""
    try:
        options = compression_options(settings)
        compressed = native.compress(joints, weights, joint_count, options)
        return compressed, native.stats_dict(compressed, most_influences(weights))
    except native.SkinpackError as error:
        if error.code in native.PER_VERTEX_ERRORS:
            detail = " (vertex %d)" % error.vertex
        else:
            detail = " (%s, %s)" % (settings["method"], budget_text(settings))
        raise native.SkinpackError("%s: %s%s" % (name, error, detail), error.code, error.vertex)
    except ValueError as error:
        raise ValueError("%s: %s" % (name, error))


def compress_object(obj):
    """Reads, compresses and stores; returns the stored result."""
    skin = gather.gather(obj)
    settings = obj.data.skinpack.options_summary()
    compressed, stats = compress_skin(obj.name, skin.joints, skin.weights, len(skin.joint_names), settings)
    return storage.save_result(obj.data, compressed, stats, skin, settings)


def stores_per_vertex_data(stats):
    """False for a skin with one joint tuple: no per-vertex bits, only the tuple table, so a
    ratio against the table alone would mean nothing."""
    return stats["tuple_bits"] + stats["weight_bits"] > 0


def size_text(stats):
    """Bits a vertex before and after (see stores_per_vertex_data for the one-tuple case)."""
    if not stores_per_vertex_data(stats):
        return "%.1f -> 0 bits/vertex (one joint tuple: only the %d-entry table is stored)" % (
            stats["input_bits_per_vertex"], stats["unique_tuples"])
    return "%.1f -> %.1f bits/vertex (%.1fx)" % (stats["input_bits_per_vertex"], stats["bits_per_vertex"],
                                                stats["ratio"])


def pruning_text(stats):
    """'' when no vertex lost an influence, else how many, from how many, and the weight change."""
    if not stats["pruned_vertices"]:
        return ""
    before = ""
    if "max_input_influences" in stats:  # results stored by older versions lack it
        before = " (up to %d%s before)" % (stats["max_input_influences"],
                                           " or more" if stats["max_input_influences_capped"] else "")
    return ("%d vertices pruned to %d influences%s, max weight change %.3f"
            % (stats["pruned_vertices"], stats["influences"], before, stats["max_pruning_error"]))


def stats_line(stats):
    line = "%s: %s, %d tuples, max error %.2e, RMS %.2e" % (
        stats["method"].upper(), size_text(stats), stats["unique_tuples"], stats["max_error"], stats["rms_error"])
    pruning = pruning_text(stats)
    return line + "; " + pruning if pruning else line


def show_decoded(obj):
    mesh = obj.data
    result = storage.load_result(mesh)
    if result is None or storage.is_stale(mesh, result):
        raise preview.PreviewError("%s: no up-to-date compression result; press Compress first" % obj.name)
    skin = gather.gather(obj)
    if not storage.matches_weights(result, skin):
        raise preview.PreviewError("%s: the weights or deform bones changed since compression; compress again"
                                   % obj.name)
    decoded_joints, decoded_weights = result.decode()
    decoded = gather.decoded_element_weights(skin, decoded_joints, decoded_weights)
    storage.save_originals(mesh, skin.element_counts, skin.element_groups, skin.element_weights)
    try:
        gather.write_element_weights(mesh, skin.element_counts, decoded, skin.element_weights)
    except Exception:
        # Whatever was written so far goes back; unchanged elements are skipped.
        _, _, partial = gather.read_elements(mesh)
        gather.write_element_weights(mesh, skin.element_counts, skin.element_weights, partial)
        storage.clear_originals(mesh)
        raise


def restore_originals(obj):
    mesh = obj.data
    counts, groups, weights = storage.load_originals(mesh)
    current_counts, current_groups, current_weights = gather.read_elements(mesh)
    if not (len(counts) == len(current_counts) and (counts == current_counts).all()
            and (groups == current_groups).all()):
        raise preview.PreviewError("%s: vertices or group memberships changed while the decoded weights were "
                                   "shown; originals kept in the mesh's '%s' property"
                                   % (obj.name, storage.ORIGINAL_KEY))
    gather.write_element_weights(mesh, counts, weights, current_weights)
    storage.clear_originals(mesh)
