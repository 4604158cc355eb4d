"""The whole Khronos validator corpus through one skinpack mode (issue 10's proof).

    python3 check_corpus.py MODE --skinpack BIN --node NODE --validator tools/validate.mjs
                            --work DIR CORPUS_DIR

MODE is info, fallback, compact, meshlets, meshlets_effort (meshlets --meshlet-effort 100) or meshopt
(compact --meshopt). Every .gltf/.glb under CORPUS_DIR goes through
`skinpack info` (info) or `skinpack compress` (the others) and every compressed output through
`skinpack decompress`. A file fails the check when a command

  - crashes (a signal or an exit status other than 0 and 1) or runs longer than the timeout,
  - fails (exit 1) but leaves an output or a temporary file behind,
  - writes an output with a Khronos validator error (code and JSON pointer) its input lacked,
  - writes an output whose JSON differs from the input outside what the extension owns (see
    json_problems), or whose buffer bytes differ for any bufferView skinpack does not own.
"""
import argparse
import base64
import concurrent.futures
import glob
import json
import os
import struct
import subprocess
import sys

EXT = "SKINPACK_packed_skin"
TIMEOUT = 60


def run(cmd):
    try:
        result = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        return None, "timed out after %d s" % TIMEOUT
    return result.returncode, result.stderr.strip()


def command_problems(rc, message, output):
    """Problems with one run: crash, hang, or a failure that left files behind."""
    if rc is None:
        return [message]
    if rc not in (0, 1):
        return ["exit status %d (crash?): %s" % (rc, message[-300:])]
    leftovers = glob.glob(output + ".tmp-*")
    if rc == 1 and os.path.exists(output):
        leftovers.append(output)
    if rc == 0 and not os.path.exists(output):
        return ["exit 0 but no output written"]
    return ["failed (%s) but left %s" % (message[-200:], ", ".join(leftovers))] if leftovers else []


# ---- reading documents (independent of the CLI) ----

def read_document(path):
    """(json, buffers): buffers are bytes or None (external file missing, fallback buffer)."""
    with open(path, "rb") as f:
        data = f.read()
    binary_chunk = None
    if data[:4] == b"glTF":
        length = struct.unpack_from("<I", data, 12)[0]
        document = json.loads(data[20:20 + length])
        offset = 20 + length
        if offset + 8 <= len(data) and struct.unpack_from("<I", data, offset + 4)[0] == 0x004E4942:
            binary_chunk = data[offset + 8:offset + 8 + struct.unpack_from("<I", data, offset)[0]]
    else:
        document = json.loads(data)
    buffers = []
    for index, buffer in enumerate(document.get("buffers", [])):
        uri = buffer.get("uri") if isinstance(buffer, dict) else None
        if uri is None:
            buffers.append(binary_chunk if index == 0 else None)
        elif uri.startswith("data:"):
            try:
                buffers.append(base64.b64decode(uri.split(",", 1)[1]))
            except Exception:  # noqa: BLE001 - a broken data uri in a broken input
                buffers.append(None)
        else:
            buffers.append(resolved(path, uri))
    return document, buffers


def resolved(document_path, uri):
    from urllib.parse import unquote
    if ":" in uri.split("/")[0]:
        return ("uri", uri)
    # realpath: the CLI rebases uris between canonical folders, so an input reached through a
    # symlink (../shared may be one) resolves to the same file by another spelling.
    return ("file", os.path.realpath(os.path.join(os.path.dirname(os.path.abspath(document_path)), unquote(uri))))


def file_bytes(reference):
    if isinstance(reference, tuple) and reference[0] == "file" and os.path.isfile(reference[1]):
        with open(reference[1], "rb") as f:
            return f.read()
    return reference if isinstance(reference, (bytes, bytearray)) else None


# ---- what the extension owns ----

def owned_accessors(before, after):
    """Accessors the extension may change: JOINTS_n/WEIGHTS_n of the primitives that carry (or
    carried) it, the extension's own, and any added at the end."""
    owned = set()
    for doc in (before, after):
        for mesh in doc.get("meshes", []):
            for prim in mesh.get("primitives", []) if isinstance(mesh, dict) else []:
                if not isinstance(prim, dict):
                    continue
                extension = (prim.get("extensions") or {}).get(EXT)
                other = primitive_of(before if doc is after else after, doc, mesh, prim)
                carried = extension is not None or (other is not None and EXT in (other.get("extensions") or {}))
                if not carried:
                    continue
                for name, index in (prim.get("attributes") or {}).items():
                    if name.startswith(("JOINTS_", "WEIGHTS_")):
                        owned.add(index)
                if isinstance(extension, dict):
                    owned.update(v for k, v in extension.items() if k in ("vertices", "tupleTable"))
                    owned.update(v for k, v in (extension.get("meshlets") or {}).items() if not k.startswith("max"))
    return owned


def primitive_of(other_doc, doc, mesh, prim):
    m = doc["meshes"].index(mesh)
    p = mesh["primitives"].index(prim)
    try:
        return other_doc["meshes"][m]["primitives"][p]
    except (KeyError, IndexError, TypeError):
        return None


MESHOPT_NAMES = ("EXT_meshopt_compression", "KHR_meshopt_compression")


def added_meshopt_names(before, after):
    """The meshopt extension names compress --meshopt declared that the input did not have."""
    return {name for key in ("extensionsUsed", "extensionsRequired") for name in after.get(key, []) or []
            if name in MESHOPT_NAMES and name not in (before.get(key, []) or [])}


def without_owned_members(doc, owned, views, lengths, names=()):
    """A copy of doc without the members the extension owns (and the extension names `names`
    compress added), for comparison."""
    doc = json.loads(json.dumps(doc))
    for key in ("extensionsUsed", "extensionsRequired"):
        if key in doc:
            doc[key] = [name for name in doc[key] if name != EXT and name not in names]
            if not doc[key]:
                del doc[key]
    for mesh in doc.get("meshes", []):
        for prim in mesh.get("primitives", []) if isinstance(mesh, dict) else []:
            if not isinstance(prim, dict):
                continue
            attributes = prim.get("attributes")
            if isinstance(attributes, dict) and any(attributes.get(n) in owned for n in attributes
                                                    if n.startswith(("JOINTS_", "WEIGHTS_"))):
                for name in [n for n in attributes if n.startswith(("JOINTS_", "WEIGHTS_"))]:
                    del attributes[name]
            extensions = prim.get("extensions")
            if isinstance(extensions, dict) and EXT in extensions:
                del extensions[EXT]
                if not extensions:
                    del prim["extensions"]
    for key in ("accessors", "bufferViews", "buffers"):
        if isinstance(doc.get(key), list):
            doc[key] = doc[key][:lengths[key]]
    for index in owned:
        if isinstance(doc.get("accessors"), list) and isinstance(index, int) and index < len(doc["accessors"]):
            doc["accessors"][index] = "owned"
    for index in views:
        if isinstance(doc.get("bufferViews"), list) and isinstance(index, int) and index < len(doc["bufferViews"]):
            doc["bufferViews"][index] = "owned"
    for view in doc.get("bufferViews", []):
        if isinstance(view, dict):
            view.pop("byteOffset", None)  # views move when freed bytes are cut before them
            view.pop("byteLength", None)  # a view shrinks when an owned accessor's bytes inside it are cut
    for accessor in doc.get("accessors", []):
        if isinstance(accessor, dict):
            accessor.pop("byteOffset", None)  # ... and the accessors after it in the view move down
    for buffer in doc.get("buffers", []):
        if isinstance(buffer, dict):
            buffer.pop("byteLength", None)
            buffer.pop("uri", None)  # compared as resolved files / bytes instead
    for image in doc.get("images", []):
        if isinstance(image, dict) and isinstance(image.get("uri"), str) and not image["uri"].startswith("data:"):
            image.pop("uri")  # relative uris are rewritten for the output's folder: compared resolved
    return doc


def owned_views(docs, owned):
    views = set()
    for doc in docs:
        for index in owned:
            accessors = doc.get("accessors", [])
            if isinstance(index, int) and index < len(accessors) and isinstance(accessors[index], dict):
                if "bufferView" in accessors[index]:
                    views.add(accessors[index]["bufferView"])
    return views


def view_bytes(doc, buffers, index):
    view = doc["bufferViews"][index]
    if not isinstance(view, dict) or not isinstance(view.get("buffer"), int) or view["buffer"] >= len(buffers):
        return None
    data = file_bytes(buffers[view["buffer"]])
    if data is None:
        return None
    offset = view.get("byteOffset", 0)
    return data[offset:offset + view.get("byteLength", 0)]


ELEMENT = {5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4}
COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}


def accessor_bytes(doc, buffers, index):
    """The bytes an accessor reads (None when they cannot be read: no view, no data, malformed)."""
    try:
        a = doc["accessors"][index]
        view = doc["bufferViews"][a["bufferView"]]
        data = file_bytes(buffers[view["buffer"]])
        element = ELEMENT[a["componentType"]] * COMPONENTS[a["type"]]
        stride = view.get("byteStride", element)
        begin = view.get("byteOffset", 0) + a.get("byteOffset", 0)
        if data is None or a["count"] < 1:
            return None
        return b"".join(bytes(data[begin + i * stride:begin + i * stride + element]) for i in range(a["count"]))
    except (KeyError, IndexError, TypeError):
        return None


def json_problems(input_path, output_path, via_path=None):
    """Differences outside the extension's members, and changed bytes of views it does not own.
    via_path: the compressed file a decompressed output came from (it says what was owned)."""
    before, before_buffers = read_document(input_path)
    after, after_buffers = read_document(output_path)
    via = read_document(via_path)[0] if via_path else after
    owned = owned_accessors(before, via)
    skip = owned_views((before, via, after), owned)
    lengths = {key: len(before.get(key, [])) if isinstance(before.get(key), list) else 0
               for key in ("accessors", "bufferViews", "buffers")}
    names = added_meshopt_names(before, via)
    a = without_owned_members(before, owned, skip, lengths, names)
    b = without_owned_members(after, owned, skip, lengths, names)
    problems = []
    for key in sorted(set(a) | set(b)):
        if a.get(key) != b.get(key):
            problems.append("JSON member %r differs outside the extension" % key)
    if problems:
        return problems
    for index, (x, y) in enumerate(zip(before_buffers, after_buffers)):
        if isinstance(x, tuple) and x[0] == "file" and not (isinstance(y, tuple) and y == x):
            problems.append("buffer %d refers to %s instead of %s" % (index, y, x))
    for kind, ours, read in (("bufferViews", skip, view_bytes), ("accessors", owned, accessor_bytes)):
        for index in range(min(lengths[kind], len(after.get(kind, [])))):
            old = None if index in ours else read(before, before_buffers, index)
            if old is not None and read(after, after_buffers, index) != old:
                problems.append("%s %d: data changed" % (kind, index))
    for key, items in (("images", before.get("images", [])),):
        for index, image in enumerate(items if isinstance(items, list) else []):
            if isinstance(image, dict) and isinstance(image.get("uri"), str) and not image["uri"].startswith("data:"):
                after_uri = after["images"][index].get("uri")
                if resolved(input_path, image["uri"]) != resolved(output_path, after_uri or ""):
                    problems.append("image %d uri %r no longer resolves to the same file" % (index, after_uri))
    return problems


# ---- the validator ----

def validate(node, validator, paths, jobs):
    """{path: set of (code, pointer)} of errors, the validator run in a few batches."""
    errors = {}
    batches = [paths[i::jobs] for i in range(jobs)]

    def one(batch):
        if not batch:
            return ""
        return subprocess.run([node, validator, "--json"] + batch, capture_output=True, text=True).stdout

    with concurrent.futures.ThreadPoolExecutor(jobs) as pool:
        for out in pool.map(one, batches):
            for line in out.splitlines():
                report = json.loads(line)
                errors[report["file"]] = {(m["code"], m.get("pointer", "")) for m in report["issues"]["messages"]
                                          if m["severity"] == 0}
    return errors


# ---- one file ----

def output_name(work, corpus, path, tag):
    relative = os.path.relpath(path, corpus) if not os.path.relpath(path, corpus).startswith("..") else \
        "also_" + os.path.basename(path)
    stem, ext = os.path.splitext(relative)
    out = os.path.join(work, stem.replace(os.sep, "__") + "." + tag + ext)
    return out


def check_file(args, path):
    """Runs the mode's commands on one file; returns (problems, [(input, output)] written)."""
    problems, written = [], []
    if args.mode == "info":
        rc, message = run([args.skinpack, "info", path, "--json"])
        if rc is None or rc not in (0, 1):
            problems.append("info: " + (message if rc is None else "exit status %d: %s" % (rc, message[-300:])))
        return problems, written
    options = {"fallback": ["--fallback"], "compact": ["--compact"], "meshlets": ["--meshlets"],
               "meshlets_effort": ["--meshlets", "--meshlet-effort", "100"],
               "meshopt": ["--compact", "--meshopt"]}[args.mode]
    out = output_name(args.work, args.corpus, path, args.mode)
    rc, message = run([args.skinpack, "compress", path, "-o", out] + options)
    problems += ["compress: " + p for p in command_problems(rc, message, out)]
    if rc != 0 or problems:
        return problems, written
    written.append((path, out, None))
    decoded = output_name(args.work, args.corpus, path, args.mode + "_decoded")
    rc, message = run([args.skinpack, "decompress", out, "-o", decoded])
    problems += ["decompress: " + p for p in command_problems(rc, message, decoded)]
    if rc == 0 and not problems:
        written.append((path, decoded, out))
    elif rc == 1 and not problems:
        problems.append("decompress refused skinpack's own output: " + message[-300:])
    return problems, written


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("mode", choices=["info", "fallback", "compact", "meshlets", "meshlets_effort", "meshopt"])
    parser.add_argument("--skinpack", required=True)
    parser.add_argument("--node", required=True)
    parser.add_argument("--validator", required=True)
    parser.add_argument("--work", required=True)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--also", nargs="*", default=[], help="more files (skinned ones, see make_rich_gltf.py)")
    parser.add_argument("corpus")
    args = parser.parse_args()
    os.makedirs(args.work, exist_ok=True)
    files = sorted(p for p in glob.glob(os.path.join(args.corpus, "**", "*"), recursive=True)
                   if p.endswith((".gltf", ".glb")) and os.path.isfile(p))
    if len(files) < 300:
        raise SystemExit("FAILED: only %d glTF files under %s" % (len(files), args.corpus))
    files += [os.path.abspath(p) for p in args.also]
    failures, written = {}, []
    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        for path, (problems, outputs) in zip(files, pool.map(lambda p: check_file(args, p), files)):
            if problems:
                failures[path] = problems
            written += outputs
    if written:
        inputs = sorted({w[0] for w in written})
        errors = validate(args.node, args.validator, inputs + [w[1] for w in written], args.jobs)
        for source, out, via in written:
            new = errors.get(out, {("VALIDATOR_FAILED", "")}) - errors.get(source, set())
            if new:
                failures.setdefault(source, []).append("%s: new validator errors %s" % (
                    os.path.basename(out), sorted(new)[:5]))
            for problem in json_problems(source, out, via):
                failures.setdefault(source, []).append("%s: %s" % (os.path.basename(out), problem))
    for path in sorted(failures):
        print("FAIL %s" % path)
        for problem in failures[path]:
            print("    " + problem)
    compressed = sum(1 for w in written if w[2] is None)
    packed = sum(1 for w in written if w[2] is None and EXT in json.dumps(read_document(w[1])[0]))
    print("%s: %d files, %d written by compress (%d with the extension), then decompressed; %d failed" % (
        args.mode, len(files), compressed, packed, len(failures)))
    if args.mode != "info" and args.also and packed < len(args.also):
        print("FAILED: a skinned file given with --also was not compressed")
        sys.exit(1)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
