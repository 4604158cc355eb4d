"""Broken inputs get a clear error, exit status 1 and no output file (issue 3, item 3).

    python3 check_bad_files.py --skinpack BIN --work DIR ASSET.glb

From ASSET (a skinned .glb with float weights, e.g. Fox.glb) it makes one broken file per case,
standard and packed, and runs the commands that read it. A case passes when the command exits
with 1 (a crash is a signal or another code), prints "Error: <file>: <reason>" on stderr where
reason contains the expected words, and leaves neither OUT nor a temporary file behind.
"""
import argparse
import copy
import glob
import json
import os
import struct
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gltf_read  # noqa: E402

EXT = gltf_read.EXTENSION


def load(path):
    doc = gltf_read.Gltf(path)
    return doc.json, bytearray(doc.bin)


def skinned(document):
    for mesh in document["meshes"]:
        for prim in mesh["primitives"]:
            if "JOINTS_0" in prim["attributes"] or EXT in prim.get("extensions", {}):
                return prim
    raise SystemExit("no skinned primitive")


def element_offset(document, accessor, index):
    a = document["accessors"][accessor]
    view = document["bufferViews"][a["bufferView"]]
    size = {5121: 1, 5123: 2, 5125: 4, 5126: 4}[a["componentType"]] * gltf_read.TYPE[a["type"]]
    return view.get("byteOffset", 0) + a.get("byteOffset", 0) + index * view.get("byteStride", size)


# ---- standard (JOINTS_0/WEIGHTS_0) cases: (name, expected words, edit(document, bin)) ----

def weights_value(value):
    def edit(d, b):
        acc = skinned(d)["attributes"]["WEIGHTS_0"]
        if d["accessors"][acc]["componentType"] != 5126:
            raise SystemExit("the asset needs FLOAT weights for this case")
        struct.pack_into("<f", b, element_offset(d, acc, 5), value)
    return edit


def drop_weights(d, b):
    del skinned(d)["attributes"]["WEIGHTS_0"]


def joint_past_skin(d, b):
    acc = skinned(d)["attributes"]["JOINTS_0"]
    ctype = d["accessors"][acc]["componentType"]
    struct.pack_into("<H" if ctype == 5123 else "<B", b, element_offset(d, acc, 7), len(d["skins"][0]["joints"]))


def accessor_past_view(d, b):
    d["accessors"][skinned(d)["attributes"]["JOINTS_0"]]["count"] *= 3


def accessor_missing(d, b):
    skinned(d)["attributes"]["JOINTS_0"] = len(d["accessors"]) + 5


def view_past_buffer(d, b):
    acc = d["accessors"][skinned(d)["attributes"]["WEIGHTS_0"]]
    d["bufferViews"][acc["bufferView"]]["byteOffset"] = len(b) - 8


def requires_draco(d, b):
    d.setdefault("extensionsUsed", []).append("KHR_draco_mesh_compression")
    d.setdefault("extensionsRequired", []).append("KHR_draco_mesh_compression")


def broken_meshopt(d, b):
    """JOINTS_0's view claims meshopt-compressed bytes that are not (16 bytes of the file)."""
    d.setdefault("extensionsUsed", []).append("EXT_meshopt_compression")
    d.setdefault("extensionsRequired", []).append("EXT_meshopt_compression")
    accessor = d["accessors"][skinned(d)["attributes"]["JOINTS_0"]]
    view = d["bufferViews"][accessor["bufferView"]]
    view.setdefault("extensions", {})["EXT_meshopt_compression"] = {
        "buffer": 0, "byteOffset": 0, "byteLength": 16, "byteStride": 8, "count": accessor["count"],
        "mode": "ATTRIBUTES"}


STANDARD = [
    ("requires-draco", "Draco", requires_draco),
    ("broken-meshopt", "does not decode", broken_meshopt),
    ("nan-weight", "finite", weights_value(float("nan"))),
    ("negative-weight", "negative", weights_value(-0.25)),
    ("joints-without-weights", "without WEIGHTS_0", drop_weights),
    ("joint-past-skin", "past the skin", joint_past_skin),
    ("accessor-past-view", "past the end", accessor_past_view),
    ("accessor-missing", "does not exist", accessor_missing),
    ("view-past-buffer", "outside buffer", view_past_buffer),
]


# ---- packed (SKINPACK_packed_skin) cases ----

def ext_of(d):
    return skinned(d)["extensions"][EXT]


def set_field(name, value):
    def edit(d, b):
        ext_of(d)[name] = value
    return edit


def word_fields(tuple_value=None, code_value=None):
    def edit(d, b):
        e = ext_of(d)
        if e["tupleBits"] + e["weightBits"] > 32:
            raise SystemExit("the asset's packed words must be one u32 for this case")
        offset = element_offset(d, e["vertices"], 3)
        word = struct.unpack_from("<I", b, offset)[0]
        mask = (1 << e["weightBits"]) - 1
        if code_value is not None:
            word = (word & ~mask) | code_value(e)
        if tuple_value is not None:
            word = (word & mask) | (tuple_value(e) << e["weightBits"])
        struct.pack_into("<I", b, offset, word & 0xffffffff)
    return edit


def lut_joint(d, b):
    e = ext_of(d)
    acc = d["accessors"][e["tupleTable"]]
    fmt = "<B" if acc["componentType"] == 5121 else "<H"
    struct.pack_into(fmt, b, element_offset(d, e["tupleTable"], 0), e["jointCount"])


def oss_code_count(n):
    """T(N) of docs/format.md, for K = 4."""
    def u(k):
        return (3 * n * k * (n - 2 * k + 3) + k * (4 * k * k - 9 * k + 6) + 2) // 9
    return u((n + 1) // 2)


def lut_size(d):
    return d["accessors"][ext_of(d)["tupleTable"]]["count"]


def twin_primitive(change):
    """A second primitive sharing the packed words, its extension edited by change(ext, document)."""
    def edit(d, b):
        prim = skinned(d)
        twin = copy.deepcopy(prim)
        change(twin["extensions"][EXT], d)
        next(m for m in d["meshes"] if prim in m["primitives"])["primitives"].append(twin)
    return edit


def another_table(ext, d):
    d["accessors"].append(copy.deepcopy(d["accessors"][ext["tupleTable"]]))
    ext["tupleTable"] = len(d["accessors"]) - 1


PACKED = [
    ("twin-other-n", "declares different properties", twin_primitive(lambda e, d: e.__setitem__("n", e["n"] - 1))),
    ("twin-other-table", 'another "tupleTable"', twin_primitive(another_table)),
    ("code-past-count", "code", word_fields(code_value=lambda e: oss_code_count(e["n"]))),
    ("tuple-past-table", "tuple", word_fields(tuple_value=lambda e: (1 << e["tupleBits"]) - 1)),
    ("lut-joint-past-count", "joint", lut_joint),
    ("weight-bits-65", "weightBits", set_field("weightBits", 65)),
    ("tuple-bits-40", "tupleBits", set_field("tupleBits", 40)),
    ("weight-bits-mismatch", "weightBits", set_field("weightBits", 20)),
    ("tuple-bits-mismatch", "tupleBits", set_field("tupleBits", 3)),
    ("unknown-method", "method", set_field("method", "zip")),
    ("influences-5", "influences", set_field("influences", 5)),
    ("n-zero", "n: 0 below the minimum", set_field("n", 0)),
    ("vertices-missing", "does not exist", set_field("vertices", 100000)),
    ("joint-count-past-skin", "jointCount", set_field("jointCount", 200)),
    ("extension-not-an-object", "no data", lambda d, b: skinned(d)["extensions"].__setitem__(EXT, [1, 2])),
]


def meshlet_byte(name, value, index=0):
    def edit(d, b):
        acc = ext_of(d)["meshlets"][name]
        b[element_offset(d, acc, index)] = value
    return edit


def meshlet_offsets_past_end(d, b):
    acc = ext_of(d)["meshlets"]["offsets"]
    struct.pack_into("<I", b, element_offset(d, acc, 0), 1 << 30)


MESHLETS = [
    ("triangle-past-vertices", "meshlets.triangles: index", meshlet_byte("triangles", 255)),
    ("tuple-past-palette", "meshlets.tuples: index", meshlet_byte("tuples", 250)),
    ("offsets-past-arrays", "meshlets.offsets: index", meshlet_offsets_past_end),
    ("meshlets-not-an-object", "must be an object", lambda d, b: ext_of(d).__setitem__("meshlets", 3)),
]


# ---- compress --meshopt files: the packed words' EXT_meshopt_compression data broken ----

def words_meshopt(d):
    """(index, extension object) of the packed words' bufferView."""
    index = d["accessors"][ext_of(d)["vertices"]]["bufferView"]
    return index, d["bufferViews"][index]["extensions"]["EXT_meshopt_compression"]


def meshopt_edit(change):
    def edit(d, b):
        change(words_meshopt(d)[1], b)
    return edit


def meshopt_cases(d):
    """(name, expected words, edit): each message must name the words' bufferView."""
    view = "bufferView %d" % words_meshopt(d)[0]
    return [
        ("truncated", view + ": EXT_meshopt_compression data does not decode (meshoptimizer error -3: truncated",
         meshopt_edit(lambda m, b: m.__setitem__("byteLength", m["byteLength"] - 9))),
        ("bad-header", view + ": EXT_meshopt_compression data does not decode",
         meshopt_edit(lambda m, b: b.__setitem__(m.get("byteOffset", 0), 0x55))),
        ("past-buffer", view + ": EXT_meshopt_compression bytes",
         meshopt_edit(lambda m, b: m.__setitem__("byteOffset", len(b) - 4))),
        ("count", view + ": EXT_meshopt_compression count * byteStride exceeds byteLength",
         meshopt_edit(lambda m, b: m.__setitem__("count", m["count"] + 1))),
        ("mode", view + ": EXT_meshopt_compression mode",
         meshopt_edit(lambda m, b: m.__setitem__("mode", "WORDS"))),
    ]


def expect_failure(cmd, words, out, work):
    if out and os.path.exists(out):
        os.remove(out)
    result = subprocess.run(cmd, capture_output=True, text=True)
    problems = []
    if result.returncode != 1:
        problems.append("exit status %d (want 1)" % result.returncode)
    if not result.stderr.startswith("Error: ") or words.lower() not in result.stderr.lower():
        problems.append("stderr %r lacks %r" % (result.stderr.strip(), words))
    if out and os.path.exists(out):
        problems.append("output %s was written" % out)
    leftovers = glob.glob(os.path.join(work, "*.tmp-*"))
    if leftovers:
        problems.append("temporary files left: %s" % leftovers)
    status = "ok  " if not problems else "FAIL"
    print("%s %s -> %s" % (status, " ".join(os.path.basename(c) for c in cmd[1:3]), result.stderr.strip()))
    return problems


def compressed(args, flags, name):
    """The asset compressed with flags (compact), loaded: (document, binary)."""
    path = os.path.join(args.work, name)
    subprocess.run([args.skinpack, "compress", args.asset, "-o", path, "--compact"] + flags, check=True,
                   capture_output=True)
    return load(path)


def edited_file_failures(args, out, document, binary):
    """Every broken copy of the asset and of its compressed forms, refused by info and by
    compress (standard copies) or decompress (packed ones)."""
    packed = compressed(args, ["--vertex-bits", "32"], "packed.glb")
    meshlets = compressed(args, ["--meshlets"], "packed_meshlets.glb")
    meshopt = compressed(args, ["--meshopt"], "packed_meshopt.glb")
    cases = [("standard", c, document, binary) for c in STANDARD] + [("packed", c) + packed for c in PACKED]
    cases += [("meshlets", c) + meshlets for c in MESHLETS]
    cases += [("meshopt", c) + meshopt for c in meshopt_cases(meshopt[0])]
    failures = []
    for kind, (name, words, edit), doc, data in cases:
        d, b = copy.deepcopy(doc), bytearray(data)
        edit(d, b)
        path = os.path.join(args.work, "%s-%s.glb" % (kind, name))
        gltf_read.write_glb(d, b, path)
        commands = [[args.skinpack, "info", path]]
        # decompress validates meshlets too (the library's sp_validate_packed), though it drops them
        commands.append([args.skinpack, "compress" if kind == "standard" else "decompress", path, "-o", out])
        for cmd in commands:
            problems = expect_failure(cmd, words, out if "-o" in cmd else None, args.work)
            failures += ["%s: %s" % (name, p) for p in problems]
    return failures


def unreadable_file_failures(args, out, document, binary):
    """Files that are not glTF at all or cut short, a .gltf whose buffer file is missing, and a
    folder in place of a file (it used to abort with an uncaught C++ exception)."""
    failures = []
    with open(args.asset, "rb") as f:
        whole = f.read()
    for name, data, words in [("truncated", whole[: len(whole) // 2], "glTF"), ("empty", b"", "too small"),
                              ("garbage", b"\x00not gltf at all" * 10, "glTF")]:
        path = os.path.join(args.work, "%s.glb" % name)
        with open(path, "wb") as f:
            f.write(data)
        for cmd in ([args.skinpack, "info", path], [args.skinpack, "compress", path, "-o", out]):
            failures += ["%s: %s" % (name, p) for p in expect_failure(cmd, words, out, args.work)]

    missing = copy.deepcopy(document)
    missing["buffers"] = [{"byteLength": len(binary), "uri": "missing.bin"}]
    path = os.path.join(args.work, "missing-buffer.gltf")
    with open(path, "w") as f:
        json.dump(missing, f)
    failures += ["missing-buffer: %s" % p for p in
                 expect_failure([args.skinpack, "compress", path, "-o", out], "missing.bin", out, args.work)]

    for command in ("info", "compress", "decompress"):
        cmd = [args.skinpack, command, args.work] + (["-o", out] if command != "info" else [])
        failures += ["folder: %s" % p for p in expect_failure(cmd, "is a folder", out if command != "info" else None,
                                                              args.work)]
    return failures


def option_failures(args, out):
    """Option mistakes are reported as option errors (exit 2), naming the option; an output
    folder that does not exist is an error, with nothing half-written anywhere."""
    failures = []
    for option, value in (("--weight-bits", "99"), ("--vertex-bits", "0"), ("--max-influences", "9"),
                          ("--method", "zip"), ("--max-error", "2")):
        cmd = [args.skinpack, "compress", args.asset, "-o", out, option, value]
        result = subprocess.run(cmd, capture_output=True, text=True)
        if result.returncode != 2 or option not in result.stderr or os.path.exists(out):
            failures.append("option %s %s: exit %d, %r" % (option, value, result.returncode, result.stderr.strip()))
    bad_out = os.path.join(args.work, "no-such-dir", "out.glb")
    failures += ["unwritable: %s" % p for p in
                 expect_failure([args.skinpack, "compress", args.asset, "-o", bad_out], "cannot", bad_out, args.work)]
    return failures


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--skinpack", required=True)
    parser.add_argument("--work", required=True)
    parser.add_argument("asset")
    args = parser.parse_args()
    os.makedirs(args.work, exist_ok=True)
    out = os.path.join(args.work, "out.glb")
    document, binary = load(args.asset)
    failures = edited_file_failures(args, out, document, binary)
    failures += unreadable_file_failures(args, out, document, binary)
    failures += option_failures(args, out)
    if failures:
        print("\n".join(failures))
        raise SystemExit("%d problem(s)" % len(failures))
    print("OK")

main()
